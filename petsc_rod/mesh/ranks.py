"""Whether a line's run is split over the ranks or done whole on one of them
(-rod_ranks_split auto|whole|split, cli/ranks.py acts on the choice).

**Cost model.** An iteration of a line of N elements costs, in seconds,

    whole, on one rank:      t_1(N) = a_1 + b_1 N
    split over p ranks:      t_p(N) = a_2 + b_2 N (2 / p)

a_1, b_1, a_2, b_2 (s, s per element) the fixed and per-element parts measured on one
rank and split over two (scripts/benchmark_scenes.py --fit: the solve time over the
iterations of the rods and cables of options/, fitted in N; docs/performance.md). a_2
exceeds a_1: a split line pays, every iteration, the collectives of the global step's
substructuring, the norms and the Newton steps, and each rank pays the same Python call
overhead on its half of the data as one rank on the whole; b_2 is about b_1 / 2, the
arithmetic halved. Splitting pays where t_p(N) < t_1(N), above

    N* = (a_2 - a_1) / (b_1 - 2 b_2 / p)

elements; never if b_1 <= 2 b_2 / p. The per-element work of a scene with a seabed, a
current or Newton steps is larger than a rod's, which lowers its N*: the constants come
from the scenes' own runs, so the rods' small N and the cables' large N both fit.

**Friction's passes.** A line with seabed friction solves its global step's x and y
problems again at every pass of the friction's secant loop (physics/friction.py,
FrictionTerm.solve_slope: until the springs settle, at most MAX_SOLVES passes), each
pass a factorisation of their shared matrix and two solves; split, each is a parallel
assembly, the substructuring's set-up (a refactorisation, W, the interface's allgather)
and a dozen collectives. Such an iteration costs

    whole:    t_1(N) = a_1 + b_1 N + P (c_1 + d_1 N)
    split:    t_p(N) = a_2 + P c_2 + (b_2 + P d_2) N (2 / p)

with P the passes an iteration (FRICTION_PASSES where the scene has friction, 0 where
not: the median measured, 16, though a line that mostly sticks makes 2 or 3) and c, d
(s, s per element) a pass's fixed and per-element cost (PASS_WHOLE, PASS_SPLIT): the
same N* as above with a + P c and b + P d. A split pass's fixed cost is many times a
whole one's, so a friction line splits only much longer than a frictionless one
(docs/performance.md, "Two ranks or one", "Friction's passes").
"""

import math
from dataclasses import dataclass

# The values -rod_ranks_split takes: the choice by the cost model, or forced.
MODES = ("auto", "whole", "split")


@dataclass(frozen=True)
class IterationCost:
    """One iteration's cost a + b N (s) of a line of N elements: ``fixed`` a (s) and
    ``per_element`` b (s per element), on one rank (whole) or split over two."""

    fixed: float
    per_element: float

    def seconds(self, elements):
        return self.fixed + self.per_element * elements


# An iteration as the run counts it (the map's, or a Newton step's), over the scenes of
# options/; how they were measured: docs/performance.md, "Two ranks or one".
WHOLE = IterationCost(fixed=0.80e-3, per_element=6.42e-6)
SPLIT = IterationCost(fixed=1.52e-3, per_element=4.35e-6)

# A pass of the friction's secant loop (module docstring), whole and split, and the
# passes an iteration of a line with friction; measured: docs/performance.md, "Two
# ranks or one", "Friction's passes".
PASS_WHOLE = IterationCost(fixed=0.155e-3, per_element=1.73e-6)
PASS_SPLIT = IterationCost(fixed=2.54e-3, per_element=0.507e-6)
FRICTION_PASSES = 16


def with_passes(cost, passes, per_pass):
    """The IterationCost ``cost`` plus ``passes`` passes of ``per_pass`` (module
    docstring: a + P c, b + P d)."""
    return IterationCost(cost.fixed + passes * per_pass.fixed,
                         cost.per_element + passes * per_pass.per_element)


def iteration_costs(passes=0, whole=WHOLE, split=SPLIT):
    """(whole, split): an iteration's IterationCost with ``passes`` friction passes, on
    one rank and split (PASS_WHOLE, PASS_SPLIT a pass)."""
    return (with_passes(whole, passes, PASS_WHOLE), with_passes(split, passes, PASS_SPLIT))


def passes_of(friction):
    """P, the friction's passes an iteration of a line (FRICTION_PASSES with seabed
    friction, ``friction`` true; 0 without)."""
    return FRICTION_PASSES if friction else 0


def predicted(elements, ranks, whole=WHOLE, split=SPLIT, passes=0):
    """(t_1, t_p): one iteration's predicted seconds of a line of ``elements`` whole on
    one rank and split over ``ranks`` (the module's model), with ``passes`` friction
    passes an iteration."""
    whole, split = iteration_costs(passes, whole, split)
    return (whole.seconds(elements),
            split.fixed + split.per_element * elements * 2.0 / ranks)


def crossover(ranks=2, whole=WHOLE, split=SPLIT, passes=0):
    """N*: the element count above which splitting over ``ranks`` is predicted faster
    (math.inf if it never is; 0 if it always is), with ``passes`` friction passes an
    iteration."""
    whole, split = iteration_costs(passes, whole, split)
    gain = whole.per_element - split.per_element * 2.0 / ranks
    if gain <= 0:
        return math.inf
    return max(0.0, (split.fixed - whole.fixed) / gain)


def choose(mode, elements, ranks, whole=WHOLE, split=SPLIT, passes=0):
    """'whole' or 'split': how a line of ``elements`` runs on ``ranks`` ranks under
    -rod_ranks_split ``mode`` (MODES), with ``passes`` friction passes an iteration
    (passes_of). One rank is always whole; 'auto' splits where the model predicts an
    iteration faster split (elements > crossover)."""
    if mode not in MODES:
        raise ValueError(f"unknown mode {mode!r}; use one of {'|'.join(MODES)}")
    if ranks <= 1:
        return "whole"
    if mode != "auto":
        return mode
    return "split" if elements > crossover(ranks, whole, split, passes) else "whole"
