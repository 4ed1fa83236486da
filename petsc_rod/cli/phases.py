"""The -log_view stages of a command-line run (docs/options.md, docs/performance.md
"Where the remaining time goes"): ``rod_setup`` the options made a started line (the
scene, the start's tension scale, the mesh, problem and solver, the first state),
``rod_steps`` the continuation (iterations, Newton steps, stability tests),
``rod_output`` what a step reports and writes (its record and lines, the result file,
the CSV table). PETSc's start, the imports after it and the exit stay in the Main
Stage; the modes have their own (analysis/modes.py)."""

from petsc4py import PETSc

SETUP, STEPS, OUTPUT = (PETSc.Log.Stage(f"rod_{name}")
                        for name in ("setup", "steps", "output"))
