"""scripts/compare_results.py, the check that a restructuring leaves every result file as
it was: a changed value, a dataset in one file only and a changed attribute are each
reported with exit 1; the run's date, wall times, commit and the file's own path are not
differences. scripts/compare_matrix.py, the same for two runs of the stability matrix."""

import importlib.util
import os

import h5py
import numpy as np
import pytest

from helpers import REPO_ROOT


def load(name):
    """The module of scripts/<name>.py."""
    path = os.path.join(REPO_ROOT, "scripts", f"{name}.py")
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def script():
    return load("compare_results")


def result(path, r, written="2026-01-01T00:00:00+00:00", wall_time=1.0, extra=None):
    """A small file shaped like a result: root attributes, a step group, a history."""
    with h5py.File(path, "w") as f:
        f["r"] = r
        f["steps/1/u"] = np.arange(6.0).reshape(2, 3)
        f["history/change"] = [1e-3, 1e-9]
        f["history/wall_time"] = [wall_time, 2 * wall_time]
        for group in (f, f["steps/1"]):
            group.attrs.update({"energy": 2.5, "written": written, "wall_time": wall_time,
                                "options": f"-rod_elements 4\n-rod_output {path}",
                                "stop_reason": "converged"})
        f.attrs.update({"commit": written, "version": written})
        f.create_group("parameters").attrs.update({"output": str(path), "elements": 4})
        if extra:
            f[extra] = [1.0]
    return str(path)


R = np.array([[0.0, 0.0, 0.0], [1.0, 0.5, -2.0]])


def test_runs_that_differ_only_in_date_time_commit_and_path_agree(script, tmp_path, capsys):
    a = result(tmp_path / "a.h5", R)
    b = result(tmp_path / "b.h5", R.copy(), written="2027-05-05T10:00:00+00:00", wall_time=7.0)
    assert script.compare_files(a, b) == []
    assert script.main([a, b]) == 0
    assert "identical" in capsys.readouterr().out


def test_a_changed_dataset_is_found_with_its_differences(script, tmp_path, capsys):
    changed = R.copy()
    changed[1, 2] += 4e-12                        # one value, one part in 5e11
    a, b = result(tmp_path / "a.h5", R), result(tmp_path / "b.h5", changed)
    lines = script.compare_files(a, b)
    assert len(lines) == 1 and lines[0].startswith("/r: ")
    abs_diff = float(lines[0].split("max abs diff ")[1].split(",")[0])
    rel_diff = float(lines[0].split("max rel diff ")[1].split(" ")[0])
    assert abs_diff == pytest.approx(4e-12, rel=1e-3)
    assert rel_diff == pytest.approx(2e-12, rel=1e-3)
    assert script.main([a, b]) == 1
    assert "/r: max abs diff" in capsys.readouterr().out
    assert script.main([a, b, "--rtol", "1e-11"]) == 0          # within the tolerance
    assert script.main([a, b, "--rtol", "1e-12"]) == 1


def test_an_added_or_missing_dataset_is_found(script, tmp_path):
    a = result(tmp_path / "a.h5", R)
    b = result(tmp_path / "b.h5", R, extra="steps/1/torque")
    assert script.compare_files(a, b) == [f"/steps/1/torque: dataset only in {b}"]
    assert script.compare_files(b, a) == [f"/steps/1/torque: dataset only in {b}"]
    assert script.main([a, b]) == 1


def test_a_changed_attribute_or_history_is_found(script, tmp_path):
    a = result(tmp_path / "a.h5", R)
    b = result(tmp_path / "b.h5", R)
    with h5py.File(b, "r+") as f:
        f["steps/1"].attrs["stop_reason"] = "diverged"
        f["history/change"][1] = 2e-9
        f["parameters"].attrs["elements"] = 5
    lines = script.compare_files(a, b)
    assert [line.split(":")[0] for line in lines] == [
        "/history/change", "/parameters@elements", "/steps/1@stop_reason"]


def test_matrix_runs_are_compared_case_by_case_without_their_wall_times(tmp_path, capsys):
    """scripts/compare_matrix.py: a case whose iterations changed, or that one run lacks,
    is a difference; another wall time is not."""
    matrix = load("compare_matrix")
    header = "group,case,ranks,elements,outcome,reason,iterations,wall_time\n"
    old, new, fewer = tmp_path / "old.csv", tmp_path / "new.csv", tmp_path / "fewer.csv"
    old.write_text(header + "g,a,1,32,converged,,37,1.1\ng,a,2,32,converged,,37,1.5\n")
    new.write_text(header + "g,a,1,32,converged,,37,9.9\ng,a,2,32,converged,,38,1.5\n")
    fewer.write_text(header + "g,a,1,32,converged,,37,1.1\n")
    assert matrix.compare(old, old) == [] and matrix.main([str(old), str(old)]) == 0
    assert matrix.compare(old, new) == ["a (2 rank(s)): iterations '37' -> '38'"]
    assert matrix.compare(old, fewer) == [f"a (2 rank(s)): only in {old}"]
    assert matrix.main([str(old), str(new)]) == 1
    assert "iterations '37' -> '38'" in capsys.readouterr().out
