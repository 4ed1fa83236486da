"""Issue 47, files lost: an output that names one of the run's inputs (an options file,
nested or not, the line types, the attachments, the restart file; through another
spelling or a symbolic link) is refused before any work in one line, exit 2, and the
input is left as it was (spawns python -m petsc_rod: serial, and on 2 ranks)."""

import os

import pytest

from helpers import describe, run_petsc_rod

TIMEOUT = 120
CATENARY = ["-options_file", "options/catenary.opts", "-rod_elements", "20"]
LINE_TYPES = "name od mass ei gj ea\nbare 0.16 36.7 1.99e4 1.99e4 4.69e8\n"
TYPED = ["-rod_sections", "bare:100", "-rod_start", "pin", "-rod_end", "pin",
         "-rod_end_position", "60,0,60", "-rod_elements", "20"]


@pytest.fixture(scope="module")
def restart_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("kept") / "run.h5"
    process = run_petsc_rod(CATENARY + ["-rod_output", str(path)], timeout=TIMEOUT)
    assert process.returncode == 0, describe(process)
    return path


def scene_files(folder, restart):
    """{name: path} of the inputs the cases name, written in ``folder``."""
    files = {"opts": folder / "scene.opts", "outer": folder / "outer.opts",
             "types": folder / "types.txt", "loads": folder / "loads.txt",
             "link": folder / "link.h5", "regions": folder / "t_regions.csv"}
    files["opts"].write_text("-rod_length 3000\n")
    files["outer"].write_text(f"-options_file {files['opts']}\n-rod_elements 20\n")
    files["types"].write_text(LINE_TYPES)
    files["loads"].write_text("s fz\n1000 -5e5\n")
    files["regions"].write_text("s fz\n2000 -5e5\n")     # named like a table's regions
    os.symlink(restart, files["link"])
    return files


CASES = {
    "output is the options file": (
        lambda f: CATENARY + ["-options_file", str(f["opts"]), "-rod_output", str(f["opts"])],
        "opts", "-rod_output", "-options_file"),
    "table is a nested options file": (
        lambda f: CATENARY + ["-options_file", str(f["outer"]), "-rod_table", str(f["opts"])],
        "opts", "-rod_table", "-options_file"),
    "output is the line types": (
        lambda f: TYPED + ["-rod_line_types", str(f["types"]), "-rod_output",
                           str(f["types"].parent / "." / "types.txt")],
        "types", "-rod_output", "-rod_line_types"),
    "table is the attachments": (
        lambda f: CATENARY + ["-rod_point_loads", str(f["loads"]), "-rod_table", str(f["loads"])],
        "loads", "-rod_table", "-rod_point_loads"),
    "output is the restart file by a link": (
        lambda f: CATENARY + ["-rod_initial", str(f["link"]), "-rod_output",
                              os.readlink(f["link"])],
        "link", "-rod_output", "-rod_initial"),
    "the table's regions are an input": (
        lambda f: CATENARY + ["-rod_point_loads", str(f["regions"]), "-rod_table",
                              str(f["regions"].parent / "t.csv")],
        "regions", "regions' table of -rod_table", "-rod_point_loads"),
}


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("case", list(CASES))
def test_an_output_naming_an_input_is_refused(restart_file, tmp_path, case, ranks):
    if case == "the table's regions are an input" and ranks == 2:
        pytest.skip("one rank is enough: the same check")
    arguments, kept, output, source = CASES[case]
    files = scene_files(tmp_path, restart_file)
    before = {name: path.read_bytes() for name, path in files.items()}
    process = run_petsc_rod(arguments(files), ranks=ranks, timeout=TIMEOUT)
    assert process.returncode == 2, describe(process)
    lines = [line for line in process.stdout.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("petsc_rod: error: "), describe(process)
    assert output in lines[0] and source in lines[0] and "name another file" in lines[0]
    assert "Traceback" not in process.stderr
    assert {name: path.read_bytes() for name, path in files.items()} == before, kept
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in files.values())
