"""The fields at the owned P2 nodes, and the sums of the stopping tests, in arrays
allocated once per mesh (docs/performance.md, "Per-iteration overhead").

A component of a P2 field is a DMDA Vec with two slots per vertex (the vertex value and
the midpoint value of the element to its right), so its first n_nodes entries are the
owned node values in node order (the last vertex's midpoint slot is a phantom). Hence:

* node directors D (n_nodes, 3 rows d1 d2 r', 3 components): 9 strided copies of Vec
  prefixes, block by block (``blocks``), into the same array every iteration;
* r at the nodes: the vertex values of r, and at the midpoint of element e
  r(S_e) + h (5 r'_0 + 8 r'_m - r'_1) / 24 (exact for the P2 slope), the element dofs
  r'_0, r'_m, r'_1 being stride-2 slices of the slope's ghosted arrays
  (fields.element_slices), not a gather through an index array;
* the sums of the stopping tests (RodState.norms): weighted row sums of squares of
  differences (to tau, to the previous values, to the unstressed reference), block by block through a scratch array that stays in cache; the previous
  values are kept by swapping two arrays, not by a copy.
"""

import numpy as np

from petsc_rod.mesh.elements import HALF_ELEMENT
from petsc_rod.mesh.fields import CHUNK, blocks, element_slices
from petsc_rod.scenes.scene import REFERENCE_FRAME



class NodeValues:
    """Node directors and positions of the current and the previous evaluation, and the
    work arrays of the stopping sums. Shapes: directors (n, 3, 3), positions (n, 3),
    n = mesh.n_local_nodes; numpy only (the Vecs stay with their fields)."""

    def __init__(self, mesh):
        n, ne = mesh.n_local_nodes, mesh.n_local_elements
        self.n, self.n_elements = n, ne
        self.first = int(mesh.element_local[0]) if ne else 0
        self.half = HALF_ELEMENT[:, None] * mesh.element_h[None, :]     # (3, ne)
        self.directors, self.positions = np.zeros((n, 3, 3)), np.zeros((n, 3))
        self.previous_directors, self.previous_positions = np.zeros((n, 3, 3)), np.zeros((n, 3))
        self._scratch = np.zeros((min(n, CHUNK), 9))
        self._rows = np.zeros(min(n, CHUNK))
        self._element_work = np.zeros(ne)

    def take_directors(self, fields):
        """D[:, i, c] = component c of field i at the nodes (fields d1, d2, r'), block by
        block: the block of D a column is scattered into stays in cache."""
        sources = [(i, c, vec.getArray(readonly=True)) for i, field in enumerate(fields)
                   for c, vec in enumerate(field.components)]
        for block in blocks(self.n):
            rows = self.directors[block]
            for i, c, values in sources:
                rows[:, i, c] = values[block]
        return self.directors

    def take_positions(self, r, slope):
        """r at the nodes from the vertex values of ``r`` and the ghosted ``slope``
        (VectorFields); one ghost update of the slope."""
        ne, work = self.n_elements, self._element_work
        for c, (vec, ghosted) in enumerate(zip(r.components, slope.ghosted_components())):
            vertices = vec.getArray(readonly=True)[0::2]
            self.positions[0::2, c] = vertices
            midpoints = self.positions[1::2, c]
            left, middle, right = element_slices(ghosted, self.first, ne)
            np.multiply(self.half[0], left, out=midpoints)
            midpoints += np.multiply(self.half[1], middle, out=work)
            midpoints += np.multiply(self.half[2], right, out=work)
            midpoints += vertices[:ne]
        return self.positions

    def remember(self):
        """The current values become the previous ones (a copy: both stay valid)."""
        np.copyto(self.previous_directors, self.directors)
        np.copyto(self.previous_positions, self.positions)

    def stopping_sums(self, tau, weights, node_S):
        """Local sums (gap, size, step, deformation) of the stopping tests, with
        X = (r, D) and X^ref the unstressed reference state at the nodes, S_n e_x and the
        reference frame (scenes.scene.REFERENCE_FRAME; node_S (n,), m: nothing stored
        per node but S):

            gap = sum_n w_n |D_n - tau_n|^2,   size = sum_n w_n |X_n|^2,
            step = sum_n w_n |X_n - X_n^prev|^2,
            deformation = sum_n w_n |X_n - X_n^ref|^2,

        over blocks of CHUNK nodes, so that the differences stay in cache and each array
        is read once; then the current values become the previous ones (the arrays are
        swapped: the next take_directors and take_positions overwrite the current
        ones)."""
        n = self.n
        directors, previous = self.directors.reshape(n, 9), self.previous_directors.reshape(n, 9)
        tau = tau.reshape(n, 9)
        reference, axis = REFERENCE_FRAME.reshape(9), REFERENCE_FRAME[2]
        positions, previous_positions = self.positions, self.previous_positions
        sums = np.zeros(4)          # gap, size, step, deformation
        for block in blocks(n):
            size = block.stop - block.start
            w, rows, work = weights[block], self._rows[:size], self._scratch[:size]

            def weighted(a, b=None):
                """sum_n w_n |a_n - b_n|^2 over the block's rows."""
                if b is not None:
                    a = np.subtract(a, b, out=work[:, :a.shape[1]])
                return w @ np.einsum("nk,nk->n", a, a, out=rows)

            d, p = directors[block], positions[block]
            sums[0] += weighted(d, tau[block])
            sums[1] += weighted(d) + weighted(p)
            sums[2] += weighted(d, previous[block]) + weighted(p, previous_positions[block])
            sums[3] += weighted(d, reference)
            away = np.subtract(p, node_S[block, None] * axis, out=work[:, :3])
            sums[3] += weighted(away)
        self.directors, self.previous_directors = self.previous_directors, self.directors
        self.positions, self.previous_positions = self.previous_positions, self.positions
        return sums
