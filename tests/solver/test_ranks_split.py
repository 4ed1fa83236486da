"""A short line's run whole on the first rank (-rod_ranks_split whole, cli/ranks.py):
the command line's run (cli.main.run) on PETSc.COMM_WORLD gives the result file of the
one-rank run bitwise, every rank ends with the run's exit code, and the run on two ranks
waits for a failure of rank 0 as one. Serially both runs are one rank's; under
``mpiexec -n 2`` the second rank waits while the first runs the line."""

import os
import signal
import time
from types import SimpleNamespace

import h5py
import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

from petsc_rod.cli import main
from petsc_rod.cli.ranks import placement, run_whole
from petsc_rod.errors import RodError, RodInterrupted, RodIOError

# a clamped-pinned rod of 12 elements, two steps (under a second of solve)
ROD = {"rod_length": "1", "rod_stiffness": "1,1.3,0.9", "rod_start": "clamp",
       "rod_end": "pin", "rod_end_position": "0.7,0.5,0.2", "rod_elements": "12",
       "rod_al_penalty": "100", "rod_steps": "2"}
# what the clock changes between two runs of the same line: their wall times, when written
TIMED = ("wall_time", "written")


def datasets(path):
    """{name: array} of every dataset of a result file, attributes as 'name@attribute'
    (the timed ones left out)."""
    found = {}

    def visit(name, item):
        if isinstance(item, h5py.Dataset) and not any(word in name for word in TIMED):
            found[name] = item[()]
        for key, value in item.attrs.items():
            if not any(word in key for word in TIMED) and key != "options":
                found[f"{name}@{key}"] = value

    with h5py.File(path, "r") as f:
        visit("", f)
        f.visititems(visit)
    return found


def test_a_short_rod_whole_on_every_rank_is_the_one_rank_run(shared_tmp, monkeypatch):
    world = PETSc.COMM_WORLD
    monkeypatch.chdir(shared_tmp)
    # the same options (the file records them), the same file name in two folders
    whole, alone = (os.path.join(shared_tmp, folder, "rod.h5") for folder in ("two", "one"))
    if world.getRank() == 0:
        os.mkdir(os.path.dirname(whole))
        os.mkdir(os.path.dirname(alone))
    world.tompi4py().Barrier()
    os.chdir(os.path.dirname(whole))
    texts = {**ROD, "rod_output": "rod.h5", "rod_ranks_split": "whole"}
    assert main.run(world, texts) == 0
    if world.getRank() == 0:            # the same run on one rank, the others idle
        os.chdir(os.path.dirname(alone))
        assert main.run(PETSc.COMM_SELF, texts) == 0
    world.tompi4py().Barrier()
    assert not os.path.exists(whole + ".partial")
    one, two = datasets(alone), datasets(whole)
    assert sorted(one) == sorted(two)
    differ = [name for name in one if not np.array_equal(np.asarray(one[name]),
                                                        np.asarray(two[name]))]
    assert differ == []
    assert int(two["@ranks"]) == 1 and int(two["@converged"]) == 1


def test_a_run_that_does_not_converge_ends_with_exit_3_on_every_rank(shared_tmp):
    path = os.path.join(shared_tmp, "capped.h5")
    code = main.run(PETSc.COMM_WORLD, {**ROD, "rod_output": path, "rod_ranks_split": "whole",
                                       "rod_al_max_it": "3", "rod_max_halvings": "0"})
    codes = PETSc.COMM_WORLD.tompi4py().allgather(code)
    assert codes == [3] * PETSc.COMM_WORLD.getSize()
    with h5py.File(path, "r") as f:
        assert int(f.attrs["converged"]) == 0


def test_an_input_error_inside_the_whole_run_is_every_rank_s(shared_tmp):
    """A restart file that is not there is found once the line is built, on rank 0
    alone: every rank ends with exit 2."""
    missing = os.path.join(shared_tmp, "missing.h5")
    code = main.run(PETSc.COMM_WORLD, {**ROD, "rod_initial": missing,
                                       "rod_ranks_split": "whole"})
    assert MPI.COMM_WORLD.allgather(code) == [2] * MPI.COMM_WORLD.size


def test_a_bad_placement_is_refused_in_one_line(capfd):
    code = main.run(PETSc.COMM_WORLD, {**ROD, "rod_ranks_split": "half"})
    assert code == 2
    lines = capfd.readouterr().out.splitlines()
    expected = ["petsc_rod: error: -rod_ranks_split half: expected one of auto|whole|split"]
    assert lines == (expected if PETSc.COMM_WORLD.getRank() == 0 else [])


class Recorded:
    """A run's signals.Interrupts as the handler leaves it: ``signal_number``."""

    def __init__(self, number):
        self.signal_number = number

    @staticmethod
    def name(number):
        return str(number)


def test_a_stop_signal_of_the_last_rank_reaches_the_whole_run():
    """The last rank received SIGUSR1 (rank 0 itself on one rank): rank 0's work asks
    for a signal and gets it; every rank returns what the work returned."""
    world = PETSc.COMM_WORLD
    last = world.getRank() == world.getSize() - 1
    interrupts = Recorded(signal.SIGUSR1 if last else 0)

    def work(line_comm, stops):
        assert line_comm.getSize() == 1
        deadline = time.monotonic() + 20.0
        while time.monotonic() < deadline:
            if stops.received():
                return stops.received()
            time.sleep(0.001)
        return 0

    assert run_whole(world, work, interrupts) == signal.SIGUSR1


@pytest.mark.skipif(not hasattr(os, "sched_getaffinity"), reason="no CPU affinity here")
def test_the_waiting_ranks_wait_on_rank_0_s_cores_and_rank_0_keeps_its_own():
    """While rank 0 works, every waiting rank on its machine may run on rank 0's cores
    only (so that the scheduler counts the job's load on rank 0's cores), rank 0 on its
    own cores as before; each rank's own cores are put back after the run."""
    world = PETSc.COMM_WORLD.tompi4py()
    own = os.sched_getaffinity(0)
    ranks = world.allgather((MPI.Get_processor_name(), os.getpid(), sorted(own)))

    def work(line_comm, stops):
        # the waiting ranks move once they have rank 0's cores: a moment after it starts
        deadline = time.monotonic() + 2.0
        while True:
            seen = [(sorted(os.sched_getaffinity(pid)), host == ranks[0][0])
                    for host, pid, _ in ranks]
            if time.monotonic() > deadline or all(cores == ranks[0][2]
                                                  for cores, local in seen if local):
                return seen
            time.sleep(0.001)

    during = run_whole(PETSc.COMM_WORLD, work, Recorded(0))
    assert during[0][0] == ranks[0][2]
    assert [cores for cores, local in during[1:] if local] == \
        [ranks[0][2]] * sum(local for _, local in during[1:])
    assert os.sched_getaffinity(0) == own


@pytest.mark.parametrize("raised, code", [
    (RodInterrupted("interrupted by SIGTERM", signal.SIGTERM), 128 + signal.SIGTERM),
    (RodIOError("the disk is full"), 5)])
def test_the_whole_run_s_error_is_raised_on_every_rank(raised, code):
    def work(line_comm, stops):
        raise raised

    with pytest.raises(RodError) as error:
        run_whole(PETSc.COMM_WORLD, work, Recorded(0))
    assert error.value.exit_code == code and str(error.value) == str(raised)
    assert getattr(error.value, "signal_number", 0) == getattr(raised, "signal_number", 0)


def test_a_file_without_the_placement_still_walks_its_restart(shared_tmp, capfd):
    """A result file written before -rod_ranks_split (its parameters without it) is not
    taken for an older version's: a restart under another end force walks from its
    scene."""
    path = os.path.join(shared_tmp, "before.h5")
    assert main.run(PETSc.COMM_WORLD, {**ROD, "rod_output": path}) == 0
    if PETSc.COMM_WORLD.getRank() == 0:
        with h5py.File(path, "r+") as f:
            del f["parameters"].attrs["ranks_split"]
    PETSc.COMM_WORLD.tompi4py().Barrier()
    capfd.readouterr()
    moved = {**ROD, "rod_end_position": "0.6,0.5,0.3", "rod_initial": path}
    assert main.run(PETSc.COMM_WORLD, moved) == 0
    out = capfd.readouterr().out
    if PETSc.COMM_WORLD.getRank() == 0:
        assert "restart: walks from the file's scene" in out and "lack" not in out, out


def test_a_line_with_seabed_friction_is_placed_with_its_passes():
    """placement gives the model the friction's passes where the scene's seabed has
    friction: 850 elements (mooring_chain's) split on 2 ranks without it, whole with it
    (mesh/ranks.py, FRICTION_PASSES)."""
    two = SimpleNamespace(getSize=lambda: 2)
    values = {"rod_ranks_split": "auto", "rod_elements": 850}

    def plan(seabed):
        return SimpleNamespace(values=values, scene=SimpleNamespace(seabed=seabed))

    assert placement(two, plan(SimpleNamespace(friction=object()))) == "whole"
    assert placement(two, plan(SimpleNamespace(friction=None))) == "split"
    assert placement(two, plan(None)) == "split"
