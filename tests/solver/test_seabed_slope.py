"""A seabed that is not flat (environment/bathymetry.py, docs/riser.md §3a, §6): a line on a
sloping seabed against the catenary on an incline (validation/incline_catenary.py),
with its grounded part lying along the slope; a profile that equals the plane, or the
flat seabed where the line touches, gives their states; one rank and two agree.
Serial and under mpiexec -n 2; bounds from measured runs with a margin for round-off."""

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import fitted_order, gather, make_solver
from petsc_rod.environment.bathymetry import Grid, Plane, Profile
from petsc_rod.environment.seabed import Seabed
from petsc_rod.io.outputs import vertex_fields
from petsc_rod.iteration.stopping import Settings
from petsc_rod.problem.penalty import default_penalty
from petsc_rod.scenes.scene import Scene
from petsc_rod.validation.incline_catenary import incline_catenary

# 10 m of line of 1 N/m pinned on the seabed at the origin and at a top end; EI = 1e-6
# N m^2 and k = 1e6 N/m^2 make bending and penetration negligible, as for the flat
# seabed's catenary with touchdown (tests/solver/test_riser.py).
LINE = dict(length=10.0, stiffness=(1e-6, 1e-6, 1e-6), start="pin", end="pin",
            load_values=[[0.0, 0.0, -1.0]])
# (slope deg along +x, top end): rising toward the top (5.30 m grounded, anchor tension
# 1.07 N) and falling toward it (3.86 m grounded, 2.05 N)
INCLINES = {"up 5 deg": (5.0, (8.0, 0.0, 4.0)), "down 10 deg": (-10.0, (7.0, 0.0, 4.0))}


def plane(deg, azimuth=0.0):
    """The plane z = tan(deg) d through the origin, d along the azimuth (deg)."""
    e = np.array([np.cos(np.radians(azimuth)), np.sin(np.radians(azimuth))])
    return Plane.sloping(np.zeros(2), 0.0, deg, e)


def solve(comm, n_elements, scene, rtol=1e-12, newton=False, max_it=20000):
    """(report, gathered vertex fields with the riser numbers, numbers, energy)."""
    mesh, solver = make_solver(comm, n_elements, scene, default_penalty(Scene(**scene)),
                               rtol=rtol, ctol=rtol, max_it=max_it, newton=newton)
    try:
        solver.problem.state.set_straight()
        report = solver.solve_step(1.0)
        fields = vertex_fields(solver.problem)
        outputs = [o for o in solver.problem.outputs(fields)]
        numbers = {}
        for output in outputs:
            fields.update(output.datasets)
            numbers.update(output.attributes)
        whole = {key: gather(comm, value) for key, value in fields.items()
                 if np.ndim(value) and len(value) == len(fields["S"])}
        return report, whole, numbers, solver.problem.energy()
    finally:
        solver.destroy()
        solver.problem.destroy()
        mesh.destroy()


def incline_errors(case, n_elements):
    """Errors against the incline catenary away from the touchdown zone (|S - S_td| >
    1 m) and the anchor (S > 0.5 m): r, n, and the tension along the grounded part."""
    deg, top = INCLINES[case]
    scene = dict(LINE, end_position=np.array(top), seabed=Seabed(0.0, 1e6, plane(deg)))
    report, fields, numbers, _ = solve(PETSc.COMM_WORLD, n_elements, scene)
    assert report.converged
    exact = incline_catenary(10.0, 1.0, np.radians(deg), top[0], top[2])
    S, r, n = fields["S"], fields["r"], fields["n"]
    x, z, force, tension = exact.at(S)
    away = (np.abs(S - exact.grounded) > 1.0) & (S > 0.5)
    grounded = away & (S < exact.grounded)
    return dict(r=np.hypot(r[:, 0] - x, r[:, 2] - z)[away].max(),
                n=np.hypot(n[:, 0] - force[:, 0], n[:, 2] - force[:, 1])[away].max(),
                lateral=np.abs(r[:, 1]).max(),
                ground=np.abs(fields["effective_tension"] - tension)[grounded].max(),
                gap=np.abs(r[grounded, 2] - np.tan(np.radians(deg)) * r[grounded, 0]).max(),
                bed=np.abs(fields["seabed_height"] - np.tan(np.radians(deg)) * r[:, 0]).max(),
                exact=exact, numbers=numbers, iterations=report.iterations,
                h=10.0 / n_elements)


@pytest.fixture(scope="module")
def incline_runs():
    return {case: {n: incline_errors(case, n) for n in (40, 80, 160)} for case in INCLINES}


@pytest.mark.parametrize("case", list(INCLINES))
def test_a_line_on_an_incline_against_the_catenary_on_an_incline(incline_runs, case):
    """Measured (r m, n N at 40 / 80 / 160 elements): up 5 deg 2.4e-4 / 4.5e-5 / 3.8e-6 and
    1.8e-3 / 4.1e-4 / 2.8e-5; down 10 deg 3.2e-4 / 1.0e-4 / 9.9e-7 and 1.4e-3 / 4.3e-4 /
    1.6e-6 (the touchdown point resolved to a node, as on the flat seabed)."""
    runs = incline_runs[case]
    assert runs[40]["r"] < 4e-4 and runs[40]["n"] < 2.5e-3
    assert runs[160]["r"] < 1e-5 and runs[160]["n"] < 5e-5
    elements = list(runs)
    assert fitted_order(elements, [runs[n]["r"] for n in elements]) > 1.5
    assert fitted_order(elements, [runs[n]["n"] for n in elements]) > 1.5
    for run in runs.values():
        assert run["lateral"] == 0.0            # a slope along the plane of the ends


@pytest.mark.parametrize("case", list(INCLINES))
def test_the_grounded_part_lies_along_the_slope(incline_runs, case):
    """Along the grounded part the line lies on the incline (within w / k = 1e-6 m), its
    tension changes by w sin(alpha) per metre (frictionless: the slope's share of the
    weight, T(0) 1.07 N up 5 deg, 2.05 N down 10 deg); the riser numbers find the
    touchdown within an element and the grounded length along the slope."""
    for run in incline_runs[case].values():
        assert run["gap"] < 3e-6
        assert run["ground"] < 1e-9 + 2 * run["n"]
        assert run["bed"] < 1e-14                # the seabed_height dataset: z_b(x, y)
        numbers, exact = run["numbers"], run["exact"]
        assert abs(numbers["touchdown_S"] - exact.grounded) < run["h"]
        assert abs(numbers["grounded_length"] - exact.grounded) < run["h"]
        deg = INCLINES[case][0]
        position = numbers["touchdown_position"]
        assert abs(position[2] - np.tan(np.radians(deg)) * position[0]) < 1e-5


def test_a_profile_that_is_the_plane_gives_the_plane():
    """Two rows on the 5 degree plane: the same state (to round-off of the heights)."""
    deg, top = INCLINES["up 5 deg"]
    t = np.tan(np.radians(deg))
    profile = Profile(np.zeros(2), np.array([1.0, 0.0]), np.array([-5.0, 3.0, 20.0]),
                      np.array([-5.0, 3.0, 20.0]) * t)
    states = []
    for shape in (plane(deg), profile):
        scene = dict(LINE, end_position=np.array(top), seabed=Seabed(0.0, 1e6, shape))
        report, fields, numbers, energy = solve(PETSc.COMM_WORLD, 40, scene)
        assert report.converged
        states.append((fields, numbers, energy))
    (a, na, ea), (b, nb, eb) = states
    assert np.abs(a["r"] - b["r"]).max() < 1e-9
    assert np.abs(a["n"] - b["n"]).max() < 1e-8
    assert na["touchdown_S"] == pytest.approx(nb["touchdown_S"], abs=1e-9)


def test_a_profile_flat_where_the_line_touches_gives_the_flat_seabed():
    """A profile flat up to 6 m from the anchor and rising steeply beyond, under the line
    of the flat seabed's catenary with touchdown (grounded 5.5 m, 7 m span, 4 m up; the
    suspended part clears the rise): the flat seabed's state, to 1e-9."""
    profile = Profile(np.zeros(2), np.array([1.0, 0.0]), np.array([-1.0, 6.0, 7.0]),
                      np.array([0.0, 0.0, 0.5]))
    states = []
    for seabed in (Seabed(0.0, 1e6), Seabed(0.0, 1e6, profile)):
        scene = dict(LINE, end_position=np.array([7.0, 0.0, 4.0]), seabed=seabed)
        report, fields, numbers, _ = solve(PETSc.COMM_WORLD, 40, scene)
        assert report.converged
        states.append((fields, numbers))
    (a, na), (b, nb) = states
    assert np.abs(a["r"] - b["r"]).max() < 1e-9
    assert np.abs(a["n"] - b["n"]).max() < 1e-9
    assert na["grounded_length"] == pytest.approx(nb["grounded_length"], abs=1e-9)


# a 50 m line with bending stiffness (test_riser.py's RISER without its current) on a
# 4 degree slope rising at azimuth 60 deg, across the plane of its ends: the grounded
# part is pushed sideways down the slope (207 iterations on 100 elements)
ACROSS = dict(length=50.0, stiffness=(20.0, 20.0, 15.0), start="pin", end="pin",
              end_position=(35.0, 3.0, 20.0), load_values=[[0.0, 0.0, -1.0]],
              seabed=Seabed(0.0, 1e3, plane(4.0, azimuth=60.0)))


def test_one_rank_and_two_give_the_same_line_on_a_cross_slope():
    """COMM_SELF against COMM_WORLD (2 ranks under mpiexec -n 2): the same state, riser
    numbers and energy to the iteration's tolerance."""
    one = solve(PETSc.COMM_SELF, 100, ACROSS, rtol=1e-11)
    every = solve(PETSc.COMM_WORLD, 100, ACROSS, rtol=1e-11)
    (report_1, fields_1, numbers_1, energy_1), (report_n, fields_n, numbers_n, energy_n) = (
        one, every)
    assert report_1.converged and report_n.converged
    assert report_n.iterations == pytest.approx(report_1.iterations, rel=0.1)
    lateral = fields_1["r"][:, 1] - 3.0 / 35.0 * fields_1["r"][:, 0]
    assert np.abs(lateral).max() > 0.01          # it does leave the plane of its ends
    for key in ("r", "d3", "n", "effective_tension", "seabed_reaction", "seabed_height"):
        scale = max(1.0, np.abs(fields_1[key]).max())
        assert np.abs(fields_1[key] - fields_n[key]).max() < 1e-8 * scale, key
    for key in ("top_tension", "top_angle", "touchdown_S", "grounded_length"):
        assert numbers_1[key] == pytest.approx(numbers_n[key], rel=1e-8, abs=1e-8), key
    assert energy_1 == pytest.approx(energy_n, rel=1e-9)


def across_grid(bump=0.0):
    """ACROSS's plane sampled on a grid of 5 m cells over the line's footprint, plus a
    hump of ``bump`` m (0 at the anchor) centred under the grounded part: a Grid."""
    xs, ys = np.linspace(-5.0, 45.0, 11), np.linspace(-10.0, 15.0, 6)
    x, y = np.meshgrid(xs, ys, indexing="ij")
    hump = bump * np.exp(-((x - 10.0) / 8.0)**2 - ((y - 2.0) / 6.0)**2)
    hump[(x == 0.0) & (y == 0.0)] = 0.0
    return Grid(np.zeros(2), xs, ys, ACROSS["seabed"].shape.height(x, y) + hump)


def test_a_grid_converges_in_newton_steps_with_the_default_tolerances():
    """ACROSS's line (its 4 degree plane across the ends' plane, a soft sideways mode)
    on that plane given as a grid, from the straight start with the default settings
    (Settings: rtol = ctol = 1e-9, Newton steps on): it ends in Newton steps (52
    iterations, 5 of them Newton) at the plane's state, solved to 1e-13, within 1e-10 m
    (measured 7e-15 m on 1 rank, 1.1e-12 m on 2). Where a grid took no Newton steps
    (the lagged push alone) it took 186 iterations and ended 9.4e-9 m off the plane's.
    On a grid that is not a plane (a 0.3 m hump under the grounded part, 0.51 m of
    sideways shift) the Newton steps' state is the lagged iteration's fixed point
    (solved without them to 1e-13: 255 iterations) within 1e-7 m (measured 1.8e-12 m
    on 1 rank, 6.0e-8 m on 2, docs/riser.md §3a)."""
    defaults = Settings(asked_penalty=0.0)
    plane_scene = dict(ACROSS)
    plane = solve(PETSc.COMM_WORLD, 100, plane_scene, rtol=1e-13, newton=True)
    states = {}
    for name, bump, newton, rtol in (("grid", 0.0, True, defaults.rtol),
                                     ("hump", 0.3, True, defaults.rtol),
                                     ("lagged", 0.3, False, 1e-13)):
        scene = dict(ACROSS, seabed=Seabed(0.0, 1e3, across_grid(bump)))
        states[name] = solve(PETSc.COMM_WORLD, 100, scene, rtol=rtol, newton=newton,
                             max_it=defaults.max_it)
    for name in ("grid", "hump"):
        report = states[name][0]
        assert report.converged and report.newton_steps > 0, name
        assert report.iterations < 80, name
    assert np.abs(states["grid"][1]["r"] - plane[1]["r"]).max() < 1e-10
    assert np.abs(states["hump"][1]["r"] - states["lagged"][1]["r"]).max() < 1e-7
    assert np.abs(states["hump"][1]["r"] - plane[1]["r"]).max() > 0.1
