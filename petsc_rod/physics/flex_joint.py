"""A flex joint: a rotational spring at a pinned end, between a pin (k = 0) and a clamp
(k -> inf), as a term (physics/term.py; docs/method.md §5, docs/riser.md).

The spring resists the turn of the end tangent d3 away from a neutral axis a (unit):
moment M = k theta, energy 1/2 k theta^2, theta = angle(d3, a) in [0, pi). It acts on d3
only: the roll about d3 stays free, as at a pin. k in N m/rad, M in N m.

**In the global step** (docs/method.md §5, "Flex joints"). The slope problem carries the
quadratic Q = k/2 |g3 - a|^2 at the end node: k on the diagonal of the slope matrix at
that dof (add_slope_matrices, factored once per penalty with the rest) and k a on the
right-hand side. On unit vectors Q = k (1 - cos theta), whose moment is k sin theta;
the difference is carried as a lagged right-hand side evaluated at the latest rotation
tau3, as §2 does for a negative a_j: with c = tau3.a, theta = arccos c and
p = a - c tau3 (the part of a normal to tau3),

    slope matrix += k (end dof),    right-hand side += k a + k (theta / sin theta - 1) p,

so that at a fixed point (g3 = tau3) the end node feels the moment of the true law,
k theta along p / |p|. The lagged part is of order k theta^3 / 6, small beside the k the
matrix carries. Only the tangential part is lagged: the radial force stays Q's,
k (1 - c), so the multiplier at the end node carries no force of order k (a lagged
k theta/sin theta a would: lambda3 ~ k / w_n there, far above R; the cantilever of
tests/solver/test_flex_joint.py (b) at k = 100 EI / L took 1056 iterations instead of
18). The end node's multipliers still carry the boundary fluxes of d1 and d2 that the
moment calls for, about k theta / h: a very stiff joint may need a larger R where no
Newton step raises it (docs/method.md §5).

**Energy, gradient, Hessian** (Newton §11, stability §10). The extension off the sphere
E_j(d) = 1/2 k theta(d)^2 + k (|d| - 1)(1 - cos theta(d)) (theta of the direction of d)
has at unit d the gradient the global step's fixed points see,
grad = -k (theta / sin theta) (a - c d) + k (1 - c) d. On the constraint set its
second variation along d -> exp([omega]x) d is, beyond grad.(omega x (omega x d)) that
the multipliers give (§10), the block

    k f''(c) v v^T + k beta (I - d d^T),   v = d x a,
    f''(c) = (sin theta - theta cos theta) / sin^3 theta,   beta = theta c / sin theta + 1 - c

(f = 1/2 arccos^2; f'' -> 1/3 and beta -> 1 at theta = 0).
"""

import numpy as np
from petsc4py import PETSc

from petsc_rod.physics.term import Term, TermOutput

# Units of the attributes the joints write into a step group (io/results.py).
ATTRIBUTE_UNITS = {f"{which}_joint_{name}": unit for which in ("start", "end")
                   for name, unit in (("angle", "deg"), ("moment", "N m"))}
# Below this angle (rad) f' and f'' are taken from their series (round-off of the ratios).
SMALL_ANGLE = 1e-4
# theta / sin theta and f'' are evaluated at no more than this angle (rad): they grow
# without bound as d3 turns to -a, where the direction of the moment is undefined
LARGEST_ANGLE = np.pi - 1e-3


def joint_angle(d3, axis):
    """theta = angle(d3, a), rad, for any nonzero d3 (3,) (its direction only)."""
    return float(np.arctan2(np.linalg.norm(np.cross(d3, axis)), d3 @ axis))


def slope_factor(theta):
    """-f'(c) = theta / sin theta, the ratio of the true moment k theta to the
    quadratic's k sin theta (1 + theta^2 / 6 near 0)."""
    if theta < SMALL_ANGLE:
        return 1.0 + theta**2 / 6
    theta = min(theta, LARGEST_ANGLE)
    return theta / np.sin(theta)


def curvature_factor(theta):
    """f''(c) = (sin theta - theta cos theta) / sin^3 theta (1/3 + 2 theta^2 / 15 near
    0)."""
    if theta < SMALL_ANGLE:
        return 1.0 / 3 + 2 * theta**2 / 15
    theta = min(theta, LARGEST_ANGLE)
    s = np.sin(theta)
    return (s - theta * np.cos(theta)) / s**3


class FlexJoint(Term):
    """The flex joint at the ``which`` ('start' or 'end') pinned end of a rod on ``mesh``,
    of rotational stiffness ``k`` (N m/rad) about the unit neutral axis ``axis`` (module
    docstring). Only the rank that holds the end node contributes; outputs are
    reduced over the ranks."""

    def __init__(self, mesh, which, k, axis):
        self.mesh, self.which, self.k = mesh, which, float(k)
        self.axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
        # the end node among this rank's owned P2 nodes (None: another rank's)
        if which == "start":
            self.node = 0 if mesh.on_lower_boundary else None
            # the element whose matrix holds the end dof, and the dof's place in it
            self.element = 0 if mesh.element_start == 0 and mesh.n_local_elements else None
            self.slot = 0
        else:
            self.node = mesh.n_local_nodes - 1 if mesh.on_upper_boundary else None
            self.element = (-1 if mesh.element_end == mesh.n_elements
                            and mesh.n_local_elements else None)
            self.slot = 2

    # a turn about the x axis leaves an axis along e_x unchanged
    @property
    def axially_symmetric(self):
        return bool(np.allclose(self.axis[1:], 0.0))

    # --- the global step ----------------------------------------------------------------
    def add_slope_matrices(self, matrices):
        """k on the diagonal at the end's slope dof (the quadratic k/2 |g3 - a|^2)."""
        if self.element is not None:
            matrices[self.element, self.slot, self.slot] += self.k

    def add_iterate_load(self, rhs, state):
        """k a + k (theta / sin theta - 1) (a - c tau3) at the end's slope dof (module
        docstring)."""
        if self.node is None:
            return
        tau3 = state.tau[self.node, 2]
        theta = joint_angle(tau3, self.axis)
        normal = self.axis - (tau3 @ self.axis) * tau3
        load = self.k * (self.axis + (slope_factor(theta) - 1.0) * normal)
        for c, vec in enumerate(rhs.components):
            vec.getArray()[self.node] += load[c]

    # --- the energy, Newton and the stability test ---------------------------------------
    def _end_tangent(self, state):
        """d3 = r' at the end node from the slope field, (3,) (on the owning rank)."""
        return np.array([vec.getArray(readonly=True)[self.node]
                         for vec in state.slope.components])

    def energy(self, state):
        """E_j = 1/2 k theta^2 + k (|d| - 1)(1 - cos theta) at the slope field's end
        tangent d (the second part vanishes on the constraint set), J. Collective."""
        local = 0.0
        if self.node is not None:
            d = self._end_tangent(state)
            theta = joint_angle(d, self.axis)
            local = self.k * (0.5 * theta**2 + (np.linalg.norm(d) - 1) * (1 - np.cos(theta)))
        return float(self.mesh.global_sum(local))

    def add_gradient(self, g, state):
        """-k (theta / sin theta) (a - c d) + k (1 - c) d on the d3 row of the end node
        (d the field's end tangent, a unit vector in the Newton steps)."""
        if self.node is None:
            return
        d = self._end_tangent(state)
        theta = joint_angle(d, self.axis)
        c = d @ self.axis
        g[self.node, 2] += self.k * (-slope_factor(theta) * (self.axis - c * d) + (1 - c) * d)

    def add_hessian(self, hessian):
        """k f''(c) v v^T + k beta (I - d d^T) on the end node's rotation block, d = tau3
        (= d3 at a fixed point and in the Newton steps), module docstring."""
        if self.node is None:
            return
        d = hessian.problem.state.tau[self.node, 2]
        theta = joint_angle(d, self.axis)
        c = d @ self.axis
        v = np.cross(d, self.axis)
        beta = c * slope_factor(theta) + 1 - c
        block = self.k * (curvature_factor(theta) * np.outer(v, v)
                          + beta * (np.eye(3) - np.outer(d, d)))
        rows = (hessian.first_row + 3 * self.node + np.arange(3)).astype(PETSc.IntType)
        hessian.matrix.setValues(rows, rows, block.ravel(), addv=PETSc.InsertMode.ADD_VALUES)

    # --- outputs ------------------------------------------------------------------------
    def angle_and_moment(self, state):
        """(theta in deg, k theta in N m) at the slope field's end tangent. Collective."""
        theta = 0.0
        if self.node is not None:
            theta = joint_angle(self._end_tangent(state), self.axis)
        theta = float(self.mesh.global_sum(theta))
        return float(np.degrees(theta)), self.k * theta

    def outputs(self, problem, vertex):
        angle, moment = self.angle_and_moment(problem.state)
        return TermOutput(attributes={f"{self.which}_joint_angle": angle,
                                      f"{self.which}_joint_moment": moment},
                          text=f"{self.which} joint {angle:.4g} deg, {moment:.4g} N m")
