"""The mass of a line for its modes about a static state (analysis/modes.py,
docs/modes.md): the kinetic energy

    T = 1/2 int [ m |u_t|^2 + m_a |(I - t t^T) u_t|^2
                  + J (omega_t . t)^2 + I_b |(I - t t^T) omega_t|^2 ] dS
        + 1/2 sum_p (m_p + m_a,p) |u_t(S_p)|^2

of the node displacements u (m) and the sections' small rotations omega (rad), t the unit
tangent of the static state: m the mass per length in air with the contents (kg/m; a
line type's mass), m_a = C_a rho_w pi od^2 / 4 the water's added mass normal to the line
(kg/m; none along it; C_a a line type's ``ca`` where it gives one, else
-rod_modes_added_mass, default 1), J the polar and
I_b = J / 2 the bending mass moment of inertia of the section per length (kg m; a pipe:
J = m (od^2 + id^2) / 8), and the attachments' mass m_p = rho_w V_p - F_z,p / g (from
their dead force F and volume V) with their added mass C_a rho_w V_p at the nearest node.
The line's added mass acts below the sea surface alone (nodal_mass's ``submerged``).
A uniform line (-rod_stiffness) takes its m and J from -rod_modes_mass and
-rod_modes_inertia (m by default its load's magnitude / g; J by default 0).

The integral is lumped at the P2 nodes with their Simpson weights w_n (exact for cubics:
the mass of each node's displacement and rotation is a 3 x 3 block, nodal_mass).
numpy only."""

from dataclasses import dataclass

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.scenes.line import piecewise_constant


MISSING_MASS = "the modes of a uniform line without a load need its mass per length"


def mass_known(scene, settings):
    """Whether line_inertia has a mass per length for the scene: its line types', the
    settings' or its load's."""
    return bool(scene.sections) or settings.mass is not None \
        or float(np.abs(scene.load_values).max(initial=0.0)) > 0


@dataclass(frozen=True)
class MassSettings:
    """The modal analysis's inputs beyond the scene: the added-mass coefficient C_a (1;
    of the attachments, and of the line types that give no ``ca``),
    and a uniform line's mass per length (kg/m; None: its load's magnitude / g) and
    polar mass moment of inertia per length (kg m)."""

    added_mass: float = 1.0
    mass: float = None
    inertia: float = 0.0


def line_inertia(scene, S, settings):
    """(m, m_a, J) at arc lengths S (n,), per length: kg/m, kg/m, kg m (module
    docstring)."""
    S = np.asarray(S, dtype=float)
    if scene.sections:
        m = piecewise_constant(scene.sections, S, "mass")
        od = piecewise_constant(scene.sections, S, "od")
        inner = piecewise_constant(scene.sections, S, "id")
        ca = piecewise_constant(scene.sections, S, "ca")
        ca = np.where(np.isnan(ca), settings.added_mass, ca)
        added = ca * scene.water_density * np.pi * od**2 / 4
        polar = m * (od**2 + inner**2) / 8
        return m, added, polar
    if not mass_known(scene, settings):
        raise RodInputError(MISSING_MASS)
    mass = settings.mass
    if mass is None:
        mass = float(np.abs(scene.load_values).max(initial=0.0)) / scene.gravity
    n = S.size
    return np.full(n, float(mass)), np.zeros(n), np.full(n, float(settings.inertia))


def weighted_inertia(scene, mesh, settings):
    """(w m, w m_a, w J) of the owned P2 nodes, (n,) each (kg, kg, kg m^2): each
    element's Simpson weights h_e (1/6, 4/6, 1/6) times its own section's values (at its
    midpoint), summed at the vertices, so that a vertex where the line type changes
    takes each side's mass with that side's weight."""
    left, right = mesh.vertex_sides()
    S = mesh.vertex_S
    sides = [np.asarray(line_inertia(scene, S + sign * h / 2, settings)) * h / 6
             for sign, h in ((-1, left), (1, right))]
    middle = np.asarray(line_inertia(scene, mesh.element_S + mesh.element_h / 2, settings))
    weighted = np.empty((3, mesh.n_local_nodes))
    weighted[:, 0::2] = sides[0] + sides[1]
    weighted[:, 1::2] = middle * 4 * mesh.element_h / 6
    return weighted


def nodal_mass(scene, mesh, tangents, settings, submerged=None):
    """The lumped mass of the owned P2 nodes: (translation (n, 3, 3), kg; rotation (n, 3,
    3), kg m^2): w_n [m I + m_a (I - t t^T)] and w_n [J t t^T + J/2 (I - t t^T)], t the
    unit tangents (n, 3), plus the attachments' masses at their nearest nodes
    (point_masses); the added mass only at the ``submerged`` nodes (n,) bool, where
    given."""
    m, added, polar = weighted_inertia(scene, mesh, settings)
    if submerged is not None:
        added = np.where(submerged, added, 0.0)
    t = tangents / np.linalg.norm(tangents, axis=1)[:, None]
    along = np.einsum("nk,nl->nkl", t, t)
    normal = np.eye(3) - along
    translation = m[:, None, None] * np.eye(3) + added[:, None, None] * normal
    rotation = polar[:, None, None] * (along + normal / 2)
    node, point = point_masses(scene, mesh, settings)
    np.add.at(translation, node, point[:, None, None] * np.eye(3))
    return translation, rotation


def point_masses(scene, mesh, settings):
    """(owned node index (k,), mass (k,), kg) of the attachments whose nearest P2 node
    this rank owns: m_p + C_a rho_w V_p with m_p = rho_w V_p - F_z,p / g. The nearest
    node is the one of smallest global index among those at the least distance, the same
    on any number of ranks. Collective."""
    S_p = scene.point_load_S
    if S_p.size == 0:
        return np.zeros(0, dtype=int), np.zeros(0)
    rho, g = scene.water_density, scene.gravity
    volume = scene.point_load_volumes
    mass = rho * volume - scene.point_load_forces[:, 2] / g + settings.added_mass * rho * volume
    S = mesh.node_S()
    nodes, values = [], []
    for k, s in enumerate(S_p):              # a handful of attachments
        distance = np.abs(S - s)
        local = int(np.argmin(distance)) if S.size else -1
        here = float(distance[local]) if S.size else np.inf
        least = mesh.global_min(here)
        first = 2 * mesh.vertex_start + local if here <= least else np.iinfo(np.int64).max
        if mesh.global_min(float(first)) == first and S.size:
            nodes.append(local)
            values.append(mass[k])
    return np.array(nodes, dtype=int), np.array(values, dtype=float)
