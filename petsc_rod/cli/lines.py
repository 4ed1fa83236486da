"""The lines a user reads: the continuation's events (iteration/events.py) and the
step records (io/outputs.py) as text, with the advice that names the options to change.
Nothing here computes or decides."""

from petsc_rod.errors import RodIterationDiverged
from petsc_rod.iteration.stopping import STOP_LINK, STOP_SADDLE
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
        return ""
    if not report.stable:
        return ", a saddle (the second variation has a negative direction)"
    left = f" after leaving {report.escapes} saddle(s)" if report.escapes else ""
    return f", stable{left} (second variation positive)"


def newton_text(report):
    """The step line's count of Newton steps among the iterations (newton.py)."""
    return f" ({report.newton_steps} Newton)" if report.newton_steps else ""


def link_text(link):
    """The step line's account of the link, '' where it is not tracked."""
    if link is None:
        return ""
    tw, wr = link
    return f", link {tw + wr:.4f} turns = twist {tw:.4f} + writhe {wr:.4f}"


def step_line(event, record):
    """The line of a StepEnded event with its io.outputs.StepRecord."""
    report = event.report
    return (f"{event.label}: load factor {event.t:.4g}, "
            f"{'converged' if report.converged else 'NOT converged'} in {report.iterations} "
            f"iterations{newton_text(report)}, change {report.change:.2e}, constraint "
            f"residual (RMS) {report.constraint_residual:.2e}, energy {record.energy:.10g} J, "
            f"u3(0) {record.u3_start:.6g}" + link_text(report.link) + stability_text(report)
            + "".join(f"; {text}" for text in record.texts))


def raised(label, raises, scale):
    """The line that says the penalty was raised in a step: its events.PenaltyRaised
    ``raises``; ``scale`` the problem's scale of R (N)."""
    listed = ", ".join(f"{event.penalty:.3g} at iteration {event.iteration}" for event in raises)
    return (f"petsc_rod: {label}: R raised to {listed} (matrices refactored): the "
            f"constraint residual fell by less than half in {ADAPT_WINDOW} iterations with "
            f"R far below the problem's scale {scale:.3g} (-rod_al_adapt_penalty), "
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


def not_converged_reason(report, settings, scale):
    """Why a step stopped without converging, and what to change (``settings``: the
    run's stopping.Settings, ``scale`` the problem's scale of R, N)."""
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
    if report.stalled:
        return (f"stalled after {report.iterations} iterations ({numbers}): at their rate they "
                "would not meet the tolerances within -rod_al_max_it: tolerances near round-off "
                "for this mesh and these forces (loosen them), or a slowly contracting "
                "iteration (take more -rod_steps or a larger -rod_al_max_it)")
    hint = ""
    if settings.asked_penalty < 0.1 * scale:
        hint = (f"; -rod_al_penalty {settings.asked_penalty:g} is far below the problem's scale "
                f"{scale:.3g} (the default): raise it")
    return f"did not converge in {report.iterations} iterations ({numbers}){hint}"


def finished(event, settings, scale):
    """The last line of a run (RunFinished)."""
    if not event.converged:
        return (f"petsc_rod: error: {event.label} "
                f"{not_converged_reason(event.report, settings, scale)}"
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
