"""Every scene of options/ runs as a user runs it (``python -m petsc_rod -options_file
options/<scene>.opts``, from the repository's root, on one rank) and converges, with a
result file that says so and holds finite numbers (a system's scene, -rod_system, in
each of its lines' groups). The scenes' own numbers are checked
where they are named (docs/riser.md, tests/system/test_riser_cli.py); this keeps every
scene runnable as the code changes."""

import glob
import os

import h5py
import numpy as np
import pytest

from helpers import REPO_ROOT, run_petsc_rod

pytestmark = [pytest.mark.serial, pytest.mark.slow]

SCENES = sorted(os.path.basename(path)[:-5]
                for path in glob.glob(os.path.join(REPO_ROOT, "options", "*.opts")))


def test_there_are_scenes():
    assert len(SCENES) >= 13 and "paper" in SCENES


@pytest.mark.parametrize("scene", SCENES)
def test_every_scene_converges(scene, tmp_path):
    path = tmp_path / f"{scene}.h5"
    done = run_petsc_rod(["-options_file", f"options/{scene}.opts", "-rod_output", str(path)],
                         1, 600)
    text = done.stdout + done.stderr
    assert done.returncode == 0, text
    assert "petsc_rod: converged" in text and "warning" not in text, text
    with h5py.File(path, "r") as f:
        assert int(f.attrs["converged"]) == 1
        # a system's scene (-rod_system): a group per line, each a line's result
        groups = [f[f"lines/{name}"] for name in f["lines"]] if "system" in f else [f]
        assert groups
        for group in groups:
            for name in ("r", "n", "m", "u"):
                assert np.all(np.isfinite(group[name][:])), name


def test_the_mooring_line_balances_its_weight_clumps_and_seabed(tmp_path):
    """options/mooring_chain.opts: the fairlead's and the anchor's forces balance the
    chain's submerged weight, the three clumps and the seabed's reaction (integrated
    by the trapezoidal rule on the 1 m elements: 1e-4)."""
    path = tmp_path / "mooring.h5"
    done = run_petsc_rod(["-options_file", "options/mooring_chain.opts", "-rod_output",
                          str(path)], 1, 600)
    assert done.returncode == 0, done.stdout + done.stderr
    with h5py.File(path, "r") as f:
        n, S, reaction = f["n"][:], f["S"][:], f["seabed_reaction"][:]
        forces = f.attrs["point_load_force"][:]
    w = (286.6 - 1025 * np.pi * 0.2156**2 / 4) * 9.80665
    np.testing.assert_allclose(forces[:, 2], -(10000 - 1025 * 1.274) * 9.80665, rtol=1e-12)
    vertical = w * 850.0 - forces[:, 2].sum() - np.trapz(reaction, S)
    assert abs((n[-1, 2] - n[0, 2]) - vertical) < 1e-4 * abs(n[-1, 2])
    assert abs(n[-1, 0] - n[0, 0]) < 1e-9 * abs(n[0, 0])       # no horizontal load


def test_the_steel_riser_is_near_its_elastic_catenary(tmp_path):
    """options/steel_catenary_riser.opts against the elastic catenary with touchdown of
    its data (validation/elastic_catenary.py, no bending stiffness): the top tension to
    2.4e-5 (measured), the shape to 2.2 cm (measured) 20 m away from the touchdown and
    the ends: the pipe's EI = 2.7e7 N m^2 (a bending length of 6 m) is all that differs."""
    from petsc_rod.validation.elastic_catenary import elastic_catenary
    path = tmp_path / "scr.h5"
    done = run_petsc_rod(["-options_file", "options/steel_catenary_riser.opts",
                          "-rod_output", str(path)], 1, 600)
    assert done.returncode == 0, done.stdout + done.stderr
    with h5py.File(path, "r") as f:
        S, r, top = f["S"][:], f["r"][:], float(f.attrs["top_tension"])
    weight = (162.07 - 1025 * np.pi * 0.2731**2 / 4) * 9.80665
    line = elastic_catenary(2400.0, weight, 3.3826e9, 1600.0, 1500.0)
    x, z, tension = line.at(S)
    away = (np.abs(S - line.grounded) > 20.0) & (S > 20.0) & (S < 2380.0)
    assert abs(top / tension[-1] - 1) < 5e-5
    assert np.abs(r[away, 0] - x[away]).max() < 0.03 and np.abs(r[away, 2] - z[away]).max() < 0.03


def test_the_steel_riser_s_wall_tension_against_a_hand_calculation(tmp_path):
    """T_w = T_e + p_i A_i - p_e A_e (quantities/pressures.py) on the steel riser with oil of
    800 kg/m^3 at 10 MPa at the hang-off, at its two ends, by hand: at the anchor
    (z = 0, 1500 m below the surface and the top) p_e = 1025 g 1500 = 15.08 MPa,
    p_i = 10 MPa + 800 g 1500 = 21.77 MPa; at the top p_e = 0, p_i = 10 MPa."""
    path = tmp_path / "scr.h5"
    done = run_petsc_rod(["-options_file", "options/steel_catenary_riser.opts",
                          "-rod_contents_density", "800", "-rod_internal_pressure", "1e7",
                          "-rod_output", str(path)], 1, 600)
    assert done.returncode == 0, done.stdout + done.stderr
    with h5py.File(path, "r") as f:
        effective, wall = f["effective_tension"][:], f["wall_tension"][:]
        external, internal = f["external_pressure"][:], f["internal_pressure"][:]
        assert f["wall_tension"].attrs["units"] == "N"
    g, outer, inner = 9.80665, 0.2731**2 * np.pi / 4, 0.2319**2 * np.pi / 4
    assert external[0] == pytest.approx(1025 * g * 1500, rel=1e-12)
    assert internal[0] == pytest.approx(1e7 + 800 * g * 1500, rel=1e-12)
    assert external[-1] < 1e-6 and internal[-1] == pytest.approx(1e7, rel=1e-12)
    by_hand = [effective[0] + (1e7 + 800 * g * 1500) * inner - 1025 * g * 1500 * outer,
               effective[-1] + 1e7 * inner]
    np.testing.assert_allclose([wall[0], wall[-1]], by_hand, rtol=1e-12)
    assert 1.15 < wall[-1] / effective[-1] < 1.25          # 2.67 against 2.25 MN


def test_a_buoyancy_jacket_does_not_change_the_wall_tension(tmp_path):
    """Review of issue 24: with one od for weight and wall, the wall tension jumped by
    690 kN at the buoyancy modules' jacket (od 0.40 m) while the effective tension is
    continuous. With the umbilical's wall (stress_od 0.15 m) under the jacket,
    T_w - T_e = -p_e A_w changes by the hydrostatic head of one element only: at most
    rho g dz pi 0.15^2 / 4 = 178 N per metre of height."""
    path = tmp_path / "lw.h5"
    done = run_petsc_rod(["-options_file", "options/lazy_wave_types.opts", "-rod_output",
                          str(path)], 1, 600)
    assert done.returncode == 0, done.stdout + done.stderr
    with h5py.File(path, "r") as f:
        difference = f["wall_tension"][:] - f["effective_tension"][:]
        z = f["r"][:, 2]
    step = np.abs(np.diff(difference))
    assert np.all(step <= 1025 * 9.80665 * np.pi * 0.15**2 / 4 * np.abs(np.diff(z)) + 1e-6)
