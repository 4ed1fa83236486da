"""What a solved system reports beyond its equilibrium (docs/systems.md, "What each line
reports"): each line's own numbers (HeldLine.summary: the largest tension and where, the
end tensions along the line and on the points, the touchdown and the grounded length),
shared to every rank; and the arrays a picture of the whole system draws
(figures/system.py), gathered to one rank only when a picture is asked for."""

import numpy as np


def line_summaries(solver):
    """[HeldLine.summary() of every line] of the SystemSolver ``solver``, in the
    system's order, on every rank (a line without ``summary``, a test's mock, gives
    {}). Collective."""
    return solver.collect(lambda line: line.summary() if hasattr(line, "summary") else {})


def centrelines(solver, root=0):
    """[(n_k + 1, 3) vertices of each line, m, absolute] on rank ``root`` (None on the
    others), each line's field gathered once to its group's root and from there to
    ``root``: for a picture only. Collective."""
    return solver.collect(lambda line: line.centreline(), root=root)


def picture(solver, root=0):
    """The arrays of a picture of the system at the solver's state, on rank ``root``
    (None on the others), as figures/system.system_figure takes them: ``lines``
    {name: (n, 3)}, ``points`` [(name, kind, (3,))], ``bodies`` [(name, X (3,),
    fairleads (k, 3))], ``seabed`` (the flat seabed's height, m, or None) and
    ``surface`` (m). Collective."""
    drawn = centrelines(solver, root)
    if drawn is None:
        return None
    system, state = solver.system, solver.state
    ends = solver.end_positions(state)
    body_end = solver.layout.body_end
    environment = system.environment
    return {"lines": {line.name: r for line, r in zip(system.lines, drawn)},
            "points": [(p.name, p.kind, state.points[i].copy())
                       for i, p in enumerate(system.points)],
            "bodies": [(b.name, state.bodies.X[i].copy(), ends[body_end == i])
                       for i, b in enumerate(system.bodies)],
            "seabed": (None if environment.seabed is None or environment.seabed_slope
                       or environment.seabed_profile is not None
                       else float(environment.seabed)),
            "surface": float(environment.surface or 0.0)}


def summary_table(system, summaries):
    """{column: (n_lines,) array} of the lines' ``summaries`` (line_summaries), the
    scalars only, with ``line`` their names: a table's columns."""
    names = [line.name for line in system.lines]
    keys = [k for k, v in (summaries[0] if summaries else {}).items() if np.ndim(v) == 0]
    table = {"line": np.array(names)}
    table.update({k: np.array([s.get(k, np.nan) for s in summaries], dtype=float)
                  for k in keys})
    return table
