"""What the sweep scripts share: PETSc started late (so that --help and the
redraw-only modes need no MPI) and progress printed once, by rank 0."""

import sys


def start_petsc():
    """petsc4py.init without the script's own arguments; returns (COMM_WORLD, say)."""
    import petsc4py
    petsc4py.init([sys.argv[0]])
    from petsc4py import PETSc

    comm = PETSc.COMM_WORLD

    def say(text):
        if comm.getRank() == 0:
            print(text, flush=True)

    return comm, say
