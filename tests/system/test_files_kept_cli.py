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


def scene_files(folder):
    """({name: path} of the inputs the cases name, written in ``folder``; {name: path}
    of the outputs they give)."""
    files = {"opts": folder / "scene.opts", "outer": folder / "outer.opts",
             "types": folder / "types.txt", "loads": folder / "loads.txt",
             "run": folder / "run.h5", "link": folder / "link.h5",
             "regions": folder / "t_regions.csv"}
    files["opts"].write_text("-rod_length 3000\n")
    files["outer"].write_text(f"-options_file {files['opts']}\n-rod_elements 20\n")
    files["types"].write_text(LINE_TYPES)
    files["loads"].write_text("s fz\n1000 -5e5\n")
    files["regions"].write_text("s fz\n2000 -5e5\n")     # named like a table's regions
    files["run"].write_text("refused before it is read\n")
    os.symlink(files["run"], files["link"])
    outputs = {**files, "types spelt": folder / "." / "types.txt", "table": folder / "t.csv"}
    return files, outputs


# (the scene, the input's option and file, the output's option and file)
CASES = {
    "output is the options file": (CATENARY, "-options_file", "opts", "-rod_output", "opts"),
    "table is a nested options file": (CATENARY, "-options_file", "outer", "-rod_table",
                                       "opts"),
    "output is the line types": (TYPED, "-rod_line_types", "types", "-rod_output",
                                 "types spelt"),
    "table is the attachments": (CATENARY, "-rod_point_loads", "loads", "-rod_table", "loads"),
    "output is the restart file by a link": (CATENARY, "-rod_initial", "link", "-rod_output",
                                             "run"),
    "the table's regions are an input": (CATENARY, "-rod_point_loads", "regions",
                                         "-rod_table", "table"),
}


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("case", list(CASES))
def test_an_output_naming_an_input_is_refused(tmp_path, case, ranks):
    scene, source, read, output, written = CASES[case]
    files, outputs = scene_files(tmp_path)
    before = {name: path.read_bytes() for name, path in files.items()}
    process = run_petsc_rod(scene + [source, str(files[read]), output, str(outputs[written])],
                            ranks=ranks, timeout=TIMEOUT)
    assert process.returncode == 2, describe(process)
    lines = [line for line in process.stdout.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("petsc_rod: error: "), describe(process)
    assert output in lines[0] and source in lines[0] and "name another file" in lines[0]
    assert "Traceback" not in process.stderr
    assert {name: path.read_bytes() for name, path in files.items()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in files.values())
