"""The options files as PETSc reads them (petsc_rod/cli/options_files.py), checked before PETSc
starts: the -options_file paths of a command line and of the files' own lines, loops
and missing nested files refused, an include of the same file twice (no loop) kept.
Pure Python: no PETSc, no MPI."""

import pytest

from petsc_rod.cli.options_files import (OptionsFileError, is_key, nested_files, options_file_error,
                                options_files)

NO_PETSCRC = {"PETSC_OPTIONS": "-skip_petscrc"}


def test_petsc_s_keys_and_the_command_line_s_paths():
    assert is_key("-rod_elements") and is_key("--rod_elements")
    assert not is_key("-3") and not is_key("-inf") and not is_key("path")
    argv = ["prog", "-rod_output", "-OPTIONS_FILE", "a.opts", "-rod_elements", "8",
            "-options_file", "b.opts"]
    assert options_files(argv) == ["a.opts", "b.opts"]
    with pytest.raises(OptionsFileError, match="needs the path"):
        options_files(["prog", "-options_file", "-rod_elements", "8"])


def test_nested_lines_as_petsc_reads_them():
    text = "# -options_file commented.opts\n-rod_elements 8 # -options_file no\n" \
           "\t-options_file  x.opts  # the rest\n"
    assert nested_files("f.opts", text) == [(3, "x.opts")]
    with pytest.raises(OptionsFileError, match="f.opts line 1"):
        nested_files("f.opts", "-options_file # none\n")


def test_a_loop_is_refused_and_the_same_file_twice_is_not(tmp_path):
    shared = tmp_path / "shared.opts"
    shared.write_text("-rod_steps 1\n")
    twice = tmp_path / "twice.opts"
    twice.write_text(f"-options_file {shared}\n-options_file {shared}\n")
    assert options_file_error(["prog", "-options_file", str(twice)], NO_PETSCRC) == ""
    first, second = tmp_path / "first.opts", tmp_path / "second.opts"
    first.write_text(f"-rod_elements 8\n-options_file {second}\n")
    second.write_text(f"-options_file {tmp_path}/./first.opts\n")
    error = options_file_error(["prog", "-options_file", str(first)], NO_PETSCRC)
    assert "include themselves" in error and f"{second} line 1" in error, error


def test_a_path_with_petsc_s_names_is_expanded_or_left_to_petsc(tmp_path, monkeypatch):
    monkeypatch.setenv("SCENES", str(tmp_path))
    (tmp_path / "inner.opts").write_text("-rod_steps 1\n")
    outer = tmp_path / "outer.opts"
    outer.write_text("-options_file ${SCENES}/inner.opts\n-options_file ${PETSC_UNKNOWN}/x\n")
    assert options_file_error(["prog", "-options_file", str(outer)], NO_PETSCRC) == ""
    outer.write_text("-options_file ${SCENES}/absent.opts\n")
    error = options_file_error(["prog", "-options_file", str(outer)], NO_PETSCRC)
    assert "absent.opts" in error and "no such file" in error, error


def test_an_options_file_above_the_input_size_cap_is_refused(tmp_path, monkeypatch):
    from petsc_rod import tables
    scene = tmp_path / "big.opts"
    scene.write_text("-rod_elements 8\n" * 4)
    monkeypatch.setattr(tables, "MAX_TABLE_BYTES", 32)
    assert "above the 3.05e-05 MiB an input file may hold" in options_file_error(
        ["petsc_rod", "-options_file", str(scene)])
    monkeypatch.setattr(tables, "MAX_TABLE_BYTES", 64)
    assert options_file_error(["petsc_rod", "-options_file", str(scene)]) == ""
