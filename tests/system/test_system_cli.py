"""A system on the command line (petsc_rod/cli_system.py, docs/systems.md "Running a
system"): ``python -m petsc_rod -rod_system FILE`` on a small MoorDyn deck (a free buoyant
body on three 70 m chains in 30 m of water, tests/data/moordyn/small_free_body.dat),
under a body load from the command line, on 1 and 2 ranks with the same numbers; its
result file's groups and tables; the Python API's solve_system on the same file gives
the same numbers (issue 49 point 6, the MoorDyn-file path against the API path); bad
input in one line, exit 2, no file left. Spawns processes: marked ``serial``."""

import base64
import os
import re

import h5py
import numpy as np
import pytest

from helpers import REPO_ROOT, describe, partial_files, run_petsc_rod
from test_sweep_cli import Page, run_module

pytestmark = pytest.mark.serial

DECK = os.path.join(REPO_ROOT, "tests", "data", "moordyn", "small_free_body.dat")
LOAD = "Body1,10e3,2e3,0,0,0,5e3"
# The sweeps of the shared runs: a watch circle of 4 headings, excursions in 2 steps at 90 deg.
WATCH = ("Body1", 20e3, 4)
SWEEPS = ["-rod_system_watch_circle", "Body1,20e3,4", "-rod_system_excursion",
          "Body1,20e3,2,90"]
# The scaled residual a system's Newton accepts as its lines' own accuracy
# (system/equilibrium.py's Settings.floor): two runs of the same system whose round-off
# differs agree to it, relative to each quantity's largest entry.
FLOOR = 1e-7
SYSTEM_DATASETS = ("point_positions", "body_positions", "body_rotations", "body_stiffness",
                   "body_stiffness_reference", "body_stiffness_moment",
                   "body_stiffness_asymmetry", "end_forces", "end_tensions",
                   "line_converged")


def system_run(folder, ranks, *extra):
    out = folder / "system.h5"
    process = run_petsc_rod(["-rod_system", DECK, "-rod_system_body_load", LOAD,
                             "-rod_output", str(out), "-rod_table",
                             str(folder / "system.csv"), *extra], ranks, 300)
    return out, process


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    found = {}
    for ranks in (1, 2):
        folder = tmp_path_factory.mktemp(f"ranks{ranks}")
        found[ranks] = (folder,) + system_run(folder, ranks, *SWEEPS)
    return found


def test_one_and_two_ranks_give_the_same_numbers(runs):
    for ranks, (_, _, process) in runs.items():
        assert process.returncode == 0, describe(process)
        assert "petsc_rod: converged" in process.stdout and "warning" not in process.stdout
        # the body moves 1.6 m from its given pose: its first solve from the catenaries'
        assert "petsc_rod: note: the system's catenary predictor used" in process.stdout
    (_, one, _), (_, two, _) = runs[1], runs[2]
    with h5py.File(one, "r") as f, h5py.File(two, "r") as g:
        assert int(g["system"].attrs["ranks"]) == 2
        for name in SYSTEM_DATASETS:
            assert np.allclose(f["system"][name][()], g["system"][name][()], rtol=1e-12,
                               atol=1e-12 * np.abs(f["system"][name][()]).max()), name
        for line in ("Line1", "Line2", "Line3"):
            assert np.array_equal(f[f"lines/{line}/r"][()], g[f"lines/{line}/r"][()])
        for sweep in ("watch_circle", "excursion"):
            group = f[f"system/{sweep}"]
            assert len(group["heading"]) > 0
            for name in group:             # each line solved alike on its rank
                assert np.array_equal(group[name][()], g[f"system/{sweep}"][name][()]), \
                    (sweep, name)


def test_the_predictor_switched_off_gives_the_same_equilibrium(runs, tmp_path):
    """-rod_system_predictor 0: the load continuation from the unloaded system, no note
    of the predictor, the pose, stiffness and end forces of the predicted run's to the
    Newton's floor (FLOOR of each quantity's largest entry)."""
    path, process = system_run(tmp_path, 1, "-rod_system_predictor", "0")
    assert process.returncode == 0, describe(process)
    assert "catenary predictor" not in process.stdout
    with h5py.File(runs[1][1], "r") as f, h5py.File(path, "r") as g:
        for name in ("body_positions", "body_stiffness", "end_forces"):
            predicted, continued = f["system"][name][()], g["system"][name][()]
            assert np.abs(predicted - continued).max() < FLOOR * np.abs(predicted).max(), name


def test_the_result_file_and_the_tables(runs):
    folder, path, process = runs[1]
    with h5py.File(path, "r") as f:
        system = f["system"]
        assert set(SYSTEM_DATASETS) <= set(system)
        assert int(system.attrs["converged"]) == 1 and system.attrs["residual"] < 1e-7
        assert system.attrs["line_names"] == "Line1,Line2,Line3"
        with open(DECK, encoding="utf-8") as deck:
            assert system.attrs["input_text"] == deck.read()
        K = system["body_stiffness"][0]
        assert K.shape == (6, 6) and np.all(np.diag(K)[:3] > 1e3)
        # the rotational block's antisymmetric part is the lines' moment about the
        # reference point (docs/systems.md)
        M = system["body_stiffness_moment"][0]
        skew = np.array([[0, -M[2], M[1]], [M[2], 0, -M[0]], [-M[1], M[0], 0]])
        assert np.abs((K - K.T)[3:, 3:] - skew).max() < 1e-8 * np.abs(K).max()
        assert np.allclose(system["body_stiffness_reference"][0],
                           system["body_positions"][0, :3])
        # the body's load is balanced: the body moved downstream of the load
        assert system["body_positions"][0, 0] > 0.5
        for k, line in enumerate(("Line1", "Line2", "Line3")):
            group = f[f"lines/{line}"]
            assert group["r"].shape == (71, 3) and int(group.attrs["converged"]) == 1
            assert np.all(np.isfinite(group["n"][()]))
            # the end tensions are the end elements' n.t, the end forces -n(L)
            assert system["end_tensions"][k, 1] == pytest.approx(
                group["effective_tension"][-1], rel=1e-12)
            assert system["end_forces"][k, 1] == pytest.approx(-group["n"][-1], rel=1e-9)
    rows = (folder / "system_system.csv").read_text().splitlines()
    assert rows[0].startswith("line,end,to,force_x (N)") and len(rows) == 7
    assert rows[2].split(",")[:3] == ["Line1", "end", "Body1"]
    table = (folder / "system_Line2.csv").read_text().splitlines()
    assert table[0].startswith("S (m),x (m)") and len(table) == 72
    assert "petsc_rod: note: line type main: EI 0 in the file" in process.stdout
    assert "Body1" in process.stdout and "stiffness diagonal" in process.stdout
    # the sweeps' tables: a row per case; their worst lines said in the run's lines
    rows = (folder / "system_watch_circle.csv").read_text().splitlines()
    assert rows[0].startswith("heading (deg),load (N),x_offset (m)") and len(rows) == 5
    assert rows[1].split(",")[-1] in ("Line1", "Line2", "Line3")
    rows = (folder / "system_excursion.csv").read_text().splitlines()
    assert rows[0].startswith("heading (deg),load (N),offset (m),restoring (N)")
    assert [float(row.split(",")[1]) for row in rows[1:]] == [0, 10e3, 20e3]
    restoring = np.array([float(row.split(",")[3]) for row in rows[1:]])
    # nothing else horizontal acts on the body: the restoring force is the load
    assert np.abs(restoring - [0, 10e3, 20e3]).max() < 1e-2
    with h5py.File(path, "r") as f:
        excursion = f["system/excursion"]
        assert excursion["restoring"].attrs["units"] == "N"
        assert np.allclose(excursion["restoring"][()], restoring, rtol=1e-11, atol=1e-6)
        assert "failed" in excursion.attrs and len(excursion["failed_heading"]) == 0
    said = [line for line in process.stdout.splitlines() if "watch circle of Body1" in line]
    assert len(said) == 1 and "largest tension" in said[0] and "smallest grounded" in said[0]
    assert "load-excursion curves of Body1" in process.stdout
    rows = [line.split() for line in process.stdout.splitlines()
            if line.startswith("  Line")]
    assert len(rows) == 3 and all(row[-1] == "yes" for row in rows), process.stdout


def test_the_api_path_equals_the_file_path(runs, tmp_path):
    """solve_system on the System read from the same file, the load added in Python:
    the command line's numbers, to the system's accuracy (FLOOR). Not bit for bit: the
    two processes' heaps differ, and OpenBLAS's AVX-512 kernels group a sum by its
    buffer's address mod 64 (OpenBLAS issues 317 and 5972), so the line solves' last bits
    and with them where each iteration stops differ; swapping OpenBLAS's kernels
    (OPENBLAS_CORETYPE Haswell, Sandybridge, Nehalem, Prescott) moved these numbers by at
    most 1.4e-7 of their largest entry (the grounded length), 4e-8 the others."""
    import subprocess
    import sys

    from helpers import child_env
    script = tmp_path / "api.py"
    out = tmp_path / "api.npz"
    script.write_text(f"""
import dataclasses, numpy as np
from petsc_rod.api import read_moordyn, solve_system
system, notes = read_moordyn({DECK!r})
body = system.bodies[0]
load = np.add(body.load, [10e3, 2e3, 0, 0, 0, 5e3])
system = dataclasses.replace(system, bodies=(dataclasses.replace(body, load=tuple(load)),))
from petsc_rod.api import Sweeps
r = solve_system(system, sweeps=Sweeps(excursion=("Body1", [0.0, 2e4], [90.0])))
from petsc4py import PETSc
from petsc_rod.system.equilibrium import SystemSolver
from petsc_rod.system.excursions import watch_circle
from petsc_rod.system.held_line import held_lines
solver = SystemSolver(system, held_lines(system, {{}}), PETSc.COMM_WORLD)
solver.solve()
circle = watch_circle(solver, "Body1", {WATCH[1]!r}, 360.0 * np.arange({WATCH[2]}) / {WATCH[2]})
solver.destroy()
np.savez({str(out)!r}, x=r.bodies["Body1"].position, K=r.bodies["Body1"].stiffness,
         F=np.array([r.end_forces[n] for n in ("Line1", "Line2", "Line3")]),
         T=np.array([r.end_tensions[n] for n in ("Line1", "Line2", "Line3")]),
         r=r.lines["Line2"].along_line(["r"])["r"], offsets=circle.offsets,
         poses=circle.poses, tension=circle.max_tension, grounded=circle.min_grounded,
         excursion=r.sweeps["excursion"].offsets)
""")
    process = subprocess.run([sys.executable, str(script)], cwd=REPO_ROOT, env=child_env(),
                             capture_output=True, text=True, timeout=300, check=False)
    assert process.returncode == 0, describe(process)
    api = np.load(out)

    def same(ours, theirs, rtol=FLOOR):
        """Within the system's accepted accuracy, relative to the largest entry."""
        ours, theirs = np.asarray(ours), np.asarray(theirs)
        return ours.shape == theirs.shape and \
            np.abs(ours - theirs).max() <= rtol * np.abs(theirs).max()

    def same_pose(ours, theirs):
        """Poses (..., 6): the positions (m) and the angles (rad) each to its own scale."""
        ours, theirs = np.asarray(ours), np.asarray(theirs)
        return same(ours[..., :3], theirs[..., :3]) and same(ours[..., 3:], theirs[..., 3:])

    with h5py.File(runs[1][1], "r") as f:
        system = f["system"]
        assert same_pose(api["x"], system["body_positions"][0])
        K = system["body_stiffness"][0]
        for rows in (slice(0, 3), slice(3, 6)):       # N/m, N/rad; N, N m/rad
            for columns in (slice(0, 3), slice(3, 6)):
                assert same(api["K"][rows, columns], K[rows, columns])
        assert same(api["F"], system["end_forces"][()])
        assert same(api["T"], system["end_tensions"][()])
        assert same(api["r"], f["lines/Line2/r"][()])
        # the command line's watch circle is the library function's on the same system
        circle = f["system/watch_circle"]
        assert np.array_equal(circle["heading"][()], [0, 90, 180, 270])
        assert np.array_equal(circle["load"][()], np.full(4, WATCH[1]))
        offsets = np.stack([circle["x_offset"][()], circle["y_offset"][()]], axis=1)
        assert same(api["offsets"], offsets)
        poses = np.stack([circle[k][()] for k in ("x", "y", "z", "roll", "pitch", "yaw")], 1)
        assert same_pose(api["poses"], poses)
        assert same(api["tension"], circle["max_tension"][()])
        # the touchdown point, interpolated between nodes: ten times looser
        assert same(api["grounded"], circle["min_grounded"][()], 10 * FLOOR)
        # under 20 kN the body moves about 2 to 3 m, downwind
        assert 1.5 < np.linalg.norm(offsets, axis=1).min() < 3.5
        assert circle["x_offset"][0] > 1.5 and circle["y_offset"][1] > 1.5
        assert circle.attrs["largest_tension"] == circle["max_tension"][()].max()
        # the API's sweeps: its curve (0 and 20 kN at 90 deg) the command line's (0, 10
        # and 20 kN), to the lines' accuracy (another warm path)
        offsets = f["system/excursion/offset"][()]
        assert np.abs(api["excursion"][0] - offsets[[0, 2]]).max() < 1e-6
        assert offsets[2] > 1.5


def refused(tmp_path, args, ranks=1):
    out = tmp_path / "bad.h5"
    process = run_petsc_rod(args + ["-rod_output", str(out)], ranks, 120)
    assert process.returncode == 2, describe(process)
    errors = [line for line in process.stdout.splitlines() if "error" in line]
    assert len(errors) == 1 and errors[0].startswith("petsc_rod: error: "), describe(process)
    assert "Traceback" not in process.stderr
    assert not out.exists() and not partial_files(out)
    return errors[0]


def test_bad_input_is_one_line_and_leaves_no_file(tmp_path):
    deck = tmp_path / "bad.dat"
    with open(DECK, encoding="utf-8") as source:
        deck.write_text(source.read().replace("1     main       1        4 ",
                                              "1     main       9        4 "))
    line = refused(tmp_path, ["-rod_system", str(deck)])
    assert "9" in line
    assert "-rod_length" in refused(tmp_path, ["-rod_system", DECK, "-rod_length", "3",
                                               "-rod_elements", "4"])
    assert "Body7" in refused(tmp_path, ["-rod_system", DECK, "-rod_system_body_load",
                                         "Body7,1,0,0,0,0,0"])
    assert "no such file" in refused(tmp_path, ["-rod_system", str(tmp_path / "none.dat")],
                                     ranks=2)
    copy = tmp_path / "deck.dat"
    with open(DECK, encoding="utf-8") as source:
        kept = source.read()
    copy.write_text(kept)
    process = run_petsc_rod(["-rod_system", str(copy), "-rod_output", str(copy)], 1, 120)
    assert process.returncode == 2 and "-rod_output" in process.stdout, describe(process)
    assert copy.read_text() == kept
    # the sweeps' options (the other refusals: tests/unit/test_system_sweeps.py)
    for option, value, word in (("watch_circle", "Body7,1e3", "Body7"),
                                ("excursion", "Body1,1e3,4,north", "north")):
        assert word in refused(tmp_path, ["-rod_system", DECK,
                                          f"-rod_system_{option}", value])
    assert "-rod_system_steps" in refused(tmp_path, ["-options_file",
                                                     "options/cantilever.opts",
                                                     "-rod_system_steps", "2"])


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_sweep_of_a_held_body_is_refused_and_the_output_kept(tmp_path, ranks):
    """The watch circle and the load-excursion curves of the coupled body of
    small_spread.dat (held in all six degrees of freedom) exited 0 with "largest offset
    0 m": now one line naming the body and why, exit 2, an existing -rod_output and no
    table written; the same option on a system's sweep (petsc_rod.sweep) likewise,
    before its folder is made."""
    held = os.path.join(REPO_ROOT, "tests", "data", "moordyn", "small_spread.dat")
    out = tmp_path / "kept.h5"
    out.write_bytes(b"an earlier result")
    why = ("body Body1 is held in {} (Coupled, CoupledPinned or Fixed in a MoorDyn file; "
           "Body.held): its position there is imposed, so the load moves it at no heading "
           "and every offset would be 0 m; sweep a body free where the load pushes it (Free "
           "in the file)")
    for option, value, axes in (("watch_circle", "Body1,1e5,4", "x and y"),
                                ("excursion", "Body1,1e5,2,90", "y")):
        process = run_petsc_rod(["-rod_system", held, f"-rod_system_{option}", value,
                                 "-rod_output", str(out), "-rod_table",
                                 str(tmp_path / "t.csv")], ranks, 120)
        assert process.returncode == 2, describe(process)
        assert process.stdout.splitlines() == [
            f"petsc_rod: error: -rod_system_{option} {value!r}: {why.format(axes)}"], \
            describe(process)
        assert "Traceback" not in process.stderr
        assert out.read_bytes() == b"an earlier result"
        assert sorted(os.listdir(tmp_path)) == ["kept.h5"]
    folder = tmp_path / "sweep"
    process = run_module("petsc_rod.sweep", [
        "-rod_system", held, "-rod_system_watch_circle", "Body1,1e5", "-sweep_offsets", "0,1",
        "-sweep_offset_of", "Body1", "-sweep_output", str(folder)], ranks)
    assert process.returncode == 2, describe(process)
    assert process.stdout.splitlines() == [
        f"petsc_rod.sweep: error: -rod_system_watch_circle 'Body1,1e5': "
        f"{why.format('x and y')}"], describe(process)
    assert not folder.exists()


def test_a_line_too_short_after_the_options_names_them(tmp_path):
    """A line that cannot reach its ends once -rod_system_line_length or
    -rod_system_offset changed it (a strain above any line type's to stretch to them):
    the line, its length, its ends' distance and the option, not a single line's
    -rod_initial_shape message (Line1: Point1 at (65, 0,
    -30) to Body1's fairlead at (5, 0, -5), 65 m)."""
    line = refused(tmp_path, ["-rod_system", DECK, "-rod_system_line_length", "Line1,10"])
    assert line == ("petsc_rod: error: line Line1: its length 10 m is shorter than its "
                    "ends' distance 65 m, Point1 to Body1 where the run starts "
                    "(-rod_system_line_length): it must stretch by 550 % or more to reach, "
                    "above 100 %, where the linear stretch models no line material; "
                    "lengthen the line or move its ends closer")
    line = refused(tmp_path, ["-rod_system", DECK, "-rod_system_offset", "Point1,1e9,0,0"])
    assert "line Line1: its length 70 m is shorter than its ends' distance 1e+09 m" in line
    assert "(-rod_system_offset)" in line and "-rod_initial_shape" not in line


@pytest.mark.parametrize("option, value, kinds, form", [
    ("offset", "Point1,1,0,0:Point1,2,0,0", "point/body", "NAME,dx,dy,dz"),
    ("line_length", "Line1,71:Line1,72", "line", "NAME,L"),
    ("body_load", "Body1,1,0,0,0,0,0:Body1,2,0,0,0,0,0", "body", "NAME,fx,fy,fz,mx,my,mz")])
def test_a_name_given_twice_in_one_option_is_refused(tmp_path, option, value, kinds, form):
    name = value.split(",")[0]
    assert refused(tmp_path, ["-rod_system", DECK, f"-rod_system_{option}", value]) == (
        f"petsc_rod: error: -rod_system_{option}: {name} is given twice; give each "
        f"{kinds} once, its values in one part {form}")


def test_help_lists_the_system_options():
    process = run_petsc_rod(["-rod_system", DECK, "-help"], 1, 120)
    assert process.returncode == 0, describe(process)
    for name in ("-rod_system ", "-rod_system_element_length ", "-rod_system_body_load ",
                 "-rod_system_steps ", "-rod_system_watch_circle ",
                 "-rod_system_excursion ", "-rod_al_rtol ", "-rod_system_modes ",
                 "-rod_system_modes_line_mass "):
        assert name in process.stdout, name


def test_no_equilibrium_writes_nothing_and_removes_old_tables(tmp_path):
    """Lines that cannot converge (two iterations allowed): exit 3 (not converged) in
    one line, no result file, and the tables of an earlier run at the same paths
    removed."""
    stale = [tmp_path / "t_Line1.csv", tmp_path / "t_system.csv"]
    for path in stale:
        path.write_text("an earlier run's\n")
    out = tmp_path / "none.h5"
    process = run_petsc_rod(["-rod_system", DECK, "-rod_al_max_it", "2", "-rod_output",
                             str(out), "-rod_table", str(tmp_path / "t.csv")], 1, 120)
    assert process.returncode == 3, describe(process)
    errors = [line for line in process.stdout.splitlines() if "error" in line]
    assert len(errors) == 1 and "did not converge" in errors[0], describe(process)
    assert not out.exists() and not partial_files(out)
    assert not any(path.exists() for path in stale)


def test_the_load_continuation_reaches_the_same_equilibrium(runs, tmp_path):
    """-rod_system_steps 3: the body load in three steps (more Newton iterations), the
    same pose and end forces as in one, to the lines' own accuracy (their end forces
    converged to about 1e-8 of themselves over a stiffness of 8e3 N/m: 6e-8 m apart)."""
    path, process = system_run(tmp_path, 1, "-rod_system_steps", "3")
    assert process.returncode == 0, describe(process)
    with h5py.File(runs[1][1], "r") as f, h5py.File(path, "r") as g:
        assert g["system"].attrs["iterations"] > f["system"].attrs["iterations"]
        assert np.abs(g["system/body_positions"][0, :3]
                      - f["system/body_positions"][0, :3]).max() < 1e-6
        assert np.abs(g["system/end_forces"][()] - f["system/end_forces"][()]).max() < (
            1e-7 * np.abs(f["system/end_forces"][()]).max())


def test_the_plots_of_a_system_file(runs, tmp_path):
    """python -m petsc_rod.plots on a system's file: the plan and elevation, the watch
    circle and the load-excursion curves, each a drawn PNG, from the file alone."""
    from helpers import png_summary
    figure = tmp_path / "spread.png"
    process = run_module("petsc_rod.plots", [str(runs[1][1]), str(figure)])
    assert process.returncode == 0, describe(process)
    for name, size in (("spread.png", (825, 1760)), ("spread_watch_circle.png", (605, 1760)),
                       ("spread_excursion.png", (605, 1760))):
        height, width, drawn = png_summary(tmp_path / name)
        assert (height, width) == size and drawn > 0.01, name
    # a figure that would replace the result file is refused in one line
    process = run_module("petsc_rod.plots", [str(runs[1][1]), str(runs[1][1])])
    assert process.returncode == 2 and process.stderr.count("\n") == 1, describe(process)


def test_the_report_page_of_a_system_file(runs, tmp_path):
    """python -m petsc_rod.report on a system's file: the bodies, the 6 x 6 stiffness,
    a row a line with the file's end tensions, the watch circle's and excursion's
    tables, the plan and elevation, the sweeps' graphs and each line's picture."""
    output = tmp_path / "page.html"
    process = run_module("petsc_rod.report", [str(runs[1][1]), "-o", str(output)])
    assert process.returncode == 0, describe(process)
    text = output.read_text()
    page = Page()
    page.feed(text)
    assert '<meta name="generator" content="petsc_rod.report">' in text
    assert {"bodies", "points", "lines", "stiffness_Body1", "watch_circle",
            "excursion"} <= set(page.tables)
    with h5py.File(runs[1][1], "r") as f:
        tensions = f["system/end_tensions"][()]
        K = f["system/body_stiffness"][0]
        circle = f["system/watch_circle/x_offset"][()]
    lines = page.tables["lines"]
    assert [row[0] for row in lines[1:]] == ["Line1", "Line2", "Line3"]
    for k, row in enumerate(lines[1:]):
        assert float(row[3]) == pytest.approx(tensions[k, 0] / 1e3, rel=1e-3)
        assert float(row[4]) == pytest.approx(tensions[k, 1] / 1e3, rel=1e-3)
        assert row[-1] == "yes" and float(row[8]) > 0
    stiffness = np.array([[float(v) for v in row[1:]]
                          for row in page.tables["stiffness_Body1"][1:]])
    assert np.allclose(stiffness, K, rtol=1e-3, atol=1e-3 * np.abs(K).max())
    rows = page.tables["watch_circle"]
    assert len(rows) == 5 and float(rows[1][2]) == pytest.approx(circle[0], rel=1e-3)
    assert len(page.tables["excursion"]) == 4
    assert page.alts == ["plan and elevation", "watch circle", "load-excursion curves",
                         "line Line1", "line Line2", "line Line3"]
    encoded = re.findall(r'src="data:image/png;base64,([^"]+)"', text)
    assert len(encoded) == 6
    assert all(base64.b64decode(e)[:8] == b"\x89PNG\r\n\x1a\n" for e in encoded)
    assert "LINE TYPES" in page.folded and "384.243E6" in page.folded     # the MoorDyn text


def test_the_report_refuses_a_broken_system_file(tmp_path):
    """A system file without its datasets: one line, exit 2, no page."""
    broken = tmp_path / "broken.h5"
    with h5py.File(broken, "w") as f:
        f.create_group("system").attrs["line_names"] = "Line1"
    output = tmp_path / "page.html"
    process = run_module("petsc_rod.report", [str(broken), "-o", str(output)])
    assert process.returncode == 2 and process.stderr.count("\n") == 1, describe(process)
    assert process.stderr.startswith("petsc_rod.report: error: ") and not output.exists()
    process = run_module("petsc_rod.plots", [str(broken), str(tmp_path / "x.png")])
    assert process.returncode == 2 and process.stderr.count("\n") == 1, describe(process)
def test_modes_of_each_line_on_the_command_line(tmp_path):
    """-rod_modes 3 on a system's run (2 ranks): a table per line in the run's lines and
    the group lines/<name>/modes of the result file, its frequencies those said."""
    path, process = system_run(tmp_path, 2, "-rod_modes", "3")
    assert process.returncode == 0, describe(process)
    assert "warning" not in process.stdout
    with h5py.File(path, "r") as f:
        for line in ("Line1", "Line2", "Line3"):
            assert f"line {line} (ends held): modes: 3 lowest" in process.stdout
            frequency = f[f"lines/{line}/modes/frequency"][()]
            assert frequency.shape == (3,) and frequency[-1] > 0.1
            assert f"{frequency[-1]:12.6g}" in process.stdout


# rank 1 alone raises while the bodies' stiffness is computed (after the equilibrium)
SYSTEM_ALONE = """
from petsc_rod.system import equilibrium
stiffness = equilibrium.SystemSolver.body_stiffness
def body_stiffness(self, name):
    if PETSc.COMM_WORLD.getRank() == 1:
        raise FloatingPointError("injected on rank 1")
    return stiffness(self, name)
equilibrium.SystemSolver.body_stiffness = body_stiffness
if sys.argv[1] == "api":
    from petsc_rod.api import read_moordyn, solve_system
    solve_system(read_moordyn(sys.argv[2])[0])
else:
    from petsc_rod import cli_system
    sys.exit(cli_system.run())
"""


@pytest.mark.parametrize("path", ["api", "cli"])
def test_one_rank_failing_alone_ends_the_system_run(tmp_path, path):
    """A system's run (the API's solve_system and the command line's) in which rank 1
    alone raises: every rank ends in the failing rank's one line, exit 4, no hang."""
    from helpers import run_failing_on_rank_1

    args = [path, DECK] if path == "api" else ["cli", "-rod_system", DECK]
    done = run_failing_on_rank_1(tmp_path / "alone.py", SYSTEM_ALONE, args, timeout=90)
    assert done.returncode == 4, describe(done)
    errors = [line for line in done.stdout.splitlines() if line.startswith("petsc_rod: error")]
    assert len(errors) == 1 and "rank 1 failed alone (FloatingPointError" in errors[0], \
        describe(done)


# rank 1's first line's modes fail before that rank has started SLEPc
MODES_ALONE = """
from petsc_rod.analysis.modes import ModesFailed
from petsc_rod.api import system_run
solve_modes, calls = system_run.solve_modes, []
def failing_first(problem, *args, **kwargs):
    calls.append(problem)
    if PETSc.COMM_WORLD.getRank() == 1 and len(calls) == 1:
        raise ModesFailed.of_error(RuntimeError("[0] injected on rank 1"))
    return solve_modes(problem, *args, **kwargs)
system_run.solve_modes = failing_first
if sys.argv[1] == "api":
    from petsc_rod.api import read_moordyn, solve_system
    solve_system(read_moordyn(sys.argv[2])[0], options={"modes": 3})
else:
    from petsc_rod import cli_system
    sys.exit(cli_system.run())
"""


@pytest.mark.parametrize("path", ["api", "cli"])
def test_a_line_whose_modes_fail_on_one_rank_ends_the_run_and_the_process(tmp_path, path):
    """A system's run with line modes (the API's options {'modes': 3}, the command
    line's -rod_modes 3) in which the eigensolver of rank 1's first line fails before
    that rank has started SLEPc: the run ends on every rank with the eigensolver's
    failure (the command line's exit 4; the API raises it), and the processes exit (SLEPc started on one rank only left PETSc's finalisation
    waiting on the other for ever: analysis/modes.start_slepc)."""
    pytest.importorskip("slepc4py")
    from helpers import run_failing_on_rank_1

    args = [path, DECK] if path == "api" else ["cli", "-rod_system", DECK, "-rod_modes", "3"]
    done = run_failing_on_rank_1(tmp_path / "modes_alone.py", MODES_ALONE, args, timeout=90)
    assert done.returncode == (1 if path == "api" else 4), describe(done)
    said = done.stdout + done.stderr
    assert "the modes' eigensolver (SLEPc) failed: injected on rank 1" in said, describe(done)


def test_a_table_that_would_replace_the_system_file_is_refused(tmp_path):
    """-rod_table X.dat with -rod_system X_system.dat (the system's table) or
    X_Line1_ends.dat (a line's ends' table): exit 2 in one line naming -rod_table, the
    input unchanged."""
    import hashlib

    with open(DECK, encoding="utf-8") as source:
        kept = source.read()
    for name in ("deck_system.dat", "deck_Line1_ends.dat"):
        copy = tmp_path / name
        copy.write_text(kept)
        before = hashlib.md5(copy.read_bytes()).hexdigest()
        process = run_petsc_rod(["-rod_system", str(copy), "-rod_table",
                                 str(tmp_path / "deck.dat")], 1, 120)
        assert process.returncode == 2, describe(process)
        errors = [line for line in process.stdout.splitlines() if "error" in line]
        assert len(errors) == 1 and "-rod_table" in errors[0] and name in errors[0], \
            describe(process)
        assert hashlib.md5(copy.read_bytes()).hexdigest() == before


# rank 1 alone raises while the system's result file is open
WRITE_ALONE = """
from petsc_rod.api import read_moordyn, solve_system, system_run
def system_datasets(*args):
    raise FloatingPointError("injected on rank 1")
if PETSc.COMM_WORLD.getRank() == 1:
    system_run.system_datasets = system_datasets
solve_system(read_moordyn(sys.argv[1])[0], output=sys.argv[2])
"""


def test_one_rank_failing_alone_while_writing_leaves_no_file(tmp_path):
    """solve_system with a result file, rank 1 alone raising while it is open: every
    rank ends in one line, exit 4, and neither the file nor its partial file is left."""
    from helpers import run_failing_on_rank_1

    out = tmp_path / "sys.h5"
    done = run_failing_on_rank_1(tmp_path / "write_alone.py", WRITE_ALONE,
                                 [DECK, str(out)], timeout=90)
    assert done.returncode == 4, describe(done)
    errors = [line for line in done.stdout.splitlines() if line.startswith("petsc_rod: error")]
    assert len(errors) == 1 and "rank 1 failed alone (FloatingPointError" in errors[0], \
        describe(done)
    assert not out.exists() and not partial_files(out)


def test_the_system_modes_in_the_lines_the_file_and_the_table(tmp_path):
    """-rod_system_modes: the bodies' modes about the equilibrium in the run's lines
    (said to be with the lines quasi-static), the file's group system/modes and the
    table FILE_system_modes.csv, the same on 1 and 2 ranks; refused without -rod_system."""
    found = {}
    for ranks in (1, 2):
        folder = tmp_path / f"r{ranks}"
        folder.mkdir()
        out, process = system_run(folder, ranks, "-rod_system_modes", "1",
                                  "-rod_system_modes_line_mass", "1")
        assert process.returncode == 0, describe(process)
        assert "the lines quasi-static" in process.stdout
        assert "the lines' mass lumped half at each end" in process.stdout
        with h5py.File(out, "r") as f:
            group = f["system/modes"]
            frequencies = group["frequencies"][()]
            assert group.attrs["dofs"].startswith("Body1 x,Body1 y,Body1 z")
            assert int(group.attrs["line_mass"]) == 1
        rows = np.genfromtxt(folder / "system_system_modes.csv", delimiter=",",
                             names=True, dtype=None, encoding="utf-8")
        assert np.allclose(rows["frequency_Hz"], frequencies, rtol=1e-9)
        # the lines' mass at the fairleads gives the rotations inertia: six modes
        assert len(frequencies) == 6 and np.all(np.diff(frequencies) >= 0)
        found[ranks] = frequencies
    assert np.allclose(found[1], found[2], rtol=1e-9)
    page = tmp_path / "page.html"
    process = run_module("petsc_rod.report", [str(tmp_path / "r1" / "system.h5"), "-o",
                                              str(page)])
    assert process.returncode == 0, describe(process)
    text = page.read_text(encoding="utf-8")
    assert "Natural modes of the bodies and free points" in text and 'id="modes"' in text
    assert f"{1 / found[1][0]:.4g}"[:4] in text             # the first period, in s
    assert "-rod_system_modes" in refused(tmp_path, ["-options_file", "options/cantilever.opts",
                                                     "-rod_system_modes", "1"])


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_stop_signal_during_the_newton_ends_the_run_there(tmp_path, ranks):
    """SIGTERM sent once the run has said its notes (before its lines are solved) stops
    it at the next iteration of the system's Newton, not once the equilibrium is found:
    one line naming the load factor and the iteration, 128 + 15 (mpiexec: 1), no file."""
    import signal
    import subprocess

    from helpers import child_env, petsc_rod_command
    out = tmp_path / "system.h5"
    process = subprocess.Popen(
        # 0.2 m elements: a Newton long enough that the signal, forwarded by mpiexec,
        # lands inside it on a fast machine too
        petsc_rod_command(["-rod_system", DECK, "-rod_system_body_load", LOAD,
                           "-rod_system_element_length", "0.2",
                           "-rod_output", str(out), *SWEEPS], ranks),
        cwd=REPO_ROOT, env=child_env(), stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
        text=True)
    try:
        first = process.stdout.readline()
        assert first.startswith("petsc_rod: note"), first
        process.send_signal(signal.SIGTERM)
        output, _ = process.communicate(timeout=300)
    finally:
        process.kill()
    errors = [line for line in output.splitlines() if line.startswith("petsc_rod: error")]
    assert process.returncode == (143 if ranks == 1 else 1), output
    assert len(errors) == 1, output
    assert "Traceback" not in output
    if ranks == 1:
        assert "stopped by SIGTERM during the system's Newton (load factor" in errors[0]
        assert "equilibrium in" not in output
    else:
        # under mpiexec the first line reaches the test through its forwarding, late: the
        # signal may land in a later Newton of the run (the watch circle's), between the
        # equilibrium's Newton and the records (the lines settled and tested there), or
        # after the sweeps; either way the run stops in one line with nothing written
        assert ("stopped by SIGTERM during the system's Newton (load factor" in errors[0]
                or "stopped by SIGTERM after the system's equilibrium was found; nothing "
                   "written" in errors[0]
                or "stopped by SIGTERM before the system's results were written; nothing "
                   "written" in errors[0]), errors[0]
    assert not out.exists() and not partial_files(out)
