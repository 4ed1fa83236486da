"""petsc_rod: static equilibrium of elastic cables (Kirchhoff rods) by the
augmented-Lagrangian (Uzawa) decomposition of Rochinha, Sampaio & Le Tallec (1990).

The method and its notation are those of ``docs/method.md``; section numbers
(e.g. "§3") in docstrings refer to it.
"""

__version__ = "0.1.0"
