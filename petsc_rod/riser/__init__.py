"""Riser and umbilical statics (docs/riser.md): a flat, frictionless, elastic seabed, a
steady current with Morison normal drag, and the quantities a riser engineer reads.

Nothing here is built or evaluated for a scene without ``-rod_seabed`` or
``-rod_current``: the solver holds ``None`` in place of the RiserTerms (terms.py).

    environment.py  the seabed, the current and the drag as given, checked
    hermite.py      the vertical slope problem in Hermite dofs (z, z') of the centreline
    seabed.py       the unilateral spring: active nodes, contact matrices, reaction, energy
    current.py      Morison drag at the nodes from the tangents and the current
    loads.py        nodal loads (P2 interpolated) as the slope problem's right-hand side
    terms.py        what the solver calls each iteration
    catenary.py     the inextensible catenary with touchdown (a start and a closed form)
    quantities.py   top tension and angle, touchdown, curvature, the riser datasets
"""
