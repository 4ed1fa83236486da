"""The terms of physics a scene needs (physics/term.py), and nothing it does not: the
dead loads always; the point loads (attachments) where it has some; a flex joint at each
pinned end given a rotational stiffness (physics/flex_joint.py); the seabed (with the
horizontal push of a sloping one, physics/slope_load.py, and its friction,
physics/friction.py) and the drag only where the scene has a seabed or a current
(docs/riser.md); the axial stretch only where some EA is finite (docs/method.md §12).

Its reports (quantities/report.py), held beside the terms: the riser numbers
(quantities/riser_numbers.py) where it has a seabed or a current; the sections' numbers,
pressures and, with an inner diameter, the pipe's stresses on a line of line types; the
results along the line (quantities/line_results.py) always; its regions
(quantities/regions.py) on a riser-like scene (a seabed, a current or line types).

And where a run's seabed friction is anchored: lay_friction_anchors, the command line's,
the API's and iteration/driver.solver_for's (scripts' and tests')."""

from petsc_rod.errors import RodInputError
from petsc_rod.physics.dead_loads import DeadLoads
from petsc_rod.physics.drag import DragTerm
from petsc_rod.physics.flex_joint import FlexJoint
from petsc_rod.physics.friction import FrictionTerm
from petsc_rod.physics.point_loads import PointLoads
from petsc_rod.physics.seabed import SeabedTerm
from petsc_rod.physics.slope_load import SeabedSlopeLoad
from petsc_rod.physics.stretch import AxialStretch
from petsc_rod.physics.surface import SurfaceTerm, reaches_surface
from petsc_rod.quantities.line_results import LineResults
from petsc_rod.quantities.module_bends import ModuleBends, module_S
from petsc_rod.quantities.pressures import PipePressures
from petsc_rod.quantities.regions import LineRegions
from petsc_rod.quantities.riser_numbers import RiserNumbers
from petsc_rod.quantities.section_numbers import SectionNumbers
from petsc_rod.quantities.stresses import PipeStresses
from petsc_rod.scenes import starts
from petsc_rod.scenes.boundary import is_held


def scene_terms(mesh, scene):
    """The list of terms of ``scene`` on ``mesh``, in the order the core calls them."""
    terms = [DeadLoads(mesh, scene)]
    if scene.point_loads(1.0)[0].size:          # attachments (scenes/point_loads.py)
        terms.append(PointLoads(mesh, scene))
    terms += [FlexJoint(mesh, which, k, axis) for which, k, axis in scene.joints()]
    seabed = SeabedTerm(mesh, scene.seabed) if scene.seabed is not None else None
    if seabed is not None:
        terms.append(seabed)
        if not scene.seabed.flat:               # a slope or a profile: its horizontal push
            terms.append(SeabedSlopeLoad(mesh, seabed))
        if scene.seabed.friction is not None:   # after the seabed: it reads its reaction
            terms.append(FrictionTerm(mesh, seabed))
    held = [state.position[2] for state in (scene.start_state(1.0), scene.end_state(1.0))
            if is_held(state)]
    # its weight in air above the sea surface, and no drag there
    surface = SurfaceTerm(mesh, scene) if reaches_surface(scene, held) else None
    if scene.drag_loads(1.0):                  # a current anywhere on the load path
        terms.append(DragTerm(mesh, scene, surface))
    if surface is not None:
        terms.append(surface)
    if scene.extensible:
        terms.append(AxialStretch(mesh, scene))
    return terms


def scene_reports(scene, terms):
    """The list of reports of ``scene`` (module docstring), in the order their outputs
    are merged; the riser numbers and the regions read the SeabedTerm among ``terms``."""
    seabed = next((term for term in terms if isinstance(term, SeabedTerm)), None)
    drag = bool(scene.drag_loads(1.0))
    reports = []
    if seabed is not None or drag:
        reports.append(RiserNumbers(seabed))
    if scene.sections:
        reports.append(SectionNumbers(scene.sections))
        reports.append(PipePressures(scene))
        if any(section.id > 0 for section in scene.sections):
            reports.append(PipeStresses(scene))
    reports.append(LineResults())
    if module_S(scene).size > 1:                 # buoyancy modules: their global bends
        reports.append(ModuleBends(module_S(scene)))
    if seabed is not None or drag or scene.sections:
        reports.append(LineRegions(seabed))
    return reports


def friction_terms(problem):
    """The seabed friction's terms (FrictionTerm) of ``problem``: a list, empty without."""
    return [term for term in problem.terms if isinstance(term, FrictionTerm)]


def lay_friction_anchors(problem, say, scene=None):
    """The seabed friction's anchors (physics/friction.py), the line as laid: the
    catenary between the ends the user gave (starts.catenary_start at t = 1 of ``scene``,
    default the problem's; a restart's walk passes its own scene, the walk's end, so
    that its anchors are those of the run from its own start: cli/line_run.start_from,
    -rod_initial_friction_anchors laid), resting on
    the seabed where it reaches it; ``FrictionTerm.laying``), for every load step and
    every halved attempt, whatever the start shape and the number of steps. The load
    path is a numerical continuation from the straight reference, no history of the
    line, so the answer is that relative to the line as laid between the user's ends
    whatever -rod_steps: a line given from its fairlead hangs clear of the seabed in its
    first steps, and anchors moved at their ends would be where its nodes hung, not where
    they land; the straight start is no line as laid either (docs/riser.md §3b, "The
    path"). The anchors of a step at t < 1 are those of t = 1 too, not the catenary
    between that step's ends: with each step's own catenary every attempt of a line
    across a current from the straight start failed, where it now converges in one step
    (with Newton's rule after a step with the iteration's curvature, iteration/newton.py;
    docs/riser.md §3b, "From the straight start"). Where no catenary can be drawn at
    t = 1 the anchors are the start's positions (the first global step's) and follow the
    return map, said in one line. Returns whether the anchors were laid so."""
    terms = friction_terms(problem)
    if not terms:
        return False
    try:
        laid = starts.catenary_start(problem.scene if scene is None else scene, 1.0)
    except RodInputError as reason:     # NoCatenaryStart included
        say(f"petsc_rod: seabed friction: no catenary between the ends ({reason}); its "
            "anchors are the start's positions")
        return False
    for term in terms:
        term.laying = laid
    return True
