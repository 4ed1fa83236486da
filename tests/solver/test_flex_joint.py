"""Flex joints (physics/flex_joint.py, docs/method.md §5): a rotational spring of
stiffness k at a pinned end, moment k theta, against closed forms and the pin and clamp
limits, on the ranks pytest runs on (1 and 2: scripts/test.sh).

(a) a cantilever whose root is a flex joint, under a tip couple M: the root turns by M/k,
    then a circular arc of curvature M/EI (exact, large rotations);
(b) a small tip force P: tip deflection P L^3 / (3 EI) + P L^2 / k (linear theory), with
    Newton steps and the stability test (the joint's gradient and Hessian);
(c) k -> 0 gives the pinned answer, k -> large the clamped one.
"""

import numpy as np
import pytest

from helpers import gather
from petsc_rod.iteration.driver import UzawaSolver
from petsc_rod.iteration.stopping import Settings
from petsc_rod.mesh.mesh import Mesh
from petsc_rod.physics.flex_joint import FlexJoint, curvature_factor, slope_factor
from petsc_rod.physics.term import Term
from petsc_rod.problem.build import scene_terms
from petsc_rod.problem.problem import RodProblem
from petsc_rod.scenes.scene import Scene

LENGTH, EI = 1.0, 1.0
STIFFNESS = (EI, EI, 0.7)
ELEMENTS = 32
PENALTY = 50.0


class TipCouple(Term):
    """A dead couple M e_z at the free end S = L, for a planar rod: work M phi, phi the
    angle of d3 in the xy plane, so the slope's right-hand side at the end node gets
    -dE/dd3 = M (-t_y, t_x, 0) / (t_x^2 + t_y^2) at the iterate's t = tau3 (lagged, like a
    follower load: no energy given, so no Newton and no stability test), scaled by the
    load factor."""

    conservative = in_newton = False

    def __init__(self, mesh, moment):
        self.moment, self.t = moment, 0.0
        self.node = mesh.n_local_nodes - 1 if mesh.on_upper_boundary else None

    def prepare(self, t, start, end):
        self.t = t

    def add_iterate_load(self, rhs, state):
        if self.node is None:
            return
        t = state.tau[self.node, 2]
        load = self.t * self.moment * np.array([-t[1], t[0], 0.0]) / (t[0]**2 + t[1]**2)
        for c, vec in enumerate(rhs.components):
            vec.getArray()[self.node] += load[c]


def solve(comm, scene_kwargs, extra_terms=(), newton=True, steps=1, elements=ELEMENTS):
    """(report, vertex positions (N + 1, 3), the joints' (angle deg, moment N m)) of the
    scene, from the straight state to load factor 1 in ``steps`` equal steps; Newton
    steps and the stability test only where every term allows them."""
    scene = Scene(length=LENGTH, stiffness=STIFFNESS, **scene_kwargs)
    mesh = Mesh(comm, elements, scene.length)
    terms = scene_terms(mesh, scene) + [make(mesh) for make in extra_terms]
    problem = RodProblem(mesh, scene, PENALTY, terms)
    exact = not extra_terms
    solver = UzawaSolver(problem, Settings(asked_penalty=PENALTY, rtol=1e-11, ctol=1e-11,
                                           max_it=5000, newton=newton and exact,
                                           check_stability=exact))
    try:
        problem.state.set_straight()
        for k in range(1, steps + 1):
            report = solver.solve_step(k / steps)
            assert report.converged, report.reason
        r = gather(comm, problem.state.r.owned()[:, 0])
        joints = [term.angle_and_moment(problem.state) for term in problem.terms
                  if isinstance(term, FlexJoint)]
        return report, r, joints
    finally:
        solver.destroy()
        problem.destroy()
        mesh.destroy()


def test_series_and_closed_forms_of_the_joint_factors_agree():
    for theta in (0.5e-4, 1.5e-4, 0.3, 2.0):
        assert slope_factor(theta) == pytest.approx(theta / np.sin(theta), rel=1e-12)
        exact = (np.sin(theta) - theta * np.cos(theta)) / np.sin(theta)**3
        assert curvature_factor(theta) == pytest.approx(exact, rel=1e-6)


@pytest.mark.parametrize("axial", [np.inf, 1e8], ids=["inextensible", "EA 1e8"])
@pytest.mark.parametrize("k", [1.0, 0.5])
def test_a_tip_couple_turns_the_root_by_m_over_k_then_bends_an_arc(comm, k, axial):
    """Root angle p = M/k (0.5 and 1 rad), then curvature M/EI: tip = ((sin(p + ML/EI) -
    sin p), (cos p - cos(p + ML/EI))) EI/M; the joint reports angle M/k and moment M.
    With EA = 1e8 N (the joint in the local step of an extensible end, docs/method.md
    §12) the same to O(1/EA) and the iteration's tolerance."""
    moment = 0.5
    report, r, joints = solve(comm, dict(start="pin", end="free",
                                         start_rotational_stiffness=k, axial_stiffness=axial),
                              [lambda mesh: TipCouple(mesh, moment)], steps=2)
    p, kappa = moment / k, moment / EI
    tip = np.array([np.sin(p + kappa * LENGTH) - np.sin(p),
                    np.cos(p) - np.cos(p + kappa * LENGTH), 0.0]) / kappa
    assert np.linalg.norm(r[-1] - tip) < 1e-6 * LENGTH, (r[-1], tip)
    angle, joint_moment = joints[0]
    assert angle == pytest.approx(np.degrees(p), rel=1e-6)
    assert joint_moment == pytest.approx(moment, rel=1e-6)


@pytest.mark.parametrize("elements", [ELEMENTS, 2])
@pytest.mark.parametrize("which", ["start", "end"])
@pytest.mark.parametrize("k", [1.0, 10.0, 1000.0])
def test_a_small_tip_force_deflects_as_linear_theory_says(comm, k, which, elements):
    """delta = P L^3 / (3 EI) + P L^2 / k at P L^2 / EI = 1e-4, the joint at S = 0 (the
    force at S = L) or at S = L (the force at a free start); geometric nonlinearity is of
    relative order (P L^2 / EI)^2 and the P2 slope is exact for the cubic, so the
    relative error is below 1e-6, on 2 elements too (on 2 ranks the rank of S = L then
    owns no element: the joint's matrix entry comes from the other). Newton steps are
    taken (the joint's gradient and Hessian) and the equilibrium is found stable (its
    second variation)."""
    force = 1e-4
    if which == "start":
        scene = dict(start="pin", end="free", end_force=(0.0, -force, 0.0),
                     start_rotational_stiffness=k)
    else:
        scene = dict(start="free", end="pin", start_force=(0.0, -force, 0.0),
                     end_rotational_stiffness=k)
    report, r, joints = solve(comm, scene, elements=elements)
    tip = r[-1] if which == "start" else r[0]
    expected = force * LENGTH**3 / (3 * EI) + force * LENGTH**2 / k
    assert abs(-tip[1] - expected) < 1e-6 * expected, (-tip[1], expected)
    assert report.stable is True
    assert report.newton_steps > 0 or elements == 2     # 2 elements converge before
    angle, moment = joints[0]
    assert moment == pytest.approx(force * LENGTH, rel=1e-6)        # M = P L at the joint
    assert np.radians(angle) == pytest.approx(force * LENGTH / k, rel=1e-6)


# A tip force at 45 degrees to the straight rod: pinned, the rod turns to lie along it;
# clamped, it bends (a large deflection).
OBLIQUE = dict(end="free", end_force=(0.5, -0.5, 0.0))


def test_a_soft_joint_gives_the_pinned_answer_and_a_stiff_one_the_clamped(comm):
    pinned = solve(comm, dict(OBLIQUE, start="pin"))[1]
    clamped = solve(comm, dict(OBLIQUE, start="clamp"))[1]
    soft = solve(comm, dict(OBLIQUE, start="pin", start_rotational_stiffness=1e-6))[1]
    stiff = solve(comm, dict(OBLIQUE, start="pin", start_rotational_stiffness=1e6))[1]
    along = LENGTH * np.array([1.0, -1.0, 0.0]) / np.sqrt(2)
    assert np.abs(pinned[-1] - along).max() < 1e-8 * LENGTH      # the pin: straight along P
    assert np.abs(pinned - clamped).max() > 0.1 * LENGTH          # the two limits differ
    assert np.abs(soft - pinned).max() < 1e-5 * LENGTH
    assert np.abs(stiff - clamped).max() < 1e-5 * LENGTH


def test_a_joint_axis_off_the_reference_holds_the_root_along_it(comm):
    """A stiff joint whose neutral axis is tilted by 0.3 rad in the xy plane, no load:
    the rod lies straight along the axis."""
    axis = np.array([np.cos(0.3), np.sin(0.3), 0.0])
    report, r, joints = solve(comm, dict(start="pin", end="free", end_force=(0, 0, 0),
                                         start_rotational_stiffness=10.0,
                                         start_joint_axis=axis), steps=2)
    assert np.abs(r[-1] - LENGTH * axis).max() < 1e-8
    assert joints[0][0] < 1e-6


@pytest.mark.parametrize("k, force, steps", [(1.0, (0.0, -1.0, 0.0), 1),
                                             (0.2, (-1.0, -1.0, 0.0), 8)])
def test_the_joint_carries_k_theta_at_large_turns(comm, k, force, steps):
    """Moment balance about the pin, exact at any rotation: k theta = |r(L) x P| (no
    other load). The root turns by 37 and 112 degrees: a law k sin theta (the
    quadratic alone) would be off by 8 % and 13 %."""
    report, r, joints = solve(comm, dict(start="pin", end="free", end_force=force,
                                         start_rotational_stiffness=k), steps=steps)
    angle, moment = joints[0]
    assert angle > 30
    assert moment == pytest.approx(k * np.radians(angle), rel=1e-12)
    assert moment == pytest.approx(abs(np.cross(r[-1], force)[2]), rel=1e-8)
    assert report.stable is True


@pytest.mark.parametrize("seabed_height, touches", [(-10.0, False), (-0.08, True)])
def test_the_joint_acts_through_the_seabeds_vertical_problem(comm, seabed_height, touches):
    """With a seabed the z slope is solved in Hermite dofs from the slope's element
    matrices (physics/seabed.py), which carry the joint's k. Far below the line (no
    contact) the seabed changes nothing: the same shape as without it, the joint at
    S = L loaded in the vertical plane by a neutral axis e_z; touched, the line differs
    and the joint still carries k theta."""
    from petsc_rod.environment.seabed import Seabed

    k = 0.05
    scene = dict(start="pin", end="pin", end_position=(0.7, 0.0, 0.3),
                 load_values=[(0.0, 0.0, -1.0)], end_rotational_stiffness=k,
                 end_joint_axis=(0.0, 0.0, 1.0))
    # 4 steps: in 2 the first (t = 0.5) of the bare line stagnates at a constraint
    # residual of 0.14, and in 3 the first (t = 1/3) with the seabed 0.08 m below did at
    # 0.094 on 2 ranks of another machine (docs/stability.md, "Stagnations that depend
    # on round-off")
    bare = solve(comm, scene, steps=4)
    with_seabed = solve(comm, dict(scene, seabed=Seabed(seabed_height, 1e3)), steps=4)
    angle, moment = with_seabed[2][0]
    assert bare[2][0][0] > 5                                    # the joint is turned
    assert moment == pytest.approx(k * np.radians(angle), rel=1e-12)
    difference = np.abs(with_seabed[1] - bare[1]).max()
    if touches:
        assert difference > 1e-3 and with_seabed[1][:, 2].min() < seabed_height + 1e-2
    else:
        assert difference < 1e-8
        assert angle == pytest.approx(bare[2][0][0], rel=1e-7)


def test_one_rank_and_all_ranks_agree(comm):
    """(d) The joint at a large turn (112 degrees, both joints' code paths: the start's
    matrix entry and node on the first rank, a free end on the last) on the ranks
    pytest runs on and, on each rank, alone (PETSc.COMM_SELF): the same shape and joint
    to the iteration's tolerance."""
    from petsc4py import PETSc

    scene = dict(start="pin", end="free", end_force=(-1.0, -1.0, 0.0),
                 start_rotational_stiffness=0.2)
    together = solve(comm, scene, steps=8)
    alone = solve(PETSc.COMM_SELF, scene, steps=8)
    assert np.abs(together[1] - alone[1]).max() < 1e-9
    assert together[2][0][0] == pytest.approx(alone[2][0][0], rel=1e-9)


# An inextensible line between pins with flex joints at both ends, at a state away from
# any solution; the joints' axes far from the end tangents (about 40 and 60 degrees), so
# that both parts of the block, k f''(c) v v^T and k beta (I - d d^T), are of the size of
# the bending's.
FD_JOINTS = dict(length=1.0, stiffness=(1e-2, 2e-2, 1.5e-2), load_values=[[0.0, 0.3, -1.0]],
                 start="pin", end="pin", end_position=(0.8, 0.0, 0.1),
                 start_rotational_stiffness=0.05, start_joint_axis=(0.6, 0.0, -0.8),
                 end_rotational_stiffness=0.08, end_joint_axis=(0.0, 0.6, 0.8))


def turn(omega):
    """The step (n, 4) of NewtonSolver._stretched that turns the frames by omega (n, 3)
    and leaves their stretch."""
    return np.column_stack([omega, np.zeros(len(omega))])


def test_the_inextensible_joints_hessian_against_finite_differences(comm):
    """The inextensible joint's gradient and Hessian block (add_gradient, add_hessian in
    the global step's branch, FlexJoint.local False) against central differences of the
    Lagrangian F + mu.c along frames -> exp(s [omega]x) frames (as
    test_stretch_newton (a) checks the extensible branch): the second difference to
    1e-6 of the quadratic form. A block without k f''(c) v v^T, without
    k beta (I - d d^T), with beta's 1 - c or its theta / sin theta dropped fails it."""
    from helpers import destroy, make_solver
    from petsc_rod.iteration.newton import NewtonSolver
    from petsc_rod.scenes.starts import catenary_start
    from test_stretch_newton import lagrangian

    mesh, solver = make_solver(comm, 12, FD_JOINTS, 5.0, newton=False)
    problem = solver.problem
    joints = [term for term in problem.terms if isinstance(term, FlexJoint)]
    assert len(joints) == 2 and not any(term.local for term in joints)
    polish = NewtonSolver(problem)
    work = problem.field_stiffness(0)[1].createVecLeft()
    x = y = None
    try:
        state = problem.state
        problem.prepare(1.0)
        state.set_from_curve(catenary_start(problem.scene, 1.0))
        n = mesh.n_local_nodes
        # the same random numbers at a node on any number of ranks
        nodes = 2 * mesh.vertex_start + np.arange(n)
        random = np.array([np.random.default_rng(2000 + i).standard_normal(9)
                           for i in nodes]).reshape(n, 3, 3)
        start = 0.2 * random[:, 0]
        start[~problem.free_nodes] = 0.0
        frames = polish._stretched(state.tau.copy(), turn(start))
        mu = np.array([0.3, -0.2, 0.5])
        gradient = polish.lagrangian_gradient(frames, mu)
        hessian = problem.second_variation()
        assert hessian.block == 3 and gradient.shape == (n, 3)
        x, y = hessian.matrix.createVecs()
        errors = []
        for trial in (1, 2):
            v = random[:, trial].copy()
            v[~problem.free_nodes] = 0.0
            x.getArray()[:] = v.ravel()
            hessian.matrix.mult(x, y)
            quadratic = x.dot(y)
            slope = mesh.global_sum(np.sum(gradient * v))
            s = 1e-4
            plus, zero, minus = (lagrangian(problem, polish._stretched(frames, turn(h * v)),
                                            mu, work) for h in (s, 0.0, -s))
            errors.append((abs((plus - minus) / (2 * s) - slope) / abs(slope),
                           abs((plus - 2 * zero + minus) / s**2 - quadratic) / abs(quadratic)))
        assert max(e[0] for e in errors) < 1e-4, errors
        assert max(e[1] for e in errors) < 1e-6, errors
    finally:
        for vec in (x, y, work):
            if vec is not None:
                vec.destroy()
        polish.destroy()
        destroy(mesh, solver)


@pytest.mark.parametrize("which", ["start", "end"])
def test_the_default_joint_axis_is_the_lines_direction_in_its_catenary(comm, which):
    """A joint without an axis on a catenary between pins (w = 100 N/m, L = 1 m, ends
    at (0.6, 0, 0.3)): its axis is the catenary's tangent at that end, so that the
    joint, installed at the cable's static angle, turns by the bending's share only
    (EI = 1 N m^2 beside w L^2 = 100 N m; measured 6.2 and 4.3 degrees at the start and
    the end against 34 and 53 about the old default e_x), and the state is the joint's
    with that axis given. At a pin whose partner is free the axis stays e_x (no
    catenary). On the steel riser: tests/system/test_riser_cli.py."""
    from petsc_rod.scenes.starts import catenary_start

    scene = dict(start="pin", end="pin", end_position=(0.6, 0.0, 0.3),
                 load_values=[(0.0, 0.0, -100.0)], **{f"{which}_rotational_stiffness": 5.0})
    tangent = catenary_start(Scene(length=LENGTH, stiffness=STIFFNESS, **scene), 1.0)(
        np.array([0.0 if which == "start" else LENGTH]))[1][0][2]
    assert getattr(Scene(length=LENGTH, stiffness=STIFFNESS, **scene), f"{which}_joint_axis") \
        == pytest.approx(tangent, abs=1e-15)
    assert abs(tangent[0]) < 0.9                      # far from e_x
    _, r, joints = solve(comm, scene, steps=2)
    _, given, given_joints = solve(comm, dict(scene, **{f"{which}_joint_axis": tangent}),
                                   steps=2)
    _, _, old_joints = solve(comm, dict(scene, **{f"{which}_joint_axis": (1.0, 0.0, 0.0)}),
                             steps=2)
    assert joints[0][0] < 0.25 * old_joints[0][0]
    assert np.abs(r - given).max() < 1e-9
    assert joints[0][0] == pytest.approx(given_joints[0][0], rel=1e-9)
    free = Scene(length=LENGTH, stiffness=STIFFNESS, start="pin", end="free",
                 start_rotational_stiffness=1.0, end_force=(0.0, -1.0, 0.0))
    assert np.array_equal(free.start_joint_axis, [1.0, 0.0, 0.0])
