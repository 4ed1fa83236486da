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


class FunctionReport(Report):
    """A report that is a function and its units, and holds no state of its own (the
    riser numbers, the regions, the sections' numbers, the pipe's pressures and
    stresses, the results along the line): ``outputs`` is ``report(problem, vertex,
    *arguments)``, ``arguments`` those it was made with (a SeabedTerm, the scene, the
    sections). A subclass names the function (``report``) beside ``name`` and the units;
    a report with state of its own (module_bends.ModuleBends) is a Report."""

    # the function (problem, vertex, *arguments) -> TermOutput or None
    report = None

    def __init__(self, *arguments):
        self.arguments = arguments

    def outputs(self, problem, vertex):
        return type(self).report(problem, vertex, *self.arguments)
