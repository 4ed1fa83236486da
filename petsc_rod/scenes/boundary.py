"""Essential boundary conditions as prescribed dofs of the scalar problems (§5).

A prescribed dof is (vertex, slot, value): the same vertex and slot for the x, y and z
components, with a 3-vector of values. Rows are fixed once per solver (the kinds of the
ends do not change); values change along the continuation path.

The fields of the global step are d1, d2 and the slope r' = d3, all P2: a clamp
prescribes the whole frame, i.e. one vertex dof of each. Positions are not dofs of the slope:
a held end (clamp or pin) is where r is integrated from, and when both ends are held
r(L) - r(0) = int slope is a constraint of the slope problem (centreline.py).
"""

import numpy as np

VERTEX, MIDPOINT = 0, 1      # P2 slots: vertex value and the midpoint to its right
HELD = ("clamp", "pin")      # end kinds whose position is prescribed


def director_prescribed(index, start, end, n_elements):
    """Prescribed dofs of d_index (index 0, 1, 2, with d3 = slope = r'): the frame row at a
    clamp, and the phantom midpoint slot of the last vertex, pinned to zero so that the
    matrix stays regular."""
    dofs = []
    for vertex, state in ((0, start), (n_elements, end)):
        if state.kind == "clamp":
            dofs.append((vertex, VERTEX, state.frame[index]))
    dofs.append((n_elements, MIDPOINT, np.zeros(3)))
    return dofs


def clamped_nodes(mesh, start, end):
    """Mask of the owned P2 nodes whose frame a clamp prescribes, (n_nodes,): the first
    node at a clamped start, the last at a clamped end, on the ranks that own them."""
    clamped = np.zeros(mesh.n_local_nodes, dtype=bool)
    if start.kind == "clamp" and mesh.on_lower_boundary:
        clamped[0] = True
    if end.kind == "clamp" and mesh.on_upper_boundary:
        clamped[-1] = True
    return clamped


def is_held(state):
    """Whether the end's position is prescribed (a clamp or a pin)."""
    return state.kind in HELD
