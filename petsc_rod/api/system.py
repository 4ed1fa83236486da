"""What a study of a system scripts (docs/systems.md): lines of the existing line types
(api.LineType, api.Line) between points (Point: fixed anchors, free joints, clump
weights and buoys, prescribed fairleads) and rigid bodies (Body, 6 degrees of freedom),
each end a Connection, in one sea (api.Environment); or the same System read from a
MoorDyn version 2 file (read_moordyn, which also returns the notes of what it
substituted). The classes are the model's own (petsc_rod/model/system.py): a System
built here and one read from the file are equal when they describe the same thing.
``System.check()`` refuses one no equilibrium can be sought for. ``clamp_frame(direction,
twist)`` is the frame a Connection's direction and twist give a clamp (docs/systems.md,
"A clamp's frame"), to compare with a single line's End.frame."""

from petsc_rod.model.moordyn import read_moordyn
from petsc_rod.model.system import Body, Connection, Point, System, SystemLine, clamp_frame

__all__ = ["Body", "Connection", "Point", "System", "SystemLine", "clamp_frame",
           "read_moordyn"]
