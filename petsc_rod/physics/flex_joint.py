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
k theta/sin theta a would: lambda3 ~ k / w_n there, far above R, and the iteration
crawls). The end node's multipliers still carry the boundary fluxes of d1 and d2 that
the moment calls for, about k theta / h: a very stiff joint may need a larger R where
no Newton step raises it (docs/method.md §5).

**On an extensible end** (``local``, set by RodProblem where EA is finite at the joint;
docs/method.md §12) the quadratic above would leave its radial pull k (|g3| - c) in the
end node's lambda3, which the stretched local step reads as the tension EA eps: the end
strain would be wrong by k (1 - cos theta) / w_n, growing with the mesh. There the joint is
left out of the global step and acts in the local step at its node instead
(``joint_local_step``: AL terms, EA eps^2 / 2 and 1/2 (k / w_n) theta(tau3)^2, minimised
over tau in SO(3) and eps by Newton's method on SO(3)); its energy is 1/2 k theta^2 of
the direction of d3 only, its gradient -k (theta / sin theta)(a - c t) / |g3| (normal to
g3: nothing on the strain), which the Newton hand-over's multipliers leave out
(``local_gradient``: the Uzawa multipliers do not carry it), and its Hessian block the
whole curvature of 1/2 k theta^2 on SO(3), k f''(c) v v^T - k (theta / sin theta)
(sym(a d^T) - c I).

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
                   for name, unit in (("angle", "deg"), ("moment", "N m"), ("axis", "1"))}
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


def _rotate(omega, frame):
    """exp([omega]x) applied to the rows of ``frame`` (3, 3) (Rodrigues)."""
    angle = np.linalg.norm(omega)
    if angle == 0.0:
        return frame.copy()
    e = omega / angle
    c, s = np.cos(angle), np.sin(angle)
    return (frame * c + np.cross(e, frame) * s
            + np.outer(frame @ e, e) * (1.0 - c))


def joint_local_step(b, start, axis, kappa, ea, penalty, tol=1e-15, steps=60):
    """The stretched local step at a flex joint's node (docs/method.md §5, §12): minimise
    over T in SO(3) and k = 1 + eps

        -b1.T1 - b2.T2 - k b3.T3 + R k^2 / 2 + EA (k - 1)^2 / 2 + kappa theta(T3)^2 / 2,

    kappa = k_joint / w_n. k is eliminated, k = (b3.T3 + EA) / (R + EA), and T found by
    Newton's method on SO(3) (T <- exp([omega]x) T, the Hessian's eigenvalues kept
    positive, steps of at most 0.5 rad) from ``start`` (3, 3), a rotation. Returns the
    targets (T1, T2, k T3), (3, 3)."""
    T = np.array(start, dtype=float)
    eye = np.eye(3)

    def sym(x):
        return 0.5 * (x + x.T)

    for _ in range(steps):
        s = b[2] @ T[2]
        k = max((s + ea) / (penalty + ea), 0.0)
        rows = b.copy()
        rows[2] *= k
        grad = -np.cross(T, rows).sum(axis=0)
        hess = np.zeros((3, 3))
        for i in range(3):
            hess += (rows[i] @ T[i]) * eye - sym(np.outer(rows[i], T[i]))
        ds = np.cross(T[2], b[2])
        if k > 0.0:
            hess -= np.outer(ds, ds) / (penalty + ea)
        c = T[2] @ axis
        theta = joint_angle(T[2], axis)
        v = np.cross(T[2], axis)
        slope = -slope_factor(theta)
        grad += kappa * slope * v
        hess += kappa * (curvature_factor(theta) * np.outer(v, v)
                         + slope * (sym(np.outer(axis, T[2])) - c * eye))
        values, vectors = np.linalg.eigh(sym(hess))
        floor = 1e-12 * max(np.abs(values).max(), 1.0)
        values = np.maximum(np.abs(values), floor)
        omega = -vectors @ ((vectors.T @ grad) / values)
        size = np.linalg.norm(omega)
        if size > 0.5:
            omega *= 0.5 / size
        T = _rotate(omega, T)
        if size <= tol:
            break
    s = b[2] @ T[2]
    k = max((s + ea) / (penalty + ea), 0.0)
    T[2] *= k
    return T


class FlexJoint(Term):
    """The flex joint at the ``which`` ('start' or 'end') pinned end of a rod on ``mesh``,
    of rotational stiffness ``k`` (N m/rad) about the unit neutral axis ``axis`` (module
    docstring). Only the rank that holds the end node contributes; outputs are
    reduced over the ranks."""

    attribute_units = ATTRIBUTE_UNITS

    # on an extensible end the joint acts in the local step at its node, not in the
    # global step (RodProblem.iterate, joint_local_step; docs/method.md §12)
    local = False

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
        if self.element is not None and not self.local:
            matrices[self.element, self.slot, self.slot] += self.k

    def add_iterate_load(self, rhs, state):
        """k a + k (theta / sin theta - 1) (a - c tau3) at the end's slope dof (module
        docstring)."""
        if self.node is None or self.local:
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
            local = 0.5 * self.k * theta**2
            if not self.local:      # on an extensible end, of the direction only
                local = self.k * (0.5 * theta**2
                                  + (np.linalg.norm(d) - 1) * (1 - np.cos(theta)))
        return float(self.mesh.global_sum(local))

    def add_gradient(self, g, state):
        """-k (theta / sin theta) (a - c d) + k (1 - c) d on the d3 row of the end node
        (d the field's end tangent, a unit vector in the Newton steps)."""
        if self.node is None:
            return
        d = self._end_tangent(state)
        if self.local:
            g[self.node, 2] += self._direction_gradient(d)
            return
        theta = joint_angle(d, self.axis)
        c = d @ self.axis
        g[self.node, 2] += self.k * (-slope_factor(theta) * (self.axis - c * d) + (1 - c) * d)

    def _direction_gradient(self, g3):
        """The gradient in g3 of 1/2 k theta(g3 / |g3|)^2, normal to g3:
        -k (theta / sin theta) (a - c t) / |g3|, t = g3 / |g3|, c = t.a."""
        size = np.linalg.norm(g3)
        t = g3 / size
        c = t @ self.axis
        return -self.k * slope_factor(joint_angle(t, self.axis)) * (self.axis - c * t) / size

    def local_gradient(self, lam, state, scale):
        """On an extensible end (``local``): take the joint's gradient out of the Newton
        hand-over's multipliers lam = -g / w (``scale`` = 1 / w, (n_nodes,)), which the
        Uzawa fixed point leaves out (the joint acts in the local step)."""
        if not self.local or self.node is None:
            return
        lam[self.node, 2] += scale[self.node] * self._direction_gradient(
            self._end_tangent(state))

    def add_hessian(self, hessian):
        """k f''(c) v v^T + k beta (I - d d^T) on the end node's rotation block, d = tau3
        (= d3 at a fixed point and in the Newton steps), module docstring."""
        if self.node is None:
            return
        d = hessian.problem.state.tau[self.node, 2]
        if self.local:
            d = d / np.linalg.norm(d)
        theta = joint_angle(d, self.axis)
        c = d @ self.axis
        v = np.cross(d, self.axis)
        if self.local:
            # the whole curvature of 1/2 k theta^2 on SO(3): the multipliers leave the
            # joint out (the local step carries it)
            outer = np.outer(self.axis, d)
            block = self.k * (curvature_factor(theta) * np.outer(v, v)
                              - slope_factor(theta) * (0.5 * (outer + outer.T)
                                                       - c * np.eye(3)))
        else:
            beta = c * slope_factor(theta) + 1 - c
            block = self.k * (curvature_factor(theta) * np.outer(v, v)
                              + beta * (np.eye(3) - np.outer(d, d)))
        rows = (hessian.first_row + hessian.block * self.node + np.arange(3)).astype(PETSc.IntType)
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
                                      f"{self.which}_joint_moment": moment,
                                      f"{self.which}_joint_axis": self.axis.copy()},
                          text=f"{self.which} joint {angle:.4g} deg, {moment:.4g} N m")
