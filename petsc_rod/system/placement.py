"""Where the lines of a system are solved: the ranks of a communicator split into
groups, each group solving its lines one after the other on a sub-communicator of its
own, balanced by the lines' element counts. The layout (``layout``) is plain numbers;
``Placement`` makes the sub-communicators (mpi4py's Split)."""

from dataclasses import dataclass

import numpy as np

from petsc_rod.model.line import UniformLine
from petsc_rod.model.names import FIELD_NAMES


def line_elements(system_line):
    """The element count of a system line's line (model/line.py), its cost's measure."""
    line = system_line.line
    if isinstance(line, UniformLine):
        return int(line.elements)
    return int(np.sum(line.element_counts(FIELD_NAMES)))


def layout(sizes, ranks):
    """(group of each line (n,), first rank of each group (g + 1,): group k holds ranks
    first[k] .. first[k + 1] - 1) for lines of ``sizes`` (n,) elements on ``ranks``
    ranks. With at least as many lines as ranks, one rank a group, the lines dealt
    largest first to the least loaded rank (ties: the lowest rank); with fewer, one
    line a group, the ranks shared out in proportion to the sizes (at least one each,
    the rest by largest remainders), so that a long line spans several ranks."""
    sizes = np.asarray(sizes, dtype=float)
    n = sizes.size
    if n == 0:                                  # a body on its hydrostatics alone
        return np.zeros(0, dtype=int), np.array([0, ranks])
    if n >= ranks:
        group = np.empty(n, dtype=int)
        load = np.zeros(ranks)
        for line in np.argsort(-sizes, kind="stable"):   # the greedy deal is sequential
            target = int(np.argmin(load))
            group[line] = target
            load[target] += sizes[line]
        return group, np.arange(ranks + 1)
    share = sizes / sizes.sum() * (ranks - n)
    counts = 1 + np.floor(share).astype(int)
    rest = ranks - counts.sum()
    counts[np.argsort(-(share - np.floor(share)), kind="stable")[:rest]] += 1
    return np.arange(n), np.concatenate([[0], np.cumsum(counts)])


@dataclass
class Placement:
    """The layout of ``sizes`` on the ranks of ``comm`` (a PETSc.Comm): ``group`` (n,)
    of each line, ``first`` (g + 1,) ranks, this rank's ``my_group``, ``mine`` (the
    indices of the lines it solves), whether it is its group's ``root``, and
    ``line_comm``, the group's PETSc.Comm (``sub`` its mpi4py communicator, freed by
    ``destroy``; collective on ``comm``: Split)."""

    group: np.ndarray
    first: np.ndarray
    my_group: int
    mine: np.ndarray
    root: bool
    line_comm: object
    mpi: object
    sub: object

    @classmethod
    def make(cls, comm, sizes):
        from petsc4py import PETSc
        mpi = comm.tompi4py()
        group, first = layout(sizes, mpi.size)
        mine_group = int(np.searchsorted(first, mpi.rank, side="right") - 1)
        sub = mpi.Split(color=mine_group, key=mpi.rank)
        return cls(group, first, mine_group, np.flatnonzero(group == mine_group),
                   mpi.rank == first[mine_group], PETSc.Comm(sub), mpi, sub)

    def share(self, values):
        """{line index: value} of every line on every rank, from the values (dict by
        line index) of this rank's lines as its group's root holds them (small arrays;
        collective on the whole communicator)."""
        parts = self.mpi.allgather(values if self.root else {})
        return {k: v for part in parts for k, v in part.items()}

    def gather(self, values, root=0):
        """share's dict on rank ``root`` of the whole communicator only (None on the
        others): for what only a picture or a file needs (collective)."""
        parts = self.mpi.gather(values if self.root else {}, root=root)
        return None if parts is None else {k: v for part in parts for k, v in part.items()}

    def destroy(self):
        if self.sub is not None:
            self.sub.Free()
            self.sub = None
