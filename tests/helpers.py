"""Helpers for the tests (importable because conftest puts tests/ on sys.path)."""

import os
import shutil
import subprocess
import sys

import numpy as np

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def make_solver(comm, n_elements, scene_kwargs, penalty, rtol=1e-8, ctol=1e-5,
                max_it=5000, newton=True):
    """A (mesh, solver) pair for ``Scene(**scene_kwargs)`` on ``comm`` (``newton``:
    Settings.newton, off where a test is about the iteration without it); the problem is
    ``solver.problem``.

    The caller must call ``destroy(mesh, solver)`` (collectively), or use the
    ``solver_factory`` fixture which does it.
    """
    from petsc_rod.mesh.mesh import Mesh
    from petsc_rod.scenes.scene import Scene
    from petsc_rod.iteration.driver import solver_for
    from petsc_rod.iteration.stopping import Settings

    scene = Scene(**scene_kwargs)
    mesh = Mesh(comm, n_elements, scene.length)
    settings = Settings(asked_penalty=penalty, max_it=max_it, rtol=rtol, ctol=ctol,
                        newton=newton)
    return mesh, solver_for(mesh, scene, settings)


def destroy(mesh, solver):
    """Destroy what make_solver made (collective)."""
    solver.destroy()
    solver.problem.destroy()
    mesh.destroy()


# The paper scene at X_F = 16 (docs/method.md §8), and clamp reactions n(0), m(0) of
# petsc_rod's solution of it (80 elements, K3 = 200), rounded to three digits: integrated
# from the clamp they give a shooting guess close to the twisted branch of the collocation
# reference.
PAPER_STIFFNESS = (235.0, 360.0, 200.0)
PAPER_LENGTH = 20.0
PAPER_END_X = 16.0
PAPER_END = np.array([PAPER_END_X, PAPER_LENGTH - PAPER_END_X, 0.0])
TWISTED_CLAMP_FORCE = (-11.6, -4.03, 2.30)
TWISTED_CLAMP_MOMENT = (9.21, -36.8, -18.0)
# The scene of options/paper.opts at X_F = 16 as Scene keywords, and the unit cantilever
# under a tip force of 3 (P L^2 / EI = 3) of the solver tests.
PAPER_SCENE = dict(length=PAPER_LENGTH, stiffness=list(PAPER_STIFFNESS), start="clamp",
                   end="pin", end_position=[PAPER_END_X, PAPER_LENGTH - PAPER_END_X, 0.0])
CANTILEVER = dict(length=1.0, stiffness=(1.0, 1.0, 1.0), start="clamp", end="free",
                  end_force=(0.0, -3.0, 0.0))

# The cantilevers of the halving tests (tests/solver/test_continuation.py,
# tests/system/test_continuation_cli.py): 16 elements, one load step too many for
# -rod_al_max_it (BENT) or for the divergence bound (PULLED), two steps fine.
HALVING_ELEMENTS = 16
HALVING_RTOL, HALVING_CTOL = 1e-7, 1e-4
BENT = dict(scene=dict(length=1.0, stiffness=(1.0, 1.0, 1.0), start="clamp", end="free",
                       end_force=(0.0, -10.0, 0.0)),
            penalty=25.0, max_it=220, snes_type="nrichardson")
PULLED = dict(scene=dict(length=1.0, stiffness=(1.0, 1.0, 1.0), start="clamp", end="free",
                         end_force=(1.5e5, 0.0, 0.0)),
              penalty=100.0, max_it=2000, snes_type="anderson")


def twisted_paper_reference(tol=1e-10):
    """The collocation solution of the paper scene's twisted branch (validation/reference.py)."""
    from petsc_rod.validation import reference

    guess = reference.shooting_guess(PAPER_LENGTH, PAPER_STIFFNESS, TWISTED_CLAMP_FORCE,
                                     TWISTED_CLAMP_MOMENT)
    return reference.solve_paper_scene(PAPER_END_X, guess, stiffness=PAPER_STIFFNESS, tol=tol)


def fitted_order(n_elements, errors):
    """Slope of log(error) against log(h) by least squares."""
    return -np.polyfit(np.log(n_elements), np.log(errors), 1)[0]


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


def zero_slope_planes(monkeypatch):
    """Make a seabed slope of 0 degrees a bathymetry.Plane (its slope vector zero) for
    as long as ``monkeypatch`` holds, instead of the flat seabed the compile makes of it
    (compile.seabed_shape): the plane's own path (its contact on the x, y, z position
    chains, HeldLine's plane response) on the flat seabed's geometry."""
    from petsc_rod import compile as compile_module
    from petsc_rod.environment.bathymetry import Plane

    made = compile_module.seabed_shape

    def shape(sea, height, origin, n):
        if sea.seabed_slope == 0 and sea.seabed_profile is None:
            start = sea.seabed_origin if sea.seabed_origin is not None else (0.0, 0.0)
            return Plane.sloping(start, height, 0.0, sea.seabed_unit_direction()).moved(origin)
        return made(sea, height, origin, n)
    monkeypatch.setattr(compile_module, "seabed_shape", shape)


def run_cli(options):
    """cli.main.run on COMM_WORLD with ``options`` {name: text} in PETSc's options
    database, removed afterwards; the exit code."""
    from petsc4py import PETSc

    from petsc_rod.cli import main
    database = PETSc.Options()
    for name, value in options.items():
        database.setValue(name, value)
    try:
        return main.run(PETSc.COMM_WORLD)
    finally:
        for name in options:
            database.delValue(name)


def continuation(solver, steps=1, imperfection=0.0, **path):
    """From the straight state to load factor 1 by the CLI's continuation loop (halving
    and link check included; ``path``: the other fields of
    iteration.continuation.PathSettings); the last StepReport."""
    from petsc_rod.cli.session import run_continuation
    from petsc_rod.iteration.continuation import PathSettings

    solver.problem.state.set_straight()
    return run_continuation(solver, PathSettings(steps, imperfection, **path)).report


# Variables an enclosing mpiexec sets for its own processes: a child must not inherit
# them, or it would try to join that job (e.g. when pytest itself runs under mpiexec -n 1).
LAUNCHER_PREFIXES = ("PMIX_", "OMPI_COMM_WORLD", "OMPI_UNIVERSE_SIZE", "OMPI_FIRST_RANKS",
                     "OMPI_APP_CTX", "OMPI_NUM_APP_CTX", "OMPI_COMMAND", "OMPI_ARGV",
                     "OMPI_FILE_LOCATION", "OMPI_MCA_orte_", "OMPI_MCA_ess",
                     "OMPI_MCA_pmix", "OMPI_MCA_initial_wdir", "OMPI_MCA_shmem_RUNTIME",
                     "OMPI_MCA_mpi_oversubscribe")


def partial_files(path):
    """Every run's partial file of the result ``path`` (io.results.partial_name)."""
    import glob
    return glob.glob(f"{glob.escape(str(path))}.*.partial")


def child_env():
    """This environment without the variables of an enclosing mpiexec."""
    return {k: v for k, v in os.environ.items() if not k.startswith(LAUNCHER_PREFIXES)}


def mpiexec(ranks):
    """The launcher words for ``ranks`` ranks ([] for one); skips the test when mpiexec
    is not on PATH."""
    import pytest

    if ranks == 1:
        return []
    launcher = shutil.which("mpiexec")
    if launcher is None:
        pytest.skip("mpiexec is not on PATH")
    return [launcher, "-n", str(ranks)]


def petsc_rod_command(args, ranks=1):
    """``python -m petsc_rod args``, under mpiexec for several ranks."""
    return mpiexec(ranks) + [sys.executable, "-m", "petsc_rod"] + list(args)


def run_petsc_rod(args, ranks=1, timeout=120):
    """Run petsc_rod from the repository root in a clean environment; CompletedProcess
    with stdout and stderr captured apart."""
    return subprocess.run(petsc_rod_command(args, ranks), cwd=REPO_ROOT, env=child_env(),
                          capture_output=True, text=True, timeout=timeout, check=False)


def describe(process):
    """A finished process's exit code and output, for an assertion message."""
    return f"exit {process.returncode}\nstdout:\n{process.stdout}\nstderr:\n{process.stderr}"


def png_summary(path):
    """(height, width, share of pixels that are not white) of a PNG file: a figure that
    was drawn, not only written."""
    import matplotlib.image

    pixels = matplotlib.image.imread(str(path))[..., :3]
    return pixels.shape[0], pixels.shape[1], float(np.mean(np.any(pixels < 0.95, axis=-1)))


# The first lines of a script in which rank 1 alone raises while it computes its first
# step's record (io.outputs.step_record), after the result file was opened; the ranks
# wait 2 s for each other (cli.line_run.FAILURE_WAIT) before rank 1 takes the failure as
# its own.
ONE_RANK_FAILS = """
import sys
import petsc4py
petsc4py.init(sys.argv)
from petsc4py import PETSc
from petsc_rod.cli import line_run, main
from petsc_rod.io import outputs
line_run.FAILURE_WAIT = 2.0
if PETSc.COMM_WORLD.getRank() == 1:
    def step_record(*args, **kwargs):
        raise FloatingPointError("injected on rank 1")
    outputs.step_record = step_record
"""


def run_failing_on_rank_1(script, body, args, timeout=60):
    """Write ONE_RANK_FAILS + ``body`` to ``script`` and run it on 2 ranks with ``args``
    from the repository, this tree's petsc_rod first on the path; CompletedProcess."""
    script.write_text(ONE_RANK_FAILS + body)
    env = {**child_env(), "PYTHONPATH": str(REPO_ROOT)}
    return subprocess.run(mpiexec(2) + [sys.executable, str(script)] + list(args),
                          cwd=REPO_ROOT, env=env, capture_output=True, text=True,
                          timeout=timeout, check=False)
