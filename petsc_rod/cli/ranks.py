"""Where a line's run goes on several ranks (-rod_ranks_split; the choice is
mesh/ranks.choose's cost model): split over all of them (line_run's own path), or whole
on the first rank, on PETSc.COMM_SELF, while the others wait. A short line's iteration
costs more split than whole (the collectives and the same Python overhead on half the
data), so there the second rank is better idle; the run on rank 0 is the one-rank run
itself, so its answers are bitwise those of one rank.

The whole run keeps the command line's behaviour on several ranks: rank 0 says the lines
and writes the files (the run's own), the ranks end with the same exit code and the same
error (a RodError's, a PETSc error's as exit 4, anything else raised on every rank, as
when every rank fails), and a stop signal that any rank receives stops the run: a waiting
rank hands its signal to rank 0, which asks for it after every iteration
(WholeInterrupts). The waiting ranks sleep between polls, so they leave their cores to
other work, and while they wait they run on rank 0's cores (on_cores; those on its
machine): Linux's group scheduling (a session's autogroup, a cgroup) gives the job's
processes one weight, shared among the cores in proportion to each core's recent load
(PELT, a 32 ms half-life): a waiting rank's load of its own start-up, left on a core of
its own, would take about half of it from rank 0's core during the first tens of
milliseconds of the solve, all of a short line's. Rank 0 keeps mpiexec's binding, so
that the scheduler does not move it away from the waiting ranks' load
(docs/performance.md, "Where a whole run lost its time").
"""

import contextlib
import os
import time

from mpi4py import MPI
from petsc4py import PETSc

from petsc_rod.cli.line_run import run_line
from petsc_rod.errors import RodDivergedError, RodError
from petsc_rod.mesh.ranks import choose, passes_of

# The tag of a waiting rank's stop signal handed to rank 0.
STOP_TAG = 51
# The waiting ranks' pause between polls: from the first to the longest, doubling, s.
FIRST_PAUSE, LONGEST_PAUSE = 0.0005, 0.01


def placement(comm, plan):
    """'whole' or 'split': how the LinePlan ``plan`` runs on ``comm``
    (mesh/ranks.choose of -rod_ranks_split, the mesh's elements, the ranks and the
    friction's passes where the scene's seabed has friction)."""
    values = plan.values
    seabed = plan.scene.seabed
    return choose(values["rod_ranks_split"], values["rod_elements"], comm.getSize(),
                  passes=passes_of(seabed is not None and seabed.friction is not None))


class WholeInterrupts:
    """The interrupts (signals.Interrupts' interface) of the whole run on rank 0: its own
    signal, or one a waiting rank handed over on ``channel``; asked without a
    collective call."""

    def __init__(self, interrupts, channel):
        self.interrupts, self.channel, self.handed = interrupts, channel, 0
        self.from_others = 0

    def received(self):
        while self.channel.Iprobe(source=MPI.ANY_SOURCE, tag=STOP_TAG):
            number = self.channel.recv(source=MPI.ANY_SOURCE, tag=STOP_TAG)
            self.handed += 1
            self.from_others = max(self.from_others, number)
        own = 0 if self.interrupts is None else self.interrupts.signal_number
        return max(own, self.from_others)

    def name(self, number):
        return self.interrupts.name(number)


def run_whole(comm, work, interrupts=None):
    """``work(line_comm, line_interrupts)`` on rank 0 of ``comm`` alone, on
    PETSc.COMM_SELF, the other ranks waiting on rank 0's cores; returns its value on
    every rank, or raises on every rank what it raised (module docstring).
    ``interrupts``: the run's signals.Interrupts (None: none asked). Collective."""
    channel = comm.tompi4py().Dup()
    try:
        host, cores = channel.bcast((MPI.Get_processor_name(), _cores()), root=0)
        if channel.Get_rank() == 0:
            return _lead(channel, work, interrupts)
        with on_cores(cores if host == MPI.Get_processor_name() else set()):
            return _wait(channel, interrupts)
    finally:
        channel.Free()


def _cores():
    """The cores this process may run on (empty where the system does not say)."""
    with contextlib.suppress(AttributeError, OSError):
        return set(os.sched_getaffinity(0))
    return set()


@contextlib.contextmanager
def on_cores(cores):
    """Within the block this process runs on ``cores`` only, its own affinity put back
    after it; nothing where ``cores`` is empty or the system cannot set it."""
    own = _cores()
    moved = False
    if own and cores and cores != own:
        with contextlib.suppress(OSError):
            os.sched_setaffinity(0, cores)
            moved = True
    try:
        yield
    finally:
        if moved:
            with contextlib.suppress(OSError):
                os.sched_setaffinity(0, own)


def _lead(channel, work, interrupts):
    """Rank 0: the work, its outcome shared, the waiting ranks' signals all received."""
    stops = WholeInterrupts(interrupts, channel) if interrupts is not None else None
    raised = None
    try:
        outcome = ("value", work(PETSc.COMM_SELF, stops))
    except RodError as error:
        raised = error
        outcome = ("rod", (str(error), error.exit_code, getattr(error, "signal_number", 0)))
    except PETSc.Error as error:
        raised = error
        outcome = ("petsc", str(error))
    except BaseException as error:
        raised = error
        outcome = ("other", f"{type(error).__name__}: {error}".splitlines()[0])
    channel.Ibarrier().Wait()
    channel.bcast(outcome, root=0)
    handed = sum(channel.gather(0, root=0)[1:])
    for _ in range(handed - (stops.handed if stops is not None else 0)):
        channel.recv(source=MPI.ANY_SOURCE, tag=STOP_TAG)      # handed after the last ask
    if raised is not None:
        raise raised
    return outcome[1]


def _wait(channel, interrupts):
    """A waiting rank: sleep until rank 0 is done (handing it a stop signal received
    meanwhile), then its outcome as this rank's."""
    done, pause, handed = channel.Ibarrier(), FIRST_PAUSE, 0
    while not done.Test():
        if not handed and interrupts is not None and interrupts.signal_number:
            channel.send(interrupts.signal_number, dest=0, tag=STOP_TAG)
            handed = 1
        time.sleep(pause)
        pause = min(2 * pause, LONGEST_PAUSE)
    kind, payload = channel.bcast(None, root=0)
    channel.gather(handed, root=0)
    if kind == "value":
        return payload
    if kind == "rod":
        text, code, number = payload
        error = RodError(text)
        error.exit_code, error.signal_number = code, number
        raise error
    if kind == "petsc":
        raise RodDivergedError("PETSc failed on rank 0 during the solve")
    raise RuntimeError(f"rank 0 failed during the run ({payload})")


def run_placed(comm, plan, say, *, options="", interrupts=None):
    """line_run.run_line of ``plan`` where placement puts it: split over ``comm``, or
    whole on its rank 0 (run_whole); returns the run's exit code on every rank, or raises
    on every rank what the run raised. Collective."""
    if placement(comm, plan) == "split":
        return run_line(comm, plan, say, options=options, interrupts=interrupts).result.code
    return run_whole(comm, lambda line_comm, stops: run_line(
        line_comm, plan, say, options=options, interrupts=stops).result.code, interrupts)
