"""The load path of the continuation (iteration/continuation.py LoadPath), numpy only:
regular steps k/K to the last bit, and halved sub-steps."""

import pytest

from petsc_rod.iteration.continuation import LoadPath


# --- the sequence of load factors ------------------------------------------------------
def test_without_halvings_the_load_factors_are_k_over_K():
    path = LoadPath(7, 0)
    factors = []
    while not path.finished:
        assert not path.can_halve
        factors.append(path.next_factor)
        path.accept()
    assert factors == [k / 7 for k in range(1, 8)]


def test_a_halved_step_goes_on_halved_to_t_k_then_regular():
    path = LoadPath(3, 2)
    assert (path.step, path.next_factor) == (1, 1 / 3)
    path.halve()                                   # step 1 failed at 1/3
    assert path.next_factor == 1 / 6
    path.accept()
    assert (path.step, path.next_factor) == (1, 1 / 3)      # still the halved increment
    path.accept()
    assert path.factor(path.reached) == 1 / 3      # t_1 exactly, the regular size again
    assert (path.step, path.next_factor) == (2, 2 / 3)
    path.halve()
    path.halve()
    assert not path.can_halve and path.halvings == 3
    assert path.next_factor == pytest.approx(1 / 3 + 1 / 12, rel=1e-15)
    for _ in range(4):
        path.accept()
    assert path.factor(path.reached) == 2 / 3 and path.next_factor == 1.0
    path.accept()
    assert path.finished


# --- nothing to halve (issue 25) -------------------------------------------------------
def test_a_path_from_its_end_has_nothing_to_halve():
    """A restart at its end load factor (t_0 = t_end = 1): every sub-step is the same
    load, so a failed step must end the run, not be retried at increment 0."""
    path = LoadPath(4, 4, start=1.0, end=1.0)
    assert path.steps == 1 and path.next_factor == 1.0
    assert path.nothing_to_halve and not path.can_halve


def test_halving_stops_where_the_increment_rounds_to_zero():
    """On a path shorter than the round-off of t, halving stops before a sub-step that
    would not move the load factor; every retry it allows moves it."""
    start = 1.0 - 2.0**-52
    path = LoadPath(1, 10, start=start, end=1.0)
    while path.can_halve:
        path.halve()
        assert path.next_factor > path.factor(path.reached)
    assert path.increment > 1 and path.nothing_to_halve
    assert path.halvings < 10


def test_an_ordinary_path_can_halve_until_its_halvings_run_out():
    path = LoadPath(2, 3, start=0.5, end=1.0)
    for _ in range(3):
        assert path.can_halve and not path.nothing_to_halve
        path.halve()
    assert not path.can_halve and not path.nothing_to_halve
