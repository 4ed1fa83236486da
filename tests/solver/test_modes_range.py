"""-rod_modes_range FMIN,FMAX (analysis/modes.solve_modes with a band): every mode in a
frequency band, counted by the inertia of K - sigma M at both ends and found by
shift-and-invert about the band's middle; a taut string's modes in a band are its
closed form's list; a bad band refused in one line. Serially and on 2 ranks."""

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import continuation, destroy, make_solver, run_cli

from test_modes import pinned

pytest.importorskip("slepc4py")


def string_modes(band=None, count=0, n_elements=32):
    from petsc_rod.analysis.mass import MassSettings
    from petsc_rod.analysis.modes import solve_modes
    scene, _, _ = pinned(100.0, 1e6, 1e-6)
    mesh, solver = make_solver(PETSc.COMM_WORLD, n_elements, scene, 1e2)
    try:
        continuation(solver)
        return solve_modes(solver.problem, count, MassSettings(mass=1.0), band=band)
    finally:
        destroy(mesh, solver)


def closed_form(n):
    _, length, m = pinned(100.0, 1e6, 1e-6)
    return n / (2 * length) * np.sqrt(100.0 / m)


def test_a_taut_string_s_modes_in_a_band_are_the_closed_form_s():
    """f_n = n / (2 L') sqrt(T / m') = 5.0 n Hz, a pair (in and out of the plane) each:
    [7, 16] Hz holds n = 2, 3, four modes; the band's ends leave out n = 1 and 4."""
    modes = string_modes(band=(7.0, 16.0))
    assert modes.band == (7.0, 16.0, 4)
    exact = closed_form(np.array([2, 2, 3, 3]))
    assert np.allclose(modes.frequencies, exact, rtol=1e-5)
    lowest = string_modes(count=6)
    assert np.allclose(modes.frequencies, lowest.frequencies[2:], rtol=1e-9)
    assert np.allclose(modes.modal_mass, lowest.modal_mass[2:], rtol=1e-6)
    every = PETSc.COMM_WORLD.tompi4py().allgather(modes.frequencies)
    assert all(np.allclose(every[0], f, rtol=1e-10) for f in every)


def test_a_band_from_zero_and_a_band_without_modes():
    below = string_modes(band=(0.0, 11.0))
    assert below.band[2] == 4
    assert np.allclose(below.frequencies, closed_form(np.array([1, 1, 2, 2])), rtol=1e-5)
    empty = string_modes(band=(5.5, 9.5))
    assert empty.band == (5.5, 9.5, 0) and len(empty.omega2) == 0


@pytest.mark.parametrize("text", ["5,1", "abc", "-1,2", "1,2,3", "1,inf", "3,3"])
def test_a_bad_band_is_refused_in_one_line(text, capsys):
    assert run_cli({"rod_length": "1", "rod_modes_mass": "1", "rod_modes_range": text}) == 2
    out = capsys.readouterr().out
    if PETSc.COMM_WORLD.getRank() == 0:
        lines = [line for line in out.splitlines() if "error" in line]
        assert len(lines) == 1 and "-rod_modes_range" in lines[0] and "step 1" not in out
        assert "expected FMIN,FMAX" in lines[0]


def test_a_band_beside_a_count_is_refused(capsys):
    assert run_cli({"rod_length": "1", "rod_modes_mass": "1", "rod_modes": "3",
                    "rod_modes_range": "1,2"}) == 2
    out = capsys.readouterr().out
    if PETSc.COMM_WORLD.getRank() == 0:
        assert "give one" in out


def test_the_api_and_the_command_line_take_a_band(tmp_path):
    """Model.options['modes_range'] on a uniform cantilever (EI 2, m 3, 16 elements):
    api.solve returns the band's modes, the command line's table the same; the
    closed form beta_n^2 / (2 pi L^2) sqrt(EI / m), beta_n L = 4.6941 (2.879 Hz) and
    7.8548 (8.061 Hz), a pair each in [1, 10] Hz, the first (1.0237 Hz) left out."""
    from petsc_rod.api import End, Model, UniformLine, solve
    EI, m = 2.0, 3.0
    cantilever = Model(UniformLine(length=1.0, stiffness=(EI, EI, EI), elements=16),
                       start=End("clamp"), end=End("free"), initial_shape="straight",
                       options={"modes_range": "1.1,10", "modes_mass": m})
    modes = solve(cantilever, comm=PETSc.COMM_WORLD).modes
    exact = np.repeat(np.array([4.6941, 7.8548]) ** 2 / (2 * np.pi) * np.sqrt(EI / m), 2)
    assert modes.band == (1.1, 10.0, 4)
    assert np.allclose(modes.frequencies, exact, rtol=1e-3)
    folder = PETSc.COMM_WORLD.tompi4py().bcast(str(tmp_path))
    path = f"{folder}/band.csv"
    given = {"length": 1, "stiffness": f"{EI},{EI},{EI}", "start": "clamp", "end": "free",
             "elements": 16, "modes_range": "1.1,10", "modes_mass": m, "modes_table": path}
    assert run_cli({f"rod_{name}": str(value) for name, value in given.items()}) == 0
    assert np.allclose(modes.frequencies, np.loadtxt(path, delimiter=",", skiprows=1,
                                                     usecols=1), rtol=1e-9)


def test_a_band_without_modes_writes_the_tables_headers(shared_tmp, capsys):
    """A band above every mode of the 8-element string (1000-1001 Hz): the run
    converges, says the inertia counts 0, and -rod_modes_table writes both tables'
    header lines alone (no row), the result file's group with zero modes."""
    import h5py
    import os
    path, output = (os.path.join(shared_tmp, name) for name in ("empty.csv", "empty.h5"))
    given = {"length": 1, "modes_mass": 1, "modes_range": "1000,1001", "elements": 8,
             "modes_table": path, "output": output}
    assert run_cli({f"rod_{name}": str(value) for name, value in given.items()}) == 0
    out = capsys.readouterr().out
    if PETSc.COMM_WORLD.getRank() == 0:
        assert "modes: 0 in 1000-1001 Hz (the inertia counts 0)" in out
        for name in (path, path.replace(".csv", "_shapes.csv")):
            with open(name) as table:
                assert len(table.read().splitlines()) == 1
        with h5py.File(output, "r") as f:
            assert f["modes/frequency"].shape == (0,)
            assert list(f["modes"].attrs["band"]) == [1000.0, 1001.0, 0.0]


def cantilever_band(band):
    from petsc_rod.api import End, Model, UniformLine, solve
    cantilever = Model(UniformLine(length=1.0, stiffness=(2.0, 2.0, 2.0), elements=16),
                       start=End("clamp"), end=End("free"), initial_shape="straight",
                       options={"modes_range": band, "modes_mass": 3.0})
    return solve(cantilever, comm=PETSc.COMM_WORLD).modes


def test_a_wide_band_gives_the_narrow_band_s_frequencies():
    """The cantilever (EI 2, m 3, 16 elements) in [0, 1e7] and [0, 1e30] Hz: one shift
    at the band's middle lost the low modes' digits (mode 1 came out far above 1.0237
    Hz); the band cut into sub-bands gives as many verified pairs as the inertia counts
    (every mode of the discretisation in the second), the lowest six of [0, 10] Hz to 1e-9
    (closed form beta_n L = 1.8751, 4.6941, a pair each), every frequency in the band
    and increasing, on 1 and 2 ranks alike."""
    narrow = cantilever_band("0,10")
    wide = cantilever_band("0,1e7")
    whole = cantilever_band("0,1e30")
    assert wide.band[2] == len(wide.omega2) and not wide.slices
    assert whole.band[2] == len(whole.omega2) and not whole.slices
    assert np.allclose(whole.frequencies[:6], narrow.frequencies, rtol=1e-9)
    exact = np.repeat(np.array([1.8751, 4.6941]) ** 2 / (2 * np.pi) * np.sqrt(2.0 / 3.0), 2)
    assert np.allclose(narrow.frequencies[:4], exact, rtol=1e-3)
    assert len(wide.omega2) >= len(narrow.omega2) == 6
    assert np.allclose(wide.frequencies[:6], narrow.frequencies, rtol=1e-9)
    assert np.all(np.diff(wide.frequencies) >= 0) and wide.frequencies[-1] <= 1e7
    assert np.all(wide.modal_mass > 0)
    every = PETSc.COMM_WORLD.tompi4py().allgather(wide.frequencies[:6])
    assert all(np.allclose(every[0], f, rtol=1e-10) for f in every)


def test_fewer_verified_modes_than_asked_are_said():
    """The lowest modes without a band: the run's lines warn where fewer than asked
    converged and verified (a pair that does not verify is never reported)."""
    from petsc_rod.cli.modes import table_lines
    modes = string_modes(count=2)
    assert modes.asked == 2 and len(modes.omega2) == 2
    assert not any("warning" in line for line in table_lines(modes, 1.0))
    modes.asked = 3
    assert any(line.startswith("modes: warning: 2 of the 3 asked converged and verified")
               for line in table_lines(modes, 1.0))
