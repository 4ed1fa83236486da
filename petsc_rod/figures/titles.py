"""What a figure's title says: the file, converged or not, and the engineer's numbers
(top tension and angle, touchdown, smallest bend radius); never the energy."""

import numpy as np

from petsc_rod.figures import along


def status(result):
    """'converged', or 'NOT converged (reason)'."""
    if result.converged:
        return "converged"
    return f"NOT converged ({result.stop_reason})" if result.stop_reason else "NOT converged"


def top_numbers(result):
    """(top tension N, angle from the vertical deg): the file's, or n.t and the tangent
    at the higher end."""
    tension, angle = result.top_tension, result.top_angle
    if tension is None:
        tension = abs(float(result.tension[result.top]))
    if angle is None:
        d3 = result.r[result.top] - result.r[result.top - 1 if result.top else 1]
        angle = float(np.degrees(np.arccos(min(abs(d3[2]) / np.linalg.norm(d3), 1.0))))
    return tension, angle


def engineer_numbers(result):
    """'top tension … at …° from the vertical · touchdown … · …' for a riser."""
    tension, angle = top_numbers(result)
    words = [f"top tension {tension / 1e3:.4g} kN at {angle:.1f}° from the vertical"]
    for end, joint_angle, moment in result.joints:
        where = "hang-off" if (end == "end") == (result.top != 0) else "anchor"
        words.append(f"{where} flex joint {joint_angle:.2f}°, {moment / 1e3:.3g} kN m")
    if result.touchdown_S is not None:
        from_anchor = float(along.horizontal_distance(
            result.touchdown_position[None, :], result.r[result.anchor])[0])
        words.append(f"touchdown at S = {result.touchdown_S:.1f} m, "
                     f"{from_anchor:.1f} m from the anchor")
    elif result.seabed is not None:
        words.append("no touchdown")
    curvature = np.hypot(*result.curvature.T)
    k = int(np.argmax(curvature))
    if curvature[k] > 0:
        words.append(f"smallest bend radius {1 / curvature[k]:.3g} m at S = {result.S[k]:.0f} m")
    return wrapped(words)


def wrapped(words, width=120):
    """``words`` joined by ' · ', a new line before one that would pass ``width``."""
    lines = [words[0]]
    for word in words[1:]:
        if len(lines[-1]) + 3 + len(word) > width:
            lines.append(word)
        else:
            lines[-1] += " · " + word
    return "\n".join(lines)


def result_title(result):
    """The title of one result's figure."""
    head = f"{result.name}: {status(result)}"
    return f"{head}\n{engineer_numbers(result)}" if result.riser else head


def sweep_title(results, labels):
    """The title of a sweep's figure: the cases and those that did not converge."""
    failed = [label for result, label in zip(results, labels) if not result.converged]
    head = f"{len(results)} cases, {len(results) - len(failed)} converged"
    return head + (f"; NOT converged: {', '.join(failed)}" if failed else "")
