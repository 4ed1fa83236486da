"""Every check that decides whether a System (model/system.py) can be solved, before any
line is meshed: the names, what each line's ends are connected to, each line's own
checks (those of a single line, model/model.py, and of its derived forces that do not
depend on where its ends are: a current's drag, the applied force, model/derived.py), a
current's drag on a free point within the model's bound, a line too short for the held
points it joins, a point without a line, and a body's degree of freedom that nothing
restores.
Each refusal is one RodInputError saying what is wrong and how to fix it.

The seabed under a sloped or profiled sea is checked per line where the line is compiled
(compile.py: check_ends_above); here only the flat seabed under the held points.
"""

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.model.end import End
from petsc_rod.model.derived import TAUT_GAP, Loads, check_applied_forces
from petsc_rod.model.model import Span, check_pipe, check_sea, check_span
from petsc_rod.model.values import MAX_MAGNITUDE, MAX_STRAIN

# The degrees of freedom of a body, in Body.position's order.
DOFS = ("x", "y", "z", "roll", "pitch", "yaw")


def rotation(roll, pitch, yaw):
    """R = R_z(yaw) R_y(pitch) R_x(roll), (..., 3, 3): body axes to global ones (angles
    in rad, scalars or arrays of one shape), as Body.position gives them."""
    cr, sr, cp, sp, cy, sy = (np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch),
                              np.cos(yaw), np.sin(yaw))
    return np.stack([np.stack([cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr], -1),
                     np.stack([sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr], -1),
                     np.stack([-sp, cp * sr, cp * cr], -1)], -2)


def tait_bryan_zyx(R):
    """(..., 3): (roll, pitch, yaw), rad, of R = R_z(yaw) R_y(pitch) R_x(roll) (pitch in
    [-pi/2, pi/2]): the angles a Body's position holds."""
    pitch = np.arcsin(np.clip(-R[..., 2, 0], -1.0, 1.0))
    return np.stack([np.arctan2(R[..., 2, 1], R[..., 2, 2]), pitch,
                     np.arctan2(R[..., 1, 0], R[..., 0, 0])], -1)


def connection_position(node, connection):
    """Where ``connection`` is, (3,), m, global, with its Point or Body ``node`` at its
    start position: the point's position, or the body's reference point plus its
    rotation times the local point."""
    if hasattr(node, "kind"):
        return np.asarray(node.position, dtype=float)
    place = np.asarray(node.position, dtype=float)
    return place[:3] + rotation(*place[3:]) @ np.asarray(connection.local, dtype=float)


def connection_frame(node, connection, at_end):
    """The line's end frame ``connection`` holds, (3, 3) rows d1, d2, d3, global axes,
    with its Body ``node`` at its start pose: D_b R^T (D_b = Connection.line_frame,
    body axes; ``at_end``: the line's end S = L); None where the connection gives no
    direction."""
    frame = connection.line_frame(at_end)
    if frame is None:
        return None
    return frame @ rotation(*np.asarray(node.position, dtype=float)[3:]).T


def is_held(node):
    """Whether a Point or Body is held where it is: a fixed or prescribed point, a body
    held in all six degrees of freedom."""
    return node.kind != "free" if hasattr(node, "kind") else bool(np.all(node.held))


def check_system(system, names, made_by=None):
    """Raise RodInputError on a System no equilibrium can be sought for; the single
    line's checks word their messages with ``names`` (names.Names), prefixed by the
    line's name; ``made_by`` {("line", name) or ("node", name): what}: what changed a
    line's length or moved a point or body from the model's (a command line's option),
    named in the messages of the spans it changed."""
    if not system.lines:
        raise RodInputError("System.lines: a system needs at least one line (SystemLine)")
    check_names(system)
    nodes = {item.name: item for item in (*system.points, *system.bodies)}
    for line in system.lines:
        check_connections(line, nodes)
    check_lines(system, names)
    check_point_drag(system, names)
    check_points(system)
    check_held_spans(system, nodes, made_by or {})
    check_seabed_under(system, names)
    sea = system.environment
    for body in system.bodies:
        # a line from the body to itself (a bridle) holds nothing against its motion
        check_restoring(body, [(line, which) for line in system.lines
                               for which in ("start", "end")
                               if getattr(line, which).to == body.name
                               and (line.start.to, line.end.to) != (body.name,) * 2],
                        sea.water_density, sea.gravity)
    check_anchored(system)


# The tables a system's run writes beside its lines' FILE_<line>.csv (api/system_run
# table_paths): its own, its sweeps' and its modes', and each line's regions' and ends'.
RESERVED = ("system", "watch_circle", "excursion", "system_modes")
SUFFIXES = ("_regions", "_ends")


def check_names(system):
    """Names unique among the points and bodies (a Connection names one of them), and
    among the lines; no line named as one of the system's tables (RESERVED) or another
    line's regions' or ends' table, whose FILE_<name>.csv it would share."""
    for what, items in (("points or bodies", (*system.points, *system.bodies)),
                        ("lines", system.lines)):
        seen = set()
        for item in items:
            if item.name in seen:
                raise RodInputError(f"two {what} are named {item.name}: give each a name "
                                    "of its own")
            seen.add(item.name)
    tables = [f"{line.name}{suffix}" for line in system.lines for suffix in SUFFIXES]
    for line in system.lines:
        if line.name in RESERVED or line.name in tables:
            owner = ("the system's" if line.name in RESERVED
                     else "another line's")
            raise RodInputError(f"line {line.name}: the name of {owner} table "
                                f"(the run's tables would share FILE_{line.name}.csv); "
                                "rename the line")


def check_connections(line, nodes):
    """Each end of ``line`` names an existing point or body; a point takes a pin at
    itself (no local point, no clamp: a point has no frame); a pin takes no direction
    nor twist, a flex joint no twist, a twist needs a direction; a flex joint has a
    stiffness >= 0 and only a flex joint has one; the two ends are not one point."""
    for which in ("start", "end"):
        connection = getattr(line, which)
        owner = f"line {line.name}: {which}"
        node = nodes.get(connection.to)
        if node is None:
            known = ", ".join(sorted(nodes)) or "none"
            raise RodInputError(f"{owner}: no point or body is named {connection.to} "
                                f"(the points and bodies: {known}); name one of them")
        if hasattr(node, "kind"):
            if connection.kind != "pin":
                raise RodInputError(
                    f"{owner}: a {connection.kind} at point {node.name}: a point has no "
                    "rotation to hold the line's end frame against; connect the end to a "
                    "Body (held in all degrees of freedom for a fixed clamp), or use a pin")
            if np.any(np.asarray(connection.local, dtype=float) != 0):
                raise RodInputError(
                    f"{owner}: Connection.local {tuple(connection.local)} at point "
                    f"{node.name}: a local point belongs to a body; move the point instead "
                    "and give local (0, 0, 0)")
        if connection.kind == "flex" and not (connection.stiffness is not None
                                              and connection.stiffness >= 0):
            raise RodInputError(f"{owner}: a flex joint needs Connection.stiffness >= 0 "
                                "(N m/rad)")
        if connection.kind == "pin" and (connection.direction is not None
                                         or connection.twist is not None):
            raise RodInputError(f"{owner}: Connection.direction or twist at a pin: a pin "
                                "holds no frame; give kind 'clamp' (or 'flex' for a "
                                "direction) or drop them")
        if connection.kind == "flex" and connection.twist is not None:
            raise RodInputError(f"{owner}: Connection.twist at a flex joint: the joint "
                                "holds no roll about the line; drop the twist or give "
                                "kind 'clamp'")
        if connection.twist is not None and connection.direction is None:
            raise RodInputError(f"{owner}: Connection.twist without a direction: the "
                                "twist turns the clamp about its direction; give both")
        if connection.kind != "flex" and connection.stiffness is not None:
            raise RodInputError(f"{owner}: Connection.stiffness is a flex joint's; give "
                                f"kind 'flex' or drop the stiffness (the end is a "
                                f"{connection.kind})")
    if line.start.to == line.end.to and hasattr(nodes[line.start.to], "kind"):
        raise RodInputError(f"line {line.name}: both ends at point {line.start.to}: a line "
                            "joins two points (or two places of a body)")


def check_lines(system, names):
    """Each line's own checks as a single line's (model.check_span, check_pipe), on a
    Span pinned at both ends whose positions are left to the system (the chord between
    held points: check_held_spans), the sea's with all of them (check_sea), then each
    line's derived forces in the system's sea (derived.check_applied_forces: a current's
    largest drag, the applied force; the line's build checks them again, with the
    model's names), so that the option that gave the current is the one named
    (``names``: the command line's)."""
    spans = [Span(line.line, End("pin"), End("pin"), tuple(line.attachments))
             for line in system.lines]
    for line, span in zip(system.lines, spans):
        of_line(line, check_span, span, system.environment, names)
        if span.sections:
            of_line(line, check_pipe, span.line, names)
    check_sea(system.environment, spans, names)
    for line, span in zip(system.lines, spans):
        of_line(line, check_applied_forces, Loads.of(span, system.environment), names)


def check_point_drag(system, names):
    """Refuse a current whose drag on a free point, 0.5 rho CdA max |v|^2 (N: its drag
    area CdA, m^2, in the current's fastest row), is above MAX_MAGNITUDE, the bound of
    the model's numbers (the lines' own: check_lines), naming the point and what gave
    the current (``names``); a fixed or prescribed point's drag pushes nothing."""
    rows = system.environment.current_rows()
    if rows is None:
        return
    current = names["current_profile"] if system.environment.profile() is not None \
        else names["current"]
    speed = float(np.max(np.sum(np.asarray(rows[1]) ** 2, axis=1)))
    for point in system.points:
        drag = 0.5 * system.environment.water_density * point.cda * speed
        if point.kind == "free" and drag > MAX_MAGNITUDE:
            raise RodInputError(
                f"point {point.name}: {current} with its drag area CdA {point.cda:g} m^2: "
                f"the largest drag 0.5 rho CdA max |v|^2 = {drag:.3g} N is above "
                f"{MAX_MAGNITUDE:g}; give the current in m/s")


def of_line(line, check, *args):
    """``check(*args)``, its RodInputError's message led by the SystemLine's name."""
    try:
        check(*args)
    except RodInputError as error:
        raise RodInputError(f"line {line.name}: {error}") from None


def check_points(system):
    """Every point is the end of some line (a point with no line is a mistake: a free
    one has nothing to hold it, a held one holds nothing)."""
    used = {getattr(line, which).to for line in system.lines for which in ("start", "end")}
    for point in system.points:
        if point.name not in used:
            raise RodInputError(f"point {point.name} ({point.kind}) is the end of no line: "
                                "connect a line to it, or drop it")


def groups(system):
    """The names of the points and bodies joined by lines, in groups (lists of names),
    each group in the order of system.points + system.bodies."""
    parent = {item.name: item.name for item in (*system.points, *system.bodies)}

    def root(name):
        while parent[name] != name:
            name = parent[name]
        return name

    for line in system.lines:
        parent[root(line.start.to)] = root(line.end.to)
    found = {}
    for name in parent:
        found.setdefault(root(name), []).append(name)
    return list(found.values())


def check_anchored(system):
    """Each group of points and bodies joined by lines (groups) is held in x, y and z by
    a fixed or prescribed point, or a body holding that translation or with a positive
    hydrostatic term in it; else the group's rigid translation is free (a buoy on a
    line to a clump weight, nothing else)."""
    sea = system.environment
    nodes = {item.name: item for item in (*system.points, *system.bodies)}
    for names in groups(system):
        held = np.zeros(3, dtype=bool)
        for name in names:
            node = nodes[name]
            if hasattr(node, "kind"):
                held |= node.kind != "free"
            else:
                held |= np.asarray(node.held, dtype=bool)[:3] | (restoring_by_hydrostatics(
                    node, sea.water_density, sea.gravity)[:3] > 0)
        if not np.all(held):
            which = ", ".join(DOFS[k] for k in np.flatnonzero(~held))
            shown = ", ".join(names[:4]) + (", ..." if len(names) > 4 else "")
            raise RodInputError(
                f"nothing holds {shown} in {which}: no fixed or prescribed point, and no "
                "body held or with hydrostatic stiffness there, among the points and bodies "
                "its lines join (a rigid motion is free); anchor a line, or hold a body")


def needed_strain(lengths, eas, chord):
    """The largest strain of a line of sections of ``lengths`` (m,), m, and axial
    stiffnesses ``eas`` (m,), N (inf: inextensible), pulled straight to ``chord`` (m):
    the tension T of sum L_i (1 + T / EA_i) = chord, eps = T / min EA; 0 when the line
    reaches slack, inf when it cannot stretch to it. The least strain of any
    equilibrium: a weight or a current only adds to it."""
    lengths, eas = np.asarray(lengths, dtype=float), np.asarray(eas, dtype=float)
    excess = chord - lengths.sum()
    if excess <= 1e-12 * lengths.sum():
        return 0.0
    compliance = float(np.sum(lengths / eas))
    return np.inf if compliance == 0 else excess / compliance / float(eas.min())


def sections_stretch(model):
    """The lengths (m) and axial stiffnesses EA (N, inf: inextensible) of a Line's
    sections, or a UniformLine's one, as needed_strain takes them."""
    if hasattr(model, "sections"):
        return model.lengths, [entry[0].ea for entry in model.sections]
    return [model.length], [model.axial_stiffness]


def ends_chord(line, nodes):
    """The vector (3,) from ``line``'s start to its end, m, with their points and bodies
    (``nodes`` by name) at their start positions."""
    return (connection_position(nodes[line.end.to], line.end)
            - connection_position(nodes[line.start.to], line.start))


def ends_distance(line, nodes):
    """The distance (m) between ``line``'s ends at their start positions (ends_chord)."""
    return float(np.linalg.norm(ends_chord(line, nodes)))


def check_not_folded(line, nodes, made_by):
    """A line whose ends lie on one vertical (their horizontal distance below 1e-9 of
    its length) must be no longer than their distance (to TAUT_GAP): a taut line (a
    tendon) is straight between them, tension linear in height, and starts so
    (scenes/starts.chord_start); a longer one has no catenary and, weighed down,
    would fold on itself."""
    chord = ends_chord(line, nodes)
    length, distance = float(line.line.length), float(np.linalg.norm(chord))
    if np.hypot(chord[0], chord[1]) <= 1e-9 * length and distance < length * (1 - TAUT_GAP):
        raise RodInputError(
            f"line {line.name}: its ends {line.start.to} and {line.end.to} lie on one "
            f"vertical {distance:.6g} m apart where the run starts{changed_by(line, made_by)}"
            f", and its length {length:.6g} m is longer, so it has no catenary and would "
            "fold on itself; shorten it to at most their distance (a taut tendon) or "
            "move an end sideways")


def changed_by(line, made_by):
    """' (OPTION, ...)': what changed ``line``'s length or moved its ends (made_by of
    check_system), '' for the model's own."""
    found = [made_by[key] for key in (("line", line.name), ("node", line.start.to),
                                      ("node", line.end.to)) if key in made_by]
    return f" ({', '.join(dict.fromkeys(found))})" if found else ""


def check_held_spans(system, nodes, made_by):
    """A line between two held points (or bodies held in all degrees of freedom) must
    reach across them: an inextensible one no shorter than their distance, an extensible
    one within MAX_STRAIN of it (the bound of the single line's model of stretch); and
    not be folded on one vertical (check_not_folded)."""
    for line in system.lines:
        start, end = nodes[line.start.to], nodes[line.end.to]
        if not (is_held(start) and is_held(end)):
            continue
        check_not_folded(line, nodes, made_by)
        chord = ends_distance(line, nodes)
        lengths, eas = sections_stretch(line.line)
        strain = needed_strain(lengths, eas, chord)
        if strain == np.inf:
            raise RodInputError(
                f"line {line.name}: {line.start.to} and {line.end.to} are held "
                f"{chord:.6g} m apart{changed_by(line, made_by)}, "
                f"{chord - float(np.sum(lengths)):.3g} m more than "
                f"its length {float(np.sum(lengths)):.6g} m (inextensible); lengthen the "
                "line, move the points closer, or give its line types an EA")
        if strain > MAX_STRAIN:
            raise RodInputError(
                f"line {line.name}: {line.start.to} and {line.end.to} are held "
                f"{chord:.6g} m apart{changed_by(line, made_by)}: its length "
                f"{float(np.sum(lengths)):.6g} m must "
                f"stretch by {100 * strain:.3g} % or more to reach, above "
                f"{100 * MAX_STRAIN:g} %, where the linear stretch models no line "
                "material; lengthen the line, move the points closer, or check its EA (N)")


def check_reach(system, made_by=None):
    """The lines with an end at a free point or body, where the run starts (the free
    one at its start position); a line between held ends is check_held_spans'. None may
    be folded on one vertical (check_not_folded). A line shorter than its ends' distance
    (to TAUT_GAP) is taut: it starts straight along its chord (scenes/starts.chord_start),
    stretched to it, so it must be able to stretch that far (needed_strain: extensible,
    within MAX_STRAIN). A longer line hangs as its catenary start. A free node
    whose lines are all taut must be pulled away along one of them at least, or be held
    between opposing ones (pulled): else they would all be in compression. Not part of check_system: a model's free
    points may stand anywhere (a MoorDyn file's are guesses); the run refuses them before
    it starts (cli_system.changed). ``made_by``: check_system's."""
    made_by = made_by or {}
    nodes = {item.name: item for item in (*system.points, *system.bodies)}
    taut, slack = {}, set()
    for line in system.lines:
        if is_held(nodes[line.start.to]) and is_held(nodes[line.end.to]):
            continue
        check_not_folded(line, nodes, made_by)
        chord = ends_chord(line, nodes)
        distance, length = float(np.linalg.norm(chord)), float(line.line.length)
        ends = [(line.start.to, -chord), (line.end.to, chord)]
        if distance < length * (1 - TAUT_GAP):
            slack.update(name for name, _ in ends)
            continue
        check_stretch(line, distance, made_by)
        for name, outward in ends:
            if line.start.to != line.end.to and not is_held(nodes[name]):
                taut.setdefault(name, []).append((line, outward / distance))
    sea = system.environment
    for name, lines in taut.items():
        if name not in slack:
            pulled(nodes[name], lines, sea.water_density, sea.gravity, made_by)


def check_stretch(line, distance, made_by):
    """A taut line (ends ``distance`` m apart, at least its length) with a free end must
    stretch to its chord: extensible, with a strain (needed_strain) within MAX_STRAIN."""
    lengths, eas = sections_stretch(line.line)
    strain = needed_strain(lengths, eas, distance)
    length = float(np.sum(lengths))
    head = (f"line {line.name}: its length {length:.6g} m is shorter than its ends' "
            f"distance {distance:.6g} m, {line.start.to} to {line.end.to} where the run "
            f"starts{changed_by(line, made_by)}")
    if strain == np.inf:
        raise RodInputError(f"{head}, and it is inextensible: lengthen the line, move its "
                            "ends closer, or give its line types an EA")
    if strain > MAX_STRAIN:
        raise RodInputError(f"{head}: it must stretch by {100 * strain:.3g} % or more to "
                            f"reach, above {100 * MAX_STRAIN:g} %, where the linear stretch "
                            "models no line material; lengthen the line or move its ends "
                            "closer")


def own_force(node, water_density, gravity):
    """The force (3,), N, global, on a Point or Body of its own at its start: buoyancy
    less weight, (rho V - m) g e_z, and its constant force or load."""
    load = np.asarray(node.force if hasattr(node, "kind") else node.load[:3], dtype=float)
    return load + np.array([0.0, 0.0, (water_density * node.volume - node.mass) * gravity])


def pulled(node, lines, water_density, gravity, made_by):
    """A free point or body whose lines are all taut (``lines``: [(SystemLine, unit
    vector from its other end to this node)]) and whose translation
    nothing else holds (a held translation, a hydrostatic term) must be pulled along one
    of them at least, its own force F (own_force) with F . e > 0 for some e, or be held
    between them (balanced: opposing lines whose tensions balance, whatever F; it moves
    until they take F). A taut line holds its node only by its tension, so with
    F . e <= 0 for all and no opposing lines (a TLP's hull heavier than its buoyancy, a
    weightless point at the end of one straight line) the tendons' equilibrium would
    need compression."""
    if not hasattr(node, "kind") and (
            np.any(np.asarray(node.held, dtype=bool)[:3])
            or np.any(restoring_by_hydrostatics(node, water_density, gravity)[:3] > 0)):
        return
    force = own_force(node, water_density, gravity)
    directions = np.array([outward for _, outward in lines])
    scale = 1e-12 * max(float(np.linalg.norm(force)), 1.0)
    if np.max(directions @ force) > scale or balanced(directions):
        return
    line = lines[0][0]
    shown = ", ".join(f"{value:.6g}" for value in force)
    raise RodInputError(
        f"line {line.name}: taut between {line.start.to} and {line.end.to} where the run "
        f"starts{changed_by(line, made_by)}, as are all lines at {node.name}, and nothing "
        f"pulls them: {node.name}'s buoyancy less weight and load, ({shown}) N, pulls it "
        "along none of them away from their other ends, so they would be in compression; "
        f"give {node.name} more buoyancy than weight (a tension leg platform), or lengthen "
        "a line so it hangs slack")


def balanced(directions, tolerance=1e-9):
    """Whether tensions T_i >= 0, not all zero, balance along the unit ``directions``
    (n, 3): sum T_i e_i = 0, i.e. 0 lies in their convex hull (a node held between
    opposing taut lines: a buoy on a level pretensioned line, a connector between two
    tendons), so their own tensions hold it whatever its own force. By Caratheodory's
    theorem in 3-D, 0 lies in the hull of at most four of them: each subset of two to
    four is tried for barycentric weights w >= 0, sum w = 1, with E^T w = 0 (least
    squares, the residual within ``tolerance``). A node's lines are few (the subsets of
    twelve lines are 781)."""
    count = len(directions)
    for size in range(2, min(count, 4) + 1):
        for subset in _subsets(count, size):
            rows = np.vstack([np.asarray(directions)[list(subset)].T, np.ones(size)])
            weights, *_ = np.linalg.lstsq(rows, np.r_[np.zeros(3), 1.0], rcond=None)
            residual = rows @ weights - np.r_[np.zeros(3), 1.0]
            if np.all(weights >= -tolerance) and np.linalg.norm(residual) <= tolerance:
                return True
    return False


def _subsets(count, size, first=0):
    """The index tuples of ``size`` of range(first, count), increasing (combinations)."""
    if size == 0:
        yield ()
        return
    for index in range(first, count - size + 1):
        for rest in _subsets(count, size - 1, index + 1):
            yield (index,) + rest


def check_seabed_under(system, names=None):
    """No held point below a flat or sloping seabed (to round-off of the lines' length),
    the plane's options named through ``names`` (names.Names; None: the model's
    fields)."""
    sea = system.environment
    scale = 1e-12 * max(float(sum(line.line.length for line in system.lines)), 1.0)
    for point in system.points:
        x, y, z = (float(value) for value in point.position)
        height = sea.plane_height(x, y)
        if point.kind == "free" or height is None or height - z <= scale:
            continue
        if not sea.seabed_slope:
            raise RodInputError(
                f"point {point.name} ({point.kind}) is held at z = {z:.6g} m, "
                f"{height - z:.3g} m below the seabed (Environment.seabed {sea.seabed:g}); "
                "hold it on or above it")
        given = ", ".join(names[field] if names is not None else f"Environment.{field}"
                          for field in ("seabed_slope", "seabed_direction", "seabed_origin"))
        raise RodInputError(
            f"point {point.name} ({point.kind}) is held at z = {z:.6g} m, {height - z:.3g} "
            f"m below the sloping seabed there (z = {height:.6g} m: the plane of {given}); "
            "hold it on or above it, or move the plane's origin or change its slope")


def restoring_by_hydrostatics(body, water_density, gravity):
    """The diagonal (6,) of a body's own restoring at its start: the given hydrostatic
    matrix's, else rho g A_wp in heave and rho g (I_wp + V z_b) - m g z_g in roll and
    pitch (body axes about the reference point; none in surge, sway and yaw)."""
    if body.hydrostatic is not None:
        return np.diag(np.asarray(body.hydrostatic, dtype=float).reshape(6, 6)).copy()
    rho_g = water_density * gravity
    moments = np.asarray(body.waterplane_moments, dtype=float)
    tilt = (rho_g * (moments + body.volume * float(body.cob[2]))
            - body.mass * gravity * float(body.cog[2]))
    return np.array([0.0, 0.0, rho_g * body.waterplane_area, tilt[0], tilt[1], 0.0])


def restoring_by_lines(body, ends):
    """Which of a body's degrees of freedom (6,) bools its lines' ends ``ends`` ((line,
    'start'|'end'), ...) hold: any line the translations; a rotation about the axis e_k
    unless every end is a pin and all of them lie on one line along e_k (the body then
    turns about that line, carrying the ends with it)."""
    if not ends:
        return np.zeros(6, dtype=bool)
    connections = [getattr(line, which) for line, which in ends]
    if any(c.kind != "pin" for c in connections):
        return np.ones(6, dtype=bool)
    turn = rotation(*np.asarray(body.position, dtype=float)[3:])
    places = np.array([turn @ np.asarray(c.local, dtype=float) for c in connections])
    offsets = places - places[0]
    scale = 1e-9 * max(float(np.abs(places).max()), 1.0)
    spread = np.array([np.abs(np.cross(offsets, axis)).max() > scale for axis in np.eye(3)])
    return np.concatenate([np.ones(3, dtype=bool), spread])


def check_restoring(body, ends, water_density, gravity):
    """Refuse a body's free degree of freedom that neither its lines (restoring_by_lines)
    nor its hydrostatics (restoring_by_hydrostatics, a positive diagonal term) restore:
    the coupled equilibrium's matrix would be singular in it."""
    if body.hydrostatic is not None and (body.waterplane_area
                                         or np.any(np.asarray(body.waterplane_moments))):
        raise RodInputError(f"body {body.name}: give its hydrostatic matrix or its waterplane "
                            "area and moments, not both (the matrix stands in for them)")
    hydro = restoring_by_hydrostatics(body, water_density, gravity) > 0
    loose = ~np.asarray(body.held, dtype=bool) & ~hydro & ~restoring_by_lines(body, ends)
    if np.any(loose):
        which = ", ".join(DOFS[k] for k in np.flatnonzero(loose))
        lines = (f"its {len(ends)} line end(s), all pinned on one line along that axis,"
                 if ends else "no line to another point or body")
        raise RodInputError(
            f"body {body.name}: nothing restores its {which}: {lines} and no hydrostatic "
            "stiffness there; attach lines, give Body.hydrostatic (or its waterplane), or "
            f"hold {which} (Body.held)")
