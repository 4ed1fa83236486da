"""The 1-D mesh: a DMDA over the vertices, the elements this rank owns, the grading.

Vertex i sits at S_i = L g(i/N). Element e = [S_e, S_e+1] belongs to the rank that owns
its left vertex; its P2 midpoint dof is stored with that vertex (slot 1), so every
element's dofs are in the rank's ghosted local vector (ghost width 1). The last
vertex's slot 1 is a phantom dof, pinned to zero in the matrices
(boundary.director_prescribed).
"""

import numpy as np
from petsc4py import PETSc


def graded_coordinates(t, grading):
    """Map g(t) = t - beta/(2 pi) sin(2 pi t) of [0, 1] onto itself.

    g'(t) = 1 - beta cos(2 pi t): elements are smallest at both ends and largest in the
    middle, their size ratio being ``grading`` = (1 + beta)/(1 - beta) >= 1. The map is
    smooth, so the graded mesh keeps the convergence orders of the uniform one.
    """
    beta = (grading - 1.0) / (grading + 1.0)
    return t - beta / (2 * np.pi) * np.sin(2 * np.pi * t)


def vertex_coordinates(vertex_index, n_elements, length, grading):
    """S of the given global vertex indices of a mesh (Mesh.coordinates)."""
    t = np.asarray(vertex_index, dtype=float) / n_elements
    return length * graded_coordinates(t, grading)


def end_element_lengths(n_elements, length, grading):
    """The lengths (m) of the first and last elements, the smallest of a graded mesh, as
    the mesh will compute them: known before the mesh is allocated."""
    ends = vertex_coordinates([0, 1, n_elements - 1, n_elements], n_elements, length, grading)
    return np.diff(ends)[[0, 2]]


class Mesh:
    """A distributed mesh of ``n_elements`` elements on [0, length].

    Attributes a kernel needs are plain numpy arrays of this rank's part; the rank
    itself never appears outside this class (``on_lower_boundary`` and
    ``on_upper_boundary`` say whether the rank holds S = 0 and S = L).
    """

    def __init__(self, comm, n_elements, length, grading=1.0):
        self.n_elements = int(n_elements)
        self.n_vertices = self.n_elements + 1
        self.length = float(length)
        self.grading = float(grading)
        self.comm = comm
        self.da = PETSc.DMDA().create(dim=1, sizes=(self.n_vertices,), dof=2,
                                      stencil_width=1, comm=comm)
        (self.vertex_start, self.vertex_end), = self.da.getRanges()
        (self.ghost_start, self.ghost_end), = self.da.getGhostRanges()
        self.element_start = self.vertex_start
        self.element_end = min(self.vertex_end, self.n_elements)
        self.on_lower_boundary = self.vertex_start == 0
        self.on_upper_boundary = self.vertex_end == self.n_vertices
        self.vertex_S = self.coordinates(np.arange(self.vertex_start, self.vertex_end))
        ends = self.coordinates(np.arange(self.element_start, self.element_end + 1))
        self.element_S = ends[:-1]
        self.element_h = np.diff(ends)
        # Local (ghosted) index of each owned element's left vertex.
        self.element_local = np.arange(self.element_start, self.element_end) - self.ghost_start

    @property
    def n_local_elements(self):
        return self.element_end - self.element_start

    @property
    def n_local_nodes(self):
        """P2 nodes this rank owns: its vertices and the midpoints stored with them, in
        DMDA order (vertex, midpoint, vertex, ...); the last vertex has no midpoint."""
        return (self.vertex_end - self.vertex_start) + self.n_local_elements

    def node_S(self):
        """S of the owned P2 nodes, (n_local_nodes,)."""
        S = np.empty(self.n_local_nodes)
        S[0::2] = self.vertex_S
        S[1::2] = self.element_S + self.element_h / 2
        return S

    def node_weights(self):
        """Simpson weights of the owned P2 nodes, (n_local_nodes,): h_e (1/6, 4/6, 1/6) per
        element, summed at the vertices, so that sum_n w_n g(S_n) = int g dS exactly for
        a piecewise cubic g (the quadrature of the constraint, docs/method.md §4)."""
        vertices = np.arange(self.vertex_start, self.vertex_end)
        left = self.coordinates(vertices) - self.coordinates(np.maximum(vertices - 1, 0))
        right = self.coordinates(np.minimum(vertices + 1, self.n_elements)) \
            - self.coordinates(vertices)
        w = np.empty(self.n_local_nodes)
        w[0::2] = (left + right) / 6
        w[1::2] = 4 * self.element_h / 6
        return w

    def coordinates(self, vertex_index):
        """S of the given global vertex indices."""
        return vertex_coordinates(vertex_index, self.n_elements, self.length, self.grading)

    def point_S(self, xi):
        """S at reference points xi (nq,) of the owned elements, (ne, nq)."""
        return self.element_S[:, None] + np.asarray(xi)[None, :] * self.element_h[:, None]

    def elements_around_owned_vertices(self):
        """(first, end) global range of the elements that touch an owned vertex.

        All their dofs are in the ghosted local vector; used to evaluate one-sided
        limits at the vertices.
        """
        return max(self.vertex_start - 1, 0), min(self.vertex_end, self.n_elements)

    def global_sum(self, value):
        """Sum of a float or array over all ranks."""
        return self.comm.tompi4py().allreduce(value)

    def prefix_sum(self, element_values):
        """Sum of the values of all elements left of each owned vertex.

        element_values: this rank's owned elements, (n_local_elements, ...). Vertex i gets
        sum_{e < i} v_e: the running sum over this rank's elements plus the total of the
        ranks before it (one MPI exscan; nothing is gathered). Returns (n_owned, ...).
        """
        values = np.asarray(element_values, dtype=float)
        before = self.comm.tompi4py().exscan(values.sum(axis=0))
        if self.on_lower_boundary:          # exscan leaves the first rank's result undefined
            before = np.zeros(values.shape[1:])
        running = np.concatenate([np.zeros((1,) + values.shape[1:]), np.cumsum(values, axis=0)])
        return before + running[:self.vertex_end - self.vertex_start]

    def global_min(self, value):
        """Minimum of a float over all ranks."""
        from mpi4py import MPI
        return self.comm.tompi4py().allreduce(value, op=MPI.MIN)

    def global_max(self, value):
        """Maximum of a float over all ranks."""
        from mpi4py import MPI
        return self.comm.tompi4py().allreduce(value, op=MPI.MAX)

    @property
    def smallest_element(self):
        """The shortest element length over all ranks (m)."""
        return self.global_min(float(self.element_h.min()) if self.element_h.size else np.inf)

    def destroy(self):
        self.da.destroy()
