"""Shared pytest set-up for petsc_rod: PETSc initialisation, communicators, MPI-safe
temporary folders, the markers and helpers to build a solver.

Tiers, one folder each, marked by it: ``unit`` (numpy only, no PETSc object), ``solver``
(solver runs in this process, on the ranks pytest runs on) and ``system`` (spawn
``python -m petsc_rod`` or a script; also marked ``serial`` and ``slow``). ``slow``
also marks the few solver runs that take seconds: ``pytest -m "not slow"`` is the quick
tier.

Every test file must pass both serially and under ``mpiexec -n 2``: collective calls are
made in the same order on every rank, and skip decisions are identical on all ranks.
"""

import os
import shutil
import sys
import tempfile

# one BLAS thread, as python -m petsc_rod runs (petsc_rod/__main__.py): the thread count
# changes numpy's round-off, and an accelerated iteration's path with it (on
# 2026-12-02 a flex-joint case converged with one thread and stagnated with two)
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import petsc4py  # noqa: E402

petsc4py.init(sys.argv[:1])

import pytest  # noqa: E402
from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc  # noqa: E402

TESTS_DIR = os.path.dirname(os.path.abspath(__file__))
REPO_ROOT = os.path.dirname(TESTS_DIR)
for path in (TESTS_DIR, REPO_ROOT):
    if path not in sys.path:
        sys.path.insert(0, path)

from helpers import destroy, gather, make_solver  # noqa: E402,F401  (re-exported for tests)


TIERS = ("unit", "solver", "system")


def pytest_configure(config):
    config.addinivalue_line(
        "markers", "serial: spawns processes (or needs the whole machine); skipped when "
        "the tests themselves run on several MPI ranks")
    config.addinivalue_line("markers", "slow: takes seconds; left out by -m 'not slow'")
    for tier in TIERS:
        config.addinivalue_line("markers", f"{tier}: a test of the tests/{tier} folder")


def pytest_collection_modifyitems(config, items):
    for item in items:
        tier = os.path.basename(os.path.dirname(str(item.fspath)))
        if tier in TIERS:
            item.add_marker(getattr(pytest.mark, tier))
        if tier == "system":
            item.add_marker(pytest.mark.serial)
            item.add_marker(pytest.mark.slow)
    if MPI.COMM_WORLD.size == 1:
        return
    skip = pytest.mark.skip(reason="serial test (spawns processes; mpiexec cannot nest): "
                                   f"skipped on {MPI.COMM_WORLD.size} ranks")
    for item in items:
        if "serial" in item.keywords:
            item.add_marker(skip)


@pytest.fixture
def comm():
    return PETSc.COMM_WORLD


@pytest.fixture
def shared_tmp():
    """A temporary folder with the same path on every rank; removed afterwards."""
    world = MPI.COMM_WORLD
    path = tempfile.mkdtemp(prefix="petsc_rod_test_") if world.rank == 0 else None
    path = world.bcast(path, root=0)
    yield path
    world.Barrier()
    if world.rank == 0:
        shutil.rmtree(path, ignore_errors=True)
    world.Barrier()


@pytest.fixture
def options():
    """``set(**values)`` sets PETSc options for one test (on every rank) and returns
    cli.options.read_options, to call for (values, given); removed afterwards."""
    from petsc_rod.cli.options import read_options
    database = PETSc.Options()
    names = []

    def set_options(**values):
        for name, value in values.items():
            database.setValue(name, value)
            names.append(name)
        return read_options

    yield set_options
    for name in names:
        database.delValue(name)


@pytest.fixture
def solver_factory():
    """``build(comm, n_elements, scene_kwargs, penalty, rtol, ctol, max_it)`` -> (mesh,
    solver); every solver built is destroyed (collectively, in reverse order) at the end."""
    built = []

    def build(*args, **kwargs):
        mesh, solver = make_solver(*args, **kwargs)
        built.append((mesh, solver))
        return mesh, solver

    yield build
    for mesh, solver in reversed(built):
        destroy(mesh, solver)
