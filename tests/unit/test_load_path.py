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
