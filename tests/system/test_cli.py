"""The command line ``python -m petsc_rod``: result file, restart, errors, exit codes.

Every test here spawns processes, so the module is marked ``serial`` (skipped when the
tests themselves run under mpiexec: mpiexec cannot nest). Exit codes: 0 converged,
2 bad input, 3 not converged (docs/method.md §6; petsc_rod/errors.py).
"""

import datetime
import json
import os
import subprocess
import sys

import h5py
import numpy as np
import pytest

import petsc_rod
from helpers import REPO_ROOT, child_env, describe, partial_files, png_summary, run_petsc_rod
from petsc_rod.plots import DPI, result_figure
from petsc_rod.cli.options import OPTIONS

pytestmark = pytest.mark.serial

OPTIONS_FILE = os.path.join("options", "cantilever.opts")
EXPLICIT = ["-rod_length", "1", "-rod_stiffness", "1,1,1", "-rod_end", "free",
            "-rod_end_force", "0,-3,0", "-rod_al_penalty", "100", "-rod_al_rtol", "1e-9",
            "-rod_al_ctol", "1e-4"]
TIMEOUT = 120


def cantilever_args():
    """The cantilever scene: the options file when the repository has it (command-line
    options after it override it), otherwise the same scene spelled out."""
    if os.path.isfile(os.path.join(REPO_ROOT, OPTIONS_FILE)):
        base = ["-options_file", OPTIONS_FILE]
    else:
        base = list(EXPLICIT)
    return base + ["-rod_elements", "32"]


def run(args, ranks=1):
    """Run petsc_rod with ``args`` from the repository root; returns CompletedProcess."""
    return run_petsc_rod(args, ranks, TIMEOUT)


def output_lines(process):
    return [line for line in (process.stdout + process.stderr).splitlines() if line.strip()]


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp("cli")


@pytest.fixture(scope="module")
def cantilever(folder):
    """One serial cantilever run: (path of its result file, the process)."""
    path = folder / "c.h5"
    process = run(cantilever_args() + ["-rod_output", str(path)])
    return path, process


def test_cantilever_run_writes_the_result_file(cantilever):
    path, process = cantilever
    assert process.returncode == 0, describe(process)
    assert path.is_file()
    assert not partial_files(path)
    with h5py.File(path, "r") as f:
        assert f["S"].shape == (33,)
        for name in ("r", "d1", "d2", "d3", "u", "m", "n"):
            assert f[name].shape == (33, 3), name
        attrs = f.attrs
        assert int(attrs["converged"]) == 1
        iterations = int(attrs["iterations"])
        assert iterations > 0
        for name in ("constraint_residual", "change", "energy", "wall_time", "ranks",
                     "load_factor"):
            assert name in attrs, name
        assert int(attrs["ranks"]) == 1
        assert float(attrs["load_factor"]) == 1.0
        assert float(attrs["wall_time"]) > 0
        assert float(attrs["constraint_residual"]) <= 1e-4
        options = attrs["options"]
        options = options.decode() if isinstance(options, bytes) else str(options)
        assert "-rod_elements 32" in options
        for name in ("change", "constraint_residual", "wall_time"):
            assert f["history"][name].shape == (iterations,), name
        history = f["history"]
        assert history["change"][-1] == pytest.approx(float(attrs["change"]), rel=1e-12)
        assert np.all(np.diff(history["wall_time"][:]) >= 0)
        assert "1" in f["steps"]
        last = f["steps"][str(len(f["steps"]))]
        assert np.array_equal(last["r"][:], f["r"][:])
        assert float(last.attrs["load_factor"]) == 1.0
        assert f["state/tau"].shape == (65, 3, 3)          # the 2 N + 1 P2 nodes
        assert f["state/lambda"].shape == (65, 3, 3)
        S = f["S"][:]
        r, d1, d2, d3 = (f[name][:] for name in ("r", "d1", "d2", "d3"))
    assert S[0] == 0.0 and S[-1] == pytest.approx(1.0, abs=1e-14)
    assert np.all(np.diff(S) > 0)
    assert np.abs(np.linalg.norm(d1, axis=1) - 1).max() < 1e-4
    assert np.abs(np.linalg.norm(d2, axis=1) - 1).max() < 1e-4
    assert np.abs(np.linalg.norm(d3, axis=1) - 1).max() < 1e-4
    assert np.abs(np.einsum("ij,ij->i", d1, d2)).max() < 1e-4
    # d3 is the tangent of the centreline: compare chords with the mean of the end
    # tangents (second order in h for a smooth curve: error ~ h^2 |r'''| / 12)
    chords = np.diff(r, axis=0) / np.diff(S)[:, None]
    mean_tangent = 0.5 * (d3[1:] + d3[:-1])
    assert np.abs(chords - mean_tangent).max() < 1e-3
    # the cantilever really bent (tip force along -y)
    assert r[-1, 1] < -0.1
    assert np.abs(r[0]).max() == 0.0


def test_restart_converges_at_once_to_the_same_state(cantilever, folder):
    path, first = cantilever
    assert first.returncode == 0, describe(first)
    second_path = folder / "c2.h5"
    # the file reached load factor 1: the restart solves one step there, from its state
    process = run(cantilever_args() + ["-rod_steps", "3", "-rod_initial", str(path),
                                       "-rod_output", str(second_path)])
    assert process.returncode == 0, describe(process)
    with h5py.File(path, "r") as f, h5py.File(second_path, "r") as g:
        first_iterations = int(f.attrs["iterations"])
        assert first_iterations >= 10        # a step with work to undo (Newton: 19)
        assert int(g.attrs["converged"]) == 1
        assert sorted(g["steps"]) == ["1"] and float(g.attrs["load_factor"]) == 1.0
        assert int(g.attrs["iterations"]) < 0.1 * first_iterations
        assert np.abs(f["r"][:] - g["r"][:]).max() < 1e-8
        assert np.abs(f["d1"][:] - g["d1"][:]).max() < 1e-8


def visit_objects(f):
    """Every group and dataset of an open file, the root included, by name."""
    found = {"/": f}
    f.visititems(lambda name, item: found.setdefault(name, item))
    return found


def test_result_file_says_what_wrote_it_with_units_and_parameters(cantilever):
    path, process = cantilever
    assert process.returncode == 0, describe(process)
    with h5py.File(path, "r") as f:
        for name, item in visit_objects(f).items():
            if isinstance(item, h5py.Dataset):
                assert str(item.attrs["units"]), name
                continue
            units = json.loads(item.attrs.get("attribute_units", "{}"))
            attributes = set(item.attrs) - {"attribute_units"}
            assert attributes == set(units), name
        attrs = f.attrs
        assert f["r"].attrs["units"] == "m" and f["state/lambda"].attrs["units"] == "N"
        assert json.loads(attrs["attribute_units"])["energy"] == "J"
        assert attrs["version"] == petsc_rod.__version__
        commit = str(attrs["commit"])
        head = subprocess.run(["git", "-C", REPO_ROOT, "rev-parse", "HEAD"],
                              capture_output=True, text=True, check=False).stdout.strip()
        if head:        # a git checkout: the file names its commit
            assert commit.split("+")[0] == head, commit
        else:
            assert commit == "unknown", commit
        written = datetime.datetime.fromisoformat(str(attrs["written"]))
        age = datetime.datetime.now(datetime.timezone.utc) - written
        assert datetime.timedelta(0) <= age < datetime.timedelta(hours=1)
        steps = [f[f"steps/{k}"] for k in sorted(f["steps"], key=int)]
        assert int(attrs["total_iterations"]) == sum(int(s.attrs["iterations"]) for s in steps)
        assert int(attrs["total_iterations"]) > int(attrs["iterations"]) or len(steps) == 1
        assert int(attrs["total_halvings"]) == 0 and int(attrs["halvings"]) == 0
        assert attrs["stop_reason"] == "converged"
        in_effect = str(attrs["options_in_effect"]).splitlines()
        assert "-rod_elements 32" in in_effect
        assert "-rod_al_max_it 2000" in in_effect         # a default, not given
        assert any(line.startswith("-rod_slope_ksp_type ") for line in in_effect)
        given = parse_options_text(str(attrs["options"]))
        parameters = f["parameters"].attrs
        assert int(parameters["elements"]) == 32
        assert float(parameters["length"]) == float(given.get("rod_length", 1.0))
        assert np.array_equal(parameters["stiffness"], given_reals(given, "rod_stiffness"))
        assert np.array_equal(parameters["end_force"], given_reals(given, "rod_end_force"))
        assert parameters["load"].shape == (1, 3)
        assert float(parameters["al_penalty"]) == float(attrs["penalty"])
        assert json.loads(parameters["attribute_units"])["stiffness"] == "N m^2"


def parse_options_text(text):
    """'-name value' lines -> {name: value}."""
    pairs = (line.lstrip("-").split(" ", 1) for line in text.splitlines() if line)
    return {pair[0]: (pair[1] if len(pair) > 1 else "") for pair in pairs}


def given_reals(given, name):
    return np.array([float(v) for v in given[name].split(",")])


def test_unknown_option_suggests_the_closest(folder):
    path = folder / "typo.h5"
    process = run(["-rod_lenght", "3", "-rod_output", str(path)])
    assert process.returncode == 2, describe(process)
    lines = output_lines(process)
    assert len(lines) == 1, describe(process)
    assert "did you mean -rod_length" in lines[0]
    assert not os.path.exists(path)
    assert not partial_files(path)


BAD_INPUTS = {
    "negative length": (["-rod_length", "-1"], "-rod_length"),
    "zero stiffness": (["-rod_stiffness", "1,0,1"], "-rod_stiffness"),
    "two stiffnesses": (["-rod_stiffness", "1,1"], "-rod_stiffness"),
    "fractional elements": (["-rod_elements", "2.5"], "-rod_elements"),
    "unknown end kind": (["-rod_start", "weld"], "-rod_start"),
    "both ends free": (["-rod_start", "free", "-rod_end", "free"], "free"),
    "end beyond reach": (["-rod_end", "pin", "-rod_end_position", "2,0,0"],
                         "-rod_end_position"),
    "frame not orthonormal": (["-rod_end", "clamp", "-rod_end_frame",
                               "1,0,0,0,1,0,0,0,2"], "-rod_end_frame"),
    "left-handed frame": (["-rod_end", "clamp", "-rod_end_frame", "0,1,0,0,0,1,-1,0,0"],
                          "-rod_end_frame"),
    "force at a clamp": (["-rod_end", "clamp", "-rod_end_force", "0,1,0"], "-rod_end_force"),
    "unknown initial shape": (["-rod_initial_shape", "helix"], "-rod_initial_shape"),
    "catenary with a free end": (["-rod_initial_shape", "catenary", "-rod_load", "0,0,-1"],
                                 "-rod_initial_shape"),
    "catenary without a load": (["-rod_initial_shape", "catenary", "-rod_end", "pin",
                                 "-rod_end_position", "0.5,0,0"], "-rod_initial_shape"),
    "catenary on one vertical": (["-rod_initial_shape", "catenary", "-rod_end", "pin",
                                  "-rod_end_position", "0,0,-0.5", "-rod_load", "0,0,-1"],
                                 "-rod_initial_shape"),
    "unknown iteration": (["-rod_snes_type", "bogus"], "-rod_snes_*"),
    "negative Anderson depth": (["-rod_snes_anderson_m", "-3"], "-rod_snes_anderson_m"),
    "malformed stability switch": (["-rod_al_stability", "maybe"], "-rod_al_stability"),
}


@pytest.mark.parametrize("case", list(BAD_INPUTS))
def test_bad_input_exits_2_with_one_line(case, folder):
    args, named = BAD_INPUTS[case]
    path = folder / f"bad_{case.replace(' ', '_')}.h5"
    process = run(["-rod_elements", "8"] + args + ["-rod_output", str(path)])
    assert process.returncode == 2, describe(process)
    lines = output_lines(process)
    assert len(lines) == 1, describe(process)
    assert named in lines[0], describe(process)
    assert not os.path.exists(path)
    assert not partial_files(path)


def test_restart_from_a_different_mesh_is_refused(cantilever, folder):
    path, first = cantilever
    assert first.returncode == 0, describe(first)
    out = folder / "mismatch.h5"
    args = [a if a != "32" else "16" for a in cantilever_args()]
    assert "16" in args
    process = run(args + ["-rod_initial", str(path), "-rod_output", str(out)])
    assert process.returncode == 2, describe(process)
    lines = output_lines(process)
    assert len(lines) == 1, describe(process)
    assert "-rod_initial" in lines[0] and "32" in lines[0]
    assert not os.path.exists(out)
    assert not partial_files(out)


def test_missing_options_file_fails_without_output(folder):
    """An unknown scene file: one line naming it, exit 2, no result file."""
    path = folder / "nofile.h5"
    process = run(["-options_file", "options/nonexistent.opts", "-rod_output", str(path)])
    assert process.returncode == 2, describe(process)
    lines = (process.stdout + process.stderr).strip().splitlines()
    assert len(lines) == 1 and "nonexistent.opts" in lines[0], describe(process)
    assert not os.path.exists(path)
    assert not partial_files(path)


def test_not_converged_exits_3_and_says_so_in_the_file(folder):
    path = folder / "capped.h5"
    process = run(cantilever_args() + ["-rod_al_max_it", "3", "-rod_output", str(path)])
    assert process.returncode == 3, describe(process)
    assert path.is_file()
    assert not partial_files(path)
    with h5py.File(path, "r") as f:
        assert int(f.attrs["converged"]) == 0
        assert int(f.attrs["iterations"]) == 3
        assert f["history/change"].shape == (3,)


def test_help_lists_every_option():
    process = run(["-help"])
    assert process.returncode == 0, describe(process)
    text = process.stdout + process.stderr
    for option in OPTIONS:
        assert f"-{option.name} " in text, option.name


def test_two_ranks_write_the_same_result(cantilever, folder):
    path, first = cantilever
    assert first.returncode == 0, describe(first)
    out = folder / "c_np2.h5"
    process = run(cantilever_args() + ["-rod_output", str(out), "-rod_ranks_split", "split"],
                  ranks=2)
    assert process.returncode == 0, describe(process)
    with h5py.File(path, "r") as f, h5py.File(out, "r") as g:
        assert int(g.attrs["ranks"]) == 2
        assert int(g.attrs["converged"]) == 1
        assert int(g.attrs["iterations"]) == int(f.attrs["iterations"])
        for name in ("S", "r", "d1", "d2", "d3"):
            assert np.abs(f[name][:] - g[name][:]).max() < 1e-10, name
        assert np.abs(f["state/tau"][:] - g["state/tau"][:]).max() < 1e-10
        assert g["history/change"].shape == f["history/change"].shape


def test_plot_of_a_result_file(cantilever, folder):
    """python -m petsc_rod.plots draws a PNG from the file alone; a wrong call exits 2."""
    path, process = cantilever
    assert process.returncode == 0, describe(process)
    figure = folder / "c.png"
    plot = subprocess.run([sys.executable, "-m", "petsc_rod.plots", str(path), str(figure)],
                          cwd=REPO_ROOT, capture_output=True, text=True, timeout=120)
    assert plot.returncode == 0, plot.stderr
    height, width, drawn = png_summary(figure)
    assert (height, width) == (4 * DPI, 16 * DPI) and drawn > 0.02
    # the curves are the file's data
    drawn_figure = result_figure(path)
    with h5py.File(path, "r") as f:
        r, S, u = f["r"][:], f["S"][:], f["u"][:]
    xy, strains = drawn_figure.axes[0].lines[0], drawn_figure.axes[3].lines
    assert np.array_equal(xy.get_xdata(), r[:, 0]) and np.array_equal(xy.get_ydata(), r[:, 1])
    assert [line.get_label() for line in strains] == ["u1", "u2", "u3"]
    assert np.array_equal(strains[2].get_xdata(), S) and np.array_equal(strains[2].get_ydata(), u[:, 2])
    wrong = subprocess.run([sys.executable, "-m", "petsc_rod.plots", str(path)],
                           cwd=REPO_ROOT, capture_output=True, text=True, timeout=120)
    assert wrong.returncode == 2 and "usage" in wrong.stderr


def readme_python_blocks():
    """The README's Python examples, in order: the api study, then the classes'."""
    with open(os.path.join(REPO_ROOT, "README.md")) as stream:
        readme = stream.read()
    blocks = readme.split("```python\n")[1:]
    return readme, [block[:block.index("```")] for block in blocks]


@pytest.mark.parametrize("index, starts", [(0, "buoyancy 500 m: top tension"),
                                           (1, "converged: True")])
def test_the_readme_python_examples_run_and_print_what_the_readme_says(tmp_path, index,
                                                                       starts):
    """The README's Python API examples, run as they stand; the last line of each is
    the one the README quotes."""
    readme, blocks = readme_python_blocks()
    script = tmp_path / "example.py"
    script.write_text(blocks[index])
    process = subprocess.run([sys.executable, str(script)], cwd=REPO_ROOT, env=child_env(),
                             capture_output=True, text=True, timeout=TIMEOUT)
    assert process.returncode == 0, describe(process)
    last = process.stdout.strip().splitlines()[-1]
    assert last.startswith(starts) and f"`{last}`" in readme, last


def test_the_step_line_is_short_and_the_monitor_adds_its_details(tmp_path):
    """Issue 24, point 6: the step line says the load factor, iterations (Newton),
    converged and stable; -rod_al_monitor adds after it the change, residual, energy and
    u3(0), which are the file's."""
    path = tmp_path / "cantilever.h5"
    plain = run(["-options_file", "options/cantilever.opts"]).stdout.splitlines()
    steps = [line for line in plain if line.startswith("step ")]
    assert steps[-1].startswith("step 2/2: load factor 1, converged in ") and \
        steps[-1].endswith(" Newton), stable"), steps
    assert not any("energy" in line or "u3(0)" in line for line in plain), plain
    verbose = run(["-options_file", "options/cantilever.opts", "-rod_al_monitor",
                   "-rod_output", str(path)]).stdout.splitlines()
    details = [line for line in verbose if line.startswith("  step 2/2 details: ")]
    with h5py.File(path, "r") as f:
        energy, change = float(f.attrs["energy"]), float(f.attrs["change"])
        u3 = float(f["u"][0, 2])
    assert len(details) == 1 and f"energy {energy:.10g} J" in details[0], verbose
    assert f"change {change:.2e}" in details[0] and f"u3(0) {u3:.6g}" in details[0]
