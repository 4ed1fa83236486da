"""cli/line_run.py, the one run path of the command line and the API, as a solver of
several lines will use it: a model planned (plan_line), its line built (BuiltLine), run,
run again from its last state (a warm start), and destroyed; the same numbers as the
whole run (run_line) and as api.solve."""

import dataclasses

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.api import End, Model, UniformLine, solve
from petsc_rod.cli.line_run import BuiltLine, LastStep, plan_line, run_line
from petsc_rod.cli.options import parse_values
from petsc_rod.model.names import FIELD_NAMES

pytestmark = pytest.mark.solver

# a uniform cantilever under its weight: small-deflection tip w L^4 / 8 EI
CANTILEVER = Model(UniformLine(length=1.0, stiffness=(1.0, 1.0, 1.0),
                               load=((0.0, 0.0, -0.01),), elements=16),
                   start=End("clamp"), end=End("free"))


def planned(comm):
    values = {**parse_values({}), "rod_initial_shape": "straight", "rod_steps": 2}
    return plan_line(comm, CANTILEVER, values, {"rod_initial_shape", "rod_steps"},
                     FIELD_NAMES)


def test_a_built_line_runs_again_from_its_last_state_and_is_destroyed():
    comm = PETSc.COMM_WORLD
    plan = planned(comm)
    with BuiltLine(comm, plan) as built:
        assert built.mesh.n_elements == 16 and built.scene is plan.scene
        path = built.start()
        first = LastStep()
        cold = built.run(path, writer=first)
        again = LastStep()          # from t_0 = t_end: one step at t = 1 from the state
        warm = built.run(dataclasses.replace(path, start=1.0), writer=again)
    assert built.mesh is None and built.problem is None and built.solver is None
    assert cold.converged and warm.converged
    # from the equilibrium itself the warm run needs one or two iterations
    assert warm.iterations <= 2 < cold.iterations
    tip = comm.tompi4py().allgather(first.vertex["r"])
    tip = np.concatenate(tip)[-1]
    assert tip[2] == pytest.approx(-0.01 / 8.0, rel=1e-3)
    warm_tip = np.concatenate(comm.tompi4py().allgather(again.vertex["r"]))[-1]
    assert np.allclose(warm_tip, tip, rtol=0, atol=1e-9)
    # the whole run and the API: the same numbers as the first run, bit for bit
    whole = run_line(comm, planned(comm), keep_last=True)
    assert whole.elements == 16 and whole.result.converged
    assert np.array_equal(whole.last.vertex["r"], first.vertex["r"])
    api = solve(Model(CANTILEVER.line, CANTILEVER.start, CANTILEVER.end, steps=2,
                      initial_shape="straight"), comm=comm)
    assert np.array_equal(api.owned["r"], first.vertex["r"])
