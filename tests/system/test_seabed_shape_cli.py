"""A sloping or profiled seabed from the command line (docs/riser.md §1a, §3a): a slope
of 0 is today's flat seabed bit for bit, a profile on the plane gives the plane, the
result file and the figure follow the seabed; and its bad input ends with one line,
exit 2, no file. Spawns processes: marked ``serial``."""

import subprocess
import sys

import h5py
import numpy as np
import pytest

from helpers import REPO_ROOT, child_env, png_summary, run_petsc_rod
from test_hostile_cli import assert_one_line_and_nothing_left
from test_riser_cli import SCENE, write

pytestmark = pytest.mark.serial

TIMEOUT = 300
# SCENE: test_riser_cli.py's 10 m line of 1 N/m pinned 7 m across and 4 m up, on 16
# elements


def run(args, ranks=1):
    return run_petsc_rod(args, ranks, TIMEOUT)


BAD = {
    "slope of 90 deg": (["-rod_seabed", "0", "-rod_seabed_slope", "90"],
                        ["-rod_seabed_slope 90", "strictly between -90 and 90"]),
    "slope of -120 deg": (["-rod_seabed", "0", "-rod_seabed_slope", "-120"],
                          ["-rod_seabed_slope -120", "strictly between"]),
    "end under the slope": (["-rod_seabed", "0", "-rod_seabed_slope", "40"],
                            ["-rod_end", "below the seabed", "z = 5.87"]),
    "end under the profile": (["-rod_seabed_profile", "{high}"],
                              ["-rod_start", "below the seabed", "hold it on or above"]),
    "profile short of the end": (["-rod_seabed_profile", "{short}"],
                                 ["-rod_seabed_profile", "from 0 to 5 m", "cover"]),
    "profile not a function": (["-rod_seabed_profile", "{backwards}"],
                               ["-rod_seabed_profile", "line 3", "increase strictly"]),
    "profile with a word": (["-rod_seabed_profile", "{word}"],
                            ["-rod_seabed_profile", "line 2", "2 numbers"]),
    "profile of one row": (["-rod_seabed_profile", "{one}"],
                           ["-rod_seabed_profile", "at least 2 rows"]),
    "missing profile": (["-rod_seabed_profile", "{folder}/nowhere.txt"],
                        ["-rod_seabed_profile", "no such file"]),
    "grid with a hole": (["-rod_seabed_profile", "{holed}"],
                         ["-rod_seabed_profile", "every x with every y", "found 2 x values"]),
    "grid short of the end": (["-rod_seabed_profile", "{small_grid}"],
                              ["-rod_seabed_profile", "the grid covers x from 0 to 5 m", "extend"]),
    "grid with a direction": (["-rod_seabed_profile", "{grid}", "-rod_seabed_direction", "30"],
                              ["-rod_seabed_direction", "drop the direction"]),
    "rows of 2 and 3 numbers": (["-rod_seabed_profile", "{mixed}"],
                                ["-rod_seabed_profile", "line 2", "the same in every row"]),
    "profile and height": (["-rod_seabed", "0", "-rod_seabed_profile", "{plane}"],
                           ["-rod_seabed_profile", "drop -rod_seabed"]),
    "slope without seabed": (["-rod_seabed_slope", "3"],
                             ["-rod_seabed_slope needs -rod_seabed"]),
    "direction of no length": (["-rod_seabed", "0", "-rod_seabed_slope", "3",
                                "-rod_seabed_direction", "0,0"],
                               ["-rod_seabed_direction 0,0", "not both 0"]),
}


def files(folder):
    return dict(
        plane=write(folder, "plane.txt", "# d z\n-1 0\n20 0\n"),
        high=write(folder, "high.txt", "-1 1\n20 1\n"),
        short=write(folder, "short.txt", "0 0\n5 0\n"),
        backwards=write(folder, "backwards.txt", "0 0\n8 0\n5 0.5\n"),
        word=write(folder, "word.txt", "0 0\n8 deep\n"),
        one=write(folder, "one.txt", "0 0\n"),
        holed=write(folder, "holed.txt", "-1 -1 0\n-1 1 0\n9 -1 0\n"),
        small_grid=write(folder, "small.txt", "0 -1 0\n0 1 0\n5 -1 0\n5 1 0\n"),
        grid=write(folder, "grid.txt", "-1 -1 0\n-1 1 0\n9 -1 0\n9 1 0\n"),
        mixed=write(folder, "mixed.txt", "-1 0\n9 0 0\n"), folder=folder)


@pytest.mark.parametrize("case", list(BAD))
@pytest.mark.parametrize("ranks", [1, 2])
def test_bad_seabed_shape_exits_2_with_one_line_and_no_file(tmp_path, case, ranks):
    args, words = BAD[case]
    args = [a.format(**files(tmp_path)) for a in args]
    path = tmp_path / "out.h5"
    done = run(SCENE + args + ["-rod_output", str(path)], ranks=ranks)
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2, words,
                                     path)


def solved(tmp_path, name, args, ranks=1):
    path = tmp_path / f"{name}.h5"
    done = run(SCENE + ["-rod_elements", "40", "-rod_al_rtol", "1e-10", "-rod_al_ctol",
                        "1e-10"] + args + ["-rod_output", str(path)], ranks=ranks)
    assert done.returncode == 0, done.stdout + done.stderr
    return path, done.stdout


def test_a_slope_of_zero_is_the_flat_seabed_bit_for_bit(tmp_path):
    flat, _ = solved(tmp_path, "flat", ["-rod_seabed", "0"])
    zero, _ = solved(tmp_path, "zero", ["-rod_seabed", "0", "-rod_seabed_slope", "0",
                                        "-rod_seabed_direction", "30"])
    with h5py.File(flat, "r") as a, h5py.File(zero, "r") as b:
        for key in ("r", "n", "d1", "d2", "u", "m", "effective_tension", "seabed_reaction"):
            assert np.array_equal(a[key][:], b[key][:]), key
        for key in ("energy", "iterations", "top_tension", "touchdown_S", "grounded_length"):
            assert a.attrs[key] == b.attrs[key], key
        assert "seabed_height" not in b


def test_a_slope_and_its_profile_agree_and_the_figure_draws_the_seabed(tmp_path):
    """-rod_seabed_slope 5 at azimuth 0 and the profile of the same plane (rows 0.4 m
    below the anchor's height at -5 m, ...), the seabed origin and the anchor moved by
    (100, 50, -20): the same state to 1e-9 m on 1 and 2 ranks, the touchdown on the
    slope, the step line's touchdown, and a figure."""
    t = np.tan(np.radians(5.0))
    origin = np.array([100.0, 50.0, -20.0])
    rows = "".join(f"{d:.17g} {origin[2] + d * t:.17g}\n" for d in (-5.0, 4.0, 20.0))
    profile = write(tmp_path, "plane.txt", rows)
    moved = ["-rod_start_position", "100,50,-20", "-rod_end_position", "108,50,-16",
             "-rod_seabed_origin", "100,50"]
    slope, text = solved(tmp_path, "slope", moved + ["-rod_seabed", "-20",
                                                     "-rod_seabed_slope", "5"])
    again, _ = solved(tmp_path, "profile", moved + ["-rod_seabed_profile", profile], ranks=2)
    with h5py.File(slope, "r") as a, h5py.File(again, "r") as b:
        assert np.abs(a["r"][:] - b["r"][:]).max() < 1e-9
        assert a.attrs["touchdown_S"] == pytest.approx(b.attrs["touchdown_S"], abs=1e-9)
        r = a["r"][:]
        assert np.abs(a["seabed_height"][:] - (-20.0 + t * (r[:, 0] - 100.0))).max() < 1e-12
        position = a.attrs["touchdown_position"]
        assert abs(position[2] - (-20.0 + t * (position[0] - 100.0))) < 1e-5
        assert f"touchdown at S = {a.attrs['touchdown_S']:.6g} m" in text
        table = b["parameters"].attrs["seabed_profile_table"]
        assert np.array_equal(table[:, 1], [-20.0 - 5.0 * t, -20.0 + 4.0 * t, -20.0 + 20 * t])
    png = tmp_path / "slope.png"
    done = run_figure(slope, png)
    assert done.returncode == 0, done.stdout + done.stderr
    height, width, drawn = png_summary(png)
    assert width > 0 and drawn > 0.05


def run_figure(path, png):
    return subprocess.run([sys.executable, "-m", "petsc_rod.plots", str(path), str(png)],
                          cwd=REPO_ROOT, env=child_env(), capture_output=True, text=True,
                          timeout=TIMEOUT)


def test_a_grid_gives_the_plane_it_samples(tmp_path):
    """A 3 x 3 grid of heights on the plane z = x tan 4 deg + y tan 3 deg (bilinear is
    exact on a plane) and the same plane as -rod_seabed_slope 4.997 deg (atan of the
    gradient's length) along the gradient: the same state to 1e-9 m; the line, pinned
    in the plane y = 0, is pushed toward -y, down the slope."""
    a, b = np.tan(np.radians(4.0)), np.tan(np.radians(3.0))
    rows = "".join(f"{x:g} {y:g} {a * x + b * y:.17g}\n" for x in (-2.0, 5.0, 12.0)
                   for y in (-3.0, 0.0, 3.0))
    grid = write(tmp_path, "grid.txt", "# x y z\n" + rows)
    slope = np.degrees(np.arctan(np.hypot(a, b)))
    plane, _ = solved(tmp_path, "plane", ["-rod_seabed", "0", "-rod_seabed_slope",
                                          f"{slope:.17g}", "-rod_seabed_direction",
                                          f"{a:.17g},{b:.17g}"])
    sampled, _ = solved(tmp_path, "grid", ["-rod_seabed_profile", grid])
    with h5py.File(plane, "r") as f, h5py.File(sampled, "r") as g:
        assert np.abs(f["r"][:] - g["r"][:]).max() < 1e-9
        assert f["r"][:, 1].min() < -0.01
        assert g["parameters"].attrs["seabed_profile_table"].shape == (9, 3)


def test_vertices_beyond_a_profile_are_counted_and_said(tmp_path):
    """A level grid 2 cm wide across the line's plane and a current across it: the
    grounded part drifts out of the grid (1.56 m sideways at the touchdown point), where
    the seabed is taken level; the step line and the file say how many vertices lie
    beyond it."""
    grid = write(tmp_path, "narrow.txt", "-1 -0.01 0\n-1 0.01 0\n8 -0.01 0\n8 0.01 0\n")
    path, text = solved(tmp_path, "narrow", ["-rod_seabed_profile", grid, "-rod_current",
                                             "0,0.2,0", "-rod_drag", "1025,1.2,0.05"])
    with h5py.File(path, "r") as f:
        beyond = int(f.attrs["seabed_vertices_beyond"])
        y = f["r"][:, 1]
    assert beyond == int(np.sum(np.abs(y) > 0.01)) > 10
    assert f"{beyond} vertices beyond the seabed profile's rows" in text


def test_modes_on_a_profile_say_where_their_stiffness_is_symmetrised(tmp_path):
    """-rod_modes on a profile whose slope turns under the grounded part (5 to 2 degrees
    at 2 m): the run's warning and the modes group's attributes give the same count of
    grounded nodes where K is the contact's symmetric part; the same line on the plane
    has neither."""
    t = np.tan(np.radians(5.0))
    kink = write(tmp_path, "kink.txt", f"-5 {-5 * t:.17g}\n2 {2 * t:.17g}\n"
                 f"20 {2 * t + 18 * np.tan(np.radians(2.0)):.17g}\n")
    modes = ["-rod_end_position", "8,0,4", "-rod_modes", "3", "-rod_modes_mass", "0.1"]
    path, text = solved(tmp_path, "kink", modes + ["-rod_seabed_profile", kink])
    with h5py.File(path, "r") as f:
        count = int(f["modes"].attrs["symmetrised_nodes"])
        assert 0 < f["modes"].attrs["symmetrised_ratio"] < 1
    assert count > 0
    assert (f"modes: warning: K takes the symmetric part of the seabed contact's "
            f"stiffness at {count} grounded nodes") in text
    plane, text = solved(tmp_path, "plane", modes + ["-rod_seabed", "0", "-rod_seabed_slope",
                                                     "5"])
    with h5py.File(plane, "r") as f:
        assert "symmetrised_nodes" not in f["modes"].attrs
    assert "modes: warning" not in text


def test_friction_on_a_level_grid_is_the_flat_seabeds(tmp_path):
    """Seabed friction on a grid (a level one) with a current across: the plane's law
    with each node's gradient and its turn (FrictionTerm._plane_law, _shape_rates), in
    the Newton steps, and the flat seabed's answer to 1e-9 m. The grid's friction read
    a profile's direction and failed (AttributeError) at the first converged step."""
    grid = write(tmp_path, "level.txt", "-2 -3 0\n-2 3 0\n12 -3 0\n12 3 0\n")
    wet = ["-rod_seabed_friction", "0.5", "-rod_current", "0,0.3,0",
           "-rod_drag", "1025,1.2,0.05"]
    gridded, _ = solved(tmp_path, "grid", ["-rod_seabed_profile", grid] + wet)
    flat, _ = solved(tmp_path, "flat", ["-rod_seabed", "0"] + wet)
    with h5py.File(gridded, "r") as f, h5py.File(flat, "r") as g:
        assert f.attrs["converged"] == 1
        assert np.abs(f["r"][:] - g["r"][:]).max() < 1e-9
        assert f.attrs["friction_slide_length"] > 0


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("case", ["grid 0", "grid 45", "grid 90", "profile 45"])
def test_friction_on_a_grid_of_a_plane_is_the_planes(tmp_path, case, ranks):
    """The plane rising at 5 deg toward 0, 45 or 90 deg from the line's plane (x) given
    as a grid of 3 x 3 heights (the origin, the catenary's anchor, at a grid node: the
    laid catenary starts on a height interpolated under it, and -1.4e-17 m there moved
    the friction's anchors by 4e-9 m and the answer by 5e-10 m), or as a profile, with
    seabed friction mu = 0.5 and the default settings: converged in Newton steps, in as
    many iterations as the plane (-rod_seabed_slope, 19: 3 Newton, measured on 1 and 2
    ranks split), the same nodes sticking and sliding, the same r to 1e-10 m (measured
    2.2e-13 m). Before, friction on a grid or profile took no Newton steps and the grid
    at 45 deg did not converge (exit 3 after 4 halvings)."""
    shape, beta = case.split()
    t, e = np.tan(np.radians(5.0)), np.array([np.cos(np.radians(float(beta))),
                                              np.sin(np.radians(float(beta)))])
    if shape == "grid":
        rows = "".join(f"{x:g} {y:g} {t * (x * e[0] + y * e[1]):.17g}\n"
                       for x in (-3.0, 0.0, 12.0) for y in (-3.0, 0.0, 3.0))
        seabed = ["-rod_seabed_profile", write(tmp_path, "grid.txt", rows)]
    else:
        seabed = ["-rod_seabed_profile", write(tmp_path, "profile.txt",
                                               f"-20 {-20 * t:.17g}\n20 {20 * t:.17g}\n"),
                  "-rod_seabed_direction", beta]
    common = SCENE + ["-rod_elements", "40", "-rod_seabed_friction", "0.5",
                      "-rod_initial_shape", "catenary", "-rod_ranks_split", "split"]
    results = {}
    for name, args in (("plane", ["-rod_seabed", "0", "-rod_seabed_slope", "5",
                                  "-rod_seabed_direction", beta]), (shape, seabed)):
        path = tmp_path / f"{name}.h5"
        done = run(common + args + ["-rod_output", str(path)], ranks=ranks)
        assert done.returncode == 0, done.stdout + done.stderr
        with h5py.File(path, "r") as f:
            results[name] = (f["r"][:], f["friction_state"][:],
                             {key: int(f.attrs[key]) for key in ("iterations", "newton_steps")})
    (r, state, counts), (r_plane, state_plane, counts_plane) = results[shape], results["plane"]
    assert counts["newton_steps"] > 0
    assert counts["iterations"] <= counts_plane["iterations"] + 2
    assert np.array_equal(state, state_plane)
    assert np.count_nonzero(state == 1) > 0
    if beta != "90":                    # across the line's plane every grounded node sticks
        assert np.count_nonzero(state == 2) > 0
    distance = np.abs(r - r_plane).max()
    print(f"{case} on {ranks} rank(s): {counts} against the plane's {counts_plane}, "
          f"r {distance:.2g} m from it")
    assert distance < 1e-10
