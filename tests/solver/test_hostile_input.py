"""Hostile input, in process (serially and on 2 ranks): option values that are not
finite or out of range, ranks that disagree, meshes too large, output paths that cannot
be written, a disk that fills up, restart files that are damaged, and the load path of a
restart. Every refusal must reach every rank (errors.on_every_rank), or a rank would go
on into a collective call alone. The same classes end to end: test_hostile_cli.py.
"""

import os
import re

import h5py
import numpy as np
import pytest
from petsc4py import PETSc

from helpers import partial_files
from petsc_rod import resources
from petsc_rod.cli.line_run import MIN_RELATIVE_ELEMENT, check_mesh
from petsc_rod.cli.options import (MAX_HALVINGS_CAP, MAX_MAGNITUDE, check_same_on_every_rank,
                               read_options)
from petsc_rod.cli.session import record_step
from petsc_rod.errors import RodInputError, RodIOError, on_every_rank
from petsc_rod.io import outputs
from petsc_rod.io import results as io
from petsc_rod.iteration.continuation import LoadPath
from petsc_rod.mesh.mesh import Mesh
from petsc_rod.resources import BYTES_PER_ELEMENT, MAX_ELEMENTS, check_elements_fit

CANTILEVER = dict(length=1.0, stiffness=(1.0, 1.0, 1.0), start="clamp", end="free",
                  end_force=(0.0, -1.0, 0.0))


# --- option values ---------------------------------------------------------------------
REFUSED = {
    "nan load": ("rod_load", "nan,0,0", "finite"),
    "inf end force": ("rod_end_force", "0,inf,0", "finite"),
    "nan end position": ("rod_end_position", "nan,0,0", "finite"),
    "nan in the end frame": ("rod_end_frame", "0,1,0,0,0,1,1,0,nan", "finite"),
    "inf twist": ("rod_end_twist", "inf", "finite"),
    "nan grading": ("rod_mesh_grading", "nan", "finite"),
    "inf penalty": ("rod_al_penalty", "inf", "finite"),
    "nan imperfection": ("rod_imperfection", "nan", "finite"),
    "inf load break": ("rod_load_breaks", "0.5,inf", "finite"),
    "inf rtol": ("rod_al_rtol", "inf", "finite"),
    "rtol of 1": ("rod_al_rtol", "1", "below 1"),
    "zero ctol": ("rod_al_ctol", "0", "positive"),
    "inf elements": ("rod_elements", "inf", "whole number"),
    "word elements": ("rod_elements", "abc", "whole number"),
    "word Newton switch": ("rod_al_newton", "maybe", "true or false"),
    "elements beyond a PETSc integer": ("rod_elements", "1e12", "PETSc integer"),
    "inf steps": ("rod_steps", "inf", "whole number"),
    "nan steps": ("rod_steps", "nan", "whole number"),
    "huge length": ("rod_length", "1e200", "out of range"),
    "tiny length": ("rod_length", "1e-40", "positive"),
    "huge stiffness": ("rod_stiffness", "1,1e31,1", "out of range"),
    "too many halvings": ("rod_max_halvings", str(MAX_HALVINGS_CAP + 1), "between"),
    "load factor above 1": ("rod_initial_load_factor", "1.5", "between 0 and 1"),
}


@pytest.mark.parametrize("case", list(REFUSED))
def test_a_value_out_of_its_range_is_refused(options, case):
    name, text, words = REFUSED[case]
    read = options(**{name: text})
    with pytest.raises(RodInputError) as error:
        read()
    message = str(error.value)
    assert message.startswith(f"-{name} ") and text in message and words in message, message


def test_the_limits_themselves_are_accepted(options):
    read = options(rod_length=f"{MAX_MAGNITUDE:g}", rod_al_rtol=f"{1 / MAX_MAGNITUDE:g}",
                   rod_max_halvings=str(MAX_HALVINGS_CAP), rod_elements="2147483647",
                   rod_load="-1e30,0,0")
    values, _ = read()
    assert values["rod_length"] == MAX_MAGNITUDE
    assert values["rod_max_halvings"] == MAX_HALVINGS_CAP
    assert values["rod_elements"] == 2147483647


# --- ranks -----------------------------------------------------------------------------
def test_an_error_on_one_rank_is_raised_on_every_rank(comm):
    mpi = comm.tompi4py()
    last = mpi.Get_size() - 1

    def action(rank):
        if rank == last:
            raise RodIOError(f"failed on rank {rank}")
        return rank

    with pytest.raises(RodIOError, match=f"failed on rank {last}"):
        on_every_rank(comm, action, mpi.Get_rank())
    assert on_every_rank(comm, lambda: "fine") == "fine"


def test_options_given_to_one_rank_only_are_refused_on_every_rank(comm):
    mpi = comm.tompi4py()
    if mpi.Get_size() == 1:
        check_same_on_every_rank(comm)          # one rank agrees with itself
        pytest.skip("needs 2 ranks (test_hostile_cli runs the same through mpiexec)")
    database = PETSc.Options()
    if mpi.Get_rank() == 1:
        database.setValue("rod_al_monitor", "")
    try:
        with pytest.raises(RodInputError, match="rank 1 .*-rod_al_monitor"):
            check_same_on_every_rank(comm)
    finally:
        if mpi.Get_rank() == 1:
            database.delValue("rod_al_monitor")
    check_same_on_every_rank(comm)


# --- what the machine can hold ---------------------------------------------------------
def test_a_mesh_too_large_for_the_memory_is_refused_with_the_numbers(comm):
    with pytest.raises(RodInputError, match="memory") as error:
        check_elements_fit(comm, 10**9)         # 8 TB: more than any test machine has
    assert "-rod_elements 1000000000" in str(error.value)
    assert f"{BYTES_PER_ELEMENT // 1024} KiB per element" in str(error.value)
    with pytest.raises(RodInputError, match="PETSc's integers"):
        check_elements_fit(comm, MAX_ELEMENTS + 1)
    check_elements_fit(comm, 1000)


def test_the_anderson_depth_keeps_the_history_in_proportion(monkeypatch):
    """Issue 21: the default depth is 30 on lines up to 1e4 elements a machine (the
    hard scenes need it); beyond, the depth whose history (576 bytes per element per
    unit) fits what 30 units take at 1e4 elements (its set-up about 0.1 s: 16 at
    18 000 elements) or 3 KiB per element, whichever is larger: 5 at 1e5 and 1e6
    elements, where the whole run then stays within 10 KiB per element
    (docs/performance.md, "Memory in proportion"). The machine's memory only lowers
    it."""
    monkeypatch.setattr(resources, "available_memory", lambda: 64 * 2**30)
    depth = resources.anderson_depth
    assert depth(1800, 1) == depth(10**4, 1) == depth(5000, 2) == 30
    assert depth(10**4 + 1, 1) == 29
    assert depth(18000, 1) == depth(9000, 2) == 16   # 18 000 elements on one machine
    assert depth(10**5, 1) == depth(10**6, 1) == depth(5 * 10**4, 2) == 5
    assert 5 < depth(5 * 10**4, 1) < 30
    for elements in (10**5, 10**6, 10**7):
        history = depth(elements, 1) * resources.ANDERSON_BYTES * elements
        assert history <= 3 * 2**10 * elements
    monkeypatch.setattr(resources, "available_memory", lambda: 2**29)
    assert depth(10**4, 1) == 23                # a quarter of 512 MiB
    assert depth(10**6, 1) == resources.MIN_DEPTH


def test_fewer_vertices_than_ranks_are_refused(comm):
    size = comm.getSize()
    if size == 1:
        pytest.skip("one rank always owns a vertex")
    with pytest.raises(RodInputError, match=f"on {size} ranks"):
        check_elements_fit(comm, size - 2)
    check_elements_fit(comm, size - 1)


def test_a_grading_double_precision_cannot_resolve_is_refused(comm, monkeypatch):
    # the memory check comes first; this test is about the grading, whatever memory the
    # machine has free at the moment
    monkeypatch.setattr(resources, "available_memory", lambda: None)
    values = {"rod_elements": 1000000, "rod_length": 1.0, "rod_mesh_grading": 1e30}
    with pytest.raises(RodInputError, match="-rod_mesh_grading") as error:
        check_mesh(comm, values)
    assert f"{MIN_RELATIVE_ELEMENT:g}" in str(error.value)
    check_mesh(comm, dict(values, rod_mesh_grading=20.0))


@pytest.mark.parametrize("elements, grading", [(1, 1.5), (2, 2.0), (3, 3.2), (16, 1e9)])
def test_a_grading_the_mesh_cannot_build_is_refused(comm, elements, grading):
    """Issue 25: -rod_mesh_grading 1e9 on 16 elements built a ratio of 77.4, and 2 elements
    stayed uniform, while the file said 1e9: refused, naming the option, the element
    count and what can be built."""
    from petsc_rod.mesh.mesh import largest_grading
    values = {"rod_elements": elements, "rod_length": 1.0, "rod_mesh_grading": grading}
    with pytest.raises(RodInputError, match=re.escape(f"-rod_mesh_grading {grading:g} with "
                                                      f"{elements} elements")) as error:
        check_mesh(comm, values)
    assert "-rod_elements" in str(error.value)
    if elements > 2:
        check_mesh(comm, dict(values, rod_mesh_grading=largest_grading(elements)))
    check_mesh(comm, dict(values, rod_mesh_grading=1.0))


def test_the_built_mesh_has_the_asked_grading(comm):
    """The distributed mesh's elements (each rank its own) have largest / smallest equal
    to -rod_mesh_grading to round-off, and the node weights add up to the length."""
    from petsc_rod.mesh.mesh import Mesh
    for elements, grading in ((3, 3.0), (16, 77.0), (17, 20.0), (64, 4.0), (301, 1e4)):
        mesh = Mesh(comm, elements, 2.0, grading)
        try:
            largest = mesh.global_max(float(mesh.element_h.max(initial=0.0)))
            assert abs(largest / mesh.smallest_element - grading) < 1e-12 * grading
            assert abs(mesh.global_sum(float(mesh.node_weights().sum())) - 2.0) < 1e-13
        finally:
            mesh.destroy()


# --- the output path -------------------------------------------------------------------
def unwritable_paths(folder):
    """Output paths that no run can write, by what is wrong with them."""
    paths = {"a folder": folder, "a missing folder": os.path.join(folder, "no", "x.h5"),
             "a device": os.devnull}
    if os.path.isdir("/proc/self"):
        paths["a special file system"] = "/proc/petsc_rod_test.h5"
    return paths


def test_an_output_that_cannot_be_written_is_refused_before_the_run(comm, shared_tmp):
    for what, path in unwritable_paths(shared_tmp).items():
        with pytest.raises(RodInputError, match="-rod_output") as error:
            io.check_output_path(path, comm)
        assert path in str(error.value), what
    good = os.path.join(shared_tmp, "good.h5")
    io.check_output_path(good, comm)
    comm.tompi4py().Barrier()
    assert not os.path.exists(good) and not partial_files(good)


# --- writing and reading a result ------------------------------------------------------
def write_result(solver, path, attributes=None):
    """A result file of the solver's current state (one step at load factor 1)."""
    report = solver.solve_step(1.0)
    writer = io.ResultWriter(path, solver.problem.mesh)
    try:
        recorded = record_step(solver.problem, report, 1.0, writer, "steps/1", wall_time=0.0,
                               options="", halvings=0, total_halvings=0,
                               total_iterations=report.iterations, undone_iterations=0)
        writer.finish("steps/1", {**recorded.attributes, **(attributes or {})})
    finally:
        if writer.file is not None:
            writer.abort()
    return report


def test_a_full_disk_ends_the_run_on_every_rank_and_removes_the_partial_file(
        solver_factory, comm, shared_tmp, monkeypatch):
    mesh, solver = solver_factory(comm, 8, CANTILEVER, 10.0, 1e-6, 1e-4, 500)
    solver.problem.state.set_straight()
    path = os.path.join(shared_tmp, "full.h5")
    monkeypatch.setattr(io, "free_disk", lambda folder: 1000)
    with pytest.raises(RodInputError, match="free"):
        io.ResultWriter(path, mesh, minimum_bytes=10**6)
    writer = io.ResultWriter(path, mesh)
    assert os.path.exists(writer.partial)
    with pytest.raises(RodIOError, match="disk .* is full"):
        report = solver.solve_step(1.0)
        record_step(solver.problem, report, 1.0, writer, "steps/1", wall_time=0.0, options="",
                    halvings=0, total_halvings=0, total_iterations=1, undone_iterations=0)
    writer.abort()
    comm.tompi4py().Barrier()
    assert not partial_files(path) and not os.path.exists(path)
    assert not io.hdf5_failed()          # a refused step never reached HDF5


@pytest.fixture
def result(solver_factory, comm, shared_tmp):
    """(solver, path of a converged result file of it)."""
    mesh, solver = solver_factory(comm, 8, CANTILEVER, 10.0, 1e-6, 1e-4, 2000)
    solver.problem.state.set_straight()
    path = os.path.join(shared_tmp, "result.h5")
    assert write_result(solver, path).converged
    return solver, path


def damaged_copy(comm, path, name, damage):
    """A copy of result file ``path`` damaged by ``damage(file)`` (on rank 0)."""
    copy = os.path.join(os.path.dirname(path), f"{name}.h5")
    mpi = comm.tompi4py()
    if mpi.Get_rank() == 0:
        with open(path, "rb") as source, open(copy, "wb") as target:
            target.write(source.read())
        with h5py.File(copy, "a") as f:
            damage(f)
    mpi.Barrier()
    return copy


def replace(f, name, values):
    del f[name]
    f.create_dataset(name, data=values)


DAMAGES = {
    "a dataset missing": (lambda f: f["state"].__delitem__("lambda"), "state/lambda is missing"),
    "tau of another shape": (lambda f: replace(f, "state/tau", f["state/tau"][:, :-1]),
                             "state/tau has shape"),
    "NaN on the last rank's rows": (lambda f: replace(f, "r", np.where(
        np.arange(len(f["r"]))[:, None] == len(f["r"]) - 1, np.nan, f["r"][:])), "r holds NaN"),
    "no load factor": (lambda f: f.attrs.__delitem__("load_factor"), "load_factor is missing"),
    "a load factor above 1": (lambda f: f.attrs.__setitem__("load_factor", 2.0), "not in [0, 1]"),
    "another mesh": (lambda f: replace(f, "S", f["S"][:] * 1.5), "mesh"),
    "other element count": (lambda f: replace(f, "S", np.linspace(0, 1, 5)), "4 elements"),
    # issue 25: numpy's ComplexWarning, and the imaginary part dropped
    "a complex tau": (lambda f: replace(f, "state/tau", f["state/tau"][:] * (1 + 1e-3j)),
                      "state/tau holds complex128 values, not real numbers"),
}


@pytest.mark.parametrize("case", list(DAMAGES))
def test_a_damaged_restart_file_is_refused_on_every_rank(result, comm, case):
    solver, path = result
    damage, words = DAMAGES[case]
    copy = damaged_copy(comm, path, case.replace(" ", "_"), damage)
    with pytest.raises(RodInputError) as error:
        io.read_restart(copy, solver.problem.mesh, outputs.restart_state(solver.problem))
    message = str(error.value)
    assert message.startswith(f"-rod_initial {copy}: ") and words in message, message


def test_a_restart_file_locked_by_another_process_is_refused_saying_so(result, comm):
    """Issue 25: a restart file another process holds open for writing said 'not an
    HDF5 result file'."""
    import subprocess
    import sys
    solver, path = result
    holder = None
    if comm.getRank() == 0:          # HDF5's file lock, held by another process
        holder = subprocess.Popen([sys.executable, "-c", "import h5py, sys; "
                                   "f = h5py.File(sys.argv[1], 'a'); print('open', flush=True); "
                                   "sys.stdin.read()", path],
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        assert holder.stdout.readline().strip() == "open"
    comm.tompi4py().Barrier()
    try:
        with pytest.raises(RodInputError, match="locked by another process"):
            io.read_restart(path, solver.problem.mesh, outputs.restart_state(solver.problem))
    finally:
        comm.tompi4py().Barrier()
        if holder is not None:
            holder.communicate("", timeout=30)


def test_the_expected_shapes_come_from_the_solver_arrays(result, comm):
    """The validation takes its shapes from outputs.restart_state: templates of another
    shape make the (good) file wrong."""
    solver, path = result
    templates = {key: np.zeros(value.shape[:1] + (7,)) for key, value in
                 outputs.restart_state(solver.problem).items()}
    with pytest.raises(RodInputError, match="has shape"):
        io.read_restart(path, solver.problem.mesh, templates)


def test_a_good_restart_file_gives_back_the_state(result, comm):
    solver, path = result
    saved = {key: np.array(value) for key, value in outputs.restart_state(solver.problem).items()}
    restart = io.read_restart(path, solver.problem.mesh, outputs.restart_state(solver.problem))
    assert restart.load_factor == 1.0 and restart.converged
    for key, value in saved.items():
        assert np.array_equal(restart.state[key], value), key
    assert np.array_equal(restart.vertex["r"], solver.problem.state.r.owned()[:, 0])


# --- the load path of a restart --------------------------------------------------------
def test_a_restart_load_path_goes_on_from_its_load_factor():
    path = LoadPath(4, 2, start=0.5)
    factors = []
    while not path.finished:
        factors.append(path.next_factor)
        path.accept()
    assert factors[:-1] == pytest.approx([0.625, 0.75, 0.875], rel=1e-15)
    assert factors[-1] == 1.0 and path.factor(0) == 0.5
    assert LoadPath(4, 2, start=1.0).steps == 1
    plain = LoadPath(3, 1)
    assert [plain.factor(u) for u in range(7)] == [u / 6 for u in range(7)]


# --- values derived from accepted input (issue 25) -------------------------------------
DERIVED = {
    "a current of 1e20 m/s": (dict(rod_current="1e20,0,0", rod_drag="1025,1.2,0.3"),
                              "-rod_current with -rod_drag"),
    "a drag coefficient of 1e60": (dict(rod_current="1,0,0", rod_drag="1e30,1,1e30"),
                                   "-rod_drag"),
    "an end force of 1e30 with a load of 1e30 N/m": (dict(rod_end_force="0,1e30,0",
                                                          rod_load="0,1e30,0"),
                                                     "-rod_load (with -rod_length)"),
    "a default penalty of 1e38 N": (dict(rod_stiffness="1e30,1e30,1e30", rod_length="1e-3"),
                                    "-rod_stiffness with -rod_length: the default "
                                    "-rod_al_penalty"),
    "a default penalty from the twist": (dict(rod_end="clamp", rod_end_twist="1e20",
                                              rod_stiffness="1,1,1e10"),
                                         "-rod_end_twist"),
    "a seabed of 1e25 N/m^2": (dict(rod_end="pin", rod_end_position="0.5,0,0.5",
                                    rod_load="0,0,-1", rod_seabed="0",
                                    rod_seabed_stiffness="1e25"), "-rod_seabed_stiffness 1e+25"),
    "a default seabed stiffness above the bound": (dict(rod_end="pin", rod_length="1e20",
                                                        rod_end_position="1e19,0,1e18",
                                                        rod_load="0,0,-1", rod_seabed="0"),
                                                   "-rod_load: the default "
                                                   "-rod_seabed_stiffness"),
}


@pytest.mark.parametrize("case", list(DERIVED))
def test_a_derived_value_out_of_range_is_refused_naming_its_option(options, case):
    """A current of 1e20 m/s derived a default penalty of 3.1e40 N, above the 1e30 that
    -rod_al_penalty accepts, and ran 10 000 iterations: every derived force, drag,
    penalty and seabed stiffness is held to the options' bound, before any work."""
    from petsc_rod.cli.scene_options import scene_from_options, settings_from_options
    given, named = DERIVED[case]
    values, names = options(**given)()
    with pytest.raises(RodInputError) as error:
        settings_from_options(values, scene_from_options(values, names))
    assert str(error.value).startswith(named), str(error.value)


def test_the_derived_bounds_accept_what_is_within_them(options):
    """Just inside: 1e14 m/s would be refused, 1e10 m/s derives a drag of 1.8e22 N/m."""
    from petsc_rod.cli.scene_options import scene_from_options, settings_from_options
    values, names = options(rod_current="1e10,0,0", rod_drag="1025,1.2,0.3")()
    settings = settings_from_options(values, scene_from_options(values, names))
    assert 1e21 < settings.asked_penalty <= MAX_MAGNITUDE


def test_a_profile_above_the_bound_is_refused_when_read(tmp_path_factory, comm):
    from petsc_rod.environment.profiles import read_profile
    folder = tmp_path_factory.mktemp("profile") if comm.getRank() == 0 else None
    folder = comm.tompi4py().bcast(folder)
    path = folder / "huge.txt"
    if comm.getRank() == 0:
        path.write_text("0 0 0 0\n10 1e300 0 0\n")
    comm.tompi4py().barrier()
    with pytest.raises(RodInputError, match="row 2 holds a magnitude above 1e"):
        read_profile(str(path), MAX_MAGNITUDE)
    depths, velocities = read_profile(str(path))            # no bound: read as it is
    assert velocities[1, 0] == 1e300


def test_ends_a_little_too_far_apart_say_by_how_much():
    """Issue 25: ends 1.0000001 m apart on a 1 m line said "1 m apart but only 1 m long"."""
    from petsc_rod.scenes.scene import Scene
    scene = Scene(length=1.0, stiffness=[1.0, 1.0, 1.0], start="clamp", end="pin",
                  end_position=[1.0000001, 0.0, 0.0])
    with pytest.raises(RodInputError) as error:
        scene.validate({"rod_end_position"})
    message = str(error.value)
    assert "1.0000001 m apart" in message and "1e-07 m more than" in message, message


# --- runs that share an output, and output paths that cannot work -----------------------
def test_each_run_has_a_partial_file_of_its_own_and_leaves_others_alone(comm, shared_tmp):
    """Issue 25: two runs with the same -rod_output both wrote FILE.partial, and the
    second one's start-up check truncated and removed the first one's live file."""
    mesh = Mesh(comm, 4, 1.0)
    path = os.path.join(shared_tmp, "shared.h5")
    others = [f"{path}.partial", f"{path}.99-abcdef.partial"]      # another run's, live
    if comm.getRank() == 0:
        for other in others:
            with open(other, "wb") as handle:
                handle.write(b"another run's data")
    comm.tompi4py().Barrier()
    first = second = None
    try:
        io.check_output_path(path, comm)
        first, second = io.ResultWriter(path, mesh), io.ResultWriter(path, mesh)
        assert first.partial != second.partial
        assert first.partial == comm.tompi4py().bcast(first.partial, root=0)   # one name
        assert first.partial.startswith(f"{path}.") and first.partial.endswith(".partial")
        assert os.path.exists(first.partial) and os.path.exists(second.partial)
    finally:
        for writer in (first, second):
            if writer is not None:
                writer.abort()
        mesh.destroy()
    comm.tompi4py().Barrier()
    for other in others:
        with open(other, "rb") as handle:
            assert handle.read() == b"another run's data", other
    assert sorted(partial_files(path)) == sorted(others[1:])


def test_output_paths_that_cannot_work_are_refused_in_one_line(comm, shared_tmp):
    """Issue 25: a dangling symlink said 'not a regular file'; a 250-character name said
    'choose a writable folder' (the partial suffix made it too long)."""
    link = os.path.join(shared_tmp, "link.h5")
    long_name = os.path.join(shared_tmp, "r" * 250 + ".h5")
    if comm.getRank() == 0:
        os.symlink(os.path.join(shared_tmp, "missing", "target.h5"), link)
    comm.tompi4py().Barrier()
    with pytest.raises(RodInputError, match="symbolic link to .*does not exist"):
        io.check_output_path(link, comm)
    with pytest.raises(RodInputError, match="too long for this file system once the run's "
                                            "partial suffix"):
        io.check_output_path(long_name, comm)
    comm.tompi4py().Barrier()
    assert sorted(os.listdir(shared_tmp)) == ["link.h5"]            # nothing made


def test_an_append_only_folder_is_refused_and_left_empty(comm, shared_tmp):
    """Issue 25: an append-only folder gave exit 2 but left a 0-byte partial file."""
    import subprocess
    folder = os.path.join(shared_tmp, "append_only")
    made = 0
    if comm.getRank() == 0:
        os.mkdir(folder)
        made = subprocess.run(["chattr", "+a", folder], capture_output=True).returncode == 0
    if not comm.tompi4py().bcast(made, root=0):
        pytest.skip("chattr +a is not available here")
    try:
        with pytest.raises(RodInputError, match="append-only"):
            io.check_output_path(os.path.join(folder, "result.h5"), comm)
        comm.tompi4py().Barrier()
        assert os.listdir(folder) == []
    finally:
        comm.tompi4py().Barrier()
        if comm.getRank() == 0:
            subprocess.run(["chattr", "-a", folder], check=True)


# --- taut inextensible lines (issue 22) -----------------------------------------------------
TAUT_TETHER = dict(rod_length="100", rod_stiffness="1e3,1e3,1e3", rod_start="pin",
                   rod_end="pin", rod_load="0,0,-100")


@pytest.mark.parametrize("gap", [0.0, 1e-10])
def test_a_loaded_line_held_taut_is_refused(options, gap):
    """Issue 22: a vertical tether pinned exactly its length apart ended "converged" with
    a bottom tension of 1.2 kN, 30.8 kN with another penalty and 2.5 kN in 3 steps: an
    inextensible line held taut carries any tension. It is refused, naming the remedy."""
    from petsc_rod.cli.scene_options import scene_from_options
    values, names = options(**TAUT_TETHER, rod_end_position=f"0,0,{100 * (1 - gap)!r}")()
    with pytest.raises(RodInputError) as error:
        scene_from_options(values, names)
    message = str(error.value)
    assert "tension is undetermined" in message and "-rod_axial_stiffness" in message


def test_a_line_with_slack_held_almost_taut_is_accepted(options):
    """Just beyond the gap (1e-8 L of slack) the tension is determined."""
    from petsc_rod.cli.scene_options import scene_from_options
    from petsc_rod.scenes.scene import TAUT_GAP
    slack = 10 * TAUT_GAP
    values, names = options(**TAUT_TETHER, rod_end_position=f"0,0,{100 * (1 - slack)!r}")()
    assert not scene_from_options(values, names).taut


def test_an_unloaded_rod_held_taut_is_accepted(options):
    """An unloaded rod twisted between clamps its length apart is straight with zero
    tension, the limit of a stiff extensible rod (docs/method.md §5)."""
    from petsc_rod.cli.scene_options import scene_from_options
    values, names = options(rod_start="clamp", rod_end="clamp", rod_end_twist="1")()
    scene = scene_from_options(values, names)
    assert scene.taut and not scene.loaded


def test_a_line_held_taut_under_point_loads_only_is_refused(options):
    """Review of issue 22: a taut tether loaded by a point force alone ended at 995 N or
    36 kN by the penalty; point loads count as loads of a taut line."""
    from petsc_rod.cli.scene_options import scene_from_options
    given = {key: value for key, value in TAUT_TETHER.items() if key != "rod_load"}
    values, names = options(**given, rod_end_position="0,0,100",
                            rod_point_load="50,0,0,-1000")()
    with pytest.raises(RodInputError, match="tension is undetermined"):
        scene_from_options(values, names)


def test_a_flex_joint_on_a_stretching_end_is_accepted(options):
    """Review of issue 22: the joint's spring loaded the end node's strain; it now acts in
    the local step on an extensible end (tests/solver/test_flex_joint_stretch.py), and
    the scene is accepted."""
    from petsc_rod.cli.scene_options import scene_from_options
    values, names = options(rod_length="100", rod_start="pin", rod_end="pin",
                            rod_end_position="80,0,-30", rod_load="0,0,-100",
                            rod_axial_stiffness="1e5",
                            rod_start_rotational_stiffness="1e3")()
    scene = scene_from_options(values, names)
    assert scene.start_rotational_stiffness == 1e3 and scene.extensible


# --- option values longer than petsc4py's getString returns (1023 characters) -------------
def long_point_loads(points=63):
    """-rod_point_load of ``points`` points, each S,fx,fy,fz with a force of -5000 N
    last: over 1023 characters for 63 points."""
    values = np.column_stack([np.linspace(1.0, 2399.0, points), np.full(points, 12.5),
                              np.full(points, -0.125), np.full(points, -5000.0)])
    return ",".join(repr(v) for v in values.ravel()), values


def test_an_option_value_over_1023_characters_is_read_whole(options):
    text, points = long_point_loads()
    sections = ",".join(f"pipe:{2400 / 121:.14g}" for _ in range(121))
    assert len(text) > 1100 and len(sections) > 1100
    values, _ = options(rod_point_load=text, rod_sections=sections)()
    assert np.array_equal(values["rod_point_load"], points.ravel())
    assert values["rod_sections"] == sections


def test_a_sweep_s_case_values_and_settings_over_1023_characters_are_read_whole(comm):
    from petsc_rod.sweep.runner import read_settings, with_options
    text, points = long_point_loads()
    read = with_options(comm, {"rod_point_load": text}, lambda: read_options()[0])
    assert np.array_equal(read["rod_point_load"], points.ravel())
    offsets = ",".join(f"{k * 0.015625:.6f}" for k in range(200))
    assert len(offsets) > 1100
    settings = with_options(comm, {"sweep_output": "out", "sweep_offsets": offsets},
                            read_settings)
    assert len(settings.offsets) == 200 and settings.offsets[-1] == 199 * 0.015625


# --- input files that are not regular files (a FIFO blocks, a device never ends) --------
def deadline(seconds=10):
    """A context in which a call still blocked after ``seconds`` raises TimeoutError
    (SIGALRM: open() of a FIFO is interrupted and Python raises the handler's error)."""
    import contextlib
    import signal

    def expire(*_):
        raise TimeoutError(f"still blocked after {seconds} s")

    @contextlib.contextmanager
    def context():
        previous = signal.signal(signal.SIGALRM, expire)
        signal.alarm(seconds)
        try:
            yield
        finally:
            signal.alarm(0)
            signal.signal(signal.SIGALRM, previous)
    return context()


def input_readers():
    """{option: read(path)} of every reader of an input table."""
    from petsc_rod.environment.profiles import read_profile, read_seabed_profile
    from petsc_rod.model.line_type import LINE_TYPE_COLUMNS, LINE_TYPE_OPTIONAL
    from petsc_rod.scenes.point_loads import read_attachments
    from petsc_rod.sweep.cases import read_cases
    from petsc_rod.tables import read_table
    return {"-rod_line_types": lambda p: read_table(p, "-rod_line_types", LINE_TYPE_COLUMNS,
                                                    LINE_TYPE_OPTIONAL),
            "-rod_point_loads": lambda p: read_attachments(p, 100.0),
            "-rod_current_profile": read_profile,
            "-rod_seabed_profile": read_seabed_profile,
            "-sweep_cases": lambda p: read_cases(p, lambda name: True)}


@pytest.mark.parametrize("option", list(input_readers()))
@pytest.mark.parametrize("kind", ["fifo", "/dev/zero", "folder"])
def test_an_input_file_that_is_not_a_regular_file_is_refused_at_once(tmp_path, option,
                                                                     kind):
    path = str(tmp_path / "table")
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "folder":
        os.mkdir(path)
    else:
        path = kind
    with deadline(), pytest.raises(RodInputError) as error:
        input_readers()[option](path)
    message = str(error.value)
    assert message.startswith(f"{option} {path}: ")
    assert ("not a regular file" if kind != "folder" else "is a folder") in message, message


def test_an_input_table_above_the_size_cap_is_refused_unread(tmp_path, monkeypatch):
    from petsc_rod import tables
    path = tmp_path / "profile.txt"
    path.write_text("0 1 0 0\n10 1 0 0\n")
    monkeypatch.setattr(tables, "MAX_TABLE_BYTES", 16)
    with pytest.raises(RodInputError, match=r"-rod_current_profile .*above the 1.53e-05 MiB"):
        input_readers()["-rod_current_profile"](str(path))


def test_a_restart_file_that_is_a_fifo_is_refused_on_every_rank(comm, shared_tmp):
    path = f"{shared_tmp}/restart.h5"
    if comm.getRank() == 0:
        os.mkfifo(path)
    comm.tompi4py().Barrier()
    mesh = Mesh(comm, 4, 1.0)
    try:
        with deadline(), pytest.raises(RodInputError, match="-rod_initial .*not a regular"):
            assert io.read_parameters(path, comm) is None
            io.read_restart(path, mesh, {})
    finally:
        mesh.destroy()


@pytest.mark.parametrize("pieces", [None, ([0.0, 0.5, 1.0], [4, 6])])
def test_a_restart_of_another_element_count_asks_for_what_sets_it(result, comm, pieces):
    """A line of sections takes its count from -rod_sections (-rod_elements beside
    counts is refused): the advice names the sections' counts there."""
    from petsc_rod.mesh.mesh import Pieces
    _, path = result
    mesh = Mesh(comm, 10, 1.0, 1.0, None if pieces is None else Pieces(*pieces))
    try:
        with pytest.raises(RodInputError) as error:
            io.read_restart(path, mesh, {})
    finally:
        mesh.destroy()
    fix = "use -rod_elements 8" if pieces is None else "use -rod_sections counts"
    assert "the file has 8 elements, this run 10; " + fix in str(error.value)


@pytest.mark.parametrize("name, value", [("rod_seabed_direction", "45"),
                                         ("rod_seabed_origin", "10,0")])
def test_a_seabed_direction_or_origin_without_a_slope_or_profile_is_refused(options, name,
                                                                            value):
    """On the flat -rod_seabed they did nothing, in silence."""
    from petsc_rod.cli.scene_options import scene_from_options
    scene = dict(rod_start="pin", rod_end="pin", rod_end_position="0.8,0,0",
                 rod_load="0,0,-1", rod_seabed="-0.5")
    values, given = options(**scene, **{name: value})()
    with pytest.raises(RodInputError, match=f"-{name} needs -rod_seabed_slope or "
                                            "-rod_seabed_profile"):
        scene_from_options(values, given)
    values, given = options(rod_seabed_slope="0")()
    assert scene_from_options(values, given).seabed.flat
