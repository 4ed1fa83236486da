"""The README's api study (petsc_rod/api, issue 24 point 7) against the command line:
the study run as the README has it on 2 ranks, and options/lazy_wave_types.opts on the
same 2 m elements through ``python -m petsc_rod`` on 2 ranks; at 400 m of buoyancy they
are the same scene, and their numbers agree to 1e-9. Spawns processes: marked
``serial``."""

import json
import subprocess
import sys

import h5py
import pytest

from helpers import (REPO_ROOT, child_env, describe, mpiexec, partial_files,
                     run_failing_on_rank_1, run_petsc_rod)
from test_cli import readme_python_blocks

pytestmark = pytest.mark.serial

TIMEOUT = 300
# options/lazy_wave_types.opts on the README study's mesh (element_length 2 m)
CLI_SECTIONS = "umbilical:600:300,buoyancy:400:200,umbilical:1000:500"
NUMBERS = ("top_tension", "top_angle", "touchdown_S", "min_bend_radius", "max_curvature_S",
           "energy")


def test_the_readme_study_agrees_with_the_command_line(tmp_path):
    _, blocks = readme_python_blocks()
    script = tmp_path / "study.py"
    dump = tmp_path / "study.json"
    script.write_text(blocks[0] + f"""
import json
if PETSc.COMM_WORLD.getRank() == 0:
    with open({str(dump)!r}, "w") as out:
        json.dump({{str(k): {{n: float(getattr(v, n)) for n in {NUMBERS!r}}}
                   for k, v in study.items()}}, out)
along = study[400.0].along_line(["S", "effective_tension"])
assert along["S"].shape == (1001,) and study[400.0].units["effective_tension"] == "N"
""")
    process = subprocess.run(mpiexec(2) + [sys.executable, str(script)], cwd=REPO_ROOT,
                             env=child_env(), capture_output=True, text=True, timeout=TIMEOUT)
    assert process.returncode == 0, describe(process)
    with open(dump) as stream:
        study = json.load(stream)
    assert study["300.0"]["top_tension"] > study["400.0"]["top_tension"] \
        > study["500.0"]["top_tension"]             # more buoyancy, less to hold up
    path = tmp_path / "cli.h5"
    done = run_petsc_rod(["-options_file", "options/lazy_wave_types.opts", "-rod_sections",
                          CLI_SECTIONS, "-rod_output", str(path)], 2, TIMEOUT)
    assert done.returncode == 0, describe(done)
    with h5py.File(path, "r") as f:
        cli = {name: float(f.attrs[name]) for name in NUMBERS}
    for name in NUMBERS:
        assert study["400.0"][name] == pytest.approx(cli[name], rel=1e-9, abs=1e-9), name


def test_a_model_exported_as_options_solves_to_the_same_numbers(tmp_path):
    """The API compiles its model directly (no option texts); Model.write_options exports
    the same problem as an options file and its tables, which the command line solves to
    the same numbers, bit for bit: a riser of two line types with a flex joint, an
    attachment, a current profile and a seabed, 80 elements."""
    import numpy as np
    from petsc4py import PETSc

    from petsc_rod.api import Attachment, End, Environment, Line, LineType, Model, solve

    pipe = LineType("pipe", od=0.2, mass=60.0, ei=1e5, gj=8e4, cd=1.0)
    floaty = LineType("floaty", od=0.5, mass=170.0, ei=1e5, gj=8e4, cd=1.0, drag_d=0.45)
    model = Model(Line([(pipe, 60.0), (floaty, 30.0), (pipe, 70.0)], element_length=2.0),
                  start=End.anchor((0.0, 0.0, 0.0)),
                  end=End.hang_off((100.0, 0.0, 55.0), flex_joint=1e4, axis=(0, 0, 1)),
                  environment=Environment(seabed=0.0, surface=60.0, current=[
                      [0.0, 0.4, 0.1, 0.0], [60.0, 0.1, 0.0, 0.0]]),
                  attachments=(Attachment(100.0, mass=200.0, name="clump"),),
                  steps=2, initial_shape="straight")
    api_file, cli_file = tmp_path / "api.h5", tmp_path / "cli.h5"
    results = solve(model, comm=PETSc.COMM_SELF, output=str(api_file))
    assert results.converged
    model.write_options(tmp_path / "model.opts")
    done = run_petsc_rod(["-options_file", str(tmp_path / "model.opts"), "-rod_output",
                          str(cli_file)], 1, TIMEOUT)
    assert done.returncode == 0, describe(done)
    with h5py.File(api_file, "r") as api, h5py.File(cli_file, "r") as cli:
        along = [name for name in api if isinstance(api[name], h5py.Dataset)]
        assert "r" in along and set(along) <= set(cli)
        for name in along:                  # the last step's arrays along the line
            assert np.array_equal(api[name][()], cli[name][()], equal_nan=True), name
        for name in NUMBERS:
            assert float(api.attrs[name]) == float(cli.attrs[name]), name
        assert float(cli.attrs["top_tension"]) == results.top_tension
        # the run's record, the API's from the model itself: the command line's, but for
        # the names of the files the export wrote
        ours, theirs = dict(api["parameters"].attrs), dict(cli["parameters"].attrs)
    files = {"output", "line_types", "point_loads", "current_profile", "seabed_profile"}
    assert set(ours) == set(theirs) and len(ours) > 60
    assert json.loads(ours.pop("attribute_units")) == json.loads(theirs.pop("attribute_units"))
    for name in sorted(set(ours) - files):
        assert np.array_equal(np.asarray(ours[name]), np.asarray(theirs[name])), name
# with rank 1 failing alone (helpers.ONE_RANK_FAILS), a small line through api.solve
API_RUN = """
from petsc_rod.api import End, Line, LineType, Model, solve
pipe = LineType("pipe", od=0.2, mass=60.0, ei=1e5, gj=8e4)
model = Model(line=Line([(pipe, 100.0)], element_length=5.0),
              start=End.anchor((0.0, 0.0, 0.0)), end=End.hang_off((80.0, 0.0, 30.0)),
              initial_shape="catenary")
solve(model, output=sys.argv[1])
"""


def test_an_exception_on_one_rank_alone_ends_the_api_without_a_file(tmp_path):
    """api.solve with a result file, an exception other than a RodError raised on one
    rank only: every rank ends (no hang) with the failing rank's one line, exit 4, and
    neither the result nor its partial file is left."""
    path = tmp_path / "out.h5"
    done = run_failing_on_rank_1(tmp_path / "api_one_rank_fails.py", API_RUN, [str(path)])
    assert done.returncode == 4, describe(done)
    errors = [line for line in done.stdout.splitlines() if line.startswith("petsc_rod: error")]
    assert len(errors) == 1 and "rank 1 failed alone (FloatingPointError" in errors[0], \
        describe(done)
    assert "Traceback" not in done.stdout + done.stderr, describe(done)
    assert not path.exists() and not partial_files(path)
