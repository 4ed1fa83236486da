"""The command line's options as a Model (petsc_rod/model), and the Scene compiled from
it (compile.py): the one place where -rod_* option values (options.py) become the
model, with the files they name read here (line types, attachments, the seabed's and the
current's profiles) and the checks of options that go together (an option of the
uniform line beside -rod_sections, a table without its partner); the model's own checks
(Model.check) and the compile's name the options (OPTION_NAMES). Also the iteration's
settings from the options."""

import numpy as np

from petsc_rod.cli.options import OPTIONS
from petsc_rod.errors import RodInputError
from petsc_rod.iteration.stopping import Settings
from petsc_rod.mesh.mesh import MIN_RELATIVE_ELEMENT, Pieces
from petsc_rod.model import (Attachment, End, Environment, Line, Model, UniformLine,
                             line_types_from_table)
from petsc_rod.model.line import element_counts
from petsc_rod.model.line_type import LINE_TYPE_COLUMNS, LINE_TYPE_OPTIONAL
from petsc_rod.model.names import Names
from petsc_rod.model.values import MAX_MAGNITUDE
from petsc_rod.problem.penalty import penalty_scales
from petsc_rod.compile import compile_scene
from petsc_rod.model.derived import line_names, rounded_down  # noqa: F401
from petsc_rod.environment.profiles import read_profile, read_seabed_profile
from petsc_rod.scenes import starts
from petsc_rod.scenes.blend import FIXED_FIELDS, PATH_FIELDS, BlendedPath, differences
from petsc_rod.scenes.line import parse_sections
from petsc_rod.scenes.point_loads import quick_point_loads, read_attachments
from petsc_rod.scenes.scene import REFERENCE_FRAME
from petsc_rod.tables import read_table

# How the model's checks name its fields on the command line: their options.
OPTION_NAMES = Names({}, lambda key: f"-rod_{key}")

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


def attachments_from_options(values, length, points=None):
    """The Attachments of -rod_point_loads FILE and -rod_point_load (scenes/
    point_loads.py), the file's first, each on the line [0, ``length``]; ``points`` (S,
    forces, drag areas, volumes) when already resolved (a result file's
    point_loads_table: weighed attachments)."""
    if points is not None:
        S, forces, areas, volumes = points
        return tuple(Attachment(S[k], volume=volumes[k], force=tuple(forces[k]), cda=areas[k],
                                name=f"point {k + 1}", weighed=True) for k in range(len(S)))
    attachments = ()
    if values["rod_point_loads"]:
        attachments += read_attachments(values["rod_point_loads"], length, MAX_MAGNITUDE)
    if values["rod_point_load"] is not None:
        attachments += quick_point_loads(values["rod_point_load"], length)
    return attachments


def given_value(values, given, name):
    """The value of option ``name`` where the user gave it, else None."""
    return values[name] if name in given else None


def model_from_options(values, given, profile=None, line_types=None, points=None,
                       seabed_rows=None):
    """The Model of parsed option values (``given`` the names the user set: a field of
    an option not given is None, the model's default); ``profile`` (depths, velocities)
    the rows of -rod_current_profile when already read (a result file's
    current_profile_table), else they are read from its file; ``line_types`` the text of
    the -rod_line_types table when already read (a result file's line_types_table);
    ``points`` (S, forces, drag areas, volumes) the point loads when already resolved (a result
    file's point_loads_table); ``seabed_rows`` (n, 2 or 3) the seabed profile's or grid's
    rows when already read (a result file's seabed_profile_table)."""
    load = np.asarray(values["rod_load"])
    if load.size % 3:
        raise RodInputError("-rod_load: give 3 values (fx,fy,fz) per load piece")
    line = line_from_options(values, given, line_types)
    if line is None:
        line = UniformLine(length=values["rod_length"], stiffness=values["rod_stiffness"],
                           load=load.reshape(-1, 3), load_breaks=values["rod_load_breaks"],
                           axial_stiffness=values["rod_axial_stiffness"],
                           drag=given_value(values, given, "rod_drag"),
                           elements=values["rod_elements"],
                           grading=values["rod_mesh_grading"])
        for name in ("rod_contents_density", "rod_internal_pressure", "rod_design_factor"):
            if name in given:
                raise RodInputError(f"-{name} needs -rod_sections (the line types' od and "
                                    "id give the pipe it applies to)")
    attachments = attachments_from_options(values, line.length, points)
    if not (isinstance(line, Line) or attachments):
        for name in ("rod_water_density", "rod_gravity"):
            if name in given:
                raise RodInputError(f"-{name} needs -rod_sections or attachments "
                                    "(-rod_point_loads): the uniform line takes -rod_load")
    start, end = (End(values[f"rod_{which}"],
                      given_value(values, given, f"rod_{which}_position"),
                      given_value(values, given, f"rod_{which}_rotational_stiffness"),
                      given_value(values, given, f"rod_{which}_joint_axis"),
                      given_value(values, given, f"rod_{which}_force"),
                      given_value(values, given, f"rod_{which}_frame"),
                      given_value(values, given, f"rod_{which}_twist") if which == "end"
                      else None)
                  for which in ("start", "end"))
    return Model(line, start, end,
                 environment_from_options(values, given, profile, seabed_rows), attachments)


def current_from_options(values, given, profile=None):
    """Environment.current of -rod_current (ux,uy,uz, m/s) or of -rod_current_profile's
    rows (depth m, ux, uy, uz m/s; ``profile`` (depths, velocities) when already read),
    None where neither is given; RodInputError where both are (a line's and a system's
    sea alike: cli_system.in_current)."""
    if "rod_current" in given and "rod_current_profile" in given:
        raise RodInputError("-rod_current and -rod_current_profile both give the current; "
                            "give one of them")
    if "rod_current_profile" in given:
        depths, velocities = (profile if profile is not None else
                              read_profile(values["rod_current_profile"], MAX_MAGNITUDE))
        return np.column_stack([depths, velocities])
    return given_value(values, given, "rod_current")


def environment_from_options(values, given, profile=None, seabed_rows=None):
    """The Environment of the sea's options (model_from_options: ``profile`` and
    ``seabed_rows`` the current's and the seabed's rows when already read)."""
    current = current_from_options(values, given, profile)
    seabed_profile = seabed_rows
    if seabed_profile is None and "rod_seabed_profile" in given:
        seabed_profile = read_seabed_profile(values["rod_seabed_profile"], MAX_MAGNITUDE)
    fields = {name: given_value(values, given, f"rod_{name}") for name in (
        "seabed", "seabed_stiffness", "seabed_friction", "seabed_friction_stiffness",
        "seabed_slope", "seabed_direction", "seabed_origin")}
    return Environment(**fields, surface=given_value(values, given, "rod_sea_surface"),
                       current=current, water_density=values["rod_water_density"],
                       gravity=values["rod_gravity"], seabed_profile=seabed_profile)


def scene_from_options(values, given, profile=None, line_types=None, points=None,
                       seabed_rows=None):
    """A validated Scene from parsed option values: the Model of model_from_options
    (its arguments), compiled (compile.py) with its refusals naming the
    options."""
    return compile_scene(model_from_options(values, given, profile, line_types, points,
                                            seabed_rows), OPTION_NAMES)


# Options the sections replace, and what gives the value instead.
SECTION_REPLACES = {"rod_stiffness": "the line types' ei and gj",
                    "rod_load": "the line types' mass and od (the submerged weight)",
                    "rod_load_breaks": "the section ends",
                    "rod_drag": "the line types' cd and drag_d",
                    "rod_axial_stiffness": "the line types' ea",
                    "rod_mesh_grading": "the element counts of -rod_sections (each "
                                        "section is meshed uniformly)"}


def line_from_options(values, given, content=None):
    """The model's Line of -rod_line_types (its table's text ``content`` when already
    read) and -rod_sections, or None when neither is given (a uniform line);
    RodInputError for one without the other, an unknown type, a length that disagrees
    with -rod_length, or an option the sections replace."""
    if "rod_sections" not in given:
        if "rod_line_types" in given:
            raise RodInputError("-rod_line_types needs -rod_sections TYPE:LENGTH[:ELEMENTS],"
                                "... (the line from S = 0 as sections of those types)")
        return None
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
    line = Line(tuple((types[name], length) + (() if count is None else (count,))
                      for name, length, count in entries),
                element_length=None,
                elements=given_value(values, given, "rod_elements"),
                **{name: given_value(values, given, f"rod_{name}") for name in (
                    "contents_density", "internal_pressure", "design_factor")})
    total = line.length
    if "rod_length" in given and abs(total - values["rod_length"]) > 1e-9 * total:
        raise RodInputError(
            f"-rod_sections add up to {total:.15g} m, -rod_length is "
            f"{values['rod_length']:.15g} m; the sections set the length: drop -rod_length "
            "or correct a section")
    return line


def mesh_pieces(values, scene, given=()):
    """The uniform pieces (mesh.Pieces) of a line of sections, every section end a
    vertex, with the element counts -rod_sections gives and the rest of -rod_elements
    shared out by length (model/line.element_counts); None for a line without sections.
    An element too small for double precision (mesh.MIN_RELATIVE_ELEMENT) is refused."""
    if not scene.sections:
        return None
    entries = parse_sections(values["rod_sections"], "-rod_sections")
    counts = element_counts([name for name, _, _ in entries],
                            [length for _, length, _ in entries],
                            [count for _, _, count in entries], values["rod_elements"],
                            "rod_elements" in given, OPTION_NAMES)
    return checked_pieces(scene, counts, "-rod_sections")


def checked_pieces(scene, counts, named):
    """mesh.Pieces of the scene's sections with ``counts`` elements each, refused
    (naming ``named``) where an element is too small for double precision."""
    ends = [scene.sections[0].start] + [section.end for section in scene.sections]
    smallest = float(np.min(np.diff(ends) / counts))
    if not smallest >= MIN_RELATIVE_ELEMENT * scene.length:
        raise RodInputError(
            f"{named}: an element of {smallest:.3g} m is {smallest / scene.length:.2g} "
            f"of the length, below what double precision resolves ({MIN_RELATIVE_ELEMENT:g}); "
            "lengthen the shortest section or give it fewer elements")
    return Pieces(ends, counts)


def settings_from_options(values, scene, names=OPTION_NAMES):
    """The iteration's Settings of the options, the default penalty resolved for
    ``scene``; refusals worded with ``names``."""
    penalty = values["rod_al_penalty"]
    if penalty is None:
        penalty = checked_default_penalty(scene, start_tension(values, scene), names)
    return Settings(asked_penalty=penalty, max_it=values["rod_al_max_it"],
                    rtol=values["rod_al_rtol"], ctol=values["rod_al_ctol"],
                    monitor=values["rod_al_monitor"],
                    adapt_penalty=values["rod_al_adapt_penalty"],
                    check_stability=values["rod_al_stability"],
                    newton=values["rod_al_newton"])


def check_stability_asked(values, given, scene, problem, names=OPTION_NAMES,
                          switch="-rod_al_stability"):
    """Refuse the stability test asked for, ``switch`` 1 given (values and given of the
    options), on a ``problem`` (problem.RodProblem, built for ``scene``) with a term that
    has no energy (Term.conservative False): the test is of the second variation of the
    energy (docs/method.md §10), and would be left out without a word
    (UzawaSolver.tests_stability). The one place that decides whether a stability
    verdict is possible: a current (its drag a follower load) and seabed friction (it
    dissipates) are named by their options as ``names`` does; the other such loads (a
    sloping seabed's lagged contact force, the sea surface's wet and dry parts,
    attachments that can reach the surface) by their terms' newton_gap."""
    if "rod_al_stability" not in given or not values["rod_al_stability"]:
        return
    if problem.conservative:
        return
    if scene.current is not None:
        option = names["current_profile" if "rod_current_profile" in given else "current"]
        load, reason = "a current", "its drag is a follower load"
    elif scene.seabed is not None and scene.seabed.friction is not None:
        option, load, reason = names["seabed_friction"], "friction", "it dissipates"
    else:
        loads = "; ".join(dict.fromkeys(term.newton_gap or type(term).__name__
                                        for term in problem.terms if not term.conservative))
        raise RodInputError(f"{switch} 1: the stability test is of the second variation "
                            f"of the energy, and this scene has loads without one ({loads}); "
                            f"drop {switch} (such a run gives no stability verdict)")
    raise RodInputError(f"{switch} 1 with {option}: the stability test is of the "
                        f"second variation of the energy, and {load} has none ({reason}); "
                        f"drop {switch} (a run with {load} gives no stability "
                        f"verdict), or test the scene without {load}")


def start_tension(values, scene):
    """The largest tension of the first step's start, N (the default penalty's start
    scale, problem/penalty.py): that of the catenary at the first step's load factor
    1 / -rod_steps where -rod_initial_shape catenary starts it, 0 for the straight start
    and a restart (whose multipliers are the file's). 0 too for a scene without a
    catenary: the start refuses it (cli/line_run.start_from), after -help has been said."""
    if values["rod_initial_shape"] != "catenary" or values["rod_initial"]:
        return 0.0
    try:
        return starts.largest_tension(scene, 1.0 / values["rod_steps"])
    except RodInputError:
        return 0.0


def checked_default_penalty(scene, start_tension=0.0, names=OPTION_NAMES):
    """default_penalty(scene, start_tension), refused above MAX_MAGNITUDE (the bound of
    -rod_al_penalty) with the options behind the scale that sets it
    (problem/penalty.penalty_scales)."""
    scales = penalty_scales(scene, start_tension)
    name = max(scales, key=scales.get)
    if scales[name] > MAX_MAGNITUDE:
        n = names
        names = line_names(scene.sections, n)
        stiffness = names["stiffness"]
        option, formula = {
            "bending": (f"{stiffness} with {names['length']}", "100 sqrt(min K max K) / L^2"),
            "tension": (f"{names['load']}, {n['start_force']}, {n['end_force']} or the "
                        "current", "F / 2"),
            "twist": (f"{n['end_twist']} (or {n['end_frame']}) with {stiffness}",
                      "2 (K3 alpha / L)^2 / min(K1, K2)"),
            "stretch": (f"{n['axial_stiffness']} with {n['end_position']}"
                        if not scene.sections
                        else f"the line types' ea with {n['end_position']}",
                        "EA (|r_L| - L) / 2L"),
            "start": (f"{names['load']} with {n['initial_shape']} catenary",
                      "the catenary start's largest tension")}[name]
        raise RodInputError(
            f"{option}: the default -rod_al_penalty {formula} = {scales[name]:.3g} N is "
            f"above {MAX_MAGNITUDE:g}, beyond what double precision carries through the "
            "solver; check the units (N m^2, m, rad)")
    return scales[name]


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
