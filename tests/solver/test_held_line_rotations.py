"""A line of a system with clamped ends whose frames are inputs (petsc_rod/system/
held_line.py): HeldLine.solve(start, end, start_frame, end_frame) walks a clamp's frame,
and end_stiffness(), the (12, 12) of the forces and moments on both ends against the
ends' positions and small rotations of the clamps' frames, from the factored second
variation, agrees with central differences of re-solves with moved ends and turned
frames, on an inextensible line (one clamp, the other end pinned) and an extensible one
(both clamped: the clamped nodes' stretches held by their force balance), on one rank
and on all."""

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.api import End, Environment, Model, UniformLine, solve
from petsc_rod.errors import RodInputError
from petsc_rod.frames import rotations
from petsc_rod.system.held_line import HeldLine

pytestmark = pytest.mark.solver

COMMS = {"one rank": PETSc.COMM_SELF, "all ranks": PETSc.COMM_WORLD}
TIGHT = {"al_rtol": 1e-12, "al_ctol": 1e-12}
ENDS = (np.zeros(3), np.array([80.0, 0.0, 20.0]))
REFERENCE = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
# a clamp turned off the reference frame about a skew axis
TURNED = REFERENCE @ rotations(np.array([0.1, -0.3, 0.2])).T


def clamped_line(comm, extensible, current=None):
    line = UniformLine(length=100.0, stiffness=(50.0, 50.0, 50.0), load=(0, 0, -10.0),
                       elements=40, axial_stiffness=1e5 if extensible else np.inf,
                       drag=None if current is None else (1025.0, 1.2, 0.1))
    end = (End(kind="clamp", position=tuple(ENDS[1])) if extensible
           else End.anchor(tuple(ENDS[1])))
    model = Model(line=line, start=End(kind="clamp", position=tuple(ENDS[0])), end=end,
                  environment=Environment(current=current))
    held = HeldLine(model, comm, options=TIGHT)
    frames = [TURNED, REFERENCE if extensible else None]
    assert held.solve(*ENDS, *frames)
    return held, frames


def outputs(line):
    return np.concatenate([line.end_forces().ravel(), line.end_moments().ravel()])


def differences(line, frames, step=1e-4, ends=ENDS):
    """(12, 12) central differences of (F_a, F_b, M_a, M_b) in (x_a, x_b, theta_a,
    theta_b) about the ends at ``ends``, a frame Q turned to exp([theta]x) Q (rows:
    Q exp(-[theta]x)); zero columns for a pinned end's rotation."""
    columns = []
    for j in range(12):
        e, k = divmod(j % 6, 3)
        if j >= 6 and frames[e] is None:
            columns.append(np.zeros(12))
            continue
        values = []
        for sign in (1.0, -1.0):
            x = [ends[0].copy(), ends[1].copy()]
            turned = list(frames)
            if j < 6:
                x[e][k] += sign * step
            else:
                turned[e] = frames[e] @ rotations(sign * step * np.eye(3)[k]).T
            assert line.solve(*x, *turned)
            values.append(outputs(line))
        columns.append((values[0] - values[1]) / (2 * step))
    assert line.solve(*ends, *frames)
    return np.array(columns).T


@pytest.mark.parametrize("comm", list(COMMS))
@pytest.mark.parametrize("extensible", [False, True], ids=["inextensible", "extensible"])
def test_end_stiffness_against_differences(comm, extensible):
    line, frames = clamped_line(COMMS[comm], extensible)
    try:
        moments = line.end_moments()
        assert abs(moments[0]).max() > 10.0                 # the turned clamp's reaction
        K = line.end_stiffness()
        assert K.shape == (12, 12)
        scale = np.abs(K).max()
        # measured: 1.5e-9 inextensible, 4e-8 extensible (the step's truncation)
        assert np.abs(K - differences(line, frames)).max() < 1e-6 * scale
        # the moment's rotation block carries the clamp's reaction
        assert np.abs(K[6:9, 6:9]).max() > 0.5 * abs(moments[0]).max()
        if not extensible:
            # a pinned end turns nothing; the 6 x 6 is stiffness()'s
            assert np.all(K[:, 9:] == 0.0)
            assert np.abs(K[:6, :6] - line.stiffness()).max() < 1e-12 * scale
        # the forces' position block is symmetric (conservative), except for the
        # extensible clamp's stretch rule EA (k - 1) = n.d3, which is not the energy's
        # (measured 7e-8 of the largest entry)
        asymmetry = np.abs(K[:6, :6] - K[:6, :6].T).max() / scale
        assert asymmetry < (1e-6 if extensible else 1e-12)
    finally:
        line.destroy()


@pytest.mark.parametrize("comm", list(COMMS))
@pytest.mark.parametrize("extensible", [False, True], ids=["inextensible", "extensible"])
def test_end_stiffness_in_a_current_against_differences(comm, extensible):
    """A clamp in a current: turning it turns the drag at the clamped node (the drag's
    Jacobian columns at the clamp's rotation) and moves the drag's resultant on the
    start; unsymmetric."""
    line, frames = clamped_line(COMMS[comm], extensible, current=(0.2, 0.5, 0.0))
    try:
        assert line.end_forces()[:, 1].sum() > 50.0             # the current's push
        K = line.end_stiffness()
        scale = np.abs(K).max()
        found = differences(line, frames)
        print("ERR", np.abs(K - found).max() / scale)
        assert np.abs(K - found).max() < 1e-6 * scale
        assert np.abs(K[6:9, 6:9]).max() > 0.5 * abs(line.end_moments()[0]).max()
    finally:
        line.destroy()


def test_a_frame_walk_is_the_fresh_solve():
    """A clamp's frame walked from the reference is the line solved afresh with it."""
    walked, frames = clamped_line(PETSc.COMM_WORLD, False)
    line = UniformLine(length=100.0, stiffness=(50.0, 50.0, 50.0), load=(0, 0, -10.0),
                       elements=40)
    model = Model(line=line, start=End(kind="clamp", position=tuple(ENDS[0]),
                                       frame=tuple(TURNED.ravel())),
                  end=End.anchor(tuple(ENDS[1])), environment=Environment())
    fresh = HeldLine(model, PETSc.COMM_WORLD, options=TIGHT)
    try:
        assert walked.solve(*ENDS, REFERENCE)               # back to the reference ...
        assert walked.solve(*ENDS, TURNED)                  # ... and turned again
        assert fresh.solve(*ENDS)
        assert np.abs(walked.end_moments() - fresh.end_moments()).max() < 1e-7
        assert np.abs(walked.end_forces() - fresh.end_forces()).max() < 1e-7
        with pytest.raises(RodInputError, match="only a clamp or a flex joint holds a frame"):
            walked.solve(*ENDS, None, REFERENCE)
        with pytest.raises(RodInputError, match="a rotation"):
            walked.solve(*ENDS, 2.0 * REFERENCE)
    finally:
        walked.destroy()
        fresh.destroy()


@pytest.mark.parametrize("comm", list(COMMS))
@pytest.mark.parametrize("extensible", [False, True], ids=["inextensible", "extensible"])
def test_a_flex_joints_end_stiffness_against_differences(comm, extensible):
    """A flex joint's support turned turns its axis with it (a = D^T D_ref a_0): the
    12 x 12 with the joint's moment on its support, -k (theta / sin theta) d3 x a,
    against central differences (measured 5e-10); its rotation block's antisymmetric
    part is -[M]x, M the joint's moment (left increments of a conservative joint); at an
    extensible end too, where the joint acts in the local step."""
    line = UniformLine(length=100.0, stiffness=(50.0, 50.0, 50.0), load=(0, 0, -10.0),
                       elements=40, axial_stiffness=1e5 if extensible else np.inf)
    model = Model(line=line, start=End(kind="pin", position=tuple(ENDS[0]), stiffness=200.0),
                  end=End.anchor(tuple(ENDS[1])), environment=Environment())
    flexed = HeldLine(model, COMMS[comm], options=TIGHT)
    frames = [TURNED, None]
    try:
        assert flexed.solve(*ENDS, *frames)
        moment = flexed.end_moments()[0]
        assert np.abs(moment).max() > 10.0                  # the turned joint's moment
        K = flexed.end_stiffness()
        scale = np.abs(K).max()
        assert np.abs(K - differences(flexed, frames)).max() < 1e-6 * scale
        skew_part = K[6:9, 6:9] - K[6:9, 6:9].T
        assert np.abs(skew_part + np.array([[0.0, -moment[2], moment[1]],
                                            [moment[2], 0.0, -moment[0]],
                                            [-moment[1], moment[0], 0.0]])).max() \
            < 1e-8 * scale
    finally:
        flexed.destroy()


@pytest.mark.parametrize("comm", list(COMMS))
def test_a_flex_joints_end_stiffness_on_the_seabed_in_a_current(comm):
    """A cable partly grounded in a uniform current across the plane of its ends, its
    fairlead on a flex joint (its support in the reference frame), walked to its ends:
    the 12 x 12 against central differences of re-solves, and again after the
    differences' walks. Round sections and nothing clamped (a flex joint holds no
    roll): one roll of every section about its tangent is a null vector of J, whose
    pivot one rank's LU keeps; end_stiffness's solves hold it, as stiffness()'s do.
    The re-solves stop at TIGHT's tolerances: at the iteration's default each walk
    stops short of the equilibrium by an amount that does not cancel between the two
    sides, a bias of the differences (in the joint's support rotation) that grows with
    the tolerance and as 1/step; the step 2e-3 balances their O(step^2) truncation
    against the re-solves' remaining noise at the grounded anchor's entries (the
    tolerance and step studies: docs/systems.md)."""
    ends = (np.array([0.0, 0.0, -30.0]), np.array([85.0, 0.0, 0.0]))
    line = UniformLine(length=100.0, stiffness=(1e-2, 1e-2, 1e-2), load=(0, 0, -10.0),
                       axial_stiffness=1e5, elements=50, drag=(1025.0, 1.2, 0.1))
    model = Model(line=line, start=End.anchor(tuple(ends[0])),
                  end=End(kind="pin", position=tuple(ends[1]), stiffness=5.0),
                  environment=Environment(seabed=-30.0, current=(0.0, 0.3, 0.0)))
    flexed = HeldLine(model, COMMS[comm], options=TIGHT)
    frames = [None, REFERENCE]
    try:
        assert flexed.solve(ends[0], ends[1] + np.array([-3.0, 2.0, 0.0]), *frames)
        assert flexed.solve(*ends, *frames)
        assert np.abs(flexed.end_moments()[1]).max() > 1.0      # the joint's
        K = flexed.end_stiffness()
        scale = np.abs(K).max()
        found = differences(flexed, frames, 2e-3, ends)
        # the anchor on the seabed: its vertical stiffness one-sided (lifting it)
        mask = np.ones((12, 12), dtype=bool)
        mask[2, 2] = False
        assert np.abs(K - found)[mask].max() < 1e-7 * scale
        for _ in range(3):                  # each Newton run moves round-off's roll
            assert np.abs(flexed.end_stiffness() - found)[mask].max() < 1e-7 * scale
            flexed.newton.run()
    finally:
        flexed.destroy()


# the mooring over a plane rising 3 degrees towards azimuth 30 degrees, 0.2 m below its
# anchor (test_held_line.SLOPE): its chain grounded on the slope and pushed across it
MOORING = (np.array([0.0, 0.0, -30.0]), np.array([85.0, 0.0, 0.0]))
SLOPE = dict(seabed=-30.2, seabed_slope=3.0, seabed_direction=30.0, seabed_origin=(0.0, 0.0))


def dipping_frame(dip):
    """A clamp's frame (rows d1, d2, d3) whose d3 points along +x and down by ``dip``
    (the slope's tangent), d1 horizontal."""
    d3 = np.array([1.0, 0.0, -dip]) / np.hypot(1.0, dip)
    d1 = np.cross([0.0, 0.0, 1.0], d3)
    d1 /= np.linalg.norm(d1)
    return np.array([d1, np.cross(d3, d1), d3])


# a seabed profile along +x, level 0.05 m below the anchor up to a row at 1.5 m, rising
# 1.5 degrees beyond: the clamp's first midpoint grounded within delta / 2 = 5.1 m of
# the row, where the profile's block is not symmetric and the midpoint's position reads
# the clamp's rotation: J's held columns take the block's antisymmetric part
# (SeabedTerm.turn_columns; without it 3.2e-2 of K off the differences)
PROFILE = dict(seabed_profile=((-100.0, -30.05), (1.5, -30.05), (200.0, -25.0)))
CASES = {"clamp": (False, SLOPE), "extensible clamp": (True, SLOPE),
         "flex": (True, SLOPE), "extensible fairlead clamp": (True, SLOPE),
         "clamp on a profile": (False, PROFILE)}
# a fairlead clamp's frame: d3 rising at 0.8 along +x (d3's z not zero: the seabed's
# vertical problem prescribes the stretched slope there too)
RISING = dipping_frame(-0.8)


@pytest.mark.parametrize("comm", list(COMMS))
@pytest.mark.parametrize("end", list(CASES))
def test_end_stiffness_on_a_sloping_seabed_against_differences(comm, end):
    """A clamped or flex-jointed end on a sloping plane: the seabed's
    reaction on the start moves with the whole start position and with the held data
    (the clamp's rotation, the joint's support), _rotation_response on
    _plane_response's (x_a, c): the 12 x 12 against central differences of re-solves.
    The clamp at the anchor of an inextensible and of an extensible line (its stretch
    prescribed in the seabed's vertical problem too, docs/method.md §12), pointing 0.3
    down so that its first element's far vertex lies on the seabed: the clamp's
    rotation moves that contact (without its share the error is of the order of K
    itself); the flex joint at the fairlead of an extensible line, its support in the
    reference frame; a clamp there, rising at 0.8."""
    extensible, sea = CASES[end]
    if "seabed_profile" in sea and (comm == "one rank" or PETSc.COMM_WORLD.getSize() > 1):
        # its 24 re-solves by the profile's lagged iteration take a minute on one rank
        # and 20 on two loaded ones; run once, serially (a profile's stiffness on two
        # ranks: test_held_line.test_stiffness_on_a_seabed_profile, test_system_profile)
        pytest.skip("the clamp on a profile: serially, once")
    line = UniformLine(length=100.0, stiffness=(50.0, 50.0, 50.0), load=(0, 0, -10.0),
                       elements=40, axial_stiffness=1e5 if extensible else np.inf)
    clamped = end not in ("flex", "extensible fairlead clamp")
    if clamped:
        ends = (End(kind="clamp", position=tuple(MOORING[0])), End.anchor(tuple(MOORING[1])))
        frames = [dipping_frame(0.3), None]
    elif end == "flex":
        ends = (End.anchor(tuple(MOORING[0])),
                End(kind="pin", position=tuple(MOORING[1]), stiffness=200.0))
        frames = [None, REFERENCE]
    else:
        ends = (End.anchor(tuple(MOORING[0])), End(kind="clamp", position=tuple(MOORING[1])))
        frames = [None, RISING]
    model = Model(line=line, start=ends[0], end=ends[1], environment=Environment(**sea))
    held = HeldLine(model, COMMS[comm], options=TIGHT)
    try:
        assert held.solve(*MOORING, *frames)
        if "seabed_slope" in sea:
            assert abs(held.end_forces()[0, 1]) > 1.0       # pushed across the slope
        e = 0 if clamped else 1
        assert np.abs(held.end_moments()[e]).max() > 1.0    # the clamp's, the joint's
        K = held.end_stiffness()
        scale = np.abs(K).max()
        # a profile's re-solves (its lagged iteration, no Newton steps) are noisier:
        # 1e-3 rad and m (8.6e-7 of K with 1e-4 in the moments' rows, on a profile
        # whose turn the clamp's element does not meet)
        step = 1e-3 if "seabed_profile" in sea else 1e-4
        error = np.abs(K - differences(held, frames, step, MOORING)).max() / scale
        print(f"end stiffness on the slope ({end}) against differences {error:.3g}")
        assert error < 1e-6
        if "seabed_profile" in sea:     # its first midpoint grounded in the turn
            r = held.problem.state.node_positions()[1:2]
            if held.mesh.vertex_start == 0:
                seabed = held.scene.seabed
                assert seabed.gap(r)[0] < 0.0
                assert seabed.shape.slopes(r[:, 0], r[:, 1])[2][0] != 0.0
        elif clamped:             # its first vertex grounded
            second = held.centreline()
            if second is not None:
                seabed, r = held.scene.seabed, second[1:3] - held.origin
                assert seabed.gap(r[0]) < 0.0
        elif end == "flex":     # the pinned start: stiffness()'s 6 x 6 (after the
            # differences' re-solves, which move the state by round-off: 1.1e-12 on 2
            # ranks; an extensible clamp's stretch rule is not stiffness()'s)
            assert np.abs(K[:6, :6] - held.stiffness()).max() < 1e-10 * scale
    finally:
        held.destroy()


@pytest.mark.filterwarnings("error::RuntimeWarning")
@pytest.mark.parametrize("comm", list(COMMS))
@pytest.mark.parametrize("seabed", ["flat", "plane"])
def test_an_extensible_line_clamped_on_the_seabed_converges_from_either_start(comm, seabed):
    """The mooring as a single line (the Python API, as the command line runs it),
    extensible and clamped at its anchor pointing 0.3 down into the seabed: the clamp's
    stretch 1 + eps (EA eps = n.d3, docs/method.md §12) prescribed in the seabed's
    vertical problem as in the slope problem. Before, that problem kept z' = d3_z
    there: no fixed point, 2000 iterations per attempt, and the local step's stretch at
    the clamp reaching 0 (a division by zero in _stretch_clamps, then NaN). Now it
    converges from the catenary and from the straight start to the same state, the
    clamp's EA eps equal to n.d3 there."""
    line = UniformLine(length=100.0, stiffness=(50.0, 50.0, 50.0), load=(0, 0, -10.0),
                       elements=40, axial_stiffness=1e5)
    frame = dipping_frame(0.3)
    sea = SLOPE if seabed == "plane" else dict(seabed=SLOPE["seabed"])
    runs = {}
    for shape in ("catenary", "straight"):
        model = Model(line=line, start=End(kind="clamp", position=tuple(MOORING[0]),
                                           frame=tuple(frame.ravel())),
                      end=End.anchor(tuple(MOORING[1])), environment=Environment(**sea),
                      initial_shape=shape)
        runs[shape] = solve(model, comm=COMMS[comm])
        assert runs[shape].converged and runs[shape].scalars["halvings"] == 0, shape
        assert runs[shape].scalars["iterations"] < 200, shape
    first, second = runs["catenary"], runs["straight"]
    force = first.scalars["start_force"]
    assert force[0] > 50.0                                  # the chain pulls the anchor
    assert np.abs(second.scalars["start_force"] - force).max() < 1e-6 * np.abs(force).max()
    along = first.along_line(["axial_strain", "n"])
    stretch = 1e5 * along["axial_strain"][0]
    assert stretch == pytest.approx(along["n"][0] @ frame[2], rel=1e-6)
    assert stretch > 50.0


@pytest.mark.filterwarnings("error::RuntimeWarning")
@pytest.mark.parametrize("comm", list(COMMS))
def test_an_extensible_line_clamped_on_a_frictional_seabed_converges(comm):
    """The same single line clamped level at its anchor on the flat seabed with Coulomb
    friction: the friction's x and y Hermite problems prescribe the clamp's
    (1 + eps) d3 too (before, d3's x: 2000 iterations per attempt, not converged); the
    clamp's EA eps near n.d3 there."""
    line = UniformLine(length=100.0, stiffness=(50.0, 50.0, 50.0), load=(0, 0, -10.0),
                       elements=40, axial_stiffness=1e5)
    model = Model(line=line, start=End(kind="clamp", position=tuple(MOORING[0])),
                  end=End.anchor(tuple(MOORING[1])),
                  environment=Environment(seabed=SLOPE["seabed"], seabed_friction=0.5),
                  initial_shape="catenary", options=TIGHT)
    run = solve(model, comm=COMMS[comm])
    assert run.converged and run.scalars["halvings"] == 0
    assert run.scalars["iterations"] < 300
    along = run.along_line(["axial_strain", "n", "d3"])
    stretch = 1e5 * along["axial_strain"][0]
    print(f"EA eps {stretch:.10g} n.d3 {along['n'][0] @ along['d3'][0]:.10g} "
          f"{run.scalars['iterations']} iterations")
    # measured 2.0e-4 apart (1e-9 without the friction; not investigated)
    assert stretch == pytest.approx(along["n"][0] @ along["d3"][0], rel=1e-3)
    assert stretch > 10.0
