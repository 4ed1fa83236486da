"""The linking number Lk = Tw + Wr of rods clamped at both ends
(petsc_rod/analysis/link.py) and the continuation's check that a step keeps it
(docs/stability.md, "Twist and Greenhill").

- Fuller's writhe against the Gauss double integral, on a curve given in closed form
  and on a converged writhed rod;
- Calugareanu-White on the solver's states: Tw + Wr is the end roll over 2 pi;
- a step that rolls the end by a whole turn (the clamps see no roll at all) is refused
  instead of returning the untwisted rod.
"""

import re

import numpy as np
import pytest

from helpers import continuation as reach_load, gather
from petsc_rod.cli.session import run_continuation
from petsc_rod.iteration.continuation import PathSettings
from petsc_rod.errors import RodNotConvergedError
from petsc_rod.validation.writhe import gauss_writhe

AXIS = np.array([1.0, 0.0, 0.0])


SLACK = dict(length=1.0, stiffness=(1.0, 1.0, 1.0), start="clamp", end="clamp",
             end_position=(0.9, 0.1, 0.0), end_twist=2 * np.pi)


def test_a_twisted_rod_with_slack_writhes_and_keeps_its_link(solver_factory, comm):
    """Clamped at both ends 0.9 L apart (0.1 L to the side), the end rolled by one turn in
    10 steps: Lk = Tw + Wr = 1 turn, part of it writhe; the solver's Fuller writhe and
    the Gauss integral of its centreline agree (same on 1 and 2 ranks)."""
    mesh, solver = solver_factory(comm, 64, SLACK, 100.0, 1e-6, 1e-5, 20000)
    report = reach_load(solver, steps=10, imperfection=0.01)
    assert report.converged
    twist, writhe = solver.problem.link()
    assert twist + writhe == pytest.approx(1.0, abs=2e-3)
    assert 0.03 < writhe < 0.1
    points = gather(comm, solver.problem.state.r.owned()[:, 0])
    assert gauss_writhe(points, AXIS) == pytest.approx(writhe, abs=2e-3)


PURE_TWIST = dict(length=1.0, stiffness=(1.0, 1.0, 0.5), start="clamp", end="clamp",
                  end_twist=2 * np.pi)


def test_a_whole_turn_in_one_step_is_refused(solver_factory, comm):
    """The end rolled by 2 pi in one step is the unrolled clamp: the iteration settles on
    the untwisted rod, which the link check refuses (exit 3); in 4 steps the rod keeps
    its turn, all of it twist (u3 = 2 pi / L)."""
    mesh, solver = solver_factory(comm, 32, PURE_TWIST, 100.0, 1e-8, 1e-5, 5000)
    solver.problem.state.set_straight()
    lines = []
    code = run_continuation(solver, PathSettings(1, max_halvings=0), say=lines.append).code
    assert code == RodNotConvergedError.exit_code, "\n".join(lines)
    found = re.search(r"linking number is (-?[0-9.]+) turns .* not the 1.000 turns", lines[-1])
    assert found and abs(float(found.group(1))) < 1e-3, lines[-1]
    solver.problem.state.set_straight()                           # -rod_track_link 0: accepted
    lines = []
    assert run_continuation(solver, PathSettings(1, max_halvings=0, track_link=False),
                            say=lines.append).code == 0
    assert abs(sum(solver.problem.link())) < 1e-3
    solver.problem.state.set_straight()
    lines = []
    assert run_continuation(solver, PathSettings(4, max_halvings=0),
                            say=lines.append).code == 0, "\n".join(lines)
    twist, writhe = solver.problem.link()
    # the twist integral of the P2 frames, O(h^4) from its limit: 3.1e-6 on 32 elements
    assert twist == pytest.approx(1.0, abs=1e-5) and abs(writhe) < 1e-9
    # the step line gives the link; its twist and writhe are the monitor's and the file's
    assert "link 1.0000 turns" in [line for line in lines if line.startswith("step 4/4")][0]
