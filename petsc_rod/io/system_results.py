"""The result file of a system (docs/output.md, "A system's result file"): one HDF5 file,
written collectively by every rank of the system's communicator and atomically (the
run's own partial file, renamed when complete; removed on any failure), with

* a group ``lines/<name>`` per line holding what a single line's file holds for its
  last step (ResultWriter.write_step: the vertex datasets, the terms' and reports' ones,
  ``state``, ``history``, the attributes): the line's datasets are created by every rank
  (HDF5's metadata is collective) and filled by the ranks of the line's own group, each
  its owned rows (the other ranks give zero rows, so that the rows' offsets over the
  whole communicator are those within the group: its ranks are consecutive);
* a group ``system``: the points', bodies' and lines' numbers (SystemWriter.finish_system).
"""

import numpy as np

from petsc_rod.io.results import ResultWriter, _set_attributes


class _Ranks:
    """What ResultWriter reads of a mesh: its communicator."""

    def __init__(self, comm):
        self.comm = comm


class SystemWriter(ResultWriter):
    """A system's result file being written by every rank of ``comm`` (a PETSc.Comm).
    Every method is collective on it; a failure on any rank raises the same RodIOError
    on every rank (ResultWriter)."""

    def __init__(self, path, comm, minimum_bytes=0):
        super().__init__(path, _Ranks(comm), minimum_bytes)

    def write_line(self, name, vertex, state, attributes, units):
        """The group ``lines/<name>``: ``vertex`` and ``state`` this rank's rows of the
        line's arrays (zero rows on a rank outside its group, the same names and trailing
        shapes everywhere), ``attributes`` and ``units`` the same on every rank."""
        self.write_step(f"lines/{name}", vertex, state, np.zeros((0, 3)), attributes, units)

    def finish_system(self, datasets, attributes, units, groups=None):
        """The group ``system`` with ``datasets`` {name: array} (the same on every rank,
        written by rank 0) and its ``attributes``, the root's ``attributes`` too, and
        its subgroups ``groups`` {name: (datasets, attributes, units)} alike (the
        watch circle, the load-excursion curves); then the file closed and renamed to
        its path. ``units`` {name: unit} of both."""
        attributes = self._shared(attributes)
        self._collective(self._finish_system, datasets, attributes, units, groups or {})
        self._collective(self._rename, self.path)

    def _group(self, group, datasets, attributes, units):
        for key, value in datasets.items():
            value = np.asarray(value, dtype=float)
            data = group.create_dataset(key, shape=value.shape, dtype="f8")
            data.attrs["units"] = units[key]
            if self.comm.Get_rank() == 0 and value.size:
                data[...] = value
        _set_attributes(group, attributes, units)

    def _finish_system(self, datasets, attributes, units, groups):
        group = self.file.create_group("system")
        self._group(group, datasets, attributes, units)
        for name, (data, values, units_of) in groups.items():
            self._group(group.create_group(name), data, values, units_of)
        _set_attributes(self.file, attributes, units)
        self.file.close()
        self.file = None
