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


def predicted(elements, ranks, whole=WHOLE, split=SPLIT):
    """(t_1, t_p): one iteration's predicted seconds of a line of ``elements`` whole on
    one rank and split over ``ranks`` (the module's model)."""
    return (whole.seconds(elements),
            split.fixed + split.per_element * elements * 2.0 / ranks)


def crossover(ranks=2, whole=WHOLE, split=SPLIT):
    """N*: the element count above which splitting over ``ranks`` is predicted faster
    (math.inf if it never is; 0 if it always is)."""
    gain = whole.per_element - split.per_element * 2.0 / ranks
    if gain <= 0:
        return math.inf
    return max(0.0, (split.fixed - whole.fixed) / gain)


def choose(mode, elements, ranks, whole=WHOLE, split=SPLIT):
    """'whole' or 'split': how a line of ``elements`` runs on ``ranks`` ranks under
    -rod_ranks_split ``mode`` (MODES). One rank is always whole; 'auto' splits where the
    model predicts an iteration faster split (elements > crossover)."""
    if mode not in MODES:
        raise ValueError(f"unknown mode {mode!r}; use one of {'|'.join(MODES)}")
    if ranks <= 1:
        return "whole"
    if mode != "auto":
        return mode
    return "split" if elements > crossover(ranks, whole, split) else "whole"
