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
