"""A mooring line with seabed friction given either way round (docs/riser.md §3b, "The
path"): from its anchor to its fairlead, and from its fairlead to its anchor (End A at
the vessel, as OrcaFlex users give it). The reversed line is the same line, so it must
reach the mirror image of the forward one's equilibrium, with the anchor's chain in
tension. Before the chains of the positions ran from the lower end
(global_step/centreline.chains_from_start) the reversed line's Newton steps found H
indefinite and its halved path ended with the chain compressed at the anchor. Spawns
processes: marked ``serial``."""

import h5py
import numpy as np
import pytest

from helpers import describe, run_petsc_rod

pytestmark = pytest.mark.serial

TIMEOUT = 300
# 500 m of the fairlead's 850 m grounded at mu = 0.5 (the lead's measured case: 108 m
# stick, 392 m slide, the anchor holds +39.04 kN)
LINE = ["-rod_line_types", "options/line_types/mooring_chain.txt",
        "-rod_sections", "chain120:850:170", "-rod_seabed_friction", "0.5",
        "-rod_start", "pin", "-rod_end", "pin"]
FORWARD = LINE + ["-rod_end_position", "780,0,186", "-rod_seabed", "0",
                  "-rod_sea_surface", "200"]
REVERSED = LINE + ["-rod_end_position", "780,0,-186", "-rod_seabed", "-186",
                   "-rod_sea_surface", "14"]
FAIRLEAD = np.array([780.0, 0.0, 186.0])


def solved(tmp_path, name, args, ranks):
    """(r (n, 3), effective tension (n,), the file's attributes) of a converged run."""
    path = tmp_path / f"{name}.h5"
    done = run_petsc_rod(args + ["-rod_output", str(path)], ranks, TIMEOUT)
    assert done.returncode == 0, describe(done)
    with h5py.File(path, "r") as f:
        return f["r"][()], f["effective_tension"][()], dict(f.attrs)


def mirrored(r):
    """The forward line's r as the reversed line's: its nodes from the fairlead, which
    is at the origin, and the anchor toward +x."""
    image = r[::-1] - FAIRLEAD
    image[:, 0] *= -1.0
    return image


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_line_given_from_its_fairlead_is_the_mirror_of_one_given_from_its_anchor(
        tmp_path, ranks):
    shape = ["-rod_initial_shape", "catenary"]
    r_forward, _, forward = solved(tmp_path, "forward", FORWARD + shape, ranks)
    r_reversed, tension, reversed_ = solved(tmp_path, "reversed", REVERSED + shape, ranks)
    assert forward["converged"] == 1 and reversed_["converged"] == 1
    assert np.max(np.abs(r_reversed - mirrored(r_forward))) < 1e-6
    assert reversed_["anchor_tension"] == pytest.approx(39.04e3, rel=2e-3)
    assert reversed_["anchor_tension"] == pytest.approx(forward["anchor_tension"], rel=1e-6)
    # the chain pulls on its anchor (the compressed answer had -37.2 kN there)
    assert tension[-1] > 35e3
    # as few iterations as the forward line (23 measured, 7 of them Newton steps)
    assert reversed_["iterations"] <= forward["iterations"] + 5


@pytest.mark.parametrize("ranks", [1, 2])
def test_the_straight_start_lays_the_anchors_on_the_catenary(tmp_path, ranks):
    """The friction's anchors are the catenary between the ends whatever the start shape
    (problem/build.lay_friction_anchors): from the straight start (a line along x, 70 m
    past the anchor, which made every grounded node slide and compressed the chain) the
    reversed line reaches the catenary start's equilibrium."""
    r_straight, tension, straight = solved(
        tmp_path, "straight", REVERSED + ["-rod_initial_shape", "straight"], ranks)
    r_catenary, _, catenary = solved(
        tmp_path, "catenary", REVERSED + ["-rod_initial_shape", "catenary"], ranks)
    assert straight["converged"] == 1
    assert np.max(np.abs(r_straight - r_catenary)) < 1e-6
    assert straight["anchor_tension"] == pytest.approx(catenary["anchor_tension"], rel=1e-6)
    assert tension[-1] > 35e3


def test_solver_for_lays_the_anchors_as_the_command_line(tmp_path):
    """iteration/driver.solver_for (the scripts' and tests' entry) lays the friction's
    anchors on the catenary through the command line's function
    (problem/build.lay_friction_anchors): the reversed line from the straight start
    reaches the command line's anchor force to 1e-6. Before, its anchors were the
    straight start's own positions, and the chain ended compressed at the anchor
    (-37.2 kN)."""
    from petsc4py import PETSc

    from helpers import continuation, destroy
    from petsc_rod.cli.options import parse_values
    from petsc_rod.cli.scene_options import scene_from_options, settings_from_options
    from petsc_rod.io.outputs import vertex_fields
    from petsc_rod.iteration.driver import solver_for
    from petsc_rod.mesh.mesh import Mesh

    args = REVERSED + ["-rod_initial_shape", "straight"]
    _, _, cli = solved(tmp_path, "straight", args, 1)
    texts = dict(zip((a[1:] for a in args[0::2]), args[1::2]))
    values = parse_values(texts)
    scene = scene_from_options(values, set(texts))
    mesh = Mesh(PETSc.COMM_SELF, 170, scene.length)
    solver = solver_for(mesh, scene, settings_from_options(values, scene))
    try:
        assert continuation(solver, values["rod_steps"]).converged
        attributes = {}
        for output in solver.problem.outputs(vertex_fields(solver.problem)):
            attributes.update(output.attributes)
    finally:
        destroy(mesh, solver)
    assert cli["anchor_tension"] > 35e3
    assert attributes["anchor_tension"] == pytest.approx(cli["anchor_tension"], rel=1e-6)


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_line_given_from_its_fairlead_in_two_load_steps_is_still_the_mirror(
        tmp_path, ranks):
    """The anchors are the line as laid between the user's ends (problem/build.
    lay_friction_anchors, every step's), so the load steps, a continuation from the
    straight reference, leave the answer as it is: in two steps the line given from its fairlead, which
    hangs clear of the seabed at the first step's load factor, reaches the mirror of the
    forward line's one step (with the anchors laid at the first step and moved at its end
    every grounded node slid: the anchor 37.26 kN, r 2.9 mm off)."""
    shape = ["-rod_initial_shape", "catenary"]
    r_forward, _, forward = solved(tmp_path, "forward", FORWARD + shape, ranks)
    r_reversed, tension, reversed_ = solved(
        tmp_path, "reversed", REVERSED + shape + ["-rod_steps", "2"], ranks)
    assert reversed_["converged"] == 1
    assert np.max(np.abs(r_reversed - mirrored(r_forward))) < 1e-6
    assert reversed_["anchor_tension"] == pytest.approx(forward["anchor_tension"], rel=1e-6)
    assert reversed_["friction_stick_nodes"] == forward["friction_stick_nodes"] > 0


@pytest.mark.parametrize("ranks", [1, 2])
def test_the_line_across_a_current_from_the_straight_start_is_the_catenary_starts(
        tmp_path, ranks):
    """The forward line across a 0.4 m/s current from the straight start reaches the
    catenary start's equilibrium in one step and in two (docs/riser.md §3b, "From the
    straight start"): its Newton attempt near the solution goes on after its first step
    (taken with the iteration's curvature) where |grad L| fell twentyfold and the next
    turn was 4 % larger (newton.py, ``settling``), and the anchors of the step at t = 1/2
    are the line as laid between the user's ends (problem/build.lay_friction_anchors).
    Before, every attempt failed (2000 iterations each, halved to t = 1/16, exit 3)."""
    current = FORWARD + ["-rod_current", "0,0.4,0"]
    r_catenary, _, catenary = solved(
        tmp_path, "catenary", current + ["-rod_initial_shape", "catenary"], ranks)
    assert catenary["converged"] == 1
    # 43 of 200 grounded nodes stick, the anchor holds 39.32 kN (measured)
    assert catenary["anchor_tension"] == pytest.approx(39.32e3, rel=1e-3)
    for steps in ("1", "2"):
        r, _, straight = solved(tmp_path, f"straight{steps}", current + [
            "-rod_initial_shape", "straight", "-rod_steps", steps], ranks)
        assert straight["converged"] == 1 and straight["total_halvings"] == 0
        assert np.max(np.abs(r - r_catenary)) < 1e-6
        assert straight["anchor_tension"] == pytest.approx(catenary["anchor_tension"],
                                                           rel=1e-6)
        assert straight["friction_stick_nodes"] == catenary["friction_stick_nodes"]
