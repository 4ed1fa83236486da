"""What a run needs from the machine, checked before anything is allocated: memory for
the element count, and an element count the PETSc integers can index."""

import os

import numpy as np
from petsc4py import PETSc

from petsc_rod.errors import RodInputError

# Memory of a run: per element (fields, matrices and their factors, the node state,
# Anderson's history, the stability test's factorisation; the default run's peak rounded
# up: docs/performance.md, "Memory for long lines") and per rank (the interpreter,
# PETSc, MPI).
BYTES_PER_ELEMENT = 20 * 2**10
BYTES_PER_RANK = 80 * 2**20
# A run whose Newton steps carry the node heights (a seabed: the positions' chain of
# analysis/positions.py in the Newton systems and their factors) needs more than twice
# that: the riser's peak on two ranks, rounded up (docs/performance.md, "Memory for long
# lines").
BYTES_PER_ELEMENT_HEIGHTS = 56 * 2**10
# Anderson mixing keeps 2 m vectors of the node state (18 numbers at 2 nodes per
# element): 576 bytes per element and unit of depth, allocated (and written: PETSc zeroes
# them) when the SNES is set up. Its default depth is the largest up to DEFAULT_DEPTH
# whose history fits the larger of HISTORY_FLOOR (per machine, shared by its ranks: the
# depth that hard scenes need, e.g. options/greenhill.opts, kept up to FULL_DEPTH_ELEMENTS;
# beyond, its set-up, the first touch of those pages, would cost more than 0.1 s and the
# long lines converge in a few tens of iterations with Newton steps:
# docs/performance.md, "Memory in proportion") and HISTORY_PER_ELEMENT per element (so
# that a run stays within 10 KiB per element at 1e5 elements and more, with the map's
# 5 KiB and the SNES's own vectors), and at most ANDERSON_SHARE of the memory available;
# never below MIN_DEPTH.
ANDERSON_BYTES = 2 * 18 * 2 * 8
DEFAULT_DEPTH = 30
MIN_DEPTH = 5
FULL_DEPTH_ELEMENTS = 10**4
HISTORY_FLOOR = DEFAULT_DEPTH * ANDERSON_BYTES * FULL_DEPTH_ELEMENTS
HISTORY_PER_ELEMENT = 3 * 2**10
ANDERSON_SHARE = 0.25
# The DMDA has 2 dofs per vertex, indexed by PETSc integers.
MAX_ELEMENTS = int(np.iinfo(PETSc.IntType).max) // 2 - 1


def bytes_per_element(heights_factored):
    """The memory estimate per element: BYTES_PER_ELEMENT, or BYTES_PER_ELEMENT_HEIGHTS
    where a second variation that carries the node heights may be factored
    (``heights_factored``: a seabed, with Newton steps or the stability test on)."""
    return BYTES_PER_ELEMENT_HEIGHTS if heights_factored else BYTES_PER_ELEMENT


def needed_memory(elements, ranks, per_element=BYTES_PER_ELEMENT):
    """Bytes a run of ``elements`` elements on ``ranks`` ranks needs, estimated with
    ``per_element`` bytes an element."""
    return ranks * BYTES_PER_RANK + elements * per_element


def anderson_depth(local_elements, ranks_here):
    """The default depth m of Anderson mixing for a rank with ``local_elements``
    elements on a machine shared by ``ranks_here`` ranks: its history m x 576 bytes
    per element within max(HISTORY_FLOOR / ranks_here, HISTORY_PER_ELEMENT per element)
    and ANDERSON_SHARE of the memory available (see the constants)."""
    if local_elements == 0:
        return DEFAULT_DEPTH
    budget = max(HISTORY_FLOOR / ranks_here, HISTORY_PER_ELEMENT * local_elements)
    available = available_memory()
    if available is not None:
        budget = min(budget, ANDERSON_SHARE * available / ranks_here)
    return int(min(DEFAULT_DEPTH, max(MIN_DEPTH, budget // (ANDERSON_BYTES * local_elements))))


def ranks_on_this_machine(comm):
    """How many ranks of ``comm`` (petsc4py) share this machine's memory. Collective."""
    from mpi4py import MPI
    node = comm.tompi4py().Split_type(MPI.COMM_TYPE_SHARED)
    here = node.Get_size()
    node.Free()
    return here


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


def check_elements_fit(comm, elements, per_element=BYTES_PER_ELEMENT, named=None):
    """Refuse an element count PETSc cannot index or distribute (every rank owns a
    vertex), or whose estimated memory (``per_element`` bytes an element,
    bytes_per_element) exceeds what a machine has available (the share of the ranks it
    runs). ``named``: how the message names the count (default '-rod_elements N'; the
    sections' counts where they set it). Collective."""
    named = named or f"-rod_elements {elements}"
    if elements > MAX_ELEMENTS:
        raise RodInputError(f"{named}: at most {MAX_ELEMENTS} elements fit "
                            "in PETSc's integers (2 dofs per vertex)")
    mpi = comm.tompi4py()
    if elements + 1 < mpi.Get_size():
        raise RodInputError(f"{named} on {mpi.Get_size()} ranks: every rank "
                            f"needs a vertex; use at least {mpi.Get_size() - 1} elements or "
                            "fewer ranks")
    here = ranks_on_this_machine(comm)
    needed = needed_memory(elements * here / mpi.Get_size(), here, per_element)
    known = [value for value in mpi.allgather(available_memory()) if value is not None]
    available = min(known) if known else None
    if available is not None and needed > available:
        largest = max(int((available - here * BYTES_PER_RANK) / per_element
                          * mpi.Get_size() / here), 0)
        raise RodInputError(
            f"{named}: the run needs about {size_text(needed)} of memory "
            f"({size_text(per_element)} per element), this machine has "
            f"{size_text(available)} available; use at most about {largest:.2g} elements, "
            "or more machines")


def free_disk(folder):
    """Bytes an unprivileged writer may still use in ``folder``'s file system."""
    stats = os.statvfs(folder)
    return stats.f_bavail * stats.f_frsize
