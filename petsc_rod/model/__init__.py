"""The typed description of a problem (docs/design.md, "The model"): line types, a line
of sections or a uniform line, its ends, the attachments, the sea, and the Model that
holds them with every check of whether it can be solved. Plain values in SI units;
nothing here knows PETSc or a front end (the command line, the API, the sweep map their
input to it; compile.py makes the solver's Scene of it)."""

from petsc_rod.model.attachment import Attachment
from petsc_rod.model.end import End
from petsc_rod.model.line import Line, UniformLine
from petsc_rod.model.line_type import LineType, Section, line_types_from_table
from petsc_rod.model.model import Model, Span
from petsc_rod.model.sea import Environment
from petsc_rod.model.system import Body, Connection, Point, System, SystemLine

__all__ = ["Attachment", "Body", "Connection", "End", "Environment", "Line", "LineType",
           "Model", "Point", "Section", "Span", "System", "SystemLine", "UniformLine",
           "line_types_from_table"]
