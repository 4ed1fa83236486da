"""The Scene the solver takes, compiled from a Model (petsc_rod/model): the line's
sections or its uniform values, the ends in the solver's frame (its origin at the
start, docs/method.md §5), the attachments' forces, the seabed (its shape, default
stiffness and friction), the current and the pipe's pressures, each resolved here and
given to the Scene's constructor; then the checks that need them (the seabed under the
held ends, a taut line, the derived forces and the seabed's stiffness in range).

    Model --compile_scene--> Scene --RodProblem--> problem --UzawaSolver--> solution
"""

import dataclasses

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.model.attachment import attachment_columns, dead_forces
from petsc_rod.model.names import FIELD_NAMES
from petsc_rod.model.values import MAX_MAGNITUDE
from petsc_rod.environment.bathymetry import Grid, Plane, Profile
from petsc_rod.environment.current import Current
from petsc_rod.environment.profiles import grid_axes
from petsc_rod.environment.seabed import (MIN_RELATIVE_PENETRATION, Friction, Seabed,
                                          check_covered, check_ends_above,
                                          default_stiffness, largest_stiffness)
from petsc_rod.scenes.boundary import is_held
from petsc_rod.scenes.scene import Scene

# The default stick stiffness of the friction over the seabed's stiffness: at the default
# seabed stiffness (weight / 1 mm) the weight mobilises the friction over mu x 1 cm, as
# pipe-soil practice has it (a few mm axially, a tenth of a diameter laterally); stiffer
# sticks slowed the iteration down (docs/riser.md §3b).
FRICTION_STIFFNESS_RATIO = 0.1


def compile_scene(model, names=FIELD_NAMES):
    """The validated Scene of ``model`` (model.Model, checked here: Model.check), every
    refusal worded with ``names`` (model/names.py)."""
    model.check(names)
    (span,) = model.spans                   # a Scene is one line
    sea = model.environment
    line, start, end = span.line, span.start, span.end
    origin = span.origin()
    if span.sections:
        sections = tuple(line.section_list(sea.water_density, sea.gravity))
        shape = dict(length=sections[-1].end, stiffness=sections[0].stiffness_start,
                     load_values=[s.weight for s in sections],
                     load_breaks=[s.start for s in sections[1:]], sections=sections)
    else:
        shape = dict(length=line.length, stiffness=line.stiffness,
                     load_values=line.load_values, load_breaks=line.load_breaks,
                     axial_stiffness=line.axial_stiffness)
    S, forces, labels, areas, volumes = points_of(span.attachments, sea)
    bare = Scene(**shape, start=start.kind, end=end.kind, start_position=origin,
                 end_position=None if end.position is None
                 else np.asarray(end.position) - origin,
                 end_frame=end.frame, start_frame=start.frame,
                 end_twist=0.0 if end.twist is None else end.twist,
                 start_force=np.zeros(3) if start.force is None else start.force,
                 end_force=np.zeros(3) if end.force is None else end.force,
                 point_load_S=S,
                 point_load_forces=forces, point_load_names=labels,
                 point_load_drag_areas=areas, point_load_volumes=volumes,
                 water_density=sea.water_density,
                 gravity=sea.gravity)
    seabed, current = environment_of(sea, bare, names,
                                     None if span.sections else line.drag)
    # the joints with the seabed: a joint's default axis is the line's direction in its
    # start shape, which rests on the seabed (Scene.__post_init__)
    joints = dict(start_rotational_stiffness=start.stiffness or 0.0,
                  end_rotational_stiffness=end.stiffness or 0.0,
                  start_joint_axis=start.axis, end_joint_axis=end.axis)
    scene = dataclasses.replace(bare, seabed=seabed, current=current, **joints,
                                **pressures_of(line, sea, origin) if span.sections else {})
    check_taut(scene, names)
    check_applied_forces(scene, sea, names)
    check_seabed_stiffness(scene, sea, names)
    return scene


def points_of(attachments, sea):
    """(S (n_p,), forces (n_p, 3), labels, drag areas (n_p,), volumes (n_p,)) of the
    attachments in the sea ``sea`` (their weight and buoyancy: model/attachment.py)."""
    if not attachments:
        return np.zeros(0), np.zeros((0, 3)), (), np.zeros(0), np.zeros(0)
    columns = attachment_columns(attachments)
    return (columns["s"], dead_forces(attachments, sea.water_density, sea.gravity),
            tuple(a.name or f"point {k + 1}" for k, a in enumerate(attachments)),
            columns["cda"], columns["volume"])


def pressures_of(line, sea, origin):
    """The Scene's pipe fields of a Line of sections: the sea surface in the solver's
    frame (None: the higher held end), the contents' density, the internal pressure at
    the top and the design factor (quantities/pressures.py, quantities/stresses.py)."""
    fields = dict(contents_density=float(line.contents_density or 0.0),
                  internal_pressure=float(line.internal_pressure or 0.0))
    if line.design_factor is not None:
        fields["design_factor"] = float(line.design_factor)
    if sea.surface is not None:
        fields["sea_surface"] = float(sea.surface - origin[2])
    return fields


def line_names(sections, n):
    """How a message names what gives the line's load, stiffness, stretch, drag and
    length: a uniform line's fields, or what the line types give in their place."""
    if sections:
        return dict(load=f"the line types' weight (mass and od in {n['line_types']})",
                    stiffness=f"the line types' ei and gj ({n['line_types']})",
                    stretch="the line types an ea column (EA, N)",
                    drag=f"the line types' cd and drag_d ({n['line_types']})",
                    length=n["sections"])
    return dict(load=n["load"], stiffness=n["stiffness"],
                stretch=f"{n['axial_stiffness']} EA", drag=n["drag"], length=n["length"])


def seabed_direction(sea):
    """The unit horizontal vector of the seabed's direction (an azimuth in degrees, or
    a vector dx,dy; checked by Model.check), default +x."""
    given = sea.seabed_direction
    if given is None:
        return np.array([1.0, 0.0])
    given = np.atleast_1d(np.asarray(given, dtype=float))
    if given.size == 1:
        angle = np.radians(given[0])
        return np.array([np.cos(angle), np.sin(angle)])
    return given / float(np.hypot(*given))


def seabed_shape(sea, height, origin, n):
    """The bathymetry.Plane, Profile or Grid of the sea's seabed in the scene's frame (its
    origin at ``origin`` (3,), absolute), or None for a flat seabed (no slope, or a
    slope of 0: the plane z = ``height``, bit for bit); ``height`` the seabed's absolute
    height."""
    direction = seabed_direction(sea)
    seabed_origin = np.asarray(sea.seabed_origin if sea.seabed_origin is not None
                               else (0.0, 0.0), dtype=float)
    if sea.seabed_profile is not None:
        table = np.asarray(sea.seabed_profile, dtype=float)
        if table.shape[1] == 2:
            return Profile(seabed_origin, direction, table[:, 0], table[:, 1]).moved(origin)
        xs, ys, heights = grid_axes(table, RodInputError)
        return Grid(seabed_origin, xs, ys, heights).moved(origin)
    if sea.seabed_slope is None or sea.seabed_slope == 0:
        return None
    return Plane.sloping(seabed_origin, height, sea.seabed_slope, direction).moved(origin)


def seabed_of(sea, load_values, sections, origin, n):
    """The Seabed (environment/seabed.py) of the sea, or None; heights in the scene's
    frame (its origin at ``origin`` (3,), absolute)."""
    if not sea.has_seabed:
        return None
    stiffness = sea.seabed_stiffness
    if stiffness is None:
        stiffness = default_stiffness(load_values)
        if stiffness is None:
            load = ("no line type sinks (mass above the water displaced)" if sections
                    else f"no {n['load']} points down")
            raise RodInputError(f"{n['seabed']}: {load} to set the default stiffness "
                                f"(weight / 1 mm); give {n['seabed_stiffness']}")
    friction = None
    if sea.seabed_friction is not None:
        mu = np.atleast_1d(np.asarray(sea.seabed_friction, dtype=float))
        stick = sea.seabed_friction_stiffness
        if stick is None:
            stick = FRICTION_STIFFNESS_RATIO * float(stiffness)
        friction = Friction(float(mu[0]), float(mu[-1]), float(stick))
    # the height in the solver's frame, and back: the plane through the same numbers
    relative = None if sea.seabed is None else sea.seabed - origin[2]
    shape = seabed_shape(sea, None if relative is None else relative + origin[2], origin, n)
    if shape is None:
        return Seabed(float(relative), float(stiffness), friction=friction)
    return Seabed(float(shape.height(0.0, 0.0)), float(stiffness), shape, friction)


def environment_of(sea, scene, n, drag=None):
    """(Seabed or None, Current or None) of the sea for the bare ``scene`` (its line and
    ends), checked against it: the seabed under and below the held ends; heights in the
    scene's frame (the model's less the start's z). ``drag``: a uniform line's (rho, Cd,
    D), which its current carries (a line of sections: the largest of theirs)."""
    z0 = float(scene.start_position[2])
    seabed = seabed_of(sea, scene.load_values, scene.sections, scene.start_position, n)
    # a flat seabed: also the unloaded reference's ends (straight along e_x on it); a
    # sloping one crosses that line, so only the loaded ends are held to it
    loads = (0.0, 1.0) if seabed is None or seabed.flat else (1.0,)
    ends = [(n["start"], scene.start_state(t)) for t in loads]
    ends += [(n["end"], scene.end_state(t)) for t in loads]
    check_covered(seabed, [state.position for _, state in ends if is_held(state)],
                  "the held ends", n["seabed_profile"])
    check_ends_above(seabed, ends, scene.length, z0, n["seabed"])
    held = [state.position[2] for _, state in ends if is_held(state)]
    seabed = seated(seabed, [state.position for _, state in ends if is_held(state)])
    return seabed, current_of(sea, scene, held, n, drag)


def current_of(sea, scene, held, n, drag=None):
    """The Current of the sea for the bare ``scene`` (None without one), its surface the
    sea's or the highest of the held ends' heights ``held`` (the scene's frame); a
    uniform line's surface (its own, or the current's) not below a held end."""
    z0 = float(scene.start_position[2])
    rows = sea.current_rows()
    if rows is None:
        return None
    depths, velocities = rows
    surface = float(max(held) if sea.surface is None else sea.surface - z0)
    if scene.sections:
        section_drag = max(s.drag for s in scene.sections)
        if section_drag == 0:
            raise RodInputError(f"a current on {n['sections']} whose line types have no "
                                "drag: give the line types a cd column")
        # each section's own c (Scene.drag_at); the current carries the largest
        return Current(depths, velocities, surface, section_drag)
    current = Current.morison(depths, velocities, surface, *drag)
    # the loaded line's held ends (a free end is not one)
    check_uniform_line_under_surface(
        sea, [state.position[2] for state in (scene.start_state(1.0), scene.end_state(1.0))
              if is_held(state)], z0, n)
    return current


def check_uniform_line_under_surface(sea, held, z0, n):
    """Refuse a sea surface below a held end of a uniform line: the part above it would
    keep the submerged weight and the current's drag it has not in the air, and the
    uniform line's load gives no diameter and mass to take them off (a line of sections
    does, physics/surface.py). ``held`` the held ends' heights in the scene's frame,
    ``z0`` the start's height (m)."""
    surface = None if sea.surface is None else sea.surface - z0   # the scene's frame
    if surface is None or not max(held) > surface:
        return
    raise RodInputError(
        f"{n['sea_surface']} {surface + z0:g}: the held end at z = "
        f"{max(held) + z0:g} m is above it, where a line given by {n['load']} would keep "
        f"its submerged weight and the current's drag; give the line as {n['line_types']} "
        f"and {n['sections']} (od and mass: its weight in air and no drag above the "
        "surface), or a surface at or above the held ends")


def seated(seabed, held):
    """``seabed`` lowered by the deepest penetration of the held ends at ``held`` (n, 3),
    m, where one lies below it by round-off (check_ends_above accepts 1e-12 of the
    length): such an end is on the seabed (a seabed at 1e-12 against an anchor at z = 0,
    or 0.1 + 0.2 against 0.3), and an anchor pressed into it by round-off started the
    catenary below the seabed (NaN at the first iteration). The whole seabed, flat or
    shaped, moves down by that round-off."""
    if seabed is None:
        return seabed
    depth = float(np.max(-seabed.gap(np.asarray(held, dtype=float).reshape(-1, 3))))
    if not depth > 0:
        return seabed
    shape = None if seabed.flat else seabed.shape.moved(np.array([0.0, 0.0, depth]))
    return dataclasses.replace(seabed, height=seabed.height - depth, shape=shape)


def check_taut(scene, n):
    """Refuse a loaded inextensible line held at both ends its length apart (Scene.taut):
    it can only be straight, and any tension balances its loads along it, so that the
    tension the iteration would stop at is arbitrary (docs/method.md §5). An unloaded one
    (a straight rod twisted between clamps) is kept: its tension is zero, the limit of a
    stiff extensible rod."""
    if not scene.taut or not scene.loaded:
        return
    chord = np.linalg.norm(scene.end_position - scene.start_state(1.0).position)
    raise RodInputError(
        f"{n['end_position']}: the held ends are {chord:.15g} m apart, the line's length "
        f"{scene.length:.15g} m: an inextensible line held taut is straight and any "
        "tension balances its loads, so its tension is undetermined; give "
        f"{line_names(scene.sections, n)['stretch']} to model the stretch, or bring the "
        "ends closer")


def rounded_down(value, digits=3):
    """``value`` > 0 rounded down to ``digits`` significant digits, so that the largest
    accepted value a message quotes is itself accepted."""
    unit = 10.0 ** (np.floor(np.log10(value)) - digits + 1)
    return float(np.floor(value / unit) * unit)


def check_seabed_stiffness(scene, sea, n):
    """Refuse a seabed stiffer than environment.largest_stiffness (given, or the default
    w / 1 mm of a long line), naming the field and the largest stiffness accepted."""
    if scene.seabed is None:
        return
    force = scene.applied_force()
    largest = min(largest_stiffness(force, scene.length), MAX_MAGNITUDE)
    k = scene.seabed.stiffness
    if k <= largest:
        return
    largest = rounded_down(largest)
    why = (f"the largest accepted is {largest:.3g} N/m^2, under which the line's mean load "
           f"{force / scene.length:.3g} N/m sinks {MIN_RELATIVE_PENETRATION:g} of the length "
           "(near the round-off of a height: a stiffer seabed changes nothing but the "
           "conditioning of the vertical problem)")
    if sea.seabed_stiffness is not None:
        raise RodInputError(f"{n['seabed_stiffness']} {k:g}: {why}; use "
                            f"{n['seabed_stiffness']} {largest:.3g} or less")
    raise RodInputError(f"{line_names(scene.sections, n)['load']}: the default "
                        f"{n['seabed_stiffness']} (weight / 1 mm) is "
                        f"{k:.3g} N/m^2, above what this line accepts: {why}; give "
                        f"{n['seabed_stiffness']} {largest:.3g} or less")


def check_applied_forces(scene, sea, n):
    """Refuse a force the model derives beyond MAX_MAGNITUDE (the bound of its numbers):
    the drag coefficient c = rho C_d D / 2, the largest drag c max |v|^2 (N/m) and the
    total applied force F = int |f| dS + |P_0| + |P_L| + L c max |v|^2 (N,
    Scene.applied_forces), naming the field behind the largest part."""
    names = line_names(scene.sections, n)
    current = n["current_profile"] if sea.profile() is not None else n["current"]
    if scene.current is not None:
        if scene.current.drag > MAX_MAGNITUDE:
            raise RodInputError(
                f"{names['drag']}: c = rho Cd D / 2 = {scene.current.drag:.3g} kg/m^2 is "
                f"above {MAX_MAGNITUDE:g}; give rho in kg/m^3 and D in m")
        drag = scene.current.largest_drag()
        if drag > MAX_MAGNITUDE:
            raise RodInputError(
                f"{current} with {names['drag']}: the largest drag c max |v|^2 = "
                f"{drag:.3g} N/m is above {MAX_MAGNITUDE:g}; give the current in m/s")
    parts = scene.applied_forces()
    total = sum(parts.values())
    if total > MAX_MAGNITUDE:
        name = max(parts, key=parts.get)
        points = (n["point_loads"] if n["point_loads"] == n["point_load"]
                  else f"{n['point_loads']}|{n['point_load']}")
        option = {"load": f"{names['load']} (with {names['length']})",
                  "start_force": n["start_force"], "point_loads": points,
                  "end_force": n["end_force"],
                  "drag": f"{current} with {names['drag']} and {names['length']}"}[name]
        raise RodInputError(
            f"{option}: the applied force (int |f| dS + the end forces + the drag) is "
            f"{total:.3g} N, above {MAX_MAGNITUDE:g}; give loads in N/m, forces in N and "
            "lengths in m")


# The largest strain eps = |n| / EA that an extensible line may need (docs/method.md
# §12): beyond it the linear stretch r' = (1 + eps) d3, energy EA eps^2 / 2, models no
# line material.
MAX_STRAIN = 1.0


def least_top_strain(scene):
    """The least strain at the higher held end in any equilibrium in tension (T >= 0 at
    its lowest point) of a uniform extensible flexible line (a bending stiffness's shear moves it a little: about, for
    a rod) under a uniform dead load w (N/m of unstretched line), its held ends h apart
    along the load (m), or None where it does not apply (sections,
    a free end, attachments, load pieces that differ, a seabed that is not flat or not
    across the load). Along the suspended line d(T + T^2 / 2EA) = w dz (the cable's
    balance along its tangent; a current's normal drag has no part along it), from the
    lowest point (a touchdown, or below the lower end) to the top, T >= 0 there:
    eps >= sqrt(1 + 2 w h / EA) - 1. Returns (eps, w h)."""
    if (scene.sections or not np.isfinite(scene.axial_stiffness) or scene.start == "free"
            or scene.end == "free" or scene.point_load_S.size):
        return None
    loads = scene.load_values
    weight = float(np.linalg.norm(loads[0]))
    if weight == 0.0 or not np.all(loads == loads[0]):
        return None
    down = loads[0] / weight
    if scene.seabed is not None and not (scene.seabed.flat and down[2] == -1.0):
        return None
    height = abs(float((scene.end_position - scene.start_state(1.0).position) @ down))
    return (float(np.sqrt(1.0 + 2.0 * weight * height / scene.axial_stiffness) - 1.0),
            weight * height)


def check_stretch_domain(scene, n=FIELD_NAMES):
    """Refuse a uniform extensible line that every equilibrium stretches by more than
    MAX_STRAIN at its top (least_top_strain), outside the domain of the model of
    stretch; the message names the EA as ``n`` does (model/names.py)."""
    least = least_top_strain(scene)
    if least is not None and least[0] > MAX_STRAIN:
        raise RodInputError(
            f"{n['axial_stiffness']} {scene.axial_stiffness:g}: hanging in tension it stretches the "
            f"line by about {100 * least[0]:.3g} % or more at its top (a flexible cable's "
            f"T + T^2/2EA >= w h, w h = {least[1]:.3g} N: the load times the ends' height "
            f"apart), above {100 * MAX_STRAIN:g} %, where the linear stretch models no line "
            "material; check EA (in N), or leave the line inextensible")
