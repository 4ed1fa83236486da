"""HDF5 results, written collectively and atomically, and read back for a restart.

Layout (documented in docs/output.md): vertex datasets S (n,), r, d1, d2, d3, u, m, n
(n, 3); attributes converged, stop_reason, iterations, halvings, total_iterations,
total_halvings, undone_iterations, constraint_residual, change, stable, energy,
wall_time, written, ranks, load_factor, penalty (in use), asked_penalty (and
twist_turns, writhe_turns where the link is tracked; the datasets axial_strain,
axial_tension and attributes stretched_length, axial_tension_gap on an extensible line,
physics/stretch.py); a group ``history``; a group ``state`` with what a restart needs
beyond the vertex datasets (outputs.restart_state); and one group ``steps/<k>`` per
accepted continuation step (halved sub-steps included) and the failed one that ends a
run, with the same content. The root links to the last step and also holds the run's
version, commit, options and options_in_effect, and a group ``parameters`` with every
option in effect as numbers. Every dataset has a ``units`` attribute, every group an
``attribute_units`` (JSON). The file is written as the run's own partial file
``<name>.<pid>-<tag>.partial`` (partial_name) and renamed only
when complete, so a crash or an interrupt never leaves a half-written result under the
requested name; a failure or an interrupt removes the partial file.

A write that fails inside HDF5 leaves the library unable to close the file (it crashes
at exit trying to flush it): such a file is removed without being closed, and
``hdf5_failed()`` tells the program to end without HDF5's shutdown (__main__).
"""

import array
import contextlib
import datetime
import errno
import fcntl
import json
import os
import secrets
import stat
import sys
from dataclasses import dataclass

import numpy as np

from petsc_rod.io.capture import stderr_captured
from petsc_rod.errors import RodInputError, RodIOError, on_every_rank
from petsc_rod.resources import free_disk, size_text
from petsc_rod.tables import check_input_file, file_problem

VERTEX_DATASETS = ("S", "r", "d1", "d2", "d3", "u", "m", "n")
RESTART_VERTEX_DATASETS = ("S", "r", "d1", "d2", "d3")
HISTORY_COLUMNS = ("change", "constraint_residual", "wall_time")

# Units of the datasets the file has for every run ("1": dimensionless) ...
DATASET_UNITS = {
    "S": "m", "r": "m", "d1": "1", "d2": "1", "d3": "1", "u": "rad/m", "m": "N m", "n": "N",
    "d1_mid": "1", "d2_mid": "1", "tau": "1", "lambda": "N",
    "change": "1", "constraint_residual": "1", "wall_time": "s",
}
# ... and of the attributes of a step group and of the root ("text": a string); the
# terms and the reports give the units of what they add (RodProblem.units, passed to
# ResultWriter.write_step).
ATTRIBUTE_UNITS = {
    "converged": "1", "stop_reason": "text", "iterations": "1", "newton_steps": "1",
    "halvings": "1",
    "total_iterations": "1", "total_halvings": "1", "undone_iterations": "1",
    "constraint_residual": "1", "change": "1", "stable": "1", "energy": "J",
    "wall_time": "s", "written": "text", "ranks": "1", "load_factor": "1", "penalty": "N",
    "asked_penalty": "N",
    "twist_turns": "turn", "writhe_turns": "turn", "options": "text",
    "options_in_effect": "text", "version": "text", "commit": "text", "restart_walk": "1",
}
# A step is written only while the disk has this many times its size free, plus
# SPACE_RESERVE for HDF5's metadata: HDF5 cannot recover from a full disk.
SPACE_FACTOR = 2
SPACE_RESERVE = 2**20
# Exceptions through which h5py and the OS report a failed write.
WRITE_FAILURES = (OSError, RuntimeError, ValueError, KeyError, TypeError)

_hdf5_failed = False
_unclosable = []            # h5py files whose writes failed, kept until the process ends


def hdf5_failed():
    """Whether a write failed inside HDF5 in this process (see the module docstring)."""
    return _hdf5_failed


def now():
    """The current UTC time, ISO 8601 to the second."""
    return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")


def distributed_layout(comm, arrays):
    """{name: (global shape, this rank's first row, its number of rows)} of arrays split
    by rows over the ranks in rank order (each rank's owned slice). Collective (mpi4py
    ``comm``)."""
    counts = comm.allgather({name: np.shape(array)[0] for name, array in arrays.items()})
    rank = comm.Get_rank()
    return {name: ((sum(c[name] for c in counts),) + np.shape(array)[1:],
                   sum(c[name] for c in counts[:rank]), counts[rank][name])
            for name, array in arrays.items()}


# --------------------------------------------------------------------- the output path
def partial_name(path, comm):
    """The run's own partial file, ``<path>.<pid>-<6 hex>.partial`` (rank 0's pid and a
    random tag, the same on every rank): two runs with the same output never write, check
    or remove each other's partial file. Collective."""
    tag = f"{os.getpid()}-{secrets.token_hex(3)}" if comm.getRank() == 0 else None
    return f"{path}.{comm.tompi4py().bcast(tag, root=0)}.partial"


def check_output_path(path, comm, option="-rod_output"):
    """Refuse, before any work, an output that could not be written: a folder, a missing
    folder, a device or other non-regular file, a link to nothing, a folder where a file
    cannot be created (permissions, a read-only or special file system), a name too long
    for the partial file's suffix. Nothing but the run's own probe is created or removed
    (another run's partial file is left alone). The message names ``option``.
    Collective: rank 0 checks, every rank raises."""
    probe = partial_name(path, comm)
    on_every_rank(comm, _check_output_path if comm.getRank() == 0 else _nothing, path, probe,
                  option)


def _nothing(*args):
    return None


def _check_output_path(path, probe, option):
    folder = os.path.dirname(os.path.abspath(path))
    if path.endswith(os.sep) or os.path.isdir(path):
        raise RodInputError(f"{option} {path}: is a folder; name a file, e.g. "
                            f"{os.path.join(path, 'result.h5')}")
    if not os.path.isdir(folder):
        raise RodInputError(f"{option} {path}: the folder {folder} does not exist")
    if os.path.islink(path) and not os.path.exists(path):
        raise RodInputError(f"{option} {path}: is a symbolic link to {os.readlink(path)}, "
                            "which does not exist; remove the link or name another file")
    if os.path.lexists(path) and not _regular_file(path):
        raise RodInputError(f"{option} {path}: exists and is not a regular file (a "
                            "folder, a device, a socket); name another file")
    if _append_only(folder):
        raise RodInputError(f"{option} {path}: the folder {folder} is append-only (a "
                            "file made there can never be renamed or removed); choose "
                            "another folder")
    try:
        descriptor = os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
    except OSError as error:
        if error.errno == errno.ENAMETOOLONG:
            suffix = probe[len(path):]
            raise RodInputError(
                f"{option} {path}: the name is too long for this file system once the "
                f"run's partial suffix ({len(suffix)} characters, e.g. {suffix}) is added; "
                "choose a shorter name") from None
        raise RodInputError(f"{option} {path}: cannot create a file in {folder} "
                            f"({error.strerror}); choose a writable folder") from None
    os.close(descriptor)
    try:
        os.remove(probe)
    except OSError as error:        # an append-only folder: a file is made, never removed
        raise RodInputError(f"{option} {path}: a file created in {folder} cannot be "
                            f"removed ({error.strerror}: an append-only or sticky folder); "
                            f"remove {probe} by hand and choose another folder") from None


# The Linux ioctl that reads a file's attribute flags, and the append-only flag.
FS_IOC_GETFLAGS = 0x80086601
FS_APPEND_FL = 0x20


def _append_only(folder):
    """Whether the folder has the append-only attribute (chattr +a); False where the file
    system keeps no such flags."""
    try:
        descriptor = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
    except OSError:
        return False
    try:
        flags = array.array("l", [0])
        fcntl.ioctl(descriptor, FS_IOC_GETFLAGS, flags, True)
        return bool(flags[0] & FS_APPEND_FL)
    except OSError:
        return False
    finally:
        os.close(descriptor)


def _regular_file(name):
    try:
        return stat.S_ISREG(os.stat(name).st_mode)
    except OSError:
        return False


# --------------------------------------------------------------------------- writing
@dataclass
class RunRecord:
    """What the root of a result file says about the run beyond its last step: root
    attributes (version, commit, options_in_effect) and the group ``parameters`` (every
    option in effect, with its unit)."""

    attributes: dict
    parameters: dict
    units: dict


def minimum_bytes(mesh, state, steps):
    """Bytes a file of ``steps`` steps needs at least: each step's vertex datasets and
    restart state (this rank's arrays ``state``); the histories come on top. Collective."""
    local = sum(np.asarray(array).nbytes for array in state.values())
    vertex = 8 * mesh.n_vertices * (1 + 3 * (len(VERTEX_DATASETS) - 1))
    return steps * (vertex + int(mesh.global_sum(local)))


def _open(path, mode, comm):
    import h5py                     # with the first file: a run without one loads no HDF5
    if h5py.get_config().mpi and comm.size > 1:
        return h5py.File(path, mode, driver="mpio", comm=comm)
    if comm.size > 1:
        raise RodInputError("h5py has no MPI support here: run the set-up script (scripts/"
                            "setup.sh) so that Debian's python3-h5py-mpi is used")
    return h5py.File(path, mode)


@contextlib.contextmanager
def _failures_collected(found):
    """The exceptions of a failed write, into ``found``: those raised, and those h5py
    reports only when a handle is freed (a traceback, then 'Exception ignored'). What
    HDF5, MPI-IO and h5py print meanwhile is kept off the terminal, unless nothing
    failed."""
    previous = sys.unraisablehook
    sys.unraisablehook = lambda report: found.append(report.exc_value)
    try:
        with stderr_captured() as printed:
            try:
                yield
            except WRITE_FAILURES as error:
                found.append(error)
            text = printed()
    finally:
        sys.unraisablehook = previous
    if not found:
        sys.stderr.write(text)


def _failure_text(error):
    """The reason of a failed write: the system's message where HDF5 quotes it."""
    text = str(error)
    if "error message = '" in text:
        return text.split("error message = '", 1)[1].split("'", 1)[0]
    return (text.strip().splitlines() or [type(error).__name__])[0]


class ResultWriter:
    """One result file being written by all ranks of ``mesh.comm``. Every method is
    collective; a failure on any rank raises the same RodIOError on every rank."""

    def __init__(self, path, mesh, minimum_bytes=0, run=None):
        """Open the run's own partial file (partial_name); ``minimum_bytes``: what the
        whole file will need at least (RodInputError when the disk has less); ``run``:
        the RunRecord the root gets when the file is finished."""
        self.path = path
        self.run = run or RunRecord({}, {}, {})
        self.partial = partial_name(path, mesh.comm)
        self.mesh = mesh
        self.comm = mesh.comm.tompi4py()
        self.folder = os.path.dirname(os.path.abspath(path))
        self.file = None
        self.broken = False           # a write failed inside HDF5
        # the units of every dataset and attribute written so far: the file's own, and
        # those write_step is given for the terms' and reports' outputs
        self.dataset_units = dict(DATASET_UNITS)
        self.attribute_units = dict(ATTRIBUTE_UNITS)
        on_every_rank(self.comm, self._check_room_for_file, minimum_bytes)
        self.file = self._collective(_open, self.partial, "w", self.comm)

    def _check_room(self, nbytes, refusal):
        """Raise ``refusal(free bytes)`` when the file's disk has fewer than ``nbytes``
        free (read on rank 0; on_every_rank makes the error every rank's)."""
        if self.comm.Get_rank() != 0:
            return
        free = free_disk(self.folder)
        if free < nbytes:
            raise refusal(free)

    def _check_room_for_file(self, nbytes):
        self._check_room(nbytes, lambda free: RodInputError(
            f"-rod_output {self.path}: the result needs at least {size_text(nbytes)}, the "
            f"disk of {self.folder} has {size_text(free)} free; free some space or choose "
            "another folder"))

    def _check_room_for_step(self, nbytes):
        self._check_room(nbytes, lambda free: RodIOError(
            f"-rod_output {self.path}: the disk of {self.folder} is full ({size_text(free)} "
            f"free, the next step needs {size_text(nbytes)} with HDF5's reserve); the "
            "partial file is removed"))

    def _collective(self, action, *args):
        """``action(*args)`` (HDF5 and file operations only, no MPI call of ours) on every
        rank; a failure on any rank becomes the same RodIOError on every rank."""
        def guarded():
            found, result = [], None
            with _failures_collected(found):
                result = action(*args)
            if found:
                failure = RodIOError(f"writing {self.partial} failed ({_failure_text(found[0])})"
                                     "; the partial file is removed")
                failure.hdf5 = self.file is not None
                raise failure
            return result
        try:
            return on_every_rank(self.comm, guarded)
        except RodIOError as error:
            self.broken = self.broken or getattr(error, "hdf5", False)
            raise

    def write_step(self, name, vertex, state, history, attributes, units=None):
        """Write one solution as group ``name``, after checking that the disk has room;
        ``units``: ({dataset: unit}, {attribute: unit}) of the datasets and attributes the
        terms and reports added (RodProblem.units), kept for the root's too."""
        if units is not None:
            self.dataset_units.update(units[0])
            self.attribute_units.update(units[1])
        table = np.asarray(history, dtype=float).reshape(-1, len(HISTORY_COLUMNS))
        # the vertex datasets, and those the terms and reports add
        arrays = {key: np.asarray(value) for key, value in vertex.items()}
        arrays.update({key: np.asarray(value) for key, value in state.items()})
        layout = distributed_layout(self.comm, arrays)
        nbytes = 8 * sum(int(np.prod(shape)) for shape, _, _ in layout.values()) + table.nbytes
        on_every_rank(self.comm, self._check_room_for_step,
                      SPACE_FACTOR * nbytes + SPACE_RESERVE)
        attributes = self._shared(attributes)
        self._collective(self._write_step, name, arrays, list(state), layout, table,
                         attributes)

    def _shared(self, attributes):
        """Rank 0's attributes with the time written: HDF5 needs the same value on every
        rank."""
        return self.comm.bcast({**attributes, "written": now()}, root=0)

    def _write_step(self, name, arrays, state_keys, layout, table, attributes):
        group = self.file.require_group(name)
        state_group = group.create_group("state")
        for key, local in arrays.items():
            shape, start, rows = layout[key]
            target = state_group if key in state_keys else group
            data = target.create_dataset(key, shape=shape, dtype="f8")
            data.attrs["units"] = self.dataset_units[key]
            if rows:
                data[start:start + rows] = local
        history_group = group.create_group("history")
        for column, key in enumerate(HISTORY_COLUMNS):
            data = history_group.create_dataset(key, shape=(table.shape[0],), dtype="f8")
            data.attrs["units"] = DATASET_UNITS[key]
            if self.comm.Get_rank() == 0:
                data[:] = table[:, column]
        _set_attributes(group, attributes, self.attribute_units)
        self.file.flush()

    def write_modes(self, modes, name="modes"):
        """The group ``name`` (``modes``; docs/modes.md, docs/output.md): per mode (m,)
        ``frequency`` Hz, ``period`` s, ``omega2`` rad^2/s^2, ``modal_mass`` kg,
        ``shares`` (m, 4) and the attribute ``classes``; along the line, distributed by
        rows as the vertex datasets, ``S`` (n,), ``offset`` m and ``rotation`` rad (n, m,
        3) of the shapes normalised to a largest offset of 1 m, and at the elements'
        midpoints ``S_mid`` (n_e,) and ``curvature`` (n_e, m, 3) 1/m; of a band
        (-rod_modes_range) the attribute ``band`` (fmin, fmax Hz, the inertia's
        count); where K holds only the symmetric part of the seabed's contact stiffness
        (Modes.symmetrised: a profile's rows) the attributes ``symmetrised_nodes`` and
        ``symmetrised_ratio``. ``modes``: analysis/modes.Modes (this rank's rows)."""
        along = {"S": modes.S, "offset": np.moveaxis(modes.offset, 0, 1),
                 "rotation": np.moveaxis(modes.rotation, 0, 1), "S_mid": modes.S_mid,
                 "curvature": np.moveaxis(modes.curvature, 0, 1)}
        layout = distributed_layout(self.comm, along)
        nbytes = 8 * sum(int(np.prod(shape)) for shape, _, _ in layout.values())
        on_every_rank(self.comm, self._check_room_for_step,
                      SPACE_FACTOR * nbytes + SPACE_RESERVE)
        self._collective(self._write_modes, modes, along, layout, name)

    def _write_modes(self, modes, along, layout, name):
        group = self.file.require_group(name)
        for key, values, unit in (("frequency", modes.frequencies, "Hz"),
                                  ("period", modes.periods, "s"),
                                  ("omega2", modes.omega2, "rad^2/s^2"),
                                  ("modal_mass", modes.modal_mass, "kg"),
                                  ("shares", modes.shares, "1")):
            data = group.create_dataset(key, shape=np.shape(values), dtype="f8")
            data.attrs["units"] = unit
            if self.comm.Get_rank() == 0:
                data[...] = values
        units = {"S": "m", "offset": "m", "rotation": "rad", "S_mid": "m",
                 "curvature": "1/m"}
        for key, local in along.items():
            shape, start, rows = layout[key]
            data = group.create_dataset(key, shape=shape, dtype="f8")
            data.attrs["units"] = units[key]
            if rows:
                data[start:start + rows] = local
        group.attrs["classes"] = ",".join(modes.labels)
        group.attrs["share_columns"] = "in-plane,out-of-plane,axial,torsional"
        if modes.band is not None:
            group.attrs["band"] = np.asarray(modes.band, dtype=float)
        if modes.symmetrised[0]:
            group.attrs["symmetrised_nodes"] = int(modes.symmetrised[0])
            group.attrs["symmetrised_ratio"] = float(modes.symmetrised[1])
        self.file.flush()

    def finish(self, last_group, attributes, name=None):
        """Link the root to ``last_group``, set the root attributes (the last step's and
        the run record's) and the group ``parameters``, close and rename to the result's
        path (or to ``name``: kept_name for the steps of an interrupted run)."""
        attributes = self._shared({**attributes, **self.run.attributes})
        self._collective(self._finish, last_group, attributes)
        self._collective(self._rename, name or self.path)

    def kept_name(self):
        """Where an interrupted run keeps its converged steps: ``<stem>.interrupted<ext>``
        beside the result (``run.h5`` -> ``run.interrupted.h5``), never the result's own
        name."""
        stem, extension = os.path.splitext(self.path)
        return f"{stem}.interrupted{extension or '.h5'}"

    def _finish(self, last_group, attributes):
        source = self.file[last_group]
        for key in list(source.keys()):
            self.file[key] = source[key]
        _set_attributes(self.file, attributes, self.attribute_units)
        _set_attributes(self.file.create_group("parameters"), self.run.parameters,
                        self.run.units)
        self.file.close()
        self.file = None

    def _rename(self, name):
        if self.comm.Get_rank() == 0:
            os.replace(self.partial, name)

    def abort(self):
        """Remove the partial file: nothing is left under the result name or beside it. A
        file whose writes failed is not closed (HDF5 cannot; hdf5_failed)."""
        global _hdf5_failed
        if self.file is not None and not self.broken:
            found = []
            with _failures_collected(found):
                self.file.close()
            self.broken = bool(found)
        if self.broken:
            _unclosable.append(self.file)   # freeing the handle would try to close it
        self.file = None
        _hdf5_failed = _hdf5_failed or self.broken
        self.comm.Barrier()
        if self.comm.Get_rank() == 0:
            with contextlib.suppress(FileNotFoundError):
                os.remove(self.partial)


def _set_attributes(group, attributes, units):
    """Attributes and their ``attribute_units`` (JSON); a unit is needed for each."""
    for key, value in attributes.items():
        group.attrs[key] = value
    group.attrs["attribute_units"] = json.dumps({key: units[key] for key in attributes})


# --------------------------------------------------------------------------- restart
@dataclass
class Restart:
    """This rank's slices of a result file, and what the run reached."""

    vertex: dict
    state: dict
    load_factor: float
    converged: bool


def read_restart(path, mesh, state_templates):
    """Owned slices of result file ``path`` for a restart on ``mesh``, validated: every
    dataset present, of the shape this run's arrays need (``state_templates``: this
    rank's arrays of outputs.restart_state, so that the check follows the solver),
    finite, on this run's mesh, with a load factor in [0, 1]. Collective: a file any rank
    finds wrong is refused (RodInputError) on every rank."""
    comm = mesh.comm.tompi4py()
    vertex_templates = {key: np.zeros((len(mesh.vertex_S), 3)) for key in
                        RESTART_VERTEX_DATASETS}
    vertex_templates["S"] = mesh.vertex_S
    layout = distributed_layout(comm, {**vertex_templates,
                                       **{f"state/{k}": v for k, v in state_templates.items()}})
    return on_every_rank(comm, _read_restart, path, mesh, layout)


def _read_restart(path, mesh, layout):
    import h5py                     # with the first file: a run without one loads no HDF5
    def refuse(what):
        raise RodInputError(f"-rod_initial {path}: {what}")

    check_input_file(path, "-rod_initial", np.inf)
    try:
        handle = h5py.File(path, "r")
    except OSError as error:
        text = _failure_text(error)
        if "lock" in text.lower() or getattr(error, "errno", None) in (errno.EAGAIN,
                                                                        errno.EWOULDBLOCK):
            refuse("is locked by another process (a run still writing or reading it); wait "
                   "for it to end, or restart from a copy of the file")
        refuse(f"not an HDF5 result file ({text})")
    with handle as f:
        if "S" not in f or not isinstance(f["S"], h5py.Dataset):
            refuse("not a petsc_rod result file (no dataset S)")
        if f["S"].shape != layout["S"][0]:
            elements = f["S"].shape[0] - 1 if f["S"].ndim == 1 else "?"
            fix = (f"-rod_elements {elements}" if mesh.pieces is None else
                   f"-rod_sections counts (TYPE:LENGTH:ELEMENTS) of {elements} in all")
            refuse(f"the file has {elements} elements, this run {mesh.n_elements}; use {fix}")
        data = {key: _read_slice(f, key, *layout[key], refuse) for key in layout}
        if not np.allclose(data["S"], mesh.vertex_S, rtol=1e-12, atol=1e-12 * mesh.length):
            refuse("the file's mesh (length or grading) is not this run's; use the same "
                   "-rod_length and -rod_mesh_grading")
        load_factor = _attribute(f, "load_factor", refuse)
        if not 0 <= load_factor <= 1:
            refuse(f"its load_factor {load_factor:g} is not in [0, 1]")
        converged = bool(_attribute(f, "converged", refuse))
    vertex = {key: data[key] for key in RESTART_VERTEX_DATASETS}
    state = {key.removeprefix("state/"): value for key, value in data.items()
             if key.startswith("state/")}
    return Restart(vertex, state, load_factor, converged)


def read_parameters(path, comm):
    """(the group ``parameters`` of result file ``path`` as {name: value}, its root's
    load_factor, whether the run that wrote it walked from another scene's file (its
    ``restart_walk``, 0 in files of older versions)): what a restart needs to rebuild
    the file's scene (cli/scene_options.py).
    None when the file cannot be read or has no such group (read_restart then says
    what is wrong with it, or the restart keeps the file's path as it is). Read on rank
    0 and broadcast, so that every rank of ``comm`` (petsc4py) builds the same scene even
    where one rank could not open the file. Collective."""
    return comm.tompi4py().bcast(_parameters(path) if comm.getRank() == 0 else None, root=0)


def _parameters(path):
    """read_parameters on one process."""
    import h5py                     # with the first file: a run without one loads no HDF5
    if file_problem(path):                  # _read_restart says what; a FIFO would block
        return None
    try:
        with h5py.File(path, "r") as f:
            group = f.get("parameters")
            if not isinstance(group, h5py.Group) or "load_factor" not in f.attrs:
                return None
            values = {key: value.decode() if isinstance(value, bytes) else value
                      for key, value in group.attrs.items() if key != "attribute_units"}
            return (values, float(np.asarray(f.attrs["load_factor"]).ravel()[0]),
                    bool(np.asarray(f.attrs.get("restart_walk", 0)).ravel()[0]))
    except (OSError, KeyError, TypeError, ValueError, IndexError):
        return None


def _read_slice(f, key, shape, start, rows, refuse):
    """Rows [start, start + rows) of dataset ``key``, checked: present, of global
    ``shape``, numbers, finite."""
    import h5py                     # with the first file: a run without one loads no HDF5
    try:
        dataset = f.get(key)
    except (KeyError, TypeError, ValueError, OSError):     # e.g. 'state' not a group
        dataset = None
    if not isinstance(dataset, h5py.Dataset):
        refuse(f"the dataset {key} is missing: not a complete petsc_rod result file")
    if dataset.shape != shape:
        refuse(f"the dataset {key} has shape {dataset.shape}, this run needs {shape} (a "
               "file of another version of petsc_rod, or damaged)")
    if dataset.dtype.kind not in "fiu":
        refuse(f"the dataset {key} holds {dataset.dtype} values, not real numbers (a file "
               "not written by petsc_rod)")
    try:
        values = np.asarray(dataset[start:start + rows], dtype=float)
    except (OSError, TypeError, ValueError) as error:
        refuse(f"the dataset {key} cannot be read as numbers ({_failure_text(error)})")
    if not np.all(np.isfinite(values)):
        refuse(f"the dataset {key} holds NaN or Inf (a diverged or damaged result)")
    return values


def _attribute(f, name, refuse):
    """A finite number attribute of the root."""
    try:
        value = float(np.asarray(f.attrs[name]).ravel()[0])
    except (KeyError, IndexError, TypeError, ValueError, OSError):
        refuse(f"its attribute {name} is missing or not a number")
    if not np.isfinite(value):
        refuse(f"its attribute {name} is {value}")
    return value
