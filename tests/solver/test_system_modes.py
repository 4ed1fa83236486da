"""The modes of each line of a system with its ends held (-rod_modes on a system's run,
api/system_run.line_modes, docs/modes.md): each line's modes about its equilibrium in
the system are the single line's modes with its ends pinned where the system holds
them; in the system's result file (lines/<name>/modes) and its run's lines."""

import os

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.api import End, Model, read_moordyn, solve, solve_system

pytestmark = pytest.mark.solver
pytest.importorskip("slepc4py")

DECK = os.path.join(os.path.dirname(__file__), "..", "data", "moordyn", "small_free_body.dat")
COUNT = 5


def test_each_line_s_modes_are_the_held_single_line_s(shared_tmp):
    """small_free_body.dat (three short chains to a free body): each line's COUNT lowest
    modes in the system equal those of api.solve of the same line with its ends pinned
    at the system's equilibrium positions (its first and last vertex) and
    Model.options {'modes': COUNT}: frequencies to 10^-6 relative (the two equilibria
    agree to the solvers' tolerance), modal masses and classes of the vibrations; the
    system's file has them in lines/<name>/modes, its lines a table per line."""
    import h5py
    system, _ = read_moordyn(DECK)
    path = os.path.join(shared_tmp, "system.h5")
    said = []
    results = solve_system(system, output=path, say=said.append, options={"modes": COUNT})
    text = "\n".join(said)
    for line in system.lines:
        assert f"line {line.name} (ends held): modes: {COUNT} lowest" in text
        found = results.modes[line.name]
        ends = results.lines[line.name].along_line(["r"])["r"][[0, -1]]
        single = os.path.join(shared_tmp, f"{line.name}.h5")
        model = Model(line.line, End("pin", position=tuple(ends[0])),
                      End("pin", position=tuple(ends[1])), system.environment,
                      tuple(line.attachments), options={"modes": COUNT})
        assert solve(model, output=single).converged
        with h5py.File(single, "r") as f:
            frequency = f["modes/frequency"][:]
            modal_mass = f["modes/modal_mass"][:]
            classes = f["modes"].attrs["classes"].split(",")
        vibrations = frequency > 1e-3                  # the free roll's rigid mode aside
        assert vibrations.sum() >= COUNT - 1
        assert np.allclose(found.frequencies[vibrations], frequency[vibrations], rtol=1e-6)
        assert np.allclose(found.frequencies[~vibrations], 0.0, atol=1e-4)
        assert np.allclose(found.modal_mass[vibrations], modal_mass[vibrations], rtol=1e-5)
        assert list(np.array(found.labels)[vibrations]) == \
            list(np.array(classes)[vibrations])
        with h5py.File(path, "r") as f:
            group = f[f"lines/{line.name}/modes"]
            assert np.array_equal(group["frequency"][:], found.frequencies)
            vertices = f[f"lines/{line.name}/S"].shape[0]
            assert group["offset"].shape == (vertices, COUNT, 3)
            swaying = vibrations & (np.array(found.labels) != "torsional")
            largest = np.linalg.norm(group["offset"][:][:, swaying], axis=2).max(axis=0)
            assert np.allclose(largest, 1.0, atol=1e-9)     # normalised to 1 m


def test_a_system_refuses_a_bad_modes_option():
    """A malformed modes option: refused in one line before any work."""
    from petsc_rod.errors import RodInputError
    system, _ = read_moordyn(DECK)
    with pytest.raises(RodInputError, match="-rod_modes"):
        solve_system(system, options={"modes": "many"})


def test_a_system_refuses_more_modes_than_a_line_has(shared_tmp):
    """Options {'modes': 100000}: refused in one line naming the first line short of
    them and how many it has (the inertia's count, analysis/modes.modes_count: 561 for
    each 70-element chain, as many as {'modes_range': '0,1e30'} finds and verifies), before
    any mode is solved and with no file (each line reported what it found and warned
    that a larger -rod_modes_eps_ncv finds the others); -rod_modes_eps_ncv below
    nev + 1 refused before any work."""
    from petsc_rod.errors import RodInputError
    system, _ = read_moordyn(DECK)
    path = os.path.join(shared_tmp, "too_many.h5")
    with pytest.raises(RodInputError) as refused:
        solve_system(system, output=path, options={"modes": 100000})
    message = str(refused.value)
    assert "\n" not in message and not os.path.exists(path)
    assert message.startswith("-rod_modes 100000: line Line1's discretisation has 561 "
                              "modes; ask for at most 561")
    database = PETSc.Options()
    database.setValue("rod_modes_eps_ncv", "5")
    try:
        with pytest.raises(RodInputError, match=r"^-rod_modes_eps_ncv 5: -rod_modes 5 "
                                                r"needs a Krylov subspace of at least 6"):
            solve_system(system, options={"modes": COUNT})
        # a value that is no whole number: an input error, not a solve's failure (exit 4)
        database.setValue("rod_modes_eps_ncv", "abc")
        with pytest.raises(RodInputError, match=r"^-rod_modes_eps_nev and "
                                                r"-rod_modes_eps_ncv take whole numbers"):
            solve_system(system, options={"modes": COUNT})
    finally:
        database.delValue("rod_modes_eps_ncv")


def test_each_line_s_modes_in_a_band():
    """Options {'modes_range': '0.2,0.4'} on the same system: each line's modes in the
    band, counted by the inertia, are those of its 8 lowest that lie in it (which
    reach beyond 0.4 Hz; frequencies to 1e-9), and the run's lines say the band and
    the count."""
    system, _ = read_moordyn(DECK)
    said = []
    band = solve_system(system, say=said.append, options={"modes_range": "0.2,0.4"})
    lowest = solve_system(system, options={"modes": 8})
    for line in system.lines:
        assert lowest.modes[line.name].frequencies[-1] > 0.4
        found, every = band.modes[line.name], lowest.modes[line.name].frequencies
        inside = every[(every >= 0.2) & (every <= 0.4)]
        assert found.band[2] == len(found.frequencies) == len(inside) > 0
        assert np.allclose(found.frequencies, inside, rtol=1e-9)
        assert f"line {line.name} (ends held): modes: {len(inside)} in 0.2-0.4 Hz" in \
            "\n".join(said)


def test_each_line_s_modes_in_a_band_wider_than_its_spectrum():
    """Options {'modes_range': '0,1e30'}: each line's every mode, as many verified as
    the inertia counts, its lowest 8 (a free roll at 0 Hz first) those of {'modes': 8}
    to 1e-9 (one shift at the band's middle gave 7e29 Hz and negative modal masses)."""
    system, _ = read_moordyn(DECK)
    said = []
    wide = solve_system(system, say=said.append, options={"modes_range": "0,1e30"})
    lowest = solve_system(system, options={"modes": 8})
    for line in system.lines:
        found, every = wide.modes[line.name], lowest.modes[line.name]
        assert found.band[2] == len(found.frequencies) > 8 and not found.slices
        assert np.all(found.modal_mass > 0)
        assert np.allclose(found.frequencies[:8], every.frequencies, rtol=1e-9, atol=1e-6)
    assert "every mode of the band verified" in "\n".join(said)


def test_a_line_whose_eigensolver_fails_is_named_on_every_rank(monkeypatch):
    """The eigensolver failing on one line only (ModesFailed: on 2 ranks, on one rank's
    lines only) ends the system's run on every rank, the line named (exit 4's
    RodDivergedError), where the other ranks would wait for its modes in the lines'
    share."""
    import pickle

    from petsc_rod.analysis.modes import ModesFailed
    from petsc_rod.api import system_run
    from petsc_rod.errors import RodDivergedError
    real, calls = system_run.solve_modes, []
    last = PETSc.COMM_WORLD.getSize() - 1

    def failing_first_on_the_last_rank(problem, *args, **kwargs):
        calls.append(problem)
        if PETSc.COMM_WORLD.getRank() == last and len(calls) == 1:
            raise ModesFailed.of_error(RuntimeError("[0] a test's"))  # a PETSc.Error's report
        return real(problem, *args, **kwargs)

    monkeypatch.setattr(system_run, "solve_modes", failing_first_on_the_last_rank)
    system, _ = read_moordyn(DECK)
    with pytest.raises(RodDivergedError) as raised:
        solve_system(system, options={"modes": COUNT})
    assert isinstance(raised.value, ModesFailed)
    text = str(raised.value)
    assert text.startswith("line Line") and text.endswith(
        ": the modes' eigensolver (SLEPc) failed: a test's; check the -rod_modes_eps_* and "
        "-rod_modes_st_* options")
    names = PETSc.COMM_WORLD.tompi4py().allgather(text)
    assert len(set(names)) == 1                     # the same line named on every rank
    # a pickle of it (an MPI share's) keeps its message, not wrapped again
    shared = pickle.loads(pickle.dumps(raised.value))
    assert isinstance(shared, ModesFailed) and str(shared) == text
