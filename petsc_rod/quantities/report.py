"""The protocol of a report: what a solved state reports beside its fields, and the
units of what it writes (docs/design.md, "Reports").

A report adds nothing to the equations: it is not a term of physics (physics/term.py)
and is not in the problem's list of terms. The problem holds its reports beside its
terms (problem/build.py builds both for the scene); io/outputs.collect merges the
outputs of the terms, then of the reports, once for the HDF5 file (io/results.py) and
the CSV table (io/line_table.py), and RodProblem.units gathers their units from the
tables below, so that the file's writers know no term and no report.
"""


class Report:
    """A report (module docstring). ``outputs`` is called on every rank, in the order of
    the problem's reports (collective where a report needs it)."""

    # what the report is, for messages and the docs
    name = ""
    # {name: unit} of the vertex datasets and of the attributes its outputs write ("1":
    # dimensionless, "text": a string)
    dataset_units = {}
    attribute_units = {}

    def outputs(self, problem, vertex):
        """A physics.term.TermOutput (vertex datasets of the owned vertices, attributes, a
        phrase for the step line) from the vertex fields ``vertex``
        (io/outputs.vertex_fields) of the problem's state, or None. Collective."""
        return None
