"""-rod_start_position (an anchor anywhere; docs/method.md §5): the solver works in the
frame whose origin is the start, and every absolute position (the end, the seabed, the
sea surface a current profile's depths are measured from, the outputs, a restart's
state) is translated by the start. A riser scene and the same scene translated by
(100, 50, -20) give the same shape translated, to round-off."""

import h5py
import numpy as np
import pytest

from helpers import describe, run_petsc_rod
from test_hostile_cli import assert_one_line_and_nothing_left

TIMEOUT = 120
SHIFT = np.array([100.0, 50.0, -20.0])
# options/riser_catenary.opts on 300 elements with a current profile (depths below the
# sea surface) and a point force, so that every absolute height is used
RISER = ["-rod_length", "1800", "-rod_stiffness", "5.6e7,5.6e7,4.3e7", "-rod_start", "pin",
         "-rod_end", "pin", "-rod_load", "0,0,-1200", "-rod_drag", "1025,1.2,0.324",
         "-rod_elements", "300", "-rod_initial_shape", "catenary",
         "-rod_point_load", "1500,0,0,2e5"]
HERE = ["-rod_end_position", "1157,0,1000", "-rod_seabed", "0", "-rod_sea_surface", "1000"]
THERE = ["-rod_start_position", "100,50,-20", "-rod_end_position", "1257,50,980",
         "-rod_seabed", "-20", "-rod_sea_surface", "980"]
POSITIONS = ("touchdown_position", "max_curvature_position", "point_load_position")


@pytest.fixture(scope="module")
def riser_files(tmp_path_factory):
    """The riser here and translated: {name: path}."""
    folder = tmp_path_factory.mktemp("start_position")
    profile = folder / "profile.txt"
    profile.write_text("0 0.5 0 0\n500 0.2 0.1 0\n1000 0 0 0\n")
    files = {}
    for name, where in (("here", HERE), ("there", THERE)):
        files[name] = folder / f"{name}.h5"
        done = run_petsc_rod(RISER + where + ["-rod_current_profile", str(profile),
                                              "-rod_output", str(files[name])], 1, TIMEOUT)
        assert done.returncode == 0, describe(done)
    files["profile"] = profile
    return files


def test_a_translated_riser_is_the_same_riser_translated(riser_files):
    """r shifted, n, d3, the riser numbers and the iteration the same, to round-off
    (measured: r 1.1e-13 m on coordinates of 1000 m; the rest bit for bit)."""
    with h5py.File(riser_files["here"], "r") as here, h5py.File(riser_files["there"], "r") as there:
        assert np.abs(there["r"][:] - SHIFT - here["r"][:]).max() < 1e-11
        for key in ("n", "d3", "u", "effective_tension", "seabed_reaction"):
            assert np.abs(there[key][:] - here[key][:]).max() <= 1e-12 * np.abs(here[key][:]).max()
        for key in POSITIONS:
            assert np.abs(there.attrs[key] - SHIFT - here.attrs[key]).max() < 1e-11
        for key in ("touchdown_S", "top_tension", "iterations", "grounded_length"):
            assert there.attrs[key] == pytest.approx(here.attrs[key], rel=1e-12)
        assert np.abs(there["r"][0] - SHIFT).max() == 0.0          # the anchor is the start
        parameters = there["parameters"].attrs
        assert np.array_equal(parameters["start_position"], SHIFT)
        assert np.array_equal(parameters["end_position"], [1257.0, 50.0, 980.0])
        assert float(parameters["sea_surface"]) == 980.0


@pytest.mark.parametrize("source", ["here", "there"])
def test_a_restart_takes_the_files_shape_from_its_own_start(riser_files, tmp_path, source):
    """The translated scene restarted from either file: no walk (the file's scene, in its
    own start's frame, is this one), the same answer as the translated file's."""
    path = tmp_path / "again.h5"
    done = run_petsc_rod(RISER + THERE + ["-rod_current_profile", str(riser_files["profile"]),
                                          "-rod_initial", str(riser_files[source]),
                                          "-rod_output", str(path)], 1, TIMEOUT)
    assert done.returncode == 0 and "restart: walks" not in done.stdout, describe(done)
    with h5py.File(path, "r") as again, h5py.File(riser_files["there"], "r") as there:
        assert np.abs(again["r"][:] - there["r"][:]).max() < 1e-6


def test_a_start_position_with_a_free_start_exits_2(tmp_path):
    path = tmp_path / "out.h5"
    done = run_petsc_rod(["-rod_elements", "8", "-rod_start", "free", "-rod_end", "clamp",
                          "-rod_start_position", "1,2,3", "-rod_output", str(path)], 1, TIMEOUT)
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2,
                                     ["-rod_start_position", "-rod_start"], path)


def test_an_end_below_the_seabed_is_named_in_absolute_heights(tmp_path):
    done = run_petsc_rod(["-rod_elements", "8", "-rod_start", "pin", "-rod_end", "pin",
                          "-rod_start_position", "0,0,-20", "-rod_end_position", "0.5,0,-20.5",
                          "-rod_load", "0,0,-1", "-rod_seabed", "-20.2"], 1, TIMEOUT)
    assert_one_line_and_nothing_left(done.returncode, done.stdout + done.stderr, 2,
                                     ["z = -20.5 m", "-rod_seabed -20.2"])
