"""Morison drag of a steady current on the line, normal component only (docs/riser.md).

Per metre of line with unit tangent t, in a current v (m/s):

    f = c |v_n| v_n,   v_n = v - (v.t) t,   c = rho C_d D / 2  (kg/m^2; f in N/m).

The tangential (skin friction) drag is not modelled. The drag follows the line: it is
evaluated at the deformed state, lagged by one iteration (terms.py).
"""

import numpy as np


def normal_drag(tangent, velocity, drag):
    """f = c |v_n| v_n, (n, 3) N/m, for tangents (n, 3) (normalised here), current
    velocities (n, 3) m/s and c = ``drag`` (kg/m^2)."""
    t = tangent / np.sqrt(_squares(tangent))[:, None]
    normal = velocity - np.einsum("nc,nc->n", velocity, t)[:, None] * t
    return drag * np.sqrt(_squares(normal))[:, None] * normal


def _squares(vectors):
    """|v|^2 of rows (n, 3): an einsum, a third of np.linalg.norm's passes (once per
    iteration at every node with a current)."""
    return np.einsum("nc,nc->n", vectors, vectors)
