"""``python -m petsc_rod -options_file options/<scene>.opts``."""

import sys


def main():
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
