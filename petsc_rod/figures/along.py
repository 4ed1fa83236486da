"""Quantities along the line from a result file's vertex fields (numpy only)."""

import numpy as np

E_Z = np.array([0.0, 0.0, 1.0])


def unit(v):
    """Rows of ``v`` over their length."""
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def tension(n, d3):
    """The effective tension n.t, t = d3/|d3| (the file's ``effective_tension`` where it
    has one): (n,), N."""
    return np.einsum("ij,ij->i", n, unit(d3))


def bending_moment(m, d1, d2):
    """|(m.d1, m.d2)|, the moment's bending part: (n,), N m."""
    return np.hypot(np.einsum("ij,ij->i", m, d1), np.einsum("ij,ij->i", m, d2))


def curvature_components(u, d1, d2, d3):
    """The bending curvature u1 d1 + u2 d2 (= t x t') in the axes an engineer reads:
    (n, 2), 1/m. Column 0 is the bending in the vertical plane of the tangent, positive
    where the line is concave up (a sag bend, the touchdown zone), negative where it is
    concave down (a hog bend); column 1 the lateral bending, out of that plane (a line
    curved in plan). Both are independent of the direction of S. Where the tangent is
    vertical the vertical plane is that of the nearest vertex where it is not."""
    t = unit(d3)
    b = u[:, :1] * d1 + u[:, 1:2] * d2
    across = np.cross(E_Z, t)                      # horizontal, normal to the plane
    size = np.linalg.norm(across, axis=1)
    good = size > 1e-6
    if not good.any():                            # a vertical line: any vertical plane
        across[:] = [0.0, 1.0, 0.0]
    else:
        index = np.arange(len(t))
        nearest = np.interp(index, index[good], index[good]).round().astype(int)
        across = across[nearest] / size[nearest, None]
    normal = np.cross(t, across)                  # in the vertical plane, normal to t
    return np.column_stack([-np.einsum("ij,ij->i", b, across),
                            np.einsum("ij,ij->i", b, normal)])


def ends(r):
    """(anchor, top): the vertex indices of the lower and the higher end (S = 0 the
    anchor where both are level)."""
    last = len(r) - 1
    return (last, 0) if r[-1, 2] < r[0, 2] else (0, last)


def horizontal_distance(r, origin):
    """The true horizontal distance of each vertex from the point ``origin`` (3,): (n,), m."""
    return np.hypot(r[:, 0] - origin[0], r[:, 1] - origin[1])


def plane_offset(r, anchor, top):
    """Signed horizontal distance of each vertex from the vertical plane through the
    vertices ``anchor`` and ``top``: (n,), m (zeros where the ends are on one vertical)."""
    chord = r[top, :2] - r[anchor, :2]
    span = np.linalg.norm(chord)
    if span == 0:
        return np.zeros(len(r))
    normal = np.array([-chord[1], chord[0]]) / span
    return (r[:, :2] - r[anchor, :2]) @ normal
