"""The horizontal part of the contact force of a seabed that is not flat (a slope, a
profile; docs/riser.md §3a), as a nodal load of the iterate beside the seabed's
vertical problem (global_step/seabed_contact.py).

At node n, with p_n = (z_b(x_n, y_n) - z_n)_+ the vertical penetration, g_n = grad z_b
and k_n = k / (1 + |g_n|^2), the seabed pushes along its normal with
k_n p_n (-g_n, 1) per metre (environment.Seabed.force): the vertical part k_n p_n is
implicit in the vertical problem, the horizontal part

    f_h,n = -k_n p_n g_n    (N/m; N tan(theta) down the slope, N = k_n p_n / cos(theta))

enters the slope problem's right-hand side as its work on the nodes' positions (the
energy's form, add_iterate_load), from the positions of the last global step. Why
lagged, and why that is stable: its
sensitivity to the iterate is that of the reaction k_n p_n, which the vertical problem
fixes from the line's equilibrium rather than from k, times tan(theta); an error dx of
the horizontal positions returns as about tan(theta)^2 dx, small for the moderate slopes
of the seabed data (docs/riser.md §3a).

Not a term of the energy: the energy of the seabed term (k_n/2 sum w_n p_n^2) is the
potential of the whole force on a plane. On a sloping plane that term's derivatives
carry all three components of the positions (Seabed.position_derivatives: k w_n N N^T
on the contact, the flat seabed's with N for e_z), so the Newton steps and the
stability test have the whole force from it and this term adds nothing to them
(``in_newton``, ``conservative``). Its outputs (the internal force's share) are the
last vertical solve's reaction where the state is that solve's, and the force at the
state's positions after Newton steps (SeabedTerm.contact_solved). On a profile or a
grid, whose slope turns (smoothed) at its rows or grid lines, the seabed term's
gradient and Jacobian are this iteration's fixed point's force and its whole derivative
(Seabed.profile_derivatives, unsymmetric near a row), so the Newton steps have this push
from it too (``in_newton``) and their stationary point is that fixed point; not an
energy's (``conservative`` False: no stability test). A line of a system reads its
stiffness from the same system (system/held_line.py).
"""

import numpy as np

from petsc_rod.physics.nodal_load import NodalLoadTerm


class SeabedSlopeLoad(NodalLoadTerm):
    """f_h of the module docstring for the seabed of the SeabedTerm ``contact``."""

    conservative = False
    # what the refusal of a stability test names (cli/scene_options.check_stability_asked)
    newton_gap = "a seabed that is not flat (docs/riser.md §3a)"

    def __init__(self, mesh, contact):
        super().__init__(mesh, "seabed_slope")
        self.contact = contact                  # the SeabedTerm (seabed.py)
        self.seabed = contact.seabed            # environment.Seabed, not flat
        # on a plane the seabed term's energy holds the whole force, on a profile or a
        # grid its gradient and Jacobian hold this push's: in the Newton steps either way
        # (module docstring)
        self.conservative = self.seabed.plane

    def node_loads(self, state):
        """f_h at the owned P2 nodes (N/m), (n_nodes, 3), z component 0: the reaction of
        the last vertical solve (seabed_contact.SeabedContact.node_force), or after
        Newton steps on a plane the force at the state's positions
        (SeabedTerm.contact_solved). Zero before the first solve: the start's own
        penetration (a straight start under a rising seabed: metres) is not a reaction,
        and k times it would throw the first iterate far away. Collective."""
        if self.contact.contact.solution is not None \
                and not self.contact.contact_solved(state):
            force = self.seabed.force(state.node_positions())
            force[:, 2] = 0.0
            return force
        return self._iterate_loads()

    def _iterate_loads(self):
        """f_h of the last vertical solve, z component 0 (the global step's lagged push;
        zero before the first solve). Collective."""
        force = self.contact.contact.node_force()
        force[:, 2] = 0.0
        return force

    def add_iterate_load(self, rhs, state):
        """Add the work of f_h (node_loads: the last vertical solve's, or after Newton
        steps on a plane, which moved the state and not the contact, the force at the
        state's positions, whose global step then keeps their fixed point) to the slope
        problem's right-hand side, then move the
        seabed's heights and springs under the nodes of the last global step for this
        step's vertical solve (seabed_contact.SeabedContact.follow; this term is built after the
        seabed's, and add_iterate_load comes before every solve of the global step).

        The work is the energy's form, sum_n w_n f_h,n . x_n with the nodes' positions
        the chain's (positions.position_gradient: its adjoint in the slopes), not
        int F.g of f_h's P2 interpolant: the two differ by O(h^2 tan(theta)), and in the
        energy's form the global step's fixed point on a plane is the stationary point
        of the Newton steps, whose seabed energy sums over the nodes with the same
        weights (seabed.py). Collective."""
        work = self.node_loads(state) * state.node_weights[:, None]
        n = work.shape[0]
        gradient = np.zeros((n, 3, 3))
        self.add_position_gradient(gradient, state, {c: -work[:, c] for c in (0, 1)})
        for c in (0, 1):
            rhs.components[c].getArray()[:n] -= gradient[:, 2, c]
        self.contact.contact.follow(state.r.ghosted())
