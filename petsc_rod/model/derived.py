"""The loads a model gives its line, derived from its fields, and the checks that need
them (Model.check): a default seabed stiffness that some load sets, a current on line
types with a drag, a uniform line under the sea surface, a line held taut, the derived
forces within the bound of the model's numbers, the seabed's stiffness within the
largest a line accepts and a uniform line's stretch within the model of stretch. Heights in the frame of the line's start (the model's less the
start's z), as the compiled Scene has them (compile.py)."""

from dataclasses import dataclass

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.model.attachment import attachment_columns, dead_forces
from petsc_rod.model.sea import (MIN_RELATIVE_PENETRATION, default_stiffness,
                                 largest_stiffness)
from petsc_rod.model.values import MAX_MAGNITUDE, MAX_STRAIN

# Held ends closer to the length than this fraction of it make a taut line (check_taut,
# Scene.taut): a catenary of sag f has (8/3) f^2 / L of slack, so at 1e-9 L of slack its
# tension is above 2000 times its weight, beyond what the constraint tolerance determines.
TAUT_GAP = 1e-9


@dataclass(frozen=True)
class Loads:
    """What a span (model.Span) in the sea ``sea`` loads its line with: the load pieces
    ``load_values`` (m, 3), N/m, ending at ``ends`` (m + 1,), m (the sections' submerged
    weights, or a uniform line's load); the end forces (3,), N; the attachments' dead
    forces (n_p, 3), N, and drag areas (n_p,), m^2; the drag coefficient c = rho C_d D / 2
    (kg/m^2; a line of sections: the largest of its sections', None without a drag);
    the current's velocities (m, 3), m/s (None: no current)."""

    span: object
    sea: object
    load_values: np.ndarray
    ends: np.ndarray
    start_force: np.ndarray
    end_force: np.ndarray
    point_forces: np.ndarray
    drag_areas: np.ndarray
    drag: float
    velocities: np.ndarray

    @classmethod
    def of(cls, span, sea):
        """The Loads of ``span`` in ``sea`` (an Environment)."""
        line = span.line
        if span.sections:
            sections = line.section_list(sea.water_density, sea.gravity)
            values = np.asarray([s.weight for s in sections], dtype=float).reshape(-1, 3)
            ends = np.concatenate([[0.0], [s.start for s in sections[1:]], [sections[-1].end]])
            drag = max(s.drag for s in sections)
        else:
            values = np.asarray(line.load_values, dtype=float).reshape(-1, 3)
            ends = np.concatenate([[0.0], np.asarray(line.load_breaks, dtype=float).ravel(),
                                   [line.length]])
            drag = (None if line.drag is None
                    else 0.5 * float(line.drag[0]) * float(line.drag[1]) * float(line.drag[2]))
        rows = sea.current_rows()
        attachments = span.attachments
        return cls(span, sea, values, ends, force_of(span.start), force_of(span.end),
                   dead_forces(attachments, sea.water_density, sea.gravity)
                   if attachments else np.zeros((0, 3)),
                   attachment_columns(attachments)["cda"] if attachments else np.zeros(0),
                   drag, None if rows is None else np.asarray(rows[1], dtype=float).reshape(-1, 3))

    @property
    def length(self):
        return float(self.ends[-1])

    def largest_drag(self):
        """c max |v|^2 (N/m): the largest drag per metre the current can exert."""
        return float(self.drag * np.max(np.sum(self.velocities**2, axis=1)))

    def applied_forces(self):
        """The parts of the applied force by where they come from, N (applied_forces)."""
        return applied_forces(self.ends, self.load_values, self.start_force, self.end_force,
                              self.point_forces, self.drag_areas, self.sea.water_density,
                              self.drag, self.velocities)

    @property
    def loaded(self):
        """Whether anything but the held ends loads the line: a distributed load, a
        point load, a seabed, a current or an end force."""
        return bool(np.any(self.load_values) or np.any(self.start_force)
                    or np.any(self.end_force) or np.any(self.point_forces)
                    or self.sea.has_seabed or self.velocities is not None)

    def held_heights(self):
        """The heights of the held ends, m, in the frame of the start."""
        span = self.span
        return ([0.0] if span.start.kind != "free" else []) + (
            [float(span.end_offset()[2])] if span.end.kind != "free" else [])

    def seabed_stiffness(self):
        """The seabed's stiffness k (N/m^2): the given one, or weight / 1 mm (None when
        no load points down)."""
        k = self.sea.seabed_stiffness
        return default_stiffness(self.load_values) if k is None else float(k)


def applied_forces(ends, load_values, start_force, end_force, point_forces, drag_areas,
                   water_density, drag, velocities):
    """The parts of the applied force by where they come from, N: {'load': int |f| dS of
    the load pieces ``load_values`` (m, 3), N/m, between ``ends`` (m + 1,), m; 'drag':
    L c max |v|^2 of the current of ``velocities`` (k, 3), m/s, on a line of drag
    coefficient c = ``drag`` (kg/m^2) and the attachments' 1/2 rho_w C_d A max |v|^2
    (``drag_areas`` (n_p,), m^2; 0 without a current: velocities None); 'start_force':
    |P_0|, 'end_force': |P_L| (3,), N; 'point_loads': sum_p |P_p| of ``point_forces``
    (n_p, 3), N}: the scale of the internal force n (Scene.applied_force)."""
    total_drag = 0.0
    if velocities is not None:            # the largest drag the current can exert
        largest_square = float(np.max(np.sum(velocities**2, axis=1)))     # max |v|^2
        total_drag = float(ends[-1]) * float(drag * largest_square)
        # and the attachments', 1/2 rho_w C_d A max |v|^2 each
        total_drag += 0.5 * water_density * drag_areas.sum() * largest_square
    return {"load": float(np.diff(ends) @ np.linalg.norm(load_values, axis=1)),
            "drag": total_drag, "start_force": float(np.linalg.norm(start_force)),
            "end_force": float(np.linalg.norm(end_force)),
            "point_loads": float(np.linalg.norm(point_forces, axis=1).sum())}


def force_of(end):
    """An End's force (3,), N (zero when not given)."""
    return np.zeros(3) if end.force is None else np.asarray(end.force, dtype=float)


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


def rounded_down(value, digits=3):
    """``value`` > 0 rounded down to ``digits`` significant digits, so that the largest
    accepted value a message quotes is itself accepted."""
    unit = 10.0 ** (np.floor(np.log10(value)) - digits + 1)
    return float(np.floor(value / unit) * unit)


def check_loads(span, sea, n):
    """The checks of one span's derived loads (module docstring), in this order."""
    loads = Loads.of(span, sea)
    check_default_stiffness(loads, n)
    check_current_drag(loads, n)
    check_uniform_line_under_surface(loads, n)
    check_taut(loads, n)
    check_applied_forces(loads, n)
    check_seabed_stiffness(loads, n)
    check_stretch_domain(loads, n)


def check_default_stiffness(loads, n):
    """Refuse a seabed without a stiffness on a line no load of which points down: the
    default, weight / 1 mm, needs a weight."""
    if not loads.sea.has_seabed or loads.seabed_stiffness() is not None:
        return
    load = ("no line type sinks (mass above the water displaced)" if loads.span.sections
            else f"no {n['load']} points down")
    raise RodInputError(f"{n['seabed']}: {load} to set the default stiffness "
                        f"(weight / 1 mm); give {n['seabed_stiffness']}")


def check_current_drag(loads, n):
    """Refuse a current on sections whose line types have no drag and whose attachments
    have no drag area (nothing for it to push on)."""
    if (loads.span.sections and loads.velocities is not None and loads.drag == 0
            and not np.any(loads.drag_areas > 0)):
        raise RodInputError(f"a current on {n['sections']} whose line types have no "
                            "drag: give the line types a cd column")


def check_uniform_line_under_surface(loads, n):
    """Refuse a sea surface below a held end of a uniform line in a current: the part
    above it would keep the submerged weight and the current's drag it has not in the
    air, and the uniform line's load gives no diameter and mass to take them off (a line
    of sections does, physics/surface.py)."""
    sea, span = loads.sea, loads.span
    if span.sections or loads.velocities is None or sea.surface is None:
        return
    z0 = float(span.origin()[2])
    held = loads.held_heights()
    surface = sea.surface - z0                   # the start's frame
    if not max(held) > surface:
        return
    raise RodInputError(
        f"{n['sea_surface']} {surface + z0:g}: the held end at z = "
        f"{max(held) + z0:g} m is above it, where a line given by {n['load']} would keep "
        f"its submerged weight and the current's drag; give the line as {n['line_types']} "
        f"and {n['sections']} (od and mass: its weight in air and no drag above the "
        "surface), or a surface at or above the held ends")


def check_taut(loads, n):
    """Refuse a loaded inextensible line held at both ends its length apart (less
    TAUT_GAP): it can only be straight, and any tension balances its loads along it, so
    that the tension the iteration would stop at is arbitrary (docs/method.md §5). An
    unloaded one (a straight rod twisted between clamps) is kept: its tension is zero,
    the limit of a stiff extensible rod."""
    span = loads.span
    held = span.start.kind != "free" and span.end.kind != "free"
    chord = float(np.linalg.norm(span.end_offset()))
    if not (held and not span.extensible and chord >= loads.length * (1 - TAUT_GAP)
            and loads.loaded):
        return
    raise RodInputError(
        f"{n['end_position']}: the held ends are {chord:.15g} m apart, the line's length "
        f"{loads.length:.15g} m: an inextensible line held taut is straight and any "
        "tension balances its loads, so its tension is undetermined; give "
        f"{line_names(span.sections, n)['stretch']} to model the stretch, or bring the "
        "ends closer")


def check_applied_forces(loads, n):
    """Refuse a force the model derives beyond MAX_MAGNITUDE (the bound of its numbers):
    the drag coefficient c = rho C_d D / 2, the largest drag c max |v|^2 (N/m) and the
    total applied force F = int |f| dS + |P_0| + |P_L| + L c max |v|^2 (N,
    Loads.applied_forces), naming the field behind the largest part."""
    names = line_names(loads.span.sections, n)
    current = n["current_profile"] if loads.sea.profile() is not None else n["current"]
    if loads.velocities is not None:
        if loads.drag > MAX_MAGNITUDE:
            raise RodInputError(
                f"{names['drag']}: c = rho Cd D / 2 = {loads.drag:.3g} kg/m^2 is "
                f"above {MAX_MAGNITUDE:g}; give rho in kg/m^3 and D in m")
        drag = loads.largest_drag()
        if drag > MAX_MAGNITUDE:
            raise RodInputError(
                f"{current} with {names['drag']}: the largest drag c max |v|^2 = "
                f"{drag:.3g} N/m is above {MAX_MAGNITUDE:g}; give the current in m/s")
    parts = loads.applied_forces()
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


def check_seabed_stiffness(loads, n):
    """Refuse a seabed stiffer than sea.largest_stiffness (given, or the default
    w / 1 mm of a long line), naming the field and the largest stiffness accepted. A
    line with no load at all (a weightless line in still water, no force) has no such
    bound: nothing presses it into the seabed, and the bound, scaled by its load, is 0
    (the model's range check still refuses a stiffness above MAX_MAGNITUDE)."""
    if not loads.sea.has_seabed:
        return
    force = float(sum(loads.applied_forces().values()))
    if force == 0.0:
        return
    largest = min(largest_stiffness(force, loads.length), MAX_MAGNITUDE)
    k = loads.seabed_stiffness()
    if k <= largest:
        return
    largest = rounded_down(largest)
    why = (f"the largest accepted is {largest:.3g} N/m^2, under which the line's mean load "
           f"{force / loads.length:.3g} N/m sinks {MIN_RELATIVE_PENETRATION:g} of the length "
           "(near the round-off of a height: a stiffer seabed changes nothing but the "
           "conditioning of the vertical problem)")
    if loads.sea.seabed_stiffness is not None:
        raise RodInputError(f"{n['seabed_stiffness']} {k:g}: {why}; use "
                            f"{n['seabed_stiffness']} {largest:.3g} or less")
    raise RodInputError(f"{line_names(loads.span.sections, n)['load']}: the default "
                        f"{n['seabed_stiffness']} (weight / 1 mm) is "
                        f"{k:.3g} N/m^2, above what this line accepts: {why}; give "
                        f"{n['seabed_stiffness']} {largest:.3g} or less")


def least_top_strain(loads):
    """The least strain at the higher held end in any equilibrium in tension (T >= 0 at
    its lowest point) of a uniform extensible flexible line under a uniform dead load w
    (N/m of unstretched line), its held ends h apart along the load (m), or None where
    it does not apply (sections, a free end, attachments, load pieces that differ, a
    seabed that is not flat or not across the load). Along the suspended line
    d(T + T^2 / 2EA) = w dz (the cable's balance along its tangent; a current's normal
    drag has no part along it), from the lowest point (a touchdown, or below the lower
    end) to the top, T >= 0 there: eps >= sqrt(1 + 2 w h / EA) - 1. Returns (eps, w h)."""
    span, sea = loads.span, loads.sea
    if (span.sections or not np.isfinite(span.line.axial_stiffness)
            or span.start.kind == "free" or span.end.kind == "free" or span.attachments):
        return None
    values = loads.load_values
    weight = float(np.linalg.norm(values[0]))
    if weight == 0.0 or not np.all(values == values[0]):
        return None
    down = values[0] / weight
    flat = sea.seabed_profile is None and (sea.seabed_slope is None or sea.seabed_slope == 0)
    if sea.has_seabed and not (flat and down[2] == -1.0):
        return None
    height = abs(float(span.end_offset() @ down))
    return (float(np.sqrt(1.0 + 2.0 * weight * height / span.line.axial_stiffness) - 1.0),
            weight * height)


def check_stretch_domain(loads, n):
    """Refuse a uniform extensible line that every equilibrium stretches by more than
    MAX_STRAIN at its top (least_top_strain), outside the domain of the model of
    stretch."""
    least = least_top_strain(loads)
    if least is not None and least[0] > MAX_STRAIN:
        raise RodInputError(
            f"{n['axial_stiffness']} {loads.span.line.axial_stiffness:g}: hanging in "
            f"tension it stretches the line by about {100 * least[0]:.3g} % or more at its "
            f"top (a flexible cable's T + T^2/2EA >= w h, w h = {least[1]:.3g} N: the load "
            "times the ends' height apart), above "
            f"{100 * MAX_STRAIN:g} %, where the linear stretch models no line material; "
            "check EA (in N), or leave the line inextensible")
