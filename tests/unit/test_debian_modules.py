"""petsc_rod finds Debian's petsc4py and slepc4py without PETSC_DIR or SLEPC_DIR (a venv
made by `pip install .`): __main__.find_module adds the newest matching folder to the
path. Checked on a made-up module in made-up version folders."""

import sys

from petsc_rod.__main__ import find_module


def version_folder(root, version, name):
    folder = root / f"slepc{version}" / "x86_64-linux-gnu-real" / "lib" / "python3" / \
        "dist-packages"
    (folder / name).mkdir(parents=True)
    (folder / name / "__init__.py").write_text(f"VERSION = '{version}'\n")
    return folder


def test_the_newest_debian_folder_is_put_on_the_path(tmp_path, monkeypatch):
    name = "petsc_rod_fake_slepc4py"
    version_folder(tmp_path, "3.9", name)
    newest = version_folder(tmp_path, "3.18", name)       # 3.18 after 3.9, not before
    monkeypatch.setattr(sys, "path", list(sys.path))
    pattern = str(tmp_path / "slepc3.*" / "*-real" / "lib" / "python3" / "dist-packages")
    try:
        assert find_module(name, pattern)
        assert sys.path[-1] == str(newest)
        assert sys.modules[name].VERSION == "3.18"
    finally:
        sys.modules.pop(name, None)


def test_a_module_found_nowhere_is_reported_missing(tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "path", list(sys.path))
    assert not find_module("petsc_rod_no_such_module", str(tmp_path / "none*"))
