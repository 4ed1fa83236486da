"""OC3-Hywind's spar as a free body on the moorings of its MoorDyn deck
(tests/data/moordyn/OC3Hywind_MoorDyn.dat): the deck's coupled fairleads (``vessel``
points, held where the coupled code puts them) become the local points of one rigid
body, free in its six degrees of freedom, so that the coupled equilibrium and the
body's 6 x 6 mooring stiffness of a real spread can be computed (tests, the system
benchmark, scripts/compare_moorpy.py).

The spar's data are the OC3 definition's (Jonkman, Definition of the floating system
for phase IV of OC3, NREL/TP-500-47566, 2010) as commonly quoted (not read here from
the report): displaced volume 8029.21 m^3, centre of buoyancy 62.07 m below the
surface, 6.5 m diameter at the waterline, the whole system's centre of gravity 78.0 m
below it (the platform's 7,466,330 kg at 89.9155 m, the tower's 249,718 kg and the
rotor-nacelle's 350,000 kg above). Its mass is not taken from there but set so that
its weight and buoyancy balance the three lines' vertical pull at rest (the elastic
catenary's, validation/elastic_catenary.py): the spar floats at rest where the deck
puts it (8.066e6 kg, the definition's total to 1e-6).
"""

from dataclasses import replace

import numpy as np

from petsc_rod.model.system import Body, Connection, System
from petsc_rod.validation.elastic_catenary import elastic_catenary

VOLUME = 8029.21                    # m^3
BUOYANCY_DEPTH = 62.07              # m below the surface
GRAVITY_DEPTH = 78.0                # m below the surface
WATERLINE_DIAMETER = 6.5            # m


def catenaries(deck):
    """(n_lines,) ElasticCatenary: each line of ``deck`` (one section) between its ends
    where the deck puts them, from its start (on the seabed)."""
    sea = deck.environment
    out = []
    for line in deck.lines:
        ((kind, length, _),) = line.line.sections
        a, b = (np.asarray(deck.node(c.to).position, dtype=float)
                for c in (line.start, line.end))
        out.append(elastic_catenary(length, kind.submerged_weight(sea.water_density,
                                                                  sea.gravity),
                                    kind.ea, float(np.hypot(*(b - a)[:2])),
                                    float(b[2] - a[2])))
    return out


def hanging_weight(deck):
    """(n_lines,): each line's vertical force on its top end at rest, N."""
    return np.array([c.V_A + c.weight * (c.length - c.grounded) for c in catenaries(deck)])


def spar(deck, load=(0.0,) * 6, held=(False,) * 6):
    """The System of ``deck`` (read_moordyn's System of the OC3-Hywind deck) with its
    prescribed points replaced by the body ``spar`` (reference point at the surface on
    its axis, body axes the global ones at rest) under the external ``load`` (6,), N
    and N m about its reference point, ``held`` its held degrees of freedom."""
    sea = deck.environment
    fairleads = {p.name: p.position for p in deck.points if p.kind == "prescribed"}
    lines = tuple(replace(line, end=Connection("spar", tuple(fairleads[line.end.to])))
                  for line in deck.lines)
    rho, g = sea.water_density, sea.gravity
    area = np.pi * WATERLINE_DIAMETER**2 / 4
    moment = np.pi * WATERLINE_DIAMETER**4 / 64
    mass = rho * VOLUME - hanging_weight(deck).sum() / g
    body = Body("spar", mass=float(mass), cog=(0.0, 0.0, -GRAVITY_DEPTH), volume=VOLUME,
                cob=(0.0, 0.0, -BUOYANCY_DEPTH), waterplane_area=float(area),
                waterplane_moments=(float(moment),) * 2, load=tuple(load), held=tuple(held))
    system = System(lines, tuple(p for p in deck.points if p.name not in fairleads),
                    (body,), sea)
    system.check()
    return system


# The OC3-Hywind system's parts (Jonkman 2010, as commonly quoted; not read from the
# report here): (mass kg, height of its centre of mass m, its own inertia about it
# (roll = pitch, yaw) kg m^2): the platform; the tower (87.6 m from 10 m, as a thin
# tube: m L^2 / 12); the rotor-nacelle assembly as a point mass at the hub, 90 m.
PARTS = ((7466330.0, -89.9155, 4229230000.0, 164230000.0),
         (249718.0, 43.4, 249718.0 * 77.6**2 / 12, 0.0),
         (350000.0, 90.0, 0.0, 0.0))
# The spar's radius against depth, m: 6.5 m diameter to 4 m down, a taper to 9.4 m at
# 12 m, 9.4 m to the keel at 120 m.
PROFILE = ((0.0, 3.25), (4.0, 3.25), (12.0, 4.7), (120.0, 4.7))
# Published natural frequencies of the whole system (Hz), as commonly quoted from the
# OC3 phase IV code comparison (Jonkman and Musial, NREL/TP-5000-48191, 2010; not at
# hand here to check the digits); the pitch value is the full system's by an
# eigenanalysis of the linearised matrices (J. Jonkman on NREL's forum, "OC3 Spar
# natural frequency").
PUBLISHED_FREQUENCIES = {"surge": 0.0080, "heave": 0.0324, "pitch": 0.0343, "yaw": 0.1210}


def spar_inertia():
    """(mass, cog height, inertia (3, 3) about the cog) of the whole system (PARTS)."""
    parts = np.array(PARTS)
    mass = parts[:, 0].sum()
    z = parts[:, 0] @ parts[:, 1] / mass
    pitch = parts[:, 2].sum() + parts[:, 0] @ (parts[:, 1] - z) ** 2
    return mass, z, np.diag([pitch, pitch, parts[:, 3].sum()])


def added_mass(rho, steps=12000):
    """(6, 6) strip-theory added mass of the spar about its reference point at the
    surface, C_a = 1 on every section: rho pi r^2 per metre across (A11 = A22), its
    first and second moments in z (A15 = -A24 = rho int a z dz, A44 = A55 = rho int a
    z^2 dz) and, in heave, the keel's disc, rho D^3 / 6 (half a disc's in an infinite
    fluid)."""
    depth = np.linspace(0.0, PROFILE[-1][0], steps + 1)
    radius = np.interp(depth, *np.array(PROFILE).T)
    z = -0.5 * (depth[1:] + depth[:-1])
    area = np.pi * (0.5 * (radius[1:] + radius[:-1])) ** 2 * np.diff(depth)
    A = np.zeros((6, 6))
    A[0, 0] = A[1, 1] = rho * area.sum()
    A[0, 4] = A[4, 0] = rho * area @ z
    A[1, 3] = A[3, 1] = -rho * area @ z
    A[3, 3] = A[4, 4] = rho * area @ z**2
    A[2, 2] = rho * (2 * radius[-1]) ** 3 / 6
    return A


def free_spar(deck):
    """The spar free at rest with the whole system's inertia and the strip theory's
    added mass (its mass stays validation/oc3_hywind's, balancing the lines, and its
    cog GRAVITY_DEPTH down)."""
    system = spar(deck)
    _, _, inertia = spar_inertia()
    body = replace(system.bodies[0], inertia=tuple(inertia.ravel()),
                   added_mass=tuple(added_mass(deck.environment.water_density).ravel()))
    return replace(system, bodies=(body,))
