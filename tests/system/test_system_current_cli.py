"""A system file in a current from the command line (cli_system.in_current;
docs/systems.md "Running a system"): -rod_current (uniform) or -rod_current_profile (rows
depth below the sea surface z = 0, ux, uy, uz) put the system's Environment.current;
each line's drag is its line type's Cd and Diam (MoorDyn's columns), 0.5 rho Cd D
|v_n| v_n per metre. tests/data/moordyn/small_free_body.dat in a 1 m/s current along
+x, and in a profile turning and slowing with depth: the command line on 1 and 2 ranks
equals the Python API with Environment.current on the same file, to the system's
accuracy (test_system_cli.FLOOR); each line's end forces balance its drag integrated
over its shape from the file's Cd and Diam; the options' refusals name them. Spawns processes: marked
``serial``."""

import subprocess
import sys

import h5py
import numpy as np
import pytest

from helpers import REPO_ROOT, child_env, describe, run_petsc_rod
from test_system_cli import DECK, FLOOR, refused
from test_system_slope_cli import cli_numbers, same

pytestmark = pytest.mark.serial

UNIFORM = (1.0, 0.0, 0.0)
# depth below z = 0 (m), ux, uy, uz (m/s): 1 m/s along +x at the surface, turning
# towards +y and slowing to 0.45 m/s at the seabed (30 m), linearly (a kink between
# rows would cost the check's quadrature its accuracy)
PROFILE = ((0.0, 1.0, 0.0, 0.0), (30.0, 0.2, 0.4, 0.0))
NAMES = ("Line1", "Line2", "Line3")
# c = 0.5 rho Cd D (kg/m^2) of the deck's line type: D = 0.09 m, Cd = 1.6, in water of
# 1025 kg/m^3
DRAG = 0.5 * 1025.0 * 1.6 * 0.09


def api_numbers(tmp_path):
    """The API's body pose, stiffness, end forces and tensions, and each line's S, r
    and d3 at its vertices, of the deck with no current, in the uniform one and in the
    profile (Environment.current), in a process of its own."""
    script, out = tmp_path / "api.py", tmp_path / "api.npz"
    script.write_text(f"""
import dataclasses, numpy as np
from petsc_rod.api import read_moordyn, solve_system
system, notes = read_moordyn({DECK!r})
found = {{}}
for label, current in (("still", None), ("uniform", {UNIFORM!r}), ("profile", {PROFILE!r})):
    sea = dataclasses.replace(system.environment, current=current)
    r = solve_system(dataclasses.replace(system, environment=sea))
    found.update({{f"{{label}}_x": r.bodies["Body1"].position,
                  f"{{label}}_K": r.bodies["Body1"].stiffness,
                  f"{{label}}_F": np.array([r.end_forces[n] for n in {NAMES!r}]),
                  f"{{label}}_T": np.array([r.end_tensions[n] for n in {NAMES!r}])}})
    for n in {NAMES!r}:
        along = r.lines[n].along_line(["S", "r", "d3"])
        found.update({{f"{{label}}_{{n}}_{{key}}": value for key, value in along.items()}})
np.savez({str(out)!r}, **found)
""")
    process = subprocess.run([sys.executable, str(script)], cwd=REPO_ROOT, env=child_env(),
                             capture_output=True, text=True, timeout=300, check=False)
    assert process.returncode == 0, describe(process)
    found = np.load(out)
    return {label: {key: found[f"{label}_{key}"] for key in
                    ["x", "K", "F", "T"] + [f"{n}_{k}" for n in NAMES for k in ("S", "r", "d3")]}
            for label in ("still", "uniform", "profile")}


def drag_integral(S, r, d3, velocity_at):
    """int 0.5 rho Cd D |v_n| v_n dS over a line, N, (3,), from its vertices' S (n,),
    positions r (n, 3) and directors d3 (n, 3) (the tangent, normalised here), the
    current ``velocity_at(z)`` (n, 3) at their heights: composite Simpson over pairs of
    its equal elements, independent of the solver's quadrature (Simpson's within each
    element, on its P2 nodes)."""
    t = d3 / np.linalg.norm(d3, axis=1)[:, None]
    v = velocity_at(r[:, 2])
    normal = v - np.einsum("nc,nc->n", v, t)[:, None] * t
    f = DRAG * np.linalg.norm(normal, axis=1)[:, None] * normal
    h = np.diff(S)[0::2]
    weights = np.zeros(len(S))
    weights[0:-1:2] += h / 3
    weights[1::2] += 4 * h / 3
    weights[2::2] += h / 3
    return weights @ f


def velocities(current):
    """velocity_at(z) of a uniform current (3,) or of PROFILE's rows below z = 0,
    linear between its depths and constant beyond (as -rod_current_profile's)."""
    rows = np.asarray(current, dtype=float)
    if rows.ndim == 1:
        return lambda z: np.broadcast_to(rows, (len(z), 3))
    return lambda z: np.column_stack([np.interp(-z, rows[:, 0], rows[:, c])
                                      for c in (1, 2, 3)])


def profile_file(tmp_path):
    path = tmp_path / "profile.txt"
    path.write_text("# depth (m) ux uy uz (m/s)\n"
                    + "".join(" ".join(f"{v:g}" for v in row) + "\n" for row in PROFILE))
    return path


@pytest.fixture(scope="module")
def api(tmp_path_factory):
    return api_numbers(tmp_path_factory.mktemp("api"))


@pytest.mark.parametrize("label, current", [("uniform", UNIFORM), ("profile", PROFILE)])
def test_each_lines_drag_is_the_line_types_on_its_shape(api, label, current):
    """The horizontal forces at each line's two ends sum to its drag (the weight and a
    flat seabed without friction push vertically), and that drag is 0.5 rho Cd D |v_n|
    v_n of the file's Cd, Diam and WtrDnsty integrated over the line's shape, at the
    profile's velocities at the nodes' depths below z = 0: measured 1.2e-6 of the drag
    in the uniform current, 4.7e-6 in the profile (the quadratures differ; the
    profile's depths taken 5 m lower: 0.37)."""
    for n in NAMES:
        found = api[label]
        drag = drag_integral(found[f"{n}_S"], found[f"{n}_r"], found[f"{n}_d3"],
                             velocities(current))
        ends = found["F"][NAMES.index(n)].sum(axis=0)
        assert np.abs(ends[:2] - drag[:2]).max() <= 1e-5 * np.abs(drag[:2]).max(), n
    # the body drifts downstream (+x), and with the profile turning to +y, to +y too
    drift = api["uniform"]["x"][:3] - api["still"]["x"][:3]
    assert drift[0] > 0.1 and abs(drift[1]) < 1e-6 * drift[0]
    assert api["profile"]["x"][1] - api["still"]["x"][1] > 1e-3


@pytest.mark.parametrize("ranks", [1, 2])
def test_the_file_in_a_current_equals_the_api_in_it(api, tmp_path, ranks):
    cli = cli_numbers(tmp_path, ranks, ["-rod_current", ",".join(map(str, UNIFORM))])
    with h5py.File(tmp_path / f"system{ranks}.h5", "r") as f:
        assert np.array_equal(f["system/current"][()], [[0.0, *UNIFORM]])
    expected = api["uniform"]
    assert same(cli["x"][:3], expected["x"][:3]) and same(cli["x"][3:], expected["x"][3:])
    for rows in (slice(0, 3), slice(3, 6)):       # N/m, N/rad; N, N m/rad
        for columns in (slice(0, 3), slice(3, 6)):
            assert same(cli["K"][rows, columns], expected["K"][rows, columns])
    for name in ("F", "T"):
        assert same(cli[name], expected[name]), name
    assert same(cli["r"], expected["Line1_r"])


@pytest.mark.parametrize("ranks", [1, 2])
def test_the_file_in_a_current_profile_equals_the_api_in_it(api, tmp_path, ranks):
    cli = cli_numbers(tmp_path, ranks, ["-rod_current_profile", str(profile_file(tmp_path))])
    with h5py.File(tmp_path / f"system{ranks}.h5", "r") as f:   # the run's current kept
        assert np.array_equal(f["system/current"][()], np.array(PROFILE))
    expected = api["profile"]
    assert same(cli["x"][:3], expected["x"][:3]) and same(cli["x"][3:], expected["x"][3:])
    for rows in (slice(0, 3), slice(3, 6)):
        for columns in (slice(0, 3), slice(3, 6)):
            assert same(cli["K"][rows, columns], expected["K"][rows, columns])
    for name in ("F", "T"):
        assert same(cli[name], expected[name]), name
    assert same(cli["r"], expected["Line1_r"])


def test_the_current_options_are_listed_and_checked(tmp_path):
    process = run_petsc_rod(["-rod_system", DECK, "-help"], 1, 120)
    assert process.returncode == 0, describe(process)
    for name in ("-rod_current ", "-rod_current_profile "):
        assert name in process.stdout, name
    profile = str(profile_file(tmp_path))
    assert refused(tmp_path, ["-rod_system", DECK, "-rod_current", "1,0,0",
                              "-rod_current_profile", profile]) == (
        "petsc_rod: error: -rod_current and -rod_current_profile both give the current; "
        "give one of them")
    bad = tmp_path / "bad_profile.txt"
    bad.write_text("0 1 0 0\n10 1 0\n")
    line = refused(tmp_path, ["-rod_system", DECK, "-rod_current_profile", str(bad)])
    assert line.startswith(f"petsc_rod: error: -rod_current_profile {bad}: ")
    # the result file must not replace the profile it reads
    text = open(profile).read()
    process = run_petsc_rod(["-rod_system", DECK, "-rod_current_profile", profile,
                             "-rod_output", profile], 1, 120)
    assert process.returncode == 2, describe(process)
    assert "-rod_current_profile" in process.stdout
    assert open(profile).read() == text
    seabed = tmp_path / "seabed.txt"                  # flat at the file's depth
    seabed.write_text("-200 -30\n200 -30\n")
    process = run_petsc_rod(["-rod_system", DECK, "-rod_seabed_profile", str(seabed),
                             "-rod_output", str(seabed)], 1, 120)
    assert process.returncode == 2, describe(process)
    assert "-rod_seabed_profile" in process.stdout
    assert seabed.read_text() == "-200 -30\n200 -30\n"


def deck_with_bare_type(tmp_path, lines):
    """The deck with a line type 'bare' of Cd 0 (else main's) for the lines ``lines``
    (IDs)."""
    with open(DECK, encoding="utf-8") as source:
        text = source.read()
    main = "main       0.09    77.7066    384.243E6  -0.8        0          1.6    1.0    0.1     0.0"
    text = text.replace(main, main + "\n" + main.replace("main ", "bare ").replace(
        " 1.6 ", " 0.0 "))
    for k in lines:
        text = text.replace(f"{k}     main       {k}        ", f"{k}     bare       {k}        ")
    deck = tmp_path / "bare.dat"
    deck.write_text(text)
    return str(deck)


def test_a_line_type_without_drag_takes_none_and_a_current_on_nothing_is_refused(tmp_path):
    """A line of Cd 0 in the system's current carries no drag (its horizontal end forces
    balance, to the system's accuracy) while the others do (held_line.line_sea, where a
    single line of such types in a current is refused); where no line type has a Cd and
    no free point a CdA (a fixed one's is never pushed), the current is refused in one
    line."""
    out = tmp_path / "bare.h5"
    process = run_petsc_rod(["-rod_system", deck_with_bare_type(tmp_path, [1]),
                             "-rod_current", "1,0,0", "-rod_output", str(out)], 1, 300)
    assert process.returncode == 0, describe(process)
    with h5py.File(out, "r") as f:
        forces = f["system"]["end_forces"][()]
    tension = np.abs(forces[0]).max()
    assert np.abs(forces[0].sum(axis=0)[:2]).max() <= FLOOR * tension
    assert forces[1].sum(axis=0)[0] > 1e3 and forces[2].sum(axis=0)[0] > 1e3   # N
    bare = deck_with_bare_type(tmp_path, [1, 2, 3])
    with open(bare, encoding="utf-8") as source:      # the anchor Point1 given a CdA
        text = source.read().replace("1     Fixed       65.0    0        -30.0   0      0       0",
                                     "1     Fixed       65.0    0        -30.0   0      0       5")
    assert "-30.0   0      0       5      0" in text
    anchored = tmp_path / "anchored.dat"
    anchored.write_text(text)
    for deck in (bare, str(anchored)):
        assert refused(tmp_path, ["-rod_system", deck, "-rod_current", "1,0,0"]) == (
            "petsc_rod: error: -rod_current: the current pushes nothing: every line type's "
            "Cd is 0 (LINE TYPES) and no free point has a CdA (POINTS); give them or drop "
            "the option")


def test_a_current_too_strong_for_a_line_names_the_option(tmp_path):
    """A current of 1e15 m/s (its drag c max |v|^2 = 0.5 rho Cd D |v|^2 = 7.38e31 N/m on
    the deck's line type, above the model's bound 1e30) was refused naming
    Environment.current, the API's field, with the reader's notes before it: now the
    option given (-rod_current or -rod_current_profile) and the file's columns, in one
    line, exit 2, no file; the API keeps its field's name
    (tests/unit/test_system_model.py)."""
    drag = f"{DRAG * 1e30:.3g}"
    assert drag == "7.38e+31"
    profile = tmp_path / "strong.txt"
    profile.write_text("0 1e15 0 0\n30 1e15 0 0\n")
    for option, value in (("-rod_current", "1e15,0,0"),
                          ("-rod_current_profile", str(profile))):
        assert refused(tmp_path, ["-rod_system", DECK, option, value]) == (
            f"petsc_rod: error: line Line1: {option} with the line types' cd and drag_d "
            f"(the -rod_system file's LINE TYPES): the largest drag c max |v|^2 = {drag} "
            "N/m is above 1e+30; give the current in m/s")
    # below that bound per metre, above it over the line's 70 m: the applied force's check
    assert refused(tmp_path, ["-rod_system", DECK, "-rod_current", "3e13,0,0"]) == (
        "petsc_rod: error: line Line1: -rod_current with the line types' cd and drag_d "
        "(the -rod_system file's LINE TYPES) and the -rod_system file's LINES (UnstrLen): the "
        f"applied force (int |f| dS + the end forces + the drag) is {70 * DRAG * 9e26:.3g} "
        "N, above 1e+30; give loads in N/m, forces in N and lengths in m")
    # a free point's drag, its tendons of Cd 0 (before: exit 3, no equilibrium found)
    with open(f"{REPO_ROOT}/tests/data/moordyn/buoy_level.dat", encoding="utf-8") as source:
        text = source.read()
    buoy = tmp_path / "buoy.dat"
    buoy.write_text(text.replace("0          1.2    1.0", "0          0.0    1.0").replace(
        "-50.0   1000   10      0", "-50.0   1000   10      5"))
    assert refused(tmp_path, ["-rod_system", str(buoy), "-rod_current", "0,1e15,0"]) == (
        "petsc_rod: error: point Point2: -rod_current with its drag area CdA 5 m^2: the "
        "largest drag 0.5 rho CdA max |v|^2 = 2.56e+33 N is above 1e+30; give the current "
        "in m/s")
