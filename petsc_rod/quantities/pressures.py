"""The pipe's pressures and its wall tension, as riser practice reports them (docs/riser.md
§2b), for a line of line types (scenes/line.py: each section's wall outer diameter od_w,
the line type's stress_od (its od unless a buoyancy jacket or coating outside the wall
carries its own pressure), and inner diameter id).

The line's loads are its submerged weight and its effective tension T_e = n.t is what
the equilibrium carries (Sparks' effective tension). The pipe wall itself carries

    T_w = T_e + p_i A_i - p_e A_e,        A_e = pi od_w^2 / 4,  A_i = pi id^2 / 4,

with the external hydrostatic pressure p_e = rho_w g max(z_s - z, 0) below the sea
surface z_s (-rod_sea_surface; default the higher held end, a hang-off at the surface),
and the internal pressure p_i = p_top + rho_c g (z_top - z) of contents of density rho_c
(-rod_contents_density) at p_top at the top, the higher held end (-rod_internal_pressure).
Sources: C. P. Sparks, "The influence of tension, pressure and weight on pipe and riser
deformations and stresses", J. Energy Resour. Technol. 106 (1984) 46-54; API RP 2RD
(1998) §4.3; DNV-OS-F201 (2010) Sec. 4 B 300. Output only: the equilibrium is not
changed by it, and the axial strain stays EA eps = T_e (docs/method.md §12), exact for
a Poisson's ratio of 1/2 only (the pipe's strain is T_e + (1 - 2 nu)(p_i A_i - p_e A_e)
over EA; docs/riser.md §2b).
"""

import numpy as np

from petsc_rod.physics.term import TermOutput
from petsc_rod.quantities.report import FunctionReport
from petsc_rod.quantities.riser_numbers import effective_tension, top_end
from petsc_rod.scenes.line import piecewise_constant

DATASET_UNITS = {"external_pressure": "Pa", "internal_pressure": "Pa", "wall_tension": "N"}
ATTRIBUTE_UNITS = {"max_wall_tension": "N", "max_wall_tension_S": "m"}


def pressures(scene, z, z_top):
    """(p_e, p_i) at heights z (n,) in the scene's frame, Pa, with the top at z_top."""
    surface = z_top if scene.sea_surface is None else scene.sea_surface
    external = scene.water_density * scene.gravity * np.maximum(surface - z, 0.0)
    internal = (scene.internal_pressure
                + scene.contents_density * scene.gravity * (z_top - z))
    return external, internal


def wall_tension(tension, external, internal, od, inner):
    """T_w = T_e + p_i pi id^2 / 4 - p_e pi od^2 / 4, N (arrays of one shape)."""
    return tension + internal * np.pi * inner**2 / 4 - external * np.pi * od**2 / 4


def pressure_report(problem, vertex, scene):
    """A TermOutput: the datasets of DATASET_UNITS at the vertices, the largest wall
    tension and where. Collective."""
    S, z = vertex["S"], vertex["r"][:, 2]
    top = problem.end_state if top_end(problem) == 1 else problem.start_state
    external, internal = pressures(scene, z, float(top.position[2]))
    od = piecewise_constant(scene.sections, S, "stress_od")        # the steel wall's
    inner = piecewise_constant(scene.sections, S, "id")
    wall = wall_tension(effective_tension(vertex), external, internal, od, inner)
    k = int(np.argmax(wall)) if wall.size else 0
    local = (wall[k], S[k]) if wall.size else (None, None)
    candidates = [c for c in problem.mesh.comm.tompi4py().allgather(local) if c[0] is not None]
    largest, where = max(candidates, key=lambda c: c[0])
    return TermOutput({"external_pressure": external, "internal_pressure": internal,
                       "wall_tension": wall},
                      {"max_wall_tension": float(largest), "max_wall_tension_S": float(where)},
                      f"wall tension up to {largest:.6g} N at S = {where:.6g} m")


class PipePressures(FunctionReport):
    """The pressures and the wall tension (pressure_report) of a line of sections, made
    with its scene (problem/build.py)."""

    name, report = "pipe_pressures", pressure_report
    dataset_units, attribute_units = DATASET_UNITS, ATTRIBUTE_UNITS
