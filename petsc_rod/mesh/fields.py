"""Distributed vector fields (r, d1, d2, the slope r'): three scalar DMDA Vecs, one per
component.

The global step solves one scalar problem per Cartesian component with the same
factorisation (docs/method.md §3), so each component is its own Vec on the mesh's DMDA.
Local views are numpy arrays of shape (n_local_vertices, 2 slots, 3 components).
"""

import numpy as np
from petsc4py import PETSc


# nodes per block of the work done block by block: a block of an (n, 3, 3) array
# (CHUNK x 9 doubles, 288 KiB) stays in a core's 1 MiB L2 cache
CHUNK = 4096


def blocks(n, size=CHUNK):
    """Slices covering range(n) in blocks of ``size``."""
    return [slice(lo, min(lo + size, n)) for lo in range(0, n, size)]


class VectorField:
    """Three scalar Vecs on ``mesh.da`` holding the x, y, z components of one field."""

    def __init__(self, mesh, name):
        self.mesh = mesh
        self.name = name
        self.components = [mesh.da.createGlobalVec() for _ in range(3)]
        self._local = [mesh.da.createLocalVec() for _ in range(3)]
        for c, vec in zip("xyz", self.components):
            vec.setName(f"{name}_{c}")

    def ghosted(self):
        """Ghosted local values, (n_ghosted_vertices, 2, 3)."""
        for glob, loc in zip(self.components, self._local):
            self.mesh.da.globalToLocal(glob, loc)
        return np.stack([loc.getArray(readonly=True).reshape(-1, 2) for loc in self._local],
                        axis=-1)

    def ghosted_components(self):
        """Ghosted local values as the three components' arrays (2 n_ghosted,), slots
        interleaved: views of the local Vecs, valid until the next ghost update."""
        for glob, loc in zip(self.components, self._local):
            self.mesh.da.globalToLocal(glob, loc)
        return [loc.getArray(readonly=True) for loc in self._local]

    def owned(self):
        """Owned values, (n_owned_vertices, 2, 3) (a copy)."""
        return np.stack([vec.getArray(readonly=True).reshape(-1, 2) for vec in self.components],
                        axis=-1)

    def set_owned(self, values):
        """Set the owned values from an array (n_owned_vertices, 2, 3)."""
        for c, vec in enumerate(self.components):
            vec.getArray()[:] = np.ascontiguousarray(values[:, :, c]).ravel()

    def add_ghosted(self, values):
        """Zero the field, then add ghosted contributions (n_ghosted, 2, 3) into it."""
        for c, (glob, loc) in enumerate(zip(self.components, self._local)):
            loc.getArray()[:] = np.ascontiguousarray(values[:, :, c]).ravel()
            glob.zeroEntries()
            self.mesh.da.localToGlobal(loc, glob, addv=PETSc.InsertMode.ADD_VALUES)

    def destroy(self):
        for vec in self.components + self._local:
            vec.destroy()


def element_slices(ghosted, first, n_elements):
    """The P2 element dofs (left vertex, midpoint, right vertex) of ``n_elements``
    consecutive elements, the first with its left vertex at ghosted vertex ``first``, as
    three stride-2 views of one component's ghosted array (2 n_ghosted,): what
    element_dofs gathers, without a copy."""
    base = 2 * first
    return (ghosted[base:base + 2 * n_elements:2],
            ghosted[base + 1:base + 2 * n_elements:2],
            ghosted[base + 2:base + 2 * n_elements + 1:2])


def element_dofs(ghosted, element_local, element):
    """Gather element dofs: (n_ghosted, 2, 3) -> (ne, element.ndofs, 3)."""
    vertex = element_local[:, None] + element.offsets[None, :]
    return ghosted[vertex, element.slots[None, :], :]


def scatter_element_vectors(n_ghosted, element_local, element, vectors):
    """Sum element vectors (ne, ndofs, 3) into a ghosted array (n_ghosted, 2, 3).

    One vectorised add per element dof: within one dof the target vertices are distinct.
    A rank's elements are consecutive (a 1-D DMDA), so each add is a slice, not an
    indexed scatter; the same sums in the same order either way.
    """
    out = np.zeros((n_ghosted, 2, 3))
    ne = len(element_local)
    first = int(element_local[0]) if ne else 0
    consecutive = bool(np.all(np.diff(element_local) == 1))
    for k in range(element.ndofs):
        if consecutive:
            start = first + int(element.offsets[k])
            out[start:start + ne, element.slots[k]] += vectors[:, k]
        else:
            out[element_local + element.offsets[k], element.slots[k]] += vectors[:, k]
    return out


def at_points(basis, dofs):
    """Evaluate at points: basis (ne, nq, k), element dofs (ne, k, 3) -> (ne, nq, 3)."""
    return np.einsum("eqk,ekc->eqc", basis, dofs)
