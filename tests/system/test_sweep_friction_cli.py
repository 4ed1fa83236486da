"""A sweep's warm start of a case with seabed friction (sweep/runner.py, docs/sweeps.md,
"Warm starts and seabed friction"): the case's answer is that of the case run alone,
whichever neighbour's file started it, on 1 and 2 ranks. The scene: the steel catenary
riser under the current across its plane on a seabed with mu = 0.5
(options/steel_catenary_riser_friction.opts) on 100 elements, its hang-off moved 10 m
toward the anchor and started from the converged unmoved case (-sweep_start nearest).
With the neighbour's positions as its anchors (the restart's, before) the case held
683.92 kN at its anchor, 23 of 25 grounded nodes sticking, where alone it holds
586.62 kN, 2 sticking (positions 0.46 m apart); now the same to 7e-11 m (1.6e-9 m
on 2 ranks, the line split). A user's restart from the same file keeps the restart's
anchors (-rod_initial_friction_anchors file, the default), or takes the run's own with
``laid``. Spawns processes: ``serial``."""

import csv

import h5py
import numpy as np
import pytest

from helpers import describe, run_petsc_rod
from test_hostile_cli import assert_one_line_and_nothing_left
from test_sweep_cli import run_module

pytestmark = pytest.mark.serial

TIMEOUT = 120
RISER = ["-options_file", "options/steel_catenary_riser_friction.opts", "-rod_sections",
         "scr10:2400:100", "-rod_max_halvings", "0"]
MOVED = "1590,0,1500"          # the hang-off 10 m toward the anchor (the base: 1600,0,1500)
CASES = f"name rod_end_position\nbase 1600,0,1500\nnear10 {MOVED}\n"
ALONE_ANCHOR = 586.6244e3       # N, near10's anchor tension run alone (measured)
FILE_ANCHOR = 683.92e3          # N, restarted from base.h5 on its positions (measured)


def split(ranks):
    """On 2 ranks the line split over them (the 100 elements would run whole on one)."""
    return ["-rod_ranks_split", "split"] if ranks == 2 else []


def numbers(path):
    """(anchor tension N, (sticking, sliding) nodes, r (n, 3) m) of a result file."""
    with h5py.File(path, "r") as f:
        return (float(f.attrs["anchor_tension"]),
                (int(f.attrs["friction_stick_nodes"]), int(f.attrs["friction_slide_nodes"])),
                f["r"][()])


def run_alone(tmp_path, ranks, args=()):
    """near10 run alone (or restarted with ``args``): its result file's numbers."""
    path = tmp_path / "alone.h5"
    done = run_petsc_rod(RISER + split(ranks) + ["-rod_end_position", MOVED, *args,
                                                  "-rod_output", str(path)], ranks, TIMEOUT)
    assert done.returncode == 0, describe(done)
    return numbers(path), done.stdout


def run_sweep(tmp_path, ranks):
    """The sweep of base and near10, near10 warm from base: (its folder, the process)."""
    cases, folder = tmp_path / "cases.txt", tmp_path / "sweep"
    cases.write_text(CASES)
    done = run_module("petsc_rod.sweep", RISER + split(ranks) + [
        "-sweep_cases", str(cases), "-sweep_output", str(folder), "-sweep_start", "nearest"],
        ranks)
    assert done.returncode == 0, describe(done)
    return folder, done


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_warm_started_friction_case_is_the_case_alone(tmp_path, ranks):
    folder, done = run_sweep(tmp_path, ranks)
    with open(folder / "summary.csv", newline="") as f:
        rows = {row["case"]: row for row in csv.DictReader(f)}
    assert rows["near10"]["start"] == "from base", rows["near10"]
    warm_anchor, warm_nodes, warm_r = numbers(folder / "near10.h5")
    (anchor, nodes, r), _ = run_alone(tmp_path, ranks)
    assert anchor == pytest.approx(ALONE_ANCHOR, rel=1e-6)
    assert warm_anchor == pytest.approx(anchor, rel=1e-8)     # 5e-11 measured
    assert warm_nodes == nodes == (2, 23)
    assert np.abs(warm_r - r).max() < 1e-6                    # m; 1.6e-9 measured
    assert "anchors are laid on this run's catenary" in done.stdout


def test_the_sweeps_own_choice_of_anchors_is_kept_and_a_cold_case_runs(tmp_path):
    """-rod_initial_friction_anchors file among the sweep's options: the first case,
    from its own start (no restart), runs (it was refused, exit 2, as every cold case
    was), and the warm case keeps the file's anchors as asked (the restart's answer,
    not the case alone's; the walk's ``laid`` overrode it)."""
    cases, folder = tmp_path / "cases.txt", tmp_path / "sweep"
    cases.write_text(CASES)
    done = run_module("petsc_rod.sweep", RISER + [
        "-rod_initial_friction_anchors", "file", "-sweep_cases", str(cases),
        "-sweep_output", str(folder), "-sweep_start", "nearest"], 1)
    assert done.returncode == 0, describe(done)
    with open(folder / "summary.csv", newline="") as f:
        rows = {row["case"]: row for row in csv.DictReader(f)}
    assert rows["base"]["start"] == "own start" and rows["base"]["exit"] == "0", rows
    assert rows["near10"]["start"] == "from base", rows["near10"]
    anchor, nodes, _ = numbers(folder / "near10.h5")
    assert anchor == pytest.approx(FILE_ANCHOR, rel=1e-4) and nodes == (23, 2)


def test_a_restart_keeps_the_files_anchors_unless_laid(tmp_path):
    """A user's restart of near10 from the base case's file: its positions are the
    anchors by default (the path goes on from that line; the answer the sweep's warm
    start gave before), the run's own with -rod_initial_friction_anchors laid."""
    base = tmp_path / "base.h5"
    done = run_petsc_rod(RISER + ["-rod_output", str(base)], 1, TIMEOUT)
    assert done.returncode == 0, describe(done)
    (anchor, nodes, r), said = run_alone(tmp_path, 1)
    assert "anchors" not in said                # no restart: nothing to say
    (restarted, restarted_nodes, _), said = run_alone(tmp_path, 1,
                                                      ["-rod_initial", str(base)])
    assert "anchors are the file's positions" in said
    assert restarted == pytest.approx(FILE_ANCHOR, rel=1e-4)
    assert restarted_nodes == (23, 2)
    (laid, laid_nodes, laid_r), said = run_alone(
        tmp_path, 1, ["-rod_initial", str(base), "-rod_initial_friction_anchors", "laid"])
    assert "anchors are laid on this run's catenary" in said
    assert laid == pytest.approx(anchor, rel=1e-8) and laid_nodes == nodes
    assert np.abs(laid_r - r).max() < 1e-6


BAD = {
    "without a restart": (["-rod_initial_friction_anchors", "laid"],
                          ["-rod_initial_friction_anchors needs -rod_initial"]),
    "an unknown value": (["-rod_initial_friction_anchors", "start"],
                         ["-rod_initial_friction_anchors", "file|laid"]),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_friction_anchors_exit_2_with_one_line(tmp_path, case):
    args, words = BAD[case]
    path = tmp_path / "out.h5"
    done = run_petsc_rod(RISER + args + ["-rod_output", str(path)], 1, TIMEOUT)
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2, words,
                                     path)
