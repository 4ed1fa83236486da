"""Terms of physics: the protocol (term.py) and the dead loads (dead_loads.py); the
riser's terms are in petsc_rod/riser/terms.py."""
