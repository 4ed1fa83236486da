"""Whether a program's output would replace one of its inputs (no PETSc, no h5py: the
solver, the sweep, the report and the plots all ask it before any work).

Two paths name one file when both exist and have the same device and inode (a hard
link, a symbolic link, another spelling of the path), or, when one does not exist yet,
when their real paths (symbolic links resolved) are equal.
"""

import os


def same_file(a, b):
    """Whether paths ``a`` and ``b`` name one file (module docstring)."""
    try:
        first, second = os.stat(a), os.stat(b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)
    return (first.st_dev, first.st_ino) == (second.st_dev, second.st_ino)


def replaced_input(outputs, inputs):
    """The first clash of an output with an input, as one sentence, or None.
    ``outputs``, ``inputs``: (what names it, e.g. an option, path) pairs; empty paths
    are skipped."""
    for written, path in outputs:
        for read, source in inputs:
            if path and source and same_file(path, source):
                return (f"{written} {path}: is the {read} {source} file, an input of this "
                        "run that writing would replace; name another file")
    return None
