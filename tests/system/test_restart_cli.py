"""Issue 25 from the command line (spawns python -m petsc_rod: serial): the lazy wave
(options/lazy_wave.opts on 400 elements, a few seconds) restarted with a current its
file did not have walks from the file's scene to the new one, and a restart whose step
moves no load ends at once instead of retrying it at increment 0."""

import h5py
import pytest

from helpers import describe, run_petsc_rod

TIMEOUT = 120
LAZY_WAVE = ["-options_file", "options/lazy_wave.opts", "-rod_elements", "400"]
# a modest current across the line's plane: a drag of about 0.9 N/m on its 300 N/m
CURRENT = ["-rod_current", "0,0.1,0", "-rod_drag", "1025,1.2,0.15"]


@pytest.fixture(scope="module")
def lazy_wave(tmp_path_factory):
    """The converged lazy wave without a current (its result file)."""
    path = tmp_path_factory.mktemp("restart") / "lazy_wave.h5"
    process = run_petsc_rod(LAZY_WAVE + ["-rod_output", str(path)], timeout=TIMEOUT)
    assert process.returncode == 0, describe(process)
    return path


@pytest.mark.serial
def test_a_current_added_on_restart_is_walked_in(lazy_wave, tmp_path):
    """The reproduction of issue 25 with a modest current: exit 0, no 'increment 0', the
    line that says the restart walks (naming the current) and -rod_steps steps."""
    path = tmp_path / "with_current.h5"
    process = run_petsc_rod(LAZY_WAVE + CURRENT + ["-rod_initial", str(lazy_wave),
                                                   "-rod_steps", "2", "-rod_output", str(path)],
                            timeout=TIMEOUT)
    assert process.returncode == 0, describe(process)
    assert "increment 0" not in process.stdout, describe(process)
    walks = [line for line in process.stdout.splitlines() if "walks from the file's scene" in line]
    assert len(walks) == 1 and "-rod_current" in walks[0], describe(process)
    # the scene file's catenary start gives way to the restart file, said in one line
    assert "-rod_initial_shape catenary is not used" in process.stdout, describe(process)
    with h5py.File(path, "r") as f:
        assert [f["steps"][k].attrs["load_factor"] for k in sorted(f["steps"], key=int)] \
            == [0.5, 1.0]


@pytest.mark.serial
def test_a_failed_step_that_moves_no_load_ends_the_run(lazy_wave):
    """The file's own scene at its own load factor 1 with a tolerance below round-off
    (the restart is the fixed point: change 4e-14 at the first iteration, then 1e-14 to
    7e-15), which 5 iterations cannot meet: exit 3 at once, saying why; no retry at
    increment 0."""
    process = run_petsc_rod(LAZY_WAVE + ["-rod_initial", str(lazy_wave), "-rod_al_max_it", "5",
                                         "-rod_al_rtol", "1e-16"], timeout=TIMEOUT)
    assert process.returncode == 3, describe(process)
    assert "increment 0" not in process.stdout and "retrying" not in process.stdout, \
        describe(process)
    assert "moves no load, so halving it cannot help" in process.stdout, describe(process)
