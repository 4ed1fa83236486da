"""What a solved state reports beside its fields (ReportTerm, physics/term.py; built in
problem/build.py): read by io/results.py and io/line_table.py.

    riser_numbers.py    RiserNumbers: top tension and angle, touchdown, anchor uplift
    line_results.py     LineResults: curvature, moments, angles along the line, end numbers
    regions.py          LineRegions: the extremes per region of the line
    stresses.py         PipeStresses: the pipe wall's von Mises stress
    pressures.py        PipePressures: internal and external pressures, wall tension
    section_numbers.py  SectionNumbers: the extremes per section of a line of sections
"""
