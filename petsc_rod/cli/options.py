"""The application's PETSc options: one table drives parsing, defaults and ``-help``.

Every option has the root prefix ``rod_``. The KSPs of the global step have their own
prefixes (``rod_slope_``, ``rod_d1_``, ``rod_d2_``; ``rod_z_`` the seabed's vertical
problem, ``rod_x_`` and ``rod_y_`` its friction's), the SNES of the iteration
``rod_snes_``, the Newton Jacobian's LU ``rod_newton_``;
they read the usual PETSc options (the second variation's LDL^T, ``rod_inertia_``,
only MUMPS's). A
``-rod_*`` name that is not in the table is an error (with the closest known name); any
other option nobody read is reported at the end of the run.
"""

import ctypes
import dataclasses
import difflib
import hashlib
import inspect
from dataclasses import dataclass

import numpy as np
from petsc4py import PETSc

from petsc_rod.environment.seabed import DEFAULT_PENETRATION
from petsc_rod.errors import RodInputError
from petsc_rod.global_step.ksp import (INERTIA_PREFIX, NEWTON_PREFIX, SUBSTRUCTURING,
                                       lu_package)
from petsc_rod.iteration.continuation import MAX_HALVINGS_CAP, PathSettings
from petsc_rod.iteration.controller import (EARLY_ESCAPE, NEWTON_AFTER, NEWTON_SWITCH,
                                            NEWTON_SWITCH_FAR, NEWTON_WORTH)
from petsc_rod.iteration.driver import DEFAULT_SNES, FUNCTION_ONLY_SNES
from petsc_rod.iteration.stopping import Settings
from petsc_rod.mesh.mesh import Mesh
from petsc_rod.mesh.ranks import MODES as RANKS_MODES
from petsc_rod.model.line import DEFAULT_ELEMENTS
from petsc_rod.model.moordyn import read_moordyn
from petsc_rod.model.values import MAX_MAGNITUDE  # noqa: F401 (the options' bound)
from petsc_rod.problem.penalty import (ADAPT_BELOW, ADAPT_FACTOR, ADAPT_PROGRESS,
                                      ADAPT_WINDOW, FRICTION_SHARE)
from petsc_rod.scenes.scene import Scene

# Prefixes of PETSc objects: the KSPs of the global step, the SNES of the iteration and
# the MUMPS factorisations of the Newton steps and the stability test, the modes' SLEPc
# eigensolver (its EPS, spectral transformation with MUMPS's LDL^T, bases, dense solver,
# region: analysis/modes.py).
SOLVER_PREFIXES = ("rod_slope_", "rod_d1_", "rod_d2_", "rod_snes_", "rod_z_", "rod_x_", "rod_y_",
                   "rod_newton_", "rod_inertia_", "rod_modes_eps_", "rod_modes_st_",
                   "rod_modes_bv_", "rod_modes_ds_", "rod_modes_rg_")

# Where a restart's seabed friction anchors are (-rod_initial_friction_anchors): the
# file's positions (followed by the return map), or the line as laid between this run's
# ends (problem/build.lay_friction_anchors).
FRICTION_ANCHORS = ("file", "laid")

# The largest whole number an integer option may hold: a PETSc integer.
MAX_INT = int(np.iinfo(PETSc.IntType).max)


def _checked_reals(values):
    """``values`` (an array), refused when not finite or too large (MAX_MAGNITUDE)."""
    if not np.all(np.isfinite(values)):
        raise ValueError("expected finite numbers, not nan or inf")
    if np.any(np.abs(values) > MAX_MAGNITUDE):
        raise ValueError(f"out of range: magnitudes above {MAX_MAGNITUDE:g} are refused")
    return values


def _real(text):
    return float(_checked_reals(np.array([float(text)]))[0])


def _real_or_inf(text):
    """A real number as _real, or +inf (a stiffness "infinite": the rigid limit)."""
    value = float(text)
    return value if value == np.inf else _real(text)


def _reals(count=None):
    def parse(text):
        values = [float(v) for v in text.replace(" ", "").split(",") if v != ""]
        if count is not None and len(values) != count:
            raise ValueError(f"expected {count} comma-separated numbers")
        return _checked_reals(np.array(values))
    return parse


def _int(text):
    try:
        value = float(text)          # "1e6" is a whole number too
    except ValueError:
        raise ValueError("expected a whole number") from None
    if not np.isfinite(value) or abs(value) > MAX_INT:
        raise ValueError(f"expected a whole number of magnitude at most {MAX_INT} (a PETSc "
                         "integer)")
    if value != int(value):
        raise ValueError("expected a whole number")
    return int(value)


def _bool(text):
    lowered = text.strip().lower()
    if lowered in ("", "1", "true", "yes", "on"):
        return True
    if lowered in ("0", "false", "no", "off"):
        return False
    raise ValueError("expected true or false")


def _string(text):
    if not text:
        raise ValueError("expected a value")
    return text


@dataclass(frozen=True)
class Option:
    name: str
    parse: object
    default: object
    metavar: str
    help: str
    check: object = None     # (predicate, what is required)
    unit: str = "1"          # of the value in the result file's ``parameters`` ("text")


POSITIVE = (lambda v: np.all(np.asarray(v) > 0), "must be positive")
# a positive scale (length, stiffness, penalty): also not below 1 / MAX_MAGNITUDE
SCALE = (lambda v: np.all(np.asarray(v) >= 1 / MAX_MAGNITUDE),
         f"must be positive (at least {1 / MAX_MAGNITUDE:g})")
NON_NEGATIVE = (lambda v: np.all(np.asarray(v) >= 0), "must not be negative")
# a seabed slope, degrees: a plane at 90 degrees or more is a wall, not a seabed
SLOPE = (lambda v: abs(v) < 90, "must lie strictly between -90 and 90 degrees (a "
         "seabed's slope above the horizontal; moderate slopes, a few degrees, are the "
         "model's range)")
# a stopping tolerance: a change or residual of 1 or more would accept any iterate
TOLERANCE = (lambda v: 1 / MAX_MAGNITUDE <= v < 1,
             f"must be positive (at least {1 / MAX_MAGNITUDE:g}) and below 1: a tolerance of "
             "1 or more accepts any iterate")
# The mesh's own default grading (Mesh's keyword).
MESH_GRADING = inspect.signature(Mesh).parameters["grading"].default


def default_of_function(function, name):
    """The default of keyword ``name`` of ``function`` (the MoorDyn reader's element
    length): an option's default is that of the code that uses it, read from there."""
    return inspect.signature(function).parameters[name].default


def default_of(owner, name):
    """The default of field ``name`` of the dataclass ``owner`` (Scene, Settings,
    PathSettings): an option's default is that of the object that uses it, read from
    there."""
    field = next(f for f in dataclasses.fields(owner) if f.name == name)
    if field.default_factory is not dataclasses.MISSING:
        return field.default_factory()
    return field.default


OPTIONS = [
    Option("rod_length", _real, 1.0, "L", "length of the cable, m", SCALE, "m"),
    Option("rod_elements", _int, DEFAULT_ELEMENTS, "N", "number of elements", POSITIVE),
    Option("rod_mesh_grading", _real, MESH_GRADING, "q",
           "ratio of the largest to the smallest element; > 1 refines both ends",
           (lambda v: v >= 1, "must be >= 1")),
    Option("rod_stiffness", _reals(3), np.ones(3), "K1,K2,K3",
           "bending (about d1, d2) and torsion stiffness, N m^2", SCALE, "N m^2"),
    Option("rod_axial_stiffness", _real_or_inf, default_of(Scene, "axial_stiffness"), "EA",
           "axial stiffness EA, N: the centreline stretches, r' = (1 + eps) d3, with energy "
           "EA eps^2 / 2 per metre of unstretched line (docs/method.md §12); default inf, "
           "inextensible", SCALE, "N"),
    Option("rod_start", _string, default_of(Scene, "start"), "clamp|pin|free",
           "condition at S = 0 (at -rod_start_position)", unit="text"),
    Option("rod_start_position", _reals(3), default_of(Scene, "start_position"), "x,y,z",
           "position of the start S = 0 (clamp, pin), m: every position (end, seabed, sea "
           "surface, outputs) is absolute, z up", unit="m"),
    Option("rod_end", _string, default_of(Scene, "end"), "clamp|pin|free", "condition at S = L",
           unit="text"),
    Option("rod_end_position", _reals(3), None, "x,y,z",
           "position of the end S = L (clamp, pin); default the start + (L,0,0)", unit="m"),
    Option("rod_end_frame", _reals(9), None, "d1,d2,d3",
           "end frame at S = L, 9 numbers, rows d1 d2 d3 (clamp); default e_y,e_z,e_x"),
    Option("rod_start_frame", _reals(9), None, "d1,d2,d3",
           "start frame at S = 0, 9 numbers, rows d1 d2 d3 (clamp); default e_y,e_z,e_x"),
    Option("rod_end_twist", _real, default_of(Scene, "end_twist"), "angle",
           "extra roll of the end frame about its d3, rad (clamp); any size, reached by "
           "continuation", unit="rad"),
    Option("rod_end_force", _reals(3), default_of(Scene, "end_force"), "fx,fy,fz",
           "dead force at a free end S = L, N", unit="N"),
    Option("rod_start_force", _reals(3), default_of(Scene, "start_force"), "fx,fy,fz",
           "dead force at a free start S = 0, N", unit="N"),
    # flex joints at pinned ends (physics/flex_joint.py, docs/method.md §5)
    Option("rod_start_rotational_stiffness", _real,
           default_of(Scene, "start_rotational_stiffness"), "k",
           "flex joint at a pinned start: rotational stiffness, N m/rad (moment k theta, "
           "theta the angle of d3 from -rod_start_joint_axis); 0 a plain pin",
           NON_NEGATIVE, "N m/rad"),
    Option("rod_end_rotational_stiffness", _real,
           default_of(Scene, "end_rotational_stiffness"), "k",
           "flex joint at a pinned end S = L: rotational stiffness, N m/rad; 0 a plain pin",
           NON_NEGATIVE, "N m/rad"),
    Option("rod_start_joint_axis", _reals(3), None, "x,y,z",
           "neutral axis of the start's flex joint (normalised); default the line's "
           "direction there in its catenary (e_x without one)"),
    Option("rod_end_joint_axis", _reals(3), None, "x,y,z",
           "neutral axis of the end's flex joint (normalised); default the line's "
           "direction there in its catenary (e_x without one)"),
    Option("rod_load", _reals(), default_of(Scene, "load_values").ravel(), "fx,fy,fz[,...]",
           "distributed dead load, N/m: 3 values, or 3 per piece with -rod_load_breaks",
           unit="N/m"),
    Option("rod_load_breaks", _reals(), default_of(Scene, "load_breaks"), "s1,...",
           "arc lengths where the piecewise-constant load changes, m", unit="m"),
    # the line as line types and sections (scenes/line.py, docs/riser.md)
    Option("rod_line_types", _string, None, "FILE",
           "line types: a header row naming the columns name od mass gj and ei (or ei1 "
           "ei2, or ei_start ei_end), optionally ea cd drag_d; one row per type (m, kg/m, "
           "N m^2, N)", unit="text"),
    Option("rod_sections", _string, None, "TYPE:LENGTH[:ELEMENTS],...",
           "the line from S = 0 as sections of -rod_line_types (m); they set the length, "
           "stiffness, weight and drag; elements shared out by length where not given",
           unit="text"),
    Option("rod_contents_density", _real, 0.0, "rho_c",
           "density of the pipe's contents, kg/m^3 (the internal pressure's head; the "
           "contents' weight is in the line types' mass)", NON_NEGATIVE, "kg/m^3"),
    Option("rod_internal_pressure", _real, 0.0, "p",
           "internal pressure at the top (the higher held end), Pa", NON_NEGATIVE, "Pa"),
    Option("rod_design_factor", _real, default_of(Scene, "design_factor"), "f",
           "the allowable von Mises stress of a line type with id and smys is f smys "
           "(utilisation = von Mises / (f smys); default the API RP 2RD operating basic "
           "allowable 2/3)", (lambda v: 0 < v <= 1, "must be in (0, 1]")),
    # attachments (scenes/point_loads.py, physics/point_loads.py; docs/riser.md)
    Option("rod_point_loads", _string, None, "FILE",
           "attachments: a table with a header row naming its columns, s (arc length, m; "
           "required) and any of mass (kg in air), volume (displaced volume, m^3), fx, fy, "
           "fz (a point force, N), cda (drag area, m^2), name; each adds the dead force "
           "(fx, fy, fz) + (rho_w volume - mass) g e_z at s", unit="text"),
    Option("rod_point_load", _reals(), None, "S,fx,fy,fz[,...]",
           "point dead forces, N, at arc lengths S, m: 4 numbers per point", unit="m, N"),
    Option("rod_water_density", _real, default_of(Scene, "water_density"), "rho",
           "sea water density rho_w, kg/m^3 (the buoyancy and drag of line types and "
           "attachments); 0: a line in air", NON_NEGATIVE, "kg/m^3"),
    Option("rod_gravity", _real, default_of(Scene, "gravity"), "g",
           "gravity, m/s^2, along -z (the weight of line types and attachments); 0: a "
           "weightless line", NON_NEGATIVE, "m/s^2"),
    # the environment (petsc_rod/environment, docs/riser.md)
    Option("rod_seabed", _real, None, "z",
           "height of a flat, frictionless, elastic seabed, m (z up): the line rests on it",
           unit="m"),
    Option("rod_seabed_stiffness", _real, None, "k",
           "seabed stiffness, N/m per m of line per m of penetration; default w / "
           f"{DEFAULT_PENETRATION * 1e3:g} mm, w the largest downward -rod_load (N/m)", SCALE,
           "N/m^2"),
    Option("rod_seabed_friction", _reals(), None, "mu|mu_axial,mu_lateral",
           "Coulomb friction of the seabed, both coefficients positive: the friction at a "
           "grounded point opposes its slip from the line as laid (the catenary between "
           "the ends; a restart's: -rod_initial_friction_anchors) and is at most mu times "
           "its contact reaction, mu between mu_axial "
           "along the line and mu_lateral across it (an ellipse); default none",
           POSITIVE, "1"),
    Option("rod_seabed_friction_stiffness", _real, None, "k_s",
           "the stick stiffness of the seabed friction, N/m per m of line per m of slip: "
           "a point moves up to mu R / k_s before it slides (R its contact reaction, N/m); "
           "default a tenth of the seabed stiffness (at its default, mu x 1 cm)",
           SCALE, "N/m^2"),
    Option("rod_seabed_slope", _real, None, "deg",
           "the seabed a plane rising at this angle (degrees above the horizontal, "
           "negative: falling) along -rod_seabed_direction, through the height -rod_seabed "
           "at -rod_seabed_origin (with -rod_system: the file's seabed height there); the "
           "contact acts normal to it", SLOPE, "deg"),
    Option("rod_seabed_direction", _reals(), None, "azimuth|dx,dy",
           "direction of the seabed's slope (upward) or profile: an azimuth, degrees from "
           "+x toward +y (anticlockwise seen from above), or a horizontal vector; default "
           "+x", unit="deg or 1"),
    Option("rod_seabed_origin", _reals(2), None, "x,y",
           "the seabed origin, m (absolute): where -rod_seabed gives the height of a "
           "sloping seabed and a profile's distances start; default 0,0", unit="m"),
    Option("rod_seabed_profile", _string, None, "FILE",
           "seabed profile: rows 'distance height' (m; '#' comments, commas allowed) along "
           "-rod_seabed_direction from -rod_seabed_origin, distances strictly increasing, "
           "heights absolute (z up), linear in between; or a grid, rows 'x y height' (x, y "
           "from -rod_seabed_origin, every x with every y), bilinear; in place of "
           "-rod_seabed",
           unit="text"),
    Option("rod_current", _reals(3), None, "ux,uy,uz",
           "uniform steady current, m/s (normal Morison drag, needs -rod_drag; in a system "
           "each line type's Cd and Diam)", unit="m/s"),
    Option("rod_current_profile", _string, None, "FILE",
           "current profile: rows 'depth ux uy uz' (m, m/s), depths from 0 down, "
           "increasing, linear in between, constant beyond", unit="text"),
    Option("rod_sea_surface", _real, None, "z",
           "height of the sea surface, m: the current profile's depths and the external "
           "pressure of line types are measured from it; default the highest held end",
           unit="m"),
    Option("rod_drag", _reals(3), None, "rho,Cd,D",
           "water density kg/m^3, normal drag coefficient, hydrodynamic diameter m: drag "
           "rho Cd D |v_n| v_n / 2 per metre", NON_NEGATIVE, "kg/m^3, 1, m"),
    Option("rod_steps", _int, default_of(PathSettings, "steps"), "K",
           "continuation steps from the straight state", POSITIVE),
    Option("rod_imperfection", _real, default_of(PathSettings, "imperfection"), "eps",
           "at the start of each step, roll the cross-sections about the tangent by "
           "eps sin(pi S / 2L) rad, so that an unstable symmetric branch is left", unit="rad"),
    Option("rod_max_halvings", _int, default_of(PathSettings, "max_halvings"), "n",
           "a step that does not converge or diverges is retried from the last converged "
           "state with half the increment, at most n times per step (smallest increment "
           "1/(K 2^n)); 0: stop at the first failure",
           (lambda v: 0 <= v <= MAX_HALVINGS_CAP, f"must be between 0 and {MAX_HALVINGS_CAP}")),
    Option("rod_track_link", _bool, default_of(PathSettings, "track_link"), "bool",
           "ends clamped on a common axis: refuse a step whose linking number Tw + Wr is "
           "not the last one plus the end roll over 2 pi (the rod passed around an end or "
           "through itself); 0 for a rod free to pass around its ends"),
    Option("rod_initial", _string, None, "FILE",
           "start from (restart) a result file; where this run's loads, end forces, end "
           "position or frame, or current differ from the file's, walk from the file's "
           "scene to this one in -rod_steps steps", unit="text"),
    Option("rod_initial_load_factor", _real, None, "t",
           "the load factor of the -rod_initial state: the load path goes on from it to 1 "
           "in -rod_steps steps; default the file's load_factor (0: walk the whole path "
           "again, e.g. from a file of another scene)",
           (lambda v: 0 <= v <= 1, "must be between 0 and 1")),
    Option("rod_initial_friction_anchors", _string, "file", "|".join(FRICTION_ANCHORS),
           "with -rod_initial and seabed friction, where its anchors are: file, the "
           "file's positions, moved by the return map along the restart's path (a restart "
           "goes on from the line the file holds); laid, the catenary between this run's "
           "ends at the full load, as a run from its own start lays them (its answer then "
           "does not depend on the file; a sweep's warm starts)",
           (lambda v: v in FRICTION_ANCHORS,
            f"expected one of {'|'.join(FRICTION_ANCHORS)}"), "text"),
    Option("rod_initial_shape", _string, "straight", "straight|catenary",
           "start of the first step: the straight reference, or the inextensible catenary "
           "of that step with its tension as multiplier (both ends held, uniform load)",
           unit="text"),
    Option("rod_output", _string, None, "FILE", "write the result (HDF5) to FILE", unit="text"),
    Option("rod_table", _string, None, "FILE.csv",
           "write the converged result along the line as CSV to FILE (one row per vertex: "
           "S, x, y, z and the results along the line, units in the header) and the "
           "regions' summary beside it, FILE's stem + _regions.csv", unit="text"),
    Option("rod_modes", _int, 0, "n",
           "after the last step, the n lowest natural modes about the converged state "
           "(undamped: no drag; SLEPc, options -rod_modes_eps_*; docs/modes.md): "
           "frequencies, periods, modal masses and classes in the run's lines; 0 none",
           NON_NEGATIVE),
    Option("rod_modes_range", _string, None, "FMIN,FMAX",
           "after the last step, every natural mode with a frequency in [FMIN, FMAX] Hz "
           "(their number counted by the inertia of K - omega^2 M at both ends; "
           "docs/modes.md), in place of -rod_modes N", unit="text"),
    Option("rod_modes_table", _string, None, "FILE.csv",
           "write the modes' table (one row per mode) to FILE, and their shapes along "
           "the line (one row per vertex and mode) to FILE's stem + _shapes.csv",
           unit="text"),
    Option("rod_modes_mass", _real, None, "m",
           "a uniform line's mass per length for -rod_modes, kg/m; default its load's "
           "magnitude / g (a line of line types: their masses)", SCALE, "kg/m"),
    Option("rod_modes_inertia", _real, 0.0, "J",
           "a uniform line's polar mass moment of inertia per length for -rod_modes, "
           "kg m (0: no torsional modes; a line of line types: m (od^2 + id^2) / 8)",
           NON_NEGATIVE, "kg m"),
    Option("rod_modes_added_mass", _real, 1.0, "Ca",
           "the added-mass coefficient C_a of -rod_modes: C_a rho_w pi od^2 / 4 normal "
           "to the line where its line type gives no ca (a type's ca wins), C_a rho_w V "
           "at an attachment", NON_NEGATIVE),
    Option("rod_system", _string, None, "FILE",
           "solve a system of lines, points and bodies read from FILE, a MoorDyn version 2 "
           "input file (docs/systems.md): the coupled equilibrium, each body's 6 x 6 "
           "mooring stiffness, every line's results; with -rod_output one HDF5 file (a "
           "group per line, the group system), with -rod_table FILE.csv the tables "
           "FILE_<line>.csv and FILE_system.csv", unit="text"),
    Option("rod_system_element_length", _real, default_of_function(read_moordyn,
                                                                   "element_length"),
           "h", "with -rod_system: the lines' longest element, m (MoorDyn's segments finer "
           "than it are kept)", SCALE, "m"),
    Option("rod_system_body_load", _string, None, "NAME,fx,fy,fz,mx,my,mz[:NAME,...]",
           "with -rod_system: a constant external load on body NAME, N and N m about its "
           "reference point, global axes, added to the file's; several bodies separated "
           "by ':'", unit="text"),
    Option("rod_system_offset", _string, None, "NAME,dx,dy,dz[:NAME,...]",
           "with -rod_system: move the fixed or prescribed point NAME, or the body NAME "
           "held in each moved direction, by (dx, dy, dz), m, global axes, from the "
           "file's position (a vessel's offset); several separated by ':'", unit="text"),
    Option("rod_system_line_length", _string, None, "NAME,L[:NAME,...]",
           "with -rod_system: line NAME's unstretched length L, m, its sections' lengths "
           "scaled to it (their elements at most -rod_system_element_length long); "
           "several separated by ':'", unit="text"),
    Option("rod_system_steps", _int, None, "n",
           "with -rod_system: the load continuation's first step is 1/n of the bodies' "
           "and points' loads (halved where it fails, doubled where it succeeds); default "
           "the system solver's (1)", POSITIVE),
    Option("rod_system_predictor", _bool, True, "bool",
           "with -rod_system: the first solve starts where the system's elastic "
           "catenaries settle, where every line can be one (pinned, one line type, a "
           "flat seabed without friction; in a current, without the lines' drag; "
           "docs/systems.md, \"Speed\"); 0: always the load continuation from the "
           "unloaded system"),
    Option("rod_system_watch_circle", _string, None, "BODY,LOAD[,N]",
           "with -rod_system: after the equilibrium, body BODY's watch circle (a Free "
           "body: a held one is refused): its position under a horizontal load LOAD (N) "
           "turned through N headings (default 24, every 15 deg), each equilibrium warm "
           "from the last; in the result file's group system/watch_circle and the table "
           "FILE_watch_circle.csv", unit="text"),
    Option("rod_system_excursion", _string, None, "BODY,LOADMAX[,N[,HEADING,...]]",
           "with -rod_system: after the equilibrium, body BODY's load-excursion curves "
           "(a Free body: a held one is refused): the restoring force against the offset "
           "under horizontal loads 0 to LOADMAX "
           "(N) in N steps (default 10) along each heading (deg from +x towards +y, "
           "default 0); in the result file's group system/excursion and the table "
           "FILE_excursion.csv", unit="text"),
    Option("rod_system_modes", _bool, False, "bool",
           "with -rod_system: the natural modes of the bodies and free points about the "
           "equilibrium, K x = omega^2 (M + A) x over their free degrees of freedom "
           "(the lines quasi-static: their static stiffness; docs/modes.md): periods, "
           "frequencies, each mode's shares per body and degree of freedom; in the run's "
           "lines, the group system/modes, the table FILE_system_modes.csv"),
    Option("rod_system_modes_line_mass", _bool, False, "bool",
           "with -rod_system_modes: each line's mass in air lumped half at each of its "
           "ends (default: left out, the lines' dynamics being in their own modes)"),
    Option("rod_al_penalty", _real, None, "R",
           "augmented-Lagrangian penalty R, N; default the largest of 100 sqrt(min(K) "
           "max(K)) / L^2, half the applied force int |f| dS + |end forces|, and 2 M^2 / "
           "min(K1, K2) with M = K3 a / L for a clamped end turned by a, and the largest "
           "tension of a -rod_initial_shape catenary start", SCALE, "N"),
    Option("rod_al_max_it", _int, default_of(Settings, "max_it"), "n", "iteration cap per step",
           POSITIVE),
    Option("rod_al_rtol", _real, default_of(Settings, "rtol"), "tol",
           "stop when the relative L2 change of (r, r', d1, d2) at the nodes per iteration "
           "is below tol", TOLERANCE),
    Option("rod_al_ctol", _real, default_of(Settings, "ctol"), "tol",
           "and the RMS constraint residual |(r'-tau3, d1-tau1, d2-tau2)|_L2 / sqrt(L) is "
           "below tol", TOLERANCE),
    Option("rod_al_stability", _bool, default_of(Settings, "check_stability"), "bool",
           "at each converged step, test the second variation of the energy (Sylvester "
           "inertia); at a saddle turn the frames along its negative curvature and go on; "
           "with a current or seabed friction (no energy) no verdict, but a negative "
           "direction is still left unless friction holds the line (1 given with either "
           "is refused: it is the default); on an extensible line the strains are "
           "unknowns of it too"),
    Option("rod_al_newton", _bool, default_of(Settings, "newton"), "bool",
           f"from iteration {NEWTON_AFTER} of a step, while change and residual are below "
           f"{NEWTON_SWITCH:g} ({NEWTON_SWITCH_FAR:g} with a seabed or a current) and more "
           f"than {NEWTON_WORTH} iterations would remain at the recent rate (with a "
           "seabed or a current at any rate), try Newton steps on the reduced problem "
           "(frames turned by the KKT system of the energy's second variation), taken "
           "only where it is positive "
           f"definite; where it is not and change and residual are below {EARLY_ESCAPE:g}, "
           "the state is near a saddle and is left at once (not with a seabed); after a "
           "failed attempt the wait doubles; with a seabed the node heights are unknowns "
           "too (with its friction, of one coefficient, the horizontal positions, an LU "
           "solve), on an "
           "extensible line the strains, with a current the resultants of the drag (an "
           "LU solve)"),
    Option("rod_al_monitor", _bool, default_of(Settings, "monitor"), "",
           "print change and residual at each iteration"),
    Option("rod_al_adapt_penalty", _bool, default_of(Settings, "adapt_penalty"), "bool",
           f"raise R {ADAPT_FACTOR:g} times, refactoring the matrices, while it is below "
           f"{ADAPT_BELOW:g} of its ceiling (the default; with seabed friction on an "
           f"extensible line {FRICTION_SHARE:g} times the least EA where larger) and the "
           f"constraint residual stays above {ADAPT_PROGRESS:g} of its value "
           f"{ADAPT_WINDOW} iterations before"),
    Option("rod_ranks_split", _string, "auto", "|".join(RANKS_MODES),
           "on several ranks, the line's run split over them (split) or done whole on "
           "the first while the others wait (whole: the answers of one rank); auto: "
           "whole where the cost model of mesh/ranks.py, measured by "
           "scripts/benchmark_scenes.py, predicts an iteration faster on one rank (the "
           "short lines, and with seabed friction longer ones: its secant passes cost "
           "more split), split elsewhere",
           (lambda v: v in RANKS_MODES, f"expected one of {'|'.join(RANKS_MODES)}"),
           "text"),
]
BY_NAME = {option.name: option for option in OPTIONS}
# Options of how a run is made or started, not of the scene it solves: a result file's
# parameters without them are not an older version's (cli/line_run.walked_scene).
HOW_RUN = ("rod_ranks_split", "rod_initial_friction_anchors")


def read_options():
    """Parse every ``-rod_*`` option of PETSc's options database; returns (values by
    name, set of names the user gave) (values_of).
    """
    return values_of(whole_values())


def values_of(texts):
    """(values by name, set of names given) of the ``-rod_*`` options among ``texts``
    {name: text} (a sweep's case: its base options and its own), parsed and checked as
    on the command line. Raises RodInputError for an unknown ``-rod_`` name or a
    malformed value.
    """
    given = {name for name in texts if name.startswith("rod_")}
    for name in sorted(given):
        if name not in BY_NAME and not name.startswith(SOLVER_PREFIXES):
            raise RodInputError(f"unknown option -{name}{nearest_hint(name)}")
    return parse_values({name: texts[name] for name in given if name in BY_NAME}), given


def nearest_hint(name):
    """'; did you mean -NAME?' of the known option closest to ``name`` (no dash), or a
    pointer to -help."""
    close = difflib.get_close_matches(name, list(BY_NAME), n=1)
    return f"; did you mean -{close[0]}?" if close else "; see -help"


def whole_values(database=None):
    """{name: text} of every option in the database ('' for a name without a value),
    each text whole: petsc4py's Options.getString returns at most 1023 characters of a
    value and cuts the rest without a word (a long -rod_sections or -rod_point_load
    would lose sections or digits), getAll the whole of it. Every -rod_* name is read
    once through getString as well, which marks it used (getAll does not), so that it is
    not reported as unused."""
    database = database or PETSc.Options()
    texts = {name: text or "" for name, text in database.getAll().items()}
    for name in texts:
        if name in BY_NAME:
            database.getString(name, "")
    return texts


def parse_values(texts):
    """{name: value} of every -rod_* option from {name: text} of those given (the rest
    take their defaults), parsed and checked as on the command line (the Python API's
    models, petsc_rod/api, are read this way too). RodInputError for a malformed value."""
    values = {}
    for option in OPTIONS:
        if option.name not in texts:
            values[option.name] = option.default
            continue
        text = texts[option.name]
        try:
            value = option.parse(text)
        except ValueError as error:
            expected = "" if "expected" in str(error) else f"; expected {option.metavar}"
            raise RodInputError(f"-{option.name} {text!r}: {error}{expected}") from None
        if option.check is not None and not option.check[0](value):
            raise RodInputError(f"-{option.name} {text}: {option.check[1]}")
        values[option.name] = value
    return values


def check_anderson_depth():
    """Refuse a -rod_snes_anderson_m that is not a whole number of at least 1 (PETSc
    itself fails on it with a stack of messages)."""
    database = PETSc.Options()
    if database.hasName("rod_snes_anderson_m"):
        depth = database.getString("rod_snes_anderson_m", "")
        if not depth.isdigit() or int(depth) < 1:
            raise RodInputError(f"-rod_snes_anderson_m {depth}: the depth of Anderson "
                                "mixing is a whole number of at least 1")


def check_snes_type():
    """Refuse a -rod_snes_type that cannot drive the fixed-point map, before any work:
    only the types that need no Jacobian can (driver.FUNCTION_ONLY_SNES); the others
    would fail inside their first solve."""
    kind = PETSc.Options().getString("rod_snes_type", DEFAULT_SNES)
    if kind not in FUNCTION_ONLY_SNES:
        raise RodInputError(
            f"-rod_snes_type {kind}: the iteration is a fixed point x = G(x) with no "
            "Jacobian, which only a SNES that needs the residual alone can drive; use one "
            f"of {'|'.join(FUNCTION_ONLY_SNES)} (and their -rod_snes_* options)")


# The switches of the Newton systems' factorisation on several ranks (global_step/ksp.py,
# SUBSTRUCTURING), read by PETSc's options database only when the first Newton system is
# factored: checked here, before any work.
SUBSTRUCTURING_SWITCHES = tuple(f"{prefix}{SUBSTRUCTURING}"
                                for prefix in (NEWTON_PREFIX, INERTIA_PREFIX))


def check_factor_switches():
    """Refuse, before any work, a -rod_newton_substructuring or
    -rod_inertia_substructuring that is not a true or false (PETSc read them only at
    the first Newton step, after the iterations before it) and a -rod_newton_lu that
    is not one of ksp.LU_PACKAGES (ksp.lu_package, read at the first Newton step)."""
    lu_package(NEWTON_PREFIX)
    given = PETSc.Options().getAll()        # read without marking them used
    for name in SUBSTRUCTURING_SWITCHES:
        if name in given:
            text = given[name]
            try:
                _bool(text)
            except ValueError:
                raise RodInputError(
                    f"-{name} {text}: expected true or false (whether the Newton steps' "
                    "systems are factored by substructuring on several ranks)") from None


def check_same_on_every_rank(comm):
    """Refuse a run whose ranks were given different options (e.g. an option on one rank
    only), which would otherwise crash or deadlock in the first collective call: the
    digests of the whole options database are compared, and a mismatch is reported with
    the options that differ. Collective; raises the same RodInputError on every rank."""
    mpi = comm.tompi4py()
    database = PETSc.Options().getAll()
    digest = hashlib.sha256(repr(sorted(database.items())).encode()).hexdigest()
    digests = mpi.allgather(digest)
    if len(set(digests)) == 1:
        return
    rank = next(k for k, other in enumerate(digests) if other != digests[0])
    first, other = mpi.bcast(database, root=0), mpi.bcast(database, root=rank)
    names = sorted(name for name in set(first) | set(other)
                   if name not in first or name not in other or first[name] != other[name])
    shown = " ".join(f"-{name}" for name in names[:5]) + (" ..." if len(names) > 5 else "")
    raise RodInputError(f"rank {rank} was given other options than rank 0 ({shown}); give every "
                        "rank the same options (one mpiexec command, one options file)")


def format_value(value):
    """An option's value as text that its parser reads back."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, np.ndarray):
        return ",".join(f"{v:.17g}" for v in value.ravel())
    if isinstance(value, float):
        return f"{value:.17g}"
    return str(value)


def help_text():
    """The lines -help prints for the application's options."""
    lines = ["petsc_rod options (prefix rod_):"]
    for option in OPTIONS:
        default = option.default
        if isinstance(default, np.ndarray):
            default = ",".join(f"{v:g}" for v in default) or "none"
        lines.append(f"  -{option.name} <{option.metavar}>: {option.help} "
                     f"(default {default})")
    lines.append("  Global-step solvers: -rod_slope_ksp_*, -rod_slope_pc_* (the slope r'), -rod_d1_*, -rod_d2_* "
                 "(directors), -rod_z_* (the height, with -rod_seabed), -rod_x_*, -rod_y_* "
                 "(with -rod_seabed_friction); default preonly + "
                 "Cholesky on one rank, preonly + the exact substructuring PC (-pc_type "
                 "python) on several.")
    lines.append("  Newton steps with a current or seabed friction: -rod_newton_* the LU of "
                 "their unsymmetric Jacobian; -rod_newton_lu petsc|mumps "
                 "(default petsc: PETSc's LU in the natural order, checked by its backward "
                 "and forward errors, MUMPS's where that fails; on one rank and for each "
                 "rank's interior on several); MUMPS's LU "
                 "(-rod_newton_mat_mumps_icntl_7 2: the AMF ordering, "
                 "-rod_newton_mat_mumps_icntl_15 -B: on the graph of the nodes, B "
                 "unknowns a node); on several ranks -rod_newton_substructuring <bool> "
                 "(default true): each rank factors its part of the chain on its own "
                 "(as on one rank), the ranks' first nodes the interface, whose Schur "
                 "complement every rank solves; false: MUMPS on all ranks.")
    lines.append("  The stability test and the Newton steps' positive-definiteness test: "
                 "-rod_inertia_mat_mumps_* MUMPS's controls of their LDL^T (MUMPS's own "
                 "ordering unless given); -rod_inertia_substructuring <bool> as for the "
                 "Newton steps' LU (the inertia the interiors' and the interface's).")
    lines.append("  The modes (-rod_modes): SLEPc's options under -rod_modes_ "
                 "(-rod_modes_eps_nev, -rod_modes_eps_ncv, -rod_modes_eps_tol, "
                 "-rod_modes_eps_view, ...; default Krylov-Schur, shift-and-invert about "
                 "omega^2 just below 0), -rod_modes_st_mat_mumps_* MUMPS's controls of "
                 "the LDL^T of K - sigma M.")
    lines.append("  The iteration: -rod_snes_type anderson (default: Anderson mixing of the "
                 "iterates) | nrichardson (the plain iteration) | ngmres | qn | ncg (the SNES "
                 "types that need no Jacobian), and the SNES options under the same prefix "
                 "(-rod_snes_anderson_m, -rod_snes_monitor).")
    return lines


def unused_options():
    """Names of options in the database that no PETSc object or this program read."""
    try:
        library = ctypes.CDLL(PETSc.__file__)
        used = library.PetscOptionsUsed
    except (OSError, AttributeError):
        return []
    unused = []
    for name in PETSc.Options().getAll():
        if name in ("help", "options_left", "options_file"):
            continue
        flag = ctypes.c_int(0)
        if used(None, name.encode(), ctypes.byref(flag)) == 0 and not flag.value:
            unused.append(name)
    return unused


def modes_asked(values):
    """Whether the run asks for modes: -rod_modes N or -rod_modes_range."""
    return bool(values["rod_modes"] or values["rod_modes_range"])
