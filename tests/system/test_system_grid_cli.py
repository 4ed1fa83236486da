"""A system file on a seabed grid from the command line (cli_system.sloped;
docs/systems.md "Running a system"): -rod_seabed_profile FILE of x, y, height rows
gives the system's seabed in place of the MoorDyn file's depth.
tests/data/moordyn/small_free_body.dat on the grid of tests/solver/test_system_grid.py
(level to x = -20 m, sloping in x and y beyond, falling more beyond a grid line at
x = 55 m): the command line on 1 and 2 ranks equals the Python API with
Environment.seabed_profile on the same rows, to the system's accuracy
(test_system_cli.FLOOR). Spawns processes: marked ``serial``."""

import pytest

from test_system_profile_cli import api_numbers, assert_same, file_numbers

pytestmark = pytest.mark.serial

# test_system_grid.GRID (a solver test's module, which this process does not import)
XS, YS = (-100.0, -20.0, 55.0, 95.0, 200.0), (-100.0, 30.0, 100.0)
ROWS = tuple((x, y, -30.2 + max(x + 20.0, 0.0) * (-0.004 + 3e-5 * y)
                - 0.03 * max(x - 55.0, 0.0)) for x in XS for y in YS)


@pytest.fixture(scope="module")
def rows_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("grid") / "grid.txt"
    path.write_text("".join(f"{x:g} {y:g} {z!r}\n" for x, y, z in ROWS))
    return path


@pytest.fixture(scope="module")
def api(tmp_path_factory):
    """The API's body pose and stiffness of the deck on the grid."""
    return api_numbers(tmp_path_factory.mktemp("api"),
                       f"dict(seabed_profile={ROWS!r}, seabed_origin=(0.0, 0.0))")


@pytest.mark.parametrize("ranks", [1, 2])
def test_the_file_on_a_grid_equals_the_api_on_a_grid(api, rows_file, tmp_path, ranks):
    x, K = file_numbers(rows_file, tmp_path / f"grid{ranks}.h5", ranks)
    assert x[0] > 1e-3 and x[1] < -1e-4         # down the grid's slopes, as the API's
    assert_same(x, K, api)
