"""The seabed's springs in the vertical problem (global_step/seabed_contact.py): when the
active set moves, only the elements where it changed are made anew
(SeabedContact._set_active with only_changed); the element matrices and vectors handed to
the vertical problem must be exactly those of making every element anew, on a flat seabed
and where z_b and k differ from node to node (a seabed that is not flat)."""

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.environment.seabed import Seabed
from petsc_rod.global_step.seabed_contact import SeabedContact
from petsc_rod.mesh.mesh import Mesh


class Recorder:
    """Stands for the vertical problem: keeps what set_added was given."""

    def set_added(self, matrices, vectors):
        self.matrices, self.vectors = matrices.copy(), vectors.copy()


def contact_on(mesh, shaped):
    """A SeabedContact at 2 m with k = 3e5 N/m^2; ``shaped``: z_b and k given per node,
    as ``follow`` sets them on a seabed that is not flat."""
    contact = SeabedContact(mesh, Seabed(height=2.0, stiffness=3e5), Recorder())
    if shaped:
        rng = np.random.default_rng(3)
        shape = contact.weights.shape
        contact.base = 2.0 + rng.uniform(-0.5, 0.5, shape)
        contact.stiffness = 3e5 * rng.uniform(0.5, 1.0, shape)
    return contact


@pytest.mark.parametrize("shaped", [False, True])
def test_the_changed_elements_alone_give_every_element_s_terms(shaped):
    mesh = Mesh(PETSc.COMM_SELF, 40, 10.0, grading=2.0)
    rng = np.random.default_rng(11)
    sets = [rng.random((mesh.n_local_elements, 3)) < p for p in (0.2, 0.5, 0.5, 0.9)]
    sets.append(sets[-1].copy())                   # and one that does not change
    moving, fresh = contact_on(mesh, shaped), contact_on(mesh, shaped)
    moving._set_active(np.zeros_like(sets[0]))
    try:
        for active in sets:
            moving._set_active(active, only_changed=True)
            fresh._set_active(active)
            assert np.array_equal(moving.problem.matrices, fresh.problem.matrices)
            assert np.array_equal(moving.problem.vectors, fresh.problem.vectors)
            assert np.any(moving.problem.matrices != 0.0)
    finally:
        for contact in (moving, fresh):
            contact.destroy()
        mesh.destroy()
