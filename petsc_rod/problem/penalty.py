"""The penalty R of the augmented Lagrangian (docs/method.md §2, §3): its default, the
splitting of the stiffness into the matrices' coefficients, and when to raise it.

Two penalties are named apart: the one asked for (``Settings.asked_penalty``:
-rod_al_penalty or ``default_penalty``) and the one in use (``UzawaSolver.penalty``),
which ``penalty_too_low`` may have raised on the way.
"""

import numpy as np

# A penalty below ADAPT_BELOW times the problem's scale (default_penalty) is multiplied
# by ADAPT_FACTOR, up to the scale, whenever the constraint residual has fallen by less
# than the factor ADAPT_PROGRESS over the last ADAPT_WINDOW iterations.
ADAPT_BELOW = 0.1
ADAPT_FACTOR = 10.0
ADAPT_PROGRESS = 0.5
ADAPT_WINDOW = 200

# Seabed friction on an extensible line: the stick springs hold the grounded line, whose
# stretch, and the tension with it, then come from the multiplier alone, by steps of R
# times the strain. Where Newton steps do not finish such a run (two load steps, two
# coefficients, a line through the surface, a chain in a current across it) the default
# R converged in none of the measured cases and about FRICTION_SHARE times the least EA
# did (docs/riser.md §3b); not a default, which slowed a line in a cross current there,
# but the ceiling of the raises of a stalling iteration (adapt_ceiling).
FRICTION_SHARE = 0.1


def default_penalty(scene, start_tension=0.0):
    """R = max(100 sqrt(min K max K) / L^2, F / 2, 2 M^2 / min(K1, K2), T / 2, T_s), N.

    The scales, each a lower bound below which the iteration crawls or leaves the
    branch (docs/method.md §3; measurements in docs/stability.md, History C):
    * bending and torsion, 100 sqrt(min K max K) / L^2: the count grows with R over the
      softest stiffness and the iteration fails when R is far below the stiffest one;
    * tension, F / 2 with F = int |f| dS + |P_0| + |P_L| + sum |P_p| (the point loads;
      Scene.applied_force): the multiplier lambda3 reaches the tension by steps of at
      most 2R per iteration;
    * twisting moment M = K3 a / L of an end turned by a: M^2 / K_b is four times the
      axial compression it stands for in Greenhill's condition
      (M / 2K_b)^2 + P / K_b = (pi / L)^2, K_b = min(K1, K2);
    * on an extensible line held taut (ends d > L apart, docs/method.md §12), its
      tension T / 2 with T = (d - L) / int dS / EA, which lambda3 must reach as it must
      reach the loads' (0 on an inextensible or slack line);
    * the tension the start holds, ``start_tension`` T_s (the largest tension of a
      catenary start, scenes/starts.largest_tension; 0 for the straight start): lambda3
      starts at the tension there, and with R below it the hanging lines' iteration
      crawls (docs/method.md §3).
    """
    return max(penalty_scales(scene, start_tension).values())


def friction_penalty(scene):
    """R = FRICTION_SHARE min EA (N), the penalty a run with seabed friction on an
    extensible line is advised where it did not converge (cli/messages.py); None
    without seabed friction or without a finite EA."""
    if scene.seabed is None or scene.seabed.friction is None or not scene.extensible:
        return None
    values = ([s.axial_stiffness for s in scene.sections] if scene.sections
              else [scene.axial_stiffness])
    finite = [float(value) for value in values if np.isfinite(value)]
    return FRICTION_SHARE * min(finite)


def adapt_ceiling(scene, scale):
    """The largest penalty R (N) that penalty_too_low's raises reach: the problem's
    ``scale`` (default_penalty), or friction_penalty where that is larger (seabed
    friction on an extensible line, whose stalling iteration the scale does not cure:
    docs/riser.md §3b). A raise is made only where the constraint residual stalls, so
    a run that converges at its penalty is the same."""
    friction = friction_penalty(scene)
    return scale if friction is None else max(scale, friction)


def penalty_scales(scene, start_tension=0.0):
    """The scales of default_penalty, N: {'bending': 100 sqrt(min K max K) / L^2,
    'tension': F / 2, 'twist': 2 M^2 / min(K1, K2), 'stretch': T / 2, 'start': T_s};
    the command line names the options behind the one that makes a default penalty out
    of range.

    Where the stiffness varies along the line (sections), min K and max K are taken over
    the three stiffnesses and the whole line (Scene.stiffness_values: the softest and the
    stiffest part, the two bounds of the bending scale), min(K1, K2) is the softest
    bending stiffness anywhere (the part that buckles first: the larger, safer scale),
    and M is the moment of the end's turn a through the line's torsional springs in
    series, a / int_0^L dS / K3 (torsional_compliance), which is K3 a / L on a uniform
    line.
    """
    if scene.uniform_stiffness:
        stiffness = scene.stiffness
        moment = stiffness[2] * scene.end_rotation() / scene.length
        bending = stiffness[:2].min()
    else:
        stiffness = scene.stiffness_values()
        moment = scene.end_rotation() / torsional_compliance(scene.sections)
        bending = stiffness[:, :2].min()
    return {"bending": 100.0 * np.sqrt(stiffness.min() * stiffness.max()) / scene.length**2,
            "tension": 0.5 * scene.applied_force(),
            "twist": 2.0 * moment**2 / bending,
            "stretch": 0.5 * taut_tension(scene),
            "start": float(start_tension)}


def torsional_compliance(sections):
    """int dS / K3 over the sections (scenes/line.py), 1/N m: l / K3 along a uniform
    section, l ln(K3_end / K3_start) / (K3_end - K3_start) along a tapered one."""
    total = 0.0
    for section in sections:
        length = section.end - section.start
        k0, k1 = section.stiffness_start[2], section.stiffness_end[2]
        total += length / k0 if k0 == k1 else length * np.log(k1 / k0) / (k1 - k0)
    return float(total)


def taut_tension(scene):
    """The tension of an extensible line whose held ends are d > L apart at t = 1,
    (d - L) / int dS / EA, N (the sections' compliances in series); 0 when the line is
    inextensible, slack or not held at both ends."""
    if not scene.extensible or "free" in (scene.start, scene.end):
        return 0.0
    excess = np.linalg.norm(scene.end_position) - scene.length
    if excess <= 0:
        return 0.0
    pieces = ([(s.end - s.start, s.axial_stiffness) for s in scene.sections]
              if scene.sections else [(scene.length, scene.axial_stiffness)])
    return float(excess / sum(length / ea for length, ea in pieces))


def matrix_split(split):
    """The coefficients c_i of the global step's matrices 2 c_i K + R W (§2), from the
    split a_i of the stiffness (frames.split_coefficients).

    Where every a_i > 0, c = a. A stiffness above the sum of the other two makes one
    a_j < 0 (a flat section; K3 > K1 + K2 in torsion), and its matrix would be indefinite
    unless R grew like 1/h^2. Instead c_j = max_i a_i and the difference
    2 (c_j - a_j) K tau_j goes to the right-hand side (GlobalStep): the fixed points are
    those of the a_i, and the matrix of d_j keeps a stiffness of the size of the others.
    Pointwise along a line whose stiffness varies: split (..., 3) -> (..., 3), the
    maximum taken over the three coefficients at each point.
    """
    split = np.asarray(split, dtype=float)
    return np.where(split < 0, split.max(axis=-1, keepdims=True), split)


def penalty_too_low(history, penalty, ceiling):
    """Whether a step's (change, residual, time) rows call for a larger penalty: R below
    ADAPT_BELOW times the ``ceiling`` of the raises (adapt_ceiling) and the residual of
    the last row more than ADAPT_PROGRESS times that of ADAPT_WINDOW rows before (the
    multiplier creeps towards the internal forces by at most 2R per iteration)."""
    if penalty >= ADAPT_BELOW * ceiling or len(history) <= ADAPT_WINDOW:
        return False
    return history[-1][1] > ADAPT_PROGRESS * history[-1 - ADAPT_WINDOW][1]


def raised_penalty(penalty, ceiling):
    """The next penalty after penalty_too_low: min(ADAPT_FACTOR R, ceiling), N, with
    ``ceiling`` that of the raises (adapt_ceiling)."""
    return min(ADAPT_FACTOR * penalty, ceiling)
