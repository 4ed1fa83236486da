"""The start of ``python -m petsc_rod`` (docs/performance.md, "Where the remaining time
goes"): Open MPI's fast start only where it cannot change what the ranks reach and the
user chose nothing, and nothing imported that the run does not use."""

import subprocess
import sys

import pytest
from helpers import REPO_ROOT, child_env

import petsc_rod.__main__
from petsc_rod.__main__ import may_write_a_result, open_mpi_defaults

FAST = {"OMPI_MCA_pml": "ob1", "OMPI_MCA_btl": "self,vader",
        "OMPI_MCA_ess_singleton_isolated": "1"}
ONE_NODE = {"OMPI_MCA_pml": "ob1", "OMPI_MCA_btl": "self,vader"}


@pytest.fixture(autouse=True)
def no_installation_file(tmp_path, monkeypatch):
    """The installation's parameter file of the machine the tests run on is not read."""
    monkeypatch.setattr(petsc_rod.__main__, "SYSTEM_MCA_FILE", str(tmp_path / "none.conf"))


def test_a_singleton_starts_isolated_on_shared_memory(tmp_path):
    # setup.sh's own OMPI_MCA_ setting is no choice of transport
    environ = {"HOME": str(tmp_path), "OMPI_MCA_rmaps_base_oversubscribe": "1"}
    assert open_mpi_defaults(environ) == FAST


def test_the_users_choice_is_kept(tmp_path):
    home = {"HOME": str(tmp_path)}
    assert open_mpi_defaults({**home, "OMPI_MCA_pml": "ucx"}) == {
        "OMPI_MCA_ess_singleton_isolated": "1"}
    assert open_mpi_defaults({**home, "OMPI_MCA_mtl": "psm2"}) == {
        "OMPI_MCA_ess_singleton_isolated": "1"}
    assert open_mpi_defaults({**home, "OMPI_MCA_ess_singleton_isolated": "0"}) == ONE_NODE
    (tmp_path / ".openmpi").mkdir()
    (tmp_path / ".openmpi" / "mca-params.conf").write_text(
        "# the user's file\nbtl = self,tcp\n")
    assert open_mpi_defaults(home) == {"OMPI_MCA_ess_singleton_isolated": "1"}
    named = tmp_path / "site.conf"
    named.write_text("pml=cm\n")
    assert open_mpi_defaults({"HOME": "/nonexistent",
                              "OMPI_MCA_mca_base_param_files": str(named)}) == {
        "OMPI_MCA_ess_singleton_isolated": "1"}


def test_mpiexec_on_one_node_and_on_several(tmp_path):
    launched = {"HOME": str(tmp_path), "PMIX_RANK": "0", "OMPI_COMM_WORLD_RANK": "0",
                "OMPI_MCA_ess": "^singleton", "OMPI_MCA_pmix": "^s1,s2,cray,isolated"}
    assert open_mpi_defaults({**launched, "OMPI_COMM_WORLD_SIZE": "2",
                              "OMPI_COMM_WORLD_LOCAL_SIZE": "2"}) == ONE_NODE
    assert open_mpi_defaults({**launched, "OMPI_COMM_WORLD_SIZE": "4",
                              "OMPI_COMM_WORLD_LOCAL_SIZE": "2"}) == {}
    # mpiexec --mca btl self,tcp reaches the ranks as the environment
    assert open_mpi_defaults({**launched, "OMPI_COMM_WORLD_SIZE": "2",
                              "OMPI_COMM_WORLD_LOCAL_SIZE": "2",
                              "OMPI_MCA_btl": "self,tcp"}) == {}
    # srun (PMIx or PMI) or MPICH's mpiexec: no word of the node's ranks
    for variable in ("PMIX_RANK", "PMI_RANK", "SLURM_STEP_NUM_TASKS"):
        assert open_mpi_defaults({"HOME": str(tmp_path), variable: "0"}) == {}


def test_the_command_line_imports_no_module_it_does_not_use():
    """A run without a result file, modes or pictures imports neither h5py, SLEPc
    (slepc4py's package, which only says where it is, may be), matplotlib, scipy, the
    modes', report's and sweep's modules nor subprocess (git runs for a result file)."""
    script = (
        "import sys; sys.argv = ['petsc_rod', '-options_file', 'options/cantilever.opts', "
        "'-rod_elements', '8', '-rod_steps', '1']\n"
        "from petsc_rod.__main__ import main\n"
        "assert main() == 0\n"
        "unused = ('h5py', 'slepc4py.SLEPc', 'slepc4py.lib', 'matplotlib', 'scipy', "
        "'petsc_rod.analysis.modes', 'petsc_rod.cli.modes', "
        "'petsc_rod.report', 'petsc_rod.sweep', 'petsc_rod.system', 'petsc_rod.plots', "
        "'petsc_rod.figures.rod', 'petsc_rod.figures.riser', 'subprocess')\n"
        "print(sorted({name.split('.')[0] if name.startswith('h5py') else name\n"
        "              for name in sys.modules if name.startswith(unused)}))\n")
    done = subprocess.run([sys.executable, "-c", script], cwd=REPO_ROOT, env=child_env(),
                          capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[-1] == "[]"


def test_log_view_names_each_phase():
    """-log_view's stages rod_setup, rod_steps and rod_output, and the stability test's
    event rod_stability, each with a time."""
    done = subprocess.run(
        [sys.executable, "-m", "petsc_rod", "-options_file", "options/cantilever.opts",
         "-rod_elements", "8", "-rod_steps", "1", "-rod_al_newton", "0", "-log_view"],
        cwd=REPO_ROOT, env=child_env(), capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    rows = [line.split(":") for line in done.stdout.splitlines() if ":" in line]
    stages = {row[1].strip(): float(row[2].split()[0]) for row in rows
              if row[0].strip().isdigit()}
    assert {"rod_setup", "rod_steps", "rod_output"} <= stages.keys()
    assert all(stages[name] > 0 for name in ("rod_setup", "rod_steps", "rod_output"))
    events = [line.split() for line in done.stdout.splitlines()
              if line.startswith("rod_stability ")]
    assert len(events) == 1 and int(events[0][1]) == 1 and float(events[0][3]) > 0


def test_git_runs_only_for_a_run_that_may_write_a_result(tmp_path):
    """The result file's record names the commit (git, run before MPI starts); a run
    whose options name no output anywhere runs no git."""
    scene = tmp_path / "scene.opts"
    scene.write_text("-rod_length 2\n")
    writes = tmp_path / "writes.opts"
    writes.write_text("-options_file scene.opts\n-rod_output run.h5\n".replace(
        "scene.opts", str(scene)))
    assert not may_write_a_result(["petsc_rod", "-options_file", str(scene)], {})
    assert may_write_a_result(["petsc_rod", "-options_file", str(scene), "-rod_output",
                               "x.h5"], {})
    assert may_write_a_result(["petsc_rod", "-options_file", str(writes)], {})
    assert may_write_a_result(["petsc_rod"], {"PETSC_OPTIONS": "-rod_output x.h5"})


def test_the_installation_s_file_and_a_comma_separated_list_are_read(tmp_path, monkeypatch):
    """Open MPI reads the user's file and then the installation's, and a list of files
    separated by commas: a transport chosen in any of them is kept; a value that only
    excludes components none of ours (Debian's pml = ^ucx) is no choice against them."""
    system = tmp_path / "openmpi-mca-params.conf"
    monkeypatch.setattr(petsc_rod.__main__, "SYSTEM_MCA_FILE", str(system))
    home = {"HOME": str(tmp_path)}
    system.write_text("mtl = ^ofi\nbtl = ^uct,openib,ofi\npml = ^ucx\n")
    assert open_mpi_defaults(home) == FAST
    system.write_text("pml = ^ob1\n")
    assert open_mpi_defaults(home) == {"OMPI_MCA_ess_singleton_isolated": "1"}
    system.write_text("btl = self,tcp\n")
    assert open_mpi_defaults(home) == {"OMPI_MCA_ess_singleton_isolated": "1"}
    first, second = tmp_path / "a.conf", tmp_path / "b.conf"
    first.write_text("# nothing of ours\n")
    second.write_text("mtl = psm2\n")
    assert open_mpi_defaults({"HOME": "/nonexistent", "OMPI_MCA_mca_base_param_files":
                              f"{first},{second}"}) == {"OMPI_MCA_ess_singleton_isolated": "1"}
