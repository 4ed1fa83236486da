"""The natural modes of a system's bodies and free points (petsc_rod/system/body_modes.py)
against closed forms, with the spring lines of test_system_equilibrium (an axial spring
and its exact 6 x 6): a neutrally buoyant point between two taut springs, omega^2 = 2k/m
along and 2T/(L m) across; a body on four horizontal springs, its surge and its heave on
the waterplane alone, 2 pi sqrt((m + A33) / (rho g A_wp)); an unstable equilibrium
refused. Serially and under mpiexec -n 2 (the lines split over the ranks: the same
numbers)."""

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.model.sea import Environment
from petsc_rod.model.system import Body, Point, System
from petsc_rod.system.body_modes import SystemModesRefused, mass_matrix, system_modes
from petsc_rod.system.equilibrium import SystemSolver

from test_system_equilibrium import G, RHO, link, spring


def solved(system):
    solver = SystemSolver(system, spring, PETSc.COMM_WORLD)
    solver.solve()
    return solver


def same_on_every_rank(values):
    every = PETSc.COMM_WORLD.tompi4py().allgather(np.asarray(values))
    assert all(np.array_equal(every[0], v) for v in every)


def point_between(k=3e4, span=20.0, rest=18.0, mass=500.0, ca=0.8):
    """A neutrally buoyant point (mass kg, volume mass / rho) between two fixed points
    2 span apart on springs of rest length ``rest``."""
    env = Environment(water_density=RHO, gravity=G)
    points = (Point("west", "fixed", (-span, 0.0, -10.0)),
              Point("east", "fixed", (span, 0.0, -10.0)),
              Point("mid", "free", (0.3, 0.0, -10.0), mass=mass, volume=mass / RHO, ca=ca))
    lines = (link("a", "west", "mid", k, rest), link("b", "mid", "east", k, rest))
    return System(lines, points, (), env)


def test_point_on_two_taut_springs():
    k, span, rest, mass, ca = 3e4, 20.0, 18.0, 500.0, 0.8
    solver = solved(point_between(k, span, rest, mass, ca))
    try:
        modes = system_modes(solver)
    finally:
        solver.destroy()
    total = mass * (1 + ca)                                 # ca rho V = ca m
    tension = k * (span - rest)
    across, along = 2 * tension / (span * total), 2 * k / total
    assert np.allclose(modes.omega2, [across, across, along], rtol=1e-12)
    assert modes.labels[2] == "mid x"
    assert sorted(modes.labels[:2]) == ["mid y", "mid z"]
    assert np.allclose(modes.shares.max(axis=1), 1.0, atol=1e-12)
    assert np.allclose(modes.modal_mass, total, rtol=1e-12)
    same_on_every_rank(modes.omega2)


def floater(rest=30.0, k=4e4, held_rotations=True, added=(2e5, 3e5, 1.5e5),
            area=60.0, mass=1e6):
    """A body (mass kg, buoyant as heavy, waterplane ``area``) on four horizontal
    springs of length 30 m from anchors at its reference point's height, at rest length
    ``rest``; its added mass diag(added) in the translations."""
    env = Environment(water_density=RHO, gravity=G)
    anchors = [Point(f"p{i}", "fixed", (30.0 * np.cos(a), 30.0 * np.sin(a), 0.0))
               for i, a in enumerate(np.radians([0, 90, 180, 270]))]
    A = np.zeros((6, 6))
    A[[0, 1, 2], [0, 1, 2]] = added
    body = Body("hull", mass=mass, volume=mass / RHO, waterplane_area=area,
                held=(False,) * 3 + (held_rotations,) * 3,
                added_mass=tuple(A.ravel()))
    lines = tuple(link(f"l{i}", p.name, "hull", k, rest) for i, p in enumerate(anchors))
    return System(lines, tuple(anchors), (body,), env)


MASS, ADDED, AREA, K = 1e6, (2e5, 3e5, 1.5e5), 60.0, 4e4


def floater_modes(rest):
    solver = solved(floater(rest=rest, k=K, added=ADDED, area=AREA, mass=MASS))
    try:
        return system_modes(solver)
    finally:
        solver.destroy()


def test_heave_on_the_waterplane_and_surge_on_springs():
    """Springs at their rest length carry no tension: heave is the waterplane's alone,
    T = 2 pi sqrt((m + A33) / (rho g A_wp)); surge and sway 2k / (m + A11)."""
    mass, added, area, k = MASS, ADDED, AREA, K
    modes = floater_modes(30.0)
    heave = RHO * G * area / (mass + added[2])
    expected = {"hull x": 2 * k / (mass + added[0]), "hull y": 2 * k / (mass + added[1]),
                "hull z": heave}
    found = dict(zip(modes.labels, modes.omega2))
    assert set(found) == set(expected)
    for name, value in expected.items():
        assert found[name] == pytest.approx(value, rel=1e-10)
    period = modes.periods[modes.labels.index("hull z")]
    assert period == pytest.approx(2 * np.pi * np.sqrt((mass + added[2]) / (RHO * G * area)),
                                   rel=1e-10)
    same_on_every_rank(modes.omega2)


def test_taut_springs_add_their_geometric_stiffness():
    """At rest length 25 m of a 30 m span each spring pulls T = 5 k: surge
    (2k + 2T/L) / (m + A11), heave (rho g A_wp + 4T/L) / (m + A33)."""
    mass, added, area, k = MASS, ADDED, AREA, K
    modes = floater_modes(25.0)
    geometric = k * 5.0 / 30.0
    found = dict(zip(modes.labels, modes.omega2))
    assert found["hull x"] == pytest.approx((2 * k + 2 * geometric) / (mass + added[0]),
                                            rel=1e-10)
    assert found["hull z"] == pytest.approx((RHO * G * area + 4 * geometric)
                                            / (mass + added[2]), rel=1e-10)


def test_rigid_mass_about_the_reference_point():
    """A body's 6 x 6 mass about X (global axes) from its mass, cog and inertia: the
    kinetic energy of a rotation rate w about X is (w . (I_g + m (|c|^2 - c c^T)) w) / 2,
    and a translation carries the cog's momentum m v, whose moment about X is c x m v."""
    system = floater(held_rotations=False, added=(0.0, 0.0, 0.0))
    inertia = np.array([[3e7, 1e5, 0.0], [1e5, 4e7, 0.0], [0.0, 0.0, 2e7]])
    body = system.bodies[0]
    from dataclasses import replace
    turned = replace(body, position=(0.0, 0.0, 0.0, 0.1, -0.2, 0.3), cog=(0.5, -0.4, -6.0),
                     inertia=tuple(inertia.ravel()), added_mass=None)
    system = replace(system, bodies=(turned,))
    solver = SystemSolver(system, spring, PETSc.COMM_WORLD)
    try:
        M = mass_matrix(solver)
        R = solver.state.bodies.R[0]
    finally:
        solver.destroy()
    c = R @ np.array(turned.cog)
    rng = np.random.default_rng(3)
    v, w = rng.normal(size=3), rng.normal(size=3)
    # the body as many small masses: a cloud with the body's mass, cog and inertia
    q = np.concatenate([v, w])
    kinetic = 0.5 * q @ M @ q
    velocity_cog = v + np.cross(w, c)
    expected = 0.5 * turned.mass * velocity_cog @ velocity_cog + 0.5 * w @ R @ inertia @ R.T @ w
    assert kinetic == pytest.approx(expected, rel=1e-13)


def test_an_unstable_equilibrium_is_refused():
    """A point between two compressed springs (rest 22 m over 20 m): in equilibrium by
    symmetry, but across the line it is pushed away (2T/L < 0): refused, no frequency."""
    solver = solved(point_between(rest=22.0))
    try:
        with pytest.raises(SystemModesRefused, match="unstable .*2 negative eigenvalues"):
            system_modes(solver)
    finally:
        solver.destroy()


def test_the_oc3_spar_s_periods_on_its_real_lines():
    """OC3-Hywind's spar free on its deck's three chains (real lines, 2 m elements),
    the definition's mass properties and a strip-theory added mass
    (validation/oc3_hywind.free_spar): its surge, heave, pitch and yaw periods equal
    those of the same spar on elastic catenaries (a rigid frictionless seabed; their
    stiffness by central differences) within the touchdown's discretisation, and the
    published surge, heave and pitch periods within the added mass's approximation
    (docs/modes.md)."""
    from petsc_rod.model.moordyn import read_moordyn
    from petsc_rod.system.held_line import held_lines
    from petsc_rod.validation.oc3_hywind import PUBLISHED_FREQUENCIES, free_spar
    from test_system_equilibrium import CatenaryLine
    from test_system_oc3 import DECK
    deck, _ = read_moordyn(DECK, element_length=2.0)
    system = free_spar(deck)
    found = {}
    for name, make in (("rod", held_lines(system)),
                       ("catenary", lambda line, comm: CatenaryLine(902.2, 698.094, 384.243e6,
                                                                    seabed=-320.0))):
        solver = SystemSolver(system, make, PETSc.COMM_WORLD)
        try:
            solver.solve()
            found[name] = system_modes(solver)
        finally:
            solver.destroy()
    rod, catenary = found["rod"], found["catenary"]
    for modes in (rod, catenary):           # the pairs in either order: degenerate
        assert {modes.labels[0], modes.labels[1]} == {"spar x", "spar y"}
        assert {modes.labels[3], modes.labels[4]} == {"spar roll", "spar pitch"}
        assert modes.labels[2] == "spar z" and modes.labels[5] == "spar yaw"
    assert np.allclose(rod.periods[:2], catenary.periods[:2], rtol=3e-3)
    assert np.allclose(rod.periods[2:], catenary.periods[2:], rtol=5e-4)
    published = {name: 1 / f for name, f in PUBLISHED_FREQUENCIES.items()}
    assert rod.periods[0] == pytest.approx(published["surge"], rel=0.01)
    assert rod.periods[2] == pytest.approx(published["heave"], rel=0.02)
    assert rod.periods[4] == pytest.approx(published["pitch"], rel=0.04)
    same_on_every_rank(rod.omega2)


def test_a_constant_yaw_moment_makes_complex_modes_and_is_refused():
    """The three-spring spread of test_system_equilibrium under a constant (global)
    yaw moment of 2 MN m: the lines' moment about the reference point makes the
    rotational stiffness unsymmetric, [M]x / 2 coupling the equal roll and pitch (and
    through them surge and sway): complex eigenvalues of M^-1 K, refused; without the
    moment the same body has six real modes."""
    from dataclasses import replace
    from test_system_equilibrium import spread
    found = {}
    for moment in (0.0, 2e6):
        system = spread(load=(0.0,) * 5 + (moment,))
        system = replace(system, bodies=(replace(system.bodies[0],
                                                 inertia=(5e8, 5e8, 8e8)),))
        solver = solved(system)
        try:
            found[moment] = system_modes(solver)
        except SystemModesRefused as refused:
            found[moment] = refused
        finally:
            solver.destroy()
    assert len(found[0.0].omega2) == 6 and found[0.0].imaginary < 1e-12
    refused = found[2e6]
    assert isinstance(refused, SystemModesRefused)
    assert refused.complex == 4 and refused.negative == 0
    assert "complex eigenvalues" in str(refused)


def test_the_lines_mass_lumped_half_at_each_end():
    """With line_mass: each spring's mass (its UniformLine's mass in air, here its load
    over g, times its length) half at each end, the fixed ends' halves held: the point carries one half
    of each, omega^2 = 2k / (m (1 + ca) + w L0 / g) along the line; without it, none."""
    from dataclasses import replace
    k, span, rest, mass, ca, w = 3e4, 20.0, 18.0, 500.0, 0.8, 400.0
    system = point_between(k, span, rest, mass, ca)
    heavy = tuple(replace(line, line=replace(line.line, load=((0.0, 0.0, -w),),
                                             mass=w / G))
                  for line in system.lines)
    solver = solved(replace(system, lines=heavy))
    try:
        lumped, bare = system_modes(solver, line_mass=True), system_modes(solver)
    finally:
        solver.destroy()
    assert lumped.line_mass and not bare.line_mass
    along = dict(zip(lumped.labels, lumped.omega2))["mid x"]
    assert along == pytest.approx(2 * k / (mass * (1 + ca) + w * rest / G), rel=1e-12)
    assert dict(zip(bare.labels, bare.omega2))["mid x"] == pytest.approx(
        2 * k / (mass * (1 + ca)), rel=1e-12)


def test_refused_modes_in_the_file_and_no_table(shared_tmp):
    """small_free_body.dat's body (given an inertia) under a constant yaw moment of
    200 kN m: its modes refused as complex, in the run's lines and the file's
    system/modes (the attribute ``refused``, no dataset), and an earlier run's
    FILE_system_modes.csv removed, no table written."""
    import dataclasses
    import os

    import h5py

    from petsc_rod.api import read_moordyn, solve_system
    from helpers import REPO_ROOT
    system, _ = read_moordyn(os.path.join(REPO_ROOT, "tests", "data", "moordyn",
                                          "small_free_body.dat"))
    body = dataclasses.replace(system.bodies[0], load=(0.0,) * 5 + (2e5,),
                               inertia=(1e5, 1e5, 1e5))
    system = dataclasses.replace(system, bodies=(body,))
    output, table = (os.path.join(shared_tmp, name) for name in ("refused.h5", "refused.csv"))
    stale = os.path.join(shared_tmp, "refused_system_modes.csv")
    if PETSc.COMM_WORLD.getRank() == 0:
        with open(stale, "w") as f:
            f.write("an earlier run's\n")
    PETSc.COMM_WORLD.tompi4py().barrier()
    said = []
    results = solve_system(system, output=output, table=table, say=said.append,
                           options={"system_modes": True})
    assert isinstance(results.body_modes, SystemModesRefused)
    refused = results.body_modes
    assert refused.complex >= 2 and refused.complex % 2 == 0 and refused.negative == 0
    assert any(line.startswith("system modes: refused: the system's equilibrium is "
                               f"unstable ({refused.complex} complex") for line in said)
    assert not os.path.exists(stale)
    with h5py.File(output, "r") as f:
        group = f["system/modes"]
        assert "complex eigenvalues" in group.attrs["refused"] and len(group) == 0


def test_a_run_removes_the_optional_tables_it_did_not_write(shared_tmp):
    """small_free_body.dat solved with -rod_table but neither the system's modes nor a
    sweep: an earlier run's FILE_system_modes.csv, FILE_watch_circle.csv and
    FILE_excursion.csv are removed (they stood beside the new tables as if this run's),
    FILE_system.csv written."""
    import os

    from petsc_rod.api import read_moordyn, solve_system
    from helpers import REPO_ROOT
    system, _ = read_moordyn(os.path.join(REPO_ROOT, "tests", "data", "moordyn",
                                          "small_free_body.dat"))
    table = os.path.join(shared_tmp, "stale.csv")
    stale = [os.path.join(shared_tmp, f"stale_{name}.csv")
             for name in ("system_modes", "watch_circle", "excursion")]
    if PETSc.COMM_WORLD.getRank() == 0:
        for path in stale:
            with open(path, "w") as f:
                f.write("an earlier run's\n")
    PETSc.COMM_WORLD.tompi4py().barrier()
    results = solve_system(system, table=table, say=lambda line: None)
    assert results.body_modes is None
    PETSc.COMM_WORLD.tompi4py().barrier()
    assert [os.path.exists(path) for path in stale] == [False] * 3
    assert os.path.exists(os.path.join(shared_tmp, "stale_system.csv"))


def test_the_lines_mass_is_their_mass_in_air():
    """line_masses: a Line of a line type of 80 kg/m in air and 0.3 m od (its weight
    in water (80 - 1025 pi 0.3^2 / 4) g, 63 % of its weight in air) weighs 80 L, and a
    UniformLine under 400 N/m given 50 kg/m its 50 L, not |w| L / g; a UniformLine
    without a mass is refused in one line (its load is a weight in water), never
    taken as |w| / g."""
    from dataclasses import replace
    from petsc_rod.model.line import Line
    from petsc_rod.model.line_type import LineType
    from petsc_rod.system.body_modes import line_masses
    from petsc_rod.errors import RodInputError
    system = point_between()
    chain = LineType("chain", od=0.3, mass=80.0, ei=(1e3, 1e3), gj=1e3, ea=1e8)
    typed = replace(system.lines[0], line=Line(((chain, 18.0),)))
    uniform = replace(system.lines[1], line=replace(system.lines[1].line,
                                                    load=((0.0, 0.0, -400.0),), mass=50.0))
    masses = line_masses(replace(system, lines=(typed, uniform)))
    assert masses == pytest.approx([80.0 * 18.0, 50.0 * 18.0], rel=1e-14)
    wet = replace(uniform, line=replace(uniform.line, mass=None))
    with pytest.raises(RodInputError, match="system_modes_line_mass: line b is a "
                                            "UniformLine without a mass in air"):
        line_masses(replace(system, lines=(typed, wet)))
