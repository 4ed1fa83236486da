"""Riser and umbilical statics (docs/riser.md): an elastic seabed (flat, sloping or
profiled) with Coulomb friction or none, a steady current with Morison normal drag, and the quantities a
riser engineer reads.

Nothing here is built or evaluated for a scene without a seabed or a current: their
terms of physics (physics/term.py) are in the problem's list only where the scene has
them (problem/build.py).

    environment.py  the seabed, the current and the drag, the profile file, checks
    bathymetry.py   the seabed's shape: a sloping plane, a profile, a grid
    slope_load.py   the horizontal part of the contact on a seabed that is not flat
    hermite.py      a component of the slope problem in Hermite dofs (z, z'), where a
                    spring on the nodes' positions is banded
    seabed.py       the unilateral spring: active nodes, contact matrices, reaction, energy
    current.py      Morison drag at the nodes from the tangents, and its derivative
    loads.py        nodal loads (P2 interpolated) as the slope problem's right-hand side
    terms.py        SeabedTerm and DragTerm: the seabed and the drag as terms, with
                    their parts of the Newton steps (analysis/positions.py, jacobian.py)
    friction.py     FrictionTerm: Coulomb friction, stick springs and sliding forces in
                    the x and y Hermite problems, anchors moved at each load step
    quantities.py   RiserNumbers: top tension and angle, touchdown, curvature, datasets
"""
