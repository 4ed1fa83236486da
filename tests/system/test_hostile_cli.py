"""Hostile input and faults, end to end (``python -m petsc_rod``, 1 and 2 ranks): each
class ends with one petsc_rod line, its documented exit code (docs/errors.md), no
traceback, no hang, and no result or ``.partial`` file left behind.

Every test spawns processes, so the module is marked ``serial``.
"""

import os
import resource
import shutil
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from helpers import (REPO_ROOT, child_env, mpiexec, partial_files, petsc_rod_command,
                     run_failing_on_rank_1, run_petsc_rod)

pytestmark = pytest.mark.serial

TIMEOUT = 120
SMALL = ["-rod_elements", "16", "-rod_end_force", "0,-3,0", "-rod_al_penalty", "100",
         "-rod_al_rtol", "1e-7", "-rod_al_ctol", "1e-4"]
# A run long enough to be stopped or made to fail while it writes: 50 steps of the plain
# iteration without Newton steps, several hundred iterations each.
LONG = ["-rod_elements", "32", "-rod_end_force", "0,-3,0", "-rod_al_penalty", "100",
        "-rod_al_rtol", "1e-9", "-rod_al_ctol", "1e-5", "-rod_steps", "50",
        "-rod_snes_type", "nrichardson", "-rod_al_newton", "0"]


def run(args, ranks=1):
    return run_petsc_rod(args, ranks, TIMEOUT)


def start(args, ranks=1):
    return subprocess.Popen(petsc_rod_command(args, ranks), cwd=REPO_ROOT, env=child_env(),
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def petsc_rod_lines(text):
    return [line for line in text.splitlines() if line.startswith("petsc_rod: error")]


def describe(code, text):
    return f"exit {code}\noutput:\n{text}"


def assert_one_line_and_nothing_left(code, text, expected_code, words, path=None):
    """The run ended with ``expected_code`` and one error line containing ``words``, no
    traceback or crash, and left neither ``path`` nor ``path.partial``."""
    assert code == expected_code, describe(code, text)
    errors = petsc_rod_lines(text)
    assert len(errors) == 1 and all(w in errors[0] for w in words), describe(code, text)
    for bad in ("Traceback", "Segmentation", "PETSC ERROR"):
        assert bad not in text, describe(code, text)
    if path is not None:
        assert not os.path.exists(path) and not partial_files(path)


def wait_for(path, process, timeout=60):
    """Wait until ``path`` exists, or for a path ending in .partial until the run's own
    partial file of it exists (the run got that far), failing if the run ends first."""
    deadline = time.monotonic() + timeout
    partial = path.endswith(".partial")

    def found():
        return partial_files(path.removesuffix(".partial")) if partial else os.path.exists(path)

    while not found():
        assert process.poll() is None, process.stdout.read()
        assert time.monotonic() < deadline, f"{path} never appeared"
        time.sleep(0.05)


def ranks_of(process, ranks):
    """The python processes of a run: the process itself, or mpiexec's children."""
    if ranks == 1:
        return [process.pid]
    children = []
    for entry in os.listdir("/proc"):
        try:
            with open(f"/proc/{entry}/stat") as stat:
                parent = int(stat.read().rsplit(")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            continue
        if parent == process.pid:
            children.append(int(entry))
    assert len(children) == ranks, children
    return children


# --- option values ---------------------------------------------------------------------
@pytest.mark.parametrize("args, named", [
    (["-rod_end", "clamp", "-rod_end_frame", "0,1,0,0,0,1,1,0,nan"], "-rod_end_frame"),
    (["-rod_al_rtol", "inf", "-rod_al_ctol", "inf"], "-rod_al_rtol"),
    (["-rod_elements", "inf"], "-rod_elements"),
    (["-rod_length", "1e200"], "-rod_length"),
], ids=["nan in the end frame", "infinite tolerances", "infinite elements", "huge length"])
def test_a_value_out_of_range_exits_2_with_one_line(tmp_path, args, named):
    path = tmp_path / "out.h5"
    done = run(["-rod_elements", "8"] + args + ["-rod_output", str(path)])
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2, [named],
                                     path)


@pytest.mark.parametrize("args, words", [
    (["-rod_start", "pin", "-rod_start_rotational_stiffness", "-2"],
     ["-rod_start_rotational_stiffness", "negative"]),
    (["-rod_end", "pin", "-rod_end_rotational_stiffness", "3", "-rod_end_joint_axis", "0,0,0"],
     ["-rod_end_joint_axis", "nonzero"]),
    (["-rod_end_rotational_stiffness", "3"],
     ["-rod_end_rotational_stiffness", "needs -rod_end pin", "free"]),
    (["-rod_start_rotational_stiffness", "3"],
     ["-rod_start_rotational_stiffness", "needs -rod_start pin", "clamp"]),
    (["-rod_start", "pin", "-rod_start_joint_axis", "0,1,0"],
     ["-rod_start_joint_axis", "needs -rod_start_rotational_stiffness"]),
], ids=["negative k", "zero axis", "k at a free end", "k at a clamp", "axis without k"])
def test_a_flex_joint_that_cannot_be_exits_2_with_one_line(tmp_path, args, words):
    path = tmp_path / "out.h5"
    done = run(["-rod_elements", "8"] + args + ["-rod_output", str(path)])
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2, words,
                                     path)


@pytest.mark.parametrize("args, words", [
    (["-rod_start_frame", "0,1,0,0,0,1,1,0,nan"], ["-rod_start_frame"]),
    (["-rod_start_frame", "1,0,0,0,1,0,0,0,2"], ["-rod_start_frame", "orthonormal"]),
    (["-rod_start_frame", "0,1,0,1,0,0,0,0,1"], ["-rod_start_frame", "right-handed"]),
    (["-rod_start", "pin", "-rod_end", "pin", "-rod_end_position", "0.5,0,0",
      "-rod_start_frame", "0,1,0,0,0,1,1,0,0"], ["-rod_start_frame", "needs -rod_start clamp"]),
], ids=["nan", "not orthonormal", "left-handed", "at a pin"])
def test_a_start_frame_that_cannot_be_exits_2_with_one_line(tmp_path, args, words):
    path = tmp_path / "out.h5"
    done = run(["-rod_elements", "8"] + args + ["-rod_output", str(path)])
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2, words,
                                     path)


LINE_TYPES = "name od mass ei gj ea\nbare 0.16 36.7 1.99e4 1.99e4 4.69e8\n"


@pytest.mark.parametrize("table, args, words", [
    (LINE_TYPES, ["-rod_sections", "bare:100,pipe:20"], ["unknown line type 'pipe'"]),
    (LINE_TYPES, ["-rod_sections", "bare:100", "-rod_length", "90"],
     ["-rod_sections add up to 100 m"]),
    (LINE_TYPES.replace("4.69e8", "0"), ["-rod_sections", "bare:100"], ["ea 0 must be"]),
    ("name od ei gj\nbare 0.16 1 1\n", ["-rod_sections", "bare:100"], ["no column mass"]),
    (LINE_TYPES, ["-rod_sections", "bare:100", "-rod_point_load", "120,0,0,-5"],
     ["beyond the line"]),
], ids=["unknown type", "lengths disagree", "zero ea", "missing column", "point beyond"])
def test_bad_line_types_exit_2_with_one_line(tmp_path, table, args, words):
    """Issue 22: each bad line-type input ends in one line, exit 2, no file."""
    types, path = tmp_path / "types.txt", tmp_path / "out.h5"
    types.write_text(table)
    done = run(["-rod_line_types", str(types), "-rod_start", "pin", "-rod_end", "pin",
                "-rod_end_position", "60,0,60"] + args + ["-rod_output", str(path)])
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2, words,
                                     path)


def test_a_mesh_too_large_for_the_machine_is_refused_before_allocating(tmp_path):
    clock = time.monotonic()
    done = run(["-rod_elements", "1000000000", "-rod_output", str(tmp_path / "big.h5")])
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2,
                                     ["-rod_elements", "memory", "TiB"], tmp_path / "big.h5")
    assert time.monotonic() - clock < 30


@pytest.mark.parametrize("switches, per_element", [("1", "56 KiB"), ("0", "20 KiB")])
def test_a_riser_s_memory_counts_the_heights_in_its_newton_systems(tmp_path, switches,
                                                                  per_element):
    """Newton steps with a seabed peaked at 45 (1 rank) and 53 KiB per element (2 ranks)
    on options/riser_catenary.opts at 72 000 elements, where the estimate said 20: the
    run would pass the check and be killed for memory mid-run. Without Newton steps and
    the stability test (which factors the same second variation) 20 KiB."""
    path = tmp_path / "big.h5"
    done = run(["-options_file", "options/riser_catenary.opts", "-rod_elements", "100000000",
                "-rod_al_newton", switches, "-rod_al_stability", switches,
                "-rod_output", str(path)])
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2,
                                     ["-rod_elements", "memory", f"({per_element} per"],
                                     path)


# --- options files and PETSc's options -------------------------------------------------
@pytest.mark.parametrize("ranks", [1, 2])
def test_an_options_file_petsc_cannot_parse_exits_2(tmp_path, ranks):
    scene = tmp_path / "bad.opts"
    scene.write_text("-rod_elements 8\nrod_length 2\n")
    done = run(["-options_file", str(scene)], ranks)
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2,
                                     [str(scene), "line 2", "rod_length"])


def test_an_options_file_without_options_exits_2(tmp_path):
    scene = tmp_path / "empty.opts"
    scene.write_text("# a comment, and nothing else\n\n")
    done = run(["-options_file", str(scene)])
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2,
                                     [str(scene), "no option"])


def options_file_loops(folder):
    """Scene files that include themselves: directly, and through a second file named
    by a relative path in other case (PETSc opens it from the working folder and
    compares option names without case)."""
    itself = folder / "itself.opts"
    itself.write_text(f"-rod_elements 8\n-options_file {itself}\n")
    first, second = folder / "first.opts", folder / "second.opts"
    first.write_text(f"-rod_elements 8\n-options_file {second}  # the rest\n")
    second.write_text(f"-rod_steps 1\n-OPTIONS_FILE {os.path.relpath(first, REPO_ROOT)}\n")
    return {"itself": itself, "through another": first}


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("loop", ["itself", "through another"])
def test_an_options_file_that_includes_itself_exits_2(tmp_path, loop, ranks):
    """PETSc follows -options_file lines without end and overflows its stack (a
    segmentation fault, no message): the loop is refused before PETSc starts."""
    scene = options_file_loops(tmp_path)[loop]
    path = tmp_path / "out.h5"
    done = run(["-options_file", str(scene), "-rod_output", str(path)], ranks)
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2,
                                     [str(scene), "include themselves", "line 2"], path)


def test_a_loop_of_options_files_through_petsc_options_exits_2(tmp_path):
    scene = options_file_loops(tmp_path)["itself"]
    env = {**child_env(), "PETSC_OPTIONS": f"-options_file {scene}"}
    done = subprocess.run(petsc_rod_command(["-rod_output", str(tmp_path / "out.h5")]),
                          cwd=REPO_ROOT, env=env, capture_output=True, text=True,
                          timeout=TIMEOUT, check=False)
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2,
                                     ["PETSC_OPTIONS", "include themselves"],
                                     tmp_path / "out.h5")


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_missing_nested_options_file_is_named(tmp_path, ranks):
    scene = tmp_path / "outer.opts"
    scene.write_text(f"-rod_elements 8\n-options_file {tmp_path / 'absent.opts'}\n")
    done = run(["-options_file", str(scene)], ranks)
    text = done.stdout + done.stderr
    assert_one_line_and_nothing_left(done.returncode, text, 2,
                                     ["absent.opts", f"{scene} line 2", "no such file"])
    assert "Petsc Release" not in text and "Option left" not in text, text


@pytest.mark.parametrize("args", [["-rod_elements", "8", "-options_file"],
                                  ["-options_file", "-rod_elements", "8"]],
                         ids=["at the end", "before an option"])
def test_options_file_without_a_path_exits_2(tmp_path, args):
    done = run(args)
    text = done.stdout + done.stderr
    assert_one_line_and_nothing_left(done.returncode, text, 2, ["-options_file", "path"])
    assert "Option left" not in text, text


def test_a_nested_options_file_line_without_a_path_exits_2(tmp_path):
    scene = tmp_path / "nopath.opts"
    scene.write_text("-rod_elements 8\n-options_file   # which one?\n")
    done = run(["-options_file", str(scene)])
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2,
                                     [f"{scene} line 2", "-options_file", "path"])


def test_an_options_file_with_a_byte_order_mark_is_refused_saying_so(tmp_path):
    """A UTF-8 byte-order mark is invisible in an editor; PETSc reads it as part of the
    first option's name (docs/errors.md says why it is refused, not stripped)."""
    scene = tmp_path / "bom.opts"
    scene.write_bytes(b"\xef\xbb\xbf-rod_elements 8\n")
    path = tmp_path / "out.h5"
    done = run(["-options_file", str(scene), "-rod_output", str(path)])
    text = done.stdout + done.stderr
    assert_one_line_and_nothing_left(done.returncode, text, 2,
                                     [str(scene), "UTF-8 byte-order mark"], path)
    assert "\ufeff" not in text, text


def test_an_options_file_that_is_a_pipe_is_refused_saying_so(tmp_path):
    """A FIFO stands for ``-options_file <(cmd)`` (/dev/fd/N, a pipe): it can be read
    only once, and petsc_rod reads the file before PETSc does."""
    fifo = tmp_path / "scene.fifo"
    os.mkfifo(fifo)
    done = run(["-options_file", str(fifo)])
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2,
                                     [str(fifo), "not a regular file"])


def test_an_unknown_solver_type_exits_2(tmp_path):
    path = tmp_path / "out.h5"
    done = run(SMALL + ["-rod_slope_ksp_type", "nonsense", "-rod_output", str(path)])
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2,
                                     ["KSP type nonsense"], path)


CANTILEVER = ["-options_file", "options/cantilever.opts", "-rod_elements", "8"]


@pytest.mark.parametrize("name, value, ranks, expected", [
    ("rod_newton_substructuring", "maybe", 2, "true or false"),
    ("rod_inertia_substructuring", "maybe", 1, "true or false"),
    ("rod_newton_lu", "superlu", 1, "petsc or mumps"),
    ("rod_newton_lu", "superlu", 2, "petsc or mumps")])
def test_a_factorisation_switch_not_understood_is_refused_before_any_work(tmp_path, name,
                                                                         value, ranks,
                                                                         expected):
    """PETSc read the substructuring switches only at the first Newton system's
    factorisation: an error of its own (exit 4) after the iterations before it. The
    LU's package (-rod_newton_lu, global_step/ksp.LU_PACKAGES) is petsc or mumps, the
    two direct_factor knows."""
    path = tmp_path / "out.h5"
    done = run(CANTILEVER + [f"-{name}", value, "-rod_output", str(path)], ranks)
    text = done.stdout + done.stderr
    assert_one_line_and_nothing_left(done.returncode, text, 2,
                                     [f"-{name} {value}", expected], path)
    assert "elements on" not in text, text          # refused before the run started


JACOBIAN_SNES = ["newtonls", "newtontr", "ngs", "ksponly", "fas", "nasm", "composite",
                 "shell", "vinewtonrsls"]


@pytest.mark.parametrize("kind, ranks", [(kind, 1) for kind in JACOBIAN_SNES]
                         + [("newtonls", 2), ("ngs", 2)])
def test_a_snes_type_that_cannot_drive_the_map_is_refused_before_any_work(tmp_path, kind,
                                                                         ranks):
    """These SNES types need a Jacobian, or set-up the map has not (a decomposition, a
    shell solve): they failed with a traceback at the first solve."""
    path = tmp_path / "out.h5"
    done = run(CANTILEVER + ["-rod_snes_type", kind, "-rod_output", str(path)], ranks)
    text = done.stdout + done.stderr
    assert_one_line_and_nothing_left(done.returncode, text, 2,
                                     [f"-rod_snes_type {kind}", "anderson|nrichardson"], path)
    assert "elements on" not in text, text          # refused before the run started


@pytest.mark.parametrize("kind", ["qn", "ncg", "ngmres"])
def test_the_other_snes_types_that_need_only_the_residual_drive_the_map(tmp_path, kind):
    done = run(CANTILEVER + ["-rod_snes_type", kind, "-rod_output", str(tmp_path / "out.h5")])
    assert done.returncode == 0, describe(done.returncode, done.stdout + done.stderr)
    assert os.path.exists(tmp_path / "out.h5")


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("options", [
    ["-rod_snes_type", "qn", "-rod_snes_qn_scale_type", "jacobian"],
    ["-rod_snes_type", "ngmres", "-rod_snes_ngmres_select_type", "linesearch",
     "-rod_snes_linesearch_type", "nleqerr"]], ids=["qn Jacobian scaling", "nleqerr"])
def test_a_petsc_error_inside_a_solve_exits_4_with_one_line(tmp_path, options, ranks):
    """SNES options that need what the map has not (a Jacobian, a preconditioner) fail
    inside PETSc during the first solve, on one rank (the other waits in a collective
    call: the run is aborted with the same code) or on all."""
    path = tmp_path / "out.h5"
    done = run(CANTILEVER + options + ["-rod_output", str(path)], ranks)
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 4,
                                     ["PETSc failed during the solve", "-rod_snes_*"], path)


# with rank 1 failing alone (helpers.ONE_RANK_FAILS), the command line's run
CLI_RUN = """
sys.exit(main.run())
"""


def test_an_exception_on_one_rank_alone_ends_the_run_without_a_file(tmp_path):
    """An exception other than a RodError or PETSc error (a numpy error, say) raised on
    one rank only, while the other writes: the run ends (no hang) with the failing rank's
    one line and exit 4, and neither the result nor its partial file is left."""
    path = tmp_path / "out.h5"
    done = run_failing_on_rank_1(tmp_path / "one_rank_fails.py", CLI_RUN,
                                 CANTILEVER + ["-rod_output", str(path),
                                               "-rod_ranks_split", "split"])
    assert_one_line_and_nothing_left(done.returncode, done.stdout, 4,
                                     ["rank 1 failed alone", "FloatingPointError",
                                      "injected on rank 1"], path)
    assert "Traceback" not in done.stderr, describe(done.returncode, done.stderr)


def test_ranks_given_different_options_exit_2_without_hanging(tmp_path):
    launcher = mpiexec(2)[0]
    path = tmp_path / "out.h5"
    python = [sys.executable, "-m", "petsc_rod", "-rod_output", str(path)]
    done = subprocess.run([launcher, "-n", "1"] + python + ["-rod_elements", "8", ":",
                                                            "-n", "1"] + python
                          + ["-rod_elements", "16"], cwd=REPO_ROOT, env=child_env(),
                          capture_output=True, text=True, timeout=TIMEOUT, check=False)
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2,
                                     ["rank 1", "-rod_elements"], path)


# --- the output path and failed writes -------------------------------------------------
@pytest.mark.parametrize("ranks", [1, 2])
def test_an_output_path_that_is_a_folder_is_refused_before_the_solve(tmp_path, ranks):
    folder = tmp_path / "folder.h5"
    folder.mkdir()
    done = run(SMALL + ["-rod_output", str(folder)], ranks)
    text = done.stdout + done.stderr
    assert_one_line_and_nothing_left(done.returncode, text, 2, ["-rod_output", "folder"])
    assert "step 1/" not in text and folder.is_dir()
    assert not partial_files(folder)


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_write_that_fails_during_the_run_exits_5_and_removes_the_partial_file(tmp_path,
                                                                                 ranks):
    """The file size limit (RLIMIT_FSIZE, set once the run has opened its file) makes
    HDF5's writes fail as a full disk does, past the free-space check."""
    path = tmp_path / "limited.h5"
    process = start(LONG + ["-rod_output", str(path)], ranks)
    try:
        wait_for(f"{path}.partial", process)
        for pid in ranks_of(process, ranks):
            resource.prlimit(pid, resource.RLIMIT_FSIZE, (20000, 20000))
        output, _ = process.communicate(timeout=TIMEOUT)
    finally:
        process.kill()
    assert_one_line_and_nothing_left(process.returncode, output, 5, ["failed"], path)


# --- signals ---------------------------------------------------------------------------
@pytest.mark.parametrize("ranks, signal_number", [
    (1, signal.SIGTERM), (1, signal.SIGHUP), (1, signal.SIGINT),
    (2, signal.SIGINT), (2, signal.SIGTERM),
    (1, signal.SIGQUIT), (1, signal.SIGUSR1), (1, signal.SIGUSR2)],
    ids=["SIGTERM", "SIGHUP", "SIGINT", "SIGINT to mpiexec", "SIGTERM to mpiexec",
         "SIGQUIT", "SIGUSR1", "SIGUSR2"])
def test_a_signal_ends_the_run_cleanly(tmp_path, ranks, signal_number):
    returncode, output, path = signalled_run(tmp_path, ranks, signal_number)
    # mpiexec forwards the signal to every rank as SIGTERM and exits 1 itself
    expected = 128 + signal_number if ranks == 1 else 1
    name = signal.Signals(signal_number).name if ranks == 1 else "SIGTERM"
    assert_one_line_and_nothing_left(returncode, output, expected,
                                     [f"interrupted by {name}", "load factor"], path)


def signalled_run(tmp_path, ranks, signal_number):
    """(exit code, output, result path) of the LONG run sent ``signal_number`` half a
    second after its partial file appeared."""
    path = tmp_path / "stopped.h5"
    process = start(LONG + ["-rod_output", str(path)], ranks)
    try:
        wait_for(f"{path}.partial", process)
        time.sleep(0.5)
        process.send_signal(signal_number)
        output, _ = process.communicate(timeout=TIMEOUT)
    finally:
        process.kill()
    return process.returncode, output, path


@pytest.mark.parametrize("signal_number", [signal.SIGUSR1, signal.SIGUSR2])
def test_a_user_signal_to_mpiexec_ends_the_run_cleanly(tmp_path, signal_number):
    """mpiexec (Open MPI) forwards SIGUSR1 and SIGUSR2 to every rank as they are."""
    returncode, output, path = signalled_run(tmp_path, 2, signal_number)
    assert_one_line_and_nothing_left(returncode, output, 128 + signal_number,
                                     [f"interrupted by {signal.Signals(signal_number).name}",
                                      "load factor"], path)


def test_a_second_signal_while_the_run_stops_changes_nothing(tmp_path):
    """Ctrl-C twice: the second SIGINT, while the run stops after the first, neither
    cuts the stop short nor changes its line."""
    path = tmp_path / "stopped.h5"
    process = start(LONG + ["-rod_output", str(path)])
    try:
        wait_for(f"{path}.partial", process)
        time.sleep(0.5)
        process.send_signal(signal.SIGINT)
        time.sleep(0.02)
        process.send_signal(signal.SIGINT)
        output, _ = process.communicate(timeout=TIMEOUT)
    finally:
        process.kill()
    assert_one_line_and_nothing_left(process.returncode, output, 130,
                                     ["interrupted by SIGINT", "load factor"], path)
    assert "KeyboardInterrupt" not in output, output


def test_output_piped_into_a_reader_that_ends_stops_the_run_cleanly(tmp_path):
    """``python -m petsc_rod ... | head -1``: the next line written gets SIGPIPE, which
    is recorded like the other stop signals (not PETSc's report, exit 59): exit 141,
    the line on stderr (stdout is gone), no file left."""
    path = tmp_path / "piped.h5"
    process = subprocess.Popen(petsc_rod_command(LONG + ["-rod_output", str(path)]),
                               cwd=REPO_ROOT, env=child_env(), stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    try:
        first = process.stdout.readline()
        process.stdout.close()              # the reader ends, as head does
        errors = process.stderr.read()
        process.wait(timeout=TIMEOUT)
    finally:
        process.kill()
    assert first.startswith("petsc_rod: "), first
    assert_one_line_and_nothing_left(process.returncode, errors, 141,
                                     ["interrupted by SIGPIPE", "load factor"], path)


# --- restarts --------------------------------------------------------------------------
@pytest.fixture(scope="module")
def half_way(tmp_path_factory):
    """A result file that stopped at load factor 0.5 without converging: a converged
    two-step run whose file is made to say so."""
    folder = tmp_path_factory.mktemp("restart")
    path = folder / "half.h5"
    done = run(SMALL + ["-rod_steps", "2", "-rod_output", str(path)])
    assert done.returncode == 0, describe(done.returncode, done.stdout + done.stderr)
    with h5py.File(path, "a") as f:
        f.attrs["load_factor"] = 0.5
        f.attrs["converged"] = 0
    return path


def step_factors(path):
    with h5py.File(path, "r") as f:
        return [float(f[f"steps/{k}"].attrs["load_factor"]) for k in
                sorted(f["steps"], key=int)]


def test_a_restart_goes_on_from_the_file_s_load_factor_and_warns_of_converged_0(half_way,
                                                                               tmp_path):
    path = tmp_path / "continued.h5"
    done = run(SMALL + ["-rod_steps", "2", "-rod_initial", str(half_way),
                        "-rod_output", str(path)])
    text = done.stdout + done.stderr
    assert done.returncode == 0, describe(done.returncode, text)
    assert "warning: -rod_initial" in text and "converged = 0" in text, text
    assert step_factors(path) == [0.75, 1.0]
    with h5py.File(path, "r") as f:
        assert float(f["parameters"].attrs["initial_load_factor"]) == 0.5


def test_a_restart_told_otherwise_walks_the_load_path_again(half_way, tmp_path):
    path = tmp_path / "again.h5"
    done = run(SMALL + ["-rod_steps", "2", "-rod_initial", str(half_way),
                        "-rod_initial_load_factor", "0", "-rod_output", str(path)])
    assert done.returncode == 0, describe(done.returncode, done.stdout + done.stderr)
    assert step_factors(path) == [0.5, 1.0]


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_restart_file_with_nan_exits_2(half_way, tmp_path, ranks):
    bad = tmp_path / "nan.h5"
    shutil.copy(half_way, bad)
    with h5py.File(bad, "a") as f:
        lam = f["state/lambda"][:]
        lam[-1] = np.nan                   # the last rank's rows
        del f["state/lambda"]
        f["state"].create_dataset("lambda", data=lam)
    path = tmp_path / "out.h5"
    done = run(SMALL + ["-rod_initial", str(bad), "-rod_output", str(path)], ranks)
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2,
                                     ["-rod_initial", "state/lambda", "NaN"], path)


def test_two_runs_with_the_same_output_both_finish_and_leave_a_whole_file(tmp_path):
    """Issue 25: two runs with the same -rod_output shared FILE.partial; the second's
    start-up check removed the first one's live file (one ended 0 with its result lost,
    the other with exit 5). Each now writes a partial file of its own."""
    path = tmp_path / "shared.h5"
    args = SMALL + ["-rod_steps", "4", "-rod_output", str(path)]
    runs = [subprocess.Popen(petsc_rod_command(args), cwd=REPO_ROOT, env=child_env(),
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            for _ in range(2)]
    outputs = [process.communicate(timeout=TIMEOUT)[0] for process in runs]
    for process, output in zip(runs, outputs):
        assert process.returncode == 0, output
    with h5py.File(path, "r") as result:
        assert result.attrs["converged"] == 1 and "r" in result
    assert not partial_files(path)


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_run_stopped_by_a_signal_keeps_its_converged_steps_as_a_restart_file(tmp_path,
                                                                              ranks):
    """Issue 25: a run stopped by a signal after some converged steps lost them all. They
    are kept in FILE's .interrupted file (never FILE itself), converged = 0, stop_reason
    interrupted, and a restart goes on from its load factor."""
    path = tmp_path / "long.h5"
    kept = tmp_path / "long.interrupted.h5"
    process = start(LONG + ["-rod_output", str(path)], ranks)
    try:
        seen = []
        for line in process.stdout:           # the second step converged: stop
            seen.append(line)
            if line.startswith("step 2/50:"):
                break
        assert seen and seen[-1].startswith("step 2/50:"), "".join(seen)
        process.send_signal(signal.SIGTERM)
        output, _ = process.communicate(timeout=TIMEOUT)
    finally:
        process.kill()
    output = "".join(seen) + output
    expected = 128 + signal.SIGTERM if ranks == 1 else 1        # mpiexec exits 1 itself
    assert process.returncode == expected, output
    assert not os.path.exists(path) and not partial_files(path), output
    assert f"the converged steps are kept in {kept}" in output, output
    with h5py.File(kept, "r") as f:
        assert f.attrs["converged"] == 0 and f.attrs["stop_reason"] == "interrupted"
        factor = float(f.attrs["load_factor"])
        assert factor >= 2 / 50 - 1e-12 and len(f["steps"]) >= 2
    again = run(LONG[:-6] + ["-rod_steps", "2", "-rod_initial", str(kept)])
    assert again.returncode == 0, again.stdout + again.stderr
    assert f"restart from {kept}, load factor {factor:.6g}" in again.stdout


CATENARY_RISER = ["-options_file", "options/riser_catenary.opts", "-rod_elements", "200"]


@pytest.mark.parametrize("args, iterations", [
    (CATENARY_RISER + ["-rod_seabed", "1e-12"], 18),
    (CATENARY_RISER + ["-rod_seabed", "0.30000000000000004", "-rod_start_position", "0,0,0.3"],
     18),
    (["-options_file", "options/steel_catenary_riser_slope.opts", "-rod_seabed", "1e-12",
      "-rod_sections", "scr10:2400:400"], 40)])
def test_an_anchor_on_the_seabed_to_round_off_is_on_it(tmp_path, args, iterations):
    """An anchor 1e-12 m below the seabed, flat or sloping (or 0.1 + 0.2 against 0.3),
    was accepted, then diverged at iteration 1 of every halving (exit 4): it is on the
    seabed, and the run converges as with the anchor exactly on it."""
    process = run(args)
    assert process.returncode == 0, process.stdout + process.stderr
    assert f"converged, {iterations} iterations" in process.stdout


def test_a_mesh_of_sections_too_large_names_the_sections_not_rod_elements(tmp_path):
    """The sections' counts set the mesh; -rod_elements beside them is refused, so the
    message must not ask for it."""
    process = run(["-options_file", "options/steel_catenary_riser.opts", "-rod_sections",
                   "scr10:2400:1000000000"])
    text = process.stdout + process.stderr
    assert_one_line_and_nothing_left(process.returncode, text, 2,
                                     ["-rod_sections (1000000000 elements in all)", "memory"])
    assert "-rod_elements" not in text


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("option", ["-rod_line_types", "-rod_current_profile",
                                    "-rod_seabed_profile", "-rod_point_loads"])
def test_a_table_that_is_a_fifo_exits_2_at_once(tmp_path, option, ranks):
    """A FIFO blocked the run for ever, deaf to SIGTERM: now one line, exit 2."""
    fifo = str(tmp_path / "table")
    os.mkfifo(fifo)
    needs = {"-rod_line_types": ["-rod_sections", "pipe:10"],
             "-rod_current_profile": ["-rod_drag", "1025,1,0.1"],
             "-rod_seabed_profile": ["-rod_seabed_stiffness", "1e3"],
             "-rod_point_loads": []}[option]
    process = subprocess.run(petsc_rod_command(SMALL + [option, fifo] + needs, ranks),
                             cwd=REPO_ROOT, env=child_env(), capture_output=True, text=True,
                             timeout=30, check=False)
    assert_one_line_and_nothing_left(process.returncode, process.stdout + process.stderr, 2,
                                     [option, "not a regular file"])
