"""Terms of physics (the protocol, term.py), each with its kernel; built for a scene
that has them (problem/build.py).

    term.py         the protocol: Term, TermOutput
    stretch.py, dead_loads.py, point_loads.py, flex_joint.py
    nodal_load.py   NodalLoadTerm: a load per metre known at the P2 nodes
    seabed.py       SeabedTerm: the elastic seabed, solved with the z slope
    drag.py         the Morison normal drag and its derivative, DragTerm
    surface.py      SurfaceTerm: the buoyancy lost above the sea surface
    friction.py     FrictionTerm: Coulomb friction of the seabed
    slope_load.py   SeabedSlopeLoad: the horizontal part of the contact on a slope
"""
