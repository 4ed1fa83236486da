"""The straight start of a heavy line resting on the seabed (docs/method.md §10, "The
straight start with a seabed"), on 1 and 2 ranks: the 2 km line of 1.2 kN/m
(EI 5.6e7 N m^2) from an anchor on the seabed to a pin 1506 m away and 1000 m up, about
490 m of it on the seabed, 100 elements, from the straight reference in 10 steps, reaches
the state of the catenary start without halving a step. Before the early escape with a
seabed its first steps buckled the line (its end nearer than the length) and converged
to the planar saddle: 8687 iterations and 3 halvings on 1 rank.
"""

import re

import h5py
import numpy as np
import pytest

from helpers import describe, run_petsc_rod

HEAVY_LINE = ["-rod_length", "2000", "-rod_stiffness", "5.6e7,5.6e7,4.3e7",
              "-rod_start", "pin", "-rod_end", "pin", "-rod_end_position", "1506,0,1000",
              "-rod_load", "0,0,-1200", "-rod_seabed", "0", "-rod_elements", "100"]
LAST_LINE = re.compile(r"converged, (\d+) iterations in \S+ s, (\d+) halving")


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_heavy_line_on_the_seabed_from_the_straight_start(ranks, tmp_path):
    straight = run_petsc_rod(HEAVY_LINE + ["-rod_initial_shape", "straight", "-rod_steps", "10",
                                           "-rod_output", str(tmp_path / "straight.h5")],
                             ranks, timeout=600)
    assert straight.returncode == 0, describe(straight)
    assert "Traceback" not in straight.stderr
    iterations, halvings = map(int, LAST_LINE.search(straight.stdout + straight.stderr).groups())
    assert halvings == 0 and iterations < 4000, describe(straight)
    catenary = run_petsc_rod(HEAVY_LINE + ["-rod_initial_shape", "catenary",
                                           "-rod_output", str(tmp_path / "catenary.h5")], ranks)
    assert catenary.returncode == 0, describe(catenary)
    with h5py.File(tmp_path / "straight.h5") as a, h5py.File(tmp_path / "catenary.h5") as b:
        assert np.abs(a["r"][...] - b["r"][...]).max() < 1e-6 * 2000
        assert np.abs(a["n"][...] - b["n"][...]).max() < 1e-6 * 1950e3
        assert a.attrs["converged"] and b.attrs["converged"]
