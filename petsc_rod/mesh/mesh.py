"""The 1-D mesh: a DMDA over the vertices, the elements this rank owns, the grading.

Vertex i sits at S_i = L g(i/N), g the sine map whose beta makes the largest element
exactly ``grading`` times the smallest (mesh_beta; grading 1 is uniform). Element
e = [S_e, S_e+1] belongs to the rank that owns
its left vertex; its P2 midpoint dof is stored with that vertex (slot 1), so every
element's dofs are in the rank's ghosted local vector (ghost width 1). The last
vertex's slot 1 is a phantom dof, pinned to zero in the matrices
(boundary.director_prescribed).
"""

import numpy as np
from petsc4py import PETSc

# The smallest element, relative to the length, whose end coordinates double precision
# still tells apart to many digits.
MIN_RELATIVE_ELEMENT = 1e-12


def _x_minus_sin(x):
    """x - sin x for 0 <= x <= pi, to round-off relative to the result: the Taylor series
    x^3/3! - x^5/5! + ... for x <= 1 (where the difference would cancel), else directly."""
    x = np.asarray(x, dtype=float)
    small = np.minimum(x, 1.0)
    term, series = small**3 / 6.0, np.zeros_like(small)
    for k in range(1, 12):                  # 23! > 1e22: the next term is below eps
        series += term
        term = -term * small**2 / ((2 * k + 2) * (2 * k + 3))
    return np.where(x <= 1.0, series, x - np.sin(x))


def sine_map(t, beta, complement=None):
    """g(t) = t - beta/(2 pi) sin(2 pi t), t in [0, 1], 0 <= beta <= 1; ``complement``
    is 1 - beta when the caller knows it more precisely than 1 - beta rounds.

    g'(t) = 1 - beta cos(2 pi t) >= 0: smallest at both ends, largest in the middle, and
    smooth, so a mesh S_i = L g(i/N) keeps the convergence orders of the uniform one.
    Evaluated as (1 - beta) t + beta (x - sin x)/(2 pi), x = 2 pi t, on t <= 1/2 and as
    1 - g(1 - t) beyond: no cancellation near the ends, and exactly symmetric.
    """
    t = np.asarray(t, dtype=float)
    if beta == 0.0:
        return t.copy()
    near = np.minimum(t, 1.0 - t)
    complement = 1.0 - beta if complement is None else complement
    g = complement * near + beta * _x_minus_sin(2 * np.pi * near) / (2 * np.pi)
    return np.where(t <= 0.5, g, 1.0 - g)


def graded_coordinates(t, grading):
    """The sine map g(t) (sine_map) whose density g' has the ratio ``grading`` >= 1
    between the middle and the ends: beta = (grading - 1)/(grading + 1). The element
    ratio of a mesh of N elements differs by O(1/N^2); a mesh uses mesh_beta."""
    return sine_map(t, (grading - 1.0) / (grading + 1.0))


def _element_coefficients(n_elements):
    """(N a, N b) with the end elements of the sine map of N elements
    (1/N)(1 - beta N a) L and the largest (1/N)(1 + beta N b) L: element i is
    L (1/N - beta/pi sin(pi/N) cos(pi (2i+1)/N)), smallest at i = 0 and N - 1, largest
    at 2i + 1 = N (N odd) or N +- 1 (N even). Also 1 - N a = (x - sin x)/x, x = 2 pi/N,
    without cancellation."""
    n = int(n_elements)
    x = 2 * np.pi / n
    one_minus_na = float(_x_minus_sin(x)) / x
    nb = 1.0 - one_minus_na if n % 2 == 0 else n * np.sin(np.pi / n) / np.pi
    return 1.0 - one_minus_na, nb, one_minus_na


def largest_grading(n_elements):
    """The largest ratio of the largest to the smallest element the sine map can give N
    elements, (1 + N b)/(1 - N a) at beta = 1 (g'(0) = 0); 1 for N <= 2, whose elements
    it keeps equal (one element; two mirror images)."""
    if n_elements <= 2:
        return 1.0
    _, nb, one_minus_na = _element_coefficients(n_elements)
    return (1.0 + nb) / one_minus_na


def fewest_elements(grading):
    """The fewest elements whose sine-map mesh reaches the ratio ``grading`` (the limit
    largest_grading(N) grows like 3 N^2 / pi^2)."""
    n = max(3, int(np.sqrt(3.0 * grading) / np.pi) - 2)
    while largest_grading(n) < grading:
        n += 1
    return n


def mesh_beta(n_elements, grading):
    """(beta, 1 - beta) of the sine map for which a mesh of N elements has largest /
    smallest element exactly ``grading`` = q (to round-off): 1 + beta N b =
    q (1 - beta N a), so beta = (q - 1) / (N b + q N a) and
    1 - beta = (1 + N b - q (1 - N a)) / (N b + q N a), each without cancellation but
    the one q near largest_grading(N) asks for. None when no beta in [0, 1] does."""
    grading = float(grading)
    if grading == 1.0:
        return 0.0, 1.0
    if not grading >= 1.0 or grading > largest_grading(n_elements):
        return None
    na, nb, one_minus_na = _element_coefficients(n_elements)
    denominator = nb + grading * na
    complement = max(0.0, (1.0 + nb - grading * one_minus_na) / denominator)
    return min(1.0, (grading - 1.0) / denominator), complement


def vertex_coordinates(vertex_index, n_elements, length, grading):
    """S of the given global vertex indices of a mesh (Mesh.coordinates): L g(i/N) with
    g the sine map of mesh_beta; ValueError when the grading cannot be built (refused
    before, with the option's name: cli.line_run.check_mesh)."""
    beta = mesh_beta(n_elements, grading)
    if beta is None:
        raise ValueError(f"a grading of {grading:g} cannot be built on {n_elements} "
                         f"elements (at most {largest_grading(n_elements):.6g})")
    index = np.asarray(vertex_index)
    t = index / n_elements
    # t beyond 1/2 from the mirror index, so that the mesh is exactly symmetric
    mirrored = 1.0 - sine_map((n_elements - index) / n_elements, *beta)
    return length * np.where(2 * index <= n_elements, sine_map(t, *beta), mirrored)


def element_lengths(element_index, n_elements, length, grading):
    """The lengths (m) of the given global elements (Mesh.element_h). An element in one
    half of the mesh is the difference of g at its vertices counted from the nearer end
    (sine_map), so that the small end elements keep their own relative precision rather
    than that of S ~ L; an element across the middle (N odd) is S_e+1 - S_e; a uniform
    mesh's are L / N."""
    beta = mesh_beta(n_elements, grading)
    e = np.asarray(element_index)
    if beta is not None and beta[0] == 0.0:
        return np.full(e.shape, length / n_elements)
    if beta is None:
        return np.diff(vertex_coordinates(np.stack([e, e + 1]), n_elements, length,
                                          grading), axis=0)[0]
    left = sine_map((e + 1) / n_elements, *beta) - sine_map(e / n_elements, *beta)
    right = (sine_map((n_elements - e) / n_elements, *beta)
             - sine_map((n_elements - e - 1) / n_elements, *beta))
    across = np.diff(vertex_coordinates(np.stack([e, e + 1]), n_elements, length, grading),
                     axis=0)[0]
    return np.where(2 * (e + 1) <= n_elements, length * left,
                    np.where(2 * e >= n_elements, length * right, across))


def end_element_lengths(n_elements, length, grading):
    """The lengths (m) of the first and last elements, the smallest of a graded mesh, as
    the mesh will compute them: known before the mesh is allocated."""
    return element_lengths([0, n_elements - 1], n_elements, length, grading)


class Pieces:
    """A mesh made of pieces, each uniform: piece k spans [S_k, S_k+1] (``ends``, (m+1,),
    m) with ``counts[k]`` elements, so that every S_k is a vertex (the ends of a line's
    sections, scenes/line.py)."""

    def __init__(self, ends, counts):
        self.ends = np.asarray(ends, dtype=float)
        self.counts = np.asarray(counts, dtype=int)
        self.first = np.concatenate([[0], np.cumsum(self.counts)])   # first vertex of each

    def coordinates(self, vertex_index):
        """S of global vertices: S_k + (i - first_k) (S_k+1 - S_k) / n_k, the piece ends
        exactly."""
        i = np.asarray(vertex_index)
        k = np.clip(np.searchsorted(self.first, i, side="right") - 1, 0,
                    len(self.counts) - 1)
        fraction = (i - self.first[k]) / self.counts[k]
        return np.where(fraction >= 1.0, self.ends[k + 1],
                        self.ends[k] + fraction * (self.ends[k + 1] - self.ends[k]))

    def element_lengths(self, element_index):
        """(S_k+1 - S_k) / n_k of the piece holding each global element."""
        e = np.asarray(element_index)
        k = np.searchsorted(self.first[1:], e, side="right")
        return (np.diff(self.ends) / self.counts)[k]


class Mesh:
    """A distributed mesh of ``n_elements`` elements on [0, length]: the sine map of
    ``grading``, or uniform ``pieces`` (Pieces) when given.

    Attributes a kernel needs are plain numpy arrays of this rank's part; the rank
    itself never appears outside this class (``on_lower_boundary`` and
    ``on_upper_boundary`` say whether the rank holds S = 0 and S = L).
    """

    def __init__(self, comm, n_elements, length, grading=1.0, pieces=None):
        self.n_elements = int(n_elements)
        self.n_vertices = self.n_elements + 1
        self.length = float(length)
        self.grading = float(grading)
        self.pieces = pieces
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
        self.element_h = self.element_lengths(np.arange(self.element_start,
                                                        self.element_end))
        # Local (ghosted) index of each owned element's left vertex.
        self.element_local = np.arange(self.element_start, self.element_end) - self.ghost_start

    @property
    def n_local_elements(self):
        return self.element_end - self.element_start

    def element_ends(self, ghosted):
        """(left, right): each owned element's values at its left and right vertex,
        (ne, ...) each, from ``ghosted`` values at the ghosted vertices (n_ghosted, ...):
        views (the owned elements' vertices are consecutive in the ghosted range), not
        the copies of an index array's gather."""
        first, ne = self.element_start - self.ghost_start, self.n_local_elements
        return ghosted[first:first + ne], ghosted[first + 1:first + ne + 1]

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

    def vertex_sides(self):
        """The lengths (m) of the elements left and right of the owned vertices, each
        (n_local_vertices,), 0 beyond the line's ends."""
        vertices = np.arange(self.vertex_start, self.vertex_end)
        lengths = self.element_lengths
        left = np.where(vertices > 0, lengths(np.maximum(vertices - 1, 0)), 0.0)
        right = np.where(vertices < self.n_elements,
                         lengths(np.minimum(vertices, self.n_elements - 1)), 0.0)
        return left, right

    def node_weights(self):
        """Simpson weights of the owned P2 nodes, (n_local_nodes,): h_e (1/6, 4/6, 1/6) per
        element, summed at the vertices, so that sum_n w_n g(S_n) = int g dS exactly for
        a piecewise cubic g (the quadrature of the constraint, docs/method.md §4)."""
        left, right = self.vertex_sides()
        w = np.empty(self.n_local_nodes)
        w[0::2] = (left + right) / 6
        w[1::2] = 4 * self.element_h / 6
        return w

    def coordinates(self, vertex_index):
        """S of the given global vertex indices."""
        if self.pieces is not None:
            return self.pieces.coordinates(vertex_index)
        return vertex_coordinates(vertex_index, self.n_elements, self.length, self.grading)

    def element_lengths(self, element_index):
        """The lengths (m) of the given global elements."""
        if self.pieces is not None:
            return self.pieces.element_lengths(element_index)
        return element_lengths(element_index, self.n_elements, self.length, self.grading)

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

    def first_of_next_rank(self, values):
        """The next rank's first row of ``values`` (this rank's owned rows, (n, ...), the
        same trailing shape on every rank), for a quantity between this rank's last node
        and the next one's first; zeros on the last rank. Collective (one exchange with
        each neighbour)."""
        values = np.ascontiguousarray(values, dtype=float)
        mpi = self.comm.tompi4py()
        rank, size = mpi.Get_rank(), mpi.Get_size()
        received = np.zeros(values.shape[1:])
        previous = rank - 1 if rank > 0 else None
        following = rank + 1 if rank < size - 1 else None
        if previous is not None and following is not None:
            mpi.Sendrecv(np.ascontiguousarray(values[0]), dest=previous,
                         recvbuf=received, source=following)
        elif previous is not None:
            mpi.Send(np.ascontiguousarray(values[0]), dest=previous)
        elif following is not None:
            mpi.Recv(received, source=following)
        return received

    def global_min(self, value):
        """Minimum of a float over all ranks (of an array: entry by entry)."""
        from mpi4py import MPI
        return self._extreme(value, MPI.MIN)

    def global_max(self, value):
        """Maximum of a float over all ranks (of an array: entry by entry)."""
        from mpi4py import MPI
        return self._extreme(value, MPI.MAX)

    def _extreme(self, value, op):
        if np.ndim(value) == 0:
            return self.comm.tompi4py().allreduce(value, op=op)
        values = np.array(value, dtype=float)
        from mpi4py import MPI
        self.comm.tompi4py().Allreduce(MPI.IN_PLACE, values, op=op)
        return values

    @property
    def smallest_element(self):
        """The shortest element length over all ranks (m)."""
        return self.global_min(float(self.element_h.min()) if self.element_h.size else np.inf)

    def destroy(self):
        self.da.destroy()
