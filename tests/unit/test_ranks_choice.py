"""The choice between a line split over the ranks and whole on one (mesh/ranks.py):
its decisions against its cost model, and what the measured constants decide for the
scenes of options/."""

import math

import pytest

from petsc_rod.mesh import ranks
from petsc_rod.mesh.ranks import IterationCost, choose, crossover, predicted

# a model with round numbers: 1 ms + 1 us an element whole, 3 ms + 0.5 us split over 2
WHOLE = IterationCost(1e-3, 1e-6)
SPLIT = IterationCost(3e-3, 0.5e-6)


def test_the_crossover_is_where_the_predicted_times_meet():
    n = crossover(2, WHOLE, SPLIT)
    assert n == pytest.approx(4000.0)
    below, above = predicted(n - 1, 2, WHOLE, SPLIT), predicted(n + 1, 2, WHOLE, SPLIT)
    assert below[0] < below[1] and above[1] < above[0]
    assert choose("auto", 3999, 2, WHOLE, SPLIT) == "whole"
    assert choose("auto", 4001, 2, WHOLE, SPLIT) == "split"


def test_more_ranks_split_shorter_lines():
    assert crossover(4, WHOLE, SPLIT) == pytest.approx(2e-3 / 0.75e-6)
    assert choose("auto", 3000, 4, WHOLE, SPLIT) == "split"


def test_a_split_that_never_pays_and_one_that_always_does():
    assert crossover(2, WHOLE, IterationCost(3e-3, 1e-6)) == math.inf
    assert choose("auto", 10**9, 2, WHOLE, IterationCost(3e-3, 1e-6)) == "whole"
    assert crossover(2, WHOLE, IterationCost(0.5e-3, 0.5e-6)) == 0.0


def test_one_rank_is_whole_and_the_forced_modes_hold():
    assert choose("split", 10**6, 1) == "whole"
    assert choose("whole", 10**6, 2) == "whole"
    assert choose("split", 8, 2) == "split"
    with pytest.raises(ValueError, match="auto|whole|split"):
        choose("half", 80, 2)


# the element counts of options/: the rods, and cable_80m (340 elements), which split
# was 1.04 times as slow on 2 ranks as on 1 (10 pairs, docs/scenes_benchmark.md)
@pytest.mark.parametrize("elements", [16, 32, 64, 80, 340])
def test_the_measured_model_runs_the_rods_of_options_whole(elements):
    assert choose("auto", elements, 2) == "whole"


@pytest.mark.parametrize("elements", [707, 850, 1800, 2000, 2400, 2741, 3000, 18000])
def test_the_measured_model_splits_the_long_lines(elements):
    """The cables and risers of options/ from cable_200m's 707 elements,
    cable_800m, riser_catenary, the 18 000-element riser: split, where a second rank
    gains today."""
    assert choose("auto", elements, 2) == "split"
    assert ranks.WHOLE.per_element > ranks.SPLIT.per_element


def test_friction_passes_add_to_both_costs_and_move_the_crossover(monkeypatch):
    """P passes of c + d N on each side: the crossover of a + P c, b + P d."""
    monkeypatch.setattr(ranks, "PASS_WHOLE", IterationCost(1e-3, 0.2e-6))
    monkeypatch.setattr(ranks, "PASS_SPLIT", IterationCost(4e-3, 0.1e-6))
    whole, split = ranks.iteration_costs(10, WHOLE, SPLIT)
    assert (whole.fixed, whole.per_element) == pytest.approx((11e-3, 3e-6))
    assert (split.fixed, split.per_element) == pytest.approx((43e-3, 1.5e-6))
    # (43 - 11) ms / (3 - 1.5) us = 21 333 elements, where 4000 without the passes
    assert crossover(2, WHOLE, SPLIT, passes=10) == pytest.approx(32e-3 / 1.5e-6)
    assert choose("auto", 21000, 2, WHOLE, SPLIT, passes=10) == "whole"
    assert choose("auto", 21400, 2, WHOLE, SPLIT, passes=10) == "split"
    assert predicted(21000, 2, WHOLE, SPLIT, passes=10)[0] == pytest.approx(11e-3 + 3e-6 * 21000)


# The measured model with friction's passes (docs/performance.md, "Two ranks or one",
# "Friction"): mooring_chain with -rod_seabed_friction 0.3 lost split at 340 and 850
# elements (2 ranks slower than 1); steel_catenary_riser_friction (2400 elements) gained.
@pytest.mark.parametrize("elements", [340, 850])
def test_a_friction_line_of_850_elements_is_kept_whole(elements):
    assert choose("auto", elements, 2, passes=ranks.passes_of(True)) == "whole"
    assert ranks.passes_of(False) == 0


def test_the_frictionless_850_element_line_still_splits():
    assert choose("auto", 850, 2, passes=ranks.passes_of(False)) == "split"


def test_the_measured_friction_crossover_lies_between_the_chain_and_the_riser():
    passes = ranks.passes_of(True)
    assert 850 < crossover(2, passes=passes) < 2400
    assert choose("auto", 2400, 2, passes=passes) == "split"
    assert ranks.PASS_SPLIT.fixed > ranks.PASS_WHOLE.fixed
