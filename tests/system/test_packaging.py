"""The wheel `pip install .` builds holds every package of petsc_rod and the `petsc_rod`
command. Built offline (no build isolation, no index) from a copy of the work tree, so
that neither build/ nor an .egg-info is left in the repository.

The test spawns pip, so it is marked ``serial`` (skipped inside an MPI run).
"""

import configparser
import os
import shutil
import subprocess
import sys
import zipfile

import pytest

from helpers import REPO_ROOT

pytestmark = pytest.mark.serial

PACKAGE_DIR = os.path.join(REPO_ROOT, "petsc_rod")
IGNORED = shutil.ignore_patterns("__pycache__", "*.pyc", "*.egg-info")


def packages(root):
    """The folders of ``root``'s petsc_rod that hold an __init__.py, as wheel paths."""
    found = []
    for folder, dirs, files in os.walk(os.path.join(root, "petsc_rod")):
        dirs[:] = [d for d in dirs if d != "__pycache__"]
        if "__init__.py" in files:
            found.append(os.path.relpath(folder, root).replace(os.sep, "/"))
    return sorted(found)


def modules(root):
    """Every .py file of ``root``'s petsc_rod, as wheel paths."""
    found = []
    for folder, dirs, files in os.walk(os.path.join(root, "petsc_rod")):
        dirs[:] = [d for d in dirs if d != "__pycache__"]
        found += [os.path.relpath(os.path.join(folder, name), root).replace(os.sep, "/")
                  for name in files if name.endswith(".py")]
    return sorted(found)


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    """(source copy, the wheel's ZipFile) built from the work tree's petsc_rod/."""
    base = tmp_path_factory.mktemp("packaging")
    source = base / "source"
    shutil.copytree(PACKAGE_DIR, source / "petsc_rod", ignore=IGNORED)
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(os.path.join(REPO_ROOT, name), source / name)
    out = base / "wheels"
    env = dict(os.environ, PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1")
    built = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
         "--no-index", "--quiet", "--wheel-dir", str(out), str(source)],
        capture_output=True, text=True, env=env, cwd=base, timeout=120)
    assert built.returncode == 0, (
        f"pip wheel failed (setuptools and wheel must be importable by {sys.executable}: "
        f"Debian's python3-setuptools, python3-wheel):\n{built.stdout}\n{built.stderr}")
    wheels = sorted(out.glob("petsc_rod-*.whl"))
    assert len(wheels) == 1, f"expected one petsc_rod wheel, found {wheels}"
    with zipfile.ZipFile(wheels[0]) as archive:
        yield source, archive


def test_every_package_is_in_the_wheel(wheel):
    source, archive = wheel
    names = set(archive.namelist())
    expected = packages(source)
    assert "petsc_rod" in expected and "petsc_rod/cli" in expected
    missing = [package for package in expected if f"{package}/__init__.py" not in names]
    assert not missing, f"packages left out of the wheel: {missing}"
    missing = [module for module in modules(source) if module not in names]
    assert not missing, f"modules left out of the wheel: {missing}"
    assert not [name for name in names if "__pycache__" in name or name.endswith(".pyc")]


def test_the_wheel_has_the_petsc_rod_command(wheel):
    _, archive = wheel
    entry_points = [name for name in archive.namelist()
                    if name.endswith(".dist-info/entry_points.txt")]
    assert len(entry_points) == 1, archive.namelist()
    parser = configparser.ConfigParser()
    parser.read_string(archive.read(entry_points[0]).decode())
    assert parser.get("console_scripts", "petsc_rod").strip() == "petsc_rod.__main__:main"
    assert "petsc_rod/__main__.py" in archive.namelist()


def test_the_wheel_needs_no_pip_h5py_petsc4py_or_scipy(wheel):
    """Runtime requirements are what the command line imports, less Debian's MPI
    packages (pip cannot see Debian's h5py and would shadow it with a serial one);
    scipy only for validation."""
    _, archive = wheel
    metadata = [name for name in archive.namelist() if name.endswith(".dist-info/METADATA")]
    assert len(metadata) == 1
    lines = archive.read(metadata[0]).decode().splitlines()
    required = [line.split(":", 1)[1].strip() for line in lines
                if line.startswith("Requires-Dist:")]
    always = [r.split(";")[0].strip() for r in required if "extra" not in r]
    assert always == ["numpy"], required
    extras = [r.replace('"', "'").replace(" ", "") for r in required if "extra" in r]
    assert "scipy;extra=='validation'" in extras, required
