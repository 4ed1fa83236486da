"""What api.solve returns: the last step's numbers with their units, as numpy (no PETSc
object: the run's are destroyed before it returns).

* scalars (the result file's attributes: ``top_tension`` N, ``top_angle`` deg,
  ``touchdown_S`` m, ``min_bend_radius`` m, ``section_max_tension`` (sections,) N, ...,
  ``energy`` J, ``iterations``), the same on every rank, as attributes:
  ``results.top_tension``, or ``results.scalars``;
* arrays along the line at the N + 1 vertices (the result file's datasets: ``S`` (n,)
  m, ``r`` (n, 3) m, ``effective_tension`` (n,) N, ``u`` (n, 3) rad/m, ``m`` (n, 3)
  N m, ...): each rank holds its own vertices (``owned``); ``along_line()`` gathers the
  whole line on every rank (collective: every rank calls it);
* ``units`` {name: unit} of both, as the result file has them (io/results.py);
* ``modes`` of Model.options['modes'] (-rod_modes, docs/modes.md) about the converged
  state: an analysis.modes.Modes (lowest first: ``frequencies`` Hz, ``periods`` s,
  ``modal_mass`` kg, ``labels`` (their classes), ``shares`` (n, 4); this rank's
  vertices' ``S``, ``offset`` and ``rotation``), None where none were asked or the run
  did not converge; ``modes_refused`` why there are none (an unstable state), else None.
"""

import numpy as np

from petsc_rod.analysis.modes import ModesRefused
from petsc_rod.cli.messages import summary
from petsc_rod.io.results import ATTRIBUTE_UNITS, DATASET_UNITS


class Results:
    """The last step of an api.solve run (module docstring). ``converged``: it reached
    load factor 1 and converged; ``elements``: of the mesh; ``units``: ({dataset: unit},
    {attribute: unit}) of what the run's terms and reports wrote (RodProblem.units)."""

    def __init__(self, owned, scalars, converged, comm, elements, units=None, modes=None):
        refused = isinstance(modes, ModesRefused)
        self.modes = None if refused else modes
        self.modes_refused = str(modes) if refused else None
        self.owned = owned
        self.scalars = scalars
        self.converged = bool(converged)
        self.elements = elements
        self._comm = comm
        given = units or ({}, {})
        datasets, attributes = {**DATASET_UNITS, **given[0]}, {**ATTRIBUTE_UNITS, **given[1]}
        self.units = {name: datasets.get(name, "") for name in owned}
        self.units.update({name: attributes.get(name, "") for name in scalars})

    def __getattr__(self, name):
        scalars = self.__dict__.get("scalars", {})
        if name in scalars:
            return scalars[name]
        raise AttributeError(f"Results has no {name!r}; its scalars: {', '.join(scalars)}; "
                             "its arrays: along_line()")

    def along_line(self, names=None):
        """{name: array} of the arrays along the whole line (or of ``names``), the ranks'
        vertices gathered in order of S on every rank. Collective."""
        names = list(self.owned) if names is None else list(names)
        gathered = {}
        for name in names:
            parts = self._comm.allgather(np.asarray(self.owned[name]))
            gathered[name] = np.concatenate(parts, axis=0)
        return gathered

    def summary(self):
        """The command line's final summary of these numbers, as lines of text."""
        return summary(self.scalars)
