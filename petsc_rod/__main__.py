"""``python -m petsc_rod -options_file options/<scene>.opts``."""

import os
import sys


def missing_options_files(argv):
    """Files named after -options_file that do not exist (PETSc would stop with a trace)."""
    return [path for flag, path in zip(argv, argv[1:])
            if flag == "-options_file" and not os.path.isfile(path)]


def main():
    for path in missing_options_files(sys.argv):
        sys.stderr.write(f"petsc_rod: error: -options_file {path}: no such scene file; the "
                         "scenes are in options/ (e.g. options/paper.opts)\n")
        return 2
    try:
        import petsc4py
    except ImportError:
        sys.stderr.write(
            "petsc_rod: error: petsc4py is not importable by this python "
            f"({sys.executable}); run scripts/setup.sh once, then `source .venv/bin/activate`"
            "\n")
        return 2
    petsc4py.init(sys.argv)
    from .cli import run
    return run()


if __name__ == "__main__":
    sys.exit(main())
