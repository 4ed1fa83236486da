"""The Python API for scripted studies (README, "Python API"): describe a line of line
types between two ends in the sea (api/model.py), solve it on the ranks of a
communicator (api/run.py), read its numbers with their units (api/results.py).

    from petsc_rod.api import LineType, Line, End, Environment, Model, solve
"""

from petsc_rod.api.model import (Attachment, End, Environment, Line, LineType, Model,
                                 UniformLine)
from petsc_rod.api.results import Results
from petsc_rod.api.run import scene_of, solve

__all__ = ["Attachment", "End", "Environment", "Line", "LineType", "Model", "Results",
           "UniformLine", "scene_of", "solve"]
