"""A system file on a sloping seabed from the command line (cli_system.sloped;
docs/systems.md "Running a system"): -rod_seabed_slope, -rod_seabed_direction and
-rod_seabed_origin turn the MoorDyn file's seabed (at its WtrDpth) into a plane through
that height at the origin. tests/data/moordyn/small_free_body.dat on a plane rising 2
degrees along +x from its anchor at x = 65 m: the command line on 1 and 2 ranks equals
the Python API with Environment.seabed_slope on the same file, to the system's accuracy
(test_system_cli.FLOOR); the options' refusals name them. Spawns processes: marked
``serial``."""

import subprocess
import sys

import h5py
import numpy as np
import pytest

from helpers import REPO_ROOT, child_env, describe, run_petsc_rod
from test_system_cli import DECK, FLOOR, refused

pytestmark = pytest.mark.serial

SLOPE = ["-rod_seabed_slope", "2", "-rod_seabed_direction", "0", "-rod_seabed_origin",
         "65,0"]


def same(ours, theirs, rtol=FLOOR):
    """Within the system's accepted accuracy, relative to the largest entry."""
    ours, theirs = np.asarray(ours), np.asarray(theirs)
    return ours.shape == theirs.shape and \
        np.abs(ours - theirs).max() <= rtol * np.abs(theirs).max()


def api_numbers(tmp_path):
    """The API's body pose, stiffness, end forces and tensions and Line1's centreline of
    the deck on the same plane (Environment.seabed_slope), in a process of its own."""
    script, out = tmp_path / "api.py", tmp_path / "api.npz"
    script.write_text(f"""
import dataclasses, numpy as np
from petsc_rod.api import read_moordyn, solve_system
system, notes = read_moordyn({DECK!r})
sea = dataclasses.replace(system.environment, seabed_slope=2.0, seabed_direction=0.0,
                          seabed_origin=(65.0, 0.0))
r = solve_system(dataclasses.replace(system, environment=sea))
names = ("Line1", "Line2", "Line3")
np.savez({str(out)!r}, x=r.bodies["Body1"].position, K=r.bodies["Body1"].stiffness,
         F=np.array([r.end_forces[n] for n in names]),
         T=np.array([r.end_tensions[n] for n in names]),
         r=r.lines["Line1"].along_line(["r"])["r"])
""")
    process = subprocess.run([sys.executable, str(script)], cwd=REPO_ROOT, env=child_env(),
                             capture_output=True, text=True, timeout=300, check=False)
    assert process.returncode == 0, describe(process)
    return np.load(out)


def cli_numbers(tmp_path, ranks, options=tuple(SLOPE)):
    """The command line's body pose, stiffness, end forces and tensions and Line1's
    centreline of the deck with ``options`` (the plane's), on ``ranks``."""
    out = tmp_path / f"system{ranks}.h5"
    process = run_petsc_rod(["-rod_system", DECK, *options, "-rod_output", str(out)], ranks,
                            300)
    assert process.returncode == 0, describe(process)
    assert "warning" not in process.stdout, describe(process)
    with h5py.File(out, "r") as f:
        system = f["system"]
        return {"x": system["body_positions"][0], "K": system["body_stiffness"][0],
                "F": system["end_forces"][()], "T": system["end_tensions"][()],
                "r": f["lines/Line1/r"][()]}


@pytest.fixture(scope="module")
def api(tmp_path_factory):
    return api_numbers(tmp_path_factory.mktemp("api"))


def test_the_api_on_a_slope_moves_the_body_downhill(api):
    # the grounded chains pushed downhill: the body drifts 1.06 m to -x (flat: none)
    assert -1.2 < api["x"][0] < -0.9
    # Line1's anchor at the origin, on the plane
    assert api["r"][0] == pytest.approx([65.0, 0.0, -30.0], abs=1e-9)


@pytest.mark.parametrize("ranks", [1, 2])
def test_the_file_on_a_slope_equals_the_api_on_a_slope(api, tmp_path, ranks):
    cli = cli_numbers(tmp_path, ranks)
    assert same(cli["x"][:3], api["x"][:3]) and same(cli["x"][3:], api["x"][3:])
    for rows in (slice(0, 3), slice(3, 6)):       # N/m, N/rad; N, N m/rad
        for columns in (slice(0, 3), slice(3, 6)):
            assert same(cli["K"][rows, columns], api["K"][rows, columns])
    for name in ("F", "T", "r"):
        assert same(cli[name], api[name]), name


def test_the_slope_options_are_listed_and_checked(tmp_path):
    process = run_petsc_rod(["-rod_system", DECK, "-help"], 1, 120)
    assert process.returncode == 0, describe(process)
    for name in ("-rod_seabed_slope ", "-rod_seabed_direction ", "-rod_seabed_origin "):
        assert name in process.stdout, name
    assert refused(tmp_path, ["-rod_system", DECK, "-rod_seabed_direction", "30"]) == (
        "petsc_rod: error: -rod_seabed_direction needs -rod_seabed_slope or "
        "-rod_seabed_profile (the flat seabed (the file's WtrDpth) has no direction "
        "or origin); give one of them, or drop -rod_seabed_direction")
    line = refused(tmp_path, ["-rod_system", DECK, "-rod_seabed_slope", "2",
                              "-rod_seabed_direction", "0,0"])
    assert line.startswith("petsc_rod: error: ") and "-rod_seabed_direction" in line


def test_a_held_point_below_the_plane_is_refused_naming_it_and_the_options(tmp_path):
    """The plane through the file's seabed (z = -30) at the default origin (0, 0),
    rising 2 degrees along +x, is 2.27 m above the anchor Point1 at x = 65 m: refused
    before the run, naming the point, the plane's height there and its options (the
    single line's check named neither the point nor an option)."""
    assert refused(tmp_path, ["-rod_system", DECK, "-rod_seabed_slope", "2"]) == (
        "petsc_rod: error: point Point1 (fixed) is held at z = -30 m, 2.27 m below the "
        "sloping seabed there (z = -27.7301 m: the plane of -rod_seabed_slope, "
        "-rod_seabed_direction, -rod_seabed_origin); hold it on or above it, or move the "
        "plane's origin or change its slope")
