"""Essential boundary conditions as prescribed dofs of the scalar problems (§5).

A prescribed dof is (vertex, slot, value): the same vertex and slot for the x, y and z
components, with a 3-vector of values. Rows are fixed once per solver (the kinds of the
ends do not change); values change along the continuation path.
"""

import numpy as np

VALUE, SLOPE = 0, 1          # Hermite slots: r and r'
VERTEX, MIDPOINT = 0, 1      # P2 slots: vertex value and the midpoint to its right


def r_prescribed(start, end, n_elements):
    """Prescribed r dofs: position at a clamp or pin, and r' = d3 at a clamp."""
    dofs = []
    for vertex, state in ((0, start), (n_elements, end)):
        if state.kind in ("clamp", "pin"):
            dofs.append((vertex, VALUE, state.position))
        if state.kind == "clamp":
            dofs.append((vertex, SLOPE, state.frame[2]))
    return dofs


def director_prescribed(index, start, end, n_elements):
    """Prescribed d_index dofs (index 0 or 1): the frame at a clamp, and the phantom
    midpoint slot of the last vertex, pinned to zero so that the matrix stays regular."""
    dofs = []
    for vertex, state in ((0, start), (n_elements, end)):
        if state.kind == "clamp":
            dofs.append((vertex, VERTEX, state.frame[index]))
    dofs.append((n_elements, MIDPOINT, np.zeros(3)))
    return dofs
