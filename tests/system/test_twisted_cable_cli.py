"""A twisted lazy-wave cable clamped at both ends, end to end on 1 and 2 ranks: its hang-off
rolled by three turns in a restart's walk from the clamped, untwisted state must converge in
Newton's count of iterations (docs/method.md §7, "The twist of round sections"), with the
answer the iteration reaches without the roll (docs/stability.md, "A twisted cable").
Spawns processes: marked ``serial``."""

import h5py
import numpy as np
import pytest

from helpers import describe, run_petsc_rod

pytestmark = pytest.mark.serial

TIMEOUT = 300
# options/cable_80m.opts on 2 m elements, clamped at the anchor (d3 = e_x on the seabed)
# and at the hang-off with d3 = e_z
CLAMPED = ["-options_file", "options/cable_80m.opts", "-rod_start", "clamp", "-rod_end",
           "clamp", "-rod_end_frame", "0,1,0,-1,0,0,0,0,1", "-rod_elements", "85"]
TURNS = 3
# Newton's count: about 19 iterations a step (12 steps: 228 measured; f2df9b3 spread the
# twist from the clamp by the iteration for 8707 iterations, up to 1500 in a step)
PER_STEP = 25
# the answer of f2df9b3 (the roll's parent) after its 8707 iterations, the same on 1 and
# 2 ranks: hang-off tension, N, and the moment on the line at the hang-off, N m (its z
# the torque of the three turns)
TOP_TENSION = 9336.436055
END_MOMENT = np.array([-142.96990291, 1822.98304363, -2176.94743912])


@pytest.fixture(scope="module")
def clamped(tmp_path_factory):
    """The clamped, untwisted cable solved from its catenary start: the restart file."""
    path = tmp_path_factory.mktemp("twisted_cable") / "clamped.h5"
    process = run_petsc_rod(CLAMPED + ["-rod_output", str(path)], 1, TIMEOUT)
    assert process.returncode == 0, describe(process)
    return path


@pytest.mark.parametrize("ranks, steps", [(1, 12), (2, 12), (1, 6), (2, 1)])
def test_a_clamped_cable_rolled_three_turns_converges_in_newtons_count(clamped, ranks,
                                                                        steps):
    """12 steps of a quarter turn; 6 of half a turn, where the clamp's frame alone cannot
    tell which way the step rolls (f2df9b3 lost the three turns at the cap); 1 step of
    three turns, which the clamp's frame does not see at all (f2df9b3 converged in 1
    iteration: the untwisted cable it started from): the load path's roll is walked
    (RodProblem._path_roll)."""
    path = clamped.parent / f"rolled_{ranks}_{steps}.h5"
    most = PER_STEP * steps
    process = run_petsc_rod(CLAMPED + [
        "-rod_initial", str(clamped), "-rod_end_twist", f"{2 * np.pi * TURNS!r}",
        "-rod_steps", str(steps), "-rod_al_max_it", str(most),
        "-rod_output", str(path)], ranks, TIMEOUT)
    assert process.returncode == 0, describe(process)
    with h5py.File(path, "r") as f:
        assert int(f.attrs["converged"]) == 1
        assert int(f.attrs["total_halvings"]) == 0
        iterations = int(f.attrs["total_iterations"])
        tension = float(f.attrs["top_tension"])
        moment = f.attrs["end_moment"][:]
    assert iterations <= most, iterations
    assert abs(tension - TOP_TENSION) <= 1e-6 * TOP_TENSION, tension
    assert np.abs(moment - END_MOMENT).max() <= 1e-6 * np.abs(END_MOMENT).max(), moment
