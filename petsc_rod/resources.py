"""What a run needs from the machine, checked before anything is allocated: memory for
the element count, and an element count the PETSc integers can index."""

import os

import numpy as np
from petsc4py import PETSc

from .errors import RodInputError

# Memory of a run: per element (fields, matrices and their factors, the Uzawa state at
# the quadrature points; about 6.5 KiB on one rank and more on two, README Performance,
# rounded up) and per rank (the interpreter, PETSc, MPI).
BYTES_PER_ELEMENT = 8 * 2**10
BYTES_PER_RANK = 80 * 2**20
# The DMDA has 2 dofs per vertex, indexed by PETSc integers.
MAX_ELEMENTS = int(np.iinfo(PETSc.IntType).max) // 2 - 1


def needed_memory(elements, ranks):
    """Bytes a run of ``elements`` elements on ``ranks`` ranks needs, estimated."""
    return ranks * BYTES_PER_RANK + elements * BYTES_PER_ELEMENT


def available_memory():
    """Bytes this machine can still give a run (MemAvailable; the address-space limit
    where it is lower), or None where neither is known."""
    limits = []
    try:
        with open("/proc/meminfo", encoding="ascii") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    limits.append(int(line.split()[1]) * 1024)
    except OSError:
        pass
    try:
        import resource
        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft != resource.RLIM_INFINITY:
            limits.append(soft)
    except (ImportError, ValueError, OSError):
        pass
    return min(limits) if limits else None


def size_text(nbytes):
    """Bytes in binary units, e.g. '7.5 TiB'."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if nbytes < 1024 or unit == "PiB":
            return f"{nbytes:.3g} {unit}"
        nbytes /= 1024


def check_elements_fit(comm, elements):
    """Refuse an element count PETSc cannot index or distribute (every rank owns a
    vertex), or whose estimated memory exceeds what a machine has available (the share
    of the ranks it runs). Collective."""
    if elements > MAX_ELEMENTS:
        raise RodInputError(f"-rod_elements {elements}: at most {MAX_ELEMENTS} elements fit "
                            "in PETSc's integers (2 dofs per vertex)")
    from mpi4py import MPI
    mpi = comm.tompi4py()
    if elements + 1 < mpi.Get_size():
        raise RodInputError(f"-rod_elements {elements} on {mpi.Get_size()} ranks: every rank "
                            f"needs a vertex; use at least {mpi.Get_size() - 1} elements or "
                            "fewer ranks")
    node = mpi.Split_type(MPI.COMM_TYPE_SHARED)
    here = node.Get_size()
    node.Free()
    needed = needed_memory(elements * here / mpi.Get_size(), here)
    known = [value for value in mpi.allgather(available_memory()) if value is not None]
    available = min(known) if known else None
    if available is not None and needed > available:
        largest = max(int((available - here * BYTES_PER_RANK) / BYTES_PER_ELEMENT
                          * mpi.Get_size() / here), 0)
        raise RodInputError(
            f"-rod_elements {elements}: the run needs about {size_text(needed)} of memory "
            f"({size_text(BYTES_PER_ELEMENT)} per element), this machine has "
            f"{size_text(available)} available; use at most about {largest:.2g} elements, "
            "or more machines")


def free_disk(folder):
    """Bytes an unprivileged writer may still use in ``folder``'s file system."""
    stats = os.statvfs(folder)
    return stats.f_bavail * stats.f_frsize
