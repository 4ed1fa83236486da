"""Initial states of the iteration (docs/method.md §3, "Start"), as smooth curves of S.

A curve maps arc lengths S (any shape) to (r, frame, force): the centreline, the director
frame (rows d1, d2, d3 = r') and the internal force n(S). The solver samples it at its
dofs and quadrature points (RodState.set_from_curve) and starts the multiplier of the
constraint r' = tau3 at lambda3 = n, which is what it converges to when the bending terms
are small (at convergence int 2 a3 r''.p'' + lambda3.p' = int f.p, the weak form of
n' + f = 0); lambda1 = lambda2 = 0.
"""

import numpy as np

from petsc_rod.scenes import section_catenary
from petsc_rod.scenes.boundary import is_held
from petsc_rod.scenes.catenary import catenary, catenary_axes
from petsc_rod.errors import NoCatenaryStart, RodInputError
from petsc_rod.frames import REFERENCE_FRAME
from petsc_rod.model.derived import TAUT_GAP
from petsc_rod.scenes.touchdown import seabed_shape

SHAPES = ("straight", "catenary")


def straight(S):
    """The reference state: r = S e_x, frame (e_y, e_z, e_x), no force."""
    S = np.asarray(S, dtype=float)
    r = S[..., None] * REFERENCE_FRAME[2]
    return r, np.broadcast_to(REFERENCE_FRAME, S.shape + (3, 3)), np.zeros(S.shape + (3,))


def catenary_start(scene, t):
    """The inextensible catenary (catenary.catenary) of the scene at load factor t:
    through both held ends, under the uniform load, with the tension as its force. The
    frame keeps d1 normal to the plane of the catenary (e_v x e_h, which is e_y for a
    cable in the x-z plane, as in the reference frame), d2 = d3 x d1.

    A load of several pieces (-rod_load_breaks: a line of sections, a lazy wave's
    buoyancy) gives the catenary of those weights, section_start.

    Raises RodInputError for scenes that have no catenary: an end not held, a load that
    is zero, the ends L or more apart, or a chord along the load; NoCatenaryStart for a
    sound scene whose catenary cannot be drawn (section_start, touchdown.seabed_shape),
    which the caller replaces by the straight start.
    """
    start, end = scene.start_state(t), scene.end_state(t)
    if not (is_held(start) and is_held(end)):
        raise RodInputError("-rod_initial_shape catenary needs both ends held "
                            "(-rod_start and -rod_end clamp or pin)")
    if len(scene.load_values) > 1:
        return section_start(scene, t, start, end)
    if not np.any(scene.load_values[0]):
        raise RodInputError("-rod_initial_shape catenary needs a non-zero -rod_load")
    load = t * scene.load_values[0]
    chord = end.position - start.position
    try:
        up, along = catenary_axes(scene.length, chord, load)
    except ValueError:
        raise RodInputError("-rod_initial_shape catenary: the ends must be less than "
                            "-rod_length apart and not on one vertical (along the load)"
                            ) from None
    normal = np.cross(up, along)

    def shape(S):
        return catenary(scene.length, chord, load, S)

    if scene.seabed is not None:        # resting on the seabed where it reaches it
        shape = seabed_shape(scene, chord, load, shape)

    return planar_curve(shape, normal, start.position)


def lies_straight(scene, t):
    """Whether the line is held at both ends at least its length less TAUT_GAP
    (relative) apart at load factor t: taut, with no catenary (catenary_axes), and the
    straight start along its chord (chord_start) its natural start."""
    start, end = scene.start_state(t), scene.end_state(t)
    chord = float(np.linalg.norm(end.position - start.position))
    return (is_held(start) and is_held(end)
            and chord >= scene.length * (1.0 - TAUT_GAP))


def chord_start(scene, t):
    """The straight line along the chord c between the held ends at load factor t, for
    a taut line (lies_straight), stretched uniformly: r = r_a + (S / L) c, d3 = e =
    c / |c|, d1 normal to the plane of e and the load's resultant (e_y projected
    normal to e where they are parallel or there is no load), d2 = d3 x d1. The force
    is that of a straight line under the load f(S) (N/m), n' + f = 0 along e:

        n(S) = (T + e . (F(S) - <F>)) e,   F(S) = int_S^L f dS,   <F> its mean over S,
        T = (|c| - L) / int_0^L dS / EA      (N, the mean tension of the stretch),

    the equilibrium of a line whose load is along the chord (a vertical tendon: the
    tension linear in height), the start of a taut one whose load sags it a little;
    T = 0 for an inextensible line (its tension is the solve's)."""
    start, end = scene.start_state(t), scene.end_state(t)
    chord = end.position - start.position
    along = chord / np.linalg.norm(chord)
    ends = scene.load_piece_ends
    loads = t * np.asarray(scene.load_values, dtype=float)
    # <F> = (1/L) int_0^L F dS = (1/L) int_0^L S f(S) dS, exact for pieces of constant f
    mean_beyond = (0.5 * (ends[1:] ** 2 - ends[:-1] ** 2)) @ loads / scene.length
    pieces = np.concatenate([[0.0], scene.stiffness_breaks, [scene.length]])
    compliance = float(np.sum(np.diff(pieces)
                              / scene.axial_stiffness_at(0.5 * (pieces[1:] + pieces[:-1]))))
    excess = float(np.linalg.norm(chord)) - scene.length
    tension = excess / compliance if compliance > 0 else 0.0
    resultant = loads.sum(axis=0)
    normal = np.cross(-resultant, along)
    if np.linalg.norm(normal) <= 1e-9 * np.linalg.norm(resultant):     # also no load
        normal = REFERENCE_FRAME[0] - (REFERENCE_FRAME[0] @ along) * along
        if np.linalg.norm(normal) < 0.5:
            normal = REFERENCE_FRAME[1] - (REFERENCE_FRAME[1] @ along) * along
    normal = normal / np.linalg.norm(normal)

    def shape(S):
        S = np.asarray(S, dtype=float)
        r = (S / scene.length)[..., None] * chord
        axial = tension + (scene.load_beyond(S, t) - mean_beyond) @ along
        tangent = np.broadcast_to(along, S.shape + (3,))
        return r, tangent, axial[..., None] * along

    return planar_curve(shape, normal, start.position)


def largest_tension(scene, t=1.0, samples=4097):
    """The largest tension |n| of the catenary start at load factor t (catenary_start,
    sampled at ``samples`` arc lengths, both ends among them), N: the multiplier the
    iteration starts from (lambda3 = n), and the tension scale of the default penalty
    (problem/penalty.py). RodInputError where the scene has no catenary start."""
    force = catenary_start(scene, t)(np.linspace(0.0, scene.length, samples))[2]
    return float(np.linalg.norm(force, axis=-1).max())


def planar_curve(shape, normal, origin):
    """The curve S -> (r, frame, force) of a planar ``shape`` S -> (r, tangent, force)
    (r from ``origin``): d1 = ``normal`` to the plane, d2 = d3 x d1, d3 the tangent."""
    def curve(S):
        r, tangent, force = shape(S)
        d1 = np.broadcast_to(normal, tangent.shape)
        frame = np.stack([d1, np.cross(tangent, d1), tangent], axis=-2)
        return origin + r, frame, force

    return curve


def section_start(scene, t, start, end):
    """The catenary of a line of sections (section_catenary.py) at load factor t: the
    weights of the load's pieces, which must all be vertical; resting on the seabed
    from S = 0 where the start lies on it. NoCatenaryStart where there is none, or where
    the line would pass below the seabed."""
    loads = t * scene.load_values
    if np.any(loads[:, :2]) or not np.any(loads[:, 2]):
        raise NoCatenaryStart("-rod_initial_shape catenary with -rod_load_breaks needs "
                              "vertical loads (0,0,fz per piece), not all zero")
    chord = end.position - start.position
    span = float(np.hypot(chord[0], chord[1]))
    seabed = scene.seabed
    on_seabed = seabed is not None and abs(start.position[2] - seabed.height) <= (
        1e-9 * scene.length)
    try:
        line = section_catenary.solve(scene.load_piece_ends, -loads[:, 2], span,
                                      float(chord[2]), on_seabed)
    except ValueError as error:
        raise NoCatenaryStart("-rod_initial_shape catenary: no catenary of the load's "
                              f"pieces ({str(error).removeprefix('section catenary: ')})"
                              ) from None
    along = np.array([chord[0], chord[1], 0.0]) / span
    up = np.array([0.0, 0.0, 1.0])
    if seabed is not None and not on_seabed:        # on it: section_catenary checks
        lowest = line.at(np.linspace(0.0, scene.length, 4097))[1].min() + start.position[2]
        if lowest < seabed.height:
            raise NoCatenaryStart("-rod_initial_shape catenary: the catenary of the "
                                  "load's pieces passes below the seabed and its start is "
                                  "not on it")

    def shape(S):
        x, z, V = line.at(S)
        force = line.H * along + V[..., None] * up
        tangent = force / np.linalg.norm(force, axis=-1, keepdims=True)
        return x[..., None] * along + z[..., None] * up, tangent, force

    return planar_curve(shape, np.cross(up, along), start.position)


def start_direction(scene, which):
    """The line's direction (d3, (3,)) at ``which`` end ('start' or 'end') in the scene's
    start shape, the default neutral axis of a flex joint there (Scene.__post_init__):
    the tangent of its catenary at load factor 1 (the curve -rod_initial_shape catenary
    starts from: through both held ends, resting on the seabed, the weights of the
    sections) where it has one, the joint then unloaded in the catenary's static angle,
    as a flex joint is installed at a hang-off; else e_x, the straight reference (an end
    free, no load). A default e_x made a riser's hang-off joint turn by 85 degrees."""
    try:
        frames = catenary_start(scene, 1.0)(np.array([0.0 if which == "start"
                                                      else scene.length]))[1]
    except RodInputError:
        return REFERENCE_FRAME[2].copy()
    return frames[0][2]
