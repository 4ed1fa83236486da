"""Project defaults for PETSc objects' own options (a KSP's sub-PC, a SNES line
search) that the user can still override from the options database."""

from petsc4py import PETSc


def set_from_options_with_defaults(obj, defaults):
    """``obj.setFromOptions()`` with ``defaults`` ({option name: value}) in effect for
    the options the user did not give: the default of a PETSc object's option that only
    the options database can set (a sub-PC type, a line search) without making it a
    user's option afterwards."""
    database = PETSc.Options()
    added = [name for name in defaults if not database.hasName(name)]
    for name in added:
        database.setValue(name, defaults[name])
    try:
        obj.setFromOptions()
    finally:
        for name in added:
            database.delValue(name)
