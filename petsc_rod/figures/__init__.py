"""Figures of result files (matplotlib and h5py only; never PETSc, never a running
solve). ``petsc_rod/plots.py`` is the entry point: ``result_figure(path)`` for one file,
``sweep_figure(paths, labels)`` for several overlaid (docs/output.md, "Figures").

    read.py      a result file as a ``Result``: the arrays and numbers a figure draws
    along.py     quantities along the line derived from the file's fields (numpy)
    style.py     the colours and markers every panel shares
    scene.py     the line in space: the elevation and the plan, with the sea, the seabed,
                 the ends, the touchdown, the sections and the attachments
    graphs.py    the graphs against S: tension, curvature, bending moment, seabed reaction
    titles.py    what the figure's title says
    rod.py       the plain rod's figure (no riser datasets): projections and strains
    riser.py     the riser's figure, and the overlay of several files (a sweep)
"""
