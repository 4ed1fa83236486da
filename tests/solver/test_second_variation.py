"""The second variation H (petsc_rod/analysis/second_variation.py, its inertia test
analysis/stability.py) as the solver keeps it: one
matrix for the solver's life, updated in place at each Newton step and stability test.

- Updated at a new state, H, its chord constraint and its inertia are those of an H
  assembled afresh there (on 1 or several ranks).
- The chord forms solved through the inertia test's solves of their orthonormal basis
  (what a Newton step uses) are the direct solves.
- The element blocks, written out in broadcast products, are the cross-product form
  sum_i 2 a_i K_ab [d_a,i]x^T [d_b,i]x of the module docstring.
"""

import numpy as np

from helpers import PAPER_SCENE as PAPER, continuation
from petsc_rod.analysis.second_variation import SecondVariation, skew
from petsc_rod.analysis.stability import StabilityTest


def test_an_updated_second_variation_is_the_one_assembled_afresh(solver_factory, comm):
    _, solver = solver_factory(comm, 24, PAPER, 400.0, 1e-3, 1e-3, 5000, newton=False)
    solver.settings.check_stability = False
    assert continuation(solver, steps=2).converged
    kept = solver.problem.second_variation()
    assert kept.decidable and len(kept.constraint) == 3          # both ends held
    before = kept.matrix.copy()
    for _ in range(40):                                          # a different state
        solver.problem.iterate()
    updated = solver.problem.second_variation()
    assert updated is kept
    fresh = StabilityTest(solver.problem)
    difference = updated.matrix.copy()
    try:
        scale = fresh.matrix.norm(norm_type=3)                  # NORM_INFINITY
        difference.axpy(-1.0, fresh.matrix)
        assert difference.norm(norm_type=3) < 1e-13 * scale
        before.axpy(-1.0, fresh.matrix)
        assert before.norm(norm_type=3) > 1e-8 * scale           # the update did something
        # the same constraint space: each fresh basis vector lies in the updated span
        for column in fresh.constraint:
            rest = column.copy()
            for kept_column in updated.constraint:
                rest.axpy(-kept_column.dot(column), kept_column)
            assert rest.norm() < 1e-12 * column.norm()
            rest.destroy()
        for shift in (-fresh.tolerance(), 1.0):
            assert updated.negative_directions(shift) == fresh.negative_directions(shift)
    finally:
        for obj in (fresh, before, difference):
            obj.destroy()


def test_chord_forms_solved_from_the_inertia_test_are_the_direct_solves(solver_factory,
                                                                         comm):
    _, solver = solver_factory(comm, 24, PAPER, 400.0, 1e-3, 1e-3, 5000, newton=False)
    solver.settings.check_stability = False
    assert continuation(solver, steps=2).converged
    hessian = solver.problem.second_variation()
    hessian.negative_directions(-hessian.tolerance())
    forms = hessian.chord_forms(solver.problem.state.tau[:, 2])
    reused = hessian.solve_in_constraint_span(forms)
    direct = [hessian.solve(form) for form in forms]
    try:
        for a, b in zip(reused, direct):
            a.axpy(-1.0, b)
            assert a.norm() < 1e-10 * b.norm()
    finally:
        for vec in forms + reused + direct:
            vec.destroy()


def test_element_blocks_are_the_cross_product_form():
    rng = np.random.default_rng(7)
    d = rng.standard_normal((20, 3, 3, 3))                  # (element, node, director, 3)
    stiffness = rng.standard_normal((20, 3, 3))
    weights = np.array([0.7, 2.0, 5.0])
    x = skew(d)
    expected = np.einsum("i,eab,eaiks,ebikt->easbt", weights, stiffness, x, x)
    blocks = SecondVariation._element_blocks(d, weights, stiffness)
    assert np.abs(blocks - expected).max() < 1e-13 * np.abs(expected).max()
