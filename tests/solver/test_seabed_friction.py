"""Coulomb friction of the seabed (physics/friction.py, docs/riser.md §3b) against closed
forms: a grounded line pulled along the seabed, whose tension falls by mu w per metre
from the pull toward the anchor (mobilised friction) and is 0 beyond the stick-slip
front; a line on an incline (the load tilted by theta on a flat seabed) that sticks for
tan(theta) < mu and slides for tan(theta) > mu with the anchor's tension of the sliding
block; a line lying along the contour of a sloping seabed held by friction with the
block's forces (friction in the seabed's tangent plane); the pulled line held at both
ends (the chord multiplier); the anchors' return map after each load step; the ellipse
of mu_axial and mu_lateral; a free start. One rank and two agree.
Serial and under mpiexec -n 2; bounds from measured runs (docs/riser.md §3b)."""

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import fitted_order, gather, make_solver
from petsc_rod.environment.bathymetry import Plane
from petsc_rod.environment.seabed import Friction, Seabed
from petsc_rod.io.outputs import vertex_fields

# 200 m of line of 100 N/m submerged weight, EI = 1 N m^2 (negligible), EA = 1e6 N, on a
# seabed of k = 1e6 N/m^2, pinned at the anchor (S = 0) and pulled at the free end by F
# along the seabed; mu = 0.5: mu w = 50 N/m, the front at S = L - F / (mu w) = 100 m.
WEIGHT, LENGTH, MU, PULL = 100.0, 200.0, 0.5, 5000.0
PULLED = dict(length=LENGTH, stiffness=(1.0, 1.0, 1.0), start="pin", end="free",
              end_force=np.array([PULL, 0.0, 0.0]), load_values=[[0.0, 0.0, -WEIGHT]],
              axial_stiffness=1e6)
# the penalty: the default (the pull's F / 2) leaves the friction's stick springs far
# stiffer than the global step and the iteration did not converge in 3000 (measured)
PENALTY = 1e6


def seabed(stiffness=1e5, mu=MU, shape=None):
    return Seabed(0.0, 1e6, shape, Friction(mu, mu, stiffness))


def solve(comm, n_elements, scene, rtol=1e-9, newton=False):
    """(report, gathered vertex fields with the terms' datasets, attributes)."""
    mesh, solver = make_solver(comm, n_elements, scene, PENALTY, rtol=rtol, ctol=rtol,
                               max_it=20000, newton=newton)
    try:
        solver.problem.state.set_straight()
        report = solver.solve_step(1.0)
        fields = vertex_fields(solver.problem)
        attributes = {}
        for output in solver.problem.outputs(fields):
            fields.update(output.datasets)
            attributes.update(output.attributes)
        whole = {key: gather(comm, value) for key, value in fields.items()
                 if np.ndim(value) and len(value) == len(fields["S"])}
        return report, whole, attributes
    finally:
        solver.destroy()
        solver.problem.destroy()
        mesh.destroy()


def pulled_error(stiffness, n_elements=200):
    """max |T - T_exact| / F along the pulled line, T_exact = max(F - mu w (L - S), 0),
    and the sliding length (exact: F / (mu w) = 100 m)."""
    report, fields, attributes = solve(PETSc.COMM_WORLD, n_elements,
                                       dict(PULLED, seabed=seabed(stiffness)))
    assert report.converged
    exact = np.maximum(PULL - MU * WEIGHT * (LENGTH - fields["S"]), 0.0)
    return (np.abs(fields["effective_tension"] - exact).max() / PULL,
            attributes["friction_slide_length"], attributes)


@pytest.fixture(scope="module")
def pulled_runs():
    return {k: pulled_error(k) for k in (1e5, 1e7)}


def test_pulled_line_tension_falls_by_mu_w(pulled_runs):
    """The tension falls by mu w per metre from the pull and is 0 beyond the front: to
    1.2 % of F with the stick stiffness 1e5 N/m^2 (mobilisation mu w / k_s = 0.5 mm) and
    0.12 % at 1e7; the sliding length 96.8 and 99.8 m against 100 (measured)."""
    error, slide, attributes = pulled_runs[1e5]
    assert error < 0.015
    assert abs(slide - 100.0) < 3.5
    error, slide, attributes = pulled_runs[1e7]
    assert error < 1.5e-3
    assert abs(slide - 100.0) < 0.3
    assert attributes["friction_max_use"] <= 1.0 + 1e-12   # the return map's
    assert abs(attributes["friction_max_force"] - MU * WEIGHT) < 1e-6 * MU * WEIGHT


def test_pulled_line_converges_as_the_stick_stiffens(pulled_runs):
    """The error is the stick's elastic zone at the front, of length sqrt(2 EA delta /
    mu w) with delta = mu w / k_s the mobilisation distance: order 1/2 in 1 / k_s
    (measured 0.50 over 1e5 to 1e7)."""
    errors = [pulled_runs[k][0] for k in (1e5, 1e7)]
    order = np.log(errors[0] / errors[1]) / np.log(100.0)
    assert 0.4 < order < 0.6


def test_pulled_line_says_how_its_sticking_part_depends_on_the_path(pulled_runs):
    """The path's numbers (FrictionTerm.path_numbers) of the pulled line at k_s = 1e5
    N/m^2, 200 elements: the 401 P2 nodes but the free end's lie on the seabed, those
    behind the stick-slip front (S < L - F / (mu w) = 100 m, the front 3.5 m on by the
    stick's elastic zone as above) stick, the others slide; the band mu R / k_s = mu w /
    k_s = 0.5 mm; the sticking node next to the front uses between exp(-h / (2 l)) and 1
    of its limit, the stick's displacement falling as exp((S - S_front) / l) with
    l = sqrt(EA / k_s) = 3.16 m (0.951 measured)."""
    attributes = pulled_runs[1e5][2]
    h = LENGTH / 200
    stick, slide = attributes["friction_stick_nodes"], attributes["friction_slide_nodes"]
    assert stick + slide == 400
    assert 2 * 100.0 / h <= stick <= 2 * 103.5 / h
    assert abs(attributes["friction_band"] - MU * WEIGHT / 1e5) < 1e-3 * MU * WEIGHT / 1e5
    assert np.exp(-h / (2 * np.sqrt(1e6 / 1e5))) < attributes["friction_stick_max_use"] < 1.0


INCLINE_LENGTH = 100.0


def tilted(theta_deg, mu=MU):
    """The line pinned at the origin, lying on a flat seabed along +x, under w tilted by
    theta toward +x: a block on an incline of theta (normal w cos theta, drive w sin
    theta)."""
    theta = np.radians(theta_deg)
    return dict(length=INCLINE_LENGTH, stiffness=(1.0, 1.0, 1.0), start="pin", end="free",
                load_values=[[WEIGHT * np.sin(theta), 0.0, -WEIGHT * np.cos(theta)]],
                axial_stiffness=1e6, seabed=seabed(1e6, mu))


@pytest.mark.parametrize("theta", [20.0, 35.0])
def test_line_on_an_incline_sticks_below_and_slides_above_mu(theta):
    """tan 20 deg = 0.36 < mu = 0.5: the whole line sticks, the anchor carries 1 % of the
    drive L w sin(theta) (the elastic zone near it: 1.1 % measured); tan 35 deg = 0.70 >
    mu: the line slides but for the anchor's node and the anchor carries L w (sin theta
    - mu cos theta) to 1 % (0.43 % measured)."""
    report, fields, attributes = solve(PETSc.COMM_WORLD, 100, tilted(theta))
    assert report.converged
    t = np.radians(theta)
    anchor = np.linalg.norm(fields["n"][0])
    drive = INCLINE_LENGTH * WEIGHT * np.sin(t)
    if np.tan(t) < MU:
        assert attributes["friction_slide_length"] < 0.02 * INCLINE_LENGTH
        assert anchor < 0.02 * drive
        # the path's numbers: every grounded node but the anchor's sticks, the block's
        # mobilisation tan(theta) / mu and band mu w cos(theta) / k_s (k_s = 1e6 N/m^2),
        # to 1e-3 (2e-4 and 6e-4 measured)
        assert attributes["friction_stick_nodes"] == 200
        assert attributes["friction_slide_nodes"] == 0
        assert abs(attributes["friction_stick_max_use"] / (np.tan(t) / MU) - 1) < 1e-3
        assert abs(attributes["friction_band"] / (MU * WEIGHT * np.cos(t) / 1e6) - 1) < 1e-3
    else:
        assert attributes["friction_stick_length"] < 0.05 * INCLINE_LENGTH
        exact = INCLINE_LENGTH * WEIGHT * (np.sin(t) - MU * np.cos(t))
        assert abs(anchor - exact) < 1e-2 * exact


def test_line_along_a_sloping_seabed_is_held_by_friction():
    """A line lying along the contour of a seabed rising at 10 deg across it (+y),
    pinned at one end, mu = 0.5 > tan 10 deg (EA = 1e6 N and EI = 100 N m^2: inextensible
    the iteration stalled at a constraint residual of 3e-9, and at EI = 1 N m^2 the pin's
    lateral reaction spreads over tens of metres and 3200 iterations, measured): it
    sticks; away from the pin (S > 20 m) and the free end the
    friction is the block's, w sin cos up the slope horizontally and w sin^2 upward, at
    a use tan(theta) / mu of the limit, and the line moves down the slope by no more
    than the mobilisation distance."""
    theta = np.radians(10.0)
    shape = Plane.sloping(np.zeros(2), 0.0, 10.0, np.array([0.0, 1.0]))
    scene = dict(length=INCLINE_LENGTH, stiffness=(100.0, 100.0, 100.0), start="pin",
                 end="free", load_values=[[0.0, 0.0, -WEIGHT]], axial_stiffness=1e6,
                 seabed=seabed(1e6, shape=shape))
    report, fields, attributes = solve(PETSc.COMM_WORLD, 100, scene)
    assert report.converged
    inner = (fields["S"] > 20.0) & (fields["S"] < INCLINE_LENGTH - 5.0)
    force = fields["friction_force"][inner]
    w = WEIGHT
    assert np.abs(force[:, 1] - w * np.sin(theta) * np.cos(theta)).max() < 1e-3 * w
    assert np.abs(force[:, 2] - w * np.sin(theta)**2).max() < 1e-3 * w
    assert np.abs(force[:, 0]).max() < 1e-3 * w
    assert np.all(fields["friction_state"][inner] == 1)
    use = np.linalg.norm(force, axis=1) / (MU * fields["seabed_reaction"][inner])
    assert np.abs(use - np.tan(theta) / MU).max() < 1e-3
    assert attributes["friction_max_use"] < 1.0
    assert np.abs(fields["r"][:, 1]).max() < MU * w / 1e6


def test_line_along_a_sloping_seabed_in_newton_steps():
    """The contour line above with Newton steps (friction's block in the tangent plane of
    a sloping plane, physics/friction.py): it takes them and converges in 23 iterations
    (741 without, measured), to the block's friction as above, and one rank and all
    ranks reach the same line to 1e-9 m and the same friction to 1e-6 w."""
    theta = np.radians(10.0)
    shape = Plane.sloping(np.zeros(2), 0.0, 10.0, np.array([0.0, 1.0]))
    scene = dict(length=INCLINE_LENGTH, stiffness=(100.0, 100.0, 100.0), start="pin",
                 end="free", load_values=[[0.0, 0.0, -WEIGHT]], axial_stiffness=1e6,
                 seabed=seabed(1e6, shape=shape))
    runs = [solve(comm, 40, scene, rtol=1e-10, newton=True)
            for comm in (PETSc.COMM_SELF, PETSc.COMM_WORLD)]
    w = WEIGHT
    for report, fields, attributes in runs:
        assert report.converged
        assert report.newton_steps > 0
        assert report.iterations < 100
        inner = (fields["S"] > 20.0) & (fields["S"] < INCLINE_LENGTH - 5.0)
        force = fields["friction_force"][inner]
        assert np.abs(force[:, 1] - w * np.sin(theta) * np.cos(theta)).max() < 1e-3 * w
        assert np.abs(force[:, 2] - w * np.sin(theta)**2).max() < 1e-3 * w
        assert np.all(fields["friction_state"][inner] == 1)
    (_, one, _), (_, all_, _) = runs
    assert np.abs(one["r"] - all_["r"]).max() < 1e-9
    assert np.abs(one["friction_force"] - all_["friction_force"]).max() < 1e-6 * w


@pytest.mark.parametrize("newton", [False, True], ids=["plain", "Newton"])
def test_one_rank_and_all_ranks_agree(newton):
    """The pulled line on PETSc.COMM_SELF and on COMM_WORLD (under mpiexec -n 2 the
    line split over the ranks), without and with Newton steps
    (tests/solver/test_friction_newton.py): the same tension and friction to the
    tolerance."""
    # rtol 1e-10. With Newton steps: at 1e-9 the schedule, which reads the change
    # against rtol without the deformation's size (7e-4 here), makes no attempt
    # (docs/stability.md, "No attempt on the pulled line"). Without: the plain
    # iteration's path through the stick-slip switches follows the round-off of the
    # global step's solves (which differ between one rank and the substructuring), and
    # at 1e-9 it stops with differences in the friction force of 0.8e-6 to 2.4e-6 of
    # mu W between the two (two orders of summation of the interface's Schur
    # complement); at 1e-10 1e-7 to 7e-7 (it stagnates near 1e-11)
    rtol = 1e-10
    runs = [solve(comm, 100, dict(PULLED, seabed=seabed()), rtol=rtol, newton=newton)
            for comm in (PETSc.COMM_SELF, PETSc.COMM_WORLD)]
    (report_one, one, a_one), (report_all, all_, a_all) = runs
    assert (report_one.newton_steps > 0) == newton
    assert (report_all.newton_steps > 0) == newton
    assert np.abs(one["effective_tension"] - all_["effective_tension"]).max() < 1e-6 * PULL
    assert np.abs(one["friction_force"] - all_["friction_force"]).max() < 1e-6 * MU * WEIGHT
    assert np.array_equal(one["friction_state"], all_["friction_state"])
    assert abs(a_one["friction_slide_length"] - a_all["friction_slide_length"]) < 1e-9


# The pulled line held at both ends: its end pinned 0.25 m beyond its length, the
# stretch int T / EA = T_L^2 / (2 mu w EA) = 0.25 m sets T_L = sqrt(2 mu w EA 0.25) =
# 5000 N, and the tension falls by mu w per metre toward the anchor as when pulled by a
# force (the chord multiplier carries the end's force in x).
STRETCHED = dict(PULLED, end="pin", end_position=np.array([LENGTH + 0.25, 0.0, 0.0]),
                 end_force=np.zeros(3))


def test_a_line_stretched_between_two_pins_has_the_pulled_line_s_tension():
    """To 1.2 % of T_L (the stick's elastic zone at the front, as pulled), the front
    within 3.5 m of S = 100 m."""
    report, fields, attributes = solve(PETSc.COMM_WORLD, 200,
                                       dict(STRETCHED, seabed=seabed(1e5)))
    assert report.converged
    exact = np.maximum(PULL - MU * WEIGHT * (LENGTH - fields["S"]), 0.0)
    assert np.abs(fields["effective_tension"] - exact).max() < 0.015 * PULL
    assert abs(attributes["friction_slide_length"] - 100.0) < 3.5


@pytest.mark.parametrize("steps", [1, 3])
def test_the_anchors_follow_the_return_map_at_each_step(steps):
    """After the last accepted step of a continuation of the stretched line, each
    anchor is x + f / k_s: the spring k_s (x - a) is the friction itself, so its size
    is at most R and equals R where the line slides; and 3 steps reach the 1 step's
    state (monotone loading)."""
    from helpers import continuation
    from petsc_rod.physics.friction import FrictionTerm, elliptic_norm

    scene = dict(STRETCHED, seabed=seabed(1e5))
    mesh, solver = make_solver(PETSc.COMM_WORLD, 100, scene, PENALTY, rtol=1e-9, ctol=1e-9,
                               max_it=20000, newton=False)
    try:
        report = continuation(solver, steps)
        assert report.converged
        term = next(t for t in solver.problem.terms if isinstance(t, FrictionTerm))
        spring = -term.friction.stiffness * (term.positions - term.anchors)
        size = elliptic_norm(spring, np.ones_like(spring) * [1.0, 0.0], term.friction)
        sliding = (term.reaction > 0) & ~term.stick
        assert np.all(size <= term.reaction * (1 + 1e-6) + 1e-9)
        assert np.all(np.abs(size[sliding] - term.reaction[sliding])
                      <= 1e-6 * term.reaction[sliding])
        assert PETSc.COMM_WORLD.tompi4py().allreduce(int(sliding.sum())) > 50
        r = gather(PETSc.COMM_WORLD, solver.problem.state.r.owned()[:, 0])
    finally:
        solver.destroy()
        solver.problem.destroy()
        mesh.destroy()
    _, fields, _ = solve(PETSc.COMM_WORLD, 100, scene)
    assert np.abs(r - fields["r"]).max() < 1e-6


@pytest.mark.parametrize("axis", ["axial", "lateral"])
def test_the_friction_ellipse_takes_mu_axial_along_the_line_and_mu_lateral_across(axis):
    """mu_a = 0.3 along the line, mu_l = 0.8 across it, the weight tilted by 35 deg
    (tan 35 = 0.70): along the line it slides with the anchor carrying L w (sin - mu_a
    cos) to 1 %; across it, it sticks with the friction at tan(35) / mu_l = 0.875 of its
    limit away from the pin."""
    theta = np.radians(35.0)
    w = WEIGHT
    drive = [w * np.sin(theta), 0.0] if axis == "axial" else [0.0, w * np.sin(theta)]
    scene = dict(tilted(35.0), load_values=[[*drive, -w * np.cos(theta)]],
                 seabed=Seabed(0.0, 1e6, None, Friction(0.3, 0.8, 1e6)))
    report, fields, attributes = solve(PETSc.COMM_WORLD, 100, scene)
    assert report.converged
    if axis == "axial":
        exact = INCLINE_LENGTH * w * (np.sin(theta) - 0.3 * np.cos(theta))
        assert abs(np.linalg.norm(fields["n"][0]) - exact) < 1e-2 * exact
        assert attributes["friction_stick_length"] < 0.05 * INCLINE_LENGTH
    else:
        inner = (fields["S"] > 20.0) & (fields["S"] < INCLINE_LENGTH - 5.0)
        use = (np.linalg.norm(fields["friction_force"][inner], axis=1)
               / (0.8 * fields["seabed_reaction"][inner]))
        assert np.abs(use - np.tan(theta) / 0.8).max() < 1e-2
        assert attributes["friction_slide_length"] < 0.02 * INCLINE_LENGTH


def test_a_free_start_pulled_from_a_held_end():
    """The tilted line of 35 deg held at its end instead (the start free, the drive
    toward the start): the end carries L w (sin - mu cos) to 1 %."""
    theta = np.radians(35.0)
    scene = dict(tilted(35.0), start="free", end="pin",
                 end_position=np.array([INCLINE_LENGTH, 0.0, 0.0]),
                 load_values=[[-WEIGHT * np.sin(theta), 0.0, -WEIGHT * np.cos(theta)]])
    report, fields, _ = solve(PETSc.COMM_WORLD, 100, scene)
    assert report.converged
    exact = INCLINE_LENGTH * WEIGHT * (np.sin(theta) - MU * np.cos(theta))
    assert abs(np.linalg.norm(fields["n"][-1]) - exact) < 1e-2 * exact
