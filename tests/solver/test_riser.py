"""The seabed and the current (petsc_rod/environment, physics, docs/riser.md) against closed
forms, and one rank against two. Serial and under mpiexec -n 2; bounds from measured runs
(docs/riser.md, "Accuracy"), with a margin for the 1-rank / 2-rank round-off only."""

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import fitted_order, gather, make_solver
from petsc_rod.cli import messages as step_lines
from petsc_rod.cli.session import record_step
from petsc_rod.environment.current import Current
from petsc_rod.environment.seabed import Seabed
from petsc_rod.global_step.matrices import load_ghosted
from petsc_rod.global_step.nodal_loads import NodalLoad
from petsc_rod.io.outputs import vertex_fields
from petsc_rod.iteration.events import StepEnded
from petsc_rod.mesh.elements import P2
from petsc_rod.mesh.fields import VectorField, scatter_element_vectors
from petsc_rod.mesh.mesh import Mesh
from petsc_rod.problem.penalty import default_penalty
from petsc_rod.scenes.catenary import catenary
from petsc_rod.scenes.scene import Scene
from petsc_rod.scenes.starts import catenary_start
from petsc_rod.scenes.touchdown import grounded_catenary


def solved(solver_factory, comm, n_elements, scene, start="straight", rtol=1e-12,
           ctol=1e-12, newton=False):
    """(mesh, solver, report) of ``scene`` (Scene keywords) at the default penalty,
    without Newton steps unless asked (the iteration's counts compare)."""
    penalty = default_penalty(Scene(**scene))
    mesh, solver = solver_factory(comm, n_elements, scene, penalty, rtol=rtol, ctol=ctol,
                                  max_it=20000, newton=newton)
    if start == "catenary":
        solver.problem.state.set_from_curve(catenary_start(solver.problem.scene, 1.0))
    else:
        solver.problem.state.set_straight()
    return mesh, solver, solver.solve_step(1.0)


# --- a heavy line resting partly on the seabed ----------------------------------------------
# 10 m of line of weight 1 N/m from an anchor on the seabed z = 0 to a pin 7 m away and
# 4 m up: 5.5 m of it rest on the seabed. Bending and penetration are made negligible
# (EI = 1e-6 N m^2: a bending length of 5e-4 m; k = 1e6 N/m^2: 1 micrometre), so that
# the closed form (scenes/touchdown.py) is the limit of the discrete problem.
GROUNDED_CHORD = np.array([7.0, 0.0, 4.0])
GROUNDED = dict(length=10.0, stiffness=(1e-6, 1e-6, 1e-6), start="pin", end="pin",
                end_position=GROUNDED_CHORD, load_values=[[0.0, 0.0, -1.0]],
                seabed=Seabed(0.0, 1e6))


def grounded_errors(comm, solver_factory, n_elements, newton=False, start="straight"):
    """Max errors of r and n away from the touchdown zone (|S - S_td| > 1 m) and the
    anchor (S > 0.5 m: the anchor pin carries the weight of its half element), and the
    riser report's numbers, against the closed form (and the solve's report)."""
    mesh, solver, report = solved(solver_factory, comm, n_elements, GROUNDED, start=start,
                                  newton=newton)
    assert report.converged and report.stable
    fields = vertex_fields(solver.problem)
    numbers = riser_output(solver.problem, fields).attributes
    S, r, n = (gather(comm, fields[key]) for key in ("S", "r", "n"))
    exact, tangent, force, (_, touchdown) = grounded_catenary(10.0, GROUNDED_CHORD, 1.0, 0.0, S)
    away = (np.abs(S - touchdown) > 1.0) & (S > 0.5)
    return dict(report=report, r=np.linalg.norm(r - exact, axis=1)[away].max(),
                n=np.linalg.norm(n - force, axis=1)[away].max(),
                numbers=numbers, touchdown=touchdown, top_force=force[-1], top_tangent=tangent[-1],
                h=10.0 / n_elements)


@pytest.fixture(scope="module")
def grounded_runs():
    """The grounded line at 40, 80 and 160 elements (built and destroyed here)."""
    built, runs = [], {}

    def factory(*args, **kwargs):
        pair = make_solver(*args, **kwargs)
        built.append(pair)
        return pair

    for n_elements in (40, 80, 160):
        runs[n_elements] = grounded_errors(PETSc.COMM_WORLD, factory, n_elements)
    yield runs
    for mesh, solver in reversed(built):
        solver.destroy()
        solver.problem.destroy()
        mesh.destroy()


def test_grounded_line_against_the_catenary_with_touchdown(grounded_runs):
    """Measured at 40 / 80 / 160 elements: r 2.1e-4 / 8.4e-5 / 3.4e-5 m, n 7.7e-4 /
    3.1e-4 / 1.3e-4 N (of a top tension of 4.5 N): observed order 1.3 for both (the
    touchdown point, where the curvature jumps, is resolved to a node)."""
    errors = {n: (run["r"], run["n"]) for n, run in grounded_runs.items()}
    assert errors[40][0] < 3e-4 and errors[40][1] < 1e-3
    assert errors[160][0] < 5e-5 and errors[160][1] < 2e-4
    elements = list(errors)
    assert fitted_order(elements, [e[0] for e in errors.values()]) > 1.1
    assert fitted_order(elements, [e[1] for e in errors.values()]) > 1.1


def test_riser_numbers_of_the_grounded_line(grounded_runs):
    """Top tension and angle (from the vertical), touchdown within an element, grounded
    length, the largest curvature at the touchdown point."""
    run = grounded_runs[160]
    numbers = run["numbers"]
    tension = np.linalg.norm(run["top_force"])
    assert abs(numbers["top_tension"] - tension) < 3e-5 * tension
    angle = np.degrees(np.arccos(run["top_tangent"][2]))
    assert abs(numbers["top_angle"] - angle) < 2e-3
    assert abs(numbers["touchdown_S"] - run["touchdown"]) < run["h"]
    assert abs(numbers["touchdown_position"][2]) < 1e-12
    assert abs(numbers["grounded_length"] - run["touchdown"]) < run["h"]
    assert abs(numbers["max_curvature_S"] - run["touchdown"]) < 2 * run["h"]
    assert numbers["min_bend_radius"] == pytest.approx(1 / numbers["max_curvature"])


def test_a_seabed_far_below_changes_nothing(comm, solver_factory):
    """The vertical problem in Hermite dofs (global_step/hermite.py) is the slope problem in
    other coordinates: with the seabed out of reach the state is the dead-load one."""
    scene = dict(length=10.0, stiffness=(1.0, 1.0, 0.8), start="pin", end="pin",
                 end_position=(7.0, 1.0, 2.0), load_values=[[0.0, 0.0, -1.0]])
    _, free, free_report = solved(solver_factory, comm, 40, scene, start="catenary")
    _, with_seabed, report = solved(solver_factory, comm, 40,
                                    {**scene, "seabed": Seabed(-100.0, 1e6)}, start="catenary")
    assert free_report.converged and report.converged
    assert report.iterations == pytest.approx(free_report.iterations, rel=0.1)
    for a, b in ((free.problem.state.r, with_seabed.problem.state.r),
                 (free.problem.state.d1, with_seabed.problem.state.d1)):
        assert np.abs(a.owned() - b.owned()).max() < 1e-9
    assert np.allclose(free.problem.end_reaction(), with_seabed.problem.end_reaction(),
                       rtol=0, atol=1e-8)


@pytest.mark.parametrize("factor", [1.0, 1e3, 1e6])
def test_a_stiffer_seabed_converges_as_fast(comm, solver_factory, factor):
    """The seabed is implicit in the global step: 1000 and 10^6 times the default
    stiffness (k l^2 / R up to 1e11 here) converge in about the same iterations
    (measured 99 / 101 / 104 at 160 elements)."""
    scene = {**GROUNDED, "stiffness": (1e-3, 1e-3, 1e-3), "seabed": Seabed(0.0, factor * 1e3)}
    _, solver, report = solved(solver_factory, comm, 160, scene, rtol=1e-9, ctol=1e-9)
    assert report.converged and report.iterations < 150
    lowest = solver.problem.mesh.global_min(float(solver.problem.state.r.owned()[:, 0, 2].min()))
    # about w / k below the seabed, 2.2 w / k at the touchdown node (measured)
    assert -3.0e-3 / factor < lowest < 0


# --- a uniform current ------------------------------------------------------------------------
# A weightless line pinned at both ends in a uniform current across its chord: the drag
# c |v_n| v_n has no tangential part, so the tension T is constant, and T kappa =
# c U^2 sin^2(phi) makes cot(phi) linear in S: the shape is the catenary of a dead load
# along the current (catenary.catenary) with T = its horizontal tension H when the dead
# load is c U^2 per metre.
CURRENT_CHORD = np.array([80.0, 0.0, 0.0])
DRAG = 0.5 * 1025.0 * 1.2 * 0.1
SPEED = 1.0


def current_scene(bending=1.0):
    return dict(length=100.0, stiffness=(bending, bending, bending), start="pin", end="pin",
                end_position=CURRENT_CHORD,
                current=Current.uniform([0.0, SPEED, 0.0], 1025.0, 1.2, 0.1))


def test_uniform_current_on_a_pinned_line_is_the_current_catenary(comm, solver_factory):
    """Measured at 200 elements: r within 4.4e-6 m of the closed form (L = 100 m,
    bending length sqrt(EI / T) = 0.02 m), the tension constant to 6.1e-7 of T = 2080 N."""
    mesh, solver, report = solved(solver_factory, comm, 200, current_scene(), rtol=1e-10,
                                  ctol=1e-10)
    assert report.converged and report.stable is None       # not tested: no energy
    fields = vertex_fields(solver.problem)
    S, r, n = (gather(comm, fields[key]) for key in ("S", "r", "n"))
    load = np.array([0.0, DRAG * SPEED**2, 0.0])
    exact, tangent, force = catenary(100.0, CURRENT_CHORD, load, S)
    tension = abs(force[0, 0])                               # H of the dead-load catenary
    assert np.linalg.norm(r - exact, axis=1).max() < 1e-5
    assert np.abs(np.linalg.norm(n, axis=1) - tension).max() < 2e-6 * tension
    assert np.abs(np.cross(n, tangent)).max() < 1e-3 * tension


def test_a_uniform_nodal_load_is_the_uniform_dead_load(comm):
    """loads.NodalLoad with the same value at every node gives the dead load's slope
    right-hand side (assembly of int F.g with F linear)."""
    mesh = Mesh(comm, 13, 3.0, 2.0)
    field = VectorField(mesh, "nodes")
    try:
        f = np.array([0.3, -1.0, 2.0])
        nodal = NodalLoad(mesh, field)
        nodal.set(np.tile(f, (mesh.n_local_nodes, 1)))
        offset = np.array([1.0, 0.5, -2.0])
        dead = load_ghosted(mesh, lambda S: (3.0 - np.asarray(S))[..., None] * f + offset,
                            np.zeros(0))
        mine = scatter_element_vectors(mesh.ghost_end - mesh.ghost_start, mesh.element_local,
                                       P2, nodal.element_vectors(offset))
        assert np.abs(mine - dead).max() < 1e-13
        assert np.allclose(nodal.beyond_vertices(), (3.0 - mesh.vertex_S)[:, None] * f)
    finally:
        field.destroy()
        mesh.destroy()


# --- one rank and all ranks -----------------------------------------------------------------
RISER = dict(length=50.0, stiffness=(20.0, 20.0, 15.0), start="pin", end="pin",
             end_position=(35.0, 3.0, 20.0), load_values=[[0.0, 0.0, -1.0]],
             seabed=Seabed(0.0, 1e3),
             current=Current(np.array([0.0, 30.0]), np.array([[0.3, 0.4, 0.0],
                                                              [0.1, 0.0, 0.0]]), 20.0, 1.0))


def riser_output(problem, fields):
    """The riser numbers (a TermOutput): the first term output of a riser scene (the
    line's results and regions follow)."""
    output, *_ = problem.outputs(fields)
    return output


def riser_on(comm):
    """The RISER scene solved on ``comm`` with the default Anderson mixing (whose path
    round-off steers: the states agree to the iteration's tolerance); its vertex fields,
    riser numbers and iterations, gathered on every rank of comm."""
    mesh, solver = make_solver(comm, 100, RISER, default_penalty(Scene(**RISER)),
                               rtol=1e-11, ctol=1e-11, max_it=20000)
    try:
        solver.problem.state.set_straight()
        report = solver.solve_step(1.0)
        fields = vertex_fields(solver.problem)
        numbers = riser_output(solver.problem, fields)
        whole = {key: gather(comm, value) for key, value in
                 {**fields, **numbers.datasets}.items()}
        return report, whole, numbers.attributes, solver.problem.energy()
    finally:
        solver.destroy()
        solver.problem.destroy()
        mesh.destroy()


def test_one_rank_and_two_give_the_same_riser():
    report_1, fields_1, numbers_1, energy_1 = riser_on(PETSc.COMM_SELF)
    report_n, fields_n, numbers_n, energy_n = riser_on(PETSc.COMM_WORLD)
    assert report_1.converged and report_n.converged
    assert report_n.iterations == pytest.approx(report_1.iterations, rel=0.1)
    for key in ("r", "d3", "n", "effective_tension", "seabed_reaction"):
        scale = max(1.0, np.abs(fields_1[key]).max())
        assert np.abs(fields_1[key] - fields_n[key]).max() < 1e-8 * scale, key
    for key in ("top_tension", "top_angle", "touchdown_S", "grounded_length"):
        assert numbers_1[key] == pytest.approx(numbers_n[key], rel=1e-8, abs=1e-8), key
    assert energy_1 == pytest.approx(energy_n, rel=1e-10)
    assert numbers_1["grounded_length"] > 5.0              # it does rest on the seabed


def test_the_step_line_and_file_attributes_of_a_riser(comm, solver_factory):
    """The step line says the riser numbers; record_step hands the datasets to the writer."""
    mesh, solver, report = solved(solver_factory, comm, 40, GROUNDED, rtol=1e-9, ctol=1e-9)
    lines, written = [], {}

    class Writer:
        def write_step(self, group, vertex, state, history, attributes, units=None):
            written.update(vertex=vertex, attributes=attributes)

    record = record_step(solver.problem, report, 1.0, Writer(), "steps/1")
    event = StepEnded("step 1/1", 1.0, report, 1, 0, 0, report.iterations, 0, 0.0)
    lines.append(step_lines.step_line(event, record))
    lines.append(step_lines.step_details(event, record))
    attributes = record.attributes
    # the short line: the engineer's numbers as the file has them, and nothing else
    assert (f"top tension {attributes['top_tension'] / 1e3:.6g} kN at "
            f"{attributes['top_angle']:.2f} deg" in lines[0])
    assert f"touchdown S = {attributes['touchdown_S']:.6g} m" in lines[0]
    assert f"smallest bend radius {attributes['min_bend_radius']:.4g} m" in lines[0]
    assert "energy" not in lines[0] and "u3(0)" not in lines[0] and len(lines[0]) < 200
    # the details (-rod_al_monitor): the energy and the riser term's long text
    assert f"energy {record.energy:.10g} J" in lines[1] and "touchdown at S = " in lines[1]
    # an intermediate step says no riser numbers
    halfway = StepEnded("step 1/2", 0.5, report, 1, 0, 0, report.iterations, 0, 0.0)
    assert "top tension" not in step_lines.step_line(halfway, record)
    summary = step_lines.summary(attributes)
    assert summary[0] == "petsc_rod: at load factor 1:"
    assert f"grounded {attributes['grounded_length']:.6g} m" in summary[1]
    assert {"effective_tension", "seabed_reaction"} <= set(written["vertex"])
    assert {"top_tension", "top_angle", "touchdown_S", "touchdown_position", "max_curvature",
            "min_bend_radius", "grounded_length"} <= set(written["attributes"])


# --- a lazy wave in the small-EI limit --------------------------------------------------
# The 80 m cable of options/cable_80m.opts (bare / buoyancy / bare, an uplift on the
# buoyancy section), on a seabed stiff enough that it sinks by 1 micrometre: as EI -> 0
# the line tends to the catenary of its sections (scenes/section_catenary.py), with
# boundary layers of width sqrt(EI / T) at the touchdown and the ends.
CABLE_ENDS = [0.0, 52.101, 102.101, 170.215]
CABLE_WEIGHTS = [157.8003, -80.1525, 157.8003]


def cable(stiffness):
    return dict(length=170.215, stiffness=(stiffness,) * 3, start="pin", end="pin",
                end_position=(120.0, 0.0, 66.0), load_breaks=CABLE_ENDS[1:-1],
                load_values=[[0.0, 0.0, -w] for w in CABLE_WEIGHTS],
                seabed=Seabed(0.0, 157.8003e6))


def test_a_lazy_wave_tends_to_the_catenary_of_its_sections(comm, solver_factory):
    """Measured: the largest distance to the section catenary is 4.0e-3 m at EI = 100
    and 3.7e-4 m at EI = 1 N m^2, falling like sqrt(EI); the hang-off tension within
    1.5e-6 of it at EI = 1. Started from that catenary (starts.section_start)."""
    from petsc_rod.scenes.section_catenary import solve
    line = solve(CABLE_ENDS, CABLE_WEIGHTS, 120.0, 66.0, on_seabed=True)
    errors = []
    for stiffness in (100.0, 1.0):
        _, solver, report = solved(solver_factory, comm, 340, cable(stiffness),
                                   start="catenary", rtol=1e-9, ctol=1e-9)
        assert report.converged
        fields = vertex_fields(solver.problem)
        S, r, n = (gather(comm, fields[key]) for key in ("S", "r", "n"))
        x, z, V = line.at(S)
        errors.append(np.hypot(r[:, 0] - x, r[:, 2] - z).max())
        assert np.abs(r[:, 1]).max() == 0.0
    tension = np.hypot(line.H, line.at(170.215)[2])
    assert errors[1] < 1e-3 and errors[0] / errors[1] > 5.0        # sqrt(100) = 10
    assert abs(np.linalg.norm(n[-1]) - tension) < 1e-5 * tension
