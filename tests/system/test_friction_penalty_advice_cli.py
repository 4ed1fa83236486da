"""A run with seabed friction on an extensible line that does not converge at the default
penalty says which to take (about EA / 10: problem/penalty.friction_penalty), and the
advised penalty gives the answer of the run that converges at the default (docs/riser.md
§3b). The 850 m chain of options/mooring_chain.opts at 100 elements with friction 0.3,
in two load steps (where the Newton steps do not finish the first step): at the default
R = 1.17e6 N it needs 648 iterations, which -rod_al_max_it 100 cuts short; at the advised
1.23e8 N it converges in 392 to the one-step run's line. Spawns processes: marked
``serial``."""

import h5py
import numpy as np
import pytest

from helpers import describe, run_petsc_rod

pytestmark = pytest.mark.serial

TIMEOUT = 300
CHAIN = ["-options_file", "options/mooring_chain.opts", "-rod_sections", "chain120:850:100",
         "-rod_seabed_friction", "0.3"]
# EA / 10 of the chain's line type (options/line_types/mooring_chain.txt), as printed
ADVISED = "1.23e+08"


def test_the_advised_penalty_is_said_and_gives_the_one_step_answer(tmp_path):
    cut = run_petsc_rod(CHAIN + ["-rod_steps", "2", "-rod_max_halvings", "0",
                                 "-rod_al_max_it", "100",
                                 "-rod_output", str(tmp_path / "cut.h5")], 1, TIMEOUT)
    assert cut.returncode == 3, describe(cut)
    assert f"try -rod_al_penalty {ADVISED}" in cut.stderr + cut.stdout, describe(cut)
    one, two = tmp_path / "one.h5", tmp_path / "two.h5"
    done = run_petsc_rod(CHAIN + ["-rod_output", str(one)], 1, TIMEOUT)
    assert done.returncode == 0, describe(done)
    done = run_petsc_rod(CHAIN + ["-rod_steps", "2", "-rod_max_halvings", "0",
                                  "-rod_al_penalty", ADVISED, "-rod_output", str(two)],
                         1, TIMEOUT)
    assert done.returncode == 0, describe(done)
    assert "try -rod_al_penalty" not in done.stdout + done.stderr
    with h5py.File(one, "r") as a, h5py.File(two, "r") as b:
        assert np.max(np.abs(a["r"][...] - b["r"][...])) < 1e-6
