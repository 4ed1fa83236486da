"""Riser and umbilical statics (docs/riser.md): a frictionless, elastic seabed (flat,
sloping or profiled), a steady current with Morison normal drag, and the quantities a
riser engineer reads.

Nothing here is built or evaluated for a scene without a seabed or a current: their
terms of physics (physics/term.py) are in the problem's list only where the scene has
them (problem/build.py).

    environment.py  the seabed, the current and the drag, the profile file, checks
    bathymetry.py   the seabed's shape: a sloping plane, a profile, a grid
    slope_load.py   the horizontal part of the contact on a seabed that is not flat
    hermite.py      the vertical slope problem in Hermite dofs (z, z') of the centreline
    seabed.py       the unilateral spring: active nodes, contact matrices, reaction, energy
    current.py      Morison drag at the nodes from the tangents, and its derivative
    loads.py        nodal loads (P2 interpolated) as the slope problem's right-hand side
    terms.py        SeabedTerm and DragTerm: the seabed and the drag as terms, with
                    their parts of the Newton steps (analysis/heights.py, jacobian.py)
    quantities.py   RiserNumbers: top tension and angle, touchdown, curvature, datasets
"""
