"""Helpers for the tests (importable because conftest puts tests/ on sys.path)."""

import os

import numpy as np


def make_solver(comm, n_elements, scene_kwargs, penalty, rtol=1e-8, ctol=1e-5,
                max_it=5000):
    """A (mesh, solver) pair for ``Scene(**scene_kwargs)`` on ``comm``.

    The caller must call ``solver.destroy(); mesh.destroy()`` (collectively), or use the
    ``solver_factory`` fixture which does it.
    """
    from petsc_rod.mesh.mesh import Mesh
    from petsc_rod.scenes.scene import Scene
    from petsc_rod.iteration.driver import UzawaSolver
    from petsc_rod.iteration.stopping import Settings

    scene = Scene(**scene_kwargs)
    mesh = Mesh(comm, n_elements, scene.length)
    settings = Settings(asked_penalty=penalty, max_it=max_it, rtol=rtol, ctol=ctol)
    solver = UzawaSolver(mesh, scene, settings)
    return mesh, solver


def gather(comm, owned):
    """All ranks' owned slices of an array (first axis), concatenated in rank order.

    ``comm`` is a PETSc or mpi4py communicator; collective; every rank gets the whole.
    """
    mpi = comm.tompi4py() if hasattr(comm, "tompi4py") else comm
    parts = mpi.allgather(np.asarray(owned))
    return np.concatenate(parts, axis=0)


def global_max(comm, value):
    """Maximum of a float over all ranks (collective)."""
    from mpi4py import MPI
    mpi = comm.tompi4py() if hasattr(comm, "tompi4py") else comm
    return mpi.allreduce(float(value), op=MPI.MAX)


def continuation(solver, steps=1, imperfection=0.0, **options):
    """From the straight state to load factor 1 by the CLI's continuation loop (halving
    and link check included; ``options`` as iteration.continuation.continuation takes
    them); the last StepReport."""
    from petsc_rod.iteration.continuation import continuation as run

    solver.state.set_straight()
    return run(solver, steps, imperfection, **options).report


# Variables an enclosing mpiexec sets for its own processes: a child must not inherit
# them, or it would try to join that job (e.g. when pytest itself runs under mpiexec -n 1).
LAUNCHER_PREFIXES = ("PMIX_", "OMPI_COMM_WORLD", "OMPI_UNIVERSE_SIZE", "OMPI_FIRST_RANKS",
                     "OMPI_APP_CTX", "OMPI_NUM_APP_CTX", "OMPI_COMMAND", "OMPI_ARGV",
                     "OMPI_FILE_LOCATION", "OMPI_MCA_orte_", "OMPI_MCA_ess",
                     "OMPI_MCA_pmix", "OMPI_MCA_initial_wdir", "OMPI_MCA_shmem_RUNTIME",
                     "OMPI_MCA_mpi_oversubscribe")


def child_env():
    """This environment without the variables of an enclosing mpiexec."""
    return {k: v for k, v in os.environ.items() if not k.startswith(LAUNCHER_PREFIXES)}
