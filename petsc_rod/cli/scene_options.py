"""The scene, the sea and the iteration's settings from the parsed -rod_* options
(options.py): the one place where option values become the objects the numerical code
takes (Scene, Seabed, Current, Settings), with the checks that need several options."""

import dataclasses

import numpy as np

from petsc_rod.cli.options import MAX_MAGNITUDE, OPTIONS
from petsc_rod.environment.bathymetry import Grid, Plane, Profile
from petsc_rod.environment.current import Current
from petsc_rod.environment.profiles import grid_axes, read_profile, read_seabed_profile
from petsc_rod.environment.seabed import (MIN_RELATIVE_PENETRATION, Friction, Seabed,
                                          check_covered, check_ends_above,
                                          default_stiffness, largest_stiffness)
from petsc_rod.errors import RodInputError
from petsc_rod.iteration.stopping import Settings
from petsc_rod.mesh.mesh import MIN_RELATIVE_ELEMENT, Pieces
from petsc_rod.problem.penalty import penalty_scales
from petsc_rod.scenes import starts
from petsc_rod.scenes.blend import FIXED_FIELDS, PATH_FIELDS, BlendedPath, differences
from petsc_rod.scenes.boundary import is_held
from petsc_rod.scenes.line import (LINE_TYPE_COLUMNS, LINE_TYPE_OPTIONAL, line_types_from_table,
                                   parse_sections, section_elements)
from petsc_rod.scenes.point_loads import quick_point_loads, read_point_loads
from petsc_rod.scenes.scene import REFERENCE_FRAME, Scene
from petsc_rod.tables import read_table

# The options behind each Scene field a restart compares (scenes/blend.py).
FIELD_OPTIONS = {"load_values": "-rod_load", "load_breaks": "-rod_load_breaks",
                 "start_force": "-rod_start_force", "end_force": "-rod_end_force",
                 "end_position": "-rod_end_position", "end_frame": "-rod_end_frame",
                 "start_frame": "-rod_start_frame",
                 "end_twist": "-rod_end_twist",
                 "current": ("the current (-rod_current|-rod_current_profile, -rod_sea_surface, "
                             "-rod_drag)"),
                 "stiffness": "-rod_stiffness", "start": "-rod_start", "end": "-rod_end",
                 "seabed": "-rod_seabed", "sections": "-rod_line_types/-rod_sections",
                 "axial_stiffness": "-rod_axial_stiffness",
                 **{f"{which}_{name}": f"-rod_{which}_{name}" for which in ("start", "end")
                    for name in ("rotational_stiffness", "joint_axis")},
                 "point_load_S": "the point loads (-rod_point_loads|-rod_point_load)",
                 "point_load_forces": ("the point loads (-rod_point_loads|-rod_point_load, "
                                       "-rod_water_density, -rod_gravity)"),
                 "point_load_drag_areas": "the attachments' drag areas (-rod_point_loads)",
                 "point_load_volumes": "the attachments' volumes (-rod_point_loads)"}


def point_loads_from_options(values, length, points=None):
    """(S (n_p,), forces (n_p, 3), names, drag areas (n_p,), volumes (n_p,)) of
    -rod_point_loads FILE and -rod_point_load (scenes/point_loads.py), the file's first,
    each on the line [0, ``length``]; ``points`` (S, forces, drag areas, volumes) when
    already resolved (a result file's point_loads_table)."""
    if points is not None:
        S, forces, areas, volumes = points
        return S, forces, tuple(f"point {k + 1}" for k in range(len(S))), areas, volumes
    parts = []
    if values["rod_point_loads"]:
        parts.append(read_point_loads(values["rod_point_loads"], values["rod_water_density"],
                                      values["rod_gravity"], length, MAX_MAGNITUDE))
    if values["rod_point_load"] is not None:
        parts.append(quick_point_loads(values["rod_point_load"], length))
    if not parts:
        return np.zeros(0), np.zeros((0, 3)), (), np.zeros(0), np.zeros(0)
    S, forces, _, areas, volumes = (np.concatenate([p[k] for p in parts])
                                    for k in range(5))
    return S, forces, sum((tuple(p[2]) for p in parts), ()), areas, volumes


def scene_from_options(values, given, profile=None, line_types=None, points=None,
                       seabed_rows=None):
    """A validated Scene from parsed option values; ``profile`` (depths, velocities) the
    rows of -rod_current_profile when already read (a result file's
    current_profile_table), else they are read from its file; ``line_types`` the text of
    the -rod_line_types table when already read (a result file's line_types_table);
    ``points`` (S, forces, drag areas, volumes) the point loads when already resolved (a result
    file's point_loads_table); ``seabed_rows`` (n, 2 or 3) the seabed profile's or grid's
    rows when already read (a result file's seabed_profile_table)."""
    load = np.asarray(values["rod_load"])
    if load.size % 3:
        raise RodInputError("-rod_load: give 3 values (fx,fy,fz) per load piece")
    line = dict(length=values["rod_length"], stiffness=values["rod_stiffness"],
                load_values=load.reshape(-1, 3), load_breaks=values["rod_load_breaks"])
    sections = sections_from_options(values, given, line_types)
    if sections:
        line = dict(length=sections[-1].end, stiffness=sections[0].stiffness_start,
                    load_values=[s.weight for s in sections],
                    load_breaks=[s.start for s in sections[1:]], sections=tuple(sections))
    point_S, point_forces, point_names, point_areas, point_volumes = point_loads_from_options(
        values, line["length"], points)
    if not (sections or point_S.size):
        for name in ("rod_water_density", "rod_gravity"):
            if name in given:
                raise RodInputError(f"-{name} needs -rod_sections or attachments "
                                    "(-rod_point_loads): the uniform line takes -rod_load")
    origin = np.asarray(values["rod_start_position"], dtype=float)
    end = values["rod_end_position"]
    scene = Scene(**line, start=values["rod_start"], end=values["rod_end"],
                  start_position=origin,
                  end_position=None if end is None else np.asarray(end) - origin,
                  end_frame=values["rod_end_frame"], start_frame=values["rod_start_frame"],
                  end_twist=values["rod_end_twist"], start_force=values["rod_start_force"],
                  end_force=values["rod_end_force"],
                  axial_stiffness=values["rod_axial_stiffness"],
                  start_rotational_stiffness=values["rod_start_rotational_stiffness"],
                  end_rotational_stiffness=values["rod_end_rotational_stiffness"],
                  start_joint_axis=values["rod_start_joint_axis"],
                  end_joint_axis=values["rod_end_joint_axis"], point_load_S=point_S,
                  point_load_forces=point_forces, point_load_names=point_names,
                  point_load_drag_areas=point_areas, point_load_volumes=point_volumes,
                  water_density=values["rod_water_density"], gravity=values["rod_gravity"])
    scene.validate(given)
    scene.seabed, scene.current = environment_from_options(values, given, scene, profile,
                                                           seabed_rows)
    pressures_from_options(values, given, scene)
    check_taut(scene)
    check_applied_forces(scene, given)
    check_seabed_stiffness(scene, given)
    return scene


# Options the sections replace, and what gives the value instead.
SECTION_REPLACES = {"rod_stiffness": "the line types' ei and gj",
                    "rod_load": "the line types' mass and od (the submerged weight)",
                    "rod_load_breaks": "the section ends",
                    "rod_drag": "the line types' cd and drag_d",
                    "rod_axial_stiffness": "the line types' ea",
                    "rod_mesh_grading": "the element counts of -rod_sections (each "
                                        "section is meshed uniformly)"}


def sections_from_options(values, given, content=None):
    """The line's Sections (scenes/line.py) from -rod_line_types (its table's text
    ``content`` when already read) and -rod_sections, or [] when neither is given;
    RodInputError for one without the other, an unknown type, a length that disagrees
    with -rod_length, or an option the sections replace."""
    if "rod_sections" not in given:
        if "rod_line_types" in given:
            raise RodInputError("-rod_line_types needs -rod_sections TYPE:LENGTH[:ELEMENTS],"
                                "... (the line from S = 0 as sections of those types)")
        return []
    if "rod_line_types" not in given:
        raise RodInputError("-rod_sections needs -rod_line_types FILE (the table of the "
                            "line types it names)")
    for name, instead in SECTION_REPLACES.items():
        if name in given:
            raise RodInputError(f"-{name} with -rod_sections: {instead} give it; drop -{name}")
    path = values["rod_line_types"]
    types = line_types_from_table(
        read_table(path, "-rod_line_types", LINE_TYPE_COLUMNS, LINE_TYPE_OPTIONAL,
                   content=content),
        f"-rod_line_types {path}", MAX_MAGNITUDE)
    entries = parse_sections(values["rod_sections"], "-rod_sections")
    for name, _, _ in entries:
        if name not in types:
            raise RodInputError(f"-rod_sections: unknown line type '{name}'; "
                                f"-rod_line_types {path} has {', '.join(types)}")
    ends = np.concatenate([[0.0], np.cumsum([length for _, length, _ in entries])])
    if "rod_length" in given and abs(ends[-1] - values["rod_length"]) > 1e-9 * ends[-1]:
        raise RodInputError(
            f"-rod_sections add up to {ends[-1]:.15g} m, -rod_length is "
            f"{values['rod_length']:.15g} m; the sections set the length: drop -rod_length "
            "or correct a section")
    rho, g = values["rod_water_density"], values["rod_gravity"]
    return [types[name].section(ends[k], ends[k + 1], rho, g)
            for k, (name, _, _) in enumerate(entries)]


def mesh_pieces(values, scene, given=()):
    """The uniform pieces (mesh.Pieces) of a line of sections, every section end a
    vertex, with the element counts -rod_sections gives and the rest of -rod_elements
    shared out by length; None for a line without sections. A -rod_elements (in
    ``given``) that disagrees with counts given for every section is refused, and so is
    an element too small for double precision (mesh.MIN_RELATIVE_ELEMENT)."""
    if not scene.sections:
        return None
    entries = parse_sections(values["rod_sections"], "-rod_sections")
    counts = [count for _, _, count in entries]
    if "rod_elements" in given and all(c is not None for c in counts) \
            and sum(counts) != values["rod_elements"]:
        raise RodInputError(
            f"-rod_elements {values['rod_elements']}: -rod_sections gives every section "
            f"its elements, {sum(counts)} in all; drop -rod_elements or a section's count")
    lengths = np.array([length for _, length, _ in entries])
    shared = np.array([c is None for c in counts])
    given_counts = int(sum(c for c in counts if c is not None))
    counts = section_elements(lengths, counts, values["rod_elements"])
    if "rod_elements" in given and np.any(shared) and counts.sum() != values["rod_elements"]:
        raise RodInputError(
            f"-rod_elements {values['rod_elements']}: -rod_sections gives {given_counts} "
            f"elements to the sections with a count and needs at least one for each of the "
            f"{int(shared.sum())} without, {int(counts.sum())} in all; give -rod_elements "
            f"{int(counts.sum())} or more")
    check_represented(entries, lengths, counts, shared, given_counts, scene.length,
                      f"-rod_elements {values['rod_elements']}" if "rod_elements" in given
                      else f"-rod_sections (the default -rod_elements {values['rod_elements']})")
    ends = [scene.sections[0].start] + [section.end for section in scene.sections]
    smallest = float(np.min(np.diff(ends) / counts))
    if not smallest >= MIN_RELATIVE_ELEMENT * scene.length:
        raise RodInputError(
            f"-rod_sections: an element of {smallest:.3g} m is {smallest / scene.length:.2g} "
            f"of the length, below what double precision resolves ({MIN_RELATIVE_ELEMENT:g}); "
            "lengthen the shortest section or give it fewer elements")
    return Pieces(ends, counts)


# The fewest elements a line of sections is meshed with along its length: an element
# longer than the length over this is a chord across a quarter of the line or more,
# which cannot represent the shape of a line of several sections (a 2300 m section of
# one element). A uniform line keeps any count: 2 elements of the P2 rod converge at the
# mesh's order (docs/stability.md, group mesh).
MIN_LINE_ELEMENTS = 4


def check_represented(entries, lengths, counts, shared, given_counts, length, sharing):
    """Refuse a section whose elements (``counts`` of ``entries``, ``shared`` those
    without their own count) are longer than length / MIN_LINE_ELEMENTS, saying what
    mesh is needed: the section's own count, or the -rod_elements that shares enough
    out to those without one (``sharing``: how the message names what shared them)."""
    element = lengths / counts
    coarse = np.flatnonzero(element > length / MIN_LINE_ELEMENTS)
    if not coarse.size:
        return
    k = int(coarse[0])
    name, section = entries[k][0], lengths[k]
    what = (f"section {k + 1} ({name}, {section:g} m) has {int(counts[k])} element(s) of "
            f"{element[k]:.4g} m, longer than 1/{MIN_LINE_ELEMENTS} of the line "
            f"({length:g} m): a mesh that coarse cannot represent the line's shape")
    needed = int(np.ceil(MIN_LINE_ELEMENTS * section / length))
    if not shared[k]:
        raise RodInputError(f"-rod_sections: {what}; give it at least {needed} elements "
                            f"({name}:{section:g}:{needed})")
    total = given_counts + int(np.ceil(MIN_LINE_ELEMENTS * lengths[shared].sum() / length)
                               ) + int(shared.sum())
    raise RodInputError(f"{sharing}: {what}; give -rod_elements {total} or more (or the "
                        f"section its own count, {name}:{section:g}:{needed})")


def pressures_from_options(values, given, scene):
    """Set the scene's sea surface (in its frame), contents density, internal
    pressure (quantities/pressures.py) and design factor (quantities/stresses.py) for a line of
    sections; refuse them on a line without
    line types (no diameters to press on)."""
    if not scene.sections:
        for name in ("rod_contents_density", "rod_internal_pressure",
                     "rod_design_factor"):
            if name in given:
                raise RodInputError(f"-{name} needs -rod_sections (the line types' od and "
                                    "id give the pipe it applies to)")
        return
    check_partners(given, scene.sections)
    surface = values["rod_sea_surface"]
    if surface is not None:
        scene.sea_surface = float(surface - scene.start_position[2])
    scene.contents_density = float(values["rod_contents_density"])
    scene.internal_pressure = float(values["rod_internal_pressure"])
    scene.design_factor = float(values["rod_design_factor"])


def check_partners(given, sections):
    """Refuse a pipe setting that does nothing without its partner in the line types:
    -rod_internal_pressure and -rod_contents_density act on the bore (no type with an
    id > 0: no bore), -rod_design_factor scales the yield stress (no type with smys: no
    utilisation)."""
    bore = any(section.id > 0 for section in sections)
    yield_stress = any(np.isfinite(section.smys) for section in sections)
    for name, present, partner in (
            ("rod_internal_pressure", bore, "an id column (the bore it acts on)"),
            ("rod_contents_density", bore, "an id column (the bore the contents fill)"),
            ("rod_design_factor", yield_stress,
             "an smys column (the yield stress it scales into the allowable stress)")):
        if name in given and not present:
            raise RodInputError(f"-{name} needs a line type with {partner}: no line type "
                                "of -rod_sections has one; give it in -rod_line_types, or "
                                f"drop -{name}")


def line_names(sections):
    """How a message names what gives the line's load, stiffness, stretch, drag and
    length: the options of a uniform line, or what the line types give in their place
    (SECTION_REPLACES: those options are refused beside -rod_sections)."""
    if sections:
        return dict(load="the line types' weight (mass and od in -rod_line_types)",
                    stiffness="the line types' ei and gj (-rod_line_types)",
                    stretch="the line types an ea column (EA, N)",
                    drag="the line types' cd and drag_d (-rod_line_types)",
                    length="-rod_sections")
    return dict(load="-rod_load", stiffness="-rod_stiffness", stretch="-rod_axial_stiffness EA",
                drag="-rod_drag", length="-rod_length")


def check_taut(scene):
    """Refuse a loaded inextensible line held at both ends its length apart (Scene.taut):
    it can only be straight, and any tension balances its loads along it, so that the
    tension the iteration would stop at is arbitrary (docs/method.md §5). An unloaded one
    (a straight rod twisted between clamps) is kept: its tension is zero, the limit of a
    stiff extensible rod."""
    if not scene.taut or not scene.loaded:
        return
    chord = np.linalg.norm(scene.end_position - scene.start_state(1.0).position)
    raise RodInputError(
        f"-rod_end_position: the held ends are {chord:.15g} m apart, the line's length "
        f"{scene.length:.15g} m: an inextensible line held taut is straight and any "
        "tension balances its loads, so its tension is undetermined; give "
        f"{line_names(scene.sections)['stretch']} to model the stretch, or bring the ends "
        "closer")


def check_seabed_stiffness(scene, given):
    """Refuse a seabed stiffer than environment.largest_stiffness (given, or the default
    w / 1 mm of a long line), naming the option and the largest stiffness accepted."""
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
    if "rod_seabed_stiffness" in given:
        raise RodInputError(f"-rod_seabed_stiffness {k:g}: {why}; use "
                            f"-rod_seabed_stiffness {largest:.3g} or less")
    raise RodInputError(f"{line_names(scene.sections)['load']}: the default "
                        f"-rod_seabed_stiffness (weight / 1 mm) is "
                        f"{k:.3g} N/m^2, above what this line accepts: {why}; give "
                        f"-rod_seabed_stiffness {largest:.3g} or less")


def rounded_down(value, digits=3):
    """``value`` > 0 rounded down to ``digits`` significant digits, so that the largest
    accepted value a message quotes is itself accepted."""
    unit = 10.0 ** (np.floor(np.log10(value)) - digits + 1)
    return float(np.floor(value / unit) * unit)


def _current_option(given):
    return "-rod_current_profile" if "rod_current_profile" in given else "-rod_current"


def check_applied_forces(scene, given):
    """Refuse a force the accepted options derive beyond MAX_MAGNITUDE (the bound of the
    options themselves): the drag coefficient c = rho C_d D / 2, the largest drag
    c max |v|^2 (N/m) and the total applied force F = int |f| dS + |P_0| + |P_L| + L c
    max |v|^2 (N, Scene.applied_forces), naming the option behind the largest part."""
    names = line_names(scene.sections)
    if scene.current is not None:
        if scene.current.drag > MAX_MAGNITUDE:
            raise RodInputError(
                f"{names['drag']}: c = rho Cd D / 2 = {scene.current.drag:.3g} kg/m^2 is "
                f"above {MAX_MAGNITUDE:g}; give rho in kg/m^3 and D in m")
        drag = scene.current.largest_drag()
        if drag > MAX_MAGNITUDE:
            raise RodInputError(
                f"{_current_option(given)} with {names['drag']}: the largest drag c max "
                f"|v|^2 = "
                f"{drag:.3g} N/m is above {MAX_MAGNITUDE:g}; give the current in m/s")
    parts = scene.applied_forces()
    total = sum(parts.values())
    if total > MAX_MAGNITUDE:
        name = max(parts, key=parts.get)
        option = {"load": f"{names['load']} (with {names['length']})",
                  "start_force": "-rod_start_force",
                  "point_loads": "-rod_point_loads|-rod_point_load",
                  "end_force": "-rod_end_force",
                  "drag": f"{_current_option(given)} with {names['drag']} and "
                          f"{names['length']}"}[name]
        raise RodInputError(
            f"{option}: the applied force (int |f| dS + the end forces + the drag) is "
            f"{total:.3g} N, above {MAX_MAGNITUDE:g}; give loads in N/m, forces in N and "
            "lengths in m")


def settings_from_options(values, scene):
    """The iteration's Settings of the options; a line stretched beyond the model of
    stretch is refused (check_stretch_domain)."""
    check_stretch_domain(scene)
    penalty = values["rod_al_penalty"]
    if penalty is None:
        penalty = checked_default_penalty(scene, start_tension(values, scene))
    return Settings(asked_penalty=penalty, max_it=values["rod_al_max_it"],
                    rtol=values["rod_al_rtol"], ctol=values["rod_al_ctol"],
                    monitor=values["rod_al_monitor"],
                    adapt_penalty=values["rod_al_adapt_penalty"],
                    check_stability=values["rod_al_stability"],
                    newton=values["rod_al_newton"])


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


def check_stretch_domain(scene):
    """Refuse a uniform extensible line that every equilibrium stretches by more than
    MAX_STRAIN at its top (least_top_strain), outside the domain of the model of
    stretch."""
    least = least_top_strain(scene)
    if least is not None and least[0] > MAX_STRAIN:
        raise RodInputError(
            f"-rod_axial_stiffness {scene.axial_stiffness:g}: hanging in tension it stretches the "
            f"line by about {100 * least[0]:.3g} % or more at its top (a flexible cable's "
            f"T + T^2/2EA >= w h, w h = {least[1]:.3g} N: the load times the ends' height "
            f"apart), above {100 * MAX_STRAIN:g} %, where the linear stretch models no line "
            "material; check EA (in N), or leave the line inextensible")


def check_stability_asked(values, scene, given):
    """Refuse -rod_al_stability 1, given, with a current or seabed friction: the test of
    the second variation of the energy (docs/method.md §10) needs every load to have an
    energy, and a current's drag (a follower load) has none, nor friction (it
    dissipates); the default (true) is then left out in silence, as documented."""
    if "rod_al_stability" not in given or not values["rod_al_stability"]:
        return
    if scene.current is not None:
        option, load, reason = _current_option(given), "a current", "its drag is a follower load"
    elif scene.seabed is not None and scene.seabed.friction is not None:
        option, load, reason = "-rod_seabed_friction", "friction", "it dissipates"
    else:
        return
    raise RodInputError(f"-rod_al_stability 1 with {option}: the stability test is of the "
                        f"second variation of the energy, and {load} has none ({reason}); "
                        f"drop -rod_al_stability (a run with {load} gives no stability "
                        f"verdict), or test the scene without {load}")


def start_tension(values, scene):
    """The largest tension of the first step's start, N (the default penalty's start
    scale, problem/penalty.py): that of the catenary at the first step's load factor
    1 / -rod_steps where -rod_initial_shape catenary starts it, 0 for the straight start
    and a restart (whose multipliers are the file's). 0 too for a scene without a
    catenary: the start refuses it (cli/main.start_from), after -help has been said."""
    if values["rod_initial_shape"] != "catenary" or values["rod_initial"]:
        return 0.0
    try:
        return starts.largest_tension(scene, 1.0 / values["rod_steps"])
    except RodInputError:
        return 0.0


def checked_default_penalty(scene, start_tension=0.0):
    """default_penalty(scene, start_tension), refused above MAX_MAGNITUDE (the bound of
    -rod_al_penalty) with the options behind the scale that sets it
    (problem/penalty.penalty_scales)."""
    scales = penalty_scales(scene, start_tension)
    name = max(scales, key=scales.get)
    if scales[name] > MAX_MAGNITUDE:
        names = line_names(scene.sections)
        stiffness = names["stiffness"]
        option, formula = {
            "bending": (f"{stiffness} with {names['length']}", "100 sqrt(min K max K) / L^2"),
            "tension": (f"{names['load']}, -rod_start_force, -rod_end_force or the current",
                        "F / 2"),
            "twist": (f"-rod_end_twist (or -rod_end_frame) with {stiffness}",
                      "2 (K3 alpha / L)^2 / min(K1, K2)"),
            "stretch": ("-rod_axial_stiffness with -rod_end_position" if not scene.sections
                        else "the line types' ea with -rod_end_position",
                        "EA (|r_L| - L) / 2L"),
            "start": (f"{names['load']} with -rod_initial_shape catenary",
                      "the catenary start's largest tension")}[name]
        raise RodInputError(
            f"{option}: the default -rod_al_penalty {formula} = {scales[name]:.3g} N is "
            f"above {MAX_MAGNITUDE:g}, beyond what double precision carries through the "
            "solver; check the units (N m^2, m, rad)")
    return scales[name]


# The options that shape the seabed (environment/bathymetry.py, docs/riser.md §1a).
SEABED_SHAPE = ("rod_seabed_slope", "rod_seabed_direction", "rod_seabed_origin",
                "rod_seabed_profile")


def seabed_direction(values):
    """The unit horizontal vector of -rod_seabed_direction (an azimuth in degrees, or a
    vector dx,dy), default +x."""
    given = values["rod_seabed_direction"]
    if given is None:
        return np.array([1.0, 0.0])
    given = np.asarray(given, dtype=float)
    if given.size == 1:
        angle = np.radians(given[0])
        return np.array([np.cos(angle), np.sin(angle)])
    norm = float(np.hypot(*given)) if given.size == 2 else 0.0
    if given.size != 2 or norm == 0:
        raise RodInputError(f"-rod_seabed_direction {','.join(f'{v:g}' for v in given)}: give "
                            "an azimuth in degrees (one number) or a horizontal vector dx,dy "
                            "(two numbers, not both 0)")
    return given / norm


def seabed_shape(values, given, origin, profile_rows=None):
    """The bathymetry.Plane or Profile of the seabed options in the scene's frame (its
    origin at ``origin`` (3,), absolute), or None for a flat seabed (no slope, or a slope
    of 0: today's plane z = -rod_seabed, bit for bit). ``profile_rows`` the profile's or
    grid's rows (n, 2 or 3), heights absolute, when already read (a result file's
    seabed_profile_table)."""
    profile = "rod_seabed_profile" in given or profile_rows is not None
    if profile and ("rod_seabed" in given or "rod_seabed_slope" in given):
        raise RodInputError("-rod_seabed_profile gives the seabed's heights: drop "
                            "-rod_seabed and -rod_seabed_slope, or the profile")
    if not profile and "rod_seabed_slope" not in given:
        for name in ("rod_seabed_direction", "rod_seabed_origin"):
            if name in given:
                raise RodInputError(f"-{name} needs -rod_seabed_slope or -rod_seabed_profile "
                                    "(the flat -rod_seabed has no direction or origin); give "
                                    f"one of them, or drop -{name}")
    direction = seabed_direction(values)
    seabed_origin = np.asarray(values["rod_seabed_origin"] if values["rod_seabed_origin"]
                               is not None else (0.0, 0.0), dtype=float)
    if profile:
        table = np.asarray(profile_rows if profile_rows is not None else
                           read_seabed_profile(values["rod_seabed_profile"], MAX_MAGNITUDE),
                           dtype=float)
        if table.shape[1] == 2:
            return Profile(seabed_origin, direction, table[:, 0], table[:, 1]).moved(origin)
        if "rod_seabed_direction" in given:
            raise RodInputError("-rod_seabed_direction: a grid's rows give x and y (from "
                                "-rod_seabed_origin); drop the direction")
        xs, ys, heights = grid_axes(table, RodInputError)
        return Grid(seabed_origin, xs, ys, heights).moved(origin)
    slope = values["rod_seabed_slope"]
    if slope is None or slope == 0:
        return None
    return Plane.sloping(seabed_origin, values["rod_seabed"], slope,
                         direction).moved(origin)


def seabed_from_options(values, given, load_values, origin=np.zeros(3), profile_rows=None):
    """The Seabed of -rod_seabed (or -rod_seabed_profile), its shape's options and
    -rod_seabed_stiffness, or None; heights in the scene's frame (its origin at
    ``origin`` (3,), absolute; -rod_seabed already less origin[2])."""
    if "rod_seabed" not in given and "rod_seabed_profile" not in given and (
            profile_rows is None):
        for name in ("rod_seabed_stiffness",) + SEABED_SHAPE + SEABED_FRICTION:
            if name in given:
                raise RodInputError(f"-{name} needs -rod_seabed (the seabed's height) or "
                                    "-rod_seabed_profile")
        return None
    stiffness = values["rod_seabed_stiffness"]
    if stiffness is None:
        stiffness = default_stiffness(load_values)
        if stiffness is None:
            load = ("no line type sinks (mass above the water displaced)"
                    if "rod_sections" in given else "no -rod_load points down")
            raise RodInputError(f"-rod_seabed: {load} to set the default stiffness "
                                "(weight / 1 mm); give -rod_seabed_stiffness")
    friction = friction_from_options(values, given, float(stiffness))
    absolute = dict(values)
    if values["rod_seabed"] is not None:
        absolute["rod_seabed"] = values["rod_seabed"] + origin[2]
    shape = seabed_shape(absolute, given, origin, profile_rows)
    if shape is None:
        return Seabed(float(values["rod_seabed"]), float(stiffness), friction=friction)
    return Seabed(float(shape.height(0.0, 0.0)), float(stiffness), shape, friction)


# The default stick stiffness of the friction over the seabed's stiffness: at the default
# seabed stiffness (weight / 1 mm) the weight mobilises the friction over mu x 1 cm, as
# pipe-soil practice has it (a few mm axially, a tenth of a diameter laterally); stiffer
# sticks slowed the iteration down (docs/riser.md §3b).
FRICTION_STIFFNESS_RATIO = 0.1

# The options of the seabed's friction (physics/friction.py, docs/riser.md §3b).
SEABED_FRICTION = ("rod_seabed_friction", "rod_seabed_friction_stiffness")


def friction_from_options(values, given, seabed_stiffness):
    """The environment.Friction of -rod_seabed_friction (one coefficient, or axial and
    lateral) and -rod_seabed_friction_stiffness (default the seabed's ``seabed_stiffness``),
    or None without friction."""
    if "rod_seabed_friction" not in given:
        if "rod_seabed_friction_stiffness" in given:
            raise RodInputError("-rod_seabed_friction_stiffness needs -rod_seabed_friction "
                                "(the friction coefficient)")
        return None
    mu = np.asarray(values["rod_seabed_friction"], dtype=float)
    if mu.size not in (1, 2):
        raise RodInputError(f"-rod_seabed_friction {','.join(f'{v:g}' for v in mu)}: give "
                            "one coefficient mu or two, mu_axial,mu_lateral")
    stiffness = values["rod_seabed_friction_stiffness"]
    if stiffness is None:
        stiffness = FRICTION_STIFFNESS_RATIO * seabed_stiffness
    return Friction(float(mu[0]), float(mu[-1]), float(stiffness))


def current_from_options(values, given, surface_default, profile_rows=None,
                         section_drag=None):
    """The Current of -rod_current or -rod_current_profile with -rod_drag, or None.
    ``surface_default``: the sea surface height when -rod_sea_surface is not given;
    ``profile_rows``: the profile's (depths, velocities) when already read;
    ``section_drag``: for a line of sections, the largest of their drag coefficients
    c (kg/m^2), which the current carries in place of -rod_drag's (the drag term takes
    each section's own, Scene.drag_at)."""
    uniform, profile = "rod_current" in given, "rod_current_profile" in given
    if uniform and profile:
        raise RodInputError("-rod_current and -rod_current_profile both give the current; "
                            "give one of them")
    if not (uniform or profile):
        names = ("rod_drag",) if section_drag is not None else ("rod_drag", "rod_sea_surface")
        for name in names:
            if name in given:
                raise RodInputError(f"-{name} needs a current (-rod_current or "
                                    "-rod_current_profile)")
        return None
    if section_drag is None and "rod_drag" not in given:
        raise RodInputError("a current needs -rod_drag rho,Cd,D (water density kg/m^3, drag "
                            "coefficient, hydrodynamic diameter m)")
    if "rod_sea_surface" in given and not profile and section_drag is None:
        raise RodInputError("-rod_sea_surface needs -rod_current_profile (a uniform "
                            "current does not depend on depth) or -rod_sections (the "
                            "external pressure)")
    if profile and profile_rows is not None:
        depths, velocities = profile_rows
    elif profile:
        depths, velocities = read_profile(values["rod_current_profile"], MAX_MAGNITUDE)
    else:
        depths, velocities = np.zeros(1), np.asarray(values["rod_current"]).reshape(1, 3)
    surface = values["rod_sea_surface"]
    surface = float(surface_default if surface is None else surface)
    if section_drag is not None:
        if section_drag == 0:
            raise RodInputError("a current on -rod_sections whose line types have no drag: "
                                "give the line types a cd column")
        # each section's own c (Scene.drag_at); the current carries the largest
        return Current(depths, velocities, surface, section_drag)
    return Current.morison(depths, velocities, surface, *values["rod_drag"])


def environment_from_options(values, given, scene, profile=None, seabed_rows=None):
    """(Seabed or None, Current or None) for a validated ``scene``, checked against it
    (``profile``: as in current_from_options), their heights in the scene's frame (the
    options' less the start's z, docs/method.md §5); ``seabed_rows`` the seabed
    profile's or grid's rows when already read."""
    z0 = float(scene.start_position[2])
    values = dict(values)
    for name in ("rod_seabed", "rod_sea_surface"):
        if values[name] is not None:
            values[name] = values[name] - z0
    seabed = seabed_from_options(values, given, scene.load_values, scene.start_position,
                                 seabed_rows)
    # a flat seabed: also the unloaded reference's ends (straight along e_x on it); a
    # sloping one crosses that line, so only the loaded ends are held to it
    loads = (0.0, 1.0) if seabed is None or seabed.flat else (1.0,)
    ends = [("-rod_start", scene.start_state(t)) for t in loads]
    ends += [("-rod_end", scene.end_state(t)) for t in loads]
    check_covered(seabed, [state.position for _, state in ends if is_held(state)],
                  "the held ends")
    check_ends_above(seabed, ends, scene.length, z0)
    held = [state.position[2] for _, state in ends if is_held(state)]
    seabed = seated(seabed, [state.position for _, state in ends if is_held(state)])
    section_drag = (max(s.drag for s in scene.sections) if scene.sections else None)
    current = current_from_options(values, given, max(held), profile, section_drag)
    if not scene.sections:          # the loaded line's held ends (a free end is not one)
        check_uniform_line_under_surface(
            values, given, [state.position[2] for state in (scene.start_state(1.0),
                                                            scene.end_state(1.0))
                            if is_held(state)], z0)
    return seabed, current


def check_uniform_line_under_surface(values, given, held, z0):
    """Refuse -rod_sea_surface below a held end of a uniform line (-rod_load): the part
    above it would keep the submerged weight and the current's drag it has not in the
    air, and -rod_load gives no diameter and mass to take them off (a line of sections
    does, physics/surface.py SurfaceTerm). ``held`` the held ends' heights and the surface
    in ``values`` in the scene's frame, ``z0`` the start's height (m)."""
    surface = values["rod_sea_surface"]
    if "rod_sea_surface" not in given or surface is None or not max(held) > surface:
        return
    raise RodInputError(
        f"-rod_sea_surface {surface + z0:g}: the held end at z = {max(held) + z0:g} m is "
        "above it, where a line given by -rod_load would keep its submerged weight and "
        "the current's drag; give the line as -rod_line_types and -rod_sections (od and "
        "mass: its weight in air and no drag above the surface), or a surface at or above "
        "the held ends")


def seated(seabed, held):
    """``seabed`` lowered by the deepest penetration of the held ends at ``held`` (n, 3),
    m, where one lies below it by round-off (check_ends_above accepts 1e-12 of the
    length): such an end is on the seabed (-rod_seabed 1e-12 against an anchor at z = 0,
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


def options_from_parameters(parameters):
    """(values, given) as read_options would return them for the run that wrote a result
    file's ``parameters`` group (io.results.read_parameters): '' is an option not given;
    an option counts as given where its value differs from its default (the end position
    and frame from the ones Scene puts in their place), so that Scene.validate and the
    riser options see the run as it was asked."""
    length = float(parameters.get("length", 1.0))
    origin = parameters.get("start_position", "")
    origin = np.zeros(3) if isinstance(origin, str) else np.asarray(origin, dtype=float)
    defaults = {"rod_end_position": origin + np.array([length, 0.0, 0.0]),
                "rod_end_frame": REFERENCE_FRAME, "rod_start_frame": REFERENCE_FRAME}
    values, given = {}, set()
    for option in OPTIONS:
        value = parameters.get(option.name.removeprefix("rod_"), "")
        if isinstance(value, str) and value == "":
            values[option.name] = option.default
            continue
        values[option.name] = value
        default = defaults.get(option.name, option.default)
        if (default is None or np.size(value) != np.size(default)
                or np.any(np.ravel(value) != np.ravel(default))):
            given.add(option.name)
    return values, given


def scene_from_parameters(parameters):
    """The Scene of the run that wrote a result file's ``parameters`` group, built by
    scene_from_options (its current profile from the file's current_profile_table and
    its line types from line_types_table, not from files that may have changed since)."""
    values, given = options_from_parameters(parameters)
    table = parameters.get("current_profile_table")
    profile = None if table is None else (table[:, 0], table[:, 1:])
    points = parameters.get("point_loads_table")
    if points is not None:
        points = np.asarray(points, dtype=float)
        # 4 columns before drag areas, 5 before volumes
        points = points.reshape(-1, points.shape[-1])
        areas, volumes = (points[:, k] if points.shape[1] > k else np.zeros(len(points))
                          for k in (4, 5))
        points = (points[:, 0], points[:, 1:4], areas, volumes)
    seabed = parameters.get("seabed_profile_table")
    return scene_from_options(values, given, profile, parameters.get("line_types_table"),
                              points, seabed)


def restart_path(scene, parameters, t_file):
    """The scene a restart's load path walks: ``scene`` itself (the path goes on from the
    file's load factor t_file) when the file's scene, rebuilt from its ``parameters``,
    carries the same load path, or t_file = 0 (both paths start from the same unloaded
    reference: this scene's own path is the walk); else the BlendedPath from the file's
    scene at t_file to ``scene`` at 1 (scenes/blend.py). Returns (that scene, the options
    whose load-path values differ, the options taken from ``scene`` from the first
    step)."""
    old = scene_from_parameters(parameters)
    walked = [FIELD_OPTIONS[name] for name in differences(old, scene, PATH_FIELDS)]
    fixed = [FIELD_OPTIONS[name] for name in differences(old, scene, FIXED_FIELDS)]
    # at t = 0 every scene is the unloaded reference; another length is another mesh,
    # which read_restart refuses
    if not walked or t_file == 0 or old.length != scene.length:
        return scene, [], fixed
    return BlendedPath(old, t_file, scene), walked, fixed
