"""The line's surroundings, data only (docs/riser.md): nothing here is a term of physics
(physics/) or a report (quantities/).

    seabed.py       the elastic seabed (flat or shaped), its friction, its stiffness
                    bounds, the checks of the ends and the footprint against it
    bathymetry.py   the seabed's shape: a sloping plane, a profile, a grid
    current.py      a steady current (uniform or a depth profile) and the drag coefficient
    profiles.py     the current profile and seabed profile or grid text files
"""
