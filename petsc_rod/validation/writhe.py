"""The writhe of a whole centreline by the Gauss double integral (numpy only), an
independent check of Fuller's local writhe that the runtime uses
(petsc_rod/analysis/link.py).
"""

import numpy as np


def gauss_writhe(points, axis, reach=50.0):
    """Writhe (turns) of a whole centreline by the Gauss double integral, an independent
    check of Fuller's formula (analysis/link.py; tests, scripts/stability_matrix.py;
    O(n^2) work and memory, n = len(points)).

    points: (n, 3) along a curve whose end tangents are ``axis``. The curve is closed as
    Fuller's formula assumes: rays of length ``reach`` along -axis and +axis from its ends
    (points geometrically spaced from the curve's own spacing), joined far away by a path
    whose offset across the axis varies linearly, so that the closure adds no writhe of its
    own. Wr = (1/4 pi) sum_{i != j} (T_i x T_j).(M_i - M_j) / |M_i - M_j|^3 over the
    segments T (midpoints M) of the closed polygon.
    """
    points = np.asarray(points, dtype=float)
    axis = np.asarray(axis, dtype=float)
    first, last = points[0], points[-1]
    spacing = np.linalg.norm(points[1] - points[0])
    ray = np.geomspace(spacing, reach, 200)[:, None] * axis
    # "up": any direction across the axis, for the far side of the closure
    up = np.cross(axis, [0.0, 0.0, 1.0] if abs(axis[2]) < 0.9 else [1.0, 0.0, 0.0])
    up = reach * up / np.linalg.norm(up)
    u = np.linspace(0.0, 1.0, 100)[1:-1, None]
    far_end, far_start = last + reach * axis, first - reach * axis
    closure = np.concatenate([
        last + ray, far_end + u * up,
        far_end + up + np.linspace(0.0, 1.0, 200)[:, None] * (far_start - far_end),
        far_start + (1 - u) * up, (first - ray)[::-1]])
    polygon = np.concatenate([points, closure])
    segments = np.roll(polygon, -1, axis=0) - polygon
    midpoints = polygon + 0.5 * segments
    offsets = midpoints[:, None, :] - midpoints[None, :, :]
    distance = np.linalg.norm(offsets, axis=2)
    np.fill_diagonal(distance, np.inf)
    crossed = np.cross(segments[:, None, :], segments[None, :, :])
    return float(np.sum(np.einsum("ijk,ijk->ij", crossed, offsets) / distance**3) / (4 * np.pi))
