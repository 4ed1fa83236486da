"""Project defaults for PETSc objects' own options (a KSP's sub-PC, a SNES line
search, a MUMPS control) that the user can still override from the options database."""

from contextlib import contextmanager

from petsc4py import PETSc


@contextmanager
def defaults_in_effect(defaults):
    """``defaults`` ({option name: value}) in the options database for the options the
    user did not give, while the block runs, and gone after it (so they never become a
    user's option, nor one reported unused)."""
    database = PETSc.Options()
    added = [name for name in defaults if not database.hasName(name)]
    for name in added:
        database.setValue(name, defaults[name])
    try:
        yield
    finally:
        for name in added:
            database.delValue(name)


def set_from_options_with_defaults(obj, defaults):
    """``obj.setFromOptions()`` with ``defaults`` in effect (defaults_in_effect): the
    default of a PETSc object's option that only the options database can set."""
    with defaults_in_effect(defaults):
        obj.setFromOptions()
