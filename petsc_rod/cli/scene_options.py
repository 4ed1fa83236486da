"""The scene, the sea and the iteration's settings from the parsed -rod_* options
(options.py): the one place where option values become the objects the numerical code
takes (Scene, Seabed, Current, Settings), with the checks that need several options."""

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.iteration.stopping import Settings
from petsc_rod.problem.penalty import default_penalty
from petsc_rod.riser.environment import (Current, Seabed, check_ends_above, default_stiffness,
                                         read_profile)
from petsc_rod.scenes.boundary import is_held
from petsc_rod.scenes.scene import Scene


def scene_from_options(values, given):
    """A validated Scene from parsed option values."""
    load = np.asarray(values["rod_load"])
    if load.size % 3:
        raise RodInputError("-rod_load: give 3 values (fx,fy,fz) per load piece")
    scene = Scene(length=values["rod_length"], stiffness=values["rod_stiffness"],
                  start=values["rod_start"], end=values["rod_end"],
                  end_position=values["rod_end_position"], end_frame=values["rod_end_frame"],
                  end_twist=values["rod_end_twist"], start_force=values["rod_start_force"],
                  end_force=values["rod_end_force"], load_values=load.reshape(-1, 3),
                  load_breaks=values["rod_load_breaks"])
    scene.validate(given)
    scene.seabed, scene.current = environment_from_options(values, given, scene)
    return scene


def settings_from_options(values, scene):
    penalty = values["rod_al_penalty"]
    if penalty is None:
        penalty = default_penalty(scene)
    return Settings(asked_penalty=penalty, max_it=values["rod_al_max_it"],
                    rtol=values["rod_al_rtol"], ctol=values["rod_al_ctol"],
                    monitor=values["rod_al_monitor"],
                    adapt_penalty=values["rod_al_adapt_penalty"],
                    check_stability=values["rod_al_stability"],
                    newton=values["rod_al_newton"])


def seabed_from_options(values, given, load_values):
    """The Seabed of -rod_seabed and -rod_seabed_stiffness, or None."""
    if "rod_seabed" not in given:
        if "rod_seabed_stiffness" in given:
            raise RodInputError("-rod_seabed_stiffness needs -rod_seabed (the height of the "
                                "seabed plane)")
        return None
    stiffness = values["rod_seabed_stiffness"]
    if stiffness is None:
        stiffness = default_stiffness(load_values)
        if stiffness is None:
            raise RodInputError("-rod_seabed: no -rod_load points down to set the default "
                                "stiffness (weight / 1 mm); give -rod_seabed_stiffness")
    return Seabed(float(values["rod_seabed"]), float(stiffness))


def current_from_options(values, given, surface_default):
    """The Current of -rod_current or -rod_current_profile with -rod_drag, or None.
    ``surface_default``: the sea surface height when -rod_sea_surface is not given."""
    uniform, profile = "rod_current" in given, "rod_current_profile" in given
    if uniform and profile:
        raise RodInputError("-rod_current and -rod_current_profile both give the current; "
                            "give one of them")
    if not (uniform or profile):
        for name in ("rod_drag", "rod_sea_surface"):
            if name in given:
                raise RodInputError(f"-{name} needs a current (-rod_current or "
                                    "-rod_current_profile)")
        return None
    if "rod_drag" not in given:
        raise RodInputError("a current needs -rod_drag rho,Cd,D (water density kg/m^3, drag "
                            "coefficient, hydrodynamic diameter m)")
    if "rod_sea_surface" in given and not profile:
        raise RodInputError("-rod_sea_surface needs -rod_current_profile (a uniform "
                            "current does not depend on depth)")
    if profile:
        depths, velocities = read_profile(values["rod_current_profile"])
    else:
        depths, velocities = np.zeros(1), np.asarray(values["rod_current"]).reshape(1, 3)
    surface = values["rod_sea_surface"]
    rho, cd, diameter = values["rod_drag"]
    return Current(depths, velocities, float(surface_default if surface is None else surface),
                   0.5 * rho * cd * diameter)


def environment_from_options(values, given, scene):
    """(Seabed or None, Current or None) for a validated ``scene``, checked against it."""
    seabed = seabed_from_options(values, given, scene.load_values)
    ends = [("-rod_start", scene.start_state(t)) for t in (0.0, 1.0)]
    ends += [("-rod_end", scene.end_state(t)) for t in (0.0, 1.0)]
    check_ends_above(seabed, ends, scene.length)
    held = [state.position[2] for _, state in ends if is_held(state)]
    return seabed, current_from_options(values, given, max(held))
