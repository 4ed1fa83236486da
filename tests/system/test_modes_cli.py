"""The modes' failures at the command line's exit (python -m petsc_rod -rod_modes): a
PETSc error inside the modes' eigensolver ends the process with exit 4 and one line, no
result file, on 1 and 2 ranks, not a segmentation fault at PetscFinalize (exit 59),
where PETSc's garbage collection would destroy a spectral transformation's python PC
after the interpreter has ended (analysis/modes.FactorKSP). The same runs in-process:
tests/solver/test_modes.py, test_an_eigensolver_failure_ends_the_run_in_one_line."""

import pytest

from helpers import describe, partial_files, run_petsc_rod

CANTILEVER = ["-rod_length", "1", "-rod_stiffness", "1,1,1", "-rod_start", "clamp",
              "-rod_end", "free", "-rod_elements", "8", "-rod_modes", "3",
              "-rod_modes_mass", "1"]


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("options, says", [
    # EPSSetUp refuses it
    (["-rod_modes_st_type", "cayley"],
     "Values of shift and antishift cannot be zero simultaneously"),
    # the spectral transformation's KSP diverges inside EPSSolve
    (["-rod_modes_st_ksp_type", "richardson", "-rod_modes_st_ksp_richardson_scale", "3",
      "-rod_modes_st_ksp_divtol", "1.5"],
     "KSPSolve has not converged, reason DIVERGED_DTOL")])
def test_an_eigensolver_failure_exits_4(options, says, ranks, tmp_path):
    output = tmp_path / "modes.h5"
    process = run_petsc_rod(CANTILEVER + options + ["-rod_output", str(output)], ranks)
    assert process.returncode == 4, describe(process)
    errors = [line for line in process.stdout.splitlines() if "error" in line]
    assert errors == [f"petsc_rod: error: the modes' eigensolver (SLEPc) failed: {says}; "
                      "check the -rod_modes_eps_* and -rod_modes_st_* options"], \
        describe(process)
    assert "step 1/1: load factor 1, converged" in process.stdout
    assert "PETSC ERROR" not in process.stderr, describe(process)
    assert not output.exists() and not partial_files(output)
