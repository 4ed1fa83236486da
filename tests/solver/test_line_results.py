"""The results along the line and at its ends (quantities/line_results.py) and the regions
(quantities/regions.py) of solved lines: against EI times the curvature, the balance of the
end forces with the loads, hand angles, and one rank against all (each scene solved on
PETSc.COMM_SELF and on PETSc.COMM_WORLD: under mpiexec -n 2 the 1-versus-2-ranks
check). Serial and under mpiexec -n 2."""

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import gather, make_solver, destroy
from petsc_rod.environment.seabed import Seabed
from petsc_rod.io.line_table import final_record
from petsc_rod.problem.penalty import default_penalty
from petsc_rod.scenes.scene import Scene
from petsc_rod.scenes.starts import catenary_start

# A catenary in the x-z plane: 10 m of line of 2 N/m, EI = 0.5 N m^2, pinned at the
# origin and at (7, 0, 3) (the top, S = L) or (7, 0, -3) (the top the start).
CATENARY = dict(length=10.0, stiffness=(0.5, 0.5, 0.4), start="pin", end="pin",
                end_position=(7.0, 0.0, 3.0), load_values=[[0.0, 0.0, -2.0]])
# The same resting partly on a seabed at z = -1 (a touchdown, a grounded part).
GROUNDED = dict(CATENARY, end_position=(6.0, 0.0, 3.0), seabed=Seabed(-1.0, 1e5))
LINE_DATASETS = ("curvature", "bend_radius", "bending_moment", "torque", "shear",
                 "declination", "effective_tension")


def solve(comm, scene, elements=80):
    """(vertex datasets gathered on every rank, attributes) of ``scene`` solved from its
    catenary start on ``comm``."""
    mesh, solver = make_solver(comm, elements, scene, default_penalty(Scene(**scene)),
                               rtol=1e-12, ctol=1e-12, max_it=20000, newton=False)
    try:
        solver.problem.state.set_from_curve(catenary_start(solver.problem.scene, 1.0))
        assert solver.solve_step(1.0).converged
        vertex, attributes = final_record(solver.problem)
        return {key: gather(comm, value) for key, value in vertex.items()}, attributes
    finally:
        destroy(mesh, solver)


@pytest.fixture(scope="module")
def catenary():
    return solve(PETSc.COMM_WORLD, CATENARY)


def test_bend_radius_and_moment_are_ei_times_the_curvature(catenary):
    """bending_moment = EI |(u1, u2)| (K1 = K2 = EI), bend_radius = 1 / curvature, the
    curvature |(u1, u2)|; the line bends in its plane: no torque; shear =
    |n - (n.t) t|."""
    vertex, _ = catenary
    kappa = np.hypot(vertex["u"][:, 0], vertex["u"][:, 1])
    np.testing.assert_allclose(vertex["curvature"], kappa, rtol=1e-15)
    assert kappa.max() > 0.05
    np.testing.assert_allclose(vertex["bending_moment"], 0.5 * kappa, rtol=1e-12,
                               atol=1e-14)
    np.testing.assert_allclose(vertex["bend_radius"], 1 / kappa, rtol=1e-14)
    assert np.abs(vertex["torque"]).max() < 1e-9
    t = vertex["d3"] / np.linalg.norm(vertex["d3"], axis=1, keepdims=True)
    tension = np.einsum("nc,nc->n", vertex["n"], t)
    np.testing.assert_allclose(vertex["effective_tension"], tension, rtol=1e-15)
    across = np.linalg.norm(vertex["n"] - tension[:, None] * t, axis=1)
    np.testing.assert_allclose(vertex["shear"], across, rtol=1e-12, atol=1e-12)
    assert vertex["shear"].max() > 1e-3        # bending carries some of the load


def test_end_forces_balance_the_weight_and_the_hang_off_angles(catenary):
    """What the line exerts on its supports carries its weight: start_force + end_force
    = (0, 0, -w L) = (0, 0, -20) N; the horizontal parts are equal and opposite (the
    line pulls the two pins toward each other). The top is the end S = L at (7, 0, 3):
    the tangent out of the line there points up and toward +x: azimuth 0, declination
    the angle of d3(L) from the vertical, the dataset's at that vertex."""
    vertex, attributes = catenary
    total = attributes["start_force"] + attributes["end_force"]
    np.testing.assert_allclose(total, [0.0, 0.0, -20.0], atol=1e-9)
    assert attributes["start_force"][0] > 1.0          # the anchor is pulled toward +x
    np.testing.assert_allclose(attributes["start_force"], vertex["n"][0], rtol=1e-15)
    np.testing.assert_allclose(attributes["end_force"], -vertex["n"][-1], rtol=1e-15)
    np.testing.assert_allclose(attributes["end_moment"], -vertex["m"][-1], rtol=1e-15)
    assert attributes["hang_off_S"] == 10.0
    assert attributes["hang_off_azimuth"] == 0.0
    t = vertex["d3"][-1] / np.linalg.norm(vertex["d3"][-1])
    assert attributes["hang_off_declination"] == pytest.approx(
        np.degrees(np.arccos(t[2])), rel=1e-13)
    assert attributes["hang_off_declination"] == pytest.approx(vertex["declination"][-1],
                                                               rel=1e-13)
    assert 0 < attributes["hang_off_declination"] < 90


def test_a_top_at_the_start_has_azimuth_180():
    """Top at S = 0 (the end at (7, 0, -3) is lower): the tangent out of the line there
    is -d3(0), pointing up and toward -x: azimuth 180, declination below 90."""
    _, attributes = solve(PETSc.COMM_WORLD, dict(CATENARY, end_position=(7.0, 0.0, -3.0)))
    assert attributes["hang_off_S"] == 0.0
    assert attributes["hang_off_azimuth"] == 180.0
    assert 0 < attributes["hang_off_declination"] < 90
    total = attributes["start_force"] + attributes["end_force"]
    np.testing.assert_allclose(total, [0.0, 0.0, -20.0], atol=1e-9)


def test_one_rank_and_all_give_the_same_results_and_regions():
    """The line's datasets and the regions' numbers of a line resting on a seabed, solved
    on one rank and on all, to the iteration's tolerance; the regions of a catenary
    riser: hang-off, sag bend, touchdown zone, grounded part."""
    one, one_attributes = solve(PETSc.COMM_SELF, GROUNDED)
    every, attributes = solve(PETSc.COMM_WORLD, GROUNDED)
    for key in LINE_DATASETS + ("seabed_reaction",):
        if key == "bend_radius":        # 1 / round-off where the grounded line is flat
            continue
        scale = np.abs(one[key]).max()
        np.testing.assert_allclose(every[key], one[key], rtol=1e-6, atol=1e-8 * scale,
                                   err_msg=key)
    curved = one["curvature"] > 1e-3 * one["curvature"].max()
    np.testing.assert_allclose(every["bend_radius"][curved], one["bend_radius"][curved],
                               rtol=1e-6)
    # the start, a pin 1 m above the seabed, hangs down to it: a free span, then the
    # line lies on the seabed up to the touchdown
    assert list(attributes["region_names"]) == ["hang_off", "sag_bend", "touchdown_zone",
                                                "grounded", "free_span"]
    assert list(one_attributes["region_names"]) == list(attributes["region_names"])
    np.testing.assert_allclose(attributes["region_bounds"], one_attributes["region_bounds"],
                               rtol=1e-8, atol=1e-8)
    for key in ("region_max_tension", "region_min_bend_radius", "region_max_bending_moment"):
        np.testing.assert_allclose(attributes[key], one_attributes[key], rtol=1e-6,
                                   err_msg=key)
    for key in ("region_max_tension_S", "region_min_bend_radius_S",
                "region_max_bending_moment_S"):
        np.testing.assert_allclose(attributes[key], one_attributes[key], atol=1e-9,
                                   err_msg=key)
    # the largest tension is at the top, in the hang-off; the grounded part ends at S = 0
    bounds = dict(zip(attributes["region_names"], attributes["region_bounds"]))
    assert attributes["region_max_tension_S"][0] == 10.0
    assert bounds["free_span"][0] == 0.0
    assert bounds["free_span"][1] == bounds["grounded"][0]
    assert bounds["grounded"][1] == pytest.approx(bounds["sag_bend"][0], abs=1e-12)
    landed = every["r"][:, 2] < -1.0 + 1e-3
    assert every["S"][landed].min() == pytest.approx(bounds["grounded"][0], abs=0.125)
    assert np.all(every["r"][every["S"] < bounds["grounded"][0] - 0.125, 2] > -1.0 + 1e-3)


# A seabed with a trench 1 m deep between x = 3 and 5 (steps of 1 cm), and a line lying on
# it (1 mm in) from the pin at the origin to x = 6, then rising at 45 degrees to the top:
# the line spans the trench. A state given as a curve: the regions read the state.
TRENCH_DEPTH, PENETRATION, FLAT = 1.0, 1e-3, 6.0


def trench_line(S):
    """(r, frames (rows d1, d2, d3), force (a unit tension)) of the line over the trench
    at S (n,)."""
    S = np.asarray(S, dtype=float)
    rising = S > FLAT
    angle = np.where(rising, np.pi / 4, 0.0)
    t = np.stack([np.cos(angle), np.zeros_like(S), np.sin(angle)], axis=-1)
    beyond = np.maximum(S - FLAT, 0.0)
    r = np.stack([np.minimum(S, FLAT) + beyond * np.cos(np.pi / 4), np.zeros_like(S),
                  -PENETRATION + beyond * np.sin(np.pi / 4)], axis=-1)
    d1 = np.broadcast_to([0.0, 1.0, 0.0], t.shape)
    return r, np.stack([d1, np.cross(t, d1), t], axis=1), t


def test_a_span_over_a_trench_is_a_free_span_not_grounded(comm):
    """Regions of the line over the trench (profile rows 3 | 3.01 and 4.99 | 5): grounded
    from the touchdown (x = 6) to the trench's far edge, a free span over the trench,
    grounded again to the anchor. In contact is a gap below the largest penetration
    (1 mm): the bounds are where the gap crosses it, within the 1 cm steps. Before, the
    whole line beyond the touchdown was "grounded"."""
    from petsc_rod.environment.bathymetry import Profile

    profile = Profile(np.zeros(2), np.array([1.0, 0.0]),
                      np.array([-1.0, 3.0, 3.01, 4.99, 5.0, 20.0]),
                      np.array([0.0, 0.0, -TRENCH_DEPTH, -TRENCH_DEPTH, 0.0, 0.0]))
    length = FLAT + 4.0
    top = trench_line(np.array([length]))[0][0]
    scene = dict(CATENARY, length=length, end_position=top,
                 seabed=Seabed(0.0, 1e5, profile))
    mesh, solver = make_solver(comm, 100, scene, 10.0)
    try:
        solver.problem.prepare(1.0)
        solver.problem.state.set_from_curve(trench_line)
        _, attributes = final_record(solver.problem)
    finally:
        destroy(mesh, solver)
    bounds = dict(zip(attributes["region_names"], attributes["region_bounds"]))
    assert list(bounds)[-3:] == ["grounded", "free_span", "grounded_2"]
    np.testing.assert_allclose(bounds["grounded"], [5.0, FLAT], atol=0.01)
    np.testing.assert_allclose(bounds["free_span"], [3.0, 5.0], atol=0.01)
    np.testing.assert_allclose(bounds["grounded_2"], [0.0, 3.0], atol=0.01)


def test_an_anchor_that_lifts_off_is_said_with_its_angle_and_force(comm):
    """The catenary pinned at an anchor on the seabed (z = 0) and pulled taut enough to
    rise from it (top at (9, 0, 4)): no touchdown, and the anchor's uplift angle and
    force are those of the inextensible catenary, atan(V0 / H) and V0 (at EI 5e-3 N m^2
    the angle is off by the bending layer's 0.9 %, 10 % at EI 0.5; the force by 1e-4 of
    V0); said in the final lines. Before, only touchdown_S = nan."""
    from petsc_rod.cli.messages import summary
    from petsc_rod.scenes.catenary import catenary

    top = np.array([9.0, 0.0, 4.0])
    vertex, attributes = solve(comm, dict(CATENARY, stiffness=(5e-3, 5e-3, 5e-3),
                                          end_position=top, seabed=Seabed(0.0, 1e5)),
                               elements=160)
    assert np.isnan(attributes["touchdown_S"])
    _, _, force = catenary(10.0, top, np.array([0.0, 0.0, -2.0]), np.array([0.0]))
    H, V0 = force[0][0], force[0][2]
    assert V0 > 0.5                                      # the exact line rises from it
    assert attributes["anchor_uplift_S"] == 0.0
    t = vertex["d3"][0]
    assert attributes["anchor_uplift_angle"] == pytest.approx(
        np.degrees(np.arctan2(t[2], t[0])), rel=1e-12)
    assert attributes["anchor_uplift_angle"] == pytest.approx(np.degrees(np.arctan2(V0, H)),
                                                              rel=1.5e-2)
    assert attributes["anchor_uplift_force"] == pytest.approx(V0, rel=1e-3)
    assert attributes["anchor_uplift_force"] == attributes["start_force"][2]
    lines = "\n".join(summary(attributes))
    assert "no touchdown: the anchor at S = 0 m lifts off at" in lines
    assert f"pulled up by {attributes['anchor_uplift_force'] / 1e3:.6g} kN" in lines


def test_a_grounded_anchor_says_no_uplift():
    """The line resting on the seabed (GROUNDED): a touchdown, no uplift numbers."""
    _, attributes = solve(PETSc.COMM_WORLD, GROUNDED)
    assert np.isfinite(attributes["touchdown_S"])
    assert "anchor_uplift_force" not in attributes


def test_fairlead_and_anchor_forces_are_the_catenary_h_and_v(comm):
    """The lifted-anchor catenary (top (9, 0, 4), EI 5e-3 N m^2): the fairlead's
    horizontal and vertical force are the inextensible catenary's H and V(L) = V0 + w L,
    the anchor's H and V0, to 1e-3 (the bending layer's share); the components are the
    end force's, the uplift flagged 1; the final lines say them in kN. Before, only the
    end_force vector and touchdown_S = nan."""
    from petsc_rod.cli.messages import summary
    from petsc_rod.scenes.catenary import catenary

    top = np.array([9.0, 0.0, 4.0])
    _, attributes = solve(comm, dict(CATENARY, stiffness=(5e-3, 5e-3, 5e-3),
                                     end_position=top, seabed=Seabed(0.0, 1e5)),
                          elements=160)
    _, _, force = catenary(10.0, top, np.array([0.0, 0.0, -2.0]), np.array([0.0, 10.0]))
    H, V0, VL = force[0][0], force[0][2], force[1][2]
    assert VL == pytest.approx(V0 + 20.0, rel=1e-9)
    a = attributes
    assert a["fairlead_horizontal"] == pytest.approx(H, rel=1e-3)
    assert a["fairlead_vertical"] == pytest.approx(VL, rel=1e-3)
    assert a["fairlead_tension"] == pytest.approx(np.hypot(H, VL), rel=1e-3)
    np.testing.assert_array_equal([a[f"fairlead_force_{c}"] for c in "xyz"], a["end_force"])
    assert a["fairlead_force_x"] < 0.0 and a["fairlead_force_z"] < 0.0   # pulled down, in
    np.testing.assert_allclose(a["fairlead_position"], top, atol=1e-12)
    assert a["anchor_horizontal"] == pytest.approx(H, rel=1e-3)
    assert a["anchor_vertical"] == pytest.approx(V0, rel=1e-3)
    assert a["anchor_vertical"] == a["anchor_uplift_force"]
    np.testing.assert_allclose(a["anchor_position"], 0.0, atol=1e-12)
    assert a["anchor_uplift"] == 1 and np.isnan(a["touchdown_x"])
    lines = "\n".join(summary(a))
    assert (f"fairlead force {a['fairlead_tension'] / 1e3:.6g} kN: horizontal "
            f"{a['fairlead_horizontal'] / 1e3:.6g} kN, vertical "
            f"{a['fairlead_vertical'] / 1e3:.6g} kN") in lines
    assert "the anchor lifts off" in lines


def test_a_grounded_anchor_is_flagged_not_lifting_with_its_touchdown():
    """The line resting on the seabed: anchor_uplift 0, the touchdown's x and y those of
    its position; the anchor holds only what friction-free ground leaves: a horizontal
    pull, equal to the fairlead's H (the line's horizontal balance, no horizontal load)."""
    _, a = solve(PETSc.COMM_WORLD, GROUNDED)
    assert a["anchor_uplift"] == 0
    assert a["touchdown_x"] == a["touchdown_position"][0] and a["touchdown_y"] == 0.0
    assert 0.5 < a["touchdown_x"] < 6.0
    assert a["anchor_horizontal"] == pytest.approx(a["fairlead_horizontal"], rel=1e-9)
