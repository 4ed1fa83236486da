"""The catenary of a line of sections (petsc_rod/scenes/section_catenary.py) against the
closed forms of a uniform line: a uniform weight cut into pieces is the catenary
(scenes/catenary.py) hanging from the start, and the catenary with touchdown
(scenes/touchdown.py) resting on the seabed, to 1e-12 of L; a lazy wave meets its ends
and its force balance; lines with no catenary, or none above the seabed, are refused."""

import numpy as np
import pytest

from petsc_rod.scenes import section_catenary
from petsc_rod.scenes.catenary import catenary, increasing_root, increasing_roots
from petsc_rod.scenes.touchdown import grounded_catenary

# the 80 m lazy-wave cable of options/cable_80m.opts (N/m, > 0 down)
CABLE_ENDS = [0.0, 52.101, 102.101, 170.215]
CABLE_WEIGHTS = [157.8003, -80.1525, 157.8003]


def assert_the_same_line(line, S, r, force, length, weight):
    """x, z, H and V of the SectionCatenary ``line`` at S against a closed form's r and
    n, to 1e-12 of the length, of H and of the whole weight."""
    x, z, V = line.at(S)
    assert np.abs(x - r[:, 0]).max() < 1e-12 * length
    assert np.abs(z - r[:, 2]).max() < 1e-12 * length
    assert abs(line.H - force[0, 0]) < 1e-12 * line.H
    assert np.abs(V - force[:, 2]).max() < 1e-12 * weight * length


def test_a_uniform_line_in_pieces_is_the_catenary():
    length, weight, chord = 3000.0, 1000.0, np.array([2500.0, 0.0, 300.0])
    line = section_catenary.solve([0.0, 700.0, 1900.0, length], [weight] * 3, chord[0],
                                  chord[2], on_seabed=False)
    S = np.linspace(0.0, length, 101)
    r, _, force = catenary(length, chord, [0.0, 0.0, -weight], S)
    assert_the_same_line(line, S, r, force, length, weight)


def test_a_uniform_line_in_pieces_on_the_seabed_is_the_catenary_with_touchdown():
    length, weight, chord = 1800.0, 1200.0, np.array([1157.0, 0.0, 1000.0])
    line = section_catenary.solve([0.0, 500.0, 1200.0, length], [weight] * 3, chord[0],
                                  chord[2], on_seabed=True)
    S = np.linspace(0.0, length, 101)
    r, _, force, (_, touchdown) = grounded_catenary(length, chord, weight, 0.0, S)
    assert abs(line.grounded - touchdown) < 1e-12 * length
    assert_the_same_line(line, S, r, force, length, weight)


def test_a_lazy_wave_meets_its_ends_and_its_force_balance():
    line = section_catenary.solve(CABLE_ENDS, CABLE_WEIGHTS, 120.0, 66.0, on_seabed=True)
    assert 0.0 < line.grounded < CABLE_ENDS[1]          # touches down on the first section
    assert np.allclose(line.end_point(), (120.0, 66.0), rtol=0, atol=1e-9)
    S = np.linspace(0.0, CABLE_ENDS[-1], 20001)
    x, z, V = line.at(S)
    # V' = w on the suspended line, V = 0 on the seabed, z >= 0 (the hog clear of it)
    suspended = np.diff(CABLE_ENDS) - np.diff(np.clip(CABLE_ENDS, 0.0, line.grounded))
    assert abs(V[-1] - suspended @ CABLE_WEIGHTS) < 1e-9 * V[-1]
    assert np.all(V[S <= line.grounded] == 0.0) and z.min() >= 0.0
    # the tangent (H, V) / |n| is the derivative of (x, z): Simpson's rule on each
    # interval where the weight does not jump (a break, the touchdown), error O(h^5)
    h = S[1] - S[0]
    _, _, middle = line.at(S[:-1] + h / 2)
    kinks = np.array(CABLE_ENDS[1:-1] + [line.grounded])
    smooth = ~np.any((S[:-1, None] <= kinks) & (kinks <= S[1:, None]), axis=1)

    def simpson(values, at_middle):
        return h / 6 * (values[:-1] + 4 * at_middle + values[1:])

    def tangent(V):
        return line.H / np.hypot(line.H, V), V / np.hypot(line.H, V)

    (tx, tz), (mx, mz) = tangent(V), tangent(middle)
    assert np.abs(np.diff(x) - simpson(tx, mx))[smooth].max() < 1e-12
    assert np.abs(np.diff(z) - simpson(tz, mz))[smooth].max() < 1e-12


@pytest.mark.parametrize("span, rise, on_seabed, words", [
    (120.0, 170.0, True, "less than L apart"),          # the ends beyond the length
    (0.0, 66.0, False, "one vertical"),
    (20.0, 10.0, True, "too long to lie taut"),          # 170 m of line, 30 m of path
    (150.0, 30.0, True, "below the seabed"),             # the sag after the arch, 5 m under
])
def test_lines_without_a_catenary_are_refused(span, rise, on_seabed, words):
    with pytest.raises(ValueError, match=words):
        section_catenary.solve(CABLE_ENDS, CABLE_WEIGHTS, span, rise, on_seabed)


def test_a_buoyant_first_section_that_would_dip_under_the_seabed_is_refused():
    """50 m of buoyant line (-50 N/m) from the anchor, then 90 m of 200 N/m, to 100 m
    away and 60 m up: its catenary rises from the anchor and then hangs below the
    seabed, which a line resting on it cannot do. 10 m shorter it stays above."""
    with pytest.raises(ValueError, match="below the seabed"):
        section_catenary.solve([0.0, 50.0, 140.0], [-50.0, 200.0], 100.0, 60.0, True)
    line = section_catenary.solve([0.0, 50.0, 130.0], [-50.0, 200.0], 100.0, 60.0, True)
    assert line.grounded == 0.0 and line.V0 > 0.0
    assert line.at(np.linspace(0.0, 130.0, 4097))[1].min() >= 0.0


def test_many_roots_at_once_are_the_doubles_of_one_bisection_each():
    """catenary.increasing_roots: each row the same double as increasing_root's
    bisection, on functions whose rounding makes them step near the root."""
    targets = np.array([1e-7, 0.3, 2.0, 1234.5678, 7.0e5])
    scales = np.array([1.0, 3.0, 1e-3, 1e4, 0.7])

    def one(k):
        return lambda x: ((x * scales[k]) ** 3 - (targets[k] * scales[k]) ** 3) * 1e12

    expected = [increasing_root(one(k), 0.0, 1e6) for k in range(targets.size)]
    for depth in (1, 4, 6):
        found = increasing_roots(lambda rows, x: ((x * scales[rows, None]) ** 3 - (
            targets[rows, None] * scales[rows, None]) ** 3) * 1e12,
            np.zeros(5), np.full(5, 1e6), depth=depth)
        assert found.tolist() == expected


def test_the_start_of_a_cable_is_solved_once_in_few_evaluations(monkeypatch):
    """The 800 m cable's catenary (options/cable_800m.opts) evaluates its pieces in
    fewer than 500 calls (the nested bisections batched; 3 650 one line at a time), and
    a second solve of the same line is the first's (a run asks twice)."""
    calls = []
    advance = section_catenary.advance

    def counted(*args):
        calls.append(1)
        return advance(*args)

    monkeypatch.setattr(section_catenary, "advance", counted)
    ends, weights = [0.0, 597.981, 997.981, 1370.43], [157.8003, -83.6829, 157.8003]
    line = section_catenary.solve(ends, weights, 800.0 + 1e-6, 786.0, True)
    assert 0 < len(calls) < 500
    assert np.allclose(line.end_point(), (800.0 + 1e-6, 786.0), rtol=0, atol=1e-9)
    again = section_catenary.solve(np.array(ends), weights, 800.0 + 1e-6, 786.0, True)
    assert again is line and len(calls) < 500
