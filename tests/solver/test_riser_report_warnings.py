"""The riser report of a line lying flat on or below the seabed (issue 25: the shipped
lazy wave printed "RuntimeWarning: divide by zero" from quantities/riser_numbers.py on 2 ranks,
where two neighbouring vertices sat at the same height below the seabed). Serial and
under mpiexec -n 2, with RuntimeWarnings turned into errors."""

import numpy as np
import pytest

from helpers import destroy, make_solver
from petsc_rod.environment.seabed import Seabed
from petsc_rod.io.outputs import vertex_fields

# The straight reference (z = 0 everywhere) under a seabed 0.5 m above it: every
# element has gap0 = gap1 = -0.5 m, the case that divided by gap0 - gap1 = 0.
FLAT = dict(length=10.0, stiffness=(1.0, 1.0, 1.0), start="pin", end="pin",
            end_position=[10.0, 0.0, 0.0], load_values=[[0.0, 0.0, -1.0]],
            seabed=Seabed(0.5, 1e3))


@pytest.mark.filterwarnings("error::RuntimeWarning")
@pytest.mark.parametrize("height", [0.5, 0.0])
def test_the_riser_report_of_a_flat_line_has_no_warning(comm, height):
    """Below the seabed (0.5) every element is grounded, the touchdown is the top; on it
    (0: gaps exactly 0) none is."""
    scene = dict(FLAT, seabed=Seabed(height, 1e3))
    mesh, solver = make_solver(comm, 12, scene, 10.0)
    try:
        problem = solver.problem
        problem.prepare(1.0)                # the ends at the full load
        problem.state.set_straight()
        output, *_ = problem.outputs(vertex_fields(problem))   # the riser numbers
        numbers = output.attributes
        expected = 10.0 if height > 0 else 0.0
        assert abs(numbers["grounded_length"] - expected) < 1e-12
        if height > 0:
            assert numbers["touchdown_S"] == 10.0
        assert np.all(np.isfinite(output.datasets["seabed_reaction"]))
    finally:
        destroy(mesh, solver)
