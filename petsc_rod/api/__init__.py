"""The Python API for scripted studies (README, "Python API"): describe a line of line
types between two ends in the sea (api/model.py), solve it on the ranks of a
communicator (api/run.py), read its numbers with their units (api/results.py); or
describe a system of such lines between points and bodies, or read one from a MoorDyn
file (api/system.py, docs/systems.md).

    from petsc_rod.api import LineType, Line, End, Environment, Model, solve
    from petsc_rod.api import System, Point, Body, Connection, SystemLine, read_moordyn
    from petsc_rod.api import solve_system       # -> SystemResults (api/system_run.py)
"""

from petsc_rod.api.model import (Attachment, End, Environment, Line, LineType, Model,
                                 UniformLine)
from petsc_rod.api.results import Results
from petsc_rod.api.run import scene_of, solve
from petsc_rod.api.system import (Body, Connection, Point, System, SystemLine,
                                  clamp_frame, read_moordyn)
from petsc_rod.api.system_run import SystemResults, solve_system
from petsc_rod.api.system_sweeps import Sweeps

__all__ = ["Attachment", "Body", "Connection", "End", "Environment", "Line", "LineType",
           "Model", "Point", "Results", "System", "SystemLine", "UniformLine",
           "SystemResults", "Sweeps", "clamp_frame", "read_moordyn", "scene_of", "solve",
           "solve_system"]
