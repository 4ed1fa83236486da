"""The penalty a run with seabed friction on an extensible line is advised where it did
not converge (problem/penalty.friction_penalty, cli/messages.not_converged_reason):
FRICTION_SHARE times the least finite EA, and only where the asked R is far below it
(docs/riser.md §3b); the same is the ceiling of a stalling iteration's raises there
(penalty.adapt_ceiling), the problem's scale elsewhere."""

from types import SimpleNamespace

import numpy as np
import pytest

from petsc_rod.cli.messages import not_converged_reason, raised
from petsc_rod.problem.penalty import FRICTION_SHARE, adapt_ceiling, friction_penalty


def scene(friction, axial, sections=()):
    return SimpleNamespace(seabed=SimpleNamespace(friction=friction),
                           sections=[SimpleNamespace(axial_stiffness=ea) for ea in sections],
                           axial_stiffness=axial,
                           extensible=bool(np.any(np.isfinite(list(sections) or [axial]))))


def test_the_advice_is_a_tenth_of_the_least_finite_axial_stiffness():
    assert friction_penalty(scene(0.3, np.inf, (2e9, np.inf, 1.2e9))) == \
        pytest.approx(FRICTION_SHARE * 1.2e9, rel=1e-15)
    assert friction_penalty(scene(0.3, 5e8)) == pytest.approx(5e7, rel=1e-15)


def test_no_advice_without_friction_or_stretch():
    assert friction_penalty(scene(None, 5e8)) is None
    assert friction_penalty(scene(0.3, np.inf)) is None
    assert friction_penalty(SimpleNamespace(seabed=None, extensible=True)) is None


def test_the_raises_reach_the_advice_with_friction_and_the_scale_elsewhere():
    assert adapt_ceiling(scene(0.3, 5e8), 1.2e6) == pytest.approx(5e7, rel=1e-15)
    assert adapt_ceiling(scene(0.3, 5e6), 1.2e6) == 1.2e6        # the scale is larger
    assert adapt_ceiling(scene(None, 5e8), 1.2e6) == 1.2e6       # no friction
    assert adapt_ceiling(scene(0.3, np.inf), 1.2e6) == 1.2e6     # inextensible


def test_the_raise_s_line_names_its_ceiling():
    raises = [SimpleNamespace(penalty=1.18e7, iteration=400)]
    friction = raised("step 1/1", raises, 1.23e8, True)
    assert "R raised to 1.18e+07 at iteration 400" in friction
    assert "ceiling 1.23e+08 (a tenth of the least EA" in friction
    assert "ceiling 1.2e+06 (the problem's scale;" in raised("step 1/1", raises, 1.2e6)


REPORT = SimpleNamespace(reason=None, stalled=False, iterations=2000, change=1e-4,
                         constraint_residual=1e-3)


def settings(penalty):
    return SimpleNamespace(rtol=1e-9, ctol=1e-9, asked_penalty=penalty)


def test_the_advice_is_given_only_where_the_penalty_is_far_below_it():
    advised = not_converged_reason(REPORT, settings(1.2e6), 1.2e6, 1.2e8)
    assert "try -rod_al_penalty 1.2e+08" in advised
    assert "try -rod_al_penalty" not in not_converged_reason(REPORT, settings(2e7), 1.2e6,
                                                             1.2e8)
    assert "try -rod_al_penalty" not in not_converged_reason(REPORT, settings(1.2e6), 1.2e6)


def test_no_advice_where_one_steps_newton_steps_finish_the_run():
    """A short pinned line on a flat seabed converged at its default R = 5000 N in 52
    iterations and failed at EA / 10 (cli/session.advised_penalty): the advice is for
    runs that Newton steps do not finish, more than one load step or a term outside
    them."""
    from petsc_rod.cli.session import advised_penalty
    from petsc_rod.iteration.continuation import PathSettings
    line = scene(0.5, 1e7)
    assert advised_penalty(SimpleNamespace(in_newton=True, scene=line),
                           PathSettings(steps=1)) is None
    assert advised_penalty(SimpleNamespace(in_newton=True, scene=line),
                           PathSettings(steps=2)) == pytest.approx(1e6, rel=1e-15)
    assert advised_penalty(SimpleNamespace(in_newton=False, scene=line),
                           PathSettings(steps=1)) == pytest.approx(1e6, rel=1e-15)
