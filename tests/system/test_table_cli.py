"""-rod_table (io/line_table.py), the results along the line and the pipe's stresses
(quantities/stresses.py) from the command line: the CSV's header and rows, the regions'
table, no table after a failed run, a bad path refused, and the steel riser's von Mises
stress and utilisation against a hand calculation."""

import csv
import os

import h5py
import numpy as np
import pytest

from helpers import partial_files, run_petsc_rod

# options/line_types/steel_riser.txt with an API 5L X65 yield stress, 448 MPa.
STEEL_X65 = """name   od      id      mass    ei         gj         ea         cd    smys
scr10  0.2731  0.2319  162.07  2.7135e7   2.0873e7   3.3826e9   1.0   448e6
"""
SCR = ["-options_file", "options/steel_catenary_riser.opts", "-rod_contents_density",
       "800", "-rod_internal_pressure", "1e7"]


def read_csv(path):
    with open(path, newline="") as handle:
        rows = list(csv.reader(handle))
    return rows[0], np.array(rows[1:], dtype=float)


@pytest.fixture(scope="module")
def riser(tmp_path_factory):
    """The steel riser with oil at 10 MPa and an X65 yield stress: (the run, its result
    file, its table, the folder)."""
    folder = tmp_path_factory.mktemp("table")
    types = folder / "x65.txt"
    types.write_text(STEEL_X65)
    output, table = folder / "scr.h5", folder / "scr.csv"
    done = run_petsc_rod(SCR + ["-rod_line_types", str(types), "-rod_output", str(output),
                                "-rod_table", str(table)], 1, 600)
    assert done.returncode == 0, done.stdout + done.stderr
    return done, output, table, folder


def test_the_table_has_a_row_per_vertex_and_units_in_its_header(riser):
    """2401 rows (2400 elements), a header naming each column with its unit, the same
    numbers as the result file's datasets; the regions' table beside it, and the
    regions' summary at the end of the run."""
    done, output, table, folder = riser
    header, values = read_csv(table)
    assert values.shape[0] == 2401
    assert header[:6] == ["S (m)", "x (m)", "y (m)", "z (m)", "u1 (rad/m)", "u2 (rad/m)"]
    for name in ("curvature (1/m)", "bend_radius (m)", "bending_moment (N m)",
                 "torque (N m)", "shear (N)", "effective_tension (N)", "wall_tension (N)",
                 "declination (deg)", "seabed_reaction (N/m)", "von_mises (Pa)",
                 "utilisation (1)"):
        assert name in header, name
    column = {name.split(" (")[0]: values[:, i] for i, name in enumerate(header)}
    with h5py.File(output, "r") as f:
        np.testing.assert_allclose(column["S"], f["S"][:], rtol=1e-11)
        np.testing.assert_allclose(column["z"], f["r"][:, 2], rtol=1e-11, atol=1e-9)
        for key in ("effective_tension", "wall_tension", "von_mises", "bending_moment"):
            np.testing.assert_allclose(column[key], f[key][:], rtol=1e-11, err_msg=key)
            assert f[key].attrs["units"] == header[[h.split(" (")[0] for h in
                                                    header].index(key)].split("(")[1][:-1]
    with open(folder / "scr_regions.csv", newline="") as handle:
        rows = list(csv.reader(handle))
    assert rows[0][:4] == ["region", "S_from (m)", "S_to (m)", "max_effective_tension (N)"]
    assert [row[0] for row in rows[1:]] == ["hang_off", "sag_bend", "touchdown_zone",
                                            "grounded"]
    with h5py.File(output, "r") as f:
        np.testing.assert_allclose(np.array([row[1:3] for row in rows[1:]], dtype=float),
                                   f.attrs["region_bounds"], rtol=1e-11)
    assert "sag_bend" in done.stdout and f"table {table}" in done.stdout
    assert not partial_files(table)


def test_the_ends_table_and_final_lines_give_the_end_forces_and_touchdown(riser):
    """scr_ends.csv beside the table: the fairlead's and anchor's forces, the uplift
    flag and the touchdown, one row a number with its unit, equal (12 digits) to the
    result file's attributes; the final lines say the fairlead's H and V in kN. Before,
    no such file and no such line."""
    done, output, table, folder = riser
    with open(folder / "scr_ends.csv", newline="") as handle:
        rows = list(csv.reader(handle))
    assert rows[0] == ["quantity", "value", "unit"]
    read = {name: (float(value), unit) for name, value, unit in rows[1:]}
    assert {"fairlead_tension", "fairlead_horizontal", "fairlead_vertical",
            "fairlead_force_x", "anchor_tension", "anchor_horizontal", "anchor_vertical",
            "anchor_uplift", "touchdown_S", "touchdown_x", "grounded_length"} <= set(read)
    with h5py.File(output, "r") as f:
        for name, (value, unit) in read.items():
            assert value == pytest.approx(float(f.attrs[name]), rel=1e-11), name
        assert read["fairlead_vertical"][1] == "N" and read["anchor_uplift"] == (0.0, "1")
        H, V = f.attrs["fairlead_horizontal"], f.attrs["fairlead_vertical"]
        assert H == pytest.approx(np.hypot(*f.attrs["end_force"][:2]), rel=1e-15)
        assert V > H > 0.0                 # a steel riser hangs steeply
    assert (f"fairlead force {np.hypot(H, V) / 1e3:.6g} kN: horizontal {H / 1e3:.6g} kN, "
            f"vertical {V / 1e3:.6g} kN") in done.stdout
    assert f"ends {folder / 'scr_ends.csv'}" in done.stdout


def test_the_riser_s_von_mises_stress_and_utilisation_by_hand(riser):
    """At the hang-off (z = 1500 m, the sea surface: p_e = 0, p_i = 10 MPa; a pin: the
    moment M only that of the vertex strain, 26 N m): s_a = T_w / A + M r_i / I with
    A = pi/4 (0.2731^2 - 0.2319^2) = 0.016341 m^2, I = pi/4 (r_o^4 - r_i^4); at the bore
    s_h = p_i (r_o^2 + r_i^2) / (r_o^2 - r_i^2), s_r = -p_i; s_vm = sqrt(s_a^2 + s_h^2
    + s_r^2 - s_a s_h - s_h s_r - s_r s_a); the utilisation s_vm / (2/3 448 MPa)."""
    done, output, _, _ = riser
    with h5py.File(output, "r") as f:
        # the run's final summary gives the largest stress and utilisation
        summary = [line for line in done.stdout.splitlines() if "von Mises" in line]
        assert len(summary) == 1, done.stdout
        assert f"{f.attrs['max_utilisation']:.4g}" in summary[0]
        wall, stress = f["wall_tension"][-1], f["von_mises"][-1]
        moment = f["bending_moment"][-1]
        utilisation = f["utilisation"][:]
        largest, design = f.attrs["max_utilisation"], f.attrs["design_factor"]
    r_o, r_i, p_i = 0.2731 / 2, 0.2319 / 2, 1e7
    axial = wall / (np.pi * (r_o**2 - r_i**2)) + moment * r_i / (np.pi * (r_o**4 - r_i**4) / 4)
    assert 10 < moment < 50
    hoop = p_i * (r_o**2 + r_i**2) / (r_o**2 - r_i**2)
    radial = -p_i
    by_hand = np.sqrt(axial**2 + hoop**2 + radial**2 - axial * hoop - hoop * radial
                      - radial * axial)
    assert 140e6 < by_hand < 170e6
    assert stress == pytest.approx(by_hand, rel=1e-12)
    assert design == pytest.approx(2 / 3, rel=1e-15)
    assert utilisation[-1] == pytest.approx(stress / (2 / 3 * 448e6), rel=1e-12)
    assert largest == pytest.approx(np.nanmax(utilisation), rel=1e-15)
    assert 0.4 < largest < 0.7


def test_no_table_after_a_run_that_did_not_converge(tmp_path):
    """-rod_al_max_it 2: exit 3 (the result file says converged = 0), and no table, no
    regions' table, no partial file."""
    table = tmp_path / "scr.csv"
    done = run_petsc_rod(SCR + ["-rod_al_max_it", "2", "-rod_max_halvings", "0",
                                "-rod_table", str(table)], 1, 300)
    assert done.returncode == 3, done.stdout + done.stderr
    assert os.listdir(tmp_path) == []


def test_an_earlier_run_s_table_does_not_stay_beside_a_failed_run(tmp_path):
    """Review of issue 24: a converged run's table stayed beside a later failed run's
    result file as if it were its. The failed run removes it and says so."""
    table, regions = tmp_path / "scr.csv", tmp_path / "scr_regions.csv"
    table.write_text("an earlier run's table\n")
    regions.write_text("an earlier run's regions\n")
    done = run_petsc_rod(SCR + ["-rod_al_max_it", "2", "-rod_max_halvings", "0",
                                "-rod_table", str(table)], 1, 300)
    assert done.returncode == 3, done.stdout + done.stderr
    assert "no table written" in done.stdout and "an earlier run's" in done.stdout
    assert os.listdir(tmp_path) == []


def test_a_table_that_cannot_be_written_is_refused_before_the_run(tmp_path):
    """A folder that does not exist, a folder, the -rod_output file: one line, exit 2."""
    for table, more in ((tmp_path / "missing" / "t.csv", []), (tmp_path, []),
                        (tmp_path / "r.h5", ["-rod_output", str(tmp_path / "r.h5")])):
        done = run_petsc_rod(["-options_file", "options/cantilever.opts", "-rod_table",
                              str(table)] + more, 1, 120)
        assert done.returncode == 2, done.stdout + done.stderr
        lines = done.stdout.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("petsc_rod: error: -rod_table")
    assert os.listdir(tmp_path) == []


def test_a_plain_rod_s_table(tmp_path):
    """A cantilever (no riser terms): the line's results, with its effective tension,
    no regions' table."""
    table = tmp_path / "c.csv"
    done = run_petsc_rod(["-options_file", "options/cantilever.opts", "-rod_table",
                          str(table)], 1, 120)
    assert done.returncode == 0, done.stdout + done.stderr
    header, values = read_csv(table)
    assert "effective_tension (N)" in header and "bending_moment (N m)" in header
    assert values.shape[0] == int(done.stdout.split(" elements")[0].split()[-1]) + 1
    assert os.listdir(tmp_path) == ["c.csv"]


def test_two_ranks_write_the_same_table(riser):
    """The steel riser on 2 ranks: the same header, rows in the same order, the same
    numbers to the iteration's tolerance (1e-9 of the state: 1e-6 of each column's
    largest value for the curvatures, derivatives of it; a component's scale is its
    vector's: the position's for x, y, z, the curvature's for u1, u2, the moment's for
    the bending moment and the torque, the force's for the shear and the tensions: y,
    u2 and the torque, zero in the riser's plane, are round-off on either, 1e-26 to
    1e-17; the bend radius, 1 / curvature, is left out); the same regions."""
    _, _, table, folder = riser
    types, two = folder / "x65.txt", folder / "scr2.csv"
    done = run_petsc_rod(SCR + ["-rod_line_types", str(types), "-rod_table", str(two)], 2,
                         600)
    assert done.returncode == 0, done.stdout + done.stderr
    header, values = read_csv(table)
    header2, values2 = read_csv(two)
    assert header2 == header and values2.shape == values.shape
    finite = np.isfinite(values)
    np.testing.assert_array_equal(finite, np.isfinite(values2))
    scale = np.nanmax(np.abs(np.where(finite, values, np.nan)), axis=0)
    names = [name.split(" (")[0] for name in header]
    for vector in (("x", "y", "z"), ("u1", "u2", "curvature"), ("bending_moment", "torque"),
                   ("shear", "effective_tension", "wall_tension")):
        columns = [names.index(c) for c in vector if c in names]
        scale[columns] = scale[columns].max()
    for j, name in enumerate(header):
        if name == "bend_radius (m)":
            continue
        rows = finite[:, j]
        np.testing.assert_allclose(values2[rows, j], values[rows, j], rtol=1e-6,
                                   atol=1e-6 * scale[j], err_msg=name)
    with open(folder / "scr_regions.csv") as one, open(folder / "scr2_regions.csv") as other:
        rows, rows2 = list(csv.reader(one)), list(csv.reader(other))
    assert [row[0] for row in rows] == [row[0] for row in rows2]
    np.testing.assert_allclose(np.array([row[1:] for row in rows2[1:]], dtype=float),
                               np.array([row[1:] for row in rows[1:]], dtype=float),
                               rtol=1e-6, atol=1e-6)


def test_a_bad_yield_stress_is_refused(tmp_path):
    """smys must be positive: one line naming it, exit 2, no table."""
    types = tmp_path / "bad.txt"
    types.write_text(STEEL_X65.replace("448e6", "-448e6"))
    done = run_petsc_rod(SCR + ["-rod_line_types", str(types), "-rod_table",
                                str(tmp_path / "t.csv")], 1, 120)
    assert done.returncode == 2, done.stdout + done.stderr
    lines = done.stdout.strip().splitlines()
    assert len(lines) == 1 and "smys" in lines[0], lines
    assert os.listdir(tmp_path) == ["bad.txt"]


def test_the_table_has_the_friction_columns(tmp_path):
    """With seabed friction (the riser catenary under 1 m/s across, mu = 0.5, 300
    elements) the table has the file's friction force per metre, its global components
    friction_force_x, _y, _z (N/m), and the stick/slide state at each vertex, equal to
    its datasets. Before, the table left them out."""
    output, table = tmp_path / "f.h5", tmp_path / "f.csv"
    done = run_petsc_rod(["-options_file", "options/riser_catenary.opts", "-rod_current",
                          "0,1,0", "-rod_elements", "300", "-rod_seabed_friction", "0.5",
                          "-rod_output", str(output), "-rod_table", str(table)], 1, 300)
    assert done.returncode == 0, done.stdout + done.stderr
    header, values = read_csv(table)
    for name in ("friction_force_x (N/m)", "friction_force_y (N/m)",
                 "friction_force_z (N/m)", "friction_state (1)"):
        assert name in header, name
    column = {name.split(" (")[0]: values[:, i] for i, name in enumerate(header)}
    with h5py.File(output, "r") as f:
        force, state = f["friction_force"][:], f["friction_state"][:]
    for k, axis in enumerate("xyz"):
        np.testing.assert_allclose(column[f"friction_force_{axis}"], force[:, k],
                                   rtol=1e-11, atol=1e-9)
    np.testing.assert_array_equal(column["friction_state"], state)
    assert np.abs(force[:, 1]).max() > 10.0           # friction holds the line sideways
