"""The natural modes about a static state (analysis/modes.py, docs/modes.md) against
closed forms, each with its observed order of convergence in the elements: a taut
string, a tensioned pinned beam, a cantilever's bending modes, a shaft's torsional
modes, a heavy chain hanging from one end (the zeros of J0); the same modes on one rank
and on all ranks; an unstable state's modes refused. Frequencies in Hz."""

import os

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import (continuation, destroy, fitted_order, make_solver, partial_files,
                     run_cli)

pytest.importorskip("slepc4py")

L = 1.0
G = 9.80665
MESHES = (8, 16, 32)
# a cantilever of 8 elements whose modes the eigensolver's options make fail
FAILING_CANTILEVER = {"rod_length": "1", "rod_stiffness": "1,1,1", "rod_start": "clamp",
                      "rod_end": "free", "rod_elements": "8", "rod_modes": "3",
                      "rod_modes_mass": "1"}


def modes_of(scene, n_elements, count, comm=PETSc.COMM_WORLD, stability=True, **mass):
    from petsc_rod.analysis.mass import MassSettings
    from petsc_rod.analysis.modes import solve_modes
    mesh, solver = make_solver(comm, n_elements, scene, 1e2)
    solver.settings.check_stability = stability
    try:
        continuation(solver)
        return solve_modes(solver.problem, count, MassSettings(**mass))
    finally:
        destroy(mesh, solver)


def errors_and_order(scene, count, exact, **mass):
    errors = np.array([np.abs(modes_of(scene, n, count, **mass).frequencies - exact).max()
                       / exact.max() for n in MESHES])
    return errors, fitted_order(np.array(MESHES), errors)


def pinned(T, EA, EI):
    """A line pinned at both ends, stretched by T (N) at EA; its stretched length and
    mass per stretched length (m of 1 kg per metre unstretched)."""
    e = T / EA
    scene = dict(length=L, stiffness=(EI, EI, EI), start="pin", end="pin",
                 end_position=[L * (1 + e), 0.0, 0.0], axial_stiffness=EA)
    return scene, L * (1 + e), 1.0 / (1 + e)


def test_taut_string():
    T = 100.0
    scene, length, m = pinned(T, 1e6, 1e-6)
    n = np.repeat(np.arange(1, 4), 2)                # in and out of the plane
    exact = n / (2 * length) * np.sqrt(T / m)
    errors, order = errors_and_order(scene, 6, exact, mass=1.0)
    assert errors[-1] < 5e-6 and order > 3.5


def test_tensioned_pinned_beam():
    T, EI = 100.0, 1.0
    scene, length, m = pinned(T, 1e8, EI)
    n = np.repeat(np.arange(1, 4), 2)
    exact = (n / (2 * length) * np.sqrt(T / m)
             * np.sqrt(1 + n**2 * np.pi**2 * EI / (T * length**2)))
    errors, order = errors_and_order(scene, 6, exact, mass=1.0)
    assert errors[-1] < 2e-5 and order > 3.5


def test_cantilever_bending_modes():
    EI, m = 2.0, 3.0
    beta = np.array([1.8751040687, 4.6940911330, 7.8547574382])
    exact = np.repeat(beta**2 / (2 * np.pi * L**2) * np.sqrt(EI / m), 2)
    scene = dict(length=L, stiffness=(EI, EI, EI), start="clamp", end="free")
    errors, order = errors_and_order(scene, 6, exact, mass=m)
    assert errors[-1] < 1e-5 and order > 3.5


def test_torsional_modes_of_a_shaft():
    GJ, J = 1.0, 1.0
    exact = (2 * np.arange(1, 4) - 1) * np.pi / (2 * L) * np.sqrt(GJ / J) / (2 * np.pi)
    scene = dict(length=L, stiffness=(1e4, 1e4, GJ), start="clamp", end="free")
    errors, order = errors_and_order(scene, 3, exact, mass=1.0, inertia=J)
    assert errors[-1] < 5e-6 and order > 3.5
    modes = modes_of(scene, 8, 3, mass=1.0, inertia=J)
    assert modes.labels == ["torsional"] * 3
    assert np.all(modes.shares[:, 3] > 0.999)


def test_heavy_chain_hanging_from_one_end():
    """Gravity along +x (the straight state is the hanging one); EI small: the zeros of
    J0, omega_n = (j_0n / 2) sqrt(g / L), to within the bending stiffness's effect."""
    from scipy.special import jn_zeros
    scene = dict(length=L, stiffness=(1e-4,) * 3, start="pin", end="free",
                 load_values=[[G, 0.0, 0.0]])          # 1 kg/m
    exact = np.repeat(jn_zeros(0, 2) / 2 * np.sqrt(G / L) / (2 * np.pi), 2)
    first = [modes_of(scene, n, 4).frequencies for n in MESHES]
    errors = np.array([np.abs(f - exact).max() / exact.max() for f in first])
    assert errors[-1] < 2e-3
    assert abs(first[-1][0] - exact[0]) < 1e-4 * exact[0]


def test_same_modes_on_one_rank_and_all_ranks():
    scene = pinned(100.0, 1e8, 1.0)[0]
    one = modes_of(scene, 16, 6, comm=PETSc.COMM_SELF, mass=1.0)
    every = modes_of(scene, 16, 6, comm=PETSc.COMM_WORLD, mass=1.0)
    assert np.allclose(one.frequencies, every.frequencies, rtol=1e-9)
    assert np.allclose(one.modal_mass, every.modal_mass, rtol=1e-6)


def test_unstable_state_refused():
    """A column standing on a pin under its weight (gravity along -x, the straight state
    an equilibrium with the stability test off): its modes are refused."""
    from petsc_rod.analysis.modes import ModesRefused
    scene = dict(length=L, stiffness=(1e-2,) * 3, start="pin", end="free",
                 load_values=[[-G, 0.0, 0.0]])
    with pytest.raises(ModesRefused) as refused:
        modes_of(scene, 8, 3, stability=False)
    assert refused.value.negative > 0


def test_failed_set_up_destroys_what_was_made(monkeypatch):
    """The modes' set-up failing after the operators and the factor were made (here the
    spectral transformation's KSP): both are destroyed, none left to leak."""
    from petsc_rod.analysis import modes
    destroyed = []
    operators_destroy = modes.ModalOperators.destroy

    def destroy_operators(self):
        destroyed.append("operators")
        operators_destroy(self)

    def counted_factor(*args):
        factor = made_factor(*args)
        factor_destroy = factor.destroy

        def destroy_factor():
            destroyed.append("factor")
            factor_destroy()
        factor.destroy = destroy_factor
        return factor

    def failing_ksp(operator, factor):
        raise PETSc.Error(73)
    made_factor = modes.direct_factor
    monkeypatch.setattr(modes.ModalOperators, "destroy", destroy_operators)
    monkeypatch.setattr(modes, "direct_factor", counted_factor)
    monkeypatch.setattr(modes, "FactorKSP", failing_ksp)
    with pytest.raises(PETSc.Error):
        modes_of(pinned(100.0, 1e6, 1e-6)[0], 8, 2, mass=1.0)
    assert destroyed == ["factor", "operators"]


# PETSc errors inside the modes' eigensolver that the options' check before the run
# (analysis/modes.check_options: set from the options, not set up) lets through
EIGENSOLVER_FAILURES = [
    # EPSSetUp: a Cayley transform about the target 0 without an antishift
    ({"rod_modes_st_type": "cayley"},
     "Values of shift and antishift cannot be zero simultaneously"),
    # EPSSolve: the spectral transformation's KSP, Richardson steps 3 times the exact
    # one, doubles its residual in the first application (the divergence tolerance
    # 1.5), which SLEPc's ST raises as an error; the EPS cannot be destroyed after it
    ({"rod_modes_st_ksp_type": "richardson", "rod_modes_st_ksp_richardson_scale": "3",
      "rod_modes_st_ksp_divtol": "1.5"},
     "KSPSolve has not converged, reason DIVERGED_DTOL")]


@pytest.mark.parametrize("split", ["whole", "split"])
@pytest.mark.parametrize("options, says", EIGENSOLVER_FAILURES)
def test_an_eigensolver_failure_ends_the_run_in_one_line(options, says, split, shared_tmp,
                                                        capsys, monkeypatch):
    """A PETSc error inside the modes' eigensolver, after the equilibrium (its set-up or
    its solve): exit 4 with one line naming the eigensolver and PETSc's message, no
    result file, and every FactorPC released once the run has returned. A python PC
    left to PETSc's garbage collection in PetscFinalize (the EPS's ST that the solve's
    traceback held, or a KSP whose destroy was skipped when the EPS's failed) is
    destroyed there after the interpreter has ended, a segmentation fault, exit 59
    (tests/system/test_modes_cli.py: the command line's exit code on 1 and 2 ranks). -rod_ranks_split: the line on rank 0 (COMM_SELF) or
    split over the ranks."""
    import gc
    import weakref
    from petsc_rod.analysis import modes
    contexts = []
    made = modes.FactorPC.__init__

    def counted(self, factor):
        made(self, factor)
        contexts.append(weakref.ref(self))
    monkeypatch.setattr(modes.FactorPC, "__init__", counted)
    output = os.path.join(shared_tmp, "failed_modes.h5")
    assert run_cli({**FAILING_CANTILEVER, "rod_output": output, "rod_ranks_split": split,
                    **options}) == 4
    out = capsys.readouterr().out
    # the solve's frames, held by cycles of its traceback, freed: no PC holds a context
    gc.collect()
    rank = PETSc.COMM_WORLD.getRank()
    assert len(contexts) == (1 if rank == 0 or split == "split" else 0)
    assert [ref() for ref in contexts] == [None] * len(contexts)
    assert not os.path.exists(output) and not partial_files(output)
    if rank == 0:
        lines = [line for line in out.splitlines() if "error" in line]
        assert lines == [f"petsc_rod: error: the modes' eigensolver (SLEPc) failed: {says}; "
                         "check the -rod_modes_eps_* and -rod_modes_st_* options"], out
        assert "step 1/1: load factor 1, converged" in out


@pytest.mark.parametrize("options, message", [
    ({"rod_modes": "3"}, "need its mass per length: give -rod_modes_mass"),
    ({"rod_modes_table": "modes.csv"}, "-rod_modes_table needs -rod_modes N"),
    ({"rod_modes": "3", "rod_modes_mass": "1", "rod_modes_table": "missing/modes.csv"},
     "does not exist")])
def test_modes_inputs_refused_before_the_run(options, message, capsys):
    """An unloaded uniform line without -rod_modes_mass, a table without -rod_modes and
    a table that cannot be written: exit 2 with one line, before any step."""
    assert run_cli({"rod_length": "1", **options}) == 2
    out = capsys.readouterr().out
    if PETSc.COMM_WORLD.getRank() == 0:
        assert message in out and "step 1" not in out


def test_modes_without_slepc4py_refused(shared_tmp, monkeypatch, capsys):
    """-rod_modes where slepc4py cannot be found: exit 2 with one line saying to
    install it, before any step and with no result file."""
    import importlib.util
    find_spec = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *rest: None if name == "slepc4py"
                        else find_spec(name, *rest))
    output = os.path.join(shared_tmp, "no_slepc.h5")
    assert run_cli({"rod_length": "1", "rod_modes": "3", "rod_modes_mass": "1",
                    "rod_output": output}) == 2
    out = capsys.readouterr().out
    assert not os.path.exists(output)
    if PETSc.COMM_WORLD.getRank() == 0:
        lines = [line for line in out.splitlines() if "error" in line]
        assert len(lines) == 1 and "python3-slepc4py" in lines[0] and "step 1" not in out


@pytest.mark.parametrize("option", ["rod_modes_eps_type", "rod_modes_st_type"])
def test_bad_modes_solver_option_refused(option, shared_tmp, capsys):
    """An unknown -rod_modes_eps_type or -rod_modes_st_type: exit 2 with one line naming
    the modes' options, before any step and with no result file."""
    output = os.path.join(shared_tmp, "bad_eps.h5")
    assert run_cli({"rod_length": "1", "rod_modes": "3", "rod_modes_mass": "1",
                    option: "nosuch", "rod_output": output}) == 2
    out = capsys.readouterr().out
    assert not os.path.exists(output)
    if PETSc.COMM_WORLD.getRank() == 0:
        lines = [line for line in out.splitlines() if "error" in line]
        assert len(lines) == 1 and "-rod_modes_eps_*" in lines[0] and "step 1" not in out


def test_more_modes_than_the_line_has_refused_before_the_solve(shared_tmp, capsys):
    """-rod_modes 1000 on an inextensible cantilever of 8 elements without rotary
    inertia: its discretisation has 32 modes (each element's vertex and midpoint move
    in the 2 bending directions, as -rod_modes_range 0,1e30's inertia counts them; 256
    at 64 elements): exit 2 with one line saying so, before any step and with no result
    file (it reported the 32 and warned that a larger -rod_modes_eps_ncv finds the
    others)."""
    output = os.path.join(shared_tmp, "too_many_modes.h5")
    options = {"rod_length": "1", "rod_stiffness": "1,1,1", "rod_start": "clamp",
               "rod_end": "free", "rod_elements": "8", "rod_modes_mass": "1",
               "rod_output": output}
    assert run_cli({**options, "rod_modes": "1000"}) == 2
    out = capsys.readouterr().out
    assert not os.path.exists(output)
    if PETSc.COMM_WORLD.getRank() == 0:
        lines = [line for line in out.splitlines() if "error" in line]
        assert len(lines) == 1 and "step 1" not in out
        assert ("-rod_modes 1000: the line's discretisation has 32 modes (8 elements); "
                "ask for at most 32") in lines[0]
    assert run_cli({**options, "rod_modes": "33"}) == 2
    assert "has 32 modes" in capsys.readouterr().out or PETSc.COMM_WORLD.getRank() != 0


def refused_before_any_step(options, says, shared_tmp, capsys):
    """Run the CLI on a 1 m line with ``options`` {name: text}: exit 2, one line that
    starts with ``says``, no step and no result file."""
    output = os.path.join(shared_tmp, "refused_modes.h5")
    assert run_cli({"rod_length": "1", "rod_modes_mass": "1", **options,
                    "rod_output": output}) == 2
    out = capsys.readouterr().out
    assert not os.path.exists(output)
    if PETSc.COMM_WORLD.getRank() == 0:
        lines = [line for line in out.splitlines() if "error" in line]
        assert len(lines) == 1 and "step 1" not in out, out
        assert lines[0].startswith(says), lines[0]


@pytest.mark.parametrize("ncv", ["2", "3"])
def test_a_krylov_subspace_smaller_than_the_modes_asked_refused(ncv, shared_tmp, capsys):
    """-rod_modes 3 with -rod_modes_eps_ncv 2 or 3 (SLEPc's Krylov-Schur needs ncv >=
    nev + 1): exit 2 with one line naming -rod_modes_eps_ncv and the least it takes,
    before any step and with no result file (it failed with exit 4 after the
    equilibrium, "PETSc failed during the solve")."""
    refused_before_any_step({"rod_modes": "3", "rod_modes_eps_ncv": ncv},
                            f"petsc_rod: error: -rod_modes_eps_ncv {ncv}: -rod_modes 3 "
                            "needs a Krylov subspace of at least 4", shared_tmp, capsys)


@pytest.mark.parametrize("nev, says", [
    ("50", "petsc_rod: error: the default -rod_modes_eps_ncv 20 (-rod_modes 5 + max(15, "
           "5 / 2)): -rod_modes_eps_nev 50 needs a Krylov subspace of at least 51"),
    ("abc", "petsc_rod: error: SLEPc refused the modes' options: Input string abc")])
def test_an_eigensolver_count_beyond_the_default_subspace_refused(nev, says, shared_tmp,
                                                                   capsys):
    """-rod_modes 5 with -rod_modes_eps_nev 50 and no -rod_modes_eps_ncv: the default
    subspace, 5 + max(15, 5 / 2) = 20 vectors, is below nev + 1; refused in one line
    before any step (it failed inside the modes' solve after the equilibrium and ended
    in a segmentation fault), and a value that is no whole number too (the options'
    check's line)."""
    refused_before_any_step({"rod_modes": "5", "rod_modes_eps_nev": nev}, says,
                            shared_tmp, capsys)


def test_cli_modes_table(shared_tmp, capsys):
    """-rod_modes 4 -rod_modes_table on a cantilever: the table's frequencies are the
    closed form's (16 elements), its classes in plane and out of plane, the shapes'
    file has one row per vertex and mode with a largest offset of 1, the result file
    has them in its group ``modes``, and the picture (figures/modes.py) a panel per
    mode."""
    from petsc_rod.cli import main
    path = os.path.join(shared_tmp, "modes.csv")
    EI, m = 2.0, 3.0
    options = {"rod_length": "1", "rod_stiffness": f"{EI},{EI},{EI}", "rod_start": "clamp",
               "rod_end": "free", "rod_elements": "16", "rod_modes": "4",
               "rod_modes_mass": str(m), "rod_modes_table": path,
               "rod_output": os.path.join(shared_tmp, "modes.h5")}
    assert run_cli(options) == 0
    assert "modes: 4 lowest about the static state" in capsys.readouterr().out \
        or PETSc.COMM_WORLD.getRank() != 0
    table = np.genfromtxt(path, delimiter=",", names=True, dtype=None, encoding=None)
    beta = np.array([1.8751040687, 4.6940911330])
    exact = np.repeat(beta**2 / (2 * np.pi) * np.sqrt(EI / m), 2)
    assert np.allclose(table["frequency_Hz"], exact, rtol=1e-4)
    assert np.allclose(table["period_s"], 1 / exact, rtol=1e-4)
    assert sorted(table["class"][:2]) == ["in-plane", "out-of-plane"]
    shapes = np.loadtxt(path.replace(".csv", "_shapes.csv"), delimiter=",", skiprows=1)
    assert shapes.shape == (4 * 17, 11)
    # the first mode's curvature at the vertices: the cantilever's phi''(S) / phi(L),
    # phi = cosh bS - cos bS - s (sinh bS - sin bS), s = (cosh bL + cos bL) /
    # (sinh bL + sin bL); the midpoints' values interpolated (the ends': their element's)
    first = shapes[shapes[:, 0] == 1]
    b = beta[0]
    sigma = (np.cosh(b) + np.cos(b)) / (np.sinh(b) + np.sin(b))
    phi = lambda x, k: b**k * (np.cosh(b * x) + (-1)**(k // 2 + 1) * np.cos(b * x)
                               - sigma * (np.sinh(b * x) + (-1)**(k // 2 + 1) * np.sin(b * x)))
    exact_curvature = np.abs(phi(first[:, 1], 2) / phi(1.0, 0))
    bending = np.linalg.norm(first[:, 8:10], axis=1)
    assert np.abs(bending - exact_curvature)[1:-1].max() < 3e-3 * exact_curvature.max()
    assert np.abs(bending - exact_curvature).max() < 0.1 * exact_curvature.max()
    assert np.abs(first[:, 10]).max() < 1e-6 * exact_curvature.max()      # no twist
    for k in range(1, 5):
        offsets = shapes[shapes[:, 0] == k][:, 2:5]
        assert abs(np.linalg.norm(offsets, axis=1).max() - 1) < 1e-9     # 10 digits
    import h5py
    with h5py.File(options["rod_output"], "r") as f:       # the result file's group
        group = f["modes"]
        assert np.allclose(group["frequency"][:], table["frequency_Hz"], rtol=1e-9)
        assert group["offset"].shape == (17, 4, 3)
        assert np.allclose(np.moveaxis(group["offset"][:], 0, 1).reshape(-1, 3),
                           shapes[:, 2:5], atol=1e-9)
        assert group.attrs["classes"].split(",") == list(table["class"])
    from petsc_rod.figures.modes import modes_figure
    figure = modes_figure(path)                      # the picture: a panel a mode
    panels = [axes for axes in figure.axes if axes.get_visible()]
    assert len(panels) == 4 and panels[2].get_title().startswith("mode 3: 2.86")


def neutral_line(surface=None):
    """(scene, m, e, od, EI) of a neutrally buoyant line type pinned taut (T = 100 N)."""
    from petsc_rod.model.line_type import LineType
    rho, od, T, EA, EI, GJ = 1025.0, 0.2, 100.0, 1e6, 1e-2, 10.0
    m = rho * np.pi * od**2 / 4
    section = LineType("neutral", od, m, EI, GJ, ea=EA).section(0.0, L, rho, G)
    e = T / EA
    scene = dict(length=L, stiffness=(EI, EI, GJ), start="pin", end="pin",
                 end_position=[L * (1 + e), 0.0, 0.0], sections=(section,),
                 axial_stiffness=EA, water_density=rho, load_values=[[0.0, 0.0, 0.0]],
                 sea_surface=surface)
    return scene, m, e, od, EI


@pytest.mark.parametrize("added_mass", [1.0, 0.0])
def test_added_mass_of_a_line_type(added_mass):
    """A neutrally buoyant line type (mass = rho_w pi od^2 / 4: no weight) pinned taut:
    its transverse modes carry the added mass C_a rho_w pi od^2 / 4 as well,
    f_n = n/(2L') sqrt(T / (m' (1 + C_a))) sqrt(1 + n^2 pi^2 EI / (T L'^2)), the
    stretched line's L' and m', lowered by the sections' rotary inertia I_b = m od^2 / 16
    (Rayleigh's: omega^2 (m (1 + C_a) + I_b k^2) = T k^2 + EI k^4, k = n pi / L); their
    polar inertia 2 I_b makes the free roll between the pins a rigid mode (the twist's
    modes above 3.9 Hz)."""
    scene, m, e, od, EI = neutral_line()
    T = 100.0
    modes = modes_of(scene, 16, 5, added_mass=added_mass)
    n = np.repeat([1, 2], 2)
    exact = (n / (2 * L * (1 + e)) * np.sqrt(T * (1 + e) / (m * (1 + added_mass)))
             * np.sqrt(1 + n**2 * np.pi**2 * EI / (T * (L * (1 + e))**2))
             / np.sqrt(1 + (n * np.pi / L)**2 * (od**2 / 16) / (1 + added_mass)))
    assert modes.labels[0] == "rigid" and modes.shares[0, 3] > 0.999
    assert np.allclose(modes.frequencies[1:], exact, rtol=2e-4)


def string_of_two_halves(mu, tension, half, count):
    """The lowest ``count`` omega (rad/s) of a string pinned at both ends, of two halves of
    length ``half`` (m) and masses per length mu (2,) (kg/m): on each half
    y = sin(k_i x) from its pin, k_i = omega sqrt(mu_i / T), and the slope continuous at
    the junction: k_1 cot(k_1 a) + k_2 cot(k_2 a) = 0 (the transfer matrix's), found by
    bisection between the sign changes of sin(k_1 a) sin(k_2 a) times it. ``tension``
    a function of omega: T - I_b omega^2 with the sections' rotary inertia I_b (kg m),
    equal on both halves."""
    def residual(omega):
        k = omega * np.sqrt(mu / tension(omega))
        return (k[0] * np.cos(k[0] * half) * np.sin(k[1] * half)
                + k[1] * np.cos(k[1] * half) * np.sin(k[0] * half))
    grid = np.linspace(1e-3, 2000.0, 200001)
    with np.errstate(invalid="ignore"):     # no string beyond T - I_b omega^2 = 0
        values = np.array([residual(w) for w in grid])
    changes = (np.sign(values[:-1]) != np.sign(values[1:])) & np.isfinite(values[1:])
    roots = []
    for i in np.flatnonzero(changes)[:count]:
        lo, hi = grid[i], grid[i + 1]
        for _ in range(60):
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if np.sign(residual(mid)) == np.sign(residual(lo)) else (lo, mid)
        roots.append((lo + hi) / 2)
    return np.array(roots)


def test_added_mass_per_line_type():
    """A neutrally buoyant taut line (T = 100 N) of two halves of one diameter and mass
    whose line types give C_a 0 and 3 (the column ``ca``): its transverse modes are those
    of a string of masses m and 4 m per length on its halves (string_of_two_halves, of
    the stretched line: m' = m / (1 + e), its tension lowered by the rotary inertia
    I_b' omega^2, I_b = m od^2 / 16; EI 10^-6): within 6.6e-5 and 3.0e-4 from 16 elements
    on (a plateau in n^2 that a uniform line of these line types shows as well, 5e-5 and
    2e-4 against its closed form). The vertex at the junction takes each side's mass
    with that side's weight (mass.weighted_inertia); -rod_modes_added_mass (5 here) is
    the C_a of a line type without ``ca`` alone."""
    from petsc_rod.model.line_type import LineType
    rho, od, T, EA, EI, GJ = 1025.0, 0.2, 100.0, 1e6, 1e-6, 10.0
    m = rho * np.pi * od**2 / 4
    halves = [LineType(f"half{k}", od, m, EI, GJ, ea=EA, ca=ca).section(
        0.5 * k, 0.5 * (k + 1), rho, G) for k, ca in enumerate((0.0, 3.0))]
    e = T / EA
    scene = dict(length=L, stiffness=(EI, EI, GJ), start="pin", end="pin",
                 end_position=[L * (1 + e), 0.0, 0.0], sections=tuple(halves),
                 axial_stiffness=EA, water_density=rho, load_values=[[0.0, 0.0, 0.0]])
    modes = modes_of(scene, 16, 5, added_mass=5.0)
    inertia = m * od**2 / 16 / (1 + e)
    omega = string_of_two_halves(np.array([m, 4 * m]) / (1 + e),
                                 lambda w: T - inertia * w**2, 0.5 * (1 + e), 2)
    exact = np.repeat(omega / (2 * np.pi), 2)
    assert modes.labels[0] == "rigid"
    assert np.allclose(modes.frequencies[1:], exact, rtol=5e-4)
    # the uniform line's closed form is far from it: the halves' masses matter
    uniform = np.sqrt(T * (1 + e) / (2.5 * m)) / (2 * (1 + e))
    assert abs(modes.frequencies[1] / uniform - 1) > 0.02


def test_no_added_mass_above_the_sea():
    """The same line with the sea surface below it (in air: it sags under its weight):
    the nodes' translation mass is w_n m I, no added mass."""
    from petsc_rod.analysis.mass import MassSettings
    from petsc_rod.analysis.modes import ModalOperators
    scene, m, *_ = neutral_line(surface=-1.0)
    mesh, solver = make_solver(PETSc.COMM_WORLD, 8, scene, 1e2)
    try:
        continuation(solver)
        operators = ModalOperators(solver.problem, MassSettings())
        expected = mesh.node_weights()[:, None, None] * m * np.eye(3)
        assert np.allclose(operators.translation, expected, rtol=1e-12, atol=0)
        assert solver.problem.state.node_positions()[:, 2].min() > -1.0
        operators.destroy()
    finally:
        destroy(mesh, solver)


@pytest.mark.parametrize("lambda2", [10.0, 60.0])
def test_suspended_cable_against_irvine(lambda2):
    """A shallow elastic cable between pins at one height (span 100 m, sag 2 m, 10 N/m),
    EA chosen for Irvine's parameter lambda^2 = (w l / H)^2 l / (H L_e / EA) below and
    above the crossover 4 pi^2: in omega_bar = omega l / sqrt(H / m), the first
    out-of-plane mode is pi, the first antisymmetric in-plane 2 pi, and the first
    symmetric in-plane the root of tan(x) = x - 4 x^3 / lambda^2, omega_bar = 2 x (Irvine,
    Cable Structures, 1981, §4.2), below 2 pi under the crossover and above it over."""
    from scipy.optimize import brentq
    from petsc_rod.analysis.mass import MassSettings
    from petsc_rod.analysis.modes import solve_modes
    w, span = 10.0, 100.0
    H0 = w * span**2 / 16                              # sag span / 50
    EA = lambda2 * H0 * 1.001 / (w * span / H0)**2
    length = span * (1 + 8 / 3 / 50**2) - H0 / EA * span
    scene = dict(length=length, stiffness=(1e-2,) * 3, start="pin", end="pin",
                 end_position=[span, 0.0, 0.0], axial_stiffness=EA,
                 load_values=[[0.0, 0.0, -w]])
    mesh, solver = make_solver(PETSc.COMM_WORLD, 64, scene, 1e3)
    try:
        continuation(solver, steps=2)
        problem = solver.problem
        H = abs(problem.end_reaction()[0])
        sag = -problem.mesh.global_min(float(problem.state.node_positions()[:, 2].min()))
        modes = solve_modes(problem, 6, MassSettings())
    finally:
        destroy(mesh, solver)
    actual = (w * span / H)**2 * span / (H * span * (1 + 8 * (sag / span)**2) / EA)
    bar = 2 * np.pi * modes.frequencies * span / np.sqrt(H * G / w)
    x = brentq(lambda x: np.tan(x) - x + 4 * x**3 / actual,
               np.pi / 2 + 1e-9, 3 * np.pi / 2 - 1e-9)
    labels = np.array(modes.labels)
    plane, out = bar[labels == "in-plane"], bar[labels == "out-of-plane"]
    assert abs(out[0] - np.pi) < 2e-3 * np.pi
    symmetric = plane[np.argmin(np.abs(plane - 2 * x))]
    antisymmetric = plane[np.argmin(np.abs(plane - 2 * np.pi))]
    assert abs(symmetric - 2 * x) < 1e-3 * 2 * x
    assert abs(antisymmetric - 2 * np.pi) < 2e-3 * 2 * np.pi
    assert (symmetric < antisymmetric) == (actual < 4 * np.pi**2)
