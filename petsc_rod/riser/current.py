"""Morison drag of a steady current on the line, normal component only (docs/riser.md).

Per metre of line with unit tangent t, in a current v (m/s):

    f = c |v_n| v_n,   v_n = v - (v.t) t,   c = rho C_d D / 2  (kg/m^2; f in N/m).

The tangential (skin friction) drag is not modelled. The drag follows the line: it is
evaluated at the deformed state, lagged by one iteration (terms.py). Its derivative in a
turn omega of the tangent, delta t = omega x t, is (drag_jacobian)

    delta f = c (|v_n| I + v_n v_n^T / |v_n|) (t v^T + (v.t) I) [t]x omega

(delta v_n = -(t v^T + (v.t) I) delta t; f is C^1 with zero derivative where v_n = 0).
"""

import numpy as np

from petsc_rod.analysis.second_variation import skew


def normal_drag(tangent, velocity, drag):
    """f = c |v_n| v_n, (n, 3) N/m, for tangents (n, 3) (normalised here), current
    velocities (n, 3) m/s and c = ``drag`` (kg/m^2)."""
    t = _unit(tangent)
    normal = velocity - np.einsum("nc,nc->n", velocity, t)[:, None] * t
    return drag * np.sqrt(_squares(normal))[:, None] * normal


def drag_jacobian(tangent, velocity, drag):
    """G, (n, 3, 3): the derivative of normal_drag in a turn omega of each tangent,
    delta f = G omega (module docstring), for tangents (n, 3) (normalised here), current
    velocities (n, 3) m/s and c = ``drag`` (n,) kg/m^2."""
    t = _unit(tangent)
    along = np.einsum("nc,nc->n", velocity, t)
    normal = velocity - along[:, None] * t
    speed = np.linalg.norm(normal, axis=1)
    unit_normal = np.divide(normal, speed[:, None], out=np.zeros_like(normal),
                            where=speed[:, None] > 0)
    eye = np.eye(3)[None]
    stiffness = np.asarray(drag, dtype=float).reshape(-1)[:, None, None] * (
        speed[:, None, None] * eye + speed[:, None, None]
        * unit_normal[:, :, None] * unit_normal[:, None, :])
    turn = t[:, :, None] * velocity[:, None, :] + along[:, None, None] * eye
    return stiffness @ turn @ skew(t)


def _unit(tangent):
    """The unit tangents of rows (n, 3), 0 where a row is 0: a node that the stretched
    local step compressed to a point (k = 0, docs/method.md §12) has no direction, and
    the whole current is normal to it (its drag is then finite, and its derivative 0)."""
    length = np.sqrt(_squares(tangent))[:, None]
    return np.divide(tangent, length, out=np.zeros_like(tangent, dtype=float),
                     where=length > 0)


def _squares(vectors):
    """|v|^2 of rows (n, 3): an einsum, a third of np.linalg.norm's passes (once per
    iteration at every node with a current)."""
    return np.einsum("nc,nc->n", vectors, vectors)
