"""A line whose bending and torsion stiffness vary along S (Scene.sections, docs/method.md
§1, §2, §4) against closed forms, with the observed orders; a uniform line given as
sections; the same answer on 1 and 2 ranks; the stability test (§10) at a stepped
column's buckling load.

Every scene holds both ends clamped, the end S = L where the closed form puts it: the
end moment M of a cantilever is then the clamp's reaction and the reaction force is
zero, so the equilibrium is the cantilever's under a tip moment. A planar moment about
e_z bends the line in circular arcs of curvature M / EI_k in each section (K1 = K2 = EI
there), theta(S) = int_0^S M / EI; a roll of the end about e_x twists a straight line at
the rate M / K3_k, the sections' torsional springs in series. Section ends fall on
vertices (uniform meshes of N a multiple of 5), except in the test that says otherwise.

Serial and under mpiexec -n 2 (the fields gathered; the agreement test solves on
COMM_SELF and COMM_WORLD). Bounds come from the measured values quoted in each docstring,
with a margin; every order is fitted by least squares over the sizes given.
"""

import numpy as np
import pytest
from petsc4py import PETSc
from scipy.integrate import quad

from helpers import continuation as solve, fitted_order, gather, make_solver
from petsc_rod.frames import rotation_about
from petsc_rod.io.outputs import vertex_fields
from petsc_rod.problem.penalty import default_penalty
from petsc_rod.model.line_type import Section
from petsc_rod.scenes.scene import REFERENCE_FRAME, Scene

# the angle (rad) the end moment turns the end by, and the roll of the twisted line
BEND, TWIST = 1.5, 2.0
TIGHT = dict(rtol=1e-12, ctol=1e-12, max_it=5000)


def section(name, start, end, k, k_end=None):
    k_end = k if k_end is None else k_end
    return Section(name, start, end, k, k_end)


# (a) two sections of different EI; (b) a bend stiffener tapering from 4 EI to EI, then
# the line; (e) a section whose K3 exceeds K1 + K2 (a3 < 0: the lagged part) after an
# ordinary one
STEPPED = (section("stiff", 0.0, 0.4, (2.0, 2.0, 1.5)), section("soft", 0.4, 1.0, (0.5, 0.5, 0.4)))
TAPERED = (section("stiffener", 0.0, 0.4, (4.0, 4.0, 3.0), (1.0, 1.0, 0.75)),
           section("line", 0.4, 1.0, (1.0, 1.0, 0.75)))
TORSION = (section("ordinary", 0.0, 0.4, (1.0, 1.0, 0.8)),
           section("torsion", 0.4, 1.0, (0.5, 0.5, 1.5)))


def compliance(sections, S):
    """int_0^S dS / EI, EI = K2 linear along each section (S a float): the sum over the
    sections before S of l / EI, or l ln(EI_end / EI_start) / (EI_end - EI_start) along a
    taper, 1/(N m^2) m."""
    total = 0.0
    for part in sections:
        upper = min(S, part.end)
        if upper <= part.start:
            break
        e0, e1 = part.stiffness_start[1], part.stiffness_end[1]
        length = part.end - part.start
        if e0 == e1:
            total += (upper - part.start) / e0
        else:
            at = e0 + (e1 - e0) * (upper - part.start) / length
            total += length * np.log(at / e0) / (e1 - e0)
    return total


def exact_bending(sections, S):
    """The end moment M and theta, r (S (n,) -> (n,), (n, 3)) of the line bent by BEND:
    theta = M int_0^S dS / EI (compliance), r = int_0^S (cos theta, sin theta, 0) dS by
    adaptive quadrature (scipy.integrate.quad), split at the section ends."""
    breaks = [part.start for part in sections[1:]]
    options = dict(epsabs=1e-14, epsrel=1e-14, limit=200)
    moment = BEND / compliance(sections, 1.0)
    theta = lambda s: moment * compliance(sections, s)
    r = np.zeros((len(S), 3))
    for k, x in enumerate(S):
        points = [b for b in breaks if b < x] or None
        for c, f in enumerate((np.cos, np.sin)):
            if x > 0:
                r[k, c] = quad(lambda s: f(theta(s)), 0.0, x, points=points, **options)[0]
    return moment, np.array([theta(x) for x in S]), r


def bent_scene(sections):
    """Both ends clamped, the end S = L at the closed form's position and turned by BEND
    about e_z."""
    _, _, end = exact_bending(sections, np.array([1.0]))
    frame = REFERENCE_FRAME @ rotation_about([0, 0, 1], BEND).T
    return dict(length=1.0, stiffness=(1.0, 1.0, 1.0), start="clamp", end="clamp",
                end_position=end[0], end_frame=frame, sections=sections)


def solved(comm, solver_factory, n, scene, steps=2, **settings):
    """(report, vertex fields gathered on every rank, energy) of ``scene`` on n elements
    at the default penalty of docs/method.md §3 (penalty.default_penalty)."""
    mesh, solver = solver_factory(comm, n, scene, default_penalty(Scene(**scene)),
                                  **{**TIGHT, **settings})
    report = solve(solver, steps=steps)
    fields = {key: gather(comm, value) for key, value in vertex_fields(solver.problem).items()}
    return report, fields, solver.problem.energy()


def bending_errors(comm, solver_factory, sections, sizes, **settings):
    """Max vertex errors of r, d3 and the moment m, the energy's error, and |n| for the
    bent line on each size."""
    scene = bent_scene(sections)
    errors = {key: [] for key in ("r", "d3", "m", "energy", "n")}
    for n in sizes:
        report, fields, energy = solved(comm, solver_factory, int(n), scene, **settings)
        assert report.converged and report.stable
        moment, theta, r = exact_bending(sections, fields["S"])
        tangent = np.stack([np.cos(theta), np.sin(theta), 0 * theta], axis=1)
        errors["r"].append(np.abs(fields["r"] - r).max())
        errors["d3"].append(np.abs(fields["d3"] - tangent).max())
        errors["m"].append(np.abs(fields["m"] - [0.0, 0.0, moment]).max())
        errors["energy"].append(abs(energy - 0.5 * moment * BEND))
        errors["n"].append(np.abs(fields["n"]).max())
    return {key: np.array(value) for key, value in errors.items()}


def test_two_sections_bend_in_two_circular_arcs(comm, solver_factory):
    """(a) EI 2 on [0, 0.4], 0.5 on [0.4, 1], M = 1.5 / 1.4: arcs of curvature M / EI_k,
    the end turned by 1.5 rad. Measured on 5, 10, 20 elements: r 7.2e-6, 4.7e-7, 2.9e-8
    (order 3.98), the energy 3.3e-5, 2.0e-6, 1.3e-7 (order 4.0), the vertex moment
    1.6e-2, 4.1e-3, 1.0e-3 (order 2.0, the strain's), the reaction force |n| 9.9e-4 to
    3.8e-6."""
    sizes = np.array([5, 10, 20])
    errors = bending_errors(comm, solver_factory, STEPPED, sizes)
    assert 3.8 < fitted_order(sizes, errors["r"]) < 4.2
    assert 3.8 < fitted_order(sizes, errors["d3"]) < 4.2
    assert 3.8 < fitted_order(sizes, errors["energy"]) < 4.2
    assert 1.8 < fitted_order(sizes, errors["m"]) < 2.2
    assert errors["r"][-1] < 4e-8 and errors["energy"][-1] < 2e-7
    assert errors["m"][-1] < 1.5e-3 and errors["n"][-1] < 6e-6


def test_a_tapered_stiffener_bends_as_int_m_over_ei(comm, solver_factory):
    """(b) EI falling linearly from 4 to 1 on [0, 0.4] (a bend stiffener), then 1:
    theta(S) = M int_0^S dS / EI, r by adaptive quadrature. The element matrices
    integrate the linear EI exactly (Gauss on each element): measured r 9.0e-6, 6.8e-7,
    4.5e-8 on 10, 20, 40 elements (order 3.8, 3.9 between the last two), the energy
    7.8e-5, 5.9e-6, 3.9e-7. The element's mean EI times the unit matrix instead gives
    order 1.9 (r 5.1e-4, 1.3e-4, 3.4e-5)."""
    sizes = np.array([10, 20, 40])
    errors = bending_errors(comm, solver_factory, TAPERED, sizes)
    assert 3.6 < fitted_order(sizes, errors["r"]) < 4.2
    assert 3.6 < fitted_order(sizes, errors["energy"]) < 4.2
    assert errors["r"][-1] < 6e-8 and errors["energy"][-1] < 5e-7


def test_a_section_end_inside_an_element(comm, solver_factory):
    """The sections of (a) on meshes whose vertices miss S = 0.4: the element matrices
    are still exact (cut at the section end, test_section_coefficients.py), but the P2
    directors cannot bend at a kink inside an element, and the error falls only like h:
    measured r 1.23e-3, 5.05e-4, 3.61e-4, 1.98e-4 on 8, 16, 32, 64 elements. Put the
    section ends on vertices."""
    sizes = np.array([8, 16, 32, 64])
    errors = bending_errors(comm, solver_factory, STEPPED, sizes)
    assert 0.7 < fitted_order(sizes, errors["r"]) < 1.3
    assert errors["r"][-1] < 2.5e-4


def test_a_uniform_line_given_as_sections(comm, solver_factory):
    """(c) Two sections of one stiffness: sections of the scene's own stiffness take the
    constant triple's path and give the same bits; the same sections under another
    -rod_stiffness take the path of a varying stiffness (the matrices integrated element
    by element) and agree to round-off. A non-convex stiffness (a2 < 0: the lagged part)
    bent out of plane by a pinned end."""
    k = (1.0, 1.6, 0.4)
    plain = dict(length=1.0, stiffness=k, start="clamp", end="pin", end_position=(0.7, 0.5, 0.2))
    halves = (section("a", 0.0, 0.6, k), section("b", 0.6, 1.0, k))
    results = [solved(comm, solver_factory, 20, scene, rtol=1e-11, ctol=1e-11)
               for scene in (plain, {**plain, "sections": halves},
                             {**plain, "stiffness": (1.0, 1.0, 1.0), "sections": halves})]
    (one, uniform, E), (two, same, E_same), (three, varying, E_varying) = results
    assert one.converged and two.converged and three.converged
    assert one.iterations == two.iterations and E_same == E
    for key in ("r", "d1", "d2", "m", "n"):
        assert np.array_equal(same[key], uniform[key]), key
        assert np.abs(varying[key] - uniform[key]).max() < 1e-9, key
    assert abs(E_varying - E) < 1e-12 * abs(E)
    assert one.stable == three.stable is True


@pytest.mark.parametrize("newton", [True, False])
def test_a_torsion_section_beside_an_ordinary_one(comm, solver_factory, newton):
    """(e) K3 = 1.5 > K1 + K2 on [0.4, 1] (a3 < 0, the lagged part of the slope), an
    ordinary section before it. Twisted by 2 rad: the twist rate is M / K3_k,
    M = 2 / (0.4 / 0.8 + 0.6 / 1.5), the roll phi(S) its integral; measured d1 against
    (0, cos phi, sin phi) 8.0e-5, 5.0e-6, 3.2e-7 on 5, 10, 20 elements (order 4), the
    vertex torque 5.6e-2 to 3.6e-3 (order 2), the energy M 2 / 2 to 6.8e-7. Bent by the
    end moment, the lagged part acts (r'' != 0 in the torsion section) and the arcs of
    (a) come out with the same errors as with K3 = 0.4 there (r 2.9e-8 on 20 elements).
    With and without Newton steps (Anderson mixing alone, 209 iterations on 20
    elements)."""
    sizes = np.array([5, 10, 20])
    twisted = dict(length=1.0, stiffness=(1.0, 1.0, 1.0), start="clamp", end="clamp",
                   end_twist=TWIST, sections=TORSION)
    moment = TWIST / (0.4 / 0.8 + 0.6 / 1.5)
    director, torque, energy = [], [], []
    for n in sizes:
        report, fields, E = solved(comm, solver_factory, int(n), twisted, newton=newton)
        assert report.converged
        S = fields["S"]
        phi = moment * np.where(S <= 0.4, S / 0.8, 0.4 / 0.8 + (S - 0.4) / 1.5)
        exact = np.stack([0 * S, np.cos(phi), np.sin(phi)], axis=1)
        director.append(np.abs(fields["d1"] - exact).max())
        torque.append(np.abs(np.einsum("ic,ic->i", fields["m"], fields["d3"]) - moment).max())
        energy.append(abs(E - 0.5 * moment * TWIST))
        assert np.abs(fields["r"][:, 1:]).max() < 1e-12
    assert 3.8 < fitted_order(sizes, director) < 4.2
    assert 1.8 < fitted_order(sizes, torque) < 2.2
    assert director[-1] < 4e-7 and energy[-1] < 1e-6
    torsion_soft = (STEPPED[0], section("soft", 0.4, 1.0, (0.5, 0.5, 1.5)))
    bent = bending_errors(comm, solver_factory, torsion_soft, sizes[-1:], newton=newton)
    assert bent["r"][0] < 4e-8 and bent["energy"][0] < 2e-7


def solve_on(comm):
    """The tapered stiffener and the torsion section together (lagged part, taper),
    bent out of plane by a pinned end; the fields gathered."""
    sections = (TAPERED[0], section("torsion", 0.4, 1.0, (1.0, 1.3, 3.0)))
    scene = dict(length=1.0, stiffness=(1.0, 1.0, 1.0), start="clamp", end="pin",
                 end_position=(0.7, 0.5, 0.2), sections=sections)
    mesh, solver = make_solver(comm, 20, scene, default_penalty(Scene(**scene)),
                               rtol=1e-11, ctol=1e-11, max_it=5000)
    try:
        report = solve(solver, steps=2)
        fields = {key: gather(comm, value)
                  for key, value in vertex_fields(solver.problem).items()}
        return report, fields, solver.problem.energy(), comm.getSize()
    finally:
        solver.destroy()
        solver.problem.destroy()
        mesh.destroy()


def test_the_same_answer_on_one_and_all_ranks():
    """(d) On PETSc.COMM_SELF and COMM_WORLD (1 and 2 ranks under mpiexec -n 2): the
    same state to the iteration's tolerance."""
    serial, parallel = solve_on(PETSc.COMM_SELF), solve_on(PETSc.COMM_WORLD)
    assert serial[0].converged and parallel[0].converged
    assert parallel[3] == PETSc.COMM_WORLD.getSize()
    for key in ("r", "d1", "d2", "m", "n"):
        assert np.abs(serial[1][key] - parallel[1][key]).max() < 1e-9, key
    assert abs(serial[2] - parallel[2]) < 1e-11 * abs(serial[2])


def stepped_column_load(a, stiff, soft):
    """The buckling load of a cantilever of bending stiffness ``stiff`` on [0, a] and
    ``soft`` on [a, 1] under a dead compressive tip force: the smallest root of
    tan(k1 a) tan(k2 (1 - a)) = k2 / k1, k_i = sqrt(P / EI_i) (w = delta (1 - cos k1 S)
    on the first part, delta - A sin(k2 (1 - S)) on the second, w and w' continuous at
    a), below the first pole."""
    from scipy.optimize import brentq

    k = lambda P, EI: np.sqrt(P / EI)
    f = lambda P: np.tan(k(P, stiff) * a) * np.tan(k(P, soft) * (1 - a)) - np.sqrt(stiff / soft)
    pole = min(stiff * (np.pi / (2 * a)) ** 2, soft * (np.pi / (2 * (1 - a))) ** 2)
    return brentq(f, 1e-9, pole * (1 - 1e-9), xtol=1e-14)


@pytest.mark.parametrize("ratio", [0.95, 1.05])
def test_a_stepped_column_buckles_at_its_load(comm, solver_factory, ratio):
    """The second variation with each field's own stiffness matrix (§10): the cantilever
    of (a) (EI 2 then 0.5) under a compressive tip force of 0.95 and 1.05 times its
    buckling load 2.4806 (between 1.2337 and 4.9348, those of the soft and the stiff
    line). Below, the straight state is a minimiser: no escape, no lateral deflection;
    above, the stability test finds it a saddle, the step leaves it (one escape,
    measured) and ends buckled (lateral 0.29 m, measured) and stable."""
    load = stepped_column_load(0.4, 2.0, 0.5)
    assert 2.48 < load < 2.481
    scene = dict(length=1.0, stiffness=(1.0, 1.0, 1.0), start="clamp", end="free",
                 end_force=(-ratio * load, 0.0, 0.0), sections=STEPPED)
    report, fields, _ = solved(comm, solver_factory, 20, scene, steps=1, rtol=1e-10, ctol=1e-10)
    assert report.converged and report.stable
    lateral = np.abs(fields["r"][:, 1:]).max()
    if ratio < 1:
        assert report.escapes == 0 and lateral < 1e-12
    else:
        assert report.escapes >= 1 and 0.2 < lateral < 0.4
