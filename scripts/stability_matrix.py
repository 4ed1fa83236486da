"""The matrix of hard cases of docs/stability.md: each case run as a user runs it, judged.

    python scripts/stability_matrix.py [--before] [--only NAME,...] [--ci] [--out DIR]

Every case is a list of -rod_* options, run in a child process exactly as a user runs
petsc_rod (``python -m petsc_rod``, or ``mpiexec -n 2 python -m petsc_rod`` for the
2-rank cases) with its result written to a file. The exit code gives the outcome:

- converged (exit 0) and, where a closed form or the independent reference exists, the
  error against it within the case's bound: **converged**;
- converged but the error above the bound: **WRONG** (a wrong answer handed back as
  right: the one outcome that must never happen), or **warned** when the run printed a
  warning that its state may be that far from the solution (a slowly contracting
  iteration stopped by the change test);
- exit 3 (not converged, file marked converged = 0) or 4 (diverged, NaN, KSP failure,
  no file), with the program's one-line reason: **stopped**;
- anything else (a crash, a timeout, a converged run without a file): **failed**.

Writes DIR/cases.csv (or cases_before.csv), and the case table into docs/stability.md
between the markers ``<!-- matrix:begin -->`` and ``<!-- matrix:end -->`` (or
``<!-- before:begin -->``/``<!-- before:end -->``). ``--before`` runs every case with the
first measures of docs/stability.md switched off (the old default penalty
400 max(K)/L^2, the straight start, no step halving, no link check, no raise of a low
penalty): the "before" table of docs/stability.md (History B). ``--only`` reruns the cases whose names contain one of the words
and merges them into the CSV and the table of the last full run. ``--ci`` runs the
small subset the tests run on 1 and 2 ranks (tests/system/test_stability_matrix.py), printed,
not written. The full
matrix takes about two minutes on two cores, half of it the 10^6-element catenary.
"""

import argparse
import csv
import math
import os
import re
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))

from petsc_rod.scenes.touchdown import grounded_catenary  # noqa: E402
from petsc_rod.validation import closed_forms  # noqa: E402
from petsc_rod.validation.writhe import gauss_writhe  # noqa: E402

TIMEOUT = 1800.0          # s per case; beyond it the case is "failed (timeout)"
COLUMNS = ("group", "case", "ranks", "elements", "outcome", "reason", "iterations",
           "constraint_residual", "wall_time", "error", "bound", "what")

# --------------------------------------------------------------------- the cases


@dataclass
class Case:
    """One hard case: options, rank count, and how to judge its result.

    ``check(result)`` returns (error, bound, what) from the result file's datasets and
    attributes, or None where nothing independent is known (the outcome then rests on
    the solver's own convergence report). ``needs`` names a case whose result file is
    this one's -rod_initial.
    """

    group: str
    name: str
    options: dict
    check: object = None
    ranks: int = 1
    needs: str = None
    ci: bool = False
    notes: str = ""

    @property
    def elements(self):
        return int(float(self.options.get("elements", 64)))


def option_list(options):
    """{'length': 1, ...} -> ['-rod_length', '1', ...]."""
    words = []
    for key, value in options.items():
        words += ["-options_file" if key == "options_file" else f"-rod_{key}", str(value)]
    return words


def max_error(a, b):
    return float(np.max(np.linalg.norm(np.asarray(a) - np.asarray(b), axis=-1)))


# A cantilever bent about its weak axis d1 (the tip force along -z, d1 = e_y): a planar
# elastica with EI = K1 whatever K2 and K3 are (bending about the stiff axis d2 would
# buckle sideways, lateral-torsional buckling, and has no planar closed form).
CANTILEVER_LOAD = 3.0              # P L^2 / K1


def cantilever(K2=1.0, K3=1.0, elements=32, **overrides):
    options = {"length": 1, "stiffness": f"1,{K2:g},{K3:g}", "start": "clamp",
               "end": "free", "end_force": f"0,0,{-CANTILEVER_LOAD:g}",
               "elements": elements, "steps": 2, "al_rtol": 1e-7, "al_ctol": 1e-5,
               "al_max_it": 10000}
    options.update(overrides)
    return options


def check_cantilever(bound):
    def check(result):
        tip = closed_forms.cantilever_tip(1.0, 1.0, CANTILEVER_LOAD)
        exact = np.array([tip[0], 0.0, tip[1]])      # the -y deflection, turned to -z
        return max_error(result["r"][-1], exact), bound, "tip position vs elastica, m"
    return check


def twist(K3=1.0, angle=1.0, elements=32, **overrides):
    options = {"length": 1, "stiffness": f"1,1,{K3:g}", "start": "clamp", "end": "clamp",
               "end_twist": angle, "elements": elements, "steps": 2, "al_rtol": 1e-8,
               "al_ctol": 1e-6, "al_max_it": 20000}
    options.update(overrides)
    return options


def check_twist(angle, K3, bound):
    def check(result):
        exact = 0.5 * K3 * angle**2               # W = K3 angle^2 / 2L, L = 1
        straight = np.outer(result["S"], [1.0, 0.0, 0.0])
        error = max(abs(float(result["energy"]) - exact) / exact,
                    max_error(result["r"], straight))
        return error, bound, "max(|W - K3 angle^2/2L| / W, |r - S e_x|)"
    return check


def hermite_points(S, r, tangent, per_element=8):
    """The C^1 cubic through the vertices (r, r' = tangent), sampled per_element times
    per element: (N per_element + 1, 3)."""
    x = np.linspace(0.0, 1.0, per_element, endpoint=False)[None, :, None]
    h = np.diff(S)[:, None, None]
    r0, r1, t0, t1 = r[:-1, None], r[1:, None], tangent[:-1, None], tangent[1:, None]
    points = ((2 * x**3 - 3 * x**2 + 1) * r0 + (x**3 - 2 * x**2 + x) * h * t0
              + (3 * x**2 - 2 * x**3) * r1 + (x**3 - x**2) * h * t1)
    return np.concatenate([points.reshape(-1, 3), r[-1:]])


def transported_twist(d1, d3):
    """Twist (turns) of vertex frames: over each element, the angle about d3 from d1
    carried by the least rotation taking d3 to the next vertex's (parallel transport
    across the element) to the next d1. (The vertex u3 of the file, a mean of the limits
    of discontinuous P2 strains, integrates by the trapezoid rule to 6e-3 turns off at
    2 turns on 64 elements; this is 3e-4 off.)"""
    a, b = d3[:-1], d3[1:]
    axis = np.cross(a, b)
    sine, cosine = np.linalg.norm(axis, axis=1), np.einsum("ij,ij->i", a, b)
    axis = axis / np.where(sine > 0, sine, 1.0)[:, None]
    v = d1[:-1]
    carried = (v * cosine[:, None] + np.cross(axis, v) * sine[:, None]
               + axis * np.einsum("ij,ij->i", axis, v)[:, None] * (1 - cosine)[:, None])
    angle = np.arctan2(np.einsum("ij,ij->i", np.cross(carried, d1[1:]), b),
                       np.einsum("ij,ij->i", carried, d1[1:]))
    return float(angle.sum() / (2 * math.pi))


def check_link(turns, bound):
    """Calugareanu-White: Tw + Wr, with Tw from the file's vertex frames
    (transported_twist) and Wr the Gauss double integral of its centreline, the cubic
    through its vertices (validation.writhe.gauss_writhe): both independent of the
    solver's own Tw + Wr (Gauss points, Fuller's formula). Against the end roll in turns."""
    def check(result):
        twist = transported_twist(result["d1"], result["d3"])
        writhe = gauss_writhe(hermite_points(result["S"], result["r"], result["d3"]),
                              [1.0, 0.0, 0.0])
        return (abs(twist + writhe - turns), bound,
                f"|Tw + Wr - {turns:g}| turns; Wr = {writhe:.4f} turns (Gauss integral)")
    return check


def check_straight(bound):
    def check(result):
        straight = np.outer(result["S"], [1.0, 0.0, 0.0])
        return max_error(result["r"], straight), bound, "|r - S e_x| (taut: straight), m"
    return check


# Small deformations (docs/method.md §6: the stopping test measures the change and the
# residual against the size of the deformation): the default tolerances, a cantilever
# with a tip force along -y and a clamped-clamped rod twisted by a tiny angle, judged
# against linear theory, exact to O((P L^2 / EI)^2) and O(angle^2) here (the elastica's
# closed form loses ~1e-8 to cancellation at such loads).
def small_cantilever(length, stiffness, force):
    return {"length": length, "stiffness": f"{stiffness:g},{stiffness:g},{stiffness:g}",
            "start": "clamp", "end": "free", "end_force": f"0,{-force:g},0",
            "elements": 16, "steps": 2}


def check_small_cantilever(length, stiffness, force, bound):
    def check(result):
        exact = force * length**3 / (3 * stiffness)         # P L^3 / 3 EI
        error = abs(-float(result["r"][-1][1]) - exact) / exact
        return error, bound, f"|deflection - P L^3/3EI| / (P L^3/3EI), P L^3/3EI = {exact:.3g} m"
    return check


def check_small_twist(angle, bound):
    def check(result):
        u3 = np.asarray(result["u"])[:, 2]              # u3 = angle / L, L = 1
        return (float(np.max(np.abs(u3 - angle))) / angle, bound,
                f"max |u3 - angle/L| / (angle/L), angle = {angle:g} rad")
    return check


CATENARY = {"length": 3000, "stiffness": "1e5,1e5,7.5e4", "start": "pin", "end": "pin",
            "end_position": "2500,0,0", "load": "0,0,-1000", "al_rtol": 1e-10,
            "al_ctol": 1e-7, "al_max_it": 20000}
# Away from the ends: 30 m, 100 boundary-layer widths sqrt(EI/T) = 0.29 m.
CATENARY_INTERIOR = 30.0


def catenary(elements, **overrides):
    options = dict(CATENARY, elements=elements, initial_shape="catenary")
    options.update(overrides)
    return options


def check_catenary(bound):
    def check(result):
        S = result["S"]
        exact, _, _ = closed_forms.catenary(3000.0, np.array([2500.0, 0.0, 0.0]),
                                            np.array([0.0, 0.0, -1000.0]), S)
        inside = (S > CATENARY_INTERIOR) & (S < 3000.0 - CATENARY_INTERIOR)
        return (max_error(result["r"][inside], exact[inside]), bound,
                "r vs inextensible catenary, 30 m from the ends, m")
    return check


# Risers (docs/riser.md): 1800 m of line of 1.2 kN/m from an anchor on the seabed z = 0
# to a pin 1000 m up. EI = 1e4 N m^2 (a bending length sqrt(EI / H) of 0.2 m or less),
# so that the catenary with touchdown (scenes/touchdown.py) is the reference 20 m away from
# the touchdown point and the ends.
RISER = {"length": 1800, "stiffness": "1e4,1e4,7.5e3", "start": "pin", "end": "pin",
         "end_position": "1157,0,1000", "load": "0,0,-1200", "seabed": 0,
         "elements": 1800, "initial_shape": "catenary"}
RISER_ZONE = 20.0


def riser(**overrides):
    options = dict(RISER)
    options.update(overrides)
    return options


def check_grounded(end_position, bound):
    """r against the catenary with touchdown to ``end_position`` (text x,y,z)."""
    chord = np.array([float(v) for v in end_position.split(",")])

    def check(result):
        S = result["S"]
        exact, _, _, (_, touchdown) = grounded_catenary(1800.0, chord, 1200.0, 0.0, S)
        away = ((np.abs(S - touchdown) > RISER_ZONE) & (S > RISER_ZONE)
                & (S < 1800.0 - RISER_ZONE))
        return (max_error(result["r"][away], exact[away]), bound,
                "r vs catenary with touchdown, 20 m from it and the ends, m")
    return check


# A weightless 100 m line pinned 80 m apart in a current across it: the current catenary
# (tests/solver/test_riser.py).
CURRENT_LINE = {"length": 100, "stiffness": "1,1,1", "start": "pin", "end": "pin",
                "end_position": "80,0,0", "drag": "1025,1.2,0.1", "elements": 200,
                "al_rtol": 1e-10, "al_ctol": 1e-10}


def check_current_catenary(speed, bound):
    def check(result):
        drag = 0.5 * 1025 * 1.2 * 0.1 * speed**2
        exact, _, _ = closed_forms.catenary(100.0, np.array([80.0, 0.0, 0.0]),
                                            np.array([0.0, drag, 0.0]), result["S"])
        return (max_error(result["r"], exact), bound,
                "r vs the catenary of the normal drag, m")
    return check


# A sloping seabed (docs/riser.md §1a, §3a): the riser above on a plane rising (or
# falling) along +x, the plane of its ends, against the catenary on an incline
# (validation/incline_catenary.py), 20 m away from the touchdown point and the ends.
SEABED_PROFILE = "scripts/matrix_seabed_profile.txt"


def check_incline(slope_deg, bound):
    from petsc_rod.validation.incline_catenary import incline_catenary
    line = incline_catenary(1800.0, 1200.0, np.radians(slope_deg), 1157.0, 1000.0)

    def check(result):
        S = result["S"]
        x, z, _, _ = line.at(S)
        away = ((np.abs(S - line.grounded) > RISER_ZONE) & (S > RISER_ZONE)
                & (S < 1800.0 - RISER_ZONE))
        exact = np.stack([x, np.zeros_like(x), z], axis=1)
        return (max_error(result["r"][away], exact[away]), bound,
                "r vs the catenary on an incline, 20 m from the touchdown and the ends, m")
    return check


# Lines of line types and stretch (issue 22): the riser above, extensible, with EA / EI
# from 1e2 to 1e6 per m^2 (EA 1e7 N, 15 % stretch at the top, to 1e9 N, 0.15 %; EI at
# most 1e5 N m^2, a bending length of 0.4 m), against the elastic catenary with
# touchdown; a line whose middle section is ten times lighter; a bend stiffener 1000
# times stiffer than the cable at a stiff flex joint.
LINE_TYPES = "scripts/matrix_line_types.txt"


def check_elastic_grounded(axial_stiffness, bound):
    from petsc_rod.validation.elastic_catenary import elastic_catenary
    line = elastic_catenary(1800.0, 1200.0, axial_stiffness, 1157.0, 1000.0)

    def check(result):
        S = result["S"]
        x, z, _ = line.at(S)
        away = ((np.abs(S - line.grounded) > RISER_ZONE) & (S > RISER_ZONE)
                & (S < 1800.0 - RISER_ZONE))
        exact = np.stack([x, np.zeros_like(x), z], axis=-1)
        return (max_error(result["r"][away], exact[away]), bound,
                "r vs elastic catenary with touchdown, 20 m from it and the ends, m")
    return check


LIGHT_MIDDLE = {"line_types": LINE_TYPES, "sections": "heavy:400:400,light:200:200,heavy:400:400",
                "start": "pin", "end": "pin", "end_position": "700,0,300",
                "initial_shape": "catenary", "al_rtol": 1e-10, "al_ctol": 1e-10}


def check_section_catenary(bound):
    from petsc_rod.scenes.section_catenary import solve
    line = solve([0.0, 400.0, 600.0, 1000.0], [1000.0, 100.0, 1000.0], 700.0, 300.0,
                 on_seabed=False)

    def check(result):
        x, z, _ = line.at(result["S"])
        exact = np.stack([x, np.zeros_like(x), z], axis=-1)
        return (max_error(result["r"], exact), bound, "r vs the catenary of the sections, m")
    return check


PAPER = {"length": 20, "stiffness": "235,360,200", "start": "clamp", "end": "pin",
         "end_position": "16,4,0", "elements": 80, "al_penalty": 400, "al_rtol": 1e-7,
         "al_ctol": 1e-5, "al_max_it": 200000, "steps": 8, "imperfection": 0.01}


def check_paper_reference(bound, stiffness):
    """Against petsc_rod.validation.reference (collocation, solve_bvp) started from the result."""
    def check(result):
        from petsc_rod.validation import reference
        guess = reference.initial_guess_from_result(result["path"])
        S, r, frames, n, m = (guess[k] for k in ("S", "r", "frames", "n", "m"))
        bvp = reference.solve_rod_bvp(20.0, stiffness, r[-1], S, r, frames, n, m, tol=1e-10)
        if bvp.status != 0:
            return math.nan, bound, "reference (solve_bvp) did not converge"
        exact = bvp.sample(result["S"])["r"]
        return max_error(result["r"], exact), bound, "r vs collocation reference, m"
    return check


# Seabed friction (docs/riser.md §3b). A line lying on the seabed, 200 m of 100 N/m, EA
# 1e6 N, pinned at the anchor and pulled 5 kN along the seabed at its free end: the
# tension falls by mu w per metre from the pull and is 0 beyond the stick-slip front
# (tests/solver/test_seabed_friction.py); the default penalty F / 2 is too soft for the
# friction's stick springs (docs/riser.md §3b).
PULLED_LINE = {"length": 200, "stiffness": "1,1,1", "start": "pin", "end": "free",
               "end_force": "5000,0,0", "load": "0,0,-100", "seabed": 0,
               "seabed_stiffness": 1e6, "axial_stiffness": 1e6, "elements": 200,
               "al_penalty": 1e6}
# 100 m on the seabed pinned at both ends 100 m apart, EA 1e6 N, in a current across:
# drag c v^2 with c = 61.5 kg/m^2 against the friction mu w = 50 N/m at mu = 0.5, which
# a current of 0.902 m/s just overcomes.
GROUNDED_LINE = {"length": 100, "stiffness": "1,1,1", "start": "pin", "end": "pin",
                 "end_position": "100,0,0", "load": "0,0,-100", "seabed": 0,
                 "axial_stiffness": 1e6, "drag": "1025,1.2,0.1", "elements": 100,
                 "seabed_friction": 0.5}


def check_pulled(mu):
    """The bound is the model's own error: the stick's elastic zone at the front, where
    the slip is below mu w / k_s, is sqrt(2 EA / k_s) = 4.5 m long (k_s = 1e5 N/m^2, a
    tenth of the seabed's) and the tension there is off by up to half its drop."""
    bound = mu * 100.0 * np.sqrt(2 * 1e6 / 1e5) / 2 / 5000.0

    def check(result):
        exact = np.maximum(5000.0 - mu * 100.0 * (200.0 - result["S"]), 0.0)
        return (float(np.max(np.abs(result["effective_tension"] - exact))) / 5000.0, bound,
                "tension vs max(F - mu w (L - S), 0), over F")
    return check


def check_friction_bound(bound):
    """The friction nowhere above mu R: the largest |f|_mu / R less 1. The force is that
    of the last solve, whose secant spring is the previous positions': it exceeds mu R by
    the last iteration's move over the slip (1e-9 of 1800 m over a slip of a metre:
    2e-6), so the bound is 1e-5."""
    def check(result):
        return (float(result["friction_max_use"]) - 1.0, bound,
                "largest friction over its limit mu R, less 1")
    return check


def check_stuck(bound):
    """A line that sticks: its largest slip from where it lay (y = 0), m."""
    def check(result):
        return (float(np.max(np.abs(result["r"][:, 1]))), bound,
                "largest sideways slip, m (mobilisation mu w / k_s = 5 mm)")
    return check


def cases():
    """The matrix (docs/stability.md, "The cases")."""
    matrix = []
    add = matrix.append
    # stiffness ratios: K2/K1 on the weak-axis cantilever, K3/K1 on pure twist
    for ratio in (1, 10, 100, 1000):
        add(Case("stiffness", f"cantilever K2/K1 = {ratio}", cantilever(K2=ratio),
                 check_cantilever(1e-5),
                 notes="K2 > K1 + K3: non-convex split" if ratio > 2 else ""))
    for ratio in (0.01, 0.1, 1, 10):
        add(Case("stiffness", f"twist K3/K1 = {ratio:g}", twist(K3=ratio, elements=16),
                 check_twist(1.0, ratio, 1e-6), ci=ratio == 1,
                 notes="K3 > K1 + K2: non-convex split" if ratio > 2 else ""))
    add(Case("stiffness", "paper K3 = 200", PAPER, check_paper_reference(2e-3, (235, 360, 200))))
    add(Case("stiffness", "paper K3 = 100", dict(PAPER, stiffness="235,360,100"),
             check_paper_reference(1e-3, (235, 360, 100)), notes="non-convex split"))
    # penalty R from 1e-3 to 1e3 times the stiffness scale K/L^2 = 1
    for exponent in range(-3, 4):
        add(Case("penalty", f"cantilever R = 1e{exponent:+d} K/L^2",
                 cantilever(al_penalty=f"1e{exponent}"), check_cantilever(1e-5),
                 ci=exponent == 2))
    # tolerances
    for rtol in (1e-6, 1e-8, 1e-10):
        add(Case("tolerance", f"cantilever rtol = {rtol:g}, ctol = {100 * rtol:g}",
                 cantilever(al_penalty=100, al_rtol=rtol, al_ctol=100 * rtol, elements=64),
                 check_cantilever(1e-6 if rtol < 1e-7 else 1e-3)))
    add(Case("tolerance", "twist rtol = 1e-10, ctol = 1e-10",
             twist(elements=64, al_rtol=1e-10, al_ctol=1e-10), check_twist(1.0, 1.0, 1e-8)))
    add(Case("tolerance", "twist on 2 elements, rtol = ctol = 1e-12",
             twist(elements=2, al_rtol=1e-12, al_ctol=1e-12), check_twist(1.0, 1.0, 1e-3),
             ci=True))
    # nearly folded and taut
    folded = math.sqrt(0.5) * 0.2
    add(Case("folded", "paper, end 0.2 m (1% of L) from the clamp",
             dict(PAPER, end_position=f"{folded:.6f},{folded:.6f},0", steps=40,
                  al_max_it=20000),
             notes="no closed form"))
    add(Case("folded", "taut: the bent paper state pulled to r(L) = (20, 0, 0)",
             dict(PAPER, end_position="20,0,0", steps=1),
             check_straight(1e-6), needs="paper K3 = 200"))
    # large twist: Greenhill. The end moves to 0.9 L along the axis and 0.1 L to the side
    # (a rod shortened exactly along its axis is held straight by its symmetry in exact
    # arithmetic, docs/method.md §9) while it is rolled: the rod is bent from the start
    # and turns part of the twist into writhe. Judged by Calugareanu-White,
    # Lk = Tw + Wr = the end roll in turns (check_link). R = 100 is below the twist term
    # of the default penalty (2 M^2 / K = 316 N), where the former iteration lost a turn
    # of link (docs/stability.md, History C).
    greenhill = 2.861 * math.pi                  # clamped-clamped, K1 = K2 = K3
    for turns, steps, penalty in ((1.5, 15, None), (2.0, 20, None), (2.0, 20, 100)):
        angle = 2 * math.pi * turns
        options = twist(angle=f"{angle:.6f}", elements=64, end_position="0.9,0.1,0",
                        steps=steps, imperfection=0.01, al_rtol=1e-6, al_ctol=1e-5)
        name = f"clamped-clamped, end at (0.9, 0.1, 0) L, twist {angle:.3g} rad"
        if penalty is not None:
            options["al_penalty"] = penalty
            name += f", R = {penalty}"
        add(Case("twist", name, options, check_link(turns, 2e-3),
                 notes=f"beyond the Greenhill angle {greenhill:.3g} rad"))
    # small deformations at the default tolerances
    for name, (length, stiffness, force) in {
            "stiff cantilever, K = 1e8 N m^2, P = 3 N": (1.0, 1e8, 3.0),
            "short cantilever, L = 1 mm, P = 0.03 N": (1e-3, 1.0, 0.03),
            "tiny load, P = 1e-8 N": (1.0, 1.0, 1e-8)}.items():
        add(Case("small", name, small_cantilever(length, stiffness, force),
                 check_small_cantilever(length, stiffness, force, 1e-6),
                 notes="P L^2/EI = " f"{force * length**2 / stiffness:.0e}"))
    add(Case("small", "tiny twist, 1e-8 rad", twist(angle=1e-8, elements=16, al_rtol=1e-9,
                                                       al_ctol=1e-9, al_max_it=2000),
             check_small_twist(1e-8, 1e-6)))
    # mesh extremes
    coarse = {"al_rtol": 1e-5, "al_ctol": 1e-3}             # the paper's tolerances
    add(Case("mesh", "cantilever, 2 elements", cantilever(elements=2, **coarse),
             check_cantilever(5e-2), ci=True))
    add(Case("mesh", "twist, 2 elements", twist(elements=2, **coarse),
             check_twist(1.0, 1.0, 1e-3), ci=True))
    # long and slender: the 3000 m catenary
    add(Case("catenary", "uniform, h = 1 m", catenary(3000), check_catenary(1e-4), ci=True))
    add(Case("catenary", "graded 20:1, h = 0.095 m at the pins",
             catenary(3000, mesh_grading=20), check_catenary(1e-4)))
    add(Case("catenary", "graded 20:1, straight start, 10 steps",
             catenary(3000, mesh_grading=20, initial_shape="straight", steps=10),
             check_catenary(1e-4)))
    add(Case("catenary", "uniform, 10^5 elements", catenary(100000), check_catenary(1e-4),
             ranks=2))
    add(Case("catenary", "uniform, 10^6 elements (h/L = 1e-6)", catenary(1000000),
             check_catenary(1e-4), ranks=2))
    # risers: the seabed and the current (docs/riser.md)
    top = RISER["end_position"]
    add(Case("riser", "catenary riser, default seabed (w / 1 mm)", riser(),
             check_grounded(top, 2e-3), ranks=2, notes="1 mm penetration"))
    add(Case("riser", "catenary riser, seabed 1000 x stiffer", riser(seabed_stiffness=1.2e9),
             check_grounded(top, 2e-4), ranks=2))
    add(Case("riser", "catenary riser, straight start, 1 step", riser(initial_shape="straight"),
             check_grounded(top, 2e-3), ranks=2))
    add(Case("riser", "nearly all on the seabed (1711 of 1800 m)",
             riser(end_position="1780,0,50"), check_grounded("1780,0,50", 2e-3), ranks=2))
    add(Case("riser", "touchdown 23 m from the anchor", riser(end_position="1397,0,1000"),
             check_grounded("1397,0,1000", 2e-3), ranks=2))
    add(Case("riser", "weightless line, current 3 m/s across",
             dict(CURRENT_LINE, current="0,3,0"), check_current_catenary(3.0, 1e-4)))
    add(Case("riser", "catenary riser, current 2 m/s across its plane",
             riser(current="0,2,0", drag="1025,1.2,0.324"), ranks=2,
             notes="no closed form; drag 40% of the weight"))
    add(Case("riser", "lazy wave (options/lazy_wave.opts)",
             {"options_file": "options/lazy_wave.opts", "elements": 2000}, ranks=2,
             notes="no closed form"))
    # a sloping or profiled seabed (docs/riser.md §3a)
    for deg in (3.0, 5.0, -5.0):
        add(Case("seabed", f"catenary riser, seabed sloping {deg:g} deg along its plane",
                 riser(seabed_slope=deg), check_incline(deg, 2e-3), ranks=2,
                 notes="rising toward the top" if deg > 0 else "falling toward the top"))
    add(Case("seabed", "catenary riser, seabed profile of the 3 deg plane",
             {k: v for k, v in riser(seabed_profile=SEABED_PROFILE).items() if k != "seabed"},
             check_incline(3.0, 2e-3),
             notes="21 rows"))
    add(Case("seabed", "catenary riser, seabed sloping 3 deg across its plane",
             riser(seabed_slope=3, seabed_direction=90), ranks=2,
             notes="no closed form; the grounded part slides down the slope"))
    add(Case("seabed", "catenary riser, 3 deg slope, straight start, 1 step",
             riser(seabed_slope=3, initial_shape="straight"), check_incline(3.0, 2e-3)))
    # seabed friction (docs/riser.md §3b)
    for mu in (0.25, 0.5, 1.0):
        add(Case("friction", f"line pulled along the seabed, mu {mu:g}: a stick-slip front",
                 dict(PULLED_LINE, seabed_friction=mu), check_pulled(mu), ranks=2,
                 notes=f"the front {200 - 5000 / (mu * 100):g} m from the anchor"
                 if mu > 0.25 else "all slides"))
    for mu in (0.01, 0.5, 2.0):
        add(Case("friction", f"catenary riser, current 1 m/s across, mu {mu:g}",
                 riser(current="0,1,0", drag="1025,1.2,0.324", seabed_friction=mu),
                 check_friction_bound(1e-5),
                 notes="no closed form; frictionless the touchdown is 113 m off the plane"))
    add(Case("friction", "line on the seabed, current 0.85 m/s across: drag below friction",
             dict(GROUNDED_LINE, current="0,0.85,0"), check_stuck(5.1e-3)))
    add(Case("friction", "line on the seabed, current 0.95 m/s across: just overcomes it",
             dict(GROUNDED_LINE, current="0,0.95,0"), check_friction_bound(1e-5), ranks=2,
             notes="no closed form; net load 11 % of mu w"))
    # lines of line types and stretch (issue 22)
    for stiffness, axial in ((1e5, 1e7), (1e5, 1e9), (1e3, 1e9)):
        add(Case("lines", f"riser, EA / EI = {axial / stiffness:.0e} per m^2",
                 riser(stiffness=f"{stiffness:g},{stiffness:g},{0.75 * stiffness:g}",
                       axial_stiffness=f"{axial:g}"),
                 check_elastic_grounded(axial, 2e-3), ranks=2,
                 notes=f"EA {axial:.0e} N: {1.5e8 / axial:.2g} % stretch at the top"))
    add(Case("lines", "a middle section ten times lighter", LIGHT_MIDDLE,
             check_section_catenary(1e-3), notes="EI 1 N m^2"))
    add(Case("lines", "80 m cable, bend stiffener 1000 x EI at a stiff flex joint",
             {"line_types": LINE_TYPES, "sections": "bare:52.101,float:50,bare:63.114,"
              "stiffener:5", "elements": 340, "start": "pin", "end": "pin",
              "end_position": "120,0,66", "seabed": 0, "initial_shape": "catenary",
              "end_rotational_stiffness": "1e6", "end_joint_axis": "0,0,1"},
             notes="no closed form; EI 2e4 to 2e7 N m^2 over the top 5 m"))
    add(Case("lines", "80 m cable, 20 discrete buoyancy modules for its section",
             {"line_types": LINE_TYPES, "sections": "bare:170.215", "elements": 340,
              "point_loads": "scripts/matrix_buoyancy_modules.txt", "start": "pin",
              "end": "pin", "end_position": "120,0,66", "seabed": 0,
              "initial_shape": "catenary"},
             notes="top tension 9320.97 N, 9320.02 N smeared (options/cable_80m.opts)"))
    add(Case("lines", "mooring chain with three clump weights (options/mooring_chain.opts)",
             {"options_file": "options/mooring_chain.opts"}, ranks=2,
             notes="no closed form; EA 1.23e9 N, EI 1e3 N m^2"))
    return matrix


# --------------------------------------------------------------------- running


def scene_option(options, key):
    """The value of -rod_<key> for a case: its own, or that of its options file."""
    if key in options:
        return str(options[key])
    with open(ROOT / options["options_file"], encoding="utf-8") as scene:
        for line in scene:
            words = line.split("#", 1)[0].split()
            if len(words) == 2 and words[0] == f"-rod_{key}":
                return words[1]
    raise KeyError(f"{key} is neither a case option nor in {options['options_file']}")


def before_options(case):
    """The case as it ran before the first measures of docs/stability.md (History B):
    the old default penalty, the straight start, no step halving, no link check, no raise
    of a low penalty."""
    options = dict(case.options)
    if "al_penalty" not in options:
        K = max(float(v) for v in scene_option(options, "stiffness").split(","))
        options["al_penalty"] = f"{400 * K / float(scene_option(options, 'length'))**2:.6g}"
    options["initial_shape"] = "straight"
    options["max_halvings"] = 0
    options["al_adapt_penalty"] = 0
    if options.get("start") == options.get("end") == "clamp":
        options["track_link"] = 0
    return options


def python_command(ranks):
    python = [sys.executable, "-m", "petsc_rod"]
    return python if ranks == 1 else ["mpiexec", "-n", str(ranks)] + python


def read_result(path):
    import h5py
    with h5py.File(path, "r") as f:
        result = {k: np.array(f[k]) for k in ("S", "r", "d1", "d2", "d3", "u")}
        result.update({k: np.array(f[k]) for k in ("effective_tension", "friction_force",
                                                   "friction_state", "seabed_reaction")
                       if k in f})
        result.update({k: f.attrs[k] for k in f.attrs})
        steps = f["steps"]
        result["total_iterations"] = int(sum(steps[k].attrs["iterations"] for k in steps))
    result["path"] = path
    return result


def run_case(case, folder, before=False, ranks=None, initial=None, keep=None, env=None):
    """Run one case in a child process (environment ``env``, default this one's); a row
    of COLUMNS plus the result (or None)."""
    ranks = ranks or case.ranks
    options = before_options(case) if before else dict(case.options)
    output = keep or os.path.join(folder, "result.h5")
    command = python_command(ranks) + option_list(options) + ["-rod_output", output]
    if initial:
        command += ["-rod_initial", initial]
    row = {"group": case.group, "case": case.name, "ranks": ranks,
           "elements": case.elements, "iterations": "", "constraint_residual": "",
           "error": "", "bound": "", "what": "", "reason": ""}
    clock = time.perf_counter()
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=TIMEOUT,
                              cwd=ROOT, env=env)
        code, text = done.returncode, done.stdout + done.stderr
    except subprocess.TimeoutExpired:
        code, text = None, f"timeout after {TIMEOUT:g} s"
    row["wall_time"] = f"{time.perf_counter() - clock:.1f}"
    lines = [line for line in text.splitlines() if line.strip()]
    errors = [line for line in lines if "error:" in line]
    row["reason"] = (errors[-1] if errors else (lines[-1] if lines else "")).replace(
        "petsc_rod: error: ", "")
    result = None
    if code in (0, 3) and os.path.isfile(output):
        result = read_result(output)
        row["iterations"] = result["total_iterations"]
        row["constraint_residual"] = f"{float(result['constraint_residual']):.2e}"
    # the slow-contraction warning is itself one of the fixes: not counted --before
    warnings = [] if before else [line.split("warning: ", 1)[1] for line in lines
                                  if "warning: " in line]
    if code == 0 and result is not None:
        row["outcome"], row["reason"] = "converged", ""
        if case.check is not None:
            error, bound, what = case.check(result)
            row.update(error=f"{error:.2e}", bound=f"{bound:.2g}", what=what)
            if not error <= bound:
                # handed back as converged: WRONG, unless the run said it may be that far
                row["outcome"] = "warned" if warnings else "WRONG"
                row["reason"] = warnings[-1] if warnings else ""
    elif code in (3, 4, 2):
        row["outcome"] = "stopped"
        if code == 4:
            match = re.search(r"iteration (\d+)", row["reason"])
            row["iterations"] = match.group(1) if match else ""
    else:
        row["outcome"] = "failed"
        row["reason"] = row["reason"] or f"exit code {code}"
    return row, result


def run_matrix(selected, folder, before, say):
    rows, files = [], {}
    for case in selected:
        initial = files.get(case.needs)
        keep = os.path.join(folder, f"case{len(rows)}.h5")
        row, _ = run_case(case, folder, before=before, initial=initial, keep=keep)
        files[case.name] = keep if os.path.isfile(keep) else None
        rows.append(row)
        say(f"{row['group']:9s} {row['case']:58s} {row['outcome']:9s} "
            f"its {row['iterations']!s:>7s}  {row['wall_time']:>7s} s  err {row['error'] or '-':>8s}"
            f"  {row['reason'][:90]}")
    return rows


# --------------------------------------------------------------------- the document


def table(rows):
    lines = ["| group | case | ranks | N | outcome | iterations | constraint residual | "
             "time (s) | error (bound) | reason or what |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for row in rows:
        error = f"{row['error']} ({row['bound']})" if row["error"] else "—"
        detail = row["reason"] or row["what"]
        lines.append(f"| {row['group']} | {row['case']} | {row['ranks']} | {row['elements']} "
                     f"| {row['outcome']} | {row['iterations']} | {row['constraint_residual']} "
                     f"| {row['wall_time']} | {error} | {detail} |")
    counts = {o: sum(r["outcome"] == o for r in rows)
              for o in ("converged", "warned", "stopped", "WRONG", "failed")}
    summary = ", ".join(f"{v} {k}" for k, v in counts.items())
    return [f"{len(rows)} cases: {summary}.", ""] + lines


def write_into(document, marker, lines):
    text = Path(document).read_text()
    begin, end = f"<!-- {marker}:begin -->", f"<!-- {marker}:end -->"
    if begin not in text:
        text += f"\n{begin}\n{end}\n"
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    Path(document).write_text(head + begin + "\n" + "\n".join(lines) + "\n" + end + tail)


def write_csv(path, rows):
    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=COLUMNS, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)


def merged(path, rows):
    """The rows of the CSV at ``path`` in the order of cases(), those of ``rows`` (a rerun
    with --only) in place of the old ones of the same case; cases the CSV lacks are
    added in their place."""
    with open(path, newline="") as handle:
        old = {row["case"]: row for row in csv.DictReader(handle)}
    old.update({row["case"]: row for row in rows})
    return [old[case.name] for case in cases() if case.name in old]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", action="store_true",
                        help="switch the first measures off (docs/stability.md, History B)")
    parser.add_argument("--only", help="comma-separated substrings of case names to run")
    parser.add_argument("--ci", action="store_true", help="only the CI subset")
    parser.add_argument("--out", default=str(ROOT / "docs" / "stability"))
    parser.add_argument("--document", default=str(ROOT / "docs" / "stability.md"))
    args = parser.parse_args()
    selected = [c for c in cases() if (not args.ci or c.ci)]
    if args.only:
        wanted = args.only.split(",")
        names = {c.name for c in selected if any(w in c.name for w in wanted)}
        needed = {c.needs for c in selected if c.name in names and c.needs}
        selected = [c for c in selected if c.name in names | needed]
    os.makedirs(args.out, exist_ok=True)

    def say(text):
        print(text, flush=True)

    clock = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        rows = run_matrix(selected, folder, args.before, say)
    name = "cases_before.csv" if args.before else "cases.csv"
    command = "python scripts/stability_matrix.py" + (" --before" if args.before else "")
    stamp = f"Written by `{command}` in {time.perf_counter() - clock:.0f} s"
    if args.only and not args.ci:
        rows, stamp = merged(os.path.join(args.out, name), rows), (
            f"Written by `{command}`; the {len(rows)} case(s) matching `--only {args.only}` "
            f"rerun on {time.strftime('%Y-%m-%d')} in {time.perf_counter() - clock:.0f} s")
    if not args.ci:
        write_csv(os.path.join(args.out, name), rows)
        lines = [f"{stamp} (CSV: `docs/stability/{name}`).", ""] + table(rows)
        write_into(args.document, "before" if args.before else "matrix", lines)
    say(f"{len(rows)} cases in {time.perf_counter() - clock:.0f} s; "
        + table(rows)[0])
    return 0 if all(r["outcome"] != "WRONG" for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
