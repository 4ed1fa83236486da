"""Attachments end to end (-rod_point_loads FILE, -rod_point_load; docs/riser.md): a
table of clump weights, buoyancy modules and point forces reaches the result file (the
points' S, forces and positions), and bad input ends in one petsc_rod line, exit 2, no
file (as tests/system/test_hostile_cli.py)."""

import h5py
import numpy as np
import pytest

from helpers import describe, run_petsc_rod
from test_hostile_cli import assert_one_line_and_nothing_left

TIMEOUT = 120
CHAIN = ["-rod_length", "10", "-rod_stiffness", "1e-2,1e-2,1e-2", "-rod_start", "pin",
         "-rod_end", "pin", "-rod_end_position", "8,0,2", "-rod_load", "0,0,-100",
         "-rod_initial_shape", "catenary", "-rod_elements", "40"]


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_table_of_attachments_reaches_the_file(tmp_path, ranks):
    """A clump (300 kg), a buoyancy module (0.2 m^3) and a point force (quick form): the
    forces (rho_w V - m) g e_z at the default rho_w = 1025 kg/m^3, g = 9.80665 m/s^2,
    the positions on the line (x increasing along it, r(S_p) within the chord)."""
    table = tmp_path / "points.txt"
    table.write_text("# attachments\ns, mass, volume, name\n4.0 300 0 clump\n"
                     "7.0 0 0.2 buoy\n")
    path = tmp_path / "out.h5"
    done = run_petsc_rod(CHAIN + ["-rod_point_loads", str(table), "-rod_point_load", "9,10,0,0",
                                  "-rod_output", str(path)], ranks, TIMEOUT)
    assert done.returncode == 0, describe(done)
    with h5py.File(path, "r") as result:
        attributes = result.attrs
        g = 9.80665
        assert np.array_equal(attributes["point_load_S"], [4.0, 7.0, 9.0])
        assert np.allclose(attributes["point_load_force"],
                           [[0, 0, -300 * g], [0, 0, 1025 * 0.2 * g], [10, 0, 0]],
                           rtol=1e-15, atol=0)
        positions = attributes["point_load_position"]
        assert positions.shape == (3, 3) and np.all(np.diff(positions[:, 0]) > 0)
        S, r = result["S"][:], result["r"][:]
        for s, position in zip((4.0, 7.0, 9.0), positions):   # next to the vertex values
            k = int(np.argmin(np.abs(S - s)))
            assert np.linalg.norm(position - r[k]) <= abs(S[k] - s) + 1e-12
        assert result.attrs["point_load_names"] == "clump,buoy,point 1"
        table_back = result["parameters"].attrs["point_loads_table"]
        assert np.array_equal(table_back[:, 0], [4.0, 7.0, 9.0])


def test_an_attachment_with_a_drag_area_feels_the_current(tmp_path):
    """A small buoy (0.1 l, C_d A = 2e-3 m^2) on the unit cantilever in a 1 m/s current
    along y (the line itself of no drag, D = 0): its drag 1/2 rho_w C_d A |v| v (the
    current uniform: a dead force) in the file as point_load_drag, the buoy pushed along
    the current and lifted."""
    table = tmp_path / "points.txt"
    table.write_text("s volume cda\n0.6 1e-4 2e-3\n")
    path = tmp_path / "out.h5"
    done = run_petsc_rod(["-rod_elements", "16", "-rod_point_loads", str(table),
                          "-rod_current", "0,1,0", "-rod_drag", "1025,1.2,0",
                          "-rod_output", str(path)], 1, TIMEOUT)
    assert done.returncode == 0, describe(done)
    with h5py.File(path, "r") as result:
        assert np.allclose(result.attrs["point_load_drag"], [[0.0, 0.5 * 1025 * 2e-3, 0.0]],
                           rtol=1e-14, atol=0)
        position = result.attrs["point_load_position"][0]
        assert position[1] > 0.01 and position[2] > 0.01
        assert np.array_equal(result["parameters"].attrs["point_loads_table"][:, 4], [2e-3])


@pytest.mark.parametrize("table, args, words", [
    ("mass fz\n1 2\n", [], ["no 's' column"]),
    ("s mass colour\n0.5 1 red\n", [], ["unknown column 'colour'"]),
    ("s,mass\n0.5,heavy\n", [], ["line 2", "mass", "not a number"]),
    ("s fz\n1.5 2\n", [], ["line 2", "beyond the line"]),
    ("s fz\n0.5\n", [], ["line 2", "1 values for the 2 columns"]),
    ("s mass\n0.5 -1\n", [], ["mass must not be negative"]),
    ("s cda\n0.5 -1\n", [], ["cda must not be negative"]),
    (None, ["-rod_point_loads", "absent.txt"], ["absent.txt", "no such file"]),
    (None, ["-rod_point_load", "2,0,0,1"], ["-rod_point_load", "beyond the line"]),
    (None, ["-rod_point_load", "-0.1,0,0,1"], ["-rod_point_load", "beyond the line"]),
    (None, ["-rod_point_load", "0.5,0,1"], ["-rod_point_load", "give 4"]),
    (None, ["-rod_point_load", "0.5,x,0,1"], ["-rod_point_load"]),
], ids=["no s", "unknown column", "not a number", "beyond the end", "short row",
        "negative mass", "negative drag area", "no file", "quick beyond the end",
        "quick before the start",
        "quick short", "quick not a number"])
def test_bad_attachments_exit_2_with_one_line(tmp_path, table, args, words):
    path = tmp_path / "out.h5"
    if table is not None:
        (tmp_path / "points.txt").write_text(table)
        args = ["-rod_point_loads", str(tmp_path / "points.txt")]
    elif args[0] == "-rod_point_loads":
        args = [args[0], str(tmp_path / args[1])]
    done = run_petsc_rod(["-rod_elements", "8"] + args + ["-rod_output", str(path)], 1, TIMEOUT)
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2, words, path)
