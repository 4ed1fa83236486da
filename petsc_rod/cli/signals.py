"""SIGINT, SIGTERM and SIGHUP end a run cleanly: the handler only records the signal,
and the continuation asks after every iteration, all ranks together, whether any rank
received one, so that every rank stops at the same iteration and the result file is
closed and removed collectively (mpiexec forwards a signal to every rank as SIGTERM,
and kills them a second later)."""

import signal

from mpi4py import MPI

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class Interrupts:
    """Within ``with Interrupts(comm) as interrupts:`` the stop signals are recorded;
    ``interrupts.received()`` (collective) gives the one any rank received, 0 if none.
    Later signals change nothing: a terminal's Ctrl-C reaches mpiexec's ranks both
    directly and as mpiexec's SIGTERM."""

    def __init__(self, comm):
        self.comm = comm.tompi4py()
        self.signal_number = 0
        self._previous = {}

    def _record(self, number, frame):
        self.signal_number = self.signal_number or number

    def __enter__(self):
        self._previous = {stop: signal.signal(stop, self._record) for stop in STOP_SIGNALS}
        return self

    def __exit__(self, *exc):
        for stop, handler in self._previous.items():
            if handler is not None:         # None: a handler not set from Python
                signal.signal(stop, handler)
        return False

    def received(self):
        """The stop signal a rank received (the largest number if several), else 0."""
        return self.comm.allreduce(self.signal_number, op=MPI.MAX)

    @staticmethod
    def name(number):
        return signal.Signals(number).name
