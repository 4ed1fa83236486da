"""A system file on a seabed profile from the command line (cli_system.sloped;
docs/systems.md "Running a system"): -rod_seabed_profile FILE (with
-rod_seabed_direction and -rod_seabed_origin) gives the system's seabed in place of the
MoorDyn file's depth. tests/data/moordyn/small_free_body.dat on the profile of
tests/solver/test_system_profile.py (level at -30.2 m to a row at x = 55 m, falling
beyond): the command line on 1 and 2 ranks equals the Python API with
Environment.seabed_profile on the same file, to the system's accuracy
(test_system_cli.FLOOR); the profile with a slope is refused in one line naming both.
Spawns processes: marked ``serial``."""

import subprocess
import sys

import h5py
import numpy as np
import pytest

from helpers import REPO_ROOT, child_env, describe, run_petsc_rod
from test_system_cli import DECK, refused
from test_system_slope_cli import same

pytestmark = pytest.mark.serial

ROWS = ((-100.0, -30.2), (55.0, -30.2), (95.0, -31.4), (200.0, -31.4))


@pytest.fixture(scope="module")
def rows_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("profile") / "profile.txt"
    path.write_text("".join(f"{d:g} {z:g}\n" for d, z in ROWS))
    return path


def api_numbers(tmp_path, sea):
    """The API's body pose and stiffness of the deck with its environment's fields
    ``sea`` (a dict's text, Environment's fields) and no flat seabed, in a process of
    its own: {"x", "K"}."""
    script, out = tmp_path / "api.py", tmp_path / "api.npz"
    script.write_text(f"""
import dataclasses, numpy as np
from petsc_rod.api import read_moordyn, solve_system
system, notes = read_moordyn({DECK!r})
sea = dataclasses.replace(system.environment, seabed=None, **{sea})
r = solve_system(dataclasses.replace(system, environment=sea))
np.savez({str(out)!r}, x=r.bodies["Body1"].position, K=r.bodies["Body1"].stiffness)
""")
    process = subprocess.run([sys.executable, str(script)], cwd=REPO_ROOT, env=child_env(),
                             capture_output=True, text=True, timeout=600, check=False)
    assert process.returncode == 0, describe(process)
    return np.load(out)


@pytest.fixture(scope="module")
def api(tmp_path_factory):
    """The API's body pose and stiffness of the deck on the profile."""
    return api_numbers(tmp_path_factory.mktemp("api"),
                       f"dict(seabed_profile={ROWS!r}, seabed_direction=0.0, "
                       "seabed_origin=(0.0, 0.0))")


def file_numbers(rows_file, out, ranks):
    """The command line's body pose and stiffness of the deck on the seabed of
    ``rows_file`` (-rod_seabed_profile) on ``ranks`` ranks, its result ``out``."""
    process = run_petsc_rod(["-rod_system", DECK, "-rod_seabed_profile", str(rows_file),
                             "-rod_output", str(out)], ranks, 600)
    assert process.returncode == 0, describe(process)
    assert "warning" not in process.stdout, describe(process)
    with h5py.File(out, "r") as f:
        x, K = f["system"]["body_positions"][0], f["system"]["body_stiffness"][0]
    print("body", x)
    return x, K


def assert_same(x, K, api):
    """The pose's positions and rotations, and each 3 x 3 block of the stiffness, the
    API's to the system's accuracy (same)."""
    assert same(x[:3], api["x"][:3]) and same(x[3:], api["x"][3:])
    for rows in (slice(0, 3), slice(3, 6)):       # N/m, N/rad; N, N m/rad
        for columns in (slice(0, 3), slice(3, 6)):
            assert same(K[rows, columns], api["K"][rows, columns])


@pytest.mark.parametrize("ranks", [1, 2])
def test_the_file_on_a_profile_equals_the_api_on_a_profile(api, rows_file, tmp_path, ranks):
    x, K = file_numbers(rows_file, tmp_path / f"profile{ranks}.h5", ranks)
    assert x[0] > 1e-3                  # toward the anchor beyond the row, as the API's
    assert_same(x, K, api)


def test_a_profile_with_a_slope_is_refused_naming_both(rows_file, tmp_path):
    line = refused(tmp_path, ["-rod_system", DECK, "-rod_seabed_profile", str(rows_file),
                              "-rod_seabed_slope", "2"])
    assert "-rod_seabed_profile" in line and "-rod_seabed_slope" in line, line


@pytest.fixture(scope="module")
def frictional_deck(tmp_path_factory):
    """The deck with the seabed's friction in its options (MoorDyn's
    FrictionCoefficient 0.5)."""
    path = tmp_path_factory.mktemp("friction") / "frictional.dat"
    text = open(DECK).read().replace(
        "30            WtrDpth", "0.5           FrictionCoefficient\n30            WtrDpth")
    assert "FrictionCoefficient" in text
    path.write_text(text)
    return path


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_frictional_file_on_a_profile_equals_the_api(frictional_deck, rows_file,
                                                        tmp_path, ranks):
    """Friction on a profile, the system's stiffness exact (system/held_line.py): the
    command line runs it (before, refused: "no exact stiffness of its seabed friction
    ... on a seabed profile") and equals the API on the same file."""
    script, numbers = tmp_path / "api.py", tmp_path / "api.npz"
    script.write_text(f"""
import dataclasses, numpy as np
from petsc_rod.api import read_moordyn, solve_system
system, notes = read_moordyn({str(frictional_deck)!r})
sea = dataclasses.replace(system.environment, seabed=None, seabed_profile={ROWS!r},
                          seabed_direction=0.0, seabed_origin=(0.0, 0.0))
assert sea.seabed_friction is not None
r = solve_system(dataclasses.replace(system, environment=sea))
np.savez({str(numbers)!r}, x=r.bodies["Body1"].position, K=r.bodies["Body1"].stiffness)
""")
    process = subprocess.run([sys.executable, str(script)], cwd=REPO_ROOT, env=child_env(),
                             capture_output=True, text=True, timeout=600, check=False)
    assert process.returncode == 0, describe(process)
    api = np.load(numbers)
    out = tmp_path / "friction.h5"
    process = run_petsc_rod(["-rod_system", str(frictional_deck), "-rod_seabed_profile",
                             str(rows_file), "-rod_output", str(out)], ranks, 600)
    assert process.returncode == 0, describe(process)
    assert "seabed friction measured from the lines' as-laid shapes" in process.stdout
    with h5py.File(out, "r") as f:
        x, K = f["system"]["body_positions"][0], f["system"]["body_stiffness"][0]
    print("body", x)
    assert same(x[:3], api["x"][:3]) and same(x[3:], api["x"][3:])
    for rows in (slice(0, 3), slice(3, 6)):
        for columns in (slice(0, 3), slice(3, 6)):
            assert same(K[rows, columns], api["K"][rows, columns])
