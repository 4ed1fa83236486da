"""The protocol of a term of physics: what a piece of the problem beside the rod's
elastic energy and its constraint contributes to each part of the method
(docs/design.md, "Terms of physics").

The problem (problem/problem.py) holds a list of terms, built for its scene
(problem/build.py): the dead loads (physics/dead_loads.py) always; the seabed and the drag
(seabed.py, drag.py) where the scene has them.
The core walks the list and calls the methods below; it never asks which terms exist.
Every default does nothing, so a term overrides only what it contributes. Every method
is called on every rank, in the same order (collective where a term needs it).

When each is called:

* the global step (global_step/global_step.py, docs/method.md §3 step 1):
  ``add_slope_matrices`` at every factorisation, before the slope matrix is assembled
  and factored; ``build`` at every factorisation, ``prepare`` at every load step, then
  ``add_step_load`` once into the load that stays fixed over the step;
  ``add_iterate_load`` at every iteration; ``solve_slope`` after the P2 solve of the
  slope, for the components of ``slope_components``;
* the energy and its derivatives (problem.energy, problem.energy_gradient, the Newton
  steps of §11 and the second variation of §10): ``energy``, ``add_gradient``,
  ``add_strain_gradient``, ``add_hessian`` and, for a load without potential,
  ``add_jacobian``; ``conservative``, ``in_newton``, ``position_components``,
  ``follower``, ``unsymmetric`` and ``outputs_of_state`` say what they are;
* the load path (iteration/continuation.py): ``accept_step`` at the end of every
  accepted load step (a path-dependent term's memory: the friction's anchors);
* the outputs (io/outputs.py): ``force_beyond`` and ``end_force`` for the internal
  force n(S), ``outputs`` for datasets, attributes and the step line, in the units of
  ``dataset_units`` and ``attribute_units``. What only reports is not a term but a
  report (quantities/report.py), held beside the terms.
"""

from dataclasses import dataclass, field


@dataclass
class TermOutput:
    """What a term or a report (quantities/report.py) adds to a step's record: vertex
    datasets {name: (n_owned, ...)}, attributes {name: value} (their units in the
    term's or report's dataset_units and attribute_units) and a phrase for the step
    line."""

    datasets: dict = field(default_factory=dict)
    attributes: dict = field(default_factory=dict)
    text: str = ""


class Term:
    """A term of physics (module docstring). Subclasses set the class attributes that
    differ and override the methods they contribute to."""

    # the term has an energy: its loads are conservative, and the stability test (§10)
    # says which equilibrium a step reached (a drag has none: docs/riser.md)
    conservative = True
    # energy, add_gradient and add_hessian are the term's whole contribution to E, so
    # that Newton steps on the reduced problem (§11) may be taken with it
    in_newton = True
    # the term is unchanged by a turn of the rod about the x axis when the scene is
    # (Scene.axially_symmetric): the solver may then report the canonical member of a
    # family of equilibria (§10). False unless the term says so: a term the core does
    # not know may load the rod off the axis
    axially_symmetric = False
    # components of the slope r' (0, 1, 2 for x, y, z) that the term solves itself in
    # the global step (solve_slope) in place of the P2 solve (the seabed: z)
    slope_components = ()
    # the components (0, 1, 2 for x, y, z) of the node positions the term's energy or
    # load reads (the seabed: the heights; the friction: the horizontal positions): the
    # Newton system and the stability test then carry their chains
    # (analysis/positions.py), and add_hessian may call hessian.add_position_curvature
    position_components = ()
    # the components of the node positions the term's load reads without an energy (the
    # drag of a current that varies with depth: the heights): the Newton system carries
    # their chains (analysis/positions.py) for the Jacobian's columns in them
    # (add_jacobian), and nothing else changes (no curvature, no stability test)
    jacobian_positions = ()
    # the centreline and the positions' chains of a line held at both ends run from its
    # lower end (global_step/centreline.chains_from_start): the term reads grounded
    # positions horizontally (the friction), whose errors from the other end are the
    # iterate's chord error and its errors in angle over the suspended part
    chains_from_end = False
    # the term's load follows the line and has no potential (the drag): the resultants'
    # chain of analysis/jacobian.py carries its linearisation
    follower = False
    # add_jacobian adds entries beyond H (a follower's; the friction's, whose limit
    # follows the contact reaction): the Newton steps then solve with that unsymmetric
    # Jacobian by LU and each must lower |grad L|; H (the stability test, the safeguard)
    # is that of the term's load held at its current value
    unsymmetric = False
    # H's pattern holds add_jacobian's entries (jacobian_pattern), so that J is a copy
    # of H (analysis/jacobian.py); otherwise J is made with room for them
    jacobian_reserved = False
    # the term's outputs and its share of the internal force are functions of the state
    # (fields, frames, multipliers), so that a step may end at a Newton state (§11,
    # "Convergence in Newton's terms"); False where they are what the last global step
    # solved (the friction's return map at its solved positions): a step that Newton
    # steps finish then ends at an iteration after them, which solves them anew
    outputs_of_state = True
    # when in_newton is False: what the term is and where its limits are documented, for
    # the line that says a run takes no Newton steps (cli/messages.no_newton)
    newton_gap = ""
    # {name: unit} of the vertex datasets and of the attributes ``outputs`` writes ("1":
    # dimensionless, "text": a string), gathered by RodProblem.units for the result file
    dataset_units = {}
    attribute_units = {}

    # --- the global step --------------------------------------------------------------
    def add_slope_matrices(self, matrices):
        """At every factorisation, before assembly: add the term's part of the slope
        problem's matrix into its element matrices ``matrices`` (n_local_elements, 3, 3),
        N m, the P2 dofs (left vertex, midpoint, right vertex) of each owned element (a
        spring on the slope at a node: the flex joint). It is factored with the rest, so
        a term that adds here keeps the matrix SPD and fixed over the penalty."""

    def build(self, slope_matrices, penalty):
        """At every factorisation of the global step: the slope problem's element
        matrices 2 c3 K + R W, (ne, 3, 3) (c3 varying along a line of sections), every
        term's add_slope_matrices included, and its penalty R (N)
        (global_step.GlobalStep.build)."""

    def prepare(self, t, start, end):
        """At each load step: the load factor t and the end states (scenes.EndState)."""

    def add_step_load(self, load):
        """Add the term's int F.g dS of a load fixed over the step (F the resultant
        beyond S, docs/method.md §5) into ``load`` (a VectorField on the slope's P2 dofs,
        N), which the global step adds to the slope's right-hand side every iteration.
        Called once per ``prepare``."""

    def add_iterate_load(self, rhs, state):
        """Add, every iteration, a load that depends on the iterate (RodState ``state``:
        its tau, lambda and the last fields) to the slope's right-hand side ``rhs``
        (VectorField)."""

    def solve_slope(self, rhs, state, bordered):
        """After the P2 solve of the slope's other components: set the components of
        ``slope_components`` of state.slope from the right-hand side ``rhs``; with both
        ends held (``bordered``) also their part of state.chord_multiplier."""

    def set_clamp_stretch(self, start, end):
        """1 + eps at a clamped start and end of an extensible line (docs/method.md §12;
        1 at an end that is not clamped), after every build and whenever they change: a
        term that solves slope components (solve_slope) prescribes (1 + eps) d3 there,
        as the P2 slope problem does (GlobalStep.set_clamp_stretch)."""

    def ksps(self):
        """The KSPs the term made (their types go to the result file)."""
        return []

    # --- the energy, Newton and the stability test -----------------------------------------
    def energy(self, state):
        """The term's part of the discrete energy E (§6) at ``state``, J: stored energy
        less the work of its loads. Collective."""
        return 0.0

    def add_gradient(self, g, state):
        """Add dE_term / dd_i at the owned P2 nodes into g (n_nodes, 3 directors, 3), the
        fields of ``state`` being the frames (iteration/newton.py)."""

    def add_strain_gradient(self, gradient, weights, eps):
        """On an extensible line (docs/method.md §12): add the derivative of E_term in the
        stretch k = 1 + eps of each owned P2 node, beyond what it gives through the fields
        g3 = k d3, into ``gradient`` (n_nodes,), N m; ``weights`` the node weights w_n, m,
        and eps the strains (n_nodes,) (the axial energy, physics/stretch.py)."""

    def add_hessian(self, hessian):
        """Add the second derivative of E_term in the directors, beyond what its gradient
        gives through the multipliers (§10), to the SecondVariation ``hessian`` before it
        is assembled (a term linear in the directors adds nothing)."""

    def symmetrised_nodes(self, state):
        """(count, ratio): the owned nodes where add_hessian holds only the symmetric
        part of the term's derivative, which is not symmetric there (a seabed profile's
        contact near a row, seabed.py), and the largest |B - B^T| / |B| of their blocks
        (max-norm); (0, 0.0) where H is the term's whole derivative. The modes say it
        (analysis/modes.py): their K is then symmetrised, not exact."""
        return 0, 0.0

    def holds(self, state):
        """Whether the term can hold a state along a negative direction of H, which
        leaves its dissipation out (seabed friction on grounded nodes: FrictionTerm);
        such a state is then not left (driver.UzawaSolver.checks_curvature). Collective."""
        return False

    def add_jacobian(self, jacobian):
        """An unsymmetric term's entries of the Newton Jacobian beyond H
        (analysis/jacobian.py NewtonJacobian, before assembly): a follower's load's
        derivative in the frames, through the resultants' chain."""

    def jacobian_pattern(self, hessian):
        """Where add_jacobian adds entries, as [(rows (k, r), columns (k, c)), ...] of
        global indices in the layout of the SecondVariation ``hessian``, of a term whose
        ``jacobian_reserved``: H holds zeros there from its first assembly, so that J is
        a copy of H on the same pattern (analysis/jacobian.py)."""
        return []

    # --- the load path -----------------------------------------------------------------
    def accept_step(self, state):
        """At the end of an accepted load step, the RodState ``state`` its equilibrium:
        commit what the term remembers along the path (a step that is undone and
        retried never reaches here). Collective."""

    # --- outputs --------------------------------------------------------------------
    def force_beyond(self, state):
        """The term's share of the internal force n(S) at the owned vertices, N,
        (n_owned, 3): the resultant of its loads beyond S, with, when the start is free,
        its share of the reaction at the held end; None: nothing."""
        return None

    def end_force(self, state):
        """The term's share of the external force on the rod at S = L, N, (3,) (that is,
        of n(L)); None: nothing. Collective."""
        return None

    def outputs(self, problem, vertex):
        """A TermOutput for the step's record from the vertex fields ``vertex``
        (io/outputs.vertex_fields), or None. Collective."""
        return None

    def destroy(self):
        """Free the term's PETSc objects (collective)."""
