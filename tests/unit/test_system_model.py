"""System.check (petsc_rod/model/system_check.py): every refusal of a system of lines,
points and bodies that cannot be solved, one line each, asserted by its words."""

import dataclasses

import numpy as np
import pytest

from petsc_rod.errors import RodInputError
from petsc_rod.model import (Body, Connection, Environment, Line, LineType, Point, System,
                             SystemLine)
from petsc_rod.model.system_check import balanced, check_reach, needed_strain, rotation

pytestmark = pytest.mark.unit

CHAIN = LineType("chain", od=0.1, mass=100.0, ei=1e3, gj=1e3, ea=1e9)
ROPE = LineType("rope", od=0.1, mass=10.0, ei=1e3, gj=1e3)          # inextensible
FAIRLEADS = ((5.0, 0.0, -10.0), (-2.5, 4.33, -10.0), (-2.5, -4.33, -10.0))
ANCHORS = ((500.0, 0.0, -200.0), (-250.0, 433.0, -200.0), (-250.0, -433.0, -200.0))


def spread(**change):
    """A floater on three 600 m chains from anchors on a flat seabed at -200 m."""
    fields = dict(
        points=tuple(Point(f"A{k + 1}", "fixed", p) for k, p in enumerate(ANCHORS)),
        bodies=(Body("float", mass=1e6, cog=(0.0, 0.0, -5.0), volume=1e3,
                     cob=(0.0, 0.0, -3.0), waterplane_area=100.0,
                     waterplane_moments=(1e4, 1e4)),),
        lines=tuple(SystemLine(f"L{k + 1}", Line([(CHAIN, 600.0)], element_length=10.0),
                               Connection(f"A{k + 1}"), Connection("float", f))
                    for k, f in enumerate(FAIRLEADS)),
        environment=Environment(seabed=-200.0))
    fields.update(change)
    return System(**fields)


def refused(system):
    with pytest.raises(RodInputError) as error:
        system.check()
    message = str(error.value)
    assert "\n" not in message
    return message


def test_the_spread_passes_every_check():
    spread().check()


def test_a_system_needs_a_line():
    assert "a system needs at least one line" in refused(spread(lines=(), points=()))


def test_names_are_unique_among_points_and_bodies_and_among_lines():
    system = spread()
    twice = dataclasses.replace(system, bodies=(Body("A1"),))
    assert refused(twice) == "two points or bodies are named A1: give each a name of its own"
    lines = system.lines[:2] + (dataclasses.replace(system.lines[2], name="L1"),)
    assert refused(dataclasses.replace(system, lines=lines)) == (
        "two lines are named L1: give each a name of its own")


def test_a_line_named_as_a_table_of_the_system_is_refused():
    """FILE_system.csv, the sweeps' tables and a line's _regions / _ends tables are
    written beside FILE_<line>.csv: a line of one of those names would share its file."""
    system = spread()
    for name in ("system", "watch_circle", "excursion"):
        message = refused(with_line(system, 0, name=name))
        assert message.startswith(f"line {name}: the name of the system's table")
        assert "rename the line" in message
    assert "another line's table" in refused(with_line(system, 1, name="L1_ends"))


def with_line(system, index, **change):
    lines = list(system.lines)
    lines[index] = dataclasses.replace(lines[index], **change)
    return dataclasses.replace(system, lines=tuple(lines))


def test_a_connection_names_an_existing_point_or_body():
    message = refused(with_line(spread(), 1, start=Connection("A9")))
    assert message == ("line L2: start: no point or body is named A9 (the points and "
                       "bodies: A1, A2, A3, float); name one of them")


def test_a_clamp_or_a_local_point_at_a_point_is_refused():
    message = refused(with_line(spread(), 0, start=Connection("A1", kind="clamp")))
    assert message.startswith("line L1: start: a clamp at point A1: a point has no "
                              "rotation to hold the line's end frame against")
    message = refused(with_line(spread(), 0, start=Connection("A1", local=(1.0, 0.0, 0.0))))
    assert "a local point belongs to a body" in message


def test_a_flex_joint_and_its_stiffness_go_together():
    system = spread()
    assert "a flex joint needs Connection.stiffness >= 0" in refused(
        with_line(system, 0, end=Connection("float", FAIRLEADS[0], "flex")))
    assert "Connection.stiffness is a flex joint's" in refused(
        with_line(system, 0, end=Connection("float", FAIRLEADS[0], "pin", 1e5)))
    with_line(system, 0, end=Connection("float", FAIRLEADS[0], "flex", 1e5)).check()


def test_a_line_does_not_join_a_point_to_itself():
    assert "both ends at point A1" in refused(with_line(spread(), 0, end=Connection("A1")))


def test_a_point_with_no_line_is_refused():
    system = spread()
    lonely = dataclasses.replace(system, points=system.points + (Point("buoy", "free"),))
    assert refused(lonely) == ("point buoy (free) is the end of no line: connect a line to "
                               "it, or drop it")


def held_pair(line_type, length, distance):
    """One line of ``length`` between a fixed and a prescribed point ``distance`` apart."""
    return System(lines=(SystemLine("tie", Line([(line_type, length)], element_length=5.0),
                                    Connection("a"), Connection("b")),),
                  points=(Point("a", "fixed", (0.0, 0.0, -50.0)),
                          Point("b", "prescribed", (distance, 0.0, -50.0))))


def test_a_line_too_short_for_its_held_points_is_refused():
    assert refused(held_pair(ROPE, 100.0, 101.0)) == (
        "line tie: a and b are held 101 m apart, 1 m more than its length 100 m "
        "(inextensible); lengthen the line, move the points closer, or give its line types "
        "an EA")
    held_pair(ROPE, 100.0, 100.0).check()
    held_pair(CHAIN, 100.0, 101.0).check()              # 1 % of stretch
    soft = dataclasses.replace(CHAIN, ea=50.0)          # T = 50 N per 100 %
    assert refused(held_pair(soft, 100.0, 250.0)).startswith(
        "line tie: a and b are held 250 m apart: its length 100 m must stretch by 150 % or "
        "more to reach, above 100 %")


def test_a_line_folded_on_one_vertical_is_refused_and_a_taut_one_passes():
    """check_not_folded: ends on one vertical (the prescribed point 50 m above the fixed
    one), a line longer than their distance refused by System.check (held ends) and by
    check_reach (a free end); as long as the distance, or stretched, it passes."""
    def vertical(length, kind="prescribed"):
        system = held_pair(CHAIN, length, 0.0)
        return dataclasses.replace(system, points=(system.points[0],
                                                   Point("b", kind, (0.0, 0.0, 0.0))))
    message = ("line tie: its ends a and b lie on one vertical 50 m apart where the run "
               "starts, and its length 60 m is longer, so it has no catenary and would "
               "fold on itself; shorten it to at most their distance (a taut tendon) or "
               "move an end sideways")
    assert refused(vertical(60.0)) == message
    free = vertical(60.0, "free")
    free.check()
    with pytest.raises(RodInputError) as error:
        check_reach(free)
    assert str(error.value) == message
    vertical(50.0).check()
    vertical(49.9).check()


def test_a_taut_line_to_a_free_point_runs_where_it_is_pulled_and_can_stretch():
    """check_reach, the run's (not System.check's: a free point's position is a guess): a
    line with a free end, as long as its ends' distance or shorter, starts straight along
    its chord (a tendon): refused where nothing pulls the free end along it (a weightless
    point, a hull heavier than its buoyancy: the taut lines would be in compression) or
    where it cannot stretch to it; passed where the free end's buoyancy pulls it; the
    option that made it named."""
    system = held_pair(CHAIN, 100.0, 100.0)
    free = dataclasses.replace(system, points=(system.points[0],
                                               Point("b", "free", (100.0, 0.0, -50.0))))
    free.check()
    message = ("line tie: taut between a and b where the run starts, as are all lines at "
               "b, and nothing pulls them: b's buoyancy less weight and load, (0, 0, 0) N, "
               "pulls it along none of them away from their other ends, so they would be "
               "in compression; give b more buoyancy than weight (a tension leg platform), "
               "or lengthen a line so it hangs slack")
    with pytest.raises(RodInputError) as error:
        check_reach(free)
    assert str(error.value) == message
    with pytest.raises(RodInputError) as error:
        check_reach(free, {("node", "b"): "-rod_system_offset", ("line", "b"): "-x"})
    assert "where the run starts (-rod_system_offset), as" in str(error.value)
    check_reach(held_pair(CHAIN, 100.0, 100.0))            # held ends: check_held_spans'
    check_reach(dataclasses.replace(free, points=(
        system.points[0], Point("b", "free", (99.9, 0.0, -50.0)))))

    def tendon(line_type, length, volume=2.0, mass=1000.0, force=(0.0, 0.0, 0.0)):
        """A 100 m vertical line from a to a free buoy b right above it."""
        return dataclasses.replace(held_pair(line_type, length, 0.0), points=(
            Point("a", "fixed", (0.0, 0.0, -150.0)),
            Point("b", "free", (0.0, 0.0, -50.0), mass=mass, volume=volume, force=force)))
    check_reach(tendon(CHAIN, 99.9))                    # 1025 kg of buoyancy net
    check_reach(tendon(CHAIN, 100.0))
    check_reach(tendon(CHAIN, 99.9, volume=0.0, mass=0.0, force=(0.0, 0.0, 1.0)))
    heavy = refused_reach(tendon(CHAIN, 99.9, volume=0.5))
    assert heavy.startswith("line tie: taut between a and b where the run starts, as are "
                            "all lines at b, and nothing pulls them: b's buoyancy less "
                            "weight and load, (0, 0, -4780.74) N, pulls it along none")
    assert refused_reach(tendon(ROPE, 99.9)) == (
        "line tie: its length 99.9 m is shorter than its ends' distance 100 m, a to b "
        "where the run starts, and it is inextensible: lengthen the line, move its ends "
        "closer, or give its line types an EA")
    check_reach(tendon(ROPE, 100.0))                    # as long as the distance
    soft = dataclasses.replace(CHAIN, ea=50.0)
    assert refused_reach(tendon(soft, 40.0)).startswith(
        "line tie: its length 40 m is shorter than its ends' distance 100 m, a to b where "
        "the run starts: it must stretch by 150 % or more to reach, above 100 %")
    # a hull held down by four tendons: buoyancy above its weight passes, below refused
    legs = [(x, y, -20.0) for x, y in ((10, 0), (0, 10), (-10, 0), (0, -10))]

    def platform(volume):
        return System(
            points=tuple(Point(f"A{k}", "fixed", (x, y, -200.0))
                         for k, (x, y, _) in enumerate(legs)),
            bodies=(Body("hull", mass=1e6, volume=volume),),
            lines=tuple(SystemLine(f"T{k}", Line([(CHAIN, 179.9)], element_length=10.0),
                                   Connection(f"A{k}"), Connection("hull", leg))
                        for k, leg in enumerate(legs)))
    check_reach(platform(1200.0))
    assert refused_reach(platform(900.0)).startswith(
        "line T0: taut between A0 and hull where the run starts, as are all lines at hull")


def refused_reach(system):
    with pytest.raises(RodInputError) as error:
        check_reach(system)
    return str(error.value)


def test_the_needed_strain_of_sections_in_series():
    # 100 m at EA 1e6 and 100 m inextensible pulled to 201 m: T = 1 / 1e-4 = 1e4 N
    assert needed_strain([100.0, 100.0], [1e6, np.inf], 201.0) == pytest.approx(1e-2)
    assert needed_strain([100.0], [np.inf], 100.5) == np.inf
    assert needed_strain([100.0], [1e6], 90.0) == 0.0


def test_a_held_body_s_fairlead_counts_as_a_held_end():
    system = held_pair(ROPE, 100.0, 0.0)
    body = Body("ship", position=(101.0, 0.0, -50.0, 0.0, 0.0, 0.0), held=(True,) * 6)
    tied = dataclasses.replace(system, points=system.points[:1], bodies=(body,),
                               lines=(dataclasses.replace(system.lines[0],
                                                          end=Connection("ship")),))
    assert "a and ship are held 101 m apart, 1 m more than its length" in refused(tied)
    # turned by 180 degrees in yaw, the fairlead 2 m ahead of the body lands at 99 m
    turned = dataclasses.replace(body, position=(101.0, 0.0, -50.0, 0.0, 0.0, np.pi))
    dataclasses.replace(tied, bodies=(turned,), lines=(dataclasses.replace(
        tied.lines[0], end=Connection("ship", (2.0, 0.0, 0.0))),)).check()


def test_a_body_that_nothing_restores_is_refused():
    lone = Body("barge", volume=10.0, mass=1e4)
    system = spread()
    message = refused(dataclasses.replace(system, bodies=system.bodies + (lone,)))
    assert message == ("body barge: nothing restores its x, y, z, roll, pitch, yaw: no "
                       "line to another point or body and no hydrostatic stiffness there; attach lines, give "
                       "Body.hydrostatic (or its waterplane), or hold x, y, z, roll, pitch, "
                       "yaw (Body.held)")
    held = dataclasses.replace(lone, waterplane_area=10.0, held=(True, True, False, True,
                                                                 True, True))
    dataclasses.replace(system, bodies=system.bodies + (held,)).check()


def test_a_body_on_one_pinned_line_turns_freely_about_it_in_yaw():
    system = spread()
    one = dataclasses.replace(system, lines=system.lines[:1], points=system.points[:1])
    message = refused(one)
    assert message.startswith("body float: nothing restores its yaw: its 1 line end(s), "
                              "all pinned on one line along that axis,")
    clamped = with_line(one, 0, end=Connection("float", FAIRLEADS[0], "clamp"))
    clamped.check()


def test_a_hydrostatic_matrix_stands_in_for_the_waterplane():
    system = spread()
    body = dataclasses.replace(system.bodies[0], hydrostatic=tuple(np.eye(6).ravel()))
    assert refused(dataclasses.replace(system, bodies=(body,))) == (
        "body float: give its hydrostatic matrix or its waterplane area and moments, not "
        "both (the matrix stands in for them)")


def test_a_line_s_own_checks_name_the_line():
    bad = dataclasses.replace(CHAIN, gj=0.0)
    lines = tuple(dataclasses.replace(line, line=Line([(bad, 600.0)], element_length=10.0))
                  for line in spread().lines)
    assert refused(dataclasses.replace(spread(), lines=lines)) == (
        "line L1: the LineTypes: line type chain: gj 0 must be positive")
    assert refused(spread(environment=Environment(seabed_stiffness=1e5))) == (
        "Environment.seabed_stiffness needs Environment.seabed (the seabed's height) or "
        "Environment.seabed_profile")


def test_a_current_too_strong_for_a_line_is_refused_before_it_is_built():
    """The lines' derived forces in the system's current (derived.check_applied_forces)
    checked by System.check, naming the line and the field the names give: a chain of
    Cd 1.2, D 0.1 m in 1025 kg/m^3 (c = 61.5 kg/m^2) under 1e15 m/s drags 6.15e31 N/m,
    above the bound 1e30 (it was refused only where the line was built, naming no
    line; the command line names its option: test_system_current_cli.py); 1e13 m/s
    (6.15e27 N/m) over 600 m, 3.69e30 N, is the applied force's refusal."""
    from petsc_rod.model.names import FIELD_NAMES, Names
    dragged = dataclasses.replace(CHAIN, cd=1.2)
    lines = tuple(dataclasses.replace(line, line=Line([(dragged, 600.0)],
                                                      element_length=10.0))
                  for line in spread().lines)
    system = spread(lines=lines, environment=Environment(seabed=-200.0,
                                                         current=(1e15, 0.0, 0.0)))
    assert refused(system) == (
        "line L1: Environment.current with the line types' cd and drag_d (the LineTypes): "
        "the largest drag c max |v|^2 = 6.15e+31 N/m is above 1e+30; give the current in "
        "m/s")
    option = Names({"current": "-rod_current"}, FIELD_NAMES.__getitem__)
    with pytest.raises(RodInputError,
                       match=r"^line L1: -rod_current with .* 6.15e\+31 N/m"):
        system.check(option)
    slower = dataclasses.replace(system, environment=Environment(seabed=-200.0,
                                                                 current=(1e13, 0.0, 0.0)))
    assert refused(slower).startswith(
        "line L1: Environment.current with the line types' cd and drag_d (the LineTypes) "
        "and Line.sections: the applied force (int |f| dS + the end forces + the drag) is "
        "3.69e+30 N, above 1e+30")
    dataclasses.replace(system, environment=Environment(seabed=-200.0,
                                                        current=(1.0, 0.0, 0.0))).check()


def test_a_current_too_strong_for_a_free_point_is_refused():
    """The buoy of tests/data/moordyn/buoy_level.dat given a drag area of 5000 m^2 in a
    1e12 m/s current: 0.5 rho CdA |v|^2 = 2.56e30 N, above the bound 1e30, while its
    tendons' drag (c = 430.5 kg/m^2: 4.3e26 N/m, 2.2e28 N over 49.99 m) is not; it ran
    into a Newton without an equilibrium. A fixed point's CdA pushes nothing."""
    from petsc_rod.model.moordyn import read_moordyn
    buoy, _ = read_moordyn("tests/data/moordyn/buoy_level.dat")
    points = tuple(dataclasses.replace(p, cda=5000.0) for p in buoy.points)
    system = dataclasses.replace(buoy, points=points, environment=dataclasses.replace(
        buoy.environment, current=(0.0, 1e12, 0.0)))
    assert refused(system) == (
        "point Point2: Environment.current with its drag area CdA 5000 m^2: the largest "
        "drag 0.5 rho CdA max |v|^2 = 2.56e+30 N is above 1e+30; give the current in m/s")
    dataclasses.replace(system, points=tuple(
        p if p.kind != "free" else dataclasses.replace(p, cda=1000.0)
        for p in points)).check()


def test_a_held_point_below_the_flat_seabed_is_refused():
    message = refused(spread(environment=Environment(seabed=-199.0)))
    assert message == ("point A1 (fixed) is held at z = -200 m, 1 m below the seabed "
                       "(Environment.seabed -199); hold it on or above it")


def test_the_rotation_takes_body_axes_to_global_ones():
    assert rotation(0.0, 0.0, np.pi / 2) @ [1.0, 0.0, 0.0] == pytest.approx([0, 1, 0])
    assert rotation(0.0, np.pi / 2, 0.0) @ [1.0, 0.0, 0.0] == pytest.approx([0, 0, -1])
    assert rotation(np.pi / 2, 0.0, 0.0) @ [0.0, 1.0, 0.0] == pytest.approx([0, 0, 1])


def test_a_group_of_points_and_bodies_with_nothing_holding_it_is_refused():
    buoy = System(lines=(SystemLine("riser", Line([(CHAIN, 50.0)], element_length=5.0),
                                    Connection("buoy"), Connection("clump")),),
                  points=(Point("buoy", "free", (0.0, 0.0, -10.0), volume=2.0),
                          Point("clump", "free", (0.0, 0.0, -60.0), mass=1e3)))
    assert refused(buoy) == (
        "nothing holds buoy, clump in x, y, z: no fixed or prescribed point, and no body "
        "held or with hydrostatic stiffness there, among the points and bodies its lines "
        "join (a rigid motion is free); anchor a line, or hold a body")
    system = spread()
    floater = dataclasses.replace(system.bodies[0], name="float2")
    bridle = (SystemLine("bridle", Line([(CHAIN, 50.0)], element_length=5.0),
                         Connection("float2", (0.0, 0.0, -1.0)),
                         Connection("float2", (0.0, 1.0, -1.0))),)
    assert refused(dataclasses.replace(system, bodies=system.bodies + (floater,),
                                       lines=system.lines + bridle)).startswith(
        "body float2: nothing restores its x, y, yaw: no line to another point or body")
    clump = (SystemLine("pendant", Line([(CHAIN, 50.0)], element_length=5.0),
                        Connection("float2", (0.0, 0.0, -1.0)), Connection("clump")),)
    steered = dataclasses.replace(floater, held=(False,) * 5 + (True,))
    assert refused(dataclasses.replace(
        system, bodies=system.bodies + (steered,), lines=system.lines + clump,
        points=system.points + (Point("clump", "free", (0.0, 0.0, -51.0), mass=1e3),)
    )).startswith("nothing holds clump, float2 in x, y: no fixed or prescribed point")


@pytest.mark.parametrize("fields, words", [
    ({"inertia": (1.0, -2.0, 3.0)}, "inertia (1.0, -2.0, 3.0): a mass matrix is symmetric"),
    ({"inertia": (1, 2, 0, 0, 1, 0, 0, 0, 1)}, "a mass matrix is symmetric"),
    ({"inertia": (1.0, 2.0)}, "expected 3 or 9 numbers"),
    ({"added_mass": (1.0,) * 35}, "expected 36 numbers"),
    ({"added_mass": tuple(-np.eye(6).ravel())}, "no negative eigenvalue"),
])
def test_a_body_s_inertia_and_added_mass_are_mass_matrices(fields, words):
    with pytest.raises(RodInputError, match=r"Body hull: ") as refused:
        Body("hull", **fields)
    assert words in str(refused.value)


def test_a_point_s_added_mass_coefficient_is_not_negative():
    with pytest.raises(RodInputError, match="Point p: ca -0.5: must not be negative"):
        Point("p", "free", ca=-0.5)


def test_the_system_modes_options_of_the_api():
    from petsc_rod.api.system_run import split_options
    assert split_options({"system_modes": True})[3] == {"line_mass": False}
    assert split_options({"system_modes": 1, "system_modes_line_mass": 1})[3] == {
        "line_mass": True}
    assert split_options({})[3] is None
    with pytest.raises(RodInputError, match="system_modes_line_mass needs system_modes"):
        split_options({"system_modes_line_mass": True})
    with pytest.raises(RodInputError, match="system_modes 'yes': True or False"):
        split_options({"system_modes": "yes"})
    with pytest.raises(RodInputError, match="modes and modes_range: give one"):
        split_options({"modes": 3, "modes_range": "1,2"})


def test_the_system_modes_options_are_named_as_the_caller_gave_them():
    """The API's wording for the API; the command line's names its options."""
    from petsc_rod.api.system_run import body_modes_request
    with pytest.raises(RodInputError, match="^system_modes_line_mass needs system_modes "):
        body_modes_request({"system_modes_line_mass": True})
    with pytest.raises(RodInputError, match="^-rod_system_modes_line_mass needs "
                                            "-rod_system_modes 1 "):
        body_modes_request({"system_modes_line_mass": True}, cli=True)


def test_a_held_point_below_a_sloping_seabed_is_refused():
    """System.check: a fixed point under the plane (its height at the point from the
    slope, direction and origin) is refused naming the point, the height there and the
    Environment's fields; on the plane or above it passes."""
    system = held_pair(CHAIN, 100.0, 100.0)
    sea = dataclasses.replace(system.environment, seabed=-50.0, seabed_slope=1.0,
                              seabed_origin=(0.0, 0.0))    # through a, rising toward b
    below = dataclasses.replace(system, environment=sea)
    with pytest.raises(RodInputError) as error:
        below.check()
    message = str(error.value)
    assert "\n" not in message and message.startswith("point ")
    assert "below the sloping seabed there" in message
    assert message == (
        "point b (prescribed) is held at z = -50 m, 1.75 m below the sloping seabed there "
        "(z = -48.2545 m: the plane of Environment.seabed_slope, "
        "Environment.seabed_direction, Environment.seabed_origin); hold it on or above "
        "it, or move the plane's origin or change its slope")
    level = dataclasses.replace(sea, seabed_slope=-1.0)    # falling toward b: passes
    dataclasses.replace(system, environment=level).check()


def test_a_node_held_between_opposing_taut_lines_passes_whatever_its_own_force():
    """check_reach's pulled: a buoy on a level pretensioned line (its buoyancy across
    both taut lines), a weightless connector between two taut lines, three taut lines at
    120 degrees in a plane: held between them (balanced), passed; a weightless point at
    the end of one straight line, or a hull heavier than its buoyancy above its tendons,
    is still refused (the test above)."""
    def between(directions, mass=0.0, volume=0.0):
        ends = [Point(f"a{k}", "fixed", tuple(50.0 * np.asarray(d))) for k, d in
                enumerate(directions)]
        return System(points=(*ends, Point("b", "free", (0.0, 0.0, 0.0), mass=mass,
                                            volume=volume)),
                      lines=tuple(SystemLine(f"t{k}", Line([(CHAIN, 49.99)],
                                                            element_length=5.0),
                                             Connection(f"a{k}"), Connection("b"))
                                  for k in range(len(directions))))
    level = [(1.0, 0.0, 0.0), (-1.0, 0.0, 0.0)]
    check_reach(between(level, mass=1000.0, volume=10.0))       # buoyant, across both
    check_reach(between([(0.0, 0.0, 1.0), (0.0, 0.0, -1.0)]))  # weightless, vertical
    third = [(np.cos(a), np.sin(a), 0.0) for a in np.radians([90.0, 210.0, 330.0])]
    check_reach(between(third, mass=500.0))
    assert balanced(np.array(third)) and not balanced(np.array(third[:2]))
    assert refused_reach(between(level[:1])).startswith("line t0: taut between a0 and b")
