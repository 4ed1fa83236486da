"""Outputs that replace no input and are never half-written (io/same_file.py), for the
report and the plots (no PETSc): an output naming an input, through another spelling
or a link, is refused in one line with exit 2 and the input left as it was; a write
that fails leaves the old file and no partial one."""

import json
import os

import h5py
import numpy as np
import pytest

from petsc_rod import plots
from petsc_rod.io.same_file import replaced_input, same_file, write_whole
from petsc_rod.report.__main__ import main as report


def result(path):
    """A small HDF5 file standing for a result."""
    with h5py.File(path, "w") as f:
        f["S"] = np.linspace(0.0, 1.0, 3)
    return path


def one_error_line(captured, program):
    lines = [line for line in captured.err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith(f"petsc_rod.{program}: error: "), \
        captured.err
    return lines[0]


def test_same_file_sees_links_and_spellings(tmp_path):
    a = tmp_path / "a.txt"
    a.write_text("x")
    os.symlink(a, tmp_path / "link.txt")
    os.link(a, tmp_path / "hard.txt")
    assert same_file(a, tmp_path / "link.txt") and same_file(a, tmp_path / "hard.txt")
    assert same_file(a, tmp_path / "sub" / ".." / "a.txt")
    assert same_file(tmp_path / "new.txt", tmp_path / "." / "new.txt")       # not there yet
    assert not same_file(a, tmp_path / "new.txt")
    assert replaced_input([("-o", str(tmp_path / "x.txt"))], [("input", str(a))]) is None


def test_the_report_does_not_write_over_its_result(tmp_path, capsys):
    path = result(tmp_path / "run.h5")
    before = path.read_bytes()
    assert report([str(path), "-o", str(tmp_path / "." / "run.h5")]) == 2
    line = one_error_line(capsys.readouterr(), "report")
    assert "-o" in line and "an input that writing would replace" in line
    assert path.read_bytes() == before


def test_the_report_does_not_write_over_a_file_of_its_sweep(tmp_path, capsys):
    folder = tmp_path / "sweep"
    folder.mkdir()
    result(folder / "a.h5")
    (folder / "sweep.json").write_text(json.dumps({"cases": [], "varied": []}))
    (folder / "summary.md").write_text("the sweep's summary\n")
    for name in ("summary.md", "a.h5", "sweep.json"):
        before = (folder / name).read_bytes()
        assert report([str(folder), "-o", str(folder / name)]) == 2
        assert "file of the sweep" in one_error_line(capsys.readouterr(), "report")
        assert (folder / name).read_bytes() == before


def test_the_plots_do_not_write_over_a_result_by_a_link(tmp_path, capsys):
    path = result(tmp_path / "run.h5")
    before = path.read_bytes()
    os.symlink(path, tmp_path / "figure.png")
    assert plots.main(["plots", str(path), str(tmp_path / "figure.png")]) == 2
    assert "the figure" in one_error_line(capsys.readouterr(), "plots")
    assert path.read_bytes() == before
    # a wrong call is one line too, with the usage in it
    assert plots.main(["plots", str(path)]) == 2
    assert "usage: " in one_error_line(capsys.readouterr(), "plots")
    # a figure in a missing folder: said as such, before any drawing
    assert plots.main(["plots", str(path), str(tmp_path / "no" / "f.png")]) == 2
    assert "its folder does not exist" in one_error_line(capsys.readouterr(), "plots")
    assert report([str(path), "-o", str(tmp_path / "no" / "r.html")]) == 2
    assert "its folder does not exist" in one_error_line(capsys.readouterr(), "report")


def test_a_write_that_fails_leaves_the_old_file(tmp_path):
    path = tmp_path / "figure.png"
    path.write_bytes(b"the old figure")

    def fails(partial):
        with open(partial, "wb") as handle:
            handle.write(b"half a ne")
        raise OSError("disk full")

    with pytest.raises(OSError):
        write_whole(path, fails)
    assert path.read_bytes() == b"the old figure"
    assert sorted(os.listdir(tmp_path)) == ["figure.png"]
    write_whole(path, lambda partial: open(partial, "wb").write(b"new"))
    assert path.read_bytes() == b"new" and sorted(os.listdir(tmp_path)) == ["figure.png"]
    assert os.stat(path).st_mode & 0o777 == 0o666 & ~current_umask()


def current_umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask
