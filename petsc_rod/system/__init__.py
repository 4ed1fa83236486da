"""A system of lines, points and bodies solved together (docs/systems.md, docs/method.md
§13): each line of a system held at its two ends, its end forces and their exact
linearisation (held_line.py); the coupled static equilibrium and each body's mooring
stiffness (equilibrium.py), the bodies' kinematics and hydrostatics (bodies.py), the
lines over groups of ranks (placement.py); what each line reports and the arrays of a
picture (outputs.py); the load-excursion curves and the watch circle (excursions.py).

    solver = SystemSolver(system, make_line, comm)   # make_line(system_line, comm)
    result = solver.solve()                          # Equilibrium
    stiffness = solver.body_stiffness("floater")     # BodyStiffness
    lines = outputs.line_summaries(solver)           # [HeldLine.summary()]
    circle = excursions.watch_circle(solver, "floater", 1e6)
    solver.destroy()
"""
