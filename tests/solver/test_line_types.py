"""Line types and sections (-rod_line_types, -rod_sections; scenes/line.py, docs/riser.md):
the weight, drag and mesh they make, one bad input a case, and a line given by line
types against the same line given by load pieces. Serial and under mpiexec -n 2."""

import numpy as np
import pytest

from helpers import gather
from petsc_rod.errors import RodInputError

# The 80 m lazy-wave cable of issue 21 (Lozon et al. 2025) as its data sheet gives it:
# bare cable od 0.160 m, 36.70 kg/m; buoyancy section od 0.290 m, 59.53 kg/m.
CABLE_TYPES = """# name od mass ei gj ea cd
name   od     mass   ei      gj      ea      cd    drag_d
bare   0.160  36.70  1.99e4  1.99e4  inf     1.2   0.160
float  0.290  59.53  1.99e4  1.99e4  inf     1.0   0.300
"""
CABLE_SECTIONS = "bare:52.101:104,float:50:100,bare:68.114:136"
CABLE_ENDS = dict(rod_start="pin", rod_end="pin", rod_end_position="120,0,66",
                  rod_seabed="0")
# The same line given by hand as three load pieces (options/cable_80m.opts), N/m.
CABLE_LOADS = dict(rod_length="170.215", rod_stiffness="1.99e4,1.99e4,1.99e4",
                   rod_load="0,0,-157.8003,0,0,80.1525,0,0,-157.8003",
                   rod_load_breaks="52.101,102.101")


@pytest.fixture
def table(shared_tmp):
    """write(text) -> the path of a table holding ``text`` (on every rank)."""
    from mpi4py import MPI
    count = [0]

    def write(text):
        count[0] += 1
        path = f"{shared_tmp}/types{count[0]}.txt"
        if MPI.COMM_WORLD.rank == 0:
            with open(path, "w") as handle:
                handle.write(text)
        MPI.COMM_WORLD.Barrier()
        return path
    return write


def scene_of(options, **given):
    from petsc_rod.cli.scene_options import scene_from_options
    values, names = options(**given)()
    return scene_from_options(values, names), values


def test_the_sections_give_the_submerged_weight_drag_and_length(options, table):
    """(mass - rho pi od^2 / 4) g: 157.80 N/m bare (the issue's figure), -80.15 N/m with
    the buoyancy; c = rho Cd D / 2 per section; the length is the sections' sum."""
    scene, _ = scene_of(options, rod_line_types=table(CABLE_TYPES),
                        rod_sections=CABLE_SECTIONS, **CABLE_ENDS)
    assert scene.length == pytest.approx(170.215, abs=1e-12)
    weight = lambda mass, od: (mass - 1025 * np.pi * od**2 / 4) * 9.80665
    np.testing.assert_allclose(-scene.load_values[:, 2], [weight(36.70, 0.16),
                               weight(59.53, 0.29), weight(36.70, 0.16)], rtol=1e-15)
    assert abs(-scene.load_values[0, 2] - 157.80) < 0.005
    np.testing.assert_allclose(scene.load_breaks, [52.101, 102.101], rtol=1e-15)
    assert scene.uniform_stiffness and not scene.extensible
    drag = scene.drag_at(np.array([10.0, 60.0, 150.0]), current=None)
    np.testing.assert_allclose(drag, [0.5 * 1025 * 1.2 * 0.16, 0.5 * 1025 * 1.0 * 0.3,
                                      0.5 * 1025 * 1.2 * 0.16], rtol=1e-15)


def test_a_table_mixes_bending_forms_row_by_row(options, table):
    """A bend stiffener (tapered) beside a bare cable (isotropic) and an anisotropic
    section: each row gives one form, the others left blank ('-'); the stiffness along S
    is each section's, linear along the taper."""
    types = ("name      od   mass  gj    ei   ei1  ei2  ei_start  ei_end\n"
             "stiffener 0.5  80    1e4   -    -    -    1e6       2e4\n"
             "bare      0.16 36.7  1e4   2e4  -    -    -         -\n"
             "flat      0.16 36.7  1e4   -    1e4  4e4  -         -\n")
    scene, _ = scene_of(options, rod_line_types=table(types),
                        rod_sections="stiffener:10,bare:100,flat:50", **CABLE_ENDS)
    K = scene.stiffness_at(np.array([0.0, 5.0, 10.0, 50.0, 135.0]))
    np.testing.assert_allclose(K[:, 0], [1e6, 0.5 * (1e6 + 2e4), 2e4, 2e4, 1e4], rtol=1e-15)
    np.testing.assert_allclose(K[:, 1], [1e6, 0.5 * (1e6 + 2e4), 2e4, 2e4, 4e4], rtol=1e-15)
    assert np.all(K[:, 2] == 1e4) and not scene.uniform_stiffness


def test_every_section_end_is_a_vertex(options, table, comm):
    from petsc_rod.cli.scene_options import mesh_pieces
    from petsc_rod.mesh.mesh import Mesh
    scene, values = scene_of(options, rod_line_types=table(CABLE_TYPES),
                             rod_sections="bare:52.101:7,float:50,bare:68.114",
                             rod_elements="100", **CABLE_ENDS)
    pieces = mesh_pieces(values, scene)
    assert pieces.counts[0] == 7 and pieces.counts.sum() == 100
    mesh = Mesh(comm, int(pieces.counts.sum()), scene.length, pieces=pieces)
    try:
        S = gather(comm, mesh.vertex_S)
        for end in (0.0, 52.101, 102.101, 170.215):
            assert np.min(np.abs(S - end)) == 0.0
        assert mesh.global_sum(mesh.element_h.sum()) == pytest.approx(scene.length, rel=1e-14)
    finally:
        mesh.destroy()


BAD = {
    "an unknown line type": (dict(rod_sections="bare:52.101,pipe:118.114"),
                             "unknown line type 'pipe'"),
    "sections that do not add up to -rod_length": (
        dict(rod_sections=CABLE_SECTIONS, rod_length="170"), "add up to 170.215 m"),
    "a zero ea": ("name od mass ei gj ea\nbare 0.16 36.7 1.99e4 1.99e4 0\n", "ea 0 must be"),
    "a negative od": ("name od mass ei gj\nbare -0.16 36.7 1.99e4 1.99e4\n", "od -0.16 must"),
    "a zero ei": ("name od mass ei gj\nbare 0.16 36.7 0 1.99e4\n", "ei 0 must be positive"),
    "a missing column": ("name od ei gj\nbare 0.16 1.99e4 1.99e4\n", "no column mass"),
    "an unknown column": ("name od mass ei gj colour\nbare 0.16 36.7 1 1 red\n",
                          "unknown column 'colour'"),
    "no bending stiffness": ("name od mass gj\nbare 0.16 36.7 1\n", "bending stiffness"),
    "two bending forms in a row": ("name od mass gj ei ei_start ei_end\nbare 0.16 36.7 1 1 2 1\n",
                                   "line type bare: give its bending stiffness"),
    "half a taper": ("name od mass gj ei_start ei_end\nbare 0.16 36.7 1 2 -\n",
                     "line type bare: give its bending stiffness"),
    "an id as large as the od": ("name od id mass ei gj\nbare 0.16 0.16 36.7 1 1\n",
                                 "id 0.16 must be"),
    "contents without line types": (dict(rod_sections=None, rod_line_types=None,
                                         rod_contents_density="800", rod_length="10",
                                         rod_load="0,0,-1"),
                                    "-rod_contents_density needs -rod_sections"),
    "a blank od": ("name od mass gj ei\nbare - 36.7 1 1\n", "column od is required"),
    "a short row": ("name od mass ei gj\nbare 0.16 36.7 1\n", "line 2 has 4 values"),
    # a row is named by its line in the file, comments counted
    "a short row after comments": ("# a data sheet\n\nname od mass ei gj\n# bare cable\n"
                                   "bare 0.16 36.7 1\n", "line 5 has 4 values"),
    "a word after comments": ("# sheet\nname od mass ei gj\n\nbare 0.16 heavy 1 1\n",
                              "line 4, column mass: 'heavy' is not a number"),
    "a word for a number": ("name od mass ei gj\nbare 0.16 heavy 1 1\n", "'heavy' is not"),
    "-rod_stiffness with sections": (dict(rod_sections="bare:10", rod_stiffness="1,1,1"),
                                     "-rod_stiffness with -rod_sections"),
    "-rod_load with sections": (dict(rod_sections="bare:10", rod_load="0,0,-1"),
                                "-rod_load with -rod_sections"),
    "a section of no length": (dict(rod_sections="bare:0"), "must be positive"),
    "a section of half an element": (dict(rod_sections="bare:10:0.5"), "whole number"),
    "sections without types": (dict(rod_sections="bare:10", rod_line_types=None),
                               "-rod_sections needs -rod_line_types"),
    # a table obeys the options' bounds (-rod_stiffness refuses below 1e-30, above 1e30)
    "an ei of 1e-300": ("name od mass ei gj\nbare 0.16 36.7 1e-300 1\n",
                        "ei 1e-300 must be positive (at least 1e-30"),
    "a gj of 1e-300": ("name od mass ei gj\nbare 0.16 36.7 1 1e-300\n",
                       "gj 1e-300 must be positive (at least 1e-30"),
    "an ea of 1e31": ("name od mass ei gj ea\nbare 0.16 36.7 1 1 1e31\n",
                      "ea 1e+31 is out of range"),
    "a mass of 1e300": ("name od mass ei gj\nbare 0.16 1e300 1 1\n",
                        "mass 1e+300 is out of range"),
    # a setting that does nothing without its partner in the line types
    "an internal pressure without an id": (dict(rod_internal_pressure="1e7"),
                                           "-rod_internal_pressure needs a line type with "
                                           "an id column"),
    "contents without an id": (dict(rod_contents_density="800"),
                               "-rod_contents_density needs a line type with an id"),
    "a design factor without smys": (dict(rod_design_factor="0.8"),
                                     "-rod_design_factor needs a line type with an smys"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_line_types_and_sections_are_refused_in_one_line(options, table, case):
    from petsc_rod.cli.scene_options import scene_from_options
    change, words = BAD[case]
    given = {**CABLE_ENDS, "rod_line_types": table(CABLE_TYPES), "rod_sections": "bare:10",
             "rod_end_position": "5,0,5"}
    if isinstance(change, str):
        given["rod_line_types"] = table(change)
    else:
        given.update(change)
    given = {key: value for key, value in given.items() if value is not None}
    values, names = options(**given)()
    with pytest.raises(RodInputError) as error:
        scene_from_options(values, names)
    message = str(error.value)
    assert words in message and "\n" not in message, message


# Advice on a line of sections names what the user can change there, never an option
# petsc_rod refuses beside -rod_sections (-rod_length, -rod_load, -rod_axial_stiffness,
# -rod_drag: SECTION_REPLACES).
ADVICE = {
    "ends farther apart than the sections": (dict(rod_end_position="12,0,0"),
                                             "the line types an ea column"),
    "ends held taut": (dict(rod_end_position="10,0,0"), "the line types an ea column"),
    "a floating line on a seabed without a stiffness": (dict(rod_sections="float:10"),
                                                       "no line type sinks"),
    "a point beyond the line": (dict(rod_point_load="12,0,0,-5"), "L = 10 m, its length"),
}


@pytest.mark.parametrize("case", list(ADVICE))
def test_advice_on_sections_names_what_the_sections_take(options, table, case):
    from petsc_rod.cli.scene_options import SECTION_REPLACES, scene_from_options
    change, words = ADVICE[case]
    given = {**CABLE_ENDS, "rod_line_types": table(CABLE_TYPES), "rod_sections": "bare:10",
             "rod_end_position": "5,0,5", **change}
    values, names = options(**given)()
    with pytest.raises(RodInputError) as error:
        scene_from_options(values, names)
    message = str(error.value)
    assert words in message, message
    for name in list(SECTION_REPLACES) + ["rod_length"]:
        assert f"-{name} " not in message + " " and f"-{name};" not in message, message


def solved_cable(options, given, comm):
    """r and the effective tension of the 80 m cable from its catenary start, and the
    step's iterations."""
    from petsc_rod.cli.scene_options import mesh_pieces, scene_from_options
    from petsc_rod.io.outputs import vertex_fields
    from petsc_rod.iteration.driver import solver_for
    from petsc_rod.iteration.stopping import Settings
    from petsc_rod.mesh.mesh import Mesh, Pieces
    from petsc_rod.problem.penalty import default_penalty
    from petsc_rod.scenes.starts import catenary_start
    values, names = options(**given)()
    scene = scene_from_options(values, names)
    pieces = mesh_pieces(values, scene) or Pieces(np.cumsum([0, 52.101, 50, 68.114]),
                                                  [104, 100, 136])
    mesh = Mesh(comm, 340, scene.length, pieces=pieces)
    solver = solver_for(mesh, scene, Settings(asked_penalty=default_penalty(scene),
                                              rtol=1e-10, ctol=1e-10))
    try:
        solver.problem.state.set_from_curve(catenary_start(scene, 1.0))
        report = solver.solve_step(1.0)
        fields = vertex_fields(solver.problem)
        tension = np.einsum("nc,nc->n", fields["n"], fields["d3"])
        return gather(comm, fields["r"]), gather(comm, tension), report
    finally:
        solver.destroy()
        solver.problem.destroy()
        mesh.destroy()


def test_a_line_of_line_types_is_the_line_of_its_load_pieces(options, table, comm):
    """The cable by line types and by the load pieces computed by hand (7 digits): the
    same shape and tension to the loads' rounding (2e-7), on a mesh of the same vertices
    (uniform per section in both: 104, 100 and 136 elements)."""
    r_types, tension_types, report = solved_cable(
        options, dict(rod_line_types=table(CABLE_TYPES), rod_sections=CABLE_SECTIONS,
                      **CABLE_ENDS), comm)
    assert report.converged
    from petsc4py import PETSc
    for key in ("rod_line_types", "rod_sections"):
        PETSc.Options().delValue(key)
    r_loads, tension_loads, report = solved_cable(
        options, dict(**CABLE_LOADS, **CABLE_ENDS), comm)
    assert report.converged
    assert np.abs(r_types - r_loads).max() < 2e-7 * 170.215
    assert np.abs(tension_types - tension_loads).max() < 2e-7 * np.abs(tension_loads).max()


def test_a_result_file_rebuilds_its_sections_from_its_own_copy_of_the_table(options, table):
    """A restart rebuilds the file's scene from the table the file holds
    (line_types_table), not from a file that may have changed or gone since."""
    from petsc_rod.cli.scene_options import scene_from_parameters
    path = table(CABLE_TYPES)
    scene, values = scene_of(options, rod_line_types=path, rod_sections=CABLE_SECTIONS,
                             **CABLE_ENDS)
    parameters = {key.removeprefix("rod_"): ("" if value is None else value)
                  for key, value in values.items()}
    parameters.update(line_types=path + ".gone", length=scene.length, end_position=[120, 0, 66],
                      line_types_table=CABLE_TYPES)
    rebuilt = scene_from_parameters(parameters)
    assert [s.name for s in rebuilt.sections] == ["bare", "float", "bare"]
    np.testing.assert_array_equal(rebuilt.load_values, scene.load_values)
    assert rebuilt.length == scene.length


@pytest.mark.parametrize("sections, words", [
    ((("a", 0.0, 4.0, 1.0), ("b", 5.0, 10.0, 1.0)), "follow each other"),
    ((("a", 0.0, 4.0, 1.0), ("b", 4.0, 9.0, 1.0)), "follow each other"),
    ((("a", 0.0, 4.0, 1.0), ("b", 4.0, 10.0, -1.0)), "must be positive")])
def test_sections_given_in_python_are_checked(sections, words):
    """A Python caller's sections must tile [0, L] with positive stiffnesses."""
    from petsc_rod.scenes.line import Section
    from petsc_rod.scenes.scene import Scene
    scene = Scene(length=10.0, stiffness=[1.0, 1.0, 1.0],
                  sections=tuple(Section(name, lo, hi, [k, k, k], [k, k, k])
                                 for name, lo, hi, k in sections))
    with pytest.raises(RodInputError, match=words):
        scene.validate(set())


def test_a_stiff_section_beside_a_soft_one_keeps_its_own_curvature(options, table, comm):
    """Review of issue 22: the vertex strain is the mean of both sides, so the stiff
    section was charged with half the soft one's curvature at their common vertex (bend
    radius 396 m for the true 1e4 m). A cantilever of two sections (EI 1e4, then 1e2
    N m^2) under a small tip force P = 0.1 N: the largest curvature of each is its
    largest M / EI, P L / EI at its clamped end for the stiff one (1e-4 1/m at S = 0), and
    P (L - 5) / EI at the section end for the soft one (5e-3 1/m at S = 5)."""
    from petsc_rod.cli.scene_options import mesh_pieces, scene_from_options
    from petsc_rod.io.outputs import vertex_fields
    from petsc_rod.iteration.driver import solver_for
    from petsc_rod.iteration.stopping import Settings
    from petsc_rod.mesh.mesh import Mesh
    from petsc_rod.problem.penalty import default_penalty
    from petsc_rod.quantities.section_numbers import SectionNumbers
    types = "name od mass ei gj\nstiff 0.1 10 1e4 1e4\nsoft 0.1 10 1e2 1e2\n"
    values, names = options(rod_line_types=table(types), rod_sections="stiff:5:50,soft:5:50",
                            rod_gravity="1e-12", rod_start="clamp", rod_end="free",
                            rod_end_force="0,0,-0.1")()
    scene = scene_from_options(values, names)
    mesh = Mesh(comm, 100, scene.length, pieces=mesh_pieces(values, scene))
    solver = solver_for(mesh, scene, Settings(asked_penalty=default_penalty(scene)))
    try:
        solver.problem.state.set_straight()
        assert solver.solve_step(1.0).converged
        term = [t for t in solver.problem.reports if isinstance(t, SectionNumbers)][0]
        numbers = term.outputs(solver.problem, vertex_fields(solver.problem)).attributes
    finally:
        solver.destroy()
        solver.problem.destroy()
        mesh.destroy()
    np.testing.assert_allclose(numbers["section_max_curvature"], [1e-4, 5e-3], rtol=1e-4)
    np.testing.assert_array_equal(numbers["section_max_curvature_S"], [0.0, 5.0])


@pytest.mark.parametrize("sections, elements, words", [
    ("bare:52.101:104,float:50:100,bare:68.114:136", "1000", "gives every section its"),
    ("bare:170.215,float:1e-12", "100", "below what double precision resolves"),
    # a mesh that cannot represent the line: a section of one element (issue 47)
    ("bare:20:40,float:150", "10", r"-rod_elements 10: .*needs at least one .* give "
                                    r"-rod_elements 41 or more"),
    ("bare:20:40,float:150", "41", r"-rod_elements 41: section 2 \(float, 150 m\) has 1 "
                                    r"element\(s\) of 150 m, .* cannot represent .* give "
                                    r"-rod_elements 45 or more .*float:150:4\)"),
    ("bare:20:40,float:150:3", "43", r"-rod_sections: section 2 \(float, 150 m\) has 3 "
                                      r"element\(s\) of 50 m.* at least 4 elements"),
    ("bare:1:70,float:169", None, r"-rod_sections \(the default -rod_elements 64\): "
                                   r"section 2 .* has 1 element"),
])
def test_element_counts_that_cannot_be_are_refused(options, table, sections, elements, words):
    """Review of issue 22: -rod_elements was silently ignored when every section gave
    its count, and a 1e-14 m section built a 1e-14 m element."""
    from petsc_rod.cli.scene_options import mesh_pieces, scene_from_options
    count = {} if elements is None else {"rod_elements": elements}
    values, names = options(rod_line_types=table(CABLE_TYPES), rod_sections=sections,
                            **count, **CABLE_ENDS)()
    scene = scene_from_options(values, names)
    with pytest.raises(RodInputError, match=words):
        mesh_pieces(values, scene, names)


def test_the_shares_of_the_elements_add_up():
    """-rod_elements 200 on sections of 300, 200, 290 and 10 m gave 199 elements."""
    from petsc_rod.scenes.line import section_elements
    counts = section_elements([300, 200, 290, 10], [None] * 4, 200)
    assert counts.sum() == 200 and counts.min() >= 1
    assert list(section_elements([1.0, 2.0], [5, None], 11)) == [5, 6]
