"""The horizontal part of the contact force of a seabed that is not flat (a slope, a
profile; docs/riser.md §3a), as a nodal load of the iterate beside the seabed's
vertical problem (global_step/seabed_contact.py).

At node n, with p_n = (z_b(x_n, y_n) - z_n)_+ the vertical penetration, g_n = grad z_b
and k_n = k / (1 + |g_n|^2), the seabed pushes along its normal with
k_n p_n (-g_n, 1) per metre (environment.Seabed.force): the vertical part k_n p_n is
implicit in the vertical problem, the horizontal part

    f_h,n = -k_n p_n g_n    (N/m; N tan(theta) down the slope, N = k_n p_n / cos(theta))

enters the slope problem's right-hand side like the drag (nodal_load.NodalLoadTerm), from
the positions of the last global step. Why lagged, and why that is stable: its
sensitivity to the iterate is that of the reaction k_n p_n, which the vertical problem
fixes from the line's equilibrium rather than from k, times tan(theta); an error dx of
the horizontal positions returns as about tan(theta)^2 dx, small for the moderate slopes
of the seabed data (docs/riser.md §3a).

Not a term of the energy: the energy of the seabed term (k_n/2 sum w_n p_n^2) is the
potential of the whole force on a plane, but the Newton steps and the stability test
would need its derivatives in x and y, which they do not have: the term says so
(``conservative``, ``in_newton`` False), so the run takes neither.
"""

from petsc_rod.global_step.nodal_loads import NodalLoad
from petsc_rod.physics.nodal_load import NodalLoadTerm


class SeabedSlopeLoad(NodalLoadTerm):
    """f_h of the module docstring for the seabed of the SeabedTerm ``contact``."""

    conservative = False
    in_newton = False
    newton_gap = "a seabed that is not flat (docs/riser.md §3a)"

    def __init__(self, mesh, contact):
        super().__init__(mesh, "seabed_slope")
        self.contact = contact                  # the SeabedTerm (seabed.py)
        self.seabed = contact.seabed            # environment.Seabed, not flat
        self.load = NodalLoad(mesh, self._nodes)

    def node_loads(self, state):
        """f_h at the owned P2 nodes (N/m), (n_nodes, 3), z component 0: the reaction of
        the last vertical solve (seabed_contact.SeabedContact.node_force). Zero before the first
        solve: the start's own penetration (a straight start under a rising seabed:
        metres) is not a reaction, and k times it would throw the first iterate far away.
        Collective."""
        force = self.contact.contact.node_force()
        force[:, 2] = 0.0
        return force

    def add_iterate_load(self, rhs, state):
        """Add int F.g of f_h to the slope problem's right-hand side, then move the
        seabed's heights and springs under the nodes of the last global step for this
        step's vertical solve (seabed_contact.SeabedContact.follow; this term is built after the
        seabed's, and add_iterate_load comes before every solve of the global step)."""
        self.load.set(self.node_loads(state))
        self.add_to_rhs(rhs, self.load)
        self.contact.contact.follow(state.r.ghosted())
