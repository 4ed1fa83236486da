"""The system's own stability at its equilibrium (system/verdict.py, docs/systems.md
"The system's verdict"): the small free body (tests/data/moordyn/small_free_body.dat)
stable with the lowest eigenvalue of its 6 x 6 (the mooring stiffness less the body's
own Jacobian); the same body made top-heavy (its cog 5 m above its reference point,
each line stable with its ends held) and the TLP of options/tlp.dat heavier than its
buoyancy (check_reach bypassed) reported as saddles of the system; in a current, no
verdict. Serially and under mpiexec -n 2 (the lines split over the ranks)."""

import dataclasses
import os

import h5py
import numpy as np
import pytest
from petsc4py import PETSc

from helpers import REPO_ROOT
from petsc_rod.api import read_moordyn, solve_system
from petsc_rod.system.equilibrium import SystemSolver
from petsc_rod.system.held_line import held_lines

pytestmark = pytest.mark.solver

SMALL = os.path.join(REPO_ROOT, "tests", "data", "moordyn", "small_free_body.dat")
TLP = os.path.join(REPO_ROOT, "options", "tlp.dat")
TIGHT = {"al_rtol": 1e-12, "al_ctol": 1e-12}


def solved(system):
    """(Equilibrium, the lowest eigenvalue of D sym(K_6x6 - J_own) D, N/m) of a system
    of one body and no free point: K_6x6 the body's mooring stiffness, J_own the
    Jacobian of its weight, buoyancy and hydrostatics, D 1 / the length scale on the
    rotations."""
    solver = SystemSolver(system, held_lines(system, TIGHT), PETSc.COMM_WORLD)
    try:
        found = solver.solve()
        K = solver.body_stiffness("Body1").matrix
        _, own = solver.own_part(solver.state, solver.loads)
        K = K - own[np.ix_(solver.layout.body_dofs[0], solver.layout.body_dofs[0])]
        D = np.diag([1.0] * 3 + [1.0 / solver.length] * 3)
        return found, float(np.linalg.eigvalsh(D @ (0.5 * (K + K.T)) @ D)[0])
    finally:
        solver.destroy()


def top_heavy():
    system, _ = read_moordyn(SMALL)
    body = dataclasses.replace(system.bodies[0], cog=(0.0, 0.0, 5.0))
    return dataclasses.replace(system, bodies=(body,))


def test_the_small_free_body_is_stable_with_its_6x6s_lowest_eigenvalue():
    system, _ = read_moordyn(SMALL)
    found, lowest = solved(system)
    verdict = found.verdict
    assert verdict.stable is True and verdict.negative == 0
    assert verdict.lowest == pytest.approx(lowest, rel=1e-10)
    assert verdict.lowest == pytest.approx(7270.88, rel=1e-5)        # heave, N/m
    assert verdict.dof == ("Body1", "z")
    assert verdict.text().startswith("stable (the lowest eigenvalue of its stiffness "
                                     "7270.88 N/m, mostly in Body1 z)")


def test_a_top_heavy_body_on_stable_lines_is_a_saddle_of_the_system(tmp_path):
    """The cog 5 m above the reference point: the weight's overturning moment,
    W 5 m = 981 kN m/rad, beats the lines' 801 kN m/rad in roll and pitch; Newton from
    the upright start stays upright (the spread is symmetric), each line stable with
    its ends held. Through the API (check_reach passes it): a saddle of the system in
    the run's lines and the file, converged = 0."""
    system = top_heavy()
    found, lowest = solved(system)
    assert found.unstable == () and all(found.stable.values())
    verdict = found.verdict
    assert verdict.stable is False and verdict.negative == 2
    assert verdict.lowest == pytest.approx(lowest, rel=1e-10)
    assert verdict.lowest == pytest.approx(-8424.52, rel=1e-5)
    assert verdict.dof[0] == "Body1" and verdict.dof[1] in ("roll", "pitch")
    output = os.path.join(str(tmp_path), "saddle.h5")
    output = PETSc.COMM_WORLD.tompi4py().bcast(output, root=0)
    said = []
    results = solve_system(system, output=output, say=said.append)
    assert results.verdict.stable is False and results.converged is False
    assert ("  the system's equilibrium: a saddle of the system: its stiffness has 2 "
            "negative eigenvalue(s), the lowest -8424.5") in "\n".join(said)
    PETSc.COMM_WORLD.tompi4py().barrier()
    with h5py.File(output, "r") as f:
        assert int(f["system"].attrs["system_stable"]) == 0
        assert int(f["system"].attrs["converged"]) == 0
        assert f["system"].attrs["system_verdict"].startswith("a saddle of the system")


def test_a_tlp_heavier_than_its_buoyancy_is_a_saddle_of_the_system():
    """check_reach refuses it up front; past it, the solver converges with the tendons
    in compression (pushing each anchor down by 2.2 MN): the hull's surge and sway
    stiffness is the tendons' pendulum's, negative, and so is its yaw's."""
    system, _ = read_moordyn(TLP)
    heavy = dataclasses.replace(system, bodies=tuple(
        dataclasses.replace(body, volume=5000.0) for body in system.bodies))
    found, lowest = solved(heavy)
    verdict = found.verdict
    assert verdict.stable is False and verdict.negative == 3
    assert verdict.lowest == pytest.approx(lowest, rel=1e-10)
    assert verdict.lowest == pytest.approx(-91556.2, rel=1e-5)
    assert verdict.dof in (("Body1", "x"), ("Body1", "y"))


def test_a_system_in_a_current_has_no_verdict():
    system = top_heavy()
    system = dataclasses.replace(system, environment=dataclasses.replace(
        system.environment, current=(0.2, 0.0, 0.0)))
    found, _ = solved(system)
    assert found.verdict.stable is None and found.verdict.code() == -1
    assert found.verdict.text().startswith("no verdict: a current: its drag")


def test_the_systems_stiffness_is_symmetric_at_a_conservative_equilibrium():
    """The reason the symmetric part is tested (docs/systems.md "The system's verdict"):
    under a force of (10, 2, 0) kN at the reference point the lines' 6 x 6 is
    unsymmetric by 1e-2 (their moment about X), but the system's K = -dR/dq, the
    weight's and buoyancy's arms with it, is symmetric to round-off (the moments sum to
    0); a moment of 50 kN m fixed in space leaves it unsymmetric (-[M_load]x) and has no
    verdict."""
    system, _ = read_moordyn(SMALL)
    asymmetry = {}
    for name, load in (("force", (1e4, 2e3, 0.0, 0.0, 0.0, 0.0)),
                       ("moment", (1e4, 2e3, 0.0, 0.0, 0.0, 5e4))):
        loaded = dataclasses.replace(system, bodies=(dataclasses.replace(
            system.bodies[0], load=load),))
        solver = SystemSolver(loaded, held_lines(loaded, TIGHT), PETSc.COMM_WORLD)
        try:
            found = solver.solve()
            _, J = solver.residual(solver.state, solver.loads, solver.forces,
                                   solver.stiffnesses)
            D = np.diag([1.0] * 3 + [1.0 / solver.length] * 3)
            K = -D @ J @ D
            asymmetry[name] = (np.linalg.norm(K - K.T) / np.linalg.norm(K),
                               solver.body_stiffness("Body1").asymmetry, found.verdict)
        finally:
            solver.destroy()
    system_part, lines_part, verdict = asymmetry["force"]
    assert lines_part > 5e-3 and system_part < 1e-12
    assert verdict.stable is True
    assert verdict.lowest == pytest.approx(6556.18, rel=1e-5)
    system_part, _, verdict = asymmetry["moment"]
    assert system_part > 1e-2
    assert verdict.stable is None and "has a moment, fixed in space" in verdict.reason
