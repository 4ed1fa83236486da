"""A body's load-excursion curves and watch circle (docs/systems.md, "Excursions and the
watch circle"): the system re-solved under a horizontal load on one body, of given
magnitudes turned through given headings, each equilibrium warm from the last
(SystemSolver.solve: the lines walked from where they stand, the load continued from
the last one), with the largest tension and the smallest grounded length of the lines
at each.

With e_h = (cos h, sin h, 0) the heading's direction and F the magnitude, the body's
load is its own ``load`` (the system's: a mean wind, a current's drag) plus
F (e_h, 0, 0, 0); the reference is the equilibrium under its own load alone (the rest,
X_0). At each equilibrium:

    offset     (X - X_0) . e_h                               m
    restoring  -(F_lines - F_lines,0) . e_h                  N

F_lines the sum of the lines' forces on the body (global axes) and F_lines,0 that at the
reference: the mooring's restoring force along the heading, equal to F where nothing
else horizontal acts on the body (its hydrostatics and weight act in heave, roll and
pitch). The slope d restoring / d offset at F = 0 is the inverse of the compliance
(K^-1)_hh of the body's free degrees of freedom (K: BodyStiffness.matrix and the
hydrostatics'), K_xx itself when the body's other degrees of freedom are held or
uncoupled.

At each equilibrium, the system's own verdict (SystemSolver.solve's
Equilibrium.verdict, system/verdict.py: computed by every solve, so recorded here at no
cost): ``stable`` 1 a strict local minimiser of the system's potential, 0 a saddle of
the system (a warm Newton under a large load can land on one: its numbers are kept and
the case is marked), -1 no verdict (not conservative, or neutral to round-off), and
the lowest eigenvalue of its scaled stiffness, N/m (NaN where there is none).

A load on a body held where it pushes it (Body.held in x or y along a heading: a
Coupled, CoupledPinned or Fixed body of a MoorDyn file) moves nothing: its position
there is imposed. A sweep none of whose headings moves the body (every offset 0 m,
every case the rest) is refused (held_text) before anything is solved.

A case no equilibrium is found for (the solver's RodDivergedError: a line that cannot
reach, a load beyond what the lines hold) is a gap in the results (NaN, its reason in
``failed``), and the next case starts from the last equilibrium found.

Every function is collective on the solver's communicator and returns the same numbers
on every rank; it leaves the solver at rest again (its system solved anew at the end),
so that the solver's ``system``, which the loads are added to, is the same base case
for the next call.
"""

from dataclasses import dataclass, field, replace

import numpy as np

from petsc_rod.errors import RodDivergedError, RodInputError
from petsc_rod.system.outputs import line_summaries

# Units of the results' arrays.
UNITS = {"headings": "deg", "loads": "N", "load": "N", "poses": "m, rad",
         "offsets": "m", "restoring": "N", "max_tension": "N", "min_grounded": "m",
         "stable": "1", "lowest_eigenvalue": "N/m"}
# Units of the columns of the results' tables (``table()``).
TABLE_UNITS = {"heading": "deg", "load": "N", "offset": "m", "restoring": "N",
               "x_offset": "m", "y_offset": "m", "x": "m", "y": "m", "z": "m",
               "roll": "rad", "pitch": "rad", "yaw": "rad", "max_tension": "N",
               "max_tension_line": "", "min_grounded": "m", "min_grounded_line": "",
               "verdict": "", "lowest_eigenvalue": "N/m"}
POSE = ("x", "y", "z", "roll", "pitch", "yaw")
# A heading's direction cosine along x or y below this is none (cos 90 deg in floating
# point is 6e-17): the load does not push the body along that axis.
NO_PUSH = 1e-12
# The table's ``verdict`` words of the ``stable`` codes (SystemVerdict.code: the result
# file's system_stable).
VERDICT_WORDS = {1: "stable", 0: "saddle", -1: "none"}


@dataclass(frozen=True)
class Worst:
    """What every excursion reports at each of its equilibria (arrays of one shape):
    ``max_tension`` N, the largest effective tension of any line, and
    ``max_tension_line`` its index in ``lines`` (the lines' names); ``min_grounded`` m,
    the smallest grounded length of a line on the seabed (NaN: no line has a seabed),
    and ``min_grounded_line``; ``rest`` (6,) the reference pose (x, y, z m, roll,
    pitch, yaw rad); ``units`` of the arrays; ``failed`` ((heading deg, load N,
    why), ...) the cases no equilibrium was found for (RodDivergedError's message),
    NaN in every array (and -1 in the line indices), the next case solved from the
    last equilibrium; the system's verdict at each equilibrium (module docstring):
    ``stable`` 1, 0 a saddle, -1 none (and at a failed case), ``lowest_eigenvalue``
    N/m (NaN: none), ``no_verdict`` why a case has none ('' where each has one; default
    for all three: no verdict)."""

    body: str
    headings: np.ndarray
    poses: np.ndarray
    failed: tuple
    max_tension: np.ndarray
    max_tension_line: np.ndarray
    min_grounded: np.ndarray
    min_grounded_line: np.ndarray
    rest: np.ndarray
    lines: tuple
    units: dict
    stable: np.ndarray = field(default=None, kw_only=True)
    lowest_eigenvalue: np.ndarray = field(default=None, kw_only=True)
    no_verdict: str = field(default="", kw_only=True)

    def __post_init__(self):
        shape = np.shape(self.max_tension)
        if self.stable is None:
            object.__setattr__(self, "stable", np.full(shape, -1))
        if self.lowest_eigenvalue is None:
            object.__setattr__(self, "lowest_eigenvalue", np.full(shape, np.nan))

    def cases(self):
        """[(heading deg, load N)] of every case, in the arrays' order (raveled)."""
        raise NotImplementedError

    @staticmethod
    def where(cases):
        """The words of ``cases`` [(heading deg, load N)]: the subclasses'."""
        raise NotImplementedError

    def saddles(self):
        """[(heading deg, load N)] of the cases that are saddles of the system."""
        cases = self.cases()
        return [cases[k] for k in np.flatnonzero(self.stable.ravel() == 0)]

    def verdict_text(self):
        """The verdicts over the cases with an equilibrium in words: 'all stable', or
        '; '-separated 'N saddle(s) of the system: headings 90, 105 deg' (the curves':
        'heading 180 deg under 60000, 80000 N'), 'N stable', 'M without a verdict: why'
        ('no verdict: why' where no case has one)."""
        solved = np.isfinite(self.poses.reshape(-1, 6)[:, 0])
        codes = self.stable.ravel()[solved]
        if not codes.size:
            return "no equilibrium"
        if np.all(codes == 1):
            return "all stable"
        parts = []
        saddles = self.saddles()
        if saddles:
            parts.append(f"{len(saddles)} saddle(s) of the system: "
                         f"{self.where(saddles)}")
        stable = int(np.count_nonzero(codes == 1))
        if stable:
            parts.append(f"{stable} stable")
        none = int(np.count_nonzero(codes == -1))
        if none:
            parts.append(("no verdict" if none == codes.size else
                          f"{none} without a verdict")
                         + (f": {self.no_verdict}" if self.no_verdict else ""))
        return "; ".join(parts)

    def _worst(self, values, lines, pick):
        """(value, index into the arrays, line name) of ``pick`` (np.nanargmax or
        np.nanargmin) over ``values``; (NaN, None, None) when all are NaN."""
        if np.all(np.isnan(values)):
            return np.nan, None, None
        index = np.unravel_index(int(pick(values)), values.shape)
        return float(values[index]), index, self.lines[int(lines[index])]

    def _table(self, first):
        """{column: (k,) array}: the columns ``first`` then the pose, the system's
        verdict (``verdict`` stable, saddle or none: VERDICT_WORDS) and its lowest
        eigenvalue, and the worst lines' numbers, a row per case (TABLE_UNITS; a
        line's name, "" where none)."""
        names = np.array(list(self.lines) + [""], dtype=object)
        table = dict(first)
        table.update(zip(POSE, self.poses.reshape(-1, 6).T))
        table.update(verdict=np.array([VERDICT_WORDS[int(c)] for c in self.stable.ravel()],
                                      dtype=object),
                     lowest_eigenvalue=self.lowest_eigenvalue.ravel(),
                     max_tension=self.max_tension.ravel(),
                     max_tension_line=names[self.max_tension_line.ravel()],
                     min_grounded=self.min_grounded.ravel(),
                     min_grounded_line=names[self.min_grounded_line.ravel()])
        return table


@dataclass(frozen=True)
class LoadExcursion(Worst):
    """Load-excursion curves of ``body``: for each of ``headings`` (h,), deg from +x
    toward +y, and each of ``loads`` (m,), N, in the order solved: ``poses`` (h, m, 6),
    ``offsets`` (h, m) m and ``restoring`` (h, m) N along the heading (module
    docstring), and Worst's arrays (h, m)."""

    loads: np.ndarray
    offsets: np.ndarray
    restoring: np.ndarray

    def table(self):
        """{column: (h m,) array}, a row per heading and load (TABLE_UNITS)."""
        heading, load = np.meshgrid(self.headings, self.loads, indexing="ij")
        return self._table({"heading": heading.ravel(), "load": load.ravel(),
                            "offset": self.offsets.ravel(),
                            "restoring": self.restoring.ravel()})

    def _at(self, value, index, line):
        if index is None:
            return value, np.nan, np.nan, None
        return value, float(self.headings[index[0]]), float(self.loads[index[1]]), line

    def cases(self):
        return [(float(h), float(f)) for h in self.headings for f in self.loads]

    @staticmethod
    def where(cases):
        """'heading 180 deg under 60000, 80000 N; ...' of ``cases``, by heading."""
        headings = list(dict.fromkeys(h for h, _ in cases))
        return "; ".join(f"heading {h:g} deg under "
                         + ", ".join(f"{f:.6g}" for g, f in cases if g == h) + " N"
                         for h in headings)

    @property
    def largest_tension(self):
        """(N, heading deg, load N, line name) of the largest tension over the curves;
        NaN and None when no line reports one."""
        return self._at(*self._worst(self.max_tension, self.max_tension_line,
                                     np.nanargmax))

    @property
    def smallest_grounded(self):
        """(m, heading deg, load N, line name) of the smallest grounded length over the
        curves; NaN and None when no line has a seabed."""
        return self._at(*self._worst(self.min_grounded, self.min_grounded_line,
                                     np.nanargmin))


@dataclass(frozen=True)
class WatchCircle(Worst):
    """The watch circle of ``body`` under a horizontal ``load`` (N) turned through
    ``headings`` (h,), deg: ``poses`` (h, 6), ``offsets`` (h, 2) the reference point's
    horizontal displacement (x, y) from the rest, m, and Worst's arrays (h,)."""

    load: float
    offsets: np.ndarray

    def table(self):
        """{column: (h,) array}, a row per heading (TABLE_UNITS)."""
        return self._table({"heading": self.headings,
                            "load": np.full(self.headings.size, self.load),
                            "x_offset": self.offsets[:, 0], "y_offset": self.offsets[:, 1]})

    @property
    def largest_offset(self):
        """The largest horizontal offset over the headings, m."""
        return float(np.nanmax(np.linalg.norm(self.offsets, axis=1)))

    def _at(self, value, index, line):
        return value, (np.nan if index is None else float(self.headings[index[0]])), line

    def cases(self):
        return [(float(h), self.load) for h in self.headings]

    @staticmethod
    def where(cases):
        """'headings 90, 105 deg' of ``cases``."""
        return (f"heading{'s' if len(cases) > 1 else ''} "
                + ", ".join(f"{h:g}" for h, _ in cases) + " deg")

    @property
    def largest_tension(self):
        """(N, heading deg, line name) of the largest tension over the headings;
        (NaN, NaN, None) when no line reports one."""
        return self._at(*self._worst(self.max_tension, self.max_tension_line,
                                     np.nanargmax))

    @property
    def smallest_grounded(self):
        """(m, heading deg, line name) of the smallest grounded length over the
        headings; (NaN, NaN, None) when no line has a seabed."""
        return self._at(*self._worst(self.min_grounded, self.min_grounded_line,
                                     np.nanargmin))


def extremes(summaries):
    """(largest tension N, its line, smallest grounded length m, its line) over the
    lines' ``summaries``: NaN and -1 where no line reports one."""
    tension = np.array([s.get("max_tension", np.nan) for s in summaries], dtype=float)
    grounded = np.array([s.get("grounded_length", np.nan) for s in summaries], dtype=float)
    picked = []
    for values, pick in ((tension, np.nanargmax), (grounded, np.nanargmin)):
        if values.size and not np.all(np.isnan(values)):
            k = int(pick(values))
            picked += [values[k], k]
        else:
            picked += [np.nan, -1]
    return tuple(picked)


def lines_force(solver, index):
    """The sum of the lines' forces on body ``index`` at the solver's state, (3,), N."""
    ends = solver.layout.body_end == index
    return solver.forces[ends].sum(axis=0)


def loaded(system, body, force):
    """``system`` with the horizontal ``force`` (3,), N, added to ``body``'s load."""
    bodies = tuple(replace(b, load=tuple(np.asarray(b.load, dtype=float)
                                         + np.concatenate([force, np.zeros(3)])))
                   if b.name == body else b for b in system.bodies)
    return replace(system, bodies=bodies)


def held_text(body, headings):
    """Why a horizontal load along ``headings`` (deg) cannot sweep the Body ``body``: at
    no heading does the direction e_h = (cos h, sin h, 0) push it along an axis among x
    and y that it leaves free (a cosine above NO_PUSH on an axis Body.held does not
    hold), so its position is imposed wherever the load pushes it and every offset
    would be 0 m; '' where some heading moves it (a body held in x alone is swept at
    any heading but 0 and 180 deg, where its offset is 0)."""
    angles = np.radians(np.asarray(headings, dtype=float).ravel())
    pushed = np.abs([np.cos(angles), np.sin(angles)]) > NO_PUSH            # (2, headings)
    holds = np.asarray(body.held[:2], dtype=bool)
    if np.any(pushed & ~holds[:, None]):
        return ""
    held = [axis for axis, push, hold in zip("xy", pushed.any(axis=1), holds)
            if push and hold]
    if not held:
        return ""
    return (f"body {body.name} is held in {' and '.join(held)} (Coupled, CoupledPinned "
            "or Fixed in a MoorDyn file; Body.held): its position there is imposed, so "
            "the load moves it at no heading and every offset would be 0 m; sweep a "
            "body free where the load pushes it (Free in the file)")


def _direction(heading):
    angle = np.radians(heading)
    return np.array([np.cos(angle), np.sin(angle), 0.0])


def _cases(solver, body, cases):
    """Solve ``cases`` [(heading deg, magnitude N)] in order, after the rest: (rest
    pose (6,), poses (k, 6), lines' force on the body (k, 3) and at rest (3,),
    extremes (k, 4), failed, verdicts: each case's SystemVerdict, None where it
    failed)."""
    base = solver.system
    names = [b.name for b in base.bodies]
    if body not in names:
        raise RodInputError(f"excursions: no body is named {body!r}; the system's bodies: "
                            f"{', '.join(names) or 'none'}")
    index = names.index(body)
    held = held_text(base.bodies[index], [heading for heading, _ in cases])
    if held:
        raise RodInputError(f"excursions: {held}")
    rest = solver.solve(base).bodies[body].copy()
    rest_force = lines_force(solver, index)
    poses, forces, worst, failed, verdicts = [], [], [], [], []
    for heading, magnitude in cases:
        saved = solver.state
        try:
            result = solver.solve(loaded(base, body, magnitude * _direction(heading)))
        except RodDivergedError as error:
            # the next case starts from the last equilibrium, as if this one was not asked
            solver.state = saved
            failed.append((float(heading), float(magnitude), str(error)))
            poses.append(np.full(6, np.nan))
            forces.append(np.full(3, np.nan))
            worst.append((np.nan, -1, np.nan, -1))
            verdicts.append(None)
            continue
        poses.append(result.bodies[body].copy())
        forces.append(lines_force(solver, index))
        worst.append(extremes(line_summaries(solver)))
        verdicts.append(result.verdict)
    solver.solve(base)
    return rest, np.array(poses).reshape(-1, 6), np.array(forces).reshape(-1, 3), \
        rest_force, np.array(worst, dtype=float).reshape(-1, 4), tuple(failed), verdicts


def load_excursion(solver, body, loads, headings=(0.0,)):
    """The LoadExcursion of ``body`` (a name) of the SystemSolver ``solver`` under the
    horizontal ``loads`` (m,), N, at each of ``headings`` (h,), deg: for each heading
    the loads in the order given (from small to large, so that each equilibrium starts
    from its neighbour's), after the rest. Collective."""
    loads = np.asarray(loads, dtype=float).ravel()
    headings = np.asarray(headings, dtype=float).ravel()
    cases = [(h, f) for h in headings for f in loads]
    rest, poses, forces, rest_force, worst, failed, verdicts = _cases(solver, body,
                                                                        cases)
    shape = (headings.size, loads.size)
    e = np.array([_direction(h) for h in headings])                  # (h, 3)
    poses = poses.reshape(shape + (6,))
    offsets = np.einsum("hmi,hi->hm", poses[..., :3] - rest[:3], e)
    restoring = -np.einsum("hmi,hi->hm", forces.reshape(shape + (3,)) - rest_force, e)
    return LoadExcursion(**_worst(solver, body, headings, poses, rest,
                                  worst.reshape(shape + (4,)), failed, verdicts, shape),
                         loads=loads, offsets=offsets, restoring=restoring)


def watch_circle(solver, body, load, headings=np.arange(0.0, 360.0, 15.0)):
    """The WatchCircle of ``body`` of ``solver`` under a horizontal ``load`` (N) turned
    through ``headings`` (deg), one after the next (each equilibrium warm from the
    last), after the rest. Collective."""
    headings = np.asarray(headings, dtype=float).ravel()
    rest, poses, _, _, worst, failed, verdicts = _cases(
        solver, body, [(h, float(load)) for h in headings])
    return WatchCircle(**_worst(solver, body, headings, poses, rest, worst, failed,
                                verdicts, headings.shape),
                       load=float(load), offsets=poses[:, :2] - rest[:2])


def _worst(solver, body, headings, poses, rest, worst, failed, verdicts, shape):
    """Worst's fields from the extremes ``worst`` (..., 4) and the cases' ``verdicts``
    (SystemVerdict or None, raveled; ``shape`` the cases')."""
    reasons = [v.reason for v in verdicts if v is not None and v.stable is None]
    return dict(body=body, headings=headings, poses=poses, failed=failed,
                stable=np.array([-1 if v is None else v.code() for v in verdicts],
                                dtype=int).reshape(shape),
                lowest_eigenvalue=np.array([np.nan if v is None else v.lowest
                                            for v in verdicts], dtype=float).reshape(shape),
                no_verdict=reasons[0] if reasons else "",
                max_tension=worst[..., 0],
                max_tension_line=worst[..., 1].astype(int), min_grounded=worst[..., 2],
                min_grounded_line=worst[..., 3].astype(int), rest=rest,
                lines=tuple(line.name for line in solver.system.lines), units=UNITS)
