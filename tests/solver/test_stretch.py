"""Axial stretch (docs/method.md §12): closed forms of extensible lines, the inextensible
limit, and the cost of a stiff EA, on one rank (PETSc.COMM_SELF) and on all ranks
(PETSc.COMM_WORLD: under ``mpiexec -n 2`` the 1-versus-2-ranks check).

(a) a bar pinned at both ends held beyond its length: eps = d/L - 1 everywhere and the
    tension EA eps from the chord's reaction, to round-off;
(b) a bar hanging under its own weight w per metre from a pin (or a clamp) at S = 0,
    free at S = L:
    eps(S) = w (L - S) / EA and the end displacement w L^2 / (2 EA); the discrete
    problem holds both exactly (the load's integral against the P2 basis is w_n F(S_n)
    at every node for a linear F), so the displacement is exact at every N;
(c) EA -> inf: EA = inf is the inextensible code path itself (nothing of stretch is
    built); EA = 1e14 on the unit cantilever agrees with it to round-off, and a
    catenary departs from the inextensible one by C / EA;
(d) a steel pipe (EA 1e10 N, EI 1e7 N m^2, 1 km between pins): the Uzawa iteration
    with stretch takes about as many iterations as without (Newton off in both);
(e) the elastic catenary against Irvine's closed form (validation/elastic_catenary.py):
    positions and horizontal tension, fourth order in h;
(f) the elastic catenary resting on a frictionless seabed: the suspended and the
    grounded profiles and the touchdown against the same closed form.
"""

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import CANTILEVER, destroy, fitted_order, gather, make_solver
from petsc_rod.io.outputs import vertex_fields
from petsc_rod.physics.stretch import AxialStretch
from petsc_rod.problem.penalty import default_penalty
from petsc_rod.scenes.scene import Scene
from petsc_rod.scenes.starts import catenary_start
from petsc_rod.validation.elastic_catenary import elastic_catenary

COMMS = {"one rank": PETSc.COMM_SELF, "all ranks": PETSc.COMM_WORLD}


def solve(comm, scene, n_elements, start="straight", steps=(1.0,), newton=False, tol=1e-12):
    """Solve ``scene`` (Scene keywords) at the default penalty on ``comm``; a dict of
    the reports, the gathered vertex fields, node S and strain, the energy and the
    AxialStretch term's outputs (None on an inextensible line)."""
    mesh, solver = make_solver(comm, n_elements, scene, default_penalty(Scene(**scene)),
                               tol, tol, 20000, newton=newton)
    try:
        problem = solver.problem
        if start == "catenary":
            problem.state.set_from_curve(catenary_start(problem.scene, steps[0]))
        else:
            problem.state.set_straight()
        reports = [solver.solve_step(t) for t in steps]
        fields = vertex_fields(problem)
        stretch = [term for term in problem.terms if isinstance(term, AxialStretch)]
        output = stretch[0].outputs(problem, fields) if stretch else None
        result = {key: gather(comm, fields[key]) for key in ("S", "r", "d3", "n")}
        result.update(reports=reports, energy=problem.energy(), output=output,
                      node_S=gather(comm, mesh.node_S()),
                      strain=gather(comm, problem.state.strain()),
                      plain=problem.axial is None and not stretch,
                      chord_multiplier=problem.state.chord_multiplier.copy())
        if output is not None:
            result.update({key: gather(comm, value)
                           for key, value in output.datasets.items()})
        return result
    finally:
        destroy(mesh, solver)


@pytest.fixture(scope="module", params=list(COMMS))
def comm(request):
    return COMMS[request.param]


# --- (a) a taut bar ----------------------------------------------------------------------
TAUT_EA = 1e4
TAUT_END = np.array([0.9, 0.5, 0.2])        # 1.0488 m from the origin: L = 1 is too short
TAUT = dict(length=1.0, stiffness=(1e-3, 1e-3, 1e-3), start="pin", end="pin",
            end_position=TAUT_END, axial_stiffness=TAUT_EA)


@pytest.fixture(scope="module")
def taut(comm):
    # two steps, both taut (ends 1.009 and 1.0488 m apart). At load factor 0.5 the pins
    # are 0.987 m apart: the straight bar in compression is a saddle, which the stability
    # test leaves, and the buckled bar (K = 1e-3 N m^2 against the taut line's default
    # R = 244 N) is not reached in 20000 iterations (test_stretch_newton.py (e))
    return solve(comm, TAUT, 16, steps=(0.75, 1.0))


def test_taut_bar_has_the_tension_of_its_stretch(taut):
    assert all(report.converged for report in taut["reports"])
    chord = np.linalg.norm(TAUT_END)
    strain = chord - 1.0
    tension = TAUT_EA * strain
    assert np.abs(taut["strain"] - strain).max() < 1e-11
    assert np.abs(taut["axial_tension"] - tension).max() < 1e-7 * tension
    # the reaction at the end pulls the bar back towards the origin: n = T e, e the chord
    assert np.abs(taut["n"] - tension * TAUT_END / chord).max() < 1e-7 * tension
    assert taut["output"].attributes["axial_tension_gap"] < 1e-9
    assert taut["output"].attributes["stretched_length"] == pytest.approx(chord, rel=1e-12)
    # straight: no bending energy, only EA L eps^2 / 2
    assert taut["energy"] == pytest.approx(0.5 * TAUT_EA * strain**2, rel=1e-9)
    assert np.abs(taut["r"][-1] - TAUT_END).max() < 1e-13


def test_taut_line_is_refused_only_when_inextensible():
    from petsc_rod.errors import RodInputError
    Scene(**TAUT).validate(set())
    with pytest.raises(RodInputError, match="inextensible"):
        Scene(**{**TAUT, "axial_stiffness": np.inf}).validate(set())
    with pytest.raises(RodInputError, match="positive"):
        Scene(**{**TAUT, "axial_stiffness": -1.0}).validate(set())


# --- (b) a bar hanging under its own weight ------------------------------------------------
HANG_EA, HANG_W = 100.0, 10.0
# bending negligible: the a3 |r''|^2 term puts a layer of width sqrt(K / 2EA) at the ends
HANGING = dict(length=1.0, stiffness=(1e-6, 1e-6, 1e-6), start="pin", end="free",
               load_values=[[HANG_W, 0.0, 0.0]], axial_stiffness=HANG_EA)
HANG_ELEMENTS = (10, 20, 40)


@pytest.fixture(scope="module", params=["pin", "clamp"])
def hanging(comm, request):
    scene = {**HANGING, "start": request.param}
    return request.param, {n: solve(comm, scene, n) for n in HANG_ELEMENTS}


def test_hanging_bar_end_displacement_is_exact(hanging):
    start, runs = hanging
    exact = HANG_W / (2 * HANG_EA)
    errors = []
    for n, run in runs.items():
        assert run["reports"][0].converged
        errors.append(abs(run["r"][-1, 0] - 1.0 - exact))
        assert np.abs(run["r"][:, 1:]).max() < 1e-14        # stays on its axis
    # pinned: exact at every N (observed 1e-15 relative), no order to fit; clamped: the
    # clamp's strain from the force balance (§12), observed 1.0e-8 relative at every N,
    # the bending layer's (without it, eps = 0 at the clamp node: 3.3e-2 at 10 elements)
    assert max(errors) < (1e-12 if start == "pin" else 1e-7) * exact


def test_hanging_bar_strain_is_linear(hanging):
    for n, run in hanging[1].items():
        exact = HANG_W * (1.0 - run["node_S"]) / HANG_EA
        # the bending layer at the ends moves eps by about w sqrt(K / 2EA) / EA (1e-6 of
        # the largest strain here), nothing else
        assert np.abs(run["strain"] - exact).max() < 2e-6 * exact.max()
        inner = (run["node_S"] > 0.1) & (run["node_S"] < 0.9)
        assert np.abs(run["strain"] - exact)[inner].max() < 1e-12


# --- (c) the inextensible limit ------------------------------------------------------------
def test_infinite_EA_is_the_inextensible_path(comm):
    plain = solve(comm, CANTILEVER, 32, newton=True)
    same = solve(comm, {**CANTILEVER, "axial_stiffness": np.inf}, 32, newton=True)
    assert plain["plain"] and same["plain"] and same["output"] is None
    assert np.array_equal(plain["r"], same["r"]) and plain["energy"] == same["energy"]
    assert plain["reports"][0].iterations == same["reports"][0].iterations
    stiff = solve(comm, {**CANTILEVER, "axial_stiffness": 1e14}, 32)
    assert not stiff["plain"]
    # P / EA = 3e-14: round-off
    assert np.abs(stiff["r"] - plain["r"]).max() < 1e-11


CATENARY = dict(length=1.0, stiffness=(1e-4, 1e-4, 1e-4), start="pin", end="pin",
                end_position=(0.8, 0.0, 0.1), load_values=[[0.0, 0.0, -1.0]])


def test_catenary_departs_from_inextensible_by_one_over_EA(comm):
    rigid = solve(comm, CATENARY, 40, start="catenary")
    scaled = [EA * np.abs(solve(comm, {**CATENARY, "axial_stiffness": EA}, 40,
                                start="catenary")["r"] - rigid["r"]).max()
              for EA in (1e4, 1e6)]
    # observed 0.34356 and 0.34360 (m N): the difference is C / EA
    assert scaled[0] > 0.1
    assert scaled[1] == pytest.approx(scaled[0], rel=1e-3)


# --- (d) a steel pipe: the cost of a stiff EA ----------------------------------------------
PIPE = dict(length=1000.0, stiffness=(1e7, 1e7, 7.7e6), start="pin", end="pin",
            end_position=(800.0, 0.0, 0.0), load_values=[[0.0, 0.0, -1000.0]])


@pytest.mark.slow
def test_stiff_EA_costs_few_more_iterations(comm):
    steps = (0.25, 0.5, 0.75, 1.0)
    rigid = solve(comm, PIPE, 200, steps=steps, tol=1e-9)
    steel = solve(comm, {**PIPE, "axial_stiffness": 1e10}, 200, steps=steps, tol=1e-9)
    counts = [sum(report.iterations for report in run["reports"]) for run in (rigid, steel)]
    assert all(report.converged for report in rigid["reports"] + steel["reports"])
    # observed (500 elements, docs/method.md §12): 184 and 183
    assert counts[1] <= 1.2 * counts[0] + 10
    # the pipe stretches by about w L / EA (6e-5) and the tension follows
    eps = steel["strain"]
    assert 1e-5 < eps.max() < 1e-4
    assert steel["output"].attributes["axial_tension_gap"] < 1e-3


# --- (e) Irvine's elastic catenary ---------------------------------------------------------
IRVINE_EA, IRVINE_END = 10.0, np.array([0.8, 0.0, 0.1])
IRVINE = dict(length=1.0, stiffness=(1e-12, 1e-12, 1e-12), start="pin", end="pin",
              end_position=IRVINE_END, load_values=[[0.0, 0.0, -1.0]],
              axial_stiffness=IRVINE_EA)
IRVINE_ELEMENTS = (20, 40, 80)


@pytest.fixture(scope="module")
def irvine(comm):
    return {n: solve(comm, IRVINE, n, start="catenary") for n in IRVINE_ELEMENTS}


def test_elastic_catenary_against_irvine(irvine):
    line = elastic_catenary(1.0, 1.0, IRVINE_EA, IRVINE_END[0], IRVINE_END[2],
                            on_seabed=False)
    H = line.H
    position_errors, tension_errors = [], []
    for n, run in irvine.items():
        assert run["reports"][0].converged
        x, z, _ = line.at(run["S"])
        exact = np.stack([x, z], axis=-1)
        position_errors.append(np.abs(run["r"][:, [0, 2]] - exact).max())
        tension_errors.append(abs(run["chord_multiplier"][0]) - H)
        # EA eps against the force balance's n.t, to the discretisation
        assert run["output"].attributes["axial_tension_gap"] < 1e-4
    tension_errors = np.abs(tension_errors)
    # observed 2.5e-7, 1.6e-8, 9.8e-10 (positions) and 1.9e-8, 1.2e-9, 6.6e-11 (H)
    assert fitted_order(IRVINE_ELEMENTS, position_errors) > 3.5
    assert fitted_order(IRVINE_ELEMENTS, tension_errors) > 3.5
    assert position_errors[-1] < 5e-9 and tension_errors[-1] < 5e-10 * H * 10


def test_one_rank_and_all_ranks_agree():
    """The elastic catenary on one rank and on all: the same state to the tolerance."""
    one, every = (solve(COMMS[name], IRVINE, 40, start="catenary") for name in COMMS)
    assert np.abs(one["r"] - every["r"]).max() < 1e-10
    assert np.abs(one["strain"] - every["strain"]).max() < 1e-10
    assert one["energy"] == pytest.approx(every["energy"], rel=1e-10)


# --- (f) the elastic catenary with touchdown ----------------------------------------------
# The grounded line of tests/solver/test_riser.py (10 m, 1 N/m, from an anchor on the
# seabed z = 0 to a pin at (7, 0, 4); EI 1e-6 N m^2, k = 1e6 N/m^2: a bending length of
# 1 mm and 1 micrometre of penetration) made extensible: EA = 100 N, 2 to 6 % stretch.
GROUNDED_EA, GROUNDED_END = 100.0, np.array([7.0, 0.0, 4.0])
ZONE = 1.0          # m kept clear of the touchdown's and the anchor's bending layers


def test_elastic_catenary_with_touchdown():
    from petsc_rod.environment.seabed import Seabed
    scene = dict(length=10.0, stiffness=(1e-6, 1e-6, 1e-6), start="pin", end="pin",
                 end_position=GROUNDED_END, load_values=[[0.0, 0.0, -1.0]],
                 seabed=Seabed(0.0, 1e6), axial_stiffness=GROUNDED_EA)
    line = elastic_catenary(10.0, 1.0, GROUNDED_EA, GROUNDED_END[0], GROUNDED_END[2])
    assert 3.0 < line.grounded < 6.0
    errors, tension_errors = [], []
    for n in (200, 400):
        run = solve(PETSc.COMM_WORLD, scene, n, start="catenary", tol=1e-11)
        assert run["reports"][0].converged
        S = run["S"]
        x, z, tension = line.at(S)
        away = (np.abs(S - line.grounded) > ZONE) & (S > ZONE)
        errors.append(max(np.abs(run["r"][away, 0] - x[away]).max(),
                          np.abs(run["r"][away, 2] - z[away]).max()))
        # both profiles: the grounded part stretched by H / EA, the suspended one hanging
        grounded = away & (S < line.grounded)
        assert grounded.sum() > 10 and (away & (S > line.grounded)).sum() > 10
        tension_errors.append(np.abs(run["axial_tension"][away] - tension[away]).max())
    # observed: positions 4.0e-5 and 5.6e-6 m (100 and 800 elements: 7.6e-5, 3.5e-6; the
    # touchdown falls inside an element), EA eps 3.6e-4 and 6.0e-5 H
    assert errors[1] < 1e-5 and errors[0] / errors[1] > 4.0
    assert tension_errors[1] < 1e-4 * line.H
