"""A run with seabed friction on an extensible line that does not converge at the default
penalty says which to take (about EA / 10: problem/penalty.friction_penalty), and the
advised penalty gives the answer of the run that converges at the default (docs/riser.md
§3b). The 850 m chain of options/mooring_chain.opts at 100 elements with friction 0.3,
in two load steps (where the Newton steps do not finish the first step): at the default
R = 1.17e6 N it needs 648 iterations, which -rod_al_max_it 100 cuts short; at the advised
1.23e8 N it converges in 392 to the one-step run's line. In one step with a current
across (0.5 m/s, 250 elements), where the Newton steps do not finish it either, the
stalling iteration raises R itself towards that penalty (penalty.adapt_ceiling) and
converges to the line of the run given it. Spawns processes: marked ``serial``."""

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


def test_a_chain_in_a_current_across_raises_its_penalty_to_the_advised_answer(tmp_path):
    """At 250 elements, kept at the default R = 1.18e6 N (the problem's scale, and the
    raises' ceiling without friction) the chain does not converge in 1200 iterations;
    the raise at iteration 400 to 1.18e7 N converges in 759, to the line of the run
    given 1.23e8 N (118 iterations) within 1e-6 m (measured 5e-10)."""
    across = ["-options_file", "options/mooring_chain.opts",
              "-rod_sections", "chain120:850:250", "-rod_seabed_friction", "0.5",
              "-rod_current", "0,0.5,0", "-rod_max_halvings", "0", "-rod_al_max_it", "1200"]
    raised, given = tmp_path / "raised.h5", tmp_path / "given.h5"
    done = run_petsc_rod(across + ["-rod_output", str(raised)], 1, TIMEOUT)
    assert done.returncode == 0, describe(done)
    said = done.stdout + done.stderr
    assert "R raised to 1.18e+07 at iteration 400" in said, describe(done)
    assert "ceiling 1.23e+08 (a tenth of the least EA" in said, describe(done)
    done = run_petsc_rod(across + ["-rod_al_penalty", ADVISED, "-rod_output", str(given)],
                         1, TIMEOUT)
    assert done.returncode == 0, describe(done)
    with h5py.File(raised, "r") as a, h5py.File(given, "r") as b:
        assert np.max(np.abs(a["r"][...] - b["r"][...])) < 1e-6
