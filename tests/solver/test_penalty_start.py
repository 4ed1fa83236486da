"""The default penalty of a run from the catenary start (cli/scene_options.py,
problem/penalty.py): at least the largest tension that start holds, at the first step's
load factor 1 / -rod_steps; the straight start and a restart keep the other scales
(docs/method.md §3, "Default penalty")."""

import pytest

# The steel catenary riser of options/riser_catenary.opts, without its current: the
# start's tension (about 1.5e6 N at the top) is above F / 2 = 1.08e6 N.
RISER = dict(rod_length="1800", rod_stiffness="5.6e7,5.6e7,4.3e7", rod_start="pin",
             rod_end="pin", rod_end_position="1157,0,1000", rod_load="0,0,-1200",
             rod_seabed="0")


def asked_penalty(options, **given):
    """(R the run would ask for, the scene, the values) of the riser with ``given``."""
    from petsc_rod.cli.scene_options import scene_from_options, settings_from_options
    values, names = options(**{**RISER, **given})()
    scene = scene_from_options(values, names)
    return settings_from_options(values, scene).asked_penalty, scene, values


@pytest.mark.parametrize("steps", [1, 4])
def test_a_catenary_start_raises_the_default_penalty_to_its_tension(options, steps):
    from petsc_rod.problem.penalty import default_penalty
    from petsc_rod.scenes.starts import largest_tension
    penalty, scene, _ = asked_penalty(options, rod_initial_shape="catenary",
                                      rod_steps=str(steps))
    tension = largest_tension(scene, 1.0 / steps)
    assert penalty == max(tension, default_penalty(scene))
    if steps == 1:      # the full weight's catenary: above F / 2
        assert penalty == tension > 1.3 * default_penalty(scene)


def test_the_straight_start_and_a_restart_keep_the_other_scales(options, shared_tmp):
    from petsc_rod.problem.penalty import default_penalty
    straight, scene, _ = asked_penalty(options)
    assert straight == default_penalty(scene)
    restart, scene, _ = asked_penalty(options, rod_initial_shape="catenary",
                                      rod_initial=f"{shared_tmp}/unread.h5")
    assert restart == default_penalty(scene)
    given, _, _ = asked_penalty(options, rod_initial_shape="catenary", rod_al_penalty="123")
    assert given == 123.0


def test_a_scene_without_a_catenary_leaves_the_refusal_to_the_start(options):
    """A free start has no catenary: the settings take the other scales (no error
    before -help is said); cli/main.start_from refuses the start."""
    from petsc_rod.problem.penalty import default_penalty
    penalty, scene, _ = asked_penalty(options, rod_initial_shape="catenary", rod_start="free")
    assert penalty == default_penalty(scene)
