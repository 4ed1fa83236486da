"""The riser scenes end to end (``mpiexec -n 2 python -m petsc_rod``, the default solver
settings), their result files and figures, and the riser's bad input: one line, exit 2,
no file. Spawns processes: marked ``serial``."""

import json
import subprocess
import sys

import h5py
import numpy as np
import pytest

from helpers import REPO_ROOT, child_env, png_summary, run_petsc_rod
from test_hostile_cli import assert_one_line_and_nothing_left

pytestmark = pytest.mark.serial

TIMEOUT = 300


def run(args, ranks=1):
    return run_petsc_rod(args, ranks, TIMEOUT)


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    """Both riser scenes solved on 2 ranks with their own options only: (process, file)."""
    folder = tmp_path_factory.mktemp("riser")
    done = {}
    for name in ("riser_catenary", "lazy_wave", "lazy_wave_types"):
        path = folder / f"{name}.h5"
        done[name] = (run(["-options_file", f"options/{name}.opts", "-rod_output", str(path)],
                          ranks=2), path)
    return done


@pytest.mark.parametrize("name", ["riser_catenary", "lazy_wave", "lazy_wave_types"])
def test_a_riser_scene_converges_on_two_ranks_with_the_defaults(scenes, name):
    process, path = scenes[name]
    text = process.stdout + process.stderr
    assert process.returncode == 0, text
    step = [line for line in text.splitlines() if line.startswith("step ")][-1]
    with h5py.File(path, "r") as f:
        assert int(f.attrs["converged"]) == 1
        # the step line and the summary say the file's numbers at load factor 1
        assert (f"top tension {f.attrs['top_tension'] / 1e3:.6g} kN" in step
                and f"touchdown S = {f.attrs['touchdown_S']:.6g} m" in step), step
        assert f"touchdown at S = {f.attrs['touchdown_S']:.6g} m" in text
        assert "energy" not in text and len(step) < 200, step
        S, r = f["S"][:], f["r"][:]
        tension, reaction = f["effective_tension"][:], f["seabed_reaction"][:]
        touchdown = float(f.attrs["touchdown_S"])
        assert f["effective_tension"].attrs["units"] == "N"
        assert "touchdown_S" in f.attrs["attribute_units"]
        in_effect = str(f.attrs["options_in_effect"]).splitlines()
    # the height's solver is recorded with the others where there is a seabed
    assert any(line.startswith("-rod_z_ksp_type ") for line in in_effect)
    grounded = S < touchdown
    assert grounded.sum() > 10 and np.all(tension > 0)
    # the grounded part rests on the seabed z = 0, within a few millimetres
    assert np.abs(r[grounded][5:, 2]).max() < 5e-3
    assert np.all(reaction[~grounded] == 0) and np.median(reaction[grounded]) > 0


def test_the_riser_figure(scenes, tmp_path):
    """The riser's figure (docs/output.md, "Figures"): drawn, with the sea surface's and
    the seabed's colours and the allowable bend radius; the title says the engineer's
    numbers, not the energy."""
    from petsc_rod.figures import style
    from petsc_rod.plots import result_figure
    _, path = scenes["riser_catenary"]
    figure = tmp_path / "riser.png"
    done = subprocess.run([sys.executable, "-m", "petsc_rod.plots", str(path), str(figure),
                           "--min-bend-radius", "200"],
                          cwd=REPO_ROOT, env=child_env(), capture_output=True, text=True,
                          timeout=TIMEOUT, check=False)
    assert done.returncode == 0, done.stderr
    height, width, drawn = png_summary(figure)
    assert height > 300 and width > 600 and drawn > 0.02
    import matplotlib.image
    pixels = matplotlib.image.imread(str(figure))[..., :3]
    for colour in (style.SEA, style.SEABED, style.ALLOWABLE):
        assert np.mean(np.all(np.abs(pixels - colour) < 0.02, axis=-1)) > 1e-4, colour
    drawn_figure = result_figure(path)
    title = drawn_figure._suptitle.get_text()
    with h5py.File(path, "r") as f:
        top, touchdown = f.attrs["top_tension"], f.attrs["touchdown_S"]
    assert "riser_catenary: converged" in title and "energy" not in title
    assert f"top tension {top / 1e3:.4g} kN" in title and f"S = {touchdown:.1f} m" in title


def test_the_lazy_wave_by_line_types_is_the_lazy_wave_by_loads(scenes, tmp_path):
    """options/lazy_wave_types.opts is options/lazy_wave.opts given by line types (their
    masses to 4 decimals: the loads agree to 2e-6): the same top tension and touchdown,
    the sections' numbers in the file, and the sections drawn in their colours."""
    numbers = {}
    for name in ("lazy_wave", "lazy_wave_types"):
        with h5py.File(scenes[name][1], "r") as f:
            numbers[name] = {key: f.attrs[key] for key in f.attrs}
    plain, typed = numbers["lazy_wave"], numbers["lazy_wave_types"]
    assert abs(typed["top_tension"] / plain["top_tension"] - 1) < 1e-5
    assert abs(typed["touchdown_S"] - plain["touchdown_S"]) < 0.01
    assert list(typed["section_names"]) == ["umbilical", "buoyancy", "umbilical"]
    np.testing.assert_array_equal(typed["section_bounds"], [[0, 600], [600, 1000], [1000, 2000]])
    # the hog bend (the buoyancy) is the most curved; the top tension the largest
    assert np.argmax(typed["section_max_curvature"]) == 1
    assert typed["section_max_tension"][2] == pytest.approx(typed["top_tension"], rel=1e-3)
    figure = tmp_path / "lazy_wave_types.png"
    done = subprocess.run([sys.executable, "-m", "petsc_rod.plots", str(scenes["lazy_wave_types"][1]),
                           str(figure)], cwd=REPO_ROOT, env=child_env(), capture_output=True,
                          text=True, timeout=TIMEOUT, check=False)
    assert done.returncode == 0, done.stderr
    import matplotlib
    import matplotlib.image
    pixels = matplotlib.image.imread(str(figure))[..., :3]
    # the two line types' colours, drawn (the buoyancy's 400 m: 6e-4 of the pixels)
    for colour in matplotlib.colormaps["tab10"].colors[:2]:
        assert np.mean(np.all(np.abs(pixels - colour) < 0.02, axis=-1)) > 1e-4


SCENE = ["-rod_length", "10", "-rod_start", "pin", "-rod_end", "pin", "-rod_end_position",
         "7,0,4", "-rod_load", "0,0,-1", "-rod_elements", "16"]


def write(folder, name, text):
    path = folder / name
    path.write_text(text)
    return str(path)


BAD = {
    "negative stiffness": (["-rod_seabed", "0", "-rod_seabed_stiffness", "-5"],
                           ["-rod_seabed_stiffness", "positive"]),
    "missing profile": (["-rod_current_profile", "{folder}/nowhere.txt", "-rod_drag",
                         "1025,1.2,0.1"], ["-rod_current_profile", "no such file"]),
    "profile not monotone": (["-rod_current_profile", "{bad_profile}", "-rod_drag",
                              "1025,1.2,0.1"], ["-rod_current_profile", "increase"]),
    "negative drag entry": (["-rod_current", "0.5,0,0", "-rod_drag", "1025,-1.2,0.1"],
                            ["-rod_drag", "negative"]),
    "end below the seabed": (["-rod_seabed", "5"], ["-rod_start", "below the seabed"]),
    "current without drag": (["-rod_current", "0.5,0,0"], ["-rod_drag"]),
    "stiffness without seabed": (["-rod_seabed_stiffness", "1e3"], ["-rod_seabed"]),
    # issue 25: numbers derived from accepted input, checked against the options' bound
    "current of 1e20 m/s": (["-rod_current", "1e20,0,0", "-rod_drag", "1025,1.2,0.3"],
                            ["-rod_current with -rod_drag", "largest drag", "1e+30"]),
    "profile with 1e300": (["-rod_current_profile", "{huge_profile}", "-rod_drag",
                            "1025,1.2,0.1"], ["-rod_current_profile", "row 2", "1e+30"]),
    "profile with 1e20 m/s": (["-rod_current_profile", "{fast_profile}", "-rod_drag",
                               "1025,1.2,0.1"], ["-rod_current_profile", "largest drag"]),
    "load of 1e30 N/m on 10 m": (["-rod_load", "0,0,-1e30"], ["-rod_load", "applied force"]),
    # issue 25: a seabed above the stated bound (1e13 N/m^2 for this 10 m line of 1 N/m)
    "seabed of 1e25 N/m^2": (["-rod_seabed", "0", "-rod_seabed_stiffness", "1e25"],
                             ["-rod_seabed_stiffness 1e+25", "largest accepted is 1e+13"]),
}


@pytest.mark.parametrize("case", list(BAD))
@pytest.mark.parametrize("ranks", [1, 2])
def test_bad_riser_input_exits_2_with_one_line_and_no_file(tmp_path, case, ranks):
    args, words = BAD[case]
    bad_profile = write(tmp_path, "profile.txt", "0 1 0 0\n50 1 0 0\n40 0 0 0\n")
    huge_profile = write(tmp_path, "huge.txt", "0 1 0 0\n50 1e300 0 0\n")
    fast_profile = write(tmp_path, "fast.txt", "0 1e20 0 0\n50 1 0 0\n")
    args = [a.format(folder=tmp_path, bad_profile=bad_profile, huge_profile=huge_profile,
                     fast_profile=fast_profile) for a in args]
    path = tmp_path / "out.h5"
    done = run(SCENE + args + ["-rod_output", str(path)], ranks=ranks)
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2, words,
                                     path)


@pytest.mark.parametrize("ranks", [1, 2])
def test_the_stiffest_seabed_accepted_converges(tmp_path, ranks):
    """Issue 25: 1e25 N/m^2 ended in DIVERGED_PCSETUP_FAILED; the largest stiffness
    accepted (environment.largest_stiffness, quoted by the refusal) converges, on the
    direct solver of one rank and the CG of two."""
    from petsc_rod.cli.scene_options import rounded_down
    from petsc_rod.environment.seabed import largest_stiffness
    largest = rounded_down(largest_stiffness(10.0, 10.0))
    path = tmp_path / "out.h5"
    done = run(SCENE + ["-rod_seabed", "0", "-rod_seabed_stiffness", f"{largest:.3g}",
                        "-rod_output", str(path)], ranks=ranks)
    assert done.returncode == 0, done.stdout + done.stderr
    with h5py.File(path, "r") as f:
        assert int(f.attrs["converged"]) == 1
        assert float(f["parameters"].attrs["seabed_stiffness"]) == largest
        # the line rests on the seabed, sunk by about w / k = 1e-13 m
        assert np.abs(f["r"][:][f["S"][:] < 2.0, 2]).max() < 1e-9


def test_the_file_holds_the_current_profile_and_the_drag_with_its_units(tmp_path):
    """Issue 25: the file held only the profile's name, and parameters/drag said "1"."""
    rows = np.array([[0.0, 0.5, 0.2, 0.0], [500.0, 0.2, 0.0, 0.0], [1000.0, 0.0, 0.0, 0.0]])
    profile = write(tmp_path, "profile.txt",
                    "# depth ux uy uz\n" + "\n".join(" ".join(f"{v:g}" for v in row)
                                                     for row in rows) + "\n")
    path = tmp_path / "profile.h5"
    # options/riser_catenary.opts, coarser, with the profile in place of its current
    done = run(["-rod_length", "1800", "-rod_stiffness", "5.6e7,5.6e7,4.3e7", "-rod_start",
                "pin", "-rod_end", "pin", "-rod_end_position", "1157,0,1000", "-rod_load",
                "0,0,-1200", "-rod_seabed", "0", "-rod_elements", "200",
                "-rod_initial_shape", "catenary", "-rod_current_profile", profile,
                "-rod_drag", "1025,1.2,0.324", "-rod_output", str(path)])
    assert done.returncode == 0, done.stdout + done.stderr
    with h5py.File(path, "r") as result:
        parameters = result["parameters"]
        units = json.loads(parameters.attrs["attribute_units"])
        assert np.array_equal(parameters.attrs["current_profile_table"], rows)
        assert units["current_profile_table"].startswith("m, m/s")
        assert np.array_equal(parameters.attrs["drag"], [1025.0, 1.2, 0.324])
        assert units["drag"] == "kg/m^3, 1, m"


def test_the_80_m_lazy_wave_cable_on_one_and_two_ranks(tmp_path):
    """options/cable_80m.opts (Lozon et al. 2025, the 80 m site) converges with the
    defaults, to the same state on 1 and 2 ranks (the iteration's tolerance; the 2-rank
    global step is another exact solve, with its own round-off)."""
    results = {}
    for ranks in (1, 2):
        path = tmp_path / f"cable_{ranks}.h5"
        # split on 2 ranks (its 340 elements run whole under -rod_ranks_split auto)
        process = run(["-options_file", "options/cable_80m.opts", "-rod_output", str(path),
                       "-rod_ranks_split", "split"], ranks=ranks)
        assert process.returncode == 0, process.stdout + process.stderr
        with h5py.File(path, "r") as f:
            results[ranks] = {key: f.attrs[key] for key in ("top_tension", "touchdown_S")}
            results[ranks]["r"] = f["r"][:]
    one, two = results[1], results[2]
    assert abs(one["top_tension"] - two["top_tension"]) < 1e-6 * one["top_tension"]
    assert abs(one["touchdown_S"] - two["touchdown_S"]) < 1e-3
    assert np.abs(one["r"] - two["r"]).max() < 1e-5


def test_the_plan_shows_a_riser_pushed_sideways(tmp_path):
    """Issue 24: projected on the vertical plane of its ends, a riser pushed sideways by
    a current looked like the one in that plane. options/riser_catenary.opts, coarser,
    with 1 m/s across: the plan draws the line about 120 m off that plane, and the
    elevation keeps the true horizontal distance from the anchor."""
    from petsc_rod.plots import result_figure
    path = tmp_path / "sideways.h5"
    done = run(["-options_file", "options/riser_catenary.opts", "-rod_elements", "300",
                "-rod_current", "0,1,0", "-rod_output", str(path)])
    assert done.returncode == 0, done.stdout + done.stderr
    with h5py.File(path, "r") as f:
        r = f["r"][:]
    figure = result_figure(path)
    plan = [a for a in figure.axes if a.get_xlabel() == "x (m)"][0]
    line = [ln for ln in plan.lines if len(ln.get_ydata()) == len(r)][0]
    assert 80 < line.get_ydata().max() < 200                    # the bow across, in plan
    assert "largest offset from the plane of the ends" in plan.get_title()
    elevation = [a for a in figure.axes if a.get_ylabel() == "z (m)"][0]
    drawn = [ln for ln in elevation.lines if len(ln.get_xdata()) == len(r)]
    np.testing.assert_allclose(drawn[-1].get_xdata(), np.hypot(r[:, 0], r[:, 1]))
    assert "projected on the vertical plane of the ends" in [ln.get_label() for ln in drawn]


def test_a_catenary_start_that_cannot_be_drawn_falls_back_to_the_straight_start(tmp_path):
    """The 80 m cable with its buoyancy as 20 discrete modules, its top moved to 90 m
    from the anchor: 170 m of line is longer than the 156 m path along the seabed and up,
    so no grounded catenary of its weight exists (touchdown.seabed_shape). The run says
    so in one line, starts straight and reaches the straight start's own answer."""
    common = ["-options_file", "options/cable_80m.opts", "-rod_end_position", "90,0,66",
              "-rod_load", "0,0,-157.8003", "-rod_load_breaks", "",
              "-rod_point_loads", "scripts/matrix_buoyancy_modules.txt",
              "-rod_elements", "170"]
    answers = {}
    for shape in ("catenary", "straight"):
        path = tmp_path / f"{shape}.h5"
        process = run(common + ["-rod_initial_shape", shape, "-rod_output", str(path)])
        text = process.stdout + process.stderr
        assert process.returncode == 0, text
        fell_back = [line for line in text.splitlines() if "starts from the straight" in line]
        assert len(fell_back) == (shape == "catenary"), text
        with h5py.File(path, "r") as f:
            answers[shape] = (f["r"][:], float(f.attrs["top_tension"]))
    (r_fell, top_fell), (r_straight, top_straight) = answers["catenary"], answers["straight"]
    assert np.abs(r_fell - r_straight).max() < 1e-9 * 170.215
    assert abs(top_fell - top_straight) < 1e-9 * top_straight


def test_a_hang_off_joint_without_an_axis_is_installed_at_the_riser_s_angle(tmp_path):
    """options/steel_catenary_riser.opts with -rod_end_rotational_stiffness 1.72e5 alone
    (200 elements): the joint's axis is the catenary's top tangent, the joint nearly
    unloaded (measured 0.019 deg, 57 N m); the issue's default e_x gave 85 deg and
    254 kN m. The file says the axis used."""
    path = tmp_path / "joint.h5"
    process = run_petsc_rod(["-options_file", "options/steel_catenary_riser.opts",
                             "-rod_sections", "scr10:2400:200",
                             "-rod_end_rotational_stiffness", "1.72e5",
                             "-rod_output", str(path)])
    assert process.returncode == 0, process.stderr
    with h5py.File(path) as f:
        step = f["steps"][max(f["steps"], key=int)]
        angle, moment = step.attrs["end_joint_angle"], step.attrs["end_joint_moment"]
        axis = step.attrs["end_joint_axis"]
    assert angle < 0.1 and moment < 1e3
    # up and toward the vessel's side, 19 degrees from the vertical like the top tension
    assert np.degrees(np.arccos(axis[2])) == pytest.approx(19.4, abs=0.5)


CABLE_TYPE = """name   od    mass  ei   gj   cd
cable  0.1   10.0  10.0 10.0 1.0
"""
CABLE = ["-rod_sections", "cable:100:100", "-rod_start", "pin", "-rod_end", "pin",
         "-rod_end_position", "80,0,0"]


def solve_cable(tmp_path, args):
    """(attributes, r) of the last step of the cable of CABLE_TYPE between the pins of
    CABLE with ``args``, a run that must converge."""
    types = write(tmp_path, "cable.txt", CABLE_TYPE)
    path = tmp_path / "cable.h5"
    process = run(["-rod_line_types", types, *CABLE, *args, "-rod_output", str(path)])
    assert process.returncode == 0, process.stderr
    with h5py.File(path) as f:
        step = f["steps"][max(f["steps"], key=int)]
        return dict(step.attrs), step["r"][:]


def test_a_line_in_air_is_the_catenary_of_its_weight_in_air(tmp_path):
    """-rod_water_density 0 (refused before): a 100 m cable of 10 kg/m between pins 80 m
    apart hangs as the catenary of w = m g = 98.07 N/m: the end force and the sag within
    1e-5 (EI 10 N m^2; measured 1e-6)."""
    from petsc_rod.scenes.catenary import catenary

    attributes, r = solve_cable(tmp_path, ["-rod_water_density", "0",
                                           "-rod_initial_shape", "catenary"])
    exact, _, force = catenary(100.0, np.array([80.0, 0.0, 0.0]),
                               np.array([0.0, 0.0, -10.0 * 9.80665]), np.array([50.0, 100.0]))
    assert np.linalg.norm(attributes["end_force"]) == pytest.approx(
        np.linalg.norm(force[1]), rel=1e-5)
    assert r[50, 2] == pytest.approx(exact[0, 2], rel=1e-5)


def test_a_weightless_line_between_pins_takes_a_point_load_in_two_straight_pieces(
        tmp_path):
    """-rod_gravity 0 (refused before): the cable weightless, 1 kN hung at its middle: two
    straight pieces of 50 m, the point 30 m below the pins, each pin carrying 500 N up
    and H = 500 / tan(asin(0.6)) = 666.7 N across (the bending rounds the kink over
    sqrt(EI / T) = 0.1 m: H within 0.5 %, the sag within 0.5 %)."""
    attributes, r = solve_cable(tmp_path, ["-rod_gravity", "0",
                                           "-rod_point_load", "50,0,0,-1000"])
    for name, sign in (("start_force", 1.0), ("end_force", -1.0)):
        assert attributes[name][2] == pytest.approx(-500.0, rel=1e-9)
        assert sign * attributes[name][0] == pytest.approx(500.0 / 0.75, rel=5e-3)
    assert r[50, 2] == pytest.approx(-30.0, rel=5e-3)


def two_piece_catenary_forces(length, chord, surface, w_water, w_air):
    """(n(0), n(L)) of the inextensible cable pinned at the origin (under water) and at
    ``chord`` (x, 0, z) (above the surface z = ``surface``), weighing ``w_water`` below
    the surface and ``w_air`` above it (N/m): n = (H, 0, V0 + int w dS), each piece a
    catenary in closed form (x: H/w asinh, z: |n| / w), (H, V0, S_b) such that the line
    crosses the surface at S_b and ends at the chord."""
    from scipy.optimize import fsolve

    def piece(H, V, w, s):
        return (H / w * (np.arcsinh((V + w * s) / H) - np.arcsinh(V / H)),
                (np.hypot(H, V + w * s) - np.hypot(H, V)) / w, V + w * s)

    def equations(v):
        H, V0, S_b = v
        x1, z1, V1 = piece(H, V0, w_water, S_b)
        x2, z2, _ = piece(H, V1, w_air, length - S_b)
        return [z1 - surface, x1 + x2 - chord[0], z1 + z2 - chord[2]]

    H, V0, S_b = fsolve(equations, [1000.0, -500.0, 0.8 * length], xtol=1e-14)
    V_L = V0 + w_water * S_b + w_air * (length - S_b)
    return np.array([H, 0.0, V0]), np.array([H, 0.0, V_L])


# the cable's weights under water and in air, N/m
WEIGHTS = (10.0 * 9.80665 - 1025.0 * 9.80665 * np.pi * 0.1**2 / 4, 10.0 * 9.80665)


def through_the_surface(tmp_path, args, ranks=1, elements=400):
    """The last step's attributes of the cable of CABLE_TYPE on ``elements`` from a pin
    15 m under -rod_sea_surface 15 to one at (80, 0, 30), with ``args``."""
    types = write(tmp_path, "cable.txt", CABLE_TYPE)
    path = tmp_path / "surface.h5"
    process = run(["-rod_line_types", types, "-rod_sections", f"cable:100:{elements}",
                   "-rod_start", "pin", "-rod_end", "pin", "-rod_end_position", "80,0,30",
                   "-rod_sea_surface", "15", "-rod_initial_shape", "catenary", *args,
                   "-rod_output", str(path)], ranks)
    assert process.returncode == 0, process.stderr
    with h5py.File(path) as f:
        return dict(f["steps"][max(f["steps"], key=int)].attrs)


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_line_out_of_the_water_weighs_its_weight_in_air(tmp_path, ranks):
    """The cable of CABLE_TYPE from a pin 15 m under -rod_sea_surface 15 to one 15 m
    above it (80, 0, 30): below the surface it weighs (m - rho_w A) g = 19.1 N/m, above
    it m g = 98.1 N/m. The reactions are those of the two-piece catenary (measured at
    400 elements: H within 9e-5, the top's vertical force within 0.6 N of 2643 N; 9.4,
    4.3, 0.57, 0.10 N at 100 to 800 elements, the crossing inside an element). Before,
    the whole line kept its buoyancy: the top carried 1912 N less the anchor's."""
    attributes = through_the_surface(tmp_path, [], ranks)
    start, end = two_piece_catenary_forces(100.0, (80.0, 0.0, 30.0), 15.0, *WEIGHTS)
    assert attributes["start_force"][0] == pytest.approx(start[0], rel=1e-3)
    assert attributes["start_force"][2] == pytest.approx(start[2], abs=0.5)
    assert -attributes["end_force"][2] == pytest.approx(end[2], abs=2.0)


def test_a_current_drags_only_the_line_under_the_surface(tmp_path):
    """The same cable in a current of 0.05 m/s across its plane (c = rho C_d D / 2 =
    51.25 kg/m^2, c U^2 = 0.128 N/m, small beside its weight: v stays normal to it to
    1e-4): the supports carry the drag of the wet length only, the two-piece catenary's
    crossing S_b = 83.3 m: c U^2 S_b = 10.671 N (measured 10.670 at 400 elements, within
    1e-3 at 200), not the whole line's 12.81 N as before."""
    from scipy.optimize import brentq

    attributes = through_the_surface(tmp_path, ["-rod_current", "0,0.05,0"], elements=200)
    start, _ = two_piece_catenary_forces(100.0, (80.0, 0.0, 30.0), 15.0, *WEIGHTS)
    H, V0 = start[0], start[2]
    # the arc length where the under-water piece reaches z = 15 m
    w = WEIGHTS[0]
    S_b = brentq(lambda S: (np.hypot(H, V0 + w * S) - np.hypot(H, V0)) / w - 15.0, 1.0, 100.0)
    lateral = attributes["start_force"][1] + attributes["end_force"][1]
    assert lateral == pytest.approx(51.25 * 0.05**2 * S_b, rel=1e-3)


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("args, words", [
    (["-options_file", "options/riser_catenary.opts", "-rod_elements", "40",
      "-rod_current", "0,1,0"], ["-rod_current", "a current has none", "drop -rod_al_stability"]),
    (["-options_file", "options/mooring_chain.opts", "-rod_seabed_friction", "0.5"],
     ["-rod_seabed_friction", "friction has none", "drop -rod_al_stability"]),
    (["-options_file", "{profiled}"],
     ["-rod_al_stability 1", "loads without one", "a seabed that is not flat",
      "drop -rod_al_stability"]),
], ids=["current", "friction", "profile"])
def test_a_stability_test_asked_for_a_scene_without_energy_is_refused(tmp_path, args,
                                                                       words, ranks):
    """-rod_al_stability 1 given with a current, seabed friction or a seabed profile
    (loads without an energy, which the test cannot take) is refused in one line, not
    left out in silence. (A sloping plane has one: test_a_stability_test_on_a_slope.)"""
    path = tmp_path / "out.h5"
    # steel_catenary_riser_slope.opts's plane as a profile of two rows
    profile = tmp_path / "profile.txt"
    profile.write_text("".join(f"{d:g} {d * np.tan(np.radians(3.0)):.17g}\n"
                               for d in (-100.0, 5000.0)))
    profiled = tmp_path / "profiled.opts"
    profiled.write_text("".join(
        row + "\n" for row in open("options/steel_catenary_riser.opts").read().splitlines()
        if not row.startswith("-rod_seabed ")) + f"-rod_seabed_profile {profile}\n")
    args = [str(profiled) if a == "{profiled}" else a for a in args]
    done = run(args + ["-rod_al_stability", "1", "-rod_output", str(path)], ranks)
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2, words,
                                     path)


def test_a_stability_test_on_a_slope(tmp_path):
    """A sloping plane's contact has an energy (docs/riser.md §3a): -rod_al_stability 1
    runs, and the equilibrium is stable."""
    done = run(["-options_file", "options/steel_catenary_riser_slope.opts",
                "-rod_sections", "scr10:2400:400", "-rod_al_stability", "1"])
    assert done.returncode == 0, done.stdout + done.stderr
    assert "stable" in done.stdout and "UNSTABLE" not in done.stdout


def test_a_current_without_a_stability_switch_still_runs(tmp_path):
    """The default -rod_al_stability (true) with a current is no refusal: the run goes
    (here ended by its iteration budget, exit 3)."""
    done = run(["-options_file", "options/riser_catenary.opts", "-rod_elements", "40",
                "-rod_current", "0,1,0", "-rod_al_max_it", "3", "-rod_max_halvings", "0"])
    assert done.returncode == 3, done.stdout + done.stderr
    assert "-rod_al_stability" not in done.stdout + done.stderr


@pytest.mark.parametrize("ranks, stiffness, words", [
    (1, "1e3", ["-rod_axial_stiffness 1000", "about 4.8e+03 % or more", "w h = 1.2e+06 N"]),
    (2, "1e3", ["-rod_axial_stiffness 1000", "about 4.8e+03 % or more", "w h = 1.2e+06 N"]),
    (1, "3e5", ["-rod_axial_stiffness 300000", "about 200 % or more", "above 100 %"]),
], ids=["1e3-1", "1e3-2", "3e5-1"])
def test_a_stretch_beyond_the_lines_length_is_refused(tmp_path, ranks, stiffness, words):
    """The riser (1200 N/m, ends 1000 m apart in height) given EA 1e3 N: any equilibrium
    stretches it by 4800 % at the top (T + T^2/2EA >= w h; the run spent minutes to exit
    3); EA 3e5 N by 200 % (the run converged with 595 kN at the top, 198 %): refused
    in one line on every rank, before any work."""
    path = tmp_path / "out.h5"
    done = run(["-options_file", "options/riser_catenary.opts", "-rod_axial_stiffness",
                stiffness, "-rod_output", str(path)], ranks)
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2, words,
                                     path)


def test_a_soft_line_within_the_stretch_domain_still_runs():
    """EA 1e6 N on that riser (84 % by the bound; the run converges with 852 kN at the
    top, 85 %) is no refusal: the run goes (here ended by its iteration budget, exit 3)."""
    done = run(["-options_file", "options/riser_catenary.opts", "-rod_elements", "40",
                "-rod_axial_stiffness", "1e6", "-rod_al_max_it", "3", "-rod_max_halvings", "0"])
    assert done.returncode == 3, done.stdout + done.stderr
    assert "stretches the" not in done.stdout + done.stderr
