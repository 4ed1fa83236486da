"""A restart whose scene differs from its file's walks from the file's scene to the new one
(issue 25, docs/method.md §7, scenes/blend.py): the whole command line run in this
process (cli.main.run with the options set in PETSc's database), on the ranks pytest
runs on.

Each case writes a converged file of scene A, restarts it with scene B in STEPS steps,
and checks that (1) the walk converges to what a direct run of B from the straight state
reaches, (2) it took STEPS steps, and (3) its middle step (s = 1/2) is the equilibrium
of the scene whose loads, forces and end position are the means of A's and B's (the
blend is exact). Before issue 25 the restart took one step at t = 1 with B's whole
load: (2) and (3) fail there.
"""

import shutil

import h5py
import numpy as np
import pytest
from petsc4py import PETSc

import helpers
from petsc_rod.frames import rotation_about, rotation_log
from petsc_rod.scenes.scene import REFERENCE_FRAME

STEPS = 2
# positions agree to this fraction of the length (the iteration's tolerances are 1e-10)
AGREEMENT = 1e-7
COMMON = {"rod_elements": "16", "rod_al_rtol": "1e-10", "rod_al_ctol": "1e-10"}
# pinned at both ends under its weight: it hangs below its ends, one stable equilibrium
HANGING = {"rod_start": "pin", "rod_end": "pin", "rod_load": "0,0,-5"}

# clamped at both ends on e_x with a little slack: the link is tracked through the walk
TWISTED = {"rod_end": "clamp", "rod_end_position": "0.97,0,0", "rod_load": "0,0,-2"}
# clamped at both ends, the end turned: its frame walks along the geodesic
CANTILEVER_DOWN = {"rod_end": "clamp", "rod_end_position": "0.8,0.3,0.2"}


def tilted(axis, angle):
    """The reference frame (rows e_y, e_z, e_x) turned by ``angle`` about ``axis``."""
    return REFERENCE_FRAME @ rotation_about(axis, angle).T


def frame_option(axis, angle):
    return ",".join(f"{v:.17g}" for v in tilted(axis, angle).ravel())


def mean_frame_option(first, second):
    """The frame halfway along the geodesic between two tilted frames a and b: a turned
    by half the angle of the rotation P = b^T a that takes a's rows to b's, about its
    axis."""
    a, b = tilted(*first), tilted(*second)
    w = rotation_log(b.T @ a)
    return ",".join(f"{v:.17g}" for v in
                    (a @ rotation_about(w, 0.5 * np.linalg.norm(w)).T).ravel())


# (file's scene A, new scene B, the mean scene, the start of a run from no file)
CASES = {
    "end force": ({"rod_end_force": "0,-3,0"}, {"rod_end_force": "0,-2,1.5"},
                  {"rod_end_force": "0,-2.5,0.75"}, {}),
    "load": ({"rod_load": "0,-2,0"}, {"rod_load": "0,-1,0,0,0,-2", "rod_load_breaks": "0.4"},
             {"rod_load": "0,-1.5,0,0,-1,-1", "rod_load_breaks": "0.4"}, {}),
    "end position": ({**HANGING, "rod_end_position": "0.8,0.3,0"},
                     {**HANGING, "rod_end_position": "0.7,0.2,0.3"},
                     {**HANGING, "rod_end_position": "0.75,0.25,0.15"},
                     {"rod_initial_shape": "catenary"}),
    "end twist": ({**TWISTED, "rod_end_twist": "1"}, {**TWISTED, "rod_end_twist": "2.5"},
                  {**TWISTED, "rod_end_twist": "1.75"}, {}),
    "end frame": ({**CANTILEVER_DOWN, "rod_end_frame": frame_option([0, 0, 1], 0.3)},
                  {**CANTILEVER_DOWN, "rod_end_frame": frame_option([0, 1, 0], -0.5)},
                  {**CANTILEVER_DOWN, "rod_end_frame": mean_frame_option(
                      ([0, 0, 1], 0.3), ([0, 1, 0], -0.5))}, {}),
    # a roll above pi at an end that is not on the axis (no link tracked): walked whole,
    # not the short way round (Scene.end_frame_parts)
    "twist at a tilted end": tuple(
        {**CANTILEVER_DOWN, "rod_end_frame": frame_option([0, 0, 1], 0.3), **twist}
        for twist in ({}, {"rod_end_twist": "5"}, {"rod_end_twist": "2.5"})) + ({},),
}


def run_cli(options):
    """cli.main.run with ``options`` (and COMMON) in the database, removed afterwards;
    the exit code."""
    return helpers.run_cli({**COMMON, **options})


def positions(path, group=""):
    """r (n, 3) of the root or of step group ``group`` of a result file (every rank reads
    the whole)."""
    with h5py.File(path, "r") as f:
        return np.asarray(f[group or "/"]["r"])


def step_factors(path):
    with h5py.File(path, "r") as f:
        return [float(f["steps"][k].attrs["load_factor"]) for k in sorted(f["steps"], key=int)]


@pytest.mark.parametrize("case", list(CASES))
def test_a_restart_walks_from_the_files_scene_to_the_new_one(case, shared_tmp):
    old, new, mean, fresh = CASES[case]
    files = {name: f"{shared_tmp}/{name}.h5" for name in ("old", "walk", "direct", "mean")}
    assert run_cli({**old, **fresh, "rod_output": files["old"]}) == 0
    assert run_cli({**new, "rod_initial": files["old"], "rod_steps": str(STEPS),
                    "rod_output": files["walk"]}) == 0
    assert run_cli({**new, **fresh, "rod_steps": str(STEPS),
                    "rod_output": files["direct"]}) == 0
    assert run_cli({**mean, **fresh, "rod_steps": str(STEPS), "rod_output": files["mean"]}) == 0

    assert step_factors(files["walk"]) == [k / STEPS for k in range(1, STEPS + 1)]
    walked = positions(files["walk"])
    direct = positions(files["direct"])
    assert np.abs(walked - direct).max() <= AGREEMENT        # L = 1
    middle = positions(files["walk"], f"steps/{STEPS // 2}")
    expected = positions(files["mean"])
    assert np.abs(middle - expected).max() <= AGREEMENT


def test_a_restart_of_the_same_scene_goes_on_from_the_files_load_factor(shared_tmp):
    """The file's own scene at load factor 1/2 (-rod_initial_load_factor): today's path
    from 1/2 to 1, not a walk."""
    old, new = f"{shared_tmp}/old.h5", f"{shared_tmp}/again.h5"
    force = {"rod_end_force": "0,-3,0"}
    assert run_cli({**force, "rod_output": old}) == 0
    assert run_cli({**force, "rod_initial": old, "rod_initial_load_factor": "0.5",
                    "rod_steps": "2", "rod_output": new}) == 0
    assert step_factors(new) == [0.75, 1.0]


def test_a_restart_adding_a_current_reaches_the_direct_run_with_it(shared_tmp):
    """A hanging line (HANGING) converged without a current, restarted with one: the
    drag is walked in, (1 - s) t_f f_A + s f_B with f_A = 0, and the end is the direct
    run's with the current (both in STEPS steps; the drag, about 0.5 N/m across, bends
    the line out of its plane)."""
    current = {"rod_current": "0,1,0", "rod_drag": "1000,1,0.001"}
    line = {**HANGING, "rod_end_position": "0.8,0,0.3"}
    files = {name: f"{shared_tmp}/{name}.h5" for name in ("still", "walk", "direct")}
    assert run_cli({**line, "rod_initial_shape": "catenary", "rod_output": files["still"]}) == 0
    assert run_cli({**line, **current, "rod_initial": files["still"], "rod_steps": str(STEPS),
                    "rod_output": files["walk"]}) == 0
    assert run_cli({**line, **current, "rod_initial_shape": "catenary",
                    "rod_steps": str(STEPS), "rod_output": files["direct"]}) == 0
    assert step_factors(files["walk"]) == [k / STEPS for k in range(1, STEPS + 1)]
    walked = positions(files["walk"])
    direct = positions(files["direct"])
    still = positions(files["still"])
    assert np.abs(walked - still).max() > 1e-2           # the current moved it
    assert np.abs(walked - direct).max() <= AGREEMENT


def test_a_restart_of_the_files_own_scene_is_not_a_walk(shared_tmp):
    """The file's scene rebuilt from its parameters (a current profile from the file's
    table, pinned ends, the default end frame) is this run's: the restart goes on from the
    file's load factor 1, one step, no walk; with another profile it walks."""
    profile = f"{shared_tmp}/profile.txt"
    if PETSc.COMM_WORLD.getRank() == 0:
        with open(profile, "w", encoding="utf-8") as handle:
            handle.write("0 0 1 0\n2 0 0.5 0\n")
    PETSc.COMM_WORLD.tompi4py().Barrier()
    line = {**HANGING, "rod_end_position": "0.8,0,0.3", "rod_current_profile": profile,
            "rod_drag": "1000,1,0.001"}
    old, again, other = (f"{shared_tmp}/{name}.h5" for name in ("old", "again", "other"))
    assert run_cli({**line, "rod_initial_shape": "catenary", "rod_output": old}) == 0
    assert run_cli({**line, "rod_initial": old, "rod_steps": "2", "rod_output": again}) == 0
    assert step_factors(again) == [1.0]
    assert run_cli({**line, "rod_sea_surface": "0.5", "rod_initial": old, "rod_steps": "2",
                    "rod_output": other}) == 0
    assert step_factors(other) == [0.5, 1.0]


def test_a_file_whose_parameters_lack_an_option_is_taken_as_this_runs_scene(shared_tmp):
    """Its scene is not rebuilt from defaults (an empty group would make it an unloaded
    rod of 1 m and walk from there): the restart goes on from the file's load factor
    with this run's scene, as for a file without parameters."""
    old, new, _, _ = CASES["end force"]
    files = {name: f"{shared_tmp}/{name}.h5" for name in ("old", "new")}
    assert run_cli({**old, "rod_output": files["old"]}) == 0
    comm = PETSc.COMM_WORLD.tompi4py()
    if comm.rank == 0:
        with h5py.File(files["old"], "r+") as f:
            del f["parameters"].attrs["end_force"]
    comm.Barrier()
    assert run_cli({**new, "rod_initial": files["old"], "rod_steps": str(STEPS),
                    "rod_output": files["new"]}) == 0
    assert step_factors(files["new"]) == [1.0]


def test_a_file_written_part_way_along_a_walk_is_refused(shared_tmp):
    """A walk that stopped at s = 1/2 (here at its iteration cap, exit 3) keeps the
    state of a scene between the two, which neither scene's path gives: a restart from
    it is refused in one line (exit 2), a finished walk's file (s = 1) is not."""
    old, new, _, _ = CASES["end force"]
    files = {name: f"{shared_tmp}/{name}.h5" for name in ("old", "part", "whole", "again")}
    assert run_cli({**old, "rod_output": files["old"]}) == 0
    walk = {**new, "rod_initial": files["old"], "rod_steps": str(STEPS)}
    assert run_cli({**walk, "rod_al_max_it": "5", "rod_max_halvings": "0",
                    "rod_output": files["part"]}) == 3
    assert step_factors(files["part"]) == [0.5]
    assert run_cli({**new, "rod_initial": files["part"], "rod_output": files["again"]}) == 2
    assert run_cli({**walk, "rod_output": files["whole"]}) == 0
    assert run_cli({**new, "rod_initial": files["whole"], "rod_output": files["again"]}) == 0


def file_at(path, factor, out):
    """A copy of result file ``path`` whose root is its step at load factor ``factor``
    (as a run stopped there leaves it: the converged steps' last one at the root), on
    rank 0; every rank waits for it."""
    comm = PETSc.COMM_WORLD.tompi4py()
    if comm.rank == 0:
        shutil.copyfile(path, out)
        with h5py.File(out, "r+") as f:
            step = next(f["steps"][k] for k in f["steps"]
                        if f["steps"][k].attrs["load_factor"] == factor)
            for key in step:
                if key in f:
                    del f[key]
                f[key] = step[key]
            for key, value in step.attrs.items():
                f.attrs[key] = value
    comm.Barrier()


def step_positions(path, factor):
    """r of the step of ``path`` at load factor ``factor``."""
    with h5py.File(path, "r") as f:
        return next(np.asarray(f["steps"][k]["r"]) for k in f["steps"]
                    if f["steps"][k].attrs["load_factor"] == factor)


def test_a_restart_from_a_files_load_factor_reaches_the_uninterrupted_states(shared_tmp):
    """The scene of an end force run in 4 steps (0.25, ..., 1) without a stop, and from
    its file at load factor 1/2 in 2 steps (0.75, 1): each step of the restart is the
    uninterrupted run's state at the same load factor (a step at a wrong factor is not:
    the states at 0.75 and 1 differ by 0.077 of the length)."""
    force = {"rod_end_force": "0,-3,0"}
    files = {name: f"{shared_tmp}/{name}.h5" for name in ("whole", "half", "again")}
    assert run_cli({**force, "rod_steps": "4", "rod_output": files["whole"]}) == 0
    file_at(files["whole"], 0.5, files["half"])
    assert run_cli({**force, "rod_initial": files["half"], "rod_steps": "2",
                    "rod_output": files["again"]}) == 0
    assert step_factors(files["again"]) == [0.75, 1.0]
    for factor in (0.75, 1.0):
        assert np.abs(step_positions(files["again"], factor)
                      - step_positions(files["whole"], factor)).max() <= AGREEMENT, factor
    assert np.abs(step_positions(files["whole"], 0.75)
                  - step_positions(files["whole"], 1.0)).max() > 1e-2


def test_a_walk_from_a_file_at_load_factor_one_half(shared_tmp):
    """A walk from scene A's file at t_f = 1/2 to scene B (end forces F_A, F_B) carries
    (1 - s) F_A / 2 + s F_B: its middle step is the equilibrium of F_A / 4 + F_B / 2, its
    end B's (a walk that took A's file at t = 1 reaches F_A / 2 + F_B / 2 at its middle,
    0.10 of the length away)."""
    old, new = {"rod_end_force": "0,-3,0"}, {"rod_end_force": "0,-2,1.5"}
    files = {name: f"{shared_tmp}/{name}.h5"
             for name in ("old", "half", "walk", "direct", "mean", "wrong")}
    assert run_cli({**old, "rod_steps": "2", "rod_output": files["old"]}) == 0
    file_at(files["old"], 0.5, files["half"])
    assert run_cli({**new, "rod_initial": files["half"], "rod_steps": str(STEPS),
                    "rod_output": files["walk"]}) == 0
    assert run_cli({**new, "rod_steps": str(STEPS), "rod_output": files["direct"]}) == 0
    assert run_cli({"rod_end_force": "0,-1.75,0.75", "rod_steps": str(STEPS),
                    "rod_output": files["mean"]}) == 0
    assert run_cli({"rod_end_force": "0,-2.5,0.75", "rod_steps": str(STEPS),
                    "rod_output": files["wrong"]}) == 0
    assert step_factors(files["walk"]) == [k / STEPS for k in range(1, STEPS + 1)]
    assert np.abs(positions(files["walk"]) - positions(files["direct"])).max() <= AGREEMENT
    middle = positions(files["walk"], f"steps/{STEPS // 2}")
    assert np.abs(middle - positions(files["mean"])).max() <= AGREEMENT
    assert np.abs(positions(files["wrong"]) - positions(files["mean"])).max() > 1e-2
