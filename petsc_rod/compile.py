"""The Scene the solver takes, compiled from a Model (petsc_rod/model): the line's
sections or its uniform values, the ends in the solver's frame (its origin at the
start, docs/method.md §5), the attachments' forces, the seabed (its shape, default
stiffness and friction), the current and the pipe's pressures, each resolved here and
given to the Scene's constructor. Model.check refuses a bad model before (the loads it
derives: model/derived.py); what stays here needs the compiled seabed's geometry
(environment/bathymetry.py, which the model does not import): a grid's axes, the
profile or grid under the held ends and the held ends on or above the seabed.

    Model --compile_scene--> Scene --RodProblem--> problem --UzawaSolver--> solution
"""

import dataclasses

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.model.attachment import attachment_columns, dead_forces
from petsc_rod.model.names import FIELD_NAMES
from petsc_rod.environment.bathymetry import Grid, Plane, Profile
from petsc_rod.environment.current import Current
from petsc_rod.environment.profiles import grid_axes
from petsc_rod.environment.seabed import (Friction, Seabed, check_covered,
                                          check_ends_above, default_stiffness)
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


def seabed_shape(sea, height, origin, n):
    """The bathymetry.Plane, Profile or Grid of the sea's seabed in the scene's frame (its
    origin at ``origin`` (3,), absolute), or None for a flat seabed (no slope, or a
    slope of 0: the plane z = ``height``, bit for bit); ``height`` the seabed's absolute
    height."""
    direction = sea.seabed_unit_direction()
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
    if stiffness is None:       # some load points down (model/derived.py)
        stiffness = default_stiffness(load_values)
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
    sea's or the highest of the held ends' heights ``held`` (the scene's frame)."""
    z0 = float(scene.start_position[2])
    rows = sea.current_rows()
    if rows is None:
        return None
    depths, velocities = rows
    surface = float(max(held) if sea.surface is None else sea.surface - z0)
    if scene.sections:
        # each section's own c (Scene.drag_at); the current carries the largest
        return Current(depths, velocities, surface, max(s.drag for s in scene.sections))
    return Current.morison(depths, velocities, surface, *drag)


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
