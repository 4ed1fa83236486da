"""The von Mises stress of a pipe's wall and its utilisation (docs/riser.md §2c), for a
line of line types with an inner diameter (scenes/line.py: od, id, smys).

At each vertex the wall carries the wall tension T_w (quantities/pressures.py), the bending
moment M = |(m.d1, m.d2)|, the torque Q = m.t and the pressures p_i, p_e. With
r_o = od / 2, r_i = id / 2, A = pi (r_o^2 - r_i^2), I = pi (r_o^4 - r_i^4) / 4 and
J = 2 I, at radius r of the wall (Lame's thick cylinder, exact for an elastic tube and
tending to the thin-wall p D / 2 t as the wall thins):

    hoop    s_h(r) = (p_i r_i^2 - p_e r_o^2) / (r_o^2 - r_i^2)
                     + (p_i - p_e) r_i^2 r_o^2 / ((r_o^2 - r_i^2) r^2)
    radial  s_r(r) = (p_i r_i^2 - p_e r_o^2) / (r_o^2 - r_i^2)
                     - (p_i - p_e) r_i^2 r_o^2 / ((r_o^2 - r_i^2) r^2)
                     (s_r(r_i) = -p_i, s_r(r_o) = -p_e)
    axial   s_a(r) = T_w / A +- M r / I         (the two ends of the bending plane)
    shear   tau(r) = Q r / J
    von Mises  s_vm = sqrt(s_a^2 + s_h^2 + s_r^2 - s_a s_h - s_h s_r - s_r s_a + 3 tau^2)

evaluated at four fibres, the outer and the inner one on the tension and on the
compression side of the bending, and the largest taken (the stresses vary monotonically
in r and linearly across the section between them). The utilisation is
s_vm / (f smys), f the design factor (-rod_design_factor, default 2/3, the
basic allowable of API RP 2RD for the operating case, C_f C_a with C_a = 2/3, C_f = 1).

Sources: G. Lame (1852), as in S. Timoshenko and J. N. Goodier, "Theory of Elasticity"
(1951) §26 (thick cylinder under pressure); API RP 2RD (1998) §4.3 (von Mises
equivalent stress of a riser's wall from the true wall tension, bending, pressure and
torsion, and its allowable C_f C_a sigma_y); C. P. Sparks, "Fundamentals of Marine Riser
Mechanics" (2007) ch. 3 (the wall tension in the axial stress). Output only: the
equilibrium is not changed.
"""

import numpy as np

from petsc_rod.physics.term import TermOutput
from petsc_rod.quantities import pressures as pipe_pressures
from petsc_rod.quantities.line_results import bending_moment, torque
from petsc_rod.quantities.report import FunctionReport
from petsc_rod.quantities.riser_numbers import effective_tension, top_end
from petsc_rod.scenes.line import piecewise_constant

DATASET_UNITS = {"von_mises": "Pa", "utilisation": "1"}
ATTRIBUTE_UNITS = {"max_von_mises": "Pa", "max_von_mises_S": "m",
                   "max_utilisation": "1", "max_utilisation_S": "m", "design_factor": "1"}


def lame_stresses(p_i, p_e, r_i, r_o, r):
    """(hoop, radial) stress at radius r of a thick tube of radii r_i < r_o under the
    internal and external pressures p_i, p_e (Pa, m; arrays that broadcast), Pa."""
    span = r_o**2 - r_i**2
    mean = (p_i * r_i**2 - p_e * r_o**2) / span
    varying = (p_i - p_e) * r_i**2 * r_o**2 / (span * r**2)
    return mean + varying, mean - varying


def von_mises(axial, hoop, radial, shear):
    """The von Mises equivalent stress of the principal-axis stresses axial, hoop,
    radial and the shear in the axial-hoop plane (torsion), Pa."""
    return np.sqrt(axial**2 + hoop**2 + radial**2 - axial * hoop - hoop * radial
                   - radial * axial + 3 * shear**2)


def pipe_von_mises(wall, moment, twist, p_i, p_e, od, inner):
    """The largest von Mises stress (Pa) over the outer and inner fibres on both sides of
    the bending of a pipe of outer and inner diameters od, inner (m) carrying the wall
    tension ``wall`` (N), the bending moment ``moment`` (N m), the torque ``twist``
    (N m) and the pressures p_i, p_e (Pa) (module docstring). Arrays of one shape (n,);
    NaN where inner is 0 (no bore: no pipe)."""
    r_o, r_i = od / 2, inner / 2
    with np.errstate(divide="ignore", invalid="ignore"):
        area = np.pi * (r_o**2 - r_i**2)
        second = np.pi * (r_o**4 - r_i**4) / 4
        largest = np.full(np.shape(wall), -np.inf)
        for r in (r_o, r_i):
            hoop, radial = lame_stresses(p_i, p_e, r_i, r_o, r)
            shear = twist * r / (2 * second)
            for side in (1.0, -1.0):
                axial = wall / area + side * moment * r / second
                largest = np.maximum(largest, von_mises(axial, hoop, radial, shear))
    return np.where(inner > 0, largest, np.nan)


def _largest(comm, values, S):
    """(largest finite value, its S) over the ranks' owned vertices; (NaN, NaN) when no
    rank has one. Collective."""
    finite = np.isfinite(values)
    local = None
    if np.any(finite):
        k = int(np.argmax(np.where(finite, values, -np.inf)))
        local = (float(values[k]), float(S[k]))
    candidates = [c for c in comm.tompi4py().allgather(local) if c is not None]
    return max(candidates) if candidates else (np.nan, np.nan)


def stress_report(problem, vertex, scene):
    """A TermOutput: the datasets von_mises (Pa, NaN where a section has no bore) and
    utilisation (1, NaN where its line type has no smys) at the vertices; the largest of
    each and where. Collective."""
    S, z = vertex["S"], vertex["r"][:, 2]
    top = problem.end_state if top_end(problem) == 1 else problem.start_state
    p_e, p_i = pipe_pressures.pressures(scene, z, float(top.position[2]))
    od = piecewise_constant(scene.sections, S, "stress_od")        # the steel wall's
    inner = piecewise_constant(scene.sections, S, "id")
    smys = piecewise_constant(scene.sections, S, "smys")
    wall = pipe_pressures.wall_tension(effective_tension(vertex), p_e, p_i, od, inner)
    stress = pipe_von_mises(wall, bending_moment(vertex), torque(vertex), p_i, p_e, od,
                            inner)
    utilisation = stress / (scene.design_factor * smys)
    comm = problem.mesh.comm
    most, most_S = _largest(comm, stress, S)
    used, used_S = _largest(comm, utilisation, S)
    text = f"von Mises up to {most / 1e6:.5g} MPa at S = {most_S:.6g} m"
    if np.isfinite(used):
        text += f", utilisation up to {used:.4g} at S = {used_S:.6g} m"
    return TermOutput({"von_mises": stress, "utilisation": utilisation},
                      {"max_von_mises": most, "max_von_mises_S": most_S,
                       "max_utilisation": used, "max_utilisation_S": used_S,
                       "design_factor": scene.design_factor}, text)


class PipeStresses(FunctionReport):
    """The von Mises stress and the utilisation (stress_report) of a line of sections
    some of which have an inner diameter, made with its scene (problem/build.py)."""

    name, report = "pipe_stresses", stress_report
    dataset_units, attribute_units = DATASET_UNITS, ATTRIBUTE_UNITS
