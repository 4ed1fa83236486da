"""The lines a user reads: the continuation's events (iteration/events.py) and the
step records (io/outputs.py) as text, with the advice that names the options to change.
Nothing here computes or decides."""

from petsc_rod.errors import RodIterationDiverged
from petsc_rod.iteration.stopping import STOP_LINK, STOP_SADDLE, STOP_UNTESTED
from petsc_rod.problem.penalty import ADAPT_WINDOW

# What a divergence suggests changing (the iteration itself never names an option).
DIVERGED_ADVICE = "try a larger -rod_al_penalty or more -rod_steps"


def monitor(label, iteration, change, residual):
    """The -rod_al_monitor line of one iteration (UzawaSolver's monitor)."""
    return f"  {label}it {iteration:5d}  change {change:.3e}  constraint {residual:.3e}"


def started(event):
    origin = f" from load factor {event.start:.6g}" if event.start > 0 else ""
    return (f"petsc_rod: {event.elements} elements on {event.ranks} rank(s), "
            f"R = {event.penalty:g}, {event.steps} step(s){origin}")


def no_newton(terms):
    """The line that says a run takes no Newton steps, naming the ``terms`` (physics
    Term) that are not in them (their newton_gap)."""
    names = ", ".join(dict.fromkeys(term.newton_gap or type(term).__name__ for term in terms))
    return (f"petsc_rod: no Newton steps with {names}: the plain accelerated iteration, "
            "hundreds of iterations where Newton steps take tens")


def failure_text(failure):
    """An attempt's failure (a sentence or a RodDivergedError) with the advice that a
    diverged iteration carries."""
    if isinstance(failure, RodIterationDiverged):
        return f"{failure}; {DIVERGED_ADVICE}"
    return str(failure)


def halved(event):
    # a divergence names the step, which the line says first
    reason = failure_text(event.failure).removeprefix(f"{event.label} ")
    return (f"petsc_rod: {event.label} at load factor {event.t:.6g}: {reason}; halving "
            f"{event.halvings}: retrying from load factor {event.retry_from:.6g} with "
            f"increment {event.increment:.6g}")


def stability_text(report):
    """The step line's account of which equilibrium was reached (stability.py)."""
    if report.stable is None:
        return _left_without_verdict(report)
    if not report.stable:
        return ", a saddle (the second variation has a negative direction)"
    left = f" after leaving {report.escapes} saddle(s)" if report.escapes else ""
    return f", stable{left} (second variation positive)"


def _left_without_verdict(report):
    """Where there is no verdict (a term without energy, or a step that ended
    otherwise): the states with a negative direction of H the step left
    (driver.UzawaSolver.checks_curvature), or ''."""
    if not report.escapes:
        return ""
    return f", after leaving {report.escapes} state(s) with negative curvature"


def newton_text(report):
    """The step line's count of Newton steps among the iterations (newton.py)."""
    return f" ({report.newton_steps} Newton)" if report.newton_steps else ""


def link_text(link):
    """The step line's account of the link, '' where it is not tracked."""
    if link is None:
        return ""
    tw, wr = link
    return f", link {tw + wr:.4f} turns = twist {tw:.4f} + writhe {wr:.4f}"


def short_stability(report):
    """The step line's word on which equilibrium was reached: 'stable', 'stable after
    leaving n saddle(s)', 'a saddle', or '' where it was not tested (stability.py)."""
    if report.stable is None:
        return _left_without_verdict(report)
    if not report.stable:
        return ", a saddle"
    return ", stable" + (f" after leaving {report.escapes} saddle(s)" if report.escapes else "")


def riser_text(attributes):
    """The engineer's numbers of a riser step (quantities/riser_numbers.py, in ``attributes``):
    top tension (kN) and its angle from the vertical, the touchdown's S (and the
    vertices beyond a seabed profile's rows, where there are any) and the smallest bend
    radius; '' for a scene without them."""
    if "top_tension" not in attributes:
        return ""
    text = (f"; top tension {attributes['top_tension'] / 1e3:.6g} kN at "
            f"{attributes['top_angle']:.2f} deg")
    if "touchdown_S" in attributes:
        S = attributes["touchdown_S"]
        text += (f", touchdown S = {S:.6g} m" if S == S else ", no touchdown"
                 + uplift_text(attributes, 1e3))
    beyond = attributes.get("seabed_vertices_beyond", 0)
    if beyond:                          # quantities/riser_numbers.py: a profile taken level there
        text += f", {beyond} vertices beyond the seabed profile's rows (level there)"
    return (text + f", smallest bend radius {attributes['min_bend_radius']:.4g} m"
            + friction_text(attributes))


def uplift_text(attributes, unit):
    """': the anchor at S = .. lifts off at .. deg, pulled up by .. N' (kN for ``unit``
    1e3) of an anchor that lifts off (quantities/riser_numbers.anchor_uplift); '' otherwise."""
    if "anchor_uplift_S" not in attributes:
        return ""
    a = attributes
    return (f": the anchor at S = {a['anchor_uplift_S']:.6g} m lifts off at "
            f"{a['anchor_uplift_angle']:.4g} deg above the horizontal, pulled up by "
            f"{a['anchor_uplift_force'] / unit:.6g} {'kN' if unit == 1e3 else 'N'}")


def friction_text(attributes):
    """The seabed friction's numbers (physics/friction.py) for the step line: the grounded
    lengths that stick and slide, the largest friction per metre and the touchdown's
    offset from the ends' plane; '' without friction."""
    a = attributes
    if "friction_stick_length" not in a:
        return ""
    offset = a.get("touchdown_offset", float("nan"))
    return (f"; friction: {a['friction_stick_length']:.4g} m stick, "
            f"{a['friction_slide_length']:.4g} m slide, largest "
            f"{a['friction_max_force']:.4g} N/m"
            + (f", touchdown {offset:.4g} m off the ends' plane" if offset == offset else ""))


def friction_path_text(attributes):
    """The line that says a frictional equilibrium is one of many (physics/friction.py
    FrictionTerm.path_numbers): how many grounded nodes stick and slide, the largest
    mobilisation of a sticking node and the band mu R / k_s within which another load
    path from the as-laid line could leave a sticking node; '' where no node sticks (a
    sliding node's force is the limit, whatever the path)."""
    a = attributes
    if a.get("friction_stick_nodes", 0) <= 0:
        return ""
    return (f"seabed friction depends on the path from the as-laid line (the start): "
            f"{a['friction_stick_nodes']} grounded nodes stick and "
            f"{a['friction_slide_nodes']} slide; a sticking node uses at most "
            f"{a['friction_stick_max_use']:.4g} of its limit mu R and could lie anywhere "
            f"within mu R / k_s = {a['friction_band'] * 1e3:.3g} mm of its anchor after "
            "another load path (this equilibrium is one of that set)")


def step_line(event, record):
    """The line of a StepEnded event with its io.outputs.StepRecord: load factor,
    iterations (Newton steps), converged, stable or a saddle, the linking number where
    it is tracked, and a riser's numbers at load factor 1 only (an intermediate step's
    touchdown may lie anywhere on the way; the file has every step's). The rest is
    step_details'."""
    report = event.report
    link = "" if report.link is None else f", link {sum(report.link):.4f} turns"
    return (f"{event.label}: load factor {event.t:.4g}, "
            f"{'converged' if report.converged else 'NOT converged'} in {report.iterations} "
            f"iterations{newton_text(report)}" + short_stability(report) + link
            + (riser_text(record.attributes) if event.t >= 1.0 else ""))


def step_details(event, record):
    """The -rod_al_monitor line after a step line: the stopping quantities, energy,
    u3(0), the link's parts and every term's phrase (the riser numbers, sections,
    stretch, joints, pressures)."""
    report = event.report
    return (f"  {event.label} details: change {report.change:.2e}, constraint "
            f"residual (RMS) {report.constraint_residual:.2e}, energy {record.energy:.10g} J, "
            f"u3(0) {record.u3_start:.6g}" + link_text(report.link) + stability_text(report)
            + "".join(f"; {text}" for text in record.texts))


def _table(header, rows):
    """Rows of text cells as lines with right-aligned columns."""
    widths = [max(len(row[k]) for row in [header, *rows]) for k in range(len(header))]
    return ["  " + "  ".join(cell.rjust(w) if k else cell.ljust(w)
                             for k, (cell, w) in enumerate(zip(row, widths)))
            for row in [header, *rows]]


def end_force_lines(attributes):
    """The final lines' fairlead and anchor forces in kN (quantities/line_results.py: the
    force the line exerts on each support, horizontal H, vertical V, global components),
    and whether the anchor lifts off; [] for a file without them."""
    a = attributes
    if "fairlead_tension" not in a:
        return []
    kN = 1e3
    out = [f"  fairlead force {a['fairlead_tension'] / kN:.6g} kN: horizontal "
           f"{a['fairlead_horizontal'] / kN:.6g} kN, vertical {a['fairlead_vertical'] / kN:.6g}"
           f" kN (x, y, z components " + ", ".join(
               f"{a[f'fairlead_force_{c}'] / kN:.6g}" for c in "xyz") + " kN)"]
    if "anchor_tension" in a:
        lifts = {1: "; the anchor lifts off", 0: "; the anchor does not lift"}.get(
            a.get("anchor_uplift"), "")
        out.append(f"  anchor force {a['anchor_tension'] / kN:.6g} kN: horizontal "
                   f"{a['anchor_horizontal'] / kN:.6g} kN, vertical (up) "
                   f"{a['anchor_vertical'] / kN:.6g} kN" + lifts)
    return out


def summary(attributes):
    """The lines of the run's final summary from the last step's attributes (at load
    factor 1): the riser's numbers, the flex joints' angles, per section its largest
    tension and smallest bend radius and where, and the same per region of the line
    (quantities/regions.py) with its largest bending moment; [] for a scene with none of
    them (a rod of the paper's kind: its energy and strains are in the file)."""
    a = attributes
    out = []
    if "top_tension" in a:
        text = (f"  top tension {a['top_tension'] / 1e3:.6g} kN at {a['top_angle']:.3f} deg "
                "from the vertical")
        if "touchdown_S" in a:
            S = a["touchdown_S"]
            at = (f" (x, y = {a['touchdown_x']:.6g}, {a['touchdown_y']:.6g} m)"
                  if "touchdown_x" in a else "")
            text += (f"; touchdown at S = {S:.6g} m{at}, grounded {a['grounded_length']:.6g} m"
                     if S == S else "; no touchdown" + uplift_text(a, 1e3))
        text += (f"; smallest bend radius {a['min_bend_radius']:.4g} m at S = "
                 f"{a['max_curvature_S']:.6g} m")
        out.append(text)
        out += end_force_lines(a)
    if "friction_stick_length" in a:
        out.append("  seabed" + friction_text(a)[1:])
        if friction_path_text(a):
            out.append("  " + friction_path_text(a))
    if "module_pitch" in a:
        out.append(f"  buoyancy modules, over the module pitch {a['module_pitch']:.4g} m: "
                   + "; ".join(f"global {kind} bend radius "
                               f"{a[f'global_{kind}_bend_radius']:.4g} m at S = "
                               f"{a[f'global_{kind}_bend_radius_S']:.6g} m (local kink "
                               f"{a[f'local_{kind}_bend_radius']:.4g} m)"
                               for kind in ("hog", "sag")))
    joints = [f"{which} joint {a[f'{which}_joint_angle']:.4g} deg, "
              f"{a[f'{which}_joint_moment'] / 1e3:.4g} kN m"
              for which in ("start", "end") if f"{which}_joint_angle" in a]
    if joints:
        out.append("  " + "; ".join(joints))
    if "max_wall_tension" in a:
        out.append(f"  largest wall tension {a['max_wall_tension'] / 1e3:.6g} kN at S = "
                   f"{a['max_wall_tension_S']:.6g} m")
    if "max_von_mises" in a and a["max_von_mises"] == a["max_von_mises"]:
        text = (f"  largest von Mises stress {a['max_von_mises'] / 1e6:.5g} MPa at S = "
                f"{a['max_von_mises_S']:.6g} m")
        if a.get("max_utilisation", float("nan")) == a.get("max_utilisation"):
            text += (f"; utilisation up to {a['max_utilisation']:.4g} at S = "
                     f"{a['max_utilisation_S']:.6g} m (design factor "
                     f"{a['design_factor']:.4g})")
        out.append(text)
    if "section_names" in a:
        header = ["section", "S from (m)", "S to (m)", "max tension (kN)", "at S (m)",
                  "min bend radius (m)", "at S (m)"]
        rows = [[name, f"{bounds[0]:.6g}", f"{bounds[1]:.6g}", f"{tension / 1e3:.6g}",
                 f"{tension_S:.6g}", f"{radius:.4g}", f"{curved_S:.6g}"]
                for name, bounds, tension, tension_S, radius, curved_S in zip(
                    a["section_names"], a["section_bounds"], a["section_max_tension"],
                    a["section_max_tension_S"], a["section_min_bend_radius"],
                    a["section_max_curvature_S"])]
        out += _table(header, rows)
    if "region_names" in a:
        header = ["region", "S from (m)", "S to (m)", "max tension (kN)", "at S (m)",
                  "min bend radius (m)", "at S (m)", "max moment (kN m)", "at S (m)"]
        rows = [[name, f"{bounds[0]:.6g}", f"{bounds[1]:.6g}", f"{tension / 1e3:.6g}",
                 f"{tension_S:.6g}", f"{radius:.4g}", f"{radius_S:.6g}",
                 f"{moment / 1e3:.4g}", f"{moment_S:.6g}"]
                for name, bounds, tension, tension_S, radius, radius_S, moment, moment_S
                in zip(a["region_names"], a["region_bounds"], a["region_max_tension"],
                       a["region_max_tension_S"], a["region_min_bend_radius"],
                       a["region_min_bend_radius_S"], a["region_max_bending_moment"],
                       a["region_max_bending_moment_S"])]
        out += _table(header, rows)
    return ["petsc_rod: at load factor 1:"] + out if out else []


def raised(label, raises, ceiling, by_friction=False):
    """The line that says the penalty was raised in a step: its events.PenaltyRaised
    ``raises``; ``ceiling`` the largest R the raises reach (N; RodProblem.adapt_ceiling),
    ``by_friction`` whether it is a tenth of the least EA (seabed friction on an
    extensible line) rather than the problem's scale."""
    listed = ", ".join(f"{event.penalty:.3g} at iteration {event.iteration}" for event in raises)
    what = ("a tenth of the least EA, for seabed friction on an extensible line"
            if by_friction else "the problem's scale")
    return (f"petsc_rod: {label}: R raised to {listed} (matrices refactored): the "
            f"constraint residual fell by less than half in {ADAPT_WINDOW} iterations with "
            f"R below a tenth of its ceiling {ceiling:.3g} ({what}; "
            "-rod_al_adapt_penalty), "
            "or a Newton solution needed a larger R to stay a fixed point (-rod_al_newton)")


def given_up(halvings, load_factor, nothing_to_halve=False):
    """What a run's failure message adds once halvings were tried ('' before), or why
    none was: a step that moves no load (a restart at its own load factor) cannot be
    made easier by halving it (continuation.LoadPath.nothing_to_halve)."""
    if nothing_to_halve:
        return (f"; the step to load factor {load_factor:.6g} starts there and moves no "
                "load, so halving it cannot help: the run ends (restart with "
                "-rod_initial_load_factor below it, more -rod_al_max_it, or looser "
                "-rod_al_rtol/-rod_al_ctol)")
    if not halvings:
        return ""
    return (f"; load factor {load_factor:.6g} after {halvings} halving(s) of the step "
            "(-rod_max_halvings)")


def diverged_message(event):
    """The one-line error of a RunDiverged event."""
    return (f"{failure_text(event.error)}"
            f"{given_up(event.halvings, event.load_factor, event.nothing_to_halve)}")


def not_converged_reason(report, settings, scale, friction_penalty=None):
    """Why a step stopped without converging, and what to change (``settings``: the
    run's stopping.Settings, ``scale`` the problem's scale of R, N; ``friction_penalty``
    the R advised for seabed friction on an extensible line, penalty.friction_penalty,
    or None)."""
    numbers = (f"change {report.change:.2e} for -rod_al_rtol {settings.rtol:.2g}, "
               f"constraint residual {report.constraint_residual:.2e} for -rod_al_ctol "
               f"{settings.ctol:.2g}")
    if report.reason == STOP_LINK:
        tw, wr = report.link
        return (f"converged to a state whose linking number is {tw + wr:.3f} turns (twist "
                f"{tw:.3f} + writhe {wr:.3f}), not the {report.link_expected:.3f} turns the "
                "load path leads to: the clamps fix the end roll only modulo a turn, and the "
                "iteration passed the rod around one of its ends or through itself, which "
                "walls at the clamps forbid (docs/stability.md); take more -rod_steps")
    if report.reason == STOP_SADDLE:
        return (f"converged {report.escapes + 1} times to a saddle, an equilibrium that is not "
                "a minimiser, after turning the frames along its direction of negative "
                "curvature each time: take more -rod_steps, or -rod_imperfection")
    if report.reason == STOP_UNTESTED:
        return ("converged, but the stability test could not decide: its factorisation of "
                "the second variation failed (singular to round-off at a shift); take more "
                "-rod_steps")
    if report.stalled:
        return (f"stalled after {report.iterations} iterations ({numbers}): at their rate they "
                "would not meet the tolerances within -rod_al_max_it: tolerances near round-off "
                "for this mesh and these forces (loosen them), or a slowly contracting "
                "iteration (take more -rod_steps or a larger -rod_al_max_it)")
    hint = ""
    if settings.asked_penalty < 0.1 * scale:
        hint = (f"; -rod_al_penalty {settings.asked_penalty:g} is far below the problem's scale "
                f"{scale:.3g} (the default): raise it")
    elif friction_penalty is not None and settings.asked_penalty < 0.1 * friction_penalty:
        hint = (f"; seabed friction on an extensible line converges slowly at R = "
                f"{settings.asked_penalty:.3g}: try -rod_al_penalty {friction_penalty:.3g} "
                "(about EA / 10, docs/riser.md §3b)")
    return f"did not converge in {report.iterations} iterations ({numbers}){hint}"


def finished(event, settings, scale, friction_penalty=None):
    """The last line of a run (RunFinished); ``friction_penalty`` as
    not_converged_reason's."""
    if not event.converged:
        return (f"petsc_rod: error: {event.label} "
                f"{not_converged_reason(event.report, settings, scale, friction_penalty)}"
                f"{given_up(event.halvings, event.load_factor, event.nothing_to_halve)}"
                "; the result file says "
                "converged = 0")
    return (f"petsc_rod: converged, {event.iterations} iterations in {event.wall_time:.3g} s, "
            f"{event.halvings} halving(s) of the step ({event.undone} iterations undone)")


def interrupted(name, event, kept=None):
    """The one-line error of a run stopped by the signal called ``name``, whose
    converged steps were kept in the file ``kept`` (None: there were none, or no file)."""
    where = (f"the converged steps are kept in {kept} (converged = 0; -rod_initial {kept} "
             "goes on from there)" if kept else "no result file is written")
    return (f"interrupted by {name} {event.where}; the last converged load factor is "
            f"{event.last_factor:.6g}; {where}")
