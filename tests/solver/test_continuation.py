"""Continuation steps that halve themselves when they fail (``-rod_max_halvings``).

Two cantilevers (16 elements, clamped at 0, free end) that one load step cannot do and
two can, measured when these tests were written:

- BENT, tip force (0, -10, 0) N, R = 25, the plain iteration (``-rod_snes_type
  nrichardson``: Anderson mixing makes the count nearly independent of the step): one
  step needs 238 iterations, so with ``-rod_al_max_it 220`` it stops unconverged; the
  half steps converge in 194 and 89.
- PULLED, pulled along its axis by 1.5e5 N, R = 100: the first global step of one step
  gives |r'| about 1 + P/R, an RMS constraint residual of 1.4e3 above the divergence
  bound (stopping.DIVERGED_RESIDUAL = 1e3); the half steps (7.5e2) converge in 648 each.

With halvings the run undoes the failed step and gets there in two half steps; since the
undo is exact, it then does what ``-rod_steps 2`` does, iteration for iteration.

The in-process tests run on any number of ranks; those that spawn ``python -m petsc_rod``
are marked ``serial`` (tests/conftest.py).
"""


import numpy as np
import pytest

from petsc4py import PETSc

from helpers import BENT, PULLED, gather
from helpers import HALVING_CTOL as CTOL, HALVING_ELEMENTS as N_ELEMENTS, HALVING_RTOL as RTOL
from petsc_rod.cli import session
from petsc_rod.iteration.continuation import PathSettings
from petsc_rod.errors import RodDivergedError, RodNotConvergedError

def build(solver_factory, comm, case):
    database = PETSc.Options()
    database.setValue("rod_snes_type", case["snes_type"])
    try:
        # the counts above are the accelerated or plain iteration's own (no Newton)
        mesh, solver = solver_factory(comm, N_ELEMENTS, case["scene"], case["penalty"], RTOL,
                                      CTOL, case["max_it"], newton=False)
    finally:
        database.delValue("rod_snes_type")
    solver.problem.state.set_straight()
    return mesh, solver


def run_continuation(solver_factory, comm, case, steps, max_halvings):
    """session.run_continuation from the straight state, no file: (exit code, printed lines, the
    final state gathered on every rank)."""
    mesh, solver = build(solver_factory, comm, case)
    lines = []
    code = session.run_continuation(solver, PathSettings(steps, max_halvings=max_halvings),
                                    say=lines.append).code
    state = {name: gather(comm, array) for name, array in owned_state(solver).items()}
    state["energy"] = solver.problem.energy()
    return code, lines, state


def owned_state(solver):
    """Copies of this rank's share of every field of the Uzawa state."""
    return {"r": solver.problem.state.r.owned(), "slope": solver.problem.state.slope.owned(), "d1": solver.problem.state.d1.owned(),
            "d2": solver.problem.state.d2.owned(), "tau": solver.problem.state.tau.copy(), "lam": solver.problem.state.lam.copy()}


def step_results(lines):
    """What the step lines say after their label: load factor, iterations, change,
    residual, energy (the label names the regular step, which halving changes)."""
    return [line.split(": ", 1)[1] for line in lines if line.startswith("step ")]


def assert_same_state(first, second):
    for name in ("r", "slope", "d1", "d2", "tau", "lam"):
        scale = np.abs(second[name]).max()
        assert np.abs(first[name] - second[name]).max() <= 1e-9 * scale, name
    assert first["energy"] == pytest.approx(second["energy"], rel=1e-9)


# --- snapshot and restore ---------------------------------------------------------------
def test_snapshot_restore_is_exact_and_the_next_step_repeats_itself(solver_factory, comm):
    mesh, solver = build(solver_factory, comm, BENT)
    assert solver.solve_step(0.5).converged
    before = owned_state(solver)
    saved = solver.problem.state.snapshot()
    first = solver.solve_step(1.0)
    moved = owned_state(solver)
    assert mesh.global_sum(float(np.abs(moved["r"] - before["r"]).max())) > 0.01
    solver.problem.state.restore(saved)
    for name, values in owned_state(solver).items():
        assert np.array_equal(values, before[name]), name
    second = solver.solve_step(1.0)               # the change test starts from the restore
    assert second.iterations == first.iterations
    assert np.array_equal(np.array(second.history)[:, :2], np.array(first.history)[:, :2])
    for name, values in owned_state(solver).items():
        assert np.array_equal(values, moved[name]), name


def test_restore_after_a_diverged_attempt_leaves_no_nan(solver_factory, comm):
    mesh, solver = build(solver_factory, comm, BENT)
    saved = solver.problem.state.snapshot()
    before = owned_state(solver)
    solver.problem.state.lam[0, 0, 0] = np.nan                   # a state gone bad on every rank
    with pytest.raises(RodDivergedError) as error:
        solver.solve_step(1.0)
    assert error.value.iterations == 1
    poisoned = [np.isnan(values).any() for values in owned_state(solver).values()]
    assert mesh.global_sum(float(sum(poisoned))) >= comm.getSize()
    solver.problem.state.restore(saved)
    for name, values in owned_state(solver).items():
        assert np.isfinite(values).all(), name
        assert np.array_equal(values, before[name]), name
    solver.settings.max_it = 2000
    assert solver.solve_step(1.0).converged


# --- the continuation -------------------------------------------------------------------
@pytest.mark.parametrize("case, failure, exit_code", [
    (BENT, "not converged in 220 iterations", RodNotConvergedError.exit_code),
    (PULLED, "diverged", None)], ids=["max_it", "diverged"])
def test_a_failed_step_is_halved_and_ends_where_two_steps_do(solver_factory, comm, case,
                                                             failure, exit_code):
    if exit_code is None:
        with pytest.raises(RodDivergedError, match="iteration 1: the iteration diverged"):
            run_continuation(solver_factory, comm, case, 1, 0)
    else:
        code, lines, _ = run_continuation(solver_factory, comm, case, 1, 0)
        assert code == exit_code, "\n".join(lines)
    code, lines, halved = run_continuation(solver_factory, comm, case, 1, 4)
    assert code == 0, "\n".join(lines)
    halvings = [line for line in lines if "halving" in line and "retrying" in line]
    assert len(halvings) == 1, "\n".join(lines)
    assert failure in halvings[0] and "increment 0.5" in halvings[0], halvings[0]
    assert "1 halving(s)" in lines[-1], lines[-1]
    regular_code, regular_lines, regular = run_continuation(solver_factory, comm, case, 2, 0)
    assert regular_code == 0, "\n".join(regular_lines)
    assert step_results(lines) == step_results(regular_lines)
    assert [r.split(",")[0] for r in step_results(lines)] == ["load factor 0.5", "load factor 1"]
    assert_same_state(halved, regular)


