"""The axial stretch of an extensible line as a term (physics/term.py): its stored
energy and what a step reports of it (docs/method.md §12). The stretch itself is found
in the local step (local_step/projection.stretched_rotation, called by
RodProblem.iterate) and carried in the state as the length of the stretched tangent
(1 + eps) tau3 (RodState.strain); this term is built only for a scene with a finite EA
somewhere (problem/build.py).

Energy: int EA eps^2 / 2 dS over the unstretched line, with the nodal weights of the
penalty terms (Simpson's rule per element, docs/method.md §4), as in the local step.
Outputs: the strain eps and the tension EA eps at the vertices (datasets
``axial_strain``, ``axial_tension``), the stretched length int (1 + eps) dS and the
largest gap between EA eps and n.t of the force balance, t = r'/|r'| (attributes
``stretched_length``, ``axial_tension_gap``, relative to the largest |n|).

In the Newton steps (§11) and the stability test (§10) the strain is an unknown of each
node beside its rotation (analysis/second_variation.py, iteration/newton.py): this term adds
its curvature w EA to the stretch rows of H (``add_hessian``). Its gradient is not one in
the fields g (the Uzawa multiplier lambda = -dE/dg / w leaves it out: the local step,
not the global one, carries EA eps): the Newton steps add w EA eps to the gradient in k
through ``add_strain_gradient``.
"""

import numpy as np

from petsc_rod.physics.term import Term, TermOutput

# Units of the datasets and attributes this term adds to the result file.
DATASET_UNITS = {"axial_strain": "1", "axial_tension": "N"}
ATTRIBUTE_UNITS = {"stretched_length": "m", "axial_tension_gap": "1"}


class AxialStretch(Term):
    """EA eps^2 / 2 per metre of unstretched line, for a Scene with a finite EA on a
    Mesh. EA at the owned nodes, N, (n_nodes,); inf (inextensible parts): eps = 0."""

    dataset_units = DATASET_UNITS
    attribute_units = ATTRIBUTE_UNITS

    axially_symmetric = True    # a turn about the x axis leaves |tau3| unchanged

    def __init__(self, mesh, scene):
        self.mesh = mesh
        self.axial = scene.axial_stiffness_at(mesh.node_S())
        self.finite = np.isfinite(self.axial)

    def node_strain(self, state):
        """eps at the owned nodes (n_nodes,), 0 where EA is infinite."""
        return np.where(self.finite, state.strain(), 0.0)

    def add_strain_gradient(self, gradient, weights, eps):
        """Add d/dk of sum_n w_n EA_n eps_n^2 / 2, w EA eps (N m; 0 where EA is infinite),
        at the strains eps (n_nodes,), k = 1 + eps, into ``gradient`` (n_nodes,)."""
        gradient += np.where(self.finite, weights * np.where(self.finite, self.axial, 0.0)
                             * eps, 0.0)

    def add_hessian(self, hessian):
        """w_n EA_n on the stretch rows of H (0 where EA is infinite: those rows are held)."""
        hessian.add_strain_diagonal(np.where(self.finite, hessian.problem.state.node_weights
                                             * np.where(self.finite, self.axial, 0.0), 0.0))

    def energy(self, state):
        """sum_n w_n EA_n eps_n^2 / 2, J. Collective."""
        eps = self.node_strain(state)
        ea = np.where(self.finite, self.axial, 0.0)
        return self.mesh.global_sum(0.5 * np.sum(state.node_weights * ea * eps**2))

    def outputs(self, problem, vertex):
        """eps and EA eps at the owned vertices, the stretched length and the largest
        relative gap |EA eps - n.t| / max |n| (t = d3 / |d3| at the vertices). A
        collective reduction."""
        state, mesh = problem.state, self.mesh
        eps = self.node_strain(state)
        n_owned = vertex["S"].shape[0]
        vertex_eps = eps[0::2][:n_owned]
        tension = np.where(self.finite[0::2][:n_owned], self.axial[0::2][:n_owned], 0.0) \
            * vertex_eps
        tangent = vertex["d3"] / np.linalg.norm(vertex["d3"], axis=1, keepdims=True)
        balance = np.einsum("nc,nc->n", vertex["n"], tangent)
        stretched = mesh.global_sum(np.sum(state.node_weights * (1.0 + eps)))
        gap = mesh.global_max(np.abs(tension - balance).max(initial=0.0))
        size = mesh.global_max(np.linalg.norm(vertex["n"], axis=1).max(initial=0.0))
        largest = mesh.global_max(np.abs(vertex_eps).max(initial=0.0))
        return TermOutput(
            datasets={"axial_strain": vertex_eps, "axial_tension": tension},
            attributes={"stretched_length": float(stretched),
                        "axial_tension_gap": float(gap / size) if size > 0 else 0.0},
            text=f"stretch max |eps| {largest:.3g}, length {stretched:.10g} m")
