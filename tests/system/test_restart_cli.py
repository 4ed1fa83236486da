"""Issue 25 from the command line (spawns python -m petsc_rod: serial): the lazy wave
(options/lazy_wave.opts on 400 elements, a few seconds) restarted with a current its
file did not have walks from the file's scene to the new one, and a restart whose step
moves no load ends at once instead of retrying it at increment 0."""

import h5py
import pytest

from helpers import describe, run_petsc_rod

TIMEOUT = 120
LAZY_WAVE = ["-options_file", "options/lazy_wave.opts", "-rod_elements", "400"]
# a modest current across the line's plane: a drag of about 0.9 N/m on its 300 N/m
CURRENT = ["-rod_current", "0,0.1,0", "-rod_drag", "1025,1.2,0.15"]


@pytest.fixture(scope="module")
def lazy_wave(tmp_path_factory):
    """The converged lazy wave without a current (its result file)."""
    path = tmp_path_factory.mktemp("restart") / "lazy_wave.h5"
    process = run_petsc_rod(LAZY_WAVE + ["-rod_output", str(path)], timeout=TIMEOUT)
    assert process.returncode == 0, describe(process)
    return path


@pytest.mark.serial
def test_a_current_added_on_restart_is_walked_in(lazy_wave, tmp_path):
    """The reproduction of issue 25 with a modest current: exit 0, no 'increment 0', the
    line that says the restart walks (naming the current) and -rod_steps steps."""
    path = tmp_path / "with_current.h5"
    process = run_petsc_rod(LAZY_WAVE + CURRENT + ["-rod_initial", str(lazy_wave),
                                                   "-rod_steps", "2", "-rod_output", str(path)],
                            timeout=TIMEOUT)
    assert process.returncode == 0, describe(process)
    assert "increment 0" not in process.stdout, describe(process)
    walks = [line for line in process.stdout.splitlines() if "walks from the file's scene" in line]
    assert len(walks) == 1 and "-rod_current" in walks[0], describe(process)
    # the scene file's catenary start gives way to the restart file, said in one line
    assert "-rod_initial_shape catenary is not used" in process.stdout, describe(process)
    with h5py.File(path, "r") as f:
        assert [f["steps"][k].attrs["load_factor"] for k in sorted(f["steps"], key=int)] \
            == [0.5, 1.0]


@pytest.mark.serial
def test_a_failed_step_that_moves_no_load_ends_the_run(lazy_wave):
    """The file's own scene at its own load factor 1 with a tolerance below round-off
    (the restart is the fixed point: change 4e-14 at the first iteration, then 1e-14 to
    7e-15), which 5 iterations cannot meet: exit 3 at once, saying why; no retry at
    increment 0."""
    process = run_petsc_rod(LAZY_WAVE + ["-rod_initial", str(lazy_wave), "-rod_al_max_it", "5",
                                         "-rod_al_rtol", "1e-16"], timeout=TIMEOUT)
    assert process.returncode == 3, describe(process)
    assert "increment 0" not in process.stdout and "retrying" not in process.stdout, \
        describe(process)
    assert "moves no load, so halving it cannot help" in process.stdout, describe(process)


# The 3 km catenary on 20 elements (a fraction of a second from its catenary start) in
# a cross current, and two attachments with drag areas: a restart that adds or removes
# them walks from the file's scene to this one and ends where a run of this scene from
# its own start does.
CATENARY = ["-options_file", "options/catenary.opts", "-rod_elements", "20",
            "-rod_current", "0,0.5,0", "-rod_drag", "1025,1.2,0.2"]
ATTACHMENTS = "s fz cda\n1000 -5e5 1\n2000 2e5 2\n"


def final_positions(path):
    with h5py.File(path, "r") as f:
        assert f.attrs["converged"] == 1
        return f["r"][:]


@pytest.fixture(scope="module")
def catenary_runs(tmp_path_factory):
    """{'plain': the catenary's file, 'attached': with the attachments} from their own
    starts, and the attachments' table."""
    folder = tmp_path_factory.mktemp("attachments")
    table = folder / "attachments.txt"
    table.write_text(ATTACHMENTS)
    files = {}
    for name, extra in (("plain", []), ("attached", ["-rod_point_loads", str(table)])):
        files[name] = folder / f"{name}.h5"
        process = run_petsc_rod(CATENARY + extra + ["-rod_output", str(files[name])],
                                timeout=TIMEOUT)
        assert process.returncode == 0, describe(process)
    return files, table


@pytest.mark.serial
@pytest.mark.parametrize("source, target", [("plain", "attached"), ("attached", "plain")])
def test_a_restart_that_adds_or_removes_attachments(catenary_runs, tmp_path, source, target):
    files, table = catenary_runs
    extra = ["-rod_point_loads", str(table)] if target == "attached" else []
    path = tmp_path / "restarted.h5"
    process = run_petsc_rod(CATENARY + extra + ["-rod_initial", str(files[source]),
                                             "-rod_steps", "2", "-rod_output", str(path)],
                            timeout=TIMEOUT)
    assert process.returncode == 0, describe(process)
    assert "Traceback" not in process.stdout + process.stderr
    walks = [line for line in process.stdout.splitlines() if "walks from the file's scene" in line]
    assert len(walks) == 1 and "the point loads" in walks[0], describe(process)
    # the state of this scene, not the file's: within the tolerance of the own start's run
    # (measured 2e-7 m), where the attachments move the line by 57 m
    difference = abs(final_positions(path) - final_positions(files[target])).max()
    assert difference < 1e-5, difference
    assert abs(final_positions(files["plain"]) - final_positions(files["attached"])).max() > 10


def test_every_field_a_restart_compares_names_its_options():
    """A Scene field that a restart compares (scenes/blend.py) without the options behind
    it in scene_options.FIELD_OPTIONS was a KeyError as soon as it differed (the
    attachments' drag areas)."""
    from petsc_rod.cli.scene_options import FIELD_OPTIONS
    from petsc_rod.scenes.blend import FIXED_FIELDS, PATH_FIELDS

    assert set(PATH_FIELDS + FIXED_FIELDS) <= set(FIELD_OPTIONS)
