"""One line of a system held at its two ends (petsc_rod/system/held_line.py), on one
rank (PETSc.COMM_SELF) and on all (PETSc.COMM_WORLD: under ``mpiexec -n 2`` the
parallel run):

(a) its end forces are the single-line solver's reactions (api.solve of the same Model:
    start_force, end_force);
(b) its stiffness, from the line's factored second variation, against central finite
    differences of re-solves: an extensible line hanging between two pins (the elastic
    catenary; also against the derivative of the closed form, Irvine's), and a mooring
    line partly on an elastic seabed (where the start's height enters through the
    seabed's positions);
(c) the stiffness is symmetric (the line is conservative), and without a seabed a
    translation of the whole line changes nothing: K_aa = K_bb = -K_ab;
(d) a small move of the ends, warm-started from the last equilibrium, takes fewer
    iterations than the first solve;
(e) the same numbers on one rank and on all;
(f) in a current (the drag follows the line) the stiffness from the Newton Jacobian
    against central differences, unsymmetric: uniform, and sheared (the drag's depth
    derivative in the Jacobian), alone and on the seabed;
(g) on a seabed profile (the fixed point of the line's lagged iteration, its contact's
    block per node) against central differences, with and without grounded nodes in
    the secant's turn about a row; the same on a seabed grid, the line heading along
    no grid axis.
"""

import dataclasses

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.api import End, Environment, Model, UniformLine, solve
from petsc_rod.errors import RodInputError
from petsc_rod.iteration.events import NewtonAttempt
from petsc_rod.iteration.newton import CONVERGED
from petsc_rod.iteration.stopping import STOP_UNTESTED
from petsc_rod.system.held_line import HeldLine
from petsc_rod.validation.elastic_catenary import elastic_catenary

from helpers import zero_slope_planes

pytestmark = pytest.mark.solver

COMMS = {"one rank": PETSc.COMM_SELF, "all ranks": PETSc.COMM_WORLD}
TIGHT = {"al_rtol": 1e-12, "al_ctol": 1e-12}
# the elastic catenary: 100 m of 10 N/m, EA 1e5 N, pins 80 m across and 20 m up
LENGTH, WEIGHT, EA = 100.0, 10.0, 1e5
HANGING = (np.zeros(3), np.array([80.0, 0.0, 20.0]))
# a mooring line: the anchor on an elastic seabed 30 m below the fairlead, 85 m away
MOORING = (np.array([0.0, 0.0, -30.0]), np.array([85.0, 0.0, 0.0]))


def line_model(ends, seabed=None, current=None, elements=40):
    line = UniformLine(length=LENGTH, stiffness=(1e-2, 1e-2, 1e-2), load=(0, 0, -WEIGHT),
                       axial_stiffness=EA, elements=elements,
                       drag=None if current is None else (1025.0, 1.2, 0.1))
    return Model(line=line, start=End.anchor(tuple(ends[0])), end=End.anchor(tuple(ends[1])),
                 environment=Environment(seabed=seabed, current=current))


def held(model, comm, ends):
    line = HeldLine(model, comm, options=TIGHT)
    assert line.solve(*ends)
    return line


def differences(line, ends, step, one_sided=False):
    """The (6, 6) finite differences of end_forces in the six end coordinates
    (central; ``one_sided``: forward)."""
    base = line.end_forces().ravel()
    columns = []
    for j in range(6):
        move = np.zeros(6)
        move[j] = step
        assert line.solve(ends[0] + move[:3], ends[1] + move[3:])
        plus = line.end_forces().ravel()
        if one_sided:
            columns.append((plus - base) / step)
            continue
        assert line.solve(ends[0] - move[:3], ends[1] - move[3:])
        columns.append((plus - line.end_forces().ravel()) / (2 * step))
    assert line.solve(*ends)
    return np.array(columns).T


@pytest.fixture(scope="module", params=list(COMMS))
def hanging(request):
    line = held(line_model(HANGING), COMMS[request.param], HANGING)
    yield line
    line.destroy()


def test_end_forces_are_the_single_line_solvers_reactions(hanging):
    results = solve(line_model(HANGING), comm=hanging.comm)
    forces = hanging.end_forces()
    assert forces[0] == pytest.approx(results.scalars["start_force"], rel=1e-8, abs=1e-6)
    assert forces[1] == pytest.approx(results.scalars["end_force"], rel=1e-8, abs=1e-6)
    # the supports carry the weight
    assert forces.sum(axis=0) == pytest.approx([0.0, 0.0, -WEIGHT * LENGTH], rel=1e-10)


def test_stiffness_of_the_elastic_catenary(hanging):
    K = hanging.stiffness()
    scale = np.abs(K).max()
    # conservative: a Hessian; no seabed: only the chord matters
    assert np.abs(K - K.T).max() < 1e-10 * scale
    assert np.abs(K[:3, :3] - K[3:, 3:]).max() < 1e-10 * scale
    assert np.abs(K[:3, :3] + K[:3, 3:]).max() < 1e-10 * scale
    assert np.all(np.linalg.eigvalsh(K[3:, 3:]) < 0)            # it pulls back
    found = differences(hanging, HANGING, 1e-3)
    assert np.abs(K - found).max() < 1e-5 * scale
    # the closed form's derivative: F_b = -(H, 0, V_A + w L) at the end (X, Z)
    def pull(X, Z):
        line = elastic_catenary(LENGTH, WEIGHT, EA, X, Z, on_seabed=False)
        return -np.array([line.H, line.V_A + WEIGHT * LENGTH])
    X, Z, step = HANGING[1][0], HANGING[1][2], 1e-3
    closed = np.column_stack([(pull(X + step, Z) - pull(X - step, Z)) / (2 * step),
                              (pull(X, Z + step) - pull(X, Z - step)) / (2 * step)])
    assert K[3:, 3:][np.ix_([0, 2], [0, 2])] == pytest.approx(closed, rel=2e-5)
    # across the plane: the string's H / X
    assert K[4, 4] == pytest.approx(-elastic_catenary(LENGTH, WEIGHT, EA, X, Z, False).H / X,
                                    rel=2e-5)


def test_a_small_move_is_warm_started(hanging):
    first = HeldLine(line_model(HANGING), hanging.comm, options=TIGHT)
    assert first.solve(*HANGING)
    cold = first.iterations
    assert first.solve(HANGING[0], HANGING[1] + np.array([0.5, 0.0, -0.3]))
    assert first.iterations < cold
    first.destroy()
    # solved without the stability test, asked once at the end
    untested = HeldLine(line_model(HANGING), hanging.comm, options={**TIGHT, "al_stability": 0})
    assert untested.solve(*HANGING) and untested.stable() is True
    assert untested.end_forces() == pytest.approx(hanging.end_forces(), rel=1e-9)
    untested.destroy()


def asking(line, monkeypatch):
    """The calls of ``line``'s stability test (appended to the list returned), the
    test itself run as before; and the test."""
    asked, test = [], line.solver.check_stability
    monkeypatch.setattr(line.solver, "check_stability", lambda: asked.append(1) or test())
    return asked, test


def test_a_line_settled_by_newton_takes_its_inertia_test_for_the_verdict(monkeypatch):
    """stable() of a line settled by a Newton run whose last H passed the inertia test
    on the constraint set (settle, or a walk that ends at Newton) is True without the
    stability test's own factorisation, which agrees; a line not settled is tested."""
    plain = HeldLine(line_model(HANGING), PETSc.COMM_WORLD,
                     options={**TIGHT, "al_stability": 0, "al_newton": 0})
    try:
        assert plain.solve(*HANGING)
        assert plain.solve(HANGING[0], HANGING[1] + np.array([0.05, 0.0, 0.0]))
        assert not plain.settled                # the iteration's own tests ended it
        asked, test = asking(plain, monkeypatch)
        assert plain.stable() is True and asked == [1]
        plain.settle()
        assert plain.settled and plain.verified
        assert plain.stable() is True and asked == [1]
        assert test()[0] is True
    finally:
        plain.destroy()
    walked = HeldLine(line_model(MOORING, seabed=-30.0), PETSc.COMM_WORLD,
                      options={**TIGHT, "al_stability": 0})
    try:
        assert walked.solve(*MOORING)
        assert walked.solve(MOORING[0], MOORING[1] + np.array([0.05, 0.0, 0.0]))
        assert walked.settled and walked.verified       # the walk ended at Newton
        asked, test = asking(walked, monkeypatch)
        assert walked.stable() is True and asked == []
        assert test()[0] is True
    finally:
        walked.destroy()


@pytest.fixture(scope="module", params=list(COMMS))
def mooring(request):
    line = held(line_model(MOORING, seabed=-30.0, elements=50), COMMS[request.param],
                MOORING)
    yield line
    line.destroy()


def test_stiffness_on_an_elastic_seabed(mooring):
    results = solve(line_model(MOORING, seabed=-30.0, elements=50), comm=mooring.comm)
    assert results.scalars["touchdown_S"] > 40.0                 # partly grounded
    forces = mooring.end_forces()
    assert forces[0] == pytest.approx(results.scalars["start_force"], rel=1e-8, abs=1e-6)
    assert forces[1] == pytest.approx(results.scalars["end_force"], rel=1e-8, abs=1e-6)
    K = mooring.stiffness()
    scale = np.abs(K).max()
    assert np.abs(K - K.T).max() < 1e-10 * scale
    # the seabed makes a vertical translation matter: K_aa is not -K_ab
    assert abs(K[2, 2] + K[2, 5]) > 10.0
    found = differences(mooring, MOORING, 1e-4)
    # the anchor sits on the seabed: its own vertical stiffness is that of lifting it
    # (pressing it in would add the contact of its node); every other entry two-sided
    mask = np.ones((6, 6), dtype=bool)
    mask[2, 2] = False
    assert np.abs(K - found)[mask].max() < 1e-5 * scale
    lifted = differences(mooring, MOORING, 1e-6, one_sided=True)
    assert K[2, 2] == pytest.approx(lifted[2, 2], rel=1e-4)


def test_one_rank_and_all_agree(mooring):
    alone = held(line_model(MOORING, seabed=-30.0, elements=50), PETSc.COMM_SELF, MOORING)
    try:
        assert mooring.end_forces() == pytest.approx(alone.end_forces(), rel=1e-9, abs=1e-7)
        K, K1 = mooring.stiffness(), alone.stiffness()
        assert np.abs(K - K1).max() < 1e-8 * np.abs(K1).max()
    finally:
        alone.destroy()


@pytest.fixture(scope="module", params=list(COMMS))
def dragged(request):
    line = held(line_model(HANGING, current=(0.0, 0.5, 0.0)), COMMS[request.param], HANGING)
    yield line
    line.destroy()


def test_stiffness_in_a_current(dragged):
    """The drag follows the line: the stiffness is the KKT system's with the Newton
    Jacobian J, and the start's force moves with the whole drag's resultant."""
    results = solve(line_model(HANGING, current=(0.0, 0.5, 0.0)), comm=dragged.comm)
    forces = dragged.end_forces()
    assert forces[0] == pytest.approx(results.scalars["start_force"], rel=1e-8, abs=1e-6)
    assert forces[1] == pytest.approx(results.scalars["end_force"], rel=1e-8, abs=1e-6)
    assert forces[:, 1].sum() > 100.0                       # the current's push
    K = dragged.stiffness()
    scale = np.abs(K).max()
    # no energy: not symmetric; a uniform current and no seabed: only the chord matters
    assert np.abs(K - K.T).max() > 0.1 * scale
    assert np.abs(K[:, :3] + K[:, 3:]).max() < 1e-10 * scale
    found = differences(dragged, HANGING, 1e-3)
    assert np.abs(K - found).max() < 1e-5 * scale


# a sheared current: turning and slowing with depth below the sea surface at z = 25 m
SHEARED = [[0.0, 0.0, 0.5, 0.0], [50.0, 0.3, 0.1, 0.0]]


def sheared_model(ends, seabed=None, elements=20):
    model = line_model(ends, seabed=seabed, current=SHEARED, elements=elements)
    return Model(line=model.line, start=model.start, end=model.end,
                 environment=Environment(seabed=seabed, current=SHEARED, surface=25.0))


@pytest.mark.parametrize("comm", list(COMMS))
@pytest.mark.parametrize("ends, seabed", [(HANGING, None), (MOORING, -30.0)],
                         ids=["hanging", "on the seabed"])
def test_stiffness_in_a_sheared_current(comm, ends, seabed):
    """The drag's depth derivative is in the Newton Jacobian: the stiffness against
    central differences of re-solves (the start raised moves every node's current),
    alone and with the seabed's contact."""
    line = held(sheared_model(ends, seabed), COMMS[comm], ends)
    try:
        K = line.stiffness()
        scale = np.abs(K).max()
        # the shear makes a vertical translation of the whole line matter
        assert abs(K[1, 2] + K[1, 5]) > 1e-3 * scale
        # the same step on the seabed: at 1e-4 m a node's contact edge can fall between
        # the two re-solves of a column (a kink, not the stiffness: 2e-5 at that column)
        found = differences(line, ends, 1e-3)
        mask = np.ones((6, 6), dtype=bool)
        if seabed is not None:              # the anchor on the seabed: one-sided (above)
            mask[2, 2] = False
        assert np.abs(K - found)[mask].max() < 1e-6 * scale
    finally:
        line.destroy()


def test_a_solve_that_fails_is_a_result():
    """Too few iterations: solve says False (no traceback), and the line has no
    equilibrium to give forces of."""
    line = HeldLine(line_model(HANGING), PETSc.COMM_WORLD, options={"al_max_it": 2})
    try:
        assert not line.solve(*HANGING)
        with pytest.raises(RodInputError, match="no converged equilibrium"):
            line.end_forces()
    finally:
        line.destroy()


def test_a_walk_that_fails_keeps_the_last_equilibrium():
    line = held(line_model(HANGING), PETSc.COMM_WORLD, HANGING)
    try:
        before = line.end_forces()
        # a budget no walk of 100 m can keep to (the controller reads it every step)
        line.solver.settings.max_it = 2
        assert not line.solve(HANGING[0], HANGING[1] - np.array([60.0, 0.0, 0.0]))
        assert line.end_forces() == pytest.approx(before, rel=1e-12)
        assert line.positions() == pytest.approx(np.array(HANGING), abs=1e-12)
        line.solver.settings.max_it = 2000
        assert line.solve(HANGING[0], HANGING[1] - np.array([1.0, 0.0, 0.0]))
    finally:
        line.destroy()


class Signalled:
    """An Interrupts (cli/signals.py) whose ranks received SIGTERM, counting the
    questions asked on a line's communicator."""

    def __init__(self):
        self.asked = 0

    def received(self, comm=None):
        self.asked += comm is not None
        return 15


def test_a_walk_stops_at_a_stop_signal_and_keeps_the_last_equilibrium():
    """A line given the run's stop signals (HeldLine.interrupts, as the system's solver
    hands them) asks after every iteration of a walk: a signal ends the walk at its
    first iteration, a failure, the last equilibrium kept."""
    line = held(line_model(HANGING), PETSc.COMM_WORLD, HANGING)
    try:
        before = line.end_forces()
        line.interrupts = Signalled()
        assert not line.solve(HANGING[0], HANGING[1] - np.array([20.0, 0.0, 0.0]))
        assert line.interrupts.asked == 1
        assert line.end_forces() == pytest.approx(before, rel=1e-12)
        line.interrupts = None
        assert line.solve(HANGING[0], HANGING[1] - np.array([20.0, 0.0, 0.0]))
    finally:
        line.destroy()


def test_stiffness_with_a_clamped_start():
    """A clamp holds its frame as the model gives it; an inextensible line's stiffness
    in the ends' positions is as exact as a pinned one's."""
    line = UniformLine(length=LENGTH, stiffness=(50.0, 50.0, 50.0), load=(0, 0, -WEIGHT),
                       elements=40)
    model = Model(line=line, start=End(kind="clamp", position=tuple(HANGING[0])),
                  end=End.anchor(tuple(HANGING[1])), environment=Environment())
    clamped = held(model, PETSc.COMM_WORLD, HANGING)
    try:
        results = solve(model, comm=PETSc.COMM_WORLD)
        assert clamped.end_forces()[0] == pytest.approx(results.scalars["start_force"],
                                                        rel=1e-8)
        moments = clamped.end_moments()
        assert moments[0] == pytest.approx(results.scalars["start_moment"], rel=1e-6,
                                           abs=1e-6)
        assert moments[1] == pytest.approx(results.scalars["end_moment"], rel=1e-6,
                                           abs=1e-6)
        assert abs(moments[0][1]) > 10.0                    # the clamp's reaction
        K = clamped.stiffness()
        scale = np.abs(K).max()
        assert np.abs(K - K.T).max() < 1e-10 * scale
        assert np.abs(K - differences(clamped, HANGING, 1e-3)).max() < 1e-5 * scale
    finally:
        clamped.destroy()


def test_lines_on_their_own_communicators():
    """Each rank holds a different line (another mesh, other ends) on a communicator of
    its own, split from the world's: nothing is collective beyond a line's ranks (a
    call on the world's would hang or mix the lines)."""
    world = PETSc.COMM_WORLD.tompi4py()
    own = PETSc.Comm(world.Split(world.Get_rank()))
    ends = (HANGING[0], HANGING[1] + np.array([-2.0 * world.Get_rank(), 0.0, 0.0]))
    model = line_model(ends, elements=30 + 10 * world.Get_rank())
    line = held(model, own, ends)
    try:
        assert line.solve(ends[0], ends[1] + np.array([0.5, 0.0, 0.0]))
        assert line.solve(*ends)
        K = line.stiffness()
        reference = solve(model, comm=PETSc.COMM_SELF)
        assert line.end_forces()[1] == pytest.approx(reference.scalars["end_force"],
                                                     rel=1e-8)
        assert np.abs(K - K.T).max() < 1e-10 * np.abs(K).max()
    finally:
        line.destroy()
        own.tompi4py().Free()


def test_a_line_of_a_system():
    """A SystemLine (model/system.py) between a fixed point and a point it is held at:
    its HeldLine is the same line as the Model's."""
    from petsc_rod.model.system import Connection, SystemLine
    line = line_model(HANGING).line
    member = SystemLine("one", line, Connection("anchor"), Connection("fairlead"))
    held_line = HeldLine.of_system_line(member, *HANGING, PETSc.COMM_WORLD, Environment(),
                                        TIGHT)
    reference = held(line_model(HANGING), PETSc.COMM_WORLD, HANGING)
    try:
        assert held_line.solve(*HANGING)
        assert held_line.end_forces() == pytest.approx(reference.end_forces(), rel=1e-10)
        assert held_line.stiffness() == pytest.approx(reference.stiffness(), rel=1e-8)
    finally:
        held_line.destroy()
        reference.destroy()


def test_a_line_of_sections_on_the_seabed():
    """Chain, rope, chain (line types of their own EA and weight) from an anchor on an
    elastic seabed: the reactions and the stiffness as for a uniform line."""
    from petsc_rod.api import Line, LineType
    chain = LineType("chain", od=0.1, mass=100.0, ei=1e2, gj=1e2, ea=5e7)
    rope = LineType("rope", od=0.15, mass=20.0, ei=1e2, gj=1e2, ea=1e7)
    line = Line([(chain, 30.0), (rope, 50.0), (chain, 20.0)], element_length=2.0)
    model = Model(line=line, start=End.anchor(tuple(MOORING[0])),
                  end=End.anchor(tuple(MOORING[1])), environment=Environment(seabed=-30.0))
    sections = held(model, PETSc.COMM_WORLD, MOORING)
    try:
        results = solve(model, comm=PETSc.COMM_WORLD)
        assert results.scalars["touchdown_S"] > 25.0
        assert sections.end_forces()[1] == pytest.approx(results.scalars["end_force"],
                                                         rel=1e-8)
        K = sections.stiffness()
        scale = np.abs(K).max()
        assert np.abs(K - K.T).max() < 1e-10 * scale
        found = differences(sections, MOORING, 1e-4)
        mask = np.ones((6, 6), dtype=bool)
        mask[2, 2] = False                  # the anchor on the seabed: one-sided
        assert np.abs(K - found)[mask].max() < 1e-5 * scale
    finally:
        sections.destroy()



@pytest.mark.parametrize("comm", list(COMMS))
@pytest.mark.parametrize("current", [(0.0, 0.3, 0.0), (0.3, 0.0, 0.0)],
                         ids=["across the ends' plane", "in it"])
def test_stiffness_on_the_seabed_in_a_uniform_current(comm, current):
    """A mooring line partly grounded in a uniform current, across the plane of its ends
    and in it, walked to its ends (the iteration's own tolerances end the walk short of
    the stationary point): the stiffness, taken at the stationary point, against central
    differences of re-solves; and again after the differences' walks (round sections,
    nothing clamped: one roll of every section is a null vector of J, whose pivot one
    rank's LU keeps: the stiffness's solves hold it)."""
    model = line_model(MOORING, seabed=-30.0, current=current, elements=50)
    line = HeldLine(model, COMMS[comm])
    try:
        assert line.solve(MOORING[0], MOORING[1] + np.array([-3.0, 2.0, 0.0]))
        assert line.solve(*MOORING)
        assert solve(model, comm=line.comm).scalars["touchdown_S"] > 30.0
        K = line.stiffness()
        scale = np.abs(K).max()
        assert np.abs(K - K.T).max() > 1e-3 * scale          # the drag: no energy
        found = differences(line, MOORING, 1e-3)
        assert but_the_anchors_lift(K - found) < 1e-6 * scale
        assert but_the_anchors_lift(line.stiffness() - found) < 1e-6 * scale
    finally:
        line.destroy()


def but_the_anchors_lift(error):
    """The largest |error| of a (6, 6) stiffness but its [2, 2]: the anchor on the seabed
    has a one-sided vertical stiffness (lifting it), which central differences miss."""
    mask = np.ones((6, 6), dtype=bool)
    mask[2, 2] = False
    return np.abs(error)[mask].max()


def test_a_converged_newton_run_of_an_undone_attempt_does_not_settle_the_line(monkeypatch):
    """A walk whose first attempt converged in Newton's steps and was then failed (as
    the stability test's failed factorisation fails it: STOP_UNTESTED) is halved, and
    its two half steps end by the iteration's (default) tolerances before any Newton
    run: the state is not Newton's stationary point, so the stiffness settles it first
    (a grounded line's sideways stiffness feels the difference). The mooring line's
    stiffness after a 2 cm sideways move of its fairlead against central differences of
    re-solves."""
    line = HeldLine(line_model(MOORING, seabed=-30.0), PETSc.COMM_WORLD)
    ends = (MOORING[0], MOORING[1] + np.array([0.0, 0.02, 0.0]))
    assert line.solve(*MOORING)
    solve_step, failed = line.solver.solve_step, []

    def untested_once(t, label="", observer=None):
        report = solve_step(t, label=label, observer=observer)
        if failed:
            return report
        failed.append(report)
        return dataclasses.replace(report, converged=False, reason=STOP_UNTESTED)
    try:
        monkeypatch.setattr(line.solver, "solve_step", untested_once)
        assert line.solve(*ends)
        monkeypatch.undo()
        newton = [e for e in failed[0].events if isinstance(e, NewtonAttempt)]
        assert newton and newton[-1].outcome == CONVERGED
        K = line.stiffness()
        scale = np.abs(K).max()
        found = differences(line, ends, 1e-3)
        assert but_the_anchors_lift(K - found) < 1e-5 * scale
    finally:
        line.destroy()


# the mooring over a plane rising 3 degrees towards azimuth 30 degrees, 0.2 m below
# the anchor there: its chain grounded on the slope and pushed across it
SLOPE = {"seabed": -30.2, "seabed_slope": 3.0, "seabed_direction": 30.0,
         "seabed_origin": (0.0, 0.0)}


def sloped_model(elements=40, drag=None, **sea):
    line = UniformLine(length=LENGTH, stiffness=(1e-2, 1e-2, 1e-2), load=(0, 0, -WEIGHT),
                       axial_stiffness=EA, elements=elements, drag=drag)
    return Model(line=line, start=End.anchor(tuple(MOORING[0])),
                 end=End.anchor(tuple(MOORING[1])), environment=Environment(**sea))


def against_differences(line, K, step=1e-4):
    """max |K - central differences of re-solves (``step`` m)| / max |K| of the
    mooring."""
    error = np.abs(K - differences(line, MOORING, step)).max() / np.abs(K).max()
    print(f"K against differences {error:.3g} of {np.abs(K).max():.6g}")
    return error


@pytest.mark.parametrize("comm", list(COMMS))
def test_stiffness_on_a_sloping_seabed(comm):
    """The plane's contact k w_n N N^T in the Newton system (Seabed.position_derivatives):
    the (6, 6) against central differences of re-solves, every entry (the anchor is off
    the plane, so no node's contact is one-sided)."""
    line = held(sloped_model(**SLOPE), COMMS[comm], MOORING)
    try:
        forces = line.end_forces()
        assert abs(forces[0, 1]) > 1.0                  # pushed across the slope
        K = line.stiffness()
        assert np.abs(K - K.T).max() < 1e-10 * np.abs(K).max()
        assert against_differences(line, K) < 1e-6
    finally:
        line.destroy()


def test_the_stiffness_after_further_newton_runs_in_a_sheared_current():
    """Newton runs from the converged state move it by round-off only (a roll of every
    section, the free roll, and round-off of the positions and the chord's multiplier),
    which on two ranks decides whether the substructured factor keeps the free roll's
    null pivot or drops it: the stiffness (its solves with J refined once) is the same
    either way, against central differences of re-solves as in
    test_stiffness_in_a_sheared_current, after each of two runs."""
    line = held(sheared_model(MOORING, -30.0), PETSc.COMM_WORLD, MOORING)
    try:
        stiffnesses = []
        for _ in range(2):
            assert line.newton.run() == CONVERGED
            stiffnesses.append(line.stiffness())
        found = differences(line, MOORING, 1e-3)
        for K in stiffnesses:
            assert but_the_anchors_lift(K - found) < 1e-6 * np.abs(K).max()
    finally:
        line.destroy()


def test_stiffness_on_a_sloping_seabed_in_a_current():
    """A uniform current across the slope: the drag's Jacobian with the plane's
    contact, against central differences of re-solves."""
    line = held(sloped_model(drag=(1025.0, 1.2, 0.1), current=(0.0, 0.3, 0.0), **SLOPE),
                PETSc.COMM_WORLD, MOORING)
    try:
        K = line.stiffness()
        assert np.abs(K - K.T).max() > 1e-3 * np.abs(K).max()    # the drag: not symmetric
        # the steps of the flat seabed's case in a current (above): its re-solves' noise
        assert against_differences(line, K, 1e-3) < 1e-6
    finally:
        line.destroy()


def test_a_plane_of_slope_zero_is_the_flat_seabed(monkeypatch):
    """The plane's path (its contact on the x, y, z chains, the stiffness's plane
    response) with a slope of 0 (zero_slope_planes) against the flat seabed's: the end
    forces and the stiffness to round-off (compile.seabed_shape makes a slope of 0 the
    flat seabed itself, so without the plane forced this compared the flat seabed with
    itself)."""
    zero_slope_planes(monkeypatch)          # a slope of 0 only
    numbers = []
    for sea in ({**SLOPE, "seabed_slope": 0.0}, {"seabed": SLOPE["seabed"]}):
        line = held(sloped_model(**sea), PETSc.COMM_SELF, MOORING)
        try:
            assert line.scene.seabed.plane is ("seabed_slope" in sea)
            numbers.append((line.end_forces(), line.stiffness()))
        finally:
            line.destroy()
    (forces, K), (flat_forces, flat_K) = numbers
    assert np.abs(forces - flat_forces).max() <= 1e-12 * np.abs(flat_forces).max()
    # the stiffness through other solves of the factor (measured 2.7e-12)
    assert np.abs(K - flat_K).max() <= 1e-10 * np.abs(flat_K).max()


# seabed profiles under the mooring along +x from the anchor, level at
# its seabed up to a row at 20 m and rising 1.7 degrees beyond: the chain's grounded
# part (to about 50 m) spans the row. NARROW adds two rows 1 m apart far away, so the
# secant turns over delta = 0.1 m only and no grounded node meets its turn; WIDE's
# rows are 120 m apart at the closest (delta = 12 m: eight grounded nodes within
# delta / 2 of the row, where g' enters and the block is not symmetric).
NARROW = ((-100.0, -30.2), (20.0, -30.2), (200.0, -25.0), (300.0, -25.0), (301.0, -25.0))
WIDE = ((-100.0, -30.2), (20.0, -30.2), (200.0, -25.0))


def turning_nodes(line):
    """How many grounded nodes of the line meet the secant's turn (g' != 0), on every
    rank."""
    seabed = line.scene.seabed
    r = line.problem.state.node_positions()
    rate = seabed.shape.slopes(r[:, 0], r[:, 1])[2]
    return line.mesh.global_sum(int(np.sum((seabed.gap(r) < 0) & (rate != 0))))


@pytest.mark.parametrize("comm", list(COMMS))
@pytest.mark.parametrize("rows", [NARROW, WIDE], ids=["away from the turn", "in the turn"])
def test_stiffness_on_a_seabed_profile(comm, rows):
    """The profile's contact in the Newton system at the fixed point of the line's
    lagged iteration (Seabed.profile_derivatives: the penetration's z_b', the push's
    secant g and its rate g', k_v's turn with g): the (6, 6) against central differences
    of re-solves, every entry; symmetric where no grounded node meets the secant's turn,
    not quite where some do."""
    line = held(sloped_model(seabed_profile=rows), COMMS[comm],
                MOORING)
    try:
        summary = line.summary()
        assert 30.0 < summary["touchdown_S"] < 70.0 and summary["grounded_length"] > 30.0
        K = line.stiffness()
        assert line.settled                 # Newton's steps reached the fixed point
        turning = turning_nodes(line)
        assert (turning == 0) if rows is NARROW else (turning >= 4)
        asymmetry = np.abs(K - K.T).max() / np.abs(K).max()
        print(f"K - K^T {asymmetry:.3g}")
        assert (asymmetry < 1e-12) if rows is NARROW else (asymmetry > 1e-7)
        assert against_differences(line, K) < 1e-7
    finally:
        line.destroy()


def test_the_secant_turn_matters_on_a_profile(monkeypatch):
    """WIDE's stiffness with the secant's rate g' dropped from the block misses the
    differences by 3.6e-3 of its largest entry: its terms are what makes the stiffness
    exact near a row."""
    from petsc_rod.environment.bathymetry import Profile

    line = held(sloped_model(seabed_profile=WIDE), PETSc.COMM_SELF,
                MOORING)
    try:
        found = differences(line, MOORING, 1e-4)
        exact = line.stiffness()
        slopes = Profile.slopes
        monkeypatch.setattr(Profile, "slopes",
                            lambda self, x, y: slopes(self, x, y)[:2] + (0.0,))
        rough = line.stiffness()
        scale = np.abs(exact).max()
        assert np.abs(exact - found).max() < 1e-7 * scale
        assert np.abs(rough - found).max() > 1e-3 * scale
    finally:
        line.destroy()


# seabed grids under the mooring turned 30 degrees off +x (its heading along no grid
# axis): heights -30.2 m at the anchor rising 0.01 along x and 0.015 along y with a
# twist, and 0.02 more along x beyond a grid line x = kink; AWAY_GRID's kink at
# 120 m, no grid line within 15 m of the grounded part (the secant turning over
# hx = 4 m at the lines), NEAR_GRID's at 20 m across it (hx = 5 m: grounded nodes
# within delta / 2 of it, where g != grad z_b and the block is not symmetric). The
# lagged iteration on these grids stalls short of TIGHT's tolerance: each solve and
# re-solve ends at a looser one, settled by Newton's steps at the fixed point
# (HeldLine.settle) before its forces are read.
HEADING = np.radians(30.0)
TURNED = (MOORING[0], np.array([85.0 * np.cos(HEADING), 85.0 * np.sin(HEADING), 0.0]))
GRID_TOLERANCE = {"al_rtol": 1e-8, "al_ctol": 1e-8}
GRID_STEP = 1e-4


def settled_differences(line, ends, step):
    """differences' (6, 6) with each re-solve settled (HeldLine.settle)."""
    solve = line.solve

    def settled(*args):
        ok = solve(*args)
        line.settle()
        assert line.settled
        return ok

    line.solve = settled
    try:
        return differences(line, ends, step)
    finally:
        del line.solve


def grid_rows(xs, kink, ys=(-100.0, 100.0, 200.0)):
    return tuple((x, y, -30.2 + 0.01 * x + 0.015 * y + 1e-4 * x * y
                  + 0.02 * max(x - kink, 0.0)) for x in xs for y in ys)


AWAY_GRID = grid_rows((-100.0, -20.0, 120.0, 300.0), 120.0)
NEAR_GRID = grid_rows((-100.0, 20.0, 120.0, 300.0), 20.0)


def grid_turning_nodes(line):
    """How many grounded nodes of the line meet the secant's turn at a grid line
    (g != grad z_b), on every rank."""
    seabed = line.scene.seabed
    r = line.problem.state.node_positions()
    rise, g, _ = seabed.shape.slopes(r[:, 0], r[:, 1])
    turning = (seabed.gap(r) < 0) & (np.abs(g - rise).max(axis=1) > 1e-12)
    return line.mesh.global_sum(int(np.sum(turning)))


@pytest.mark.parametrize("comm", list(COMMS))
@pytest.mark.parametrize("rows", [AWAY_GRID, NEAR_GRID],
                         ids=["away from the grid lines", "at a grid line"])
def test_stiffness_on_a_seabed_grid(comm, rows):
    """The grid's contact in the Newton system (Seabed.profile_derivatives with
    Grid.slopes' grad z_b, g and Dg in the plan), the line heading 30 degrees off the
    grid's x axis: the (6, 6) against central differences of re-solves, every entry;
    not symmetric where grounded nodes meet the secant's turn."""
    line = HeldLine(sloped_model(seabed_profile=rows), COMMS[comm], options=GRID_TOLERANCE)
    assert line.solve(*TURNED)
    try:
        summary = line.summary()
        assert 30.0 < summary["touchdown_S"] < 70.0 and summary["grounded_length"] > 30.0
        forces = line.end_forces()
        assert abs(forces[0, 0] * np.sin(HEADING) - forces[0, 1] * np.cos(HEADING)) > 1.0
        K = line.stiffness()
        assert line.settled
        turning = grid_turning_nodes(line)
        assert (turning == 0) if rows is AWAY_GRID else (turning >= 4)
        asymmetry = np.abs(K - K.T).max() / np.abs(K).max()
        print(f"K - K^T {asymmetry:.3g}")
        if rows is NEAR_GRID:
            assert asymmetry > 1e-7
        error = (np.abs(K - settled_differences(line, TURNED, GRID_STEP)).max()
                 / np.abs(K).max())
        print(f"K against differences {error:.3g} of {np.abs(K).max():.6g}")
        assert error < 1e-7
    finally:
        line.destroy()


def test_the_secant_turn_matters_on_a_grid(monkeypatch):
    """NEAR_GRID's stiffness with the secant's derivative Dg dropped from the block
    misses the settled differences by 3.9e-3 of its largest entry: Dg's terms are what
    makes the stiffness exact near a grid line."""
    from petsc_rod.environment.bathymetry import Grid

    line = HeldLine(sloped_model(seabed_profile=NEAR_GRID), PETSc.COMM_SELF,
                    options=GRID_TOLERANCE)
    try:
        assert line.solve(*TURNED)
        exact = line.stiffness()
        found = settled_differences(line, TURNED, GRID_STEP)
        slopes = Grid.slopes

        def without_turn(self, x, y):
            rise, g, rate = slopes(self, x, y)
            return rise, g, np.zeros_like(rate)

        monkeypatch.setattr(Grid, "slopes", without_turn)
        rough = line.stiffness()
        scale = np.abs(exact).max()
        print(f"exact {np.abs(exact - found).max() / scale:.3g}, "
              f"without Dg {np.abs(rough - found).max() / scale:.3g}")
        assert np.abs(exact - found).max() < 1e-7 * scale
        assert np.abs(rough - found).max() > 1e-3 * scale
    finally:
        line.destroy()
