"""The quantities an engineer reads from a solved state beside its fields (the
result file's reports; the page of a sweep is report/), behind one protocol (report.py: its
outputs and their units), held by the problem beside its terms (problem/build.py) and
collected once (io/outputs.collect) for the HDF5 file and the CSV table.

    report.py           Report: the protocol

    riser_numbers.py    RiserNumbers: top tension and angle, touchdown, anchor uplift
    line_results.py     LineResults: curvature, moments, angles along the line, end numbers
    regions.py          LineRegions: the extremes per region of the line
    stresses.py         PipeStresses: the pipe wall's von Mises stress
    pressures.py        PipePressures: internal and external pressures, wall tension
    section_numbers.py  SectionNumbers: the extremes per section of a line of sections
"""
