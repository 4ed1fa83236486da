"""A system's result file (docs/output.md, "A system's result file") read into plain
arrays: the arguments of figures/system.py's figures and the report page's tables, from
the file alone (h5py and numpy; never PETSc)."""

import os
from dataclasses import dataclass

import h5py
import numpy as np

# The pose's columns of a sweep's group.
POSE = ("x", "y", "z", "roll", "pitch", "yaw")


def is_system_file(path):
    """Whether the HDF5 file ``path`` is a system's (a group ``system`` with its
    lines' names)."""
    with h5py.File(path, "r") as f:
        return "system" in f and "line_names" in f["system"].attrs


def names_of(text):
    """The names of a comma-separated text (empty parts dropped)."""
    return [name for name in str(text).split(",") if name]


@dataclass
class SystemFile:
    """A system's result file: ``picture`` the keyword arguments of
    figures.system.system_figure; ``bodies`` [{name, position (6,), stiffness (6, 6),
    reference (3,), moment (3,), asymmetry}]; ``lines`` [{name, start, end,
    end_tensions (2,), end_forces (2, 3), max_tension, grounded_length (NaN: none),
    stable}]; ``watch_circle``, ``excursion``: the sweep's arrays (``sweep``) or None;
    ``attributes`` the group ``system``'s; ``modes`` the group ``system/modes``'s
    arrays and attributes (the bodies' and free points' modes), or None."""

    path: str
    name: str
    picture: dict
    bodies: list
    lines: list
    watch_circle: dict
    excursion: dict
    attributes: dict
    modes: dict = None


def sweep(group):
    """{name: array} of a sweep's group (its datasets over its attributes of the same
    name), with ``poses`` (k, 6), ``lines`` its lines'
    names and the attributes; for the load-excursion curves also the (h, m) arrays
    ``grid_*`` (NaN where a case had no equilibrium: in memory, for a graph only)."""
    found = {key: group.attrs[key] for key in group.attrs}
    found.update({name: group[name][()] for name in group})      # a row's load, not the
    # watch circle's attribute of the same name
    found["poses"] = np.stack([found[k] for k in POSE], axis=1) if found["heading"].size \
        else np.zeros((0, 6))
    found["lines"] = names_of(group.attrs["line_names"])
    if "min_grounded" not in found:
        found["min_grounded"] = np.full(found["heading"].shape, np.nan)
    if "offset" in found:                           # the load-excursion curves
        headings = np.unique(np.concatenate([found["heading"], found["failed_heading"]]))
        loads = np.unique(np.concatenate([found["load"], found["failed_load"]]))
        h = np.searchsorted(headings, found["heading"])
        m = np.searchsorted(loads, found["load"])
        for name in ("offset", "restoring", "max_tension", "min_grounded", "verdict"):
            if name not in found:       # a file written before the sweeps' verdicts
                continue
            grid = np.full((headings.size, loads.size), np.nan)
            grid[h, m] = found[name]
            found[f"grid_{name}"] = grid
        found["grid_headings"], found["grid_loads"] = headings, loads
    return found


def read_system(path):
    """The SystemFile of ``path``."""
    with h5py.File(path, "r") as f:
        system = f["system"]
        attributes = {key: system.attrs[key] for key in system.attrs}
        names = names_of(attributes["line_names"])
        starts = names_of(attributes.get("line_starts", ""))
        ends = names_of(attributes.get("line_ends", ""))
        centrelines = {name: f[f"lines/{name}/r"][()] for name in names}
        point_names = names_of(attributes["point_names"])
        kinds = names_of(attributes.get("point_kinds", "")) or ["fixed"] * len(point_names)
        points = [(name, kind, position) for name, kind, position
                  in zip(point_names, kinds, system["point_positions"][()])]
        bodies, drawn = [], []
        for k, name in enumerate(names_of(attributes["body_names"])):
            fairleads = [centrelines[line][0] for line, to in zip(names, starts) if to == name]
            fairleads += [centrelines[line][-1] for line, to in zip(names, ends) if to == name]
            position = system["body_positions"][k]
            drawn.append((name, position[:3], np.array(fairleads).reshape(-1, 3)))
            bodies.append({"name": name, "position": position,
                           "stiffness": system["body_stiffness"][k],
                           "reference": system["body_stiffness_reference"][k],
                           "moment": system["body_stiffness_moment"][k],
                           "asymmetry": float(system["body_stiffness_asymmetry"][k])})
        lines = []
        for k, name in enumerate(names):
            group = f[f"lines/{name}"]
            grounded = group.attrs.get("grounded_length", np.nan)
            lines.append({"name": name, "start": starts[k] if starts else "",
                          "end": ends[k] if ends else "",
                          "end_tensions": system["end_tensions"][k],
                          "end_forces": system["end_forces"][k],
                          "max_tension": float(np.max(group["effective_tension"][()])),
                          "grounded_length": float(grounded),
                          "stable": int(group.attrs.get("stable", -1))})
        picture = {"lines": centrelines, "points": points, "bodies": drawn,
                   "seabed": attributes.get("seabed"),
                   "surface": float(attributes.get("surface", 0.0))}
        sweeps = {name: sweep(system[name]) if name in system else None
                  for name in ("watch_circle", "excursion")}
        modes = ({**{key: group[key][()] for key in group},
                  **{key: group.attrs[key] for key in group.attrs}}
                 if (group := system.get("modes")) is not None else None)
    name = os.path.basename(path).removesuffix(".h5")
    return SystemFile(path, name, picture, bodies, lines, sweeps["watch_circle"],
                      sweeps["excursion"], attributes, modes)


def figures(found):
    """{suffix: matplotlib Figure} of the SystemFile ``found``: '' the plan and the
    elevation, '_watch_circle' and '_excursion' where the file holds them."""
    from petsc_rod.figures.system import (excursion_figure, system_figure,
                                          watch_circle_figure)
    drawn = {"": system_figure(**found.picture, title=f"{found.name}: plan and elevation")}
    circle = found.watch_circle
    if circle is not None and circle["heading"].size:
        drawn["_watch_circle"] = watch_circle_figure(
            np.stack([circle["x_offset"], circle["y_offset"]], axis=1), circle["heading"],
            circle["max_tension"], circle["min_grounded"], float(circle["load"][0]),
            str(circle["body"]), saddle=_saddle(circle.get("verdict")))
    curves = found.excursion
    if curves is not None and curves["heading"].size:
        drawn["_excursion"] = excursion_figure(
            curves["grid_offset"], curves["grid_restoring"], curves["grid_headings"],
            curves["grid_max_tension"], curves["grid_min_grounded"], str(curves["body"]),
            saddle=_saddle(curves.get("grid_verdict")))
    return drawn


def _saddle(verdict):
    """The cases whose ``verdict`` (the file's codes; None: a file without them) says
    a saddle of the system (0), or None."""
    return None if verdict is None else np.asarray(verdict) == 0
