"""Essential and natural end conditions (docs/method.md §5) on 1 or several ranks.

For each combination of end kinds a small scene is solved from the straight state in one
step, and the prescribed values are checked to round-off at the vertex that carries them
(on whichever rank owns it; errors are reduced so every rank asserts the same numbers).
The recovered forces and moments are checked where the continuum says what they are:
n = the dead force at a free end (n(0) = -F at a free start, read from the FE reaction at
the other end), m = 0 at a pinned or free end, and the moment balance about the origin
(docs/method.md §9) m(0) = m(L) + r(L) x n(L) with no distributed load.

Every case converges to the default tolerances (change and RMS constraint residual
1e-9): with the constraint at the nodes the discrete constraint set is reached whatever
the ends hold.
"""

import numpy as np
import pytest

from helpers import gather, global_max
from petsc_rod.io import outputs
from petsc_rod.frames import rotation_about
from petsc_rod.scenes.scene import REFERENCE_FRAME

ROUND_OFF = 1e-12
LENGTH = 1.0
STIFFNESS = (1.0, 1.5, 0.8)
N_ELEMENTS = 24
PENALTY = 100.0
RTOL = CTOL = 1e-9
MAX_IT = 5000
END_ROTATION = rotation_about([1.0, 0.0, 0.0], 0.3)
ROTATED_FRAME = REFERENCE_FRAME @ END_ROTATION.T      # rows Q d_i

CASES = {
    "clamp-clamp": dict(start="clamp", end="clamp", end_frame=ROTATED_FRAME,
                        end_position=(0.9, 0.2, 0.1)),
    "clamp-pin": dict(start="clamp", end="pin", end_position=(0.8, 0.3, 0.0)),
    "clamp-free": dict(start="clamp", end="free", end_force=(0.0, -1.0, 0.5)),
    "pin-clamp": dict(start="pin", end="clamp", end_position=(0.8, 0.3, 0.0)),
    "free-clamp": dict(start="free", end="clamp", start_force=(0.0, -1.0, 0.5)),
}


@pytest.fixture(scope="module")
def solved():
    """Each case solved once (collectively, in the same order on every rank)."""
    from petsc4py import PETSc

    from helpers import make_solver

    comm = PETSc.COMM_WORLD
    results = {}
    for name, kwargs in CASES.items():
        scene_kwargs = dict(length=LENGTH, stiffness=STIFFNESS, **kwargs)
        mesh, solver = make_solver(comm, N_ELEMENTS, scene_kwargs, PENALTY, RTOL,
                                   CTOL, MAX_IT)
        try:
            solver.problem.state.set_straight()
            report = solver.solve_step(1.0)
            fields = outputs.vertex_fields(solver.problem)
            owned = {"r": solver.problem.state.r.owned(), "d1": solver.problem.state.d1.owned()[:, 0],
                     "d2": solver.problem.state.d2.owned()[:, 0]}
            results[name] = dict(
                report=report, scene=solver.problem.scene, comm=comm,
                lower=mesh.on_lower_boundary, upper=mesh.on_upper_boundary,
                owned=owned, fields={k: gather(comm, v) for k, v in fields.items()},
                end_frame=solver.problem.scene.end_state(1.0).frame)
        finally:
            solver.destroy()
            solver.problem.destroy()
            mesh.destroy()
    return results


def boundary_error(result, at_start, expected):
    """Max |value - expected| over the given (field, slot) pairs at one end, on the rank
    that owns that end, reduced over all ranks. ``expected`` maps a key to a 3-vector:
    "r", "r'" (Hermite slots 0, 1), "d1", "d2" (P2 vertex values)."""
    owned = result["owned"]
    mine = result["lower"] if at_start else result["upper"]
    error = 0.0
    if mine:
        row = 0 if at_start else -1
        values = {"r": owned["r"][row, 0], "r'": owned["r"][row, 1],
                  "d1": owned["d1"][row], "d2": owned["d2"][row]}
        for key, target in expected.items():
            error = max(error, np.abs(values[key] - np.asarray(target)).max())
    # exactly one rank holds each end: the others contribute 0
    assert result["comm"].tompi4py().allreduce(int(mine)) == 1
    return global_max(result["comm"], error)


@pytest.mark.parametrize("name", list(CASES))
def test_converges(solved, name):
    report = solved[name]["report"]
    assert report.converged, (name, report.iterations, report.change,
                              report.constraint_residual)
    assert report.change <= RTOL
    assert report.constraint_residual <= CTOL
    assert report.iterations < MAX_IT


@pytest.mark.parametrize("name", list(CASES))
def test_prescribed_values_hold_to_round_off(solved, name):
    result = solved[name]
    kwargs = CASES[name]
    start, end = kwargs["start"], kwargs["end"]
    e_x, e_y, e_z = np.eye(3)
    expected_start = {}
    if start in ("clamp", "pin"):
        expected_start["r"] = np.zeros(3)
    if start == "clamp":
        expected_start.update({"r'": e_x, "d1": e_y, "d2": e_z})
    expected_end = {}
    if end in ("clamp", "pin"):
        expected_end["r"] = np.asarray(kwargs.get("end_position", (LENGTH, 0.0, 0.0)), float)
    if end == "clamp":
        frame = result["end_frame"]
        expected_end.update({"r'": frame[2], "d1": frame[0], "d2": frame[1]})
    assert boundary_error(result, True, expected_start) < ROUND_OFF
    assert boundary_error(result, False, expected_end) < ROUND_OFF
    # and the unprescribed end really moved (the checks above are not vacuous)
    fields = result["fields"]
    if start == "free":
        assert np.linalg.norm(fields["r"][0]) > 0.1
    if end == "free":
        assert np.linalg.norm(fields["r"][-1] - [LENGTH, 0.0, 0.0]) > 0.1
    if start == "pin":
        assert np.linalg.norm(fields["d3"][0] - e_x) > 0.1
    if end == "pin":
        assert np.linalg.norm(fields["d3"][-1] - e_x) > 0.1


def test_end_frame_of_the_clamp_is_the_given_rotation(solved):
    """scene.end_state(1).frame (used above) is the frame the user asked for: the
    reference frame rotated by 0.3 rad about e_x, built here independently."""
    c, s = np.cos(0.3), np.sin(0.3)
    expected = np.array([[0.0, c, s], [0.0, -s, c], [1.0, 0.0, 0.0]])
    assert np.abs(solved["clamp-clamp"]["end_frame"] - expected).max() < ROUND_OFF
    for name in ("clamp-pin", "pin-clamp", "free-clamp"):
        assert np.abs(solved[name]["end_frame"] - REFERENCE_FRAME).max() < ROUND_OFF


def test_force_at_a_free_end(solved):
    force = np.array(CASES["clamp-free"]["end_force"])
    n = solved["clamp-free"]["fields"]["n"]
    assert np.abs(n[-1] - force).max() < ROUND_OFF
    # no distributed load: the contact force is the same all along
    assert np.abs(n - force).max() < ROUND_OFF


def test_force_at_a_free_start_from_the_reaction(solved):
    """n(S) is the force of the part beyond S on the part before it: at a free start
    loaded by F, n(0) = -F. The solver takes the reaction at the clamp S = L from the
    force balance, N = -(int f + F), which is the FE reaction of the r equation whatever
    the Uzawa iterate (the constant test function is in the space of r: tests/
    test_centreline.py compares it with the Hermite residual)."""
    force = np.array(CASES["free-clamp"]["start_force"])
    n = solved["free-clamp"]["fields"]["n"]
    assert np.abs(n[0] + force).max() < 1e-8
    assert np.abs(n[-1] + force).max() < 1e-8


@pytest.mark.parametrize("name, at_start", [("clamp-pin", False), ("pin-clamp", True),
                                            ("clamp-free", False), ("free-clamp", True)])
def test_moment_vanishes_at_a_pinned_or_free_end(solved, name, at_start):
    """|m(end)| / max |m| on 24 elements, measured: pins 9.0e-5, free ends 8.4e-7."""
    m = solved[name]["fields"]["m"]
    size = np.linalg.norm(m, axis=1)
    assert size.max() > 0.5
    end = size[0] if at_start else size[-1]
    bound = 2e-4 if "pin" in name else 2e-6
    assert end < bound * size.max()


@pytest.mark.parametrize("name", list(CASES))
def test_moment_balance_about_the_origin(solved, name):
    """m(0) = m(L) + (r(L) - r(0)) x n(L) without distributed load (docs/method.md §9).

    Measured |error| / max|m|: 1e-4 (free end) to 2.3e-3 (clamp-pin) on 24 elements; a
    sign error in the reaction or in the moment would give O(1).
    """
    fields = solved[name]["fields"]
    m, n, r = fields["m"], fields["n"], fields["r"]
    error = m[0] - m[-1] - np.cross(r[-1] - r[0], n[-1])
    scale = np.linalg.norm(m, axis=1).max()
    assert np.abs(error).max() < 1e-2 * scale
    assert np.linalg.norm(np.cross(r[-1] - r[0], n[-1])) > 0.1 * scale


# A clamp at S = 0 turned by 0.7 rad about (1, 2, 3) (-rod_start_frame), its d3 the
# cantilever's direction; a small tip force across it.
START_ROTATION = rotation_about(np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0), 0.7)
START_FRAME = REFERENCE_FRAME @ START_ROTATION.T


@pytest.mark.parametrize("steps", [1, 2])
def test_a_cantilever_clamped_along_a_given_start_frame(steps):
    """The cantilever clamped at S = 0 in the frame START_FRAME (K1 = K2 = 1 N m^2) under
    a tip force P d1' + 0.5 P d2' across its axis, |P| L^2 / EI = 1.1e-4: across d3' the
    tip is P L^3 / (3 EI) along the force (linear theory; geometric terms of relative
    order 1e-8), along d3' at L less the shortening |P|^2 L^5 / (15 EI^2), and the
    start's slope and directors are the frame's to round-off.
    Before, S = 0 could only be clamped along e_x."""
    from petsc4py import PETSc

    from helpers import destroy, make_solver

    force = 1e-4 * (START_FRAME[0] + 0.5 * START_FRAME[1])
    scene = dict(length=LENGTH, stiffness=(1.0, 1.0, 0.8), start="clamp", end="free",
                 start_frame=START_FRAME, end_force=force)
    comm = PETSc.COMM_WORLD
    mesh, solver = make_solver(comm, N_ELEMENTS, scene, PENALTY, 1e-12, 1e-12, MAX_IT)
    try:
        problem = solver.problem
        problem.state.set_straight()
        for k in range(1, steps + 1):
            assert solver.solve_step(k / steps).converged
        assert np.abs(problem.scene.start_state(1.0).frame - START_FRAME).max() < ROUND_OFF
        r = gather(comm, problem.state.r.owned()[:, 0])
        fields = outputs.vertex_fields(problem)
        d1, d2, d3 = (gather(comm, fields[name])[0] for name in ("d1", "d2", "d3"))
    finally:
        destroy(mesh, solver)
    axis, deflection = START_FRAME[2], force * LENGTH**3 / 3.0
    across = r[-1] - (r[-1] @ axis) * axis
    assert np.linalg.norm(across - deflection) < 1e-6 * np.linalg.norm(deflection)
    # and along it the length less the bent line's shortening, int w'^2 / 2 dS
    shortening = (force @ force) * LENGTH**5 / 15.0
    assert abs(r[-1] @ axis - (LENGTH - shortening)) < 1e-3 * shortening
    assert np.abs(np.array([d1, d2, d3]) - START_FRAME).max() < 1e-10
