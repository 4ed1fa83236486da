"""Sweeps and the report from the command line (spawns python -m petsc_rod.sweep and
python -m petsc_rod.report: serial): a 3-case offset sweep of a small riser (the SCR of
options/riser_catenary.opts on 200 elements, about 40 iterations a case) on 1 and 2
ranks gives the same summary; a case that fails in the middle is marked and the next
still runs; warm starts take fewer iterations than each case's own start (a straight
start in 4 steps); bad sweep input is one line, exit 2, before any run; the report's
table holds the files' numbers and its pictures are drawn."""

import base64
import csv
import html.parser
import io
import os
import subprocess
import sys

import h5py
import numpy as np
import pytest

from helpers import REPO_ROOT, child_env, describe, mpiexec

TIMEOUT = 300
RISER = ["-options_file", "options/riser_catenary.opts", "-rod_elements", "200"]
# started straight in 4 steps, a cold start that costs its continuation
STRAIGHT = ["-rod_initial_shape", "straight", "-rod_steps", "4"]
OFFSETS = ["-sweep_offsets", "0,50", "-sweep_headings", "near,far"]
CASES = ["offset0", "near50", "far50"]


def run_module(module, args, ranks=1):
    """``python -m module args`` (under mpiexec for several ranks) from the repository."""
    command = mpiexec(ranks) + [sys.executable, "-m", module] + list(args)
    return subprocess.run(command, cwd=REPO_ROOT, env=child_env(), capture_output=True,
                          text=True, timeout=TIMEOUT, check=False)


def read_summary(folder):
    """{case: {column: text}} of a sweep's summary.csv."""
    with open(os.path.join(folder, "summary.csv"), newline="") as f:
        return {row["case"]: row for row in csv.DictReader(f)}


@pytest.fixture(scope="module")
def offset_sweep(tmp_path_factory):
    """The 3-case offset sweep on one rank: (its folder, the process)."""
    folder = tmp_path_factory.mktemp("sweep") / "offsets"
    process = run_module("petsc_rod.sweep", RISER + OFFSETS + ["-sweep_output", str(folder)])
    return folder, process


@pytest.mark.serial
def test_offset_sweep_writes_a_file_per_case_and_the_summary(offset_sweep):
    folder, process = offset_sweep
    assert process.returncode == 0, describe(process)
    rows = read_summary(folder)
    assert list(rows) == CASES
    for name, row in rows.items():
        assert row["status"] == "converged", row
        # -sweep_start auto: a case that starts from its catenary starts from it
        assert row["start"] == "own start", row
        with h5py.File(folder / f"{name}.h5", "r") as f:
            assert f.attrs["converged"] == 1
            # the summary's numbers are the file's attributes (full precision in the CSV)
            assert float(row["top_tension (N)"]) == float(f.attrs["top_tension"])
            assert float(row["min_bend_radius (m)"]) == float(f.attrs["min_bend_radius"])
            assert float(row["touchdown_S (m)"]) == float(f.attrs["touchdown_S"])
    # the offsets: near toward the anchor (x smaller), far away from it
    assert rows["near50"]["-rod_end_position"] == "1107,0,1000"
    assert rows["far50"]["-rod_end_position"] == "1207,0,1000"
    # physics: the far offset pulls the line tighter
    tension = {k: float(v["top_tension (N)"]) for k, v in rows.items()}
    assert tension["near50"] < tension["offset0"] < tension["far50"]
    assert (folder / "summary.md").read_text().count("\n| ") == 1 + len(CASES)


@pytest.mark.serial
def test_the_same_summary_on_two_ranks(offset_sweep, tmp_path):
    folder, _ = offset_sweep
    other = tmp_path / "two"
    process = run_module("petsc_rod.sweep", RISER + OFFSETS + ["-sweep_output", str(other)],
                         ranks=2)
    assert process.returncode == 0, describe(process)
    one, two = read_summary(folder), read_summary(other)
    assert list(one) == list(two) == CASES
    for name in CASES:
        for column in ("top_tension (N)", "top_angle (deg)", "touchdown_S (m)",
                       "min_bend_radius (m)", "max_curvature (1/m)"):
            assert float(one[name][column]) == pytest.approx(float(two[name][column]),
                                                             rel=1e-6), (name, column)


@pytest.mark.serial
def test_warm_starts_take_fewer_iterations(tmp_path):
    """Each offset case from the converged offset0 (a one-step walk) against its own start
    (straight, 4 steps): measured 43 and 39 against about 300 iterations; asserted only
    that the warm start takes less than half."""
    warm, cold = tmp_path / "warm", tmp_path / "cold"
    # -sweep_start auto (the default) warm-starts a case whose own start is straight
    for folder, start in ((warm, "auto"), (cold, "scene")):
        process = run_module("petsc_rod.sweep", RISER + STRAIGHT + OFFSETS + [
            "-sweep_output", str(folder), "-sweep_start", start])
        assert process.returncode == 0, describe(process)
    warm_rows, cold_rows = read_summary(warm), read_summary(cold)
    for name in ("near50", "far50"):
        assert warm_rows[name]["start"] == "from offset0"
        assert cold_rows[name]["start"] == "own start"
        assert int(warm_rows[name]["iterations (1)"]) < int(cold_rows[name]["iterations (1)"]) / 2
        assert float(warm_rows[name]["top_tension (N)"]) == pytest.approx(
            float(cold_rows[name]["top_tension (N)"]), rel=1e-6)


@pytest.mark.serial
def test_a_failing_case_is_marked_and_the_next_runs(tmp_path):
    cases = tmp_path / "cases.txt"
    cases.write_text("# offsets, the middle case with one iteration allowed\n"
                     "name rod_end_position rod_al_max_it\n"
                     "base 1157,0,1000 -\n"
                     "capped 1107,0,1000 1\n"
                     "far 1207,0,1000 -\n")
    folder = tmp_path / "out"
    process = run_module("petsc_rod.sweep", ["-options_file", "options/riser_catenary.opts",
                                             "-rod_elements", "200", "-sweep_cases", str(cases),
                                             "-sweep_output", str(folder),
                                             "-sweep_start", "nearest"])
    assert process.returncode == 3, describe(process)
    rows = read_summary(folder)
    assert list(rows) == ["base", "capped", "far"]
    assert rows["capped"]["exit"] == "3"
    assert rows["capped"]["status"] == "not converged (max_it)"
    assert rows["capped"]["top_tension (N)"] == ""         # no equilibrium: no numbers
    # the warm start failed, then the case's own start (-sweep_retry)
    assert rows["capped"]["start"] == "own start (from base: exit 3)"
    assert rows["far"]["status"] == "converged"
    # the cap was the case's own: the next case ran with the default again
    assert rows["far"]["-rod_al_max_it"] == "(base)"
    assert rows["far"]["start"] == "from base"              # never from the failed case
    with h5py.File(folder / "far.h5", "r") as f:
        assert "-rod_al_max_it 2000" in f.attrs["options_in_effect"]
    assert "1 case(s)" not in process.stdout
    assert "2 of 3 case(s) converged; not: capped" in process.stdout


@pytest.mark.serial
def test_a_case_with_bad_input_is_marked_and_the_sweep_goes_on(tmp_path):
    """A value petsc_rod refuses is that case's bad input (exit 2 in the table), not the
    sweep's: the paper scene (80 elements) with a two-number end position in the middle."""
    cases = tmp_path / "cases.txt"
    cases.write_text("name rod_end_position\nxf16 16,4,0\nwrong 1,2\nxf15 15,5,0\n")
    folder = tmp_path / "out"
    process = run_module("petsc_rod.sweep", ["-options_file", "options/paper.opts",
                                             "-sweep_cases", str(cases),
                                             "-sweep_output", str(folder)])
    assert process.returncode == 3, describe(process)
    assert "-rod_end_position '1,2': expected 3 comma-separated numbers" in process.stdout
    rows = read_summary(folder)
    assert [(r["exit"], r["status"]) for r in rows.values()] == [
        ("0", "converged"), ("2", "bad input"), ("0", "converged")]
    # the paper scene needs its 8 steps from straight; from xf16, one
    assert rows["xf15"]["start"] == "from xf16"
    assert int(rows["xf15"]["iterations (1)"]) < int(rows["xf16"]["iterations (1)"]) / 2
    assert not (folder / "wrong.h5").exists()


@pytest.mark.serial
@pytest.mark.parametrize("content, args, message", [
    ("name rod_end_positio\na 1,2,3\n", [], "column rod_end_positio is not a petsc_rod option"),
    ("name rod_end_position\na 1,2,3 4\n", [], "3 value(s) for 2 column(s)"),
    ("name rod_output\na x.h5\n", [], "the sweep sets -rod_output itself"),
    ("name rod_end_position\na 1,2,3\na 1,2,4\n", [], "two cases are named a"),
    ("name rod_end_position\n", [], "at least one case row"),
    ("name rod_end_position\na 1,2,3\n", ["-sweep_offset", "1"], "did you mean -sweep_offsets"),
    ("name rod_end_position\na 1,2,3\n", ["-sweep_headings", "up"], "unknown heading up"),
])
def test_bad_sweep_input_is_one_line_and_exit_2(tmp_path, content, args, message):
    cases = tmp_path / "cases.txt"
    cases.write_text(content)
    folder = tmp_path / "out"
    extra = ["-sweep_offsets", "10"] if "-sweep_headings" in args else []
    process = run_module("petsc_rod.sweep", ["-options_file", "options/riser_catenary.opts",
                                             "-sweep_cases", str(cases), "-sweep_output",
                                             str(folder)] + args + extra)
    assert process.returncode == 2, describe(process)
    lines = [line for line in process.stdout.splitlines() if line.strip()]
    assert len(lines) == 1 and message in lines[0], describe(process)
    assert not folder.exists()


class Tables(html.parser.HTMLParser):
    """The cells of the <table id=summary> and the embedded PNGs of a page."""

    def __init__(self):
        super().__init__()
        self.rows, self.images, self._in, self._cell = [], [], False, None

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "table":
            self._in = attrs.get("id") == "summary"
        elif tag == "tr" and self._in:
            self.rows.append([])
        elif tag in ("td", "th") and self._in:
            self._cell = ""
        elif tag == "img":
            self.images.append(attrs["src"])

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self.rows[-1].append(self._cell)
            self._cell = None
        elif tag == "table":
            self._in = False

    def handle_data(self, data):
        if self._cell is not None:
            self._cell += data


@pytest.mark.serial
def test_the_report_of_a_sweep(offset_sweep, tmp_path):
    import matplotlib.image

    folder, _ = offset_sweep
    output = tmp_path / "report.html"
    process = run_module("petsc_rod.report", [str(folder), "-o", str(output)])
    assert process.returncode == 0, describe(process)
    text = output.read_text()
    assert "http://" not in text and "https://" not in text      # self-contained
    page = Tables()
    page.feed(text)
    header, rows = page.rows[0], {row[0]: row for row in page.rows[1:]}
    assert list(rows) == CASES
    for name, row in rows.items():
        cells = dict(zip(header, row))
        with h5py.File(folder / f"{name}.h5", "r") as f:
            for column, attribute in (("top_tension (N)", "top_tension"),
                                      ("top_angle (deg)", "top_angle"),
                                      ("touchdown_S (m)", "touchdown_S"),
                                      ("min_bend_radius (m)", "min_bend_radius")):
                assert float(cells[column]) == pytest.approx(float(f.attrs[attribute]),
                                                             rel=1e-5), (name, column)
    # the excursion graphs, one range graph a quantity (effective tension, bend radius,
    # curvature, bending moment, declination, seabed clearance) and one picture per
    # case, each a PNG with something drawn
    assert len(page.images) == 1 + 6 + len(CASES)
    for source in page.images:
        assert source.startswith("data:image/png;base64,")
        data = base64.b64decode(source.split(",", 1)[1])
        assert data[:8] == b"\x89PNG\r\n\x1a\n"
        pixels = matplotlib.image.imread(io.BytesIO(data), format="png")[..., :3]
        drawn = float(np.mean(np.any(pixels < 0.95, axis=-1)))
        assert 0.02 < drawn < 0.9, drawn
    assert "<pre id=\"options\">" in text and "-rod_stiffness" in text


# The ends' columns of the summary and the attributes they are.
END_COLUMNS = ("fairlead_tension", "fairlead_horizontal", "fairlead_vertical",
               "fairlead_force_x", "fairlead_force_y", "fairlead_force_z", "anchor_tension",
               "anchor_horizontal", "anchor_vertical", "touchdown_x", "touchdown_y")


@pytest.mark.serial
def test_the_summary_has_the_end_forces_and_the_touchdown_excursion(offset_sweep, tmp_path):
    """summary.csv holds each case's fairlead and anchor forces, the anchor's uplift
    flag and the touchdown's position, equal to its file's attributes; the fairlead's
    offset is -50, 0, 50 m (the pin's position to its constraint residual, 1e-4 m); the
    touchdown's excursion is the touchdown's x less offset0's (the anchor-to-fairlead
    direction is +x); the horizontal force grows with the offset (the load-excursion
    curve) and the touchdown moves toward the anchor; the report's table shows the same
    numbers. Before, none of these columns."""
    folder, process = offset_sweep
    assert process.returncode == 0, describe(process)
    rows = read_summary(folder)
    for name, row in rows.items():
        with h5py.File(folder / f"{name}.h5", "r") as f:
            for column in END_COLUMNS:
                unit = "m" if column.startswith("touchdown") else "N"
                assert float(row[f"{column} ({unit})"]) == float(f.attrs[column]), column
            assert int(row["anchor_uplift (1)"]) == int(f.attrs["anchor_uplift"]) == 0
            assert float(row["fairlead_horizontal (N)"]) == -float(f.attrs["end_force"][0])
            np.testing.assert_allclose(f.attrs["fairlead_position"][1:], [0.0, 1000.0],
                                       atol=1e-4)
    offset = {k: float(v["fairlead_offset (m)"]) for k, v in rows.items()}
    assert offset == pytest.approx({"offset0": 0.0, "near50": -50.0, "far50": 50.0},
                                   abs=1e-4)
    x0 = float(rows["offset0"]["touchdown_x (m)"])
    for name, row in rows.items():
        assert float(row["touchdown_excursion (m)"]) == pytest.approx(
            float(row["touchdown_x (m)"]) - x0, rel=1e-12, abs=1e-9)
    H = {k: float(v["fairlead_horizontal (N)"]) for k, v in rows.items()}
    assert H["near50"] < H["offset0"] < H["far50"]
    excursion = {k: float(v["touchdown_excursion (m)"]) for k, v in rows.items()}
    assert excursion["far50"] < -30.0 < 30.0 < excursion["near50"]
    output = tmp_path / "report.html"
    process = run_module("petsc_rod.report", [str(folder), "-o", str(output)])
    assert process.returncode == 0, describe(process)
    page = Tables()
    page.feed(output.read_text())
    header, shown = page.rows[0], {row[0]: row for row in page.rows[1:]}
    for name, row in rows.items():
        cells = dict(zip(header, shown[name]))
        for column in ("fairlead_horizontal (N)", "fairlead_offset (m)",
                       "touchdown_excursion (m)"):
            assert float(cells[column]) == pytest.approx(float(row[column]), rel=1e-5,
                                                         abs=1e-9)
    assert 'alt="excursion graphs"' in output.read_text()


class Page(html.parser.HTMLParser):
    """Every table of a page by its id ({id: rows of cell texts}), the images' alt
    texts, and the text inside <details>."""

    def __init__(self):
        super().__init__()
        self.tables, self.alts, self.folded = {}, [], ""
        self._table, self._cell, self._details = None, None, 0

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "table":
            self._table = self.tables.setdefault(attrs.get("id"), [])
        elif tag == "tr" and self._table is not None:
            self._table.append([])
        elif tag in ("td", "th") and self._table is not None:
            self._cell = ""
        elif tag == "img":
            self.alts.append(attrs.get("alt", ""))
        elif tag == "details":
            self._details += 1

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self._table[-1].append(self._cell)
            self._cell = None
        elif tag == "table":
            self._table = None
        elif tag == "details":
            self._details -= 1

    def handle_data(self, data):
        if self._cell is not None:
            self._cell += data
        if self._details:
            self.folded += data


@pytest.mark.serial
def test_the_report_page_an_engineer_reads(offset_sweep, tmp_path):
    """The page says its units once and shows the results in kN, m, deg (the files'
    numbers to the 4 digits shown); the inputs given, not the solver's options (those
    folded in <details>); a regions' table naming the governing case of each extreme
    (its numbers the files' region_* attributes); one range graph a quantity, each titled
    with the case that governs it; the allowable bend radius drawn when given; under a
    few seconds. Before, one strip of five graphs, numbers in N, every option listed, no
    region table."""
    import time

    folder, _ = offset_sweep
    output = tmp_path / "report.html"
    begun = time.perf_counter()
    process = run_module("petsc_rod.report", [str(folder), "-o", str(output),
                                              "--min-bend-radius", "150"])
    took = time.perf_counter() - begun
    assert process.returncode == 0, describe(process)
    assert took < 20.0, took
    text = output.read_text()
    assert text.count("Units: forces kN, moments kN m, stresses MPa, angles degrees") == 1
    page = Page()
    page.feed(text)
    results = {row[0]: row for row in page.tables["results"][1:]}
    assert page.tables["results"][0] == ["quantity", "unit"] + CASES
    inputs = dict(page.tables["inputs"][1:])
    assert inputs["-rod_stiffness"] == "5.6e7,5.6e7,4.3e7"
    assert not any(name.startswith(("-rod_al_", "-rod_d1_", "-sweep_")) for name in inputs)
    assert "-rod_al_penalty" in page.folded and "-rod_al_penalty" not in inputs
    regions = {row[0]: row for row in page.tables["regions"][1:]}
    assert list(regions)[0] == "hang_off" and "grounded" in regions
    largest, governing = -np.inf, None
    for k, name in enumerate(CASES):
        with h5py.File(folder / f"{name}.h5", "r") as f:
            for label, unit, attribute, factor in (
                    ("top tension", "kN", "top_tension", 1e-3),
                    ("fairlead horizontal force H", "kN", "fairlead_horizontal", 1e-3),
                    ("touchdown S", "m", "touchdown_S", 1.0),
                    ("smallest bend radius", "m", "min_bend_radius", 1.0)):
                assert results[label][1] == unit
                assert float(results[label][2 + k]) == pytest.approx(
                    float(f.attrs[attribute]) * factor, rel=1e-3), (name, label)
            assert results["anchor lifts off"][2 + k] == "no"
            names = [n.decode() if isinstance(n, bytes) else n for n in f.attrs["region_names"]]
            tension = float(f.attrs["region_max_tension"][names.index("hang_off")])
            if tension > largest:
                largest, governing = tension, name
    assert float(regions["hang_off"][3]) == pytest.approx(largest / 1e3, rel=1e-3)
    assert regions["hang_off"][4] == governing == "far50"
    graphs = [alt for alt in page.alts if alt.startswith("range graph: ")]
    assert graphs == [f"range graph: {q}" for q in (
        "effective tension", "bend radius", "curvature", "bending moment", "declination",
        "seabed clearance")]
    assert "the allowable bend radius 150 m" in text


@pytest.mark.serial
def test_the_report_of_one_file_and_a_bad_source(offset_sweep, tmp_path):
    folder, _ = offset_sweep
    output = tmp_path / "one.html"
    process = run_module("petsc_rod.report", [str(folder / "far50.h5"), "-o", str(output)])
    assert process.returncode == 0, describe(process)
    page = Tables()
    page.feed(output.read_text())
    assert len(page.rows) == 2 and page.rows[1][0] == "far50"
    assert len(page.images) == 1
    process = run_module("petsc_rod.report", [str(tmp_path), "-o", str(output)])
    assert process.returncode == 2 and "sweep.json" in process.stderr, describe(process)


@pytest.mark.serial
def test_the_summary_shows_what_newer_files_add(tmp_path):
    """Attributes this version does not write (a utilisation, a von Mises stress) appear
    in the table with the file's unit; a vector attribute does not."""
    import json

    from petsc_rod.sweep import summary

    path = tmp_path / "a.h5"
    with h5py.File(path, "w") as f:
        f.attrs.update(converged=1, total_iterations=7, top_tension=1.5e6,
                       max_utilisation=0.61, max_von_mises=2.9e8, end_force=[1.0, 2.0, 3.0],
                       attribute_units=json.dumps({"top_tension": "N", "max_utilisation": "1",
                                                   "max_von_mises": "Pa"}))
    header, rows = summary.table([{"name": "a", "options": {}, "code": 0, "start": "",
                                   "file": str(path)}], [])
    cells = dict(zip(header, rows[0]))
    assert cells["top_tension (N)"] == 1.5e6 and cells["iterations (1)"] == 7
    assert cells["max_utilisation (1)"] == 0.61 and cells["max_von_mises (Pa)"] == 2.9e8
    assert not any(h.startswith("end_force") for h in header)


@pytest.mark.serial
def test_warm_starts_across_attachments(tmp_path):
    """-sweep_start nearest over a point load (the 3 km catenary on 20 elements): each
    case after the first warm-starts from a file with other attachments (none, one, two,
    none again) and converges to the state of its own start."""
    cases = tmp_path / "cases.txt"
    cases.write_text("name rod_point_load\nnone -\none 1000,0,0,-5e5\n"
                     "two 1000,0,0,-5e5,2000,0,0,2e5\nagain -\n")
    rows = {}
    for start in ("nearest", "scene"):
        folder = tmp_path / start
        process = run_module("petsc_rod.sweep", ["-options_file", "options/catenary.opts",
                                                 "-rod_elements", "20", "-sweep_cases",
                                                 str(cases), "-sweep_output", str(folder),
                                                 "-sweep_start", start])
        assert process.returncode == 0, describe(process)
        assert "Traceback" not in process.stdout + process.stderr
        rows[start] = read_summary(folder)
    assert [r["start"] for r in rows["nearest"].values()] == [
        "own start", "from none", "from none", "from none"]
    for name, row in rows["nearest"].items():
        assert row["status"] == "converged"
        with h5py.File(tmp_path / "nearest" / f"{name}.h5", "r") as warm, \
                h5py.File(tmp_path / "scene" / f"{name}.h5", "r") as own:
            assert abs(warm["r"][:] - own["r"][:]).max() < 1e-5, name


# The 3 km catenary on 20 elements: a case runs in a fraction of a second.
QUICK = ["-options_file", "options/catenary.opts", "-rod_elements", "20"]


def quick_sweep(tmp_path, rows, folder, extra=()):
    """A sweep of QUICK over -rod_point_load with the case file ``rows`` (name value
    lines) into ``folder``; the process."""
    cases = tmp_path / f"cases{abs(hash(rows))}.txt"
    cases.write_text("name rod_point_load\n" + rows)
    return run_module("petsc_rod.sweep", QUICK + ["-sweep_cases", str(cases),
                                                  "-sweep_output", str(folder)] + list(extra))


def one_line(process, *words):
    lines = [line for line in process.stdout.splitlines() if line.strip()]
    assert process.returncode == 2, describe(process)
    assert len(lines) == 1 and lines[0].startswith("petsc_rod.sweep: error: "), \
        describe(process)
    assert all(word in lines[0] for word in words), describe(process)


@pytest.mark.serial
@pytest.mark.parametrize("rows, words", [
    ("summary -\n", ["case summary", "summary.csv", "the sweep's own"]),
    ("a -\na_regions 1000,0,0,-5e5\n", ["case a_regions", "a_regions.csv", "case a's"]),
    ("a -\na.interrupted 1000,0,0,-5e5\n", ["case a.interrupted", "case a's"]),
], ids=["summary", "regions", "interrupted"])
def test_a_case_whose_files_are_others_is_refused(tmp_path, rows, words):
    folder = tmp_path / "out"
    one_line(quick_sweep(tmp_path, rows, folder, ["-rod_table", "t.csv"]), *words)
    assert not folder.exists()


@pytest.mark.serial
def test_a_folder_reused_holds_only_the_last_sweeps_files(tmp_path):
    """Two sweeps into one folder, one after the other: the second removes the first's
    files (its sweep.json lists them) before its first case; every file in the folder is
    in its summary."""
    folder = tmp_path / "out"
    first = quick_sweep(tmp_path, "a -\nb 1000,0,0,-5e5\n", folder, ["-rod_table", "t.csv"])
    assert first.returncode == 0, describe(first)
    assert sorted(os.listdir(folder)) == ["a.csv", "a.h5", "b.csv", "b.h5", "summary.csv",
                                          "summary.md", "sweep.json"]
    second = quick_sweep(tmp_path, "c 2000,0,0,-5e5\n", folder)
    assert second.returncode == 0, describe(second)
    assert list(read_summary(folder)) == ["c"]
    assert sorted(os.listdir(folder)) == ["c.h5", "summary.csv", "summary.md", "sweep.json"]


@pytest.mark.serial
def test_a_folder_not_a_sweeps_or_holding_an_input_is_refused(tmp_path):
    import fcntl

    folder = tmp_path / "out"
    assert quick_sweep(tmp_path, "a -\n", folder).returncode == 0
    result = (folder / "a.h5").read_bytes()
    # a file no sweep wrote: refused, nothing removed
    (folder / "notes.txt").write_text("mine\n")
    one_line(quick_sweep(tmp_path, "b -\n", folder), "holds notes.txt", "choose another folder")
    assert (folder / "notes.txt").read_text() == "mine\n" and (folder / "a.h5").exists()
    (folder / "notes.txt").unlink()
    # the earlier sweep's file as this sweep's input: refused, the file kept
    one_line(quick_sweep(tmp_path, "b -\n", folder, ["-rod_initial", str(folder / "a.h5")]),
             "-rod_initial", "would remove or replace")
    assert (folder / "a.h5").read_bytes() == result
    # a sweep still writing into it (its lock held)
    lock = os.open(folder, os.O_RDONLY)
    try:
        fcntl.flock(lock, fcntl.LOCK_EX)
        one_line(quick_sweep(tmp_path, "b -\n", folder), "another sweep is writing into it")
    finally:
        os.close(lock)
    assert (folder / "a.h5").read_bytes() == result


@pytest.mark.serial
def test_a_sweep_killed_mid_case_can_be_run_again_into_its_folder(tmp_path):
    """A sweep killed outright (SIGKILL) while its first case writes leaves that case's
    partial file: the same sweep run again into the folder removes it (its case's, its
    process gone) and runs; a partial file of another name stays a stranger, and one of
    a live process (pid 1) is refused as a run still running."""
    import signal
    import time

    folder = tmp_path / "out"
    rows = "a -\nb 1000,0,0,-5e5\n"
    cases = tmp_path / "killed.txt"
    cases.write_text("name rod_point_load\n" + rows)
    slow = ["-rod_steps", "50", "-rod_snes_type", "nrichardson", "-rod_al_newton", "0",
            "-rod_al_rtol", "1e-10"]
    process = subprocess.Popen([sys.executable, "-m", "petsc_rod.sweep"] + QUICK + slow
                               + ["-sweep_cases", str(cases), "-sweep_output", str(folder)],
                               cwd=REPO_ROOT, env=child_env(), stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)

    def partials():
        return [n for n in os.listdir(folder) if n.endswith(".partial")] if folder.exists() else []

    deadline = time.monotonic() + 120
    try:
        while not partials():
            assert process.poll() is None and time.monotonic() < deadline
            time.sleep(0.02)
    finally:
        process.send_signal(signal.SIGKILL)
        process.wait()
    assert len(partials()) == 1 and partials()[0].startswith("a.h5."), partials()
    again = quick_sweep(tmp_path, rows, folder)
    assert again.returncode == 0, describe(again)
    assert sorted(os.listdir(folder)) == ["a.h5", "b.h5", "summary.csv", "summary.md",
                                          "sweep.json"]
    # another name's partial file is not the sweep's: refused, kept
    (folder / "notes.h5.1-abcdef.partial").write_text("x")
    one_line(quick_sweep(tmp_path, rows, folder), "holds notes.h5.1-abcdef.partial")
    (folder / "notes.h5.1-abcdef.partial").unlink()
    # a case's partial file whose process lives: a run still writing, refused, kept
    (folder / "b.h5.1-abcdef.partial").write_text("x")
    one_line(quick_sweep(tmp_path, rows, folder), "b.h5.1-abcdef.partial", "still running")
    assert (folder / "b.h5.1-abcdef.partial").exists() and (folder / "a.h5").exists()


def test_which_partial_files_a_killed_sweep_left():
    """runner.left_partials: a run's partial file of a case file (its pid gone) and a
    summary's temporary file are stale; one whose pid lives is live; another name's,
    or a file that only looks partial, is neither."""
    from petsc_rod.sweep.runner import SWEEP_FILES, case_files, left_partials

    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)
    dead = int(gone.stdout)
    files = set(SWEEP_FILES).union(case_files("a"))
    entries = [f"a.h5.{dead}-0a1b2c.partial", f"a_regions.csv.{dead}-ffffff.partial",
               ".summary.csv.k3j_x9q2.partial.csv", f"a.h5.{os.getpid()}-0a1b2c.partial",
               f"b.h5.{dead}-0a1b2c.partial", f"a.h5.{dead}.partial", "a.h5"]
    stale, live = left_partials(entries, files)
    assert stale == entries[:3]
    assert live == [entries[3]]


def test_a_bad_allowable_bend_radius_is_one_line_and_exit_2(offset_sweep, tmp_path):
    folder, _ = offset_sweep
    output = tmp_path / "r.html"
    process = run_module("petsc_rod.report", [str(folder), "-o", str(output),
                                              "--min-bend-radius", "-3"])
    assert process.returncode == 2 and not output.exists()
    assert process.stderr == ("petsc_rod.report: error: --min-bend-radius -3: the allowable "
                              "bend radius must be a positive number of metres\n")


@pytest.mark.serial
def test_a_report_in_the_sweep_s_folder_is_written_again(offset_sweep, tmp_path):
    """The report page written into the sweep's own folder can be written there again
    (the second run refused it as a file of the sweep, an input), and the sweep run again
    into that folder takes the page for its own (it refused the folder)."""
    import shutil

    folder = tmp_path / "sweep"
    shutil.copytree(offset_sweep[0], folder)
    output = folder / "report.html"
    for _ in range(2):
        process = run_module("petsc_rod.report", [str(folder), "-o", str(output)])
        assert process.returncode == 0, describe(process)
    assert output.stat().st_size > 0
    process = run_module("petsc_rod.report", [str(folder), "-o", str(folder / "far50.h5")])
    assert process.returncode == 2 and "far50.h5" in process.stderr, describe(process)
    # the sweep run again into its folder removes the earlier report's page with its files
    process = run_module("petsc_rod.sweep", RISER + ["-sweep_offsets", "0",
                                                     "-sweep_output", str(folder)])
    assert process.returncode == 0, describe(process)
    assert not output.exists() and (folder / "offset0.h5").exists()
