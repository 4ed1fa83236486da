"""The command line on two ranks with a short line run whole on rank 0
(-rod_ranks_split auto, cli/ranks.py): the lines of the one-rank run, said once, the
same result file and table, and a bad value refused in one line with exit 2."""

import re

import h5py
import numpy as np
import pytest

from helpers import describe, run_petsc_rod

pytestmark = pytest.mark.serial

# options/cantilever.opts on 16 elements: below the cost model's crossover
SHORT = ["-options_file", "options/cantilever.opts", "-rod_elements", "16"]
CLOCK = re.compile(r"in [0-9.e+-]+ s")


def test_a_short_line_on_two_ranks_says_and_writes_what_one_rank_does(tmp_path):
    runs = {}
    for ranks in (1, 2):
        output, table = tmp_path / f"r{ranks}.h5", tmp_path / f"r{ranks}.csv"
        done = run_petsc_rod(SHORT + ["-rod_output", str(output), "-rod_table", str(table)],
                             ranks=ranks)
        assert done.returncode == 0, describe(done)
        assert done.stderr.strip() == "", describe(done)
        lines = [CLOCK.sub("in T s", line).replace(f"r{ranks}.", "r.")
                 for line in done.stdout.splitlines()]
        runs[ranks] = lines, output, table
    (one, file_one, table_one), (two, file_two, table_two) = runs[1], runs[2]
    assert two == one
    assert table_two.read_text() == table_one.read_text()
    with h5py.File(file_one, "r") as f, h5py.File(file_two, "r") as g:
        for name in ("r", "d1", "d2", "d3", "state/tau", "state/lambda"):
            assert np.array_equal(f[name][:], g[name][:]), name
        assert int(g.attrs["iterations"]) == int(f.attrs["iterations"])


def test_a_bad_placement_exits_2_in_one_line():
    done = run_petsc_rod(SHORT + ["-rod_ranks_split", "halves"])
    assert done.returncode == 2, describe(done)
    assert done.stdout.splitlines() == [
        "petsc_rod: error: -rod_ranks_split halves: expected one of auto|whole|split"]


def test_the_scenes_benchmark_times_each_scene_on_one_and_two_ranks():
    """scripts/benchmark_scenes.py on two rods, one pair, with --fit: a row a scene with
    its elements, auto's placement, the times and the pairs' ratio; the constants
    fitted; no file written with --only."""
    import subprocess
    import sys

    from helpers import REPO_ROOT, child_env

    done = subprocess.run([sys.executable, "scripts/benchmark_scenes.py", "--only", "twist",
                           "cantilever", "--pairs", "1", "--fit"], cwd=REPO_ROOT,
                          env=child_env(), capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, describe(done)
    rows = [line.split(" | ") for line in done.stdout.splitlines()
            if line.startswith(("| twist", "| cantilever"))]
    assert [(row[0], row[1], row[2]) for row in rows] == [("| cantilever", "64", "whole"),
                                                        ("| twist", "32", "whole")]
    for row in rows:
        one, two, ratio = (float(cell) for cell in row[3:6])
        assert one > 0 and two > 0 and ratio == pytest.approx(two / one, rel=0.02)
        first, second = row[6].rstrip(" |").split(" / ")
        assert int(first) == int(second) > 0        # whole on 2 ranks: the 1-rank run
    assert "WHOLE = IterationCost(fixed=" in done.stdout and "N* = " in done.stdout
    assert "load average" in done.stdout


def test_a_sweep_of_a_short_line_on_two_ranks_runs_each_case_whole(tmp_path):
    """python -m petsc_rod.sweep under mpiexec -n 2: each case of a 16-element cantilever
    runs whole on rank 0 (its file says 1 rank), the summary is the 1-rank sweep's."""
    import subprocess
    import sys

    from helpers import REPO_ROOT, child_env, mpiexec

    cases = tmp_path / "cases.txt"
    cases.write_text("rod_end_force\n0,-3,0\n0,-4,0\n")
    summaries = {}
    for ranks in (1, 2):
        folder = tmp_path / f"sweep{ranks}"
        done = subprocess.run(mpiexec(ranks) + [sys.executable, "-m", "petsc_rod.sweep"]
                              + SHORT + ["-sweep_cases", str(cases), "-sweep_output",
                                         str(folder)], cwd=REPO_ROOT, env=child_env(),
                              capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, describe(done)
        summaries[ranks] = (folder / "summary.csv").read_text()
        for case in ("case1", "case2"):
            with h5py.File(folder / f"{case}.h5", "r") as f:
                assert int(f.attrs["ranks"]) == 1
    assert summaries[2] == summaries[1]
