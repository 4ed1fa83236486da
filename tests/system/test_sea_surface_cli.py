"""The sea surface (-rod_sea_surface, docs/riser.md §2a and §9) on attachments and on a
uniform line, end to end: an attachment above the surface has neither buoyancy nor
drag, one under it both (physics/point_loads.py), against the closed-form catenary of
the pieces and points; the result file's point_loads_table keeps the volumes so that a
restart from it rebuilds the same attachments; a uniform line (-rod_load) with a held
end above the surface is refused in one line (it cannot weigh its weight in air)."""

import h5py
import numpy as np
import pytest
from scipy.optimize import fsolve

from helpers import describe, run_petsc_rod
from test_hostile_cli import assert_one_line_and_nothing_left

TIMEOUT = 240
G, RHO = 9.80665, 1025.0
CABLE_TYPE = "name od mass ei gj cd\ncable 0.1 10.0 10.0 10.0 1.0\n"
# the cable's weights under water and in air, N/m
WEIGHTS = ((10.0 - RHO * np.pi * 0.1**2 / 4) * G, 10.0 * G)
# two attachments of 2 kg and 10 l with a drag area of 1 m^2: one deep, one in the air
POINTS = "s mass volume cda name\n40 2 0.01 1 deep\n95 2 0.01 1 high\n"
CHORD, SURFACE, LENGTH = (80.0, 0.0, 30.0), 15.0, 100.0


def catenary_with_points(points, surface=SURFACE):
    """(H, V0, S_b): the inextensible cable pinned at the origin and at CHORD, WEIGHTS[0]
    per metre under the surface z = ``surface`` and WEIGHTS[1] above it, with the point
    forces ``points`` [(S_p, P_z)] (N, up): n = (H, 0, V(S)), V(S) = V0 + int_0^S w
    - sum P_z [S > S_p], each piece of constant w a catenary in closed form (x: H/w asinh,
    z: |n| / w); S_b where it crosses the surface."""
    def ends(H, V0, S_b):
        cuts = sorted({0.0, S_b, LENGTH, *(s for s, _ in points)})
        x = z = 0.0
        V = V0
        heights = {}
        for a, b in zip(cuts[:-1], cuts[1:]):
            V -= sum(p for s, p in points if s == a)     # n jumps by -P at S_p
            w = WEIGHTS[0] if a < S_b else WEIGHTS[1]
            x += H / w * (np.arcsinh((V + w * (b - a)) / H) - np.arcsinh(V / H))
            z += (np.hypot(H, V + w * (b - a)) - np.hypot(H, V)) / w
            V += w * (b - a)
            heights[b] = z
        return x, z, heights[S_b]

    def equations(v):
        x, z, z_b = ends(*v)
        return [z_b - surface, x - CHORD[0], z - CHORD[2]]

    return fsolve(equations, [1000.0, -500.0, 0.8 * LENGTH], xtol=1e-14)


def surface_run(tmp_path, args, ranks=1, elements=400, name="surface.h5"):
    """The process and the path of the cable of CABLE_TYPE from a pin 15 m under
    -rod_sea_surface 15 to one at CHORD, with ``args``."""
    types = tmp_path / "cable.txt"
    types.write_text(CABLE_TYPE)
    path = tmp_path / name
    done = run_petsc_rod(["-rod_line_types", str(types), "-rod_sections",
                          f"cable:{LENGTH:g}:{elements}", "-rod_start", "pin", "-rod_end",
                          "pin", "-rod_end_position", ",".join(f"{c:g}" for c in CHORD),
                          "-rod_sea_surface", f"{SURFACE:g}", "-rod_initial_shape",
                          "catenary", *args, "-rod_output", str(path)], ranks, TIMEOUT)
    return done, path


def last_step(path):
    """The attributes of the last step of the result file ``path``."""
    with h5py.File(path) as f:
        return dict(f["steps"][max(f["steps"], key=int)].attrs)


def with_points(tmp_path, args=(), ranks=1, elements=400):
    """The last step's attributes of the cable through the surface with POINTS."""
    table = tmp_path / "points.txt"
    table.write_text(POINTS)
    done, path = surface_run(tmp_path, ["-rod_point_loads", str(table), *args], ranks,
                             elements)
    assert done.returncode == 0, describe(done)
    return last_step(path)


# the deep point's net lift (rho_w V - m) g and the high one's weight -m g, N
LIFT, WEIGHT = (RHO * 0.01 - 2.0) * G, -2.0 * G


@pytest.mark.parametrize("ranks", [1, 2])
def test_an_attachment_out_of_the_water_has_no_buoyancy(tmp_path, ranks):
    """POINTS on the cable through the surface: the deep one pulls up by
    (rho_w V - m) g = 80.9 N, the high one (10 m above the surface) down by its weight
    m g = 19.6 N (before: up by 80.9 N as well, its buoyancy kept in the air: the top
    carried 100.5 N less). The reactions are the closed-form catenary's of the pieces
    and points at 400 elements (measured on 1 and 2 ranks alike: H within 1.8e-4 of
    itself, the anchor's vertical force within 0.011 N, the top's within 0.84 N of
    2598.1 N, about the line alone's 0.57 N in test_riser_cli.py)."""
    attributes = with_points(tmp_path, (), ranks)
    np.testing.assert_allclose(attributes["point_load_wet"], [1.0, 0.0], atol=1e-14)
    np.testing.assert_allclose(attributes["point_load_force"][:, 2], [LIFT, WEIGHT],
                               rtol=1e-14)
    H, V0, S_b = catenary_with_points([(40.0, LIFT), (95.0, WEIGHT)])
    start, end = attributes["start_force"], attributes["end_force"]
    assert start[0] == pytest.approx(H, rel=5e-4)
    assert start[2] == pytest.approx(V0, abs=0.05)
    top = V0 + WEIGHTS[0] * S_b + WEIGHTS[1] * (LENGTH - S_b) - LIFT - WEIGHT
    assert -end[2] == pytest.approx(top, abs=1.5)


def test_an_attachment_out_of_the_water_has_no_drag(tmp_path):
    """The same in a current of 0.05 m/s across the cable's plane, at 200 elements:
    across the plane the supports carry the drag of the wet length c U^2 S_b and of the
    deep point 1/2 rho_w C_d A U^2 = 1.28 N only (before: of both points; measured
    within 2.1e-4 of the sum, 11.97 N); the reactions in the plane those of the
    catenary (H within 3.3e-4, the top within 1.8 N)."""
    attributes = with_points(tmp_path, ["-rod_current", "0,0.05,0"], elements=200)
    drag = 0.5 * RHO * 1.0 * 0.05**2
    assert attributes["point_load_drag"][:, 1] == pytest.approx([drag, 0.0], abs=1e-12)
    H, V0, S_b = catenary_with_points([(40.0, LIFT), (95.0, WEIGHT)])
    start, end = attributes["start_force"], attributes["end_force"]
    assert start[1] + end[1] == pytest.approx(51.25 * 0.05**2 * S_b + drag, rel=1e-3)
    assert start[0] == pytest.approx(H, rel=1e-3)
    top = V0 + WEIGHTS[0] * S_b + WEIGHTS[1] * (LENGTH - S_b) - LIFT - WEIGHT
    assert -end[2] == pytest.approx(top, abs=2.5)


def test_a_restart_rebuilds_the_attachments_with_their_volumes(tmp_path):
    """The result file's point_loads_table holds the volumes (its sixth column), so that
    the scene rebuilt from the file has the run's attachments: a restart from it with
    the same options walks nothing (before, the volumes were lost). A file of the older
    five columns still reads (volumes zero: the buoyancy it kept everywhere), and a
    restart from it walks to this run's volumes, said in one line."""
    from petsc_rod.cli.scene_options import scene_from_parameters
    from petsc_rod.io.results import _parameters

    table = tmp_path / "points.txt"
    table.write_text(POINTS)
    args = ["-rod_point_loads", str(table)]
    done, path = surface_run(tmp_path, args, elements=100, name="first.h5")
    assert done.returncode == 0, describe(done)
    parameters = _parameters(str(path))[0]
    np.testing.assert_array_equal(parameters["point_loads_table"][:, 5], [0.01, 0.01])
    rebuilt = scene_from_parameters(parameters)
    np.testing.assert_array_equal(rebuilt.point_load_volumes, [0.01, 0.01])
    again, second = surface_run(tmp_path, args + ["-rod_initial", str(path)],
                                elements=100, name="second.h5")
    assert again.returncode == 0, describe(again)
    assert "restart: walks" not in again.stdout + again.stderr
    np.testing.assert_allclose(last_step(second)["end_force"], last_step(path)["end_force"],
                               rtol=1e-8)
    with h5py.File(path, "r+") as f:                       # as an older version wrote it
        f["parameters"].attrs["point_loads_table"] = parameters["point_loads_table"][:, :5]
    old = scene_from_parameters(_parameters(str(path))[0])
    np.testing.assert_array_equal(old.point_load_volumes, [0.0, 0.0])
    walked, third = surface_run(tmp_path, args + ["-rod_initial", str(path)],
                                elements=100, name="third.h5")
    assert walked.returncode == 0, describe(walked)
    assert "the attachments' volumes (-rod_point_loads)" in walked.stdout + walked.stderr
    np.testing.assert_allclose(last_step(third)["end_force"], last_step(second)["end_force"],
                               rtol=1e-6)


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_buoy_floats_at_the_surface_in_one_step(tmp_path, ranks):
    """A buoy of 0.5 m^3 and 20 kg at the middle of the cable, its two pins 60 m apart
    on the plane 15 m under -rod_sea_surface: it floats, part of it out of the water.
    Its wet fraction is read at the iterate's heights, as the line's buoyancy in air
    (physics/iterate_heights.py), so that the mixing sees it: the run converges in its
    one step (measured 529 iterations at 200 elements, w = 0.2908 with the buoy's centre
    0.14 m above the surface; before, with the heights of the last global step, the
    iteration cycled: 4 halvings, not converged at load factor 0.125, exit 3). The
    reported w is the sphere's cap at the reported height, and the buoy's force its
    part-wet lift (rho_w V w - m) g."""
    types, table = tmp_path / "cable.txt", tmp_path / "buoy.txt"
    types.write_text(CABLE_TYPE)
    table.write_text("s mass volume cda name\n50 20 0.5 0 buoy\n")
    path = tmp_path / "buoy.h5"
    done = run_petsc_rod(["-rod_line_types", str(types), "-rod_sections", "cable:100:200",
                          "-rod_start", "pin", "-rod_end", "pin", "-rod_end_position",
                          "60,0,0", "-rod_sea_surface", "15", "-rod_initial_shape",
                          "catenary", "-rod_point_loads", str(table), "-rod_output",
                          str(path)], ranks, TIMEOUT)
    assert done.returncode == 0, describe(done)
    assert "0 halving(s) of the step" in done.stdout + done.stderr
    from petsc_rod.physics.point_loads import wet_fraction

    attributes = last_step(path)
    (wet,), height = attributes["point_load_wet"], attributes["point_load_position"][0, 2]
    assert 0.1 < wet < 0.9 and abs(height - SURFACE) < 0.49
    assert wet == pytest.approx(float(wet_fraction(height - SURFACE, 0.5)), abs=1e-6)
    assert attributes["point_load_force"][0, 2] == pytest.approx(
        (RHO * 0.5 * wet - 20.0) * G, rel=1e-12)
    assert attributes["start_force"][2] == pytest.approx(attributes["end_force"][2], rel=1e-6)


# a uniform line (-rod_load) from a pin at the origin to one 10 m across and 25 m down,
# in a current of one row (uniform in depth) measured from -rod_sea_surface
UNIFORM = ["-rod_length", "30", "-rod_stiffness", "1,1,1", "-rod_start", "pin", "-rod_end",
           "pin", "-rod_end_position", "10,0,-25", "-rod_load", "0,0,-10", "-rod_drag",
           "1025,1.2,0.1", "-rod_elements", "60"]


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_uniform_line_above_the_surface_is_refused(tmp_path, ranks):
    """-rod_sea_surface below a held end of a line given by -rod_load: the part above
    the surface would keep its submerged weight and the current's drag (before: accepted
    and solved so, in silence); refused in one line that says to give line types, exit 2,
    no file. The surface at the hang-off (a riser's usual sea) is accepted."""
    profile = tmp_path / "current.txt"
    profile.write_text("0 0.5 0 0\n")
    path = tmp_path / "out.h5"
    done = run_petsc_rod(UNIFORM + ["-rod_current_profile", str(profile), "-rod_sea_surface",
                                    "-15", "-rod_output", str(path)], ranks, TIMEOUT)
    assert_one_line_and_nothing_left(
        done.returncode, done.stdout + done.stderr, 2,
        ["-rod_sea_surface -15", "held end at z = 0 m", "-rod_load", "-rod_line_types",
         "-rod_sections"], path)
    done = run_petsc_rod(UNIFORM + ["-rod_current_profile", str(profile), "-rod_sea_surface",
                                    "0", "-rod_output", str(path)], ranks, TIMEOUT)
    assert done.returncode == 0, describe(done)


def test_a_uniform_line_hanging_below_the_surface_from_its_only_held_end_runs(tmp_path):
    """A free start is no held end: a line hanging from its pinned end 10 m under the
    surface (the unloaded reference's start at z = 0 above it) is accepted and solved
    (it was refused, naming a held end at z = 0 m that does not exist)."""
    profile = tmp_path / "current.txt"
    profile.write_text("0 0.05 0 0\n")
    path = tmp_path / "out.h5"
    args = ["-rod_length", "20", "-rod_stiffness", "1,1,1", "-rod_start", "free", "-rod_end",
            "pin", "-rod_end_position", "5,0,-10", "-rod_load", "0,0,-10", "-rod_drag",
            "1025,1.2,0.1", "-rod_elements", "20", "-rod_current_profile", str(profile),
            "-rod_sea_surface", "-5", "-rod_output", str(path)]
    done = run_petsc_rod(args, 1, TIMEOUT)
    assert done.returncode == 0, describe(done)
    assert "-rod_sea_surface" not in done.stdout + done.stderr
