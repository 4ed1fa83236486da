"""Colours and markers shared by the panels. The sections take the tab10 colours in
order of their line type's first appearance (as do the cases of a sweep); the sea, the
seabed and the marks take colours outside tab10, so that each can be found in a PNG."""

import matplotlib

PALETTE = matplotlib.colormaps["tab10"].colors
LINE = PALETTE[0]                   # a line without sections
SEA = (0.30, 0.75, 0.93)            # the sea-surface line
SEABED = (0.55, 0.27, 0.07)         # the seabed line (saddlebrown)
SEABED_FILL = (0.87, 0.78, 0.62)    # below the seabed
TOUCHDOWN = (0.85, 0.0, 0.0)
ATTACHMENT = (0.45, 0.0, 0.55)      # clump weights, buoys
ALLOWABLE = (0.85, 0.0, 0.0)        # the allowable bend radius
END = "black"                       # the anchor and the hang-off
PROJECTION = (0.6, 0.6, 0.6)        # the line projected on the plane of the ends


def section_colours(names):
    """A colour per line type name, in order of first appearance."""
    kinds = list(dict.fromkeys(names))
    return {name: PALETTE[kinds.index(name) % len(PALETTE)] for name in kinds}


def case_colour(k):
    """The colour of case ``k`` of a sweep."""
    return PALETTE[k % len(PALETTE)]
