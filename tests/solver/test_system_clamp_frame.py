"""A clamp's frame at a body given by its Connection (direction, twist: the line's
end frame in the body's axes, model/system.py clamp_frame), on one rank and on all:

(a) a riser clamped hanging down from a fixed body is the single-line solver's line
    with its start clamped in the same frame (api.solve), at either end of the line;
(b) the body turned (yaw) with its anchor turned about it turns the clamp's frame with
    it: the end forces and moments turn by the same rotation;
(c) the body's 6 x 6 with a riser clamped in a given frame (a skew direction, a twist)
    agrees with central differences of the lines re-solved at moved and turned poses;
(d) a bad frame is refused in one line."""

import dataclasses

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.api import (Body, Connection, End, Environment, Model, Point, System,
                           SystemLine, UniformLine, clamp_frame, solve, solve_system)
from petsc_rod.errors import RodInputError
from petsc_rod.model.system_check import rotation
from petsc_rod.system.equilibrium import Settings, SystemSolver
from petsc_rod.system.held_line import held_lines

pytestmark = pytest.mark.solver

TIGHT = {"al_rtol": 1e-12, "al_ctol": 1e-12}
HANG_OFF = np.array([0.0, 0.0, -5.0])           # body axes
ANCHOR = np.array([60.0, 0.0, -100.0])          # global, the body's reference at 0
DOWN = (0.0, 0.0, -1.0)


def riser():
    return UniformLine(length=130.0, stiffness=(2e3, 2e3, 2e3), load=(0, 0, -10.0),
                       elements=40)


def hanging(yaw=0.0, direction=DOWN, twist=None, reverse=False):
    """A 130 m riser clamped to a fixed vessel (held in all six degrees of freedom,
    turned by ``yaw``) at ``direction`` (body axes), pinned at an anchor turned with the
    vessel; ``reverse``: the line runs from the anchor to the vessel."""
    R = rotation(0.0, 0.0, yaw)
    clamp = Connection("vessel", tuple(HANG_OFF), "clamp", direction=direction, twist=twist)
    ends = (Connection("anchor"), clamp) if reverse else (clamp, Connection("anchor"))
    return System(lines=(SystemLine("riser", riser(), *ends),),
                  points=(Point("anchor", "fixed", tuple(R @ ANCHOR)),),
                  bodies=(Body("vessel", position=(0.0, 0.0, 0.0, 0.0, 0.0, yaw),
                               held=(True,) * 6),),
                  environment=Environment())


def run(system):
    found = solve_system(system, options=TIGHT)
    scalars = found.lines["riser"].scalars
    return (found, np.array([scalars["start_force"], scalars["end_force"]]),
            np.array([scalars["start_moment"], scalars["end_moment"]]))


@pytest.mark.parametrize("reverse", [False, True], ids=["clamp at S=0", "clamp at S=L"])
def test_a_riser_clamped_hanging_down_is_the_single_line_clamped_so(reverse):
    found, forces, moments = run(hanging(reverse=reverse))
    frame = clamp_frame(DOWN)                       # rows (e_y, e_x, -e_z)
    assert np.abs(frame - [[0, 1, 0], [1, 0, 0], [0, 0, -1]]).max() < 1e-15
    if reverse:                                     # the line's d3 arrives into the body
        frame = frame * np.array([[1.0], [-1.0], [-1.0]])
    clamp = End(kind="clamp", position=tuple(HANG_OFF), frame=tuple(frame.ravel()))
    anchor = End.anchor(tuple(ANCHOR))
    single = solve(Model(line=riser(), start=anchor if reverse else clamp,
                         end=clamp if reverse else anchor, options=TIGHT))
    reference = np.array([single.scalars["start_moment"], single.scalars["end_moment"]])
    top = 1 if reverse else 0
    # the clamp holds the riser vertical: a moment of hundreds of N m there
    assert np.linalg.norm(reference[top]) > 100.0
    assert np.abs(moments - reference).max() < 1e-6 * np.abs(reference).max()
    assert np.abs(forces - [single.scalars["start_force"], single.scalars["end_force"]]
                  ).max() < 1e-7 * np.abs(forces).max()
    along = found.lines["riser"].along_line(["r", "d3"])
    assert np.abs(along["r"] - single.along_line(["r"])["r"]).max() < 1e-7 * 130.0
    # the line's tangent at the clamp is the frame's d3: down, S increasing into the
    # line at its start, out of it into the vessel at its end
    d3 = along["d3"][-top] / np.linalg.norm(along["d3"][-top])
    assert np.abs(d3 - (DOWN if not reverse else -np.array(DOWN))).max() < 1e-8

def test_turning_the_body_turns_the_clamp_frame():
    """Yaw the vessel by 50 degrees with its anchor turned about it: the forces and the
    clamp's moment turn by R_z(50 deg) (the sea is the same under a yaw); with the
    frame held in global axes instead (no yaw of the clamp) they would not."""
    yaw = np.radians(50.0)
    direction = (0.3, -0.2, -1.0)
    _, forces, moments = run(hanging(direction=direction, twist=0.4))
    _, turned_forces, turned_moments = run(hanging(yaw, direction=direction, twist=0.4))
    R = rotation(0.0, 0.0, yaw)
    scale = np.abs(moments).max()
    assert scale > 100.0
    assert np.abs(turned_moments - moments @ R.T).max() < 1e-6 * scale
    assert np.abs(turned_forces - forces @ R.T).max() < 1e-7 * np.abs(forces).max()
    # the moment did turn: it is not the unturned one
    assert np.abs(turned_moments - moments).max() > 0.3 * scale


def test_a_twist_is_a_roll_of_the_clamp():
    """On a riser stiffer in bending about d2 than about d1 the twist (a roll of d1, d2
    about the direction) changes the equilibrium: the system's clamp is the single
    line's clamped in clamp_frame(direction, twist)."""
    direction, twist = (0.3, -0.2, -1.0), 0.4
    stiff = UniformLine(length=130.0, stiffness=(2e3, 2e4, 5e3), load=(0, 0, -10.0),
                        elements=40)

    def moments_of(twisted):
        system = hanging(direction=direction, twist=twist if twisted else None)
        system = dataclasses.replace(system, lines=(dataclasses.replace(
            system.lines[0], line=stiff),))
        _, _, moments = run(system)
        return moments

    twisted, straight = moments_of(True), moments_of(False)
    frame = clamp_frame(direction, twist)
    single = solve(Model(line=stiff, start=End(kind="clamp", position=tuple(HANG_OFF),
                                               frame=tuple(frame.ravel())),
                         end=End.anchor(tuple(ANCHOR)), options=TIGHT))
    reference = np.array([single.scalars["start_moment"], single.scalars["end_moment"]])
    scale = np.abs(reference).max()
    assert np.abs(twisted - reference).max() < 1e-6 * scale
    assert np.abs(twisted - straight).max() > 0.01 * scale


def test_a_bad_frame_is_refused_in_one_line():
    with pytest.raises(RodInputError, match="the zero vector has no direction"):
        Connection("vessel", (0, 0, 0), "clamp", direction=(0.0, 0.0, 0.0))
    system = hanging()
    pinned = dataclasses.replace(system.lines[0], start=Connection(
        "vessel", tuple(HANG_OFF), "pin", direction=DOWN))
    with pytest.raises(RodInputError, match="a pin holds no frame"):
        dataclasses.replace(system, lines=(pinned,)).check()
    flexed = dataclasses.replace(system.lines[0], start=Connection(
        "vessel", tuple(HANG_OFF), "flex", 100.0, direction=DOWN, twist=0.1))
    with pytest.raises(RodInputError, match="holds no roll"):
        dataclasses.replace(system, lines=(flexed,)).check()
    lone = dataclasses.replace(system.lines[0], start=Connection(
        "vessel", tuple(HANG_OFF), "clamp", twist=0.1))
    with pytest.raises(RodInputError, match="twist without a direction"):
        dataclasses.replace(system, lines=(lone,)).check()
