"""Point loads (attachments: physics/point_loads.py, scenes/point_loads.py) against
closed forms, on 1 and 2 ranks: a cantilever under a point force against linear beam
theory (small load) and against the elastica of the inner part with a straight outer
part (large load), the same from a free start, a chain with a clump weight against the
two-piece catenary, a point on a vertex and inside an element (the order), and one rank
against all. Bounds from measured runs (docs/riser.md, "Attachments"), with a margin."""

import numpy as np
import pytest
from petsc4py import PETSc
from scipy.optimize import fsolve

from helpers import destroy, fitted_order, gather, make_solver
from petsc_rod.io.outputs import vertex_fields
from petsc_rod.mesh.elements import GAUSS_POINTS, GAUSS_WEIGHTS, p2_basis
from petsc_rod.mesh.mesh import Mesh
from petsc_rod.physics.point_loads import PointLoads, point_load_element_vectors
from petsc_rod.problem.penalty import default_penalty
from petsc_rod.scenes.scene import Scene
from petsc_rod.scenes.starts import catenary_start
from petsc_rod.validation.closed_forms import cantilever_shape

UNIT = dict(length=1.0, stiffness=(1.0, 1.0, 1.0), start="clamp", end="free")


def solve(comm, n_elements, scene, steps=(1.0,), start=None, rtol=1e-9, ctol=1e-9):
    """(report of the last step, vertex fields gathered, the attachments' positions,
    energy) of Scene(**scene) at the default penalty, from the straight state or
    ``start`` (a curve)."""
    mesh, solver = make_solver(comm, n_elements, scene, default_penalty(Scene(**scene)),
                               rtol=rtol, ctol=ctol, max_it=20000)
    try:
        state = solver.problem.state
        state.set_straight() if start is None else state.set_from_curve(start(solver))
        for t in steps:
            report = solver.solve_step(t)
        fields = vertex_fields(solver.problem)
        term = next(t for t in solver.problem.terms if isinstance(t, PointLoads))
        return (report, {k: gather(comm, fields[k]) for k in ("S", "r", "d3", "n")},
                term.positions(state), solver.problem.energy())
    finally:
        destroy(mesh, solver)


def test_the_load_vector_integrates_the_step_exactly(comm):
    """int_e F g_k dS of F = P [S < S_p] + offset against 3-point Gauss on the two parts
    of each element (exact for the quadratic g_k), a point inside an element and one on a
    vertex."""
    mesh = Mesh(comm, 7, 2.0, grading=2.0)
    try:
        S = np.array([0.61, mesh.coordinates(3), 2.0])
        force = np.array([[1.0, -2.0, 0.5], [0.0, 3.0, -1.0], [2.0, 0.0, 1.0]])
        offset = np.array([0.3, -0.1, 0.2])
        vectors = point_load_element_vectors(mesh, S, force, offset)
        expected = np.zeros_like(vectors)
        for e, (left, h) in enumerate(zip(mesh.element_S, mesh.element_h)):
            for a, b, F in ((left, left + h, offset),) + tuple(
                    (left, min(max(s, left), left + h), p) for s, p in zip(S, force)):
                x = (a + (b - a) * GAUSS_POINTS - left) / h
                phi = p2_basis(x[None, :], np.array([h]))[0][0]
                expected[e] += (b - a) * np.einsum("q,qk->k", GAUSS_WEIGHTS, phi)[:, None] * F
        assert np.abs(vectors - expected).max() < 1e-14
    finally:
        mesh.destroy()


@pytest.mark.parametrize("S_p", [0.5, 0.53])
def test_a_small_point_force_bends_a_cantilever_as_beam_theory(comm, S_p):
    """P = 1e-4 N at S_p (on a vertex, inside an element) of the unit cantilever: tip
    deflection P a^2 (3L - a) / 6EI and the point's P a^3 / 3EI, the part beyond the
    point straight, n = P before the point and 0 beyond, E = -P delta_p / 2. Measured:
    the tip 1.8e-9 and 2.8e-9 of itself, the point 2.5e-5 inside an element of 16.
    Solved to rtol = ctol = 1e-10: at the default 1e-9 the stopping test allows about
    1e-8 of the tip (the state's error against a deflection of 1e-5), which the
    iteration reached on one machine (1.05e-8) where Newton steps went further on
    another; below 1e-10 it stalls at round-off."""
    P, a = 1e-4, S_p
    scene = dict(UNIT, point_load_S=[S_p], point_load_forces=[[0.0, -P, 0.0]])
    report, fields, positions, energy = solve(comm, 16, scene, rtol=1e-10, ctol=1e-10)
    assert report.converged and report.stable
    tip = P * a**2 * (3 - a) / 6
    point = P * a**3 / 3
    assert abs(fields["r"][-1, 1] + tip) < 1e-8 * tip
    assert abs(positions[0, 1] + point) < 1e-4 * point
    assert abs(positions[0, 0] - a) < 1e-9
    beyond = fields["S"] >= S_p
    assert np.abs(fields["d3"][beyond] - fields["d3"][-1]).max() < 1e-12
    expected_n = np.where(fields["S"][:, None] < S_p, [0.0, -P, 0.0], 0.0)
    assert np.abs(fields["n"] - expected_n).max() < 1e-12
    assert abs(energy + 0.5 * P * point) < 1e-4 * P * point


def test_from_a_free_start_the_point_force_is_carried_to_the_held_end(comm):
    """The mirror image: free at S = 0, clamped at S = L: the free start deflects by
    P b^2 (3L - b) / 6EI, b = L - S_p the point's distance from the clamp; n = -P beyond
    the point (the reaction's share) and 0 before it."""
    P, S_p = 1e-4, 0.3
    scene = dict(length=1.0, stiffness=(1.0, 1.0, 1.0), start="free", end="clamp",
                 point_load_S=[S_p], point_load_forces=[[0.0, -P, 0.0]])
    report, fields, positions, _ = solve(comm, 16, scene)
    assert report.converged
    b = 1.0 - S_p
    assert abs(fields["r"][0, 1] + P * b**2 * (3 - b) / 6) < 1e-6 * P * b**3
    expected_n = np.where(fields["S"][:, None] > S_p, [0.0, P, 0.0], 0.0)
    assert np.abs(fields["n"] - expected_n).max() < 1e-12


# --- a large point force: the elastica of the inner part, the outer part straight -------
LARGE_S, LARGE_P = 0.5, 12.0           # P S_p^2 / EI = 3
LARGE = dict(UNIT, point_load_S=[LARGE_S], point_load_forces=[[0.0, -LARGE_P, 0.0]])


def large_errors(comm, n_elements):
    """(inner, point, tip, straight) errors of the unit cantilever under LARGE_P at
    LARGE_S in two steps: the vertices up to S_p against the tip-loaded elastica of
    length S_p (closed_forms.cantilever_shape), r(S_p), the tip against r(S_p) +
    (L - S_p) d3(S_p) of the closed form, and how far d3 beyond S_p is from constant."""
    report, fields, positions, _ = solve(comm, n_elements, LARGE, steps=(0.5, 1.0))
    assert report.converged and report.stable and report.newton_steps > 0
    S, r, d3 = fields["S"], fields["r"], fields["d3"]
    inner = S <= LARGE_S
    _, x, y = cantilever_shape(LARGE_S, 1.0, LARGE_P, S[inner])
    theta, xp, yp = (v[0] for v in cantilever_shape(LARGE_S, 1.0, LARGE_P, [LARGE_S]))
    tip = np.array([xp, yp, 0.0]) + (1 - LARGE_S) * np.array([np.cos(theta), -np.sin(theta), 0])
    beyond = S >= LARGE_S
    return dict(inner=np.abs(r[inner][:, :2] - np.stack([x, y], axis=-1)).max(),
                point=np.abs(positions[0] - [xp, yp, 0.0]).max(),
                tip=np.abs(r[-1] - tip).max(),
                straight=np.abs(d3[beyond] - d3[beyond][-1]).max())


def test_beyond_a_large_point_force_the_rod_is_straight_and_within_it_an_elastica(comm):
    """Measured (16 / 32 elements, the point on a vertex): inner 8.5e-6 / 5.3e-7, tip
    1.2e-5 / 7.3e-7 m; d3 beyond the point constant to 5e-14 (Newton steps taken, the
    state stable)."""
    coarse, fine = large_errors(comm, 16), large_errors(comm, 32)
    assert coarse["inner"] < 1.2e-5 and fine["inner"] < 8e-7
    assert coarse["tip"] < 1.6e-5 and fine["tip"] < 1e-6
    assert coarse["point"] < 1.2e-5 and fine["point"] < 8e-7
    assert max(coarse["straight"], fine["straight"]) < 1e-12


def test_a_point_inside_an_element_converges_to_the_same_answer(comm):
    """S_p = 0.5 on a vertex (16, 32, 64 elements) and inside one (15, 31, 63: the
    midpoint of an element): the same limit; the tip's error falls at order 4 on a vertex
    and at order 3 inside (the jump of the shear r''' inside a cubic element).
    Measured: vertex 1.16e-5, 7.3e-7, 4.5e-8 (order 4.0); inside 2.8e-5, 2.5e-6, 2.7e-7
    (order 3.3)."""
    vertex = [large_errors(comm, n)["tip"] for n in (16, 32, 64)]
    inside = [large_errors(comm, n)["tip"] for n in (15, 31, 63)]
    assert fitted_order([16, 32, 64], vertex) > 3.7
    assert fitted_order([15, 31, 63], inside) > 3.0
    assert inside[-1] < 4e-7 and vertex[-1] < 7e-8


# --- a chain with a clump weight -------------------------------------------------------------
CHAIN_L, CHAIN_CHORD, CHAIN_W, CLUMP, CLUMP_S = 10.0, np.array([8.0, 0.0, 2.0]), 1.0, 3.0, 4.0
CHAIN = dict(length=CHAIN_L, stiffness=(1e-6, 1e-6, 1e-6), start="pin", end="pin",
             end_position=CHAIN_CHORD, load_values=[[0.0, 0.0, -CHAIN_W]],
             point_load_S=[CLUMP_S], point_load_forces=[[0.0, 0.0, -CLUMP]])


def two_piece_catenary(S):
    """(r (n, 3), n (n, 3)) of the inextensible chain of CHAIN at arc lengths S: the
    force n = (H, 0, c0 + w S + W [S > S_p]) (n' + f = 0 with the clump's jump W, so that
    the kink angle is the force balance's), r' = n / |n|, integrated in closed form
    piece by piece (x: H/w asinh, z: |n| / w), (H, c0) such that r(L) is the chord."""
    w, W, S_p = CHAIN_W, CLUMP, CLUMP_S

    def shape(H, c0, S):
        def part(c, a, b):
            return (H / w * (np.arcsinh((c + w * b) / H) - np.arcsinh((c + w * a) / H)),
                    (np.hypot(H, c + w * b) - np.hypot(H, c + w * a)) / w)
        x1, z1 = part(c0, 0.0, np.minimum(S, S_p))
        x2, z2 = part(c0 + W, S_p, np.maximum(S, S_p))
        return x1 + x2, z1 + z2

    H, c0 = fsolve(lambda v: np.array(shape(v[0], v[1], CHAIN_L)) - CHAIN_CHORD[[0, 2]],
                   [5.0, -8.0], xtol=1e-14)
    x, z = shape(H, c0, np.asarray(S))
    zeros = np.zeros_like(x)
    return (np.stack([x, zeros, z], axis=-1),
            np.stack([np.full_like(x, H), zeros, c0 + w * S + W * (S >= S_p)], axis=-1))


def test_a_chain_with_a_clump_weight_is_a_two_piece_catenary(comm):
    """EI = 1e-6 N m^2 (a bending length of 4e-4 m), from the catenary without the clump.
    The kink, sharp in the chain, is smoothed over the elements next to it by the C^1
    discrete centreline: r and n converge at order 1. Measured: r 8.7e-3, 4.4e-3 m, n
    6.5e-3, 3.2e-3 N (40, 80 elements); the tangent 0.5 m either side of the clump
    6.2e-4, 3.1e-4."""
    errors = []
    for n_elements in (40, 80):
        report, fields, positions, _ = solve(
            comm, n_elements, CHAIN, start=lambda solver: catenary_start(solver.problem.scene, 1.0),
            rtol=1e-12, ctol=1e-12)
        assert report.converged and report.stable
        S = fields["S"]
        r, n = two_piece_catenary(S)
        tangent = n / np.linalg.norm(n, axis=1)[:, None]
        away = np.abs(S - CLUMP_S) > 0.49
        errors.append((np.abs(fields["r"] - r).max(), np.abs(fields["n"] - n).max(),
                       np.abs(fields["d3"] - tangent)[away].max(),
                       np.abs(positions[0] - two_piece_catenary(np.array([CLUMP_S]))[0][0]).max()))
    (r40, n40, t40, p40), (r80, n80, t80, p80) = errors
    assert r40 < 1e-2 and r80 < 5e-3 and n40 < 7.5e-3 and n80 < 3.7e-3
    assert t40 < 7e-4 and t80 < 3.5e-4 and p80 < 5e-3
    assert 0.9 < np.log2(r40 / r80) < 1.1


def test_one_rank_and_all_ranks_agree(comm):
    """LARGE on COMM_SELF and COMM_WORLD (the point inside an element of 15): the same
    state to the iteration's tolerance."""
    alone = solve(PETSc.COMM_SELF, 15, LARGE, steps=(0.5, 1.0))
    shared = solve(comm, 15, LARGE, steps=(0.5, 1.0))
    assert np.abs(alone[1]["r"] - shared[1]["r"]).max() < 1e-9
    assert np.abs(alone[1]["n"] - shared[1]["n"]).max() < 1e-9
    assert np.abs(alone[2] - shared[2]).max() < 1e-9
    assert abs(alone[3] - shared[3]) < 1e-9


# --- the drag of an attachment in a current ------------------------------------------------
RHO, CDA = 1025.0, 2e-3          # kg/m^3, m^2


def with_drag(comm, current, forces):
    """Solve the unit cantilever with an attachment of drag area CDA at S = 0.6 and dead
    force ``forces`` in ``current`` (a riser Current whose line drag c is 0, so that only
    the attachment feels it); (fields, positions, the reported drag)."""
    scene = dict(UNIT, point_load_S=[0.6], point_load_forces=[forces],
                 point_load_drag_areas=[CDA], current=current)
    mesh, solver = make_solver(comm, 16, scene, default_penalty(Scene(**scene)), rtol=1e-11,
                               ctol=1e-11, max_it=20000, newton=False)
    try:
        solver.problem.state.set_straight()
        report = solver.solve_step(1.0)
        assert report.converged
        term = next(t for t in solver.problem.terms if isinstance(t, PointLoads))
        assert not term.conservative and not term.in_newton
        fields = vertex_fields(solver.problem)
        state = solver.problem.state
        return ({k: gather(comm, fields[k]) for k in ("r", "n")}, term.positions(state),
                term.drag_forces(state))
    finally:
        destroy(mesh, solver)


def test_the_drag_of_an_attachment_is_its_point_force(comm):
    """In a uniform current U e_y the drag 1/2 rho C_d A U^2 e_y is a dead force: the same
    state as that force given directly. In a current that varies with depth (1 m/s at
    the surface z = 0, none 1 m down) under a weight that sinks the point: the drag is
    1/2 rho C_d A |v| v at the point's depth, and the state the same as with that force
    given as a dead one (the fixed point). Measured: 2.1e-13 and 3.1e-13 m."""
    from petsc_rod.environment.current import Current
    uniform = Current(np.zeros(1), np.array([[0.0, 0.8, 0.0]]), 0.0, 0.0)
    fields, _, drag = with_drag(comm, uniform, [0.0, 0.0, 0.0])
    expected = 0.5 * RHO * CDA * 0.8**2
    assert np.allclose(drag, [[0.0, expected, 0.0]], rtol=1e-14, atol=0)
    dead = solve(comm, 16, dict(UNIT, point_load_S=[0.6], point_load_forces=[[0.0, expected, 0.0]]),
                 rtol=1e-11, ctol=1e-11)[1]
    assert np.abs(fields["r"] - dead["r"]).max() < 1e-11
    assert np.abs(fields["n"] - dead["n"]).max() < 1e-11
    profile = Current(np.array([0.0, 1.0]), np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 0.0]]), 0.0, 0.0)
    fields, positions, drag = with_drag(comm, profile, [0.0, 0.0, -2.0])
    speed = 1.0 + positions[0, 2]                # linear in depth -z from 1 to 0
    assert positions[0, 2] < -0.1
    assert np.allclose(drag[0], [0.0, 0.5 * RHO * CDA * speed**2, 0.0], rtol=1e-12, atol=0)
    dead = solve(comm, 16, dict(UNIT, point_load_S=[0.6],
                                point_load_forces=[drag[0] + [0.0, 0.0, -2.0]]),
                 rtol=1e-11, ctol=1e-11)[1]
    assert np.abs(fields["r"] - dead["r"]).max() < 1e-11


# --- a point on a held end ----------------------------------------------------------------
def reactions_and_shape(comm, scene, start):
    """(r gathered, start_force, end_force) of Scene(**scene) converged from ``start``
    ('catenary' or 'straight'): the reactions of line_results.end_numbers."""
    from petsc_rod.quantities.line_results import end_numbers

    mesh, solver = make_solver(comm, 40, scene, default_penalty(Scene(**scene)),
                               rtol=1e-11, ctol=1e-11, max_it=20000)
    try:
        problem = solver.problem
        if start == "catenary":
            problem.state.set_from_curve(catenary_start(problem.scene, 1.0))
        else:
            problem.state.set_straight()
        assert solver.solve_step(1.0).converged
        fields = vertex_fields(problem)
        numbers = end_numbers(problem, fields)
        return gather(comm, fields["r"]), numbers["start_force"], numbers["end_force"]
    finally:
        destroy(mesh, solver)


def test_a_point_on_a_held_end_is_carried_by_its_support(comm):
    """Points at S = 0 and S = L of the clump-weight chain (both ends pinned): the
    supports carry them. The reactions (the attributes start_force and end_force, what
    the line exerts on its supports) balance every load, the weight w L, the clump and
    the points on the ends, to the iteration's tolerance, each end's by its own point;
    the shape is that without the end points. Before, a point on a held end was in
    neither reaction (the sum was off by the points)."""
    ends = np.array([[0.0, 0.0, -5.0], [1.0, -2.0, -7.0]])
    scene = dict(CHAIN, point_load_S=[0.0, CLUMP_S, CHAIN_L],
                 point_load_forces=[ends[0], [0.0, 0.0, -CLUMP], ends[1]])
    r, start_force, end_force = reactions_and_shape(comm, scene, "catenary")
    r_bare, start_bare, end_bare = reactions_and_shape(comm, CHAIN, "catenary")
    loads = np.array([0.0, 0.0, -CHAIN_W * CHAIN_L - CLUMP]) + ends.sum(axis=0)
    assert np.abs(start_force + end_force - loads).max() < 1e-6 * CHAIN_L * CHAIN_W
    assert np.abs(start_force - start_bare - ends[0]).max() < 1e-6
    assert np.abs(end_force - end_bare - ends[1]).max() < 1e-6
    assert np.abs(r - r_bare).max() < 1e-6


def test_a_point_on_a_clamp_is_carried_by_the_clamp(comm):
    """The unit cantilever with a point on its clamp at S = 0 and one at the free tip:
    the clamp carries both, start_force = P_0 + P_L (no other load)."""
    forces = np.array([[0.0, 0.0, -3.0], [0.0, 1e-3, -2e-3]])
    scene = dict(UNIT, point_load_S=[0.0, 1.0], point_load_forces=forces)
    _, start_force, _ = reactions_and_shape(comm, scene, "straight")
    assert np.abs(start_force - forces.sum(axis=0)).max() < 1e-9
