"""Validation code for tests and scripts (closed forms, collocation reference, round-off
probe, Gauss writhe); a run (python -m petsc_rod) never imports it."""
