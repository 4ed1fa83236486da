"""The global hog and sag bend radii of a line with discrete buoyancy modules
(quantities/module_bends.py) from the command line: the 80 m cable of
options/cable_80m.opts with its buoyancy as 20 modules 2.5 m apart
(scripts/matrix_buoyancy_modules.txt): the result file, the final lines and the summary
table give the same numbers, on one rank and two."""

import h5py
import numpy as np
import pytest

from helpers import run_petsc_rod
from petsc_rod.sweep import summary

MODULES = ["-options_file", "options/cable_80m.opts", "-rod_load", "0,0,-157.8003",
           "-rod_load_breaks", "", "-rod_point_loads", "scripts/matrix_buoyancy_modules.txt",
           "-rod_elements", "680"]


def radius_from_positions(r, S, centre, length):
    """L_a / the angle between the central chords r(S_k+1) - r(S_k-1) at the vertices
    S_k = centre -+ L_a / 2."""
    def chord(s):
        k = int(np.argmin(np.abs(S - s)))
        t = r[k + 1] - r[k - 1]
        return t / np.linalg.norm(t)
    a, b = chord(centre - length / 2), chord(centre + length / 2)
    return length / np.arctan2(np.linalg.norm(np.cross(a, b)), a @ b)


def test_the_modules_global_and_local_bend_radii(tmp_path):
    """The pitch is 2.5 m; the global hog radius over it, 17.9 m, is larger than the local
    kink's at a module, 16.1 m, and is the turn of the line's own central chords at the
    window's ends (to 0.2 %); the final lines and summary.table give the file's numbers;
    two ranks the same to 1e-6. Before, only the local radius (min_bend_radius, the
    regions')."""
    files = {}
    for ranks in (1, 2):
        files[ranks] = tmp_path / f"m{ranks}.h5"
        done = run_petsc_rod(MODULES + ["-rod_output", str(files[ranks])], ranks, 300)
        assert done.returncode == 0, done.stdout + done.stderr
        if ranks == 1:
            stdout = done.stdout
    with h5py.File(files[1], "r") as f:
        a = {key: f.attrs[key] for key in f.attrs}
        r, S = f["r"][:], f["S"][:]
        units = f.attrs["attribute_units"]
    assert a["module_pitch"] == 2.5 and '"global_hog_bend_radius": "m"' in units
    assert 15.0 < a["local_hog_bend_radius"] < a["global_hog_bend_radius"] < 20.0
    assert a["local_hog_bend_radius"] == pytest.approx(a["region_min_bend_radius"][2],
                                                       rel=1e-12)
    for kind in ("hog", "sag"):
        assert a[f"global_{kind}_bend_radius"] == pytest.approx(radius_from_positions(
            r, S, a[f"global_{kind}_bend_radius_S"], 2.5), rel=2e-3), kind
    assert (f"global hog bend radius {a['global_hog_bend_radius']:.4g} m at S = "
            f"{a['global_hog_bend_radius_S']:.6g} m (local kink "
            f"{a['local_hog_bend_radius']:.4g} m)") in stdout
    header, rows = summary.table([{"name": "m1", "options": {}, "code": 0, "start": "",
                                   "file": str(files[1])}], [])
    row = dict(zip(header, rows[0]))
    for key in ("module_pitch", "global_hog_bend_radius", "local_hog_bend_radius",
                "global_sag_bend_radius", "local_sag_bend_radius"):
        assert row[f"{key} (m)"] == a[key], key
    with h5py.File(files[2], "r") as f:
        for key in ("global_hog_bend_radius", "global_sag_bend_radius",
                    "local_hog_bend_radius", "global_hog_bend_radius_S"):
            assert float(f.attrs[key]) == pytest.approx(a[key], rel=1e-6), key
