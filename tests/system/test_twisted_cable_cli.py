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
STEPS = 12
# Newton's count: about 19 iterations a step (228 measured); the iteration alone spread
# the twist from the clamp for 8707 iterations (up to 1500 in a step)
MOST_ITERATIONS = 25 * STEPS
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


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_clamped_cable_rolled_three_turns_converges_in_newtons_count(clamped, ranks):
    path = clamped.parent / f"rolled_{ranks}.h5"
    process = run_petsc_rod(CLAMPED + [
        "-rod_initial", str(clamped), "-rod_end_twist", f"{2 * np.pi * TURNS!r}",
        "-rod_steps", str(STEPS), "-rod_al_max_it", str(MOST_ITERATIONS),
        "-rod_output", str(path)], ranks, TIMEOUT)
    assert process.returncode == 0, describe(process)
    with h5py.File(path, "r") as f:
        assert int(f.attrs["converged"]) == 1
        assert int(f.attrs["total_halvings"]) == 0
        iterations = int(f.attrs["total_iterations"])
        tension = float(f.attrs["top_tension"])
        moment = f.attrs["end_moment"][:]
    assert iterations <= MOST_ITERATIONS, iterations
    assert abs(tension - TOP_TENSION) <= 1e-6 * TOP_TENSION, tension
    assert np.abs(moment - END_MOMENT).max() <= 1e-6 * np.abs(END_MOMENT).max(), moment
