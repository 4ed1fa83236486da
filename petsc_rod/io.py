"""HDF5 results, written collectively and atomically, and read back for a restart.

Layout (documented in README.md): vertex datasets S (n,), r, d1, d2, d3, u, m, n (n, 3);
attributes converged, iterations, constraint_residual, change, estimated_distance, energy,
wall_time, ranks, options, load_factor, penalty (and twist_turns, writhe_turns where the
link is tracked); a group ``history``; a group ``state`` with what a restart needs beyond
the vertex datasets (d1, d2 midpoints per element, tau and lambda per P2 node); and one group ``steps/<k>`` per accepted continuation step (halved sub-steps included) and the failed
one that ends a run, with the same content. The root links to the last step. The file
is written as ``<name>.partial`` and renamed only when complete, so a crash or an
interrupt never leaves a half-written result under the requested name.
"""

import os

import h5py
import numpy as np

from .errors import RodInputError

VERTEX_DATASETS = ("S", "r", "d1", "d2", "d3", "u", "m", "n")
ELEMENT_STATE = ("d1_mid", "d2_mid")       # per element
NODE_STATE = ("tau", "lambda")              # per P2 node (2 N + 1 of them)
HISTORY_COLUMNS = ("change", "constraint_residual", "wall_time")


def _open(path, mode, comm):
    if h5py.get_config().mpi and comm.size > 1:
        return h5py.File(path, mode, driver="mpio", comm=comm)
    if comm.size > 1:
        raise RodInputError("h5py has no MPI support here: run the set-up script (scripts/"
                            "setup.sh) so that Debian's python3-h5py-mpi is used")
    return h5py.File(path, mode)


class ResultWriter:
    """One result file being written by all ranks of ``mesh.comm``."""

    def __init__(self, path, mesh):
        self.path = path
        self.partial = f"{path}.partial"
        self.mesh = mesh
        self.comm = mesh.comm.tompi4py()
        folder = os.path.dirname(os.path.abspath(path))
        if not os.path.isdir(folder):
            raise RodInputError(f"-rod_output {path}: the folder {folder} does not exist")
        self.file = _open(self.partial, "w", self.comm)

    def _dataset(self, group, name, rows, local, start):
        data = group.create_dataset(name, shape=(rows,) + local.shape[1:], dtype="f8")
        if local.shape[0]:
            data[start:start + local.shape[0]] = local

    def write_step(self, name, vertex, state, history, attributes):
        """Write one solution as group ``name``: collective on every rank."""
        mesh = self.mesh
        group = self.file.require_group(name)
        for key in VERTEX_DATASETS:
            self._dataset(group, key, mesh.n_vertices, np.asarray(vertex[key]),
                          mesh.vertex_start)
        state_group = group.create_group("state")
        for key in ELEMENT_STATE:
            self._dataset(state_group, key, mesh.n_elements, np.asarray(state[key]),
                          mesh.element_start)
        for key in NODE_STATE:
            self._dataset(state_group, key, 2 * mesh.n_elements + 1, np.asarray(state[key]),
                          2 * mesh.vertex_start)
        history_group = group.create_group("history")
        table = np.asarray(history, dtype=float).reshape(-1, len(HISTORY_COLUMNS))
        for column, key in enumerate(HISTORY_COLUMNS):
            data = history_group.create_dataset(key, shape=(table.shape[0],), dtype="f8")
            if self.comm.rank == 0:
                data[:] = table[:, column]
        for key, value in attributes.items():
            group.attrs[key] = value

    def finish(self, last_group, attributes):
        """Link the root to ``last_group``, set the root attributes, close and rename."""
        source = self.file[last_group]
        for key in list(source.keys()):
            self.file[key] = source[key]
        for key, value in attributes.items():
            self.file.attrs[key] = value
        self.file.close()
        self.comm.Barrier()
        if self.comm.rank == 0:
            os.replace(self.partial, self.path)
        self.comm.Barrier()

    def abort(self):
        """Close and remove the partial file: nothing is left under the result name."""
        try:
            self.file.close()
        finally:
            if self.comm.rank == 0 and os.path.exists(self.partial):
                os.remove(self.partial)


def read_state(path, mesh):
    """Owned slices of a result file for a restart; the mesh must be the file's mesh."""
    if not os.path.isfile(path):
        raise RodInputError(f"-rod_initial {path}: no such file")
    try:
        handle = h5py.File(path, "r")
    except OSError:
        raise RodInputError(f"-rod_initial {path}: not an HDF5 result file") from None
    with handle as f:
        if "S" not in f or "state" not in f:
            raise RodInputError(f"-rod_initial {path}: not a petsc_rod result file")
        S = f["S"]
        if S.shape[0] != mesh.n_vertices:
            raise RodInputError(
                f"-rod_initial {path}: the file has {S.shape[0] - 1} elements, this run "
                f"{mesh.n_elements}; use -rod_elements {S.shape[0] - 1}")
        vs, ve, es, ee = mesh.vertex_start, mesh.vertex_end, mesh.element_start, mesh.element_end
        if not np.allclose(S[vs:ve], mesh.vertex_S, rtol=1e-12, atol=1e-12 * mesh.length):
            raise RodInputError(f"-rod_initial {path}: the file's mesh (length or grading) is "
                                "not this run's; use the same -rod_length and -rod_mesh_grading")
        vertex = {key: f[key][vs:ve] for key in ("r", "d1", "d2", "d3")}
        element = {key: f["state"][key][es:ee] for key in ELEMENT_STATE}
        ns = 2 * vs
        node = {key: f["state"][key][ns:ns + mesh.n_local_nodes] for key in NODE_STATE}
    return vertex, element, node
