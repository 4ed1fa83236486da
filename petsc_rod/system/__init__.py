"""A system of lines, points and bodies solved together (docs/systems.md): the coupled
static equilibrium and each body's mooring stiffness (equilibrium.py), the bodies'
kinematics and hydrostatics (bodies.py), the lines over groups of ranks (placement.py).

    solver = SystemSolver(system, make_line, comm)   # make_line(system_line, comm)
    result = solver.solve()                          # Equilibrium
    stiffness = solver.body_stiffness("floater")     # BodyStiffness
    solver.destroy()
"""
