"""Outputs that neither replace an input nor are ever half-written (no PETSc, no h5py:
the solver, the sweep, the report and the plots use it).

Two paths name one file when both exist and have the same device and inode (a hard
link, a symbolic link, another spelling of the path), or, when one does not exist yet,
when their real paths (symbolic links resolved) are equal. A file is written whole
beside its path and renamed onto it (write_whole): the path holds the old content or
the new, never part of one.
"""

import contextlib
import os
import tempfile


def same_file(a, b):
    """Whether paths ``a`` and ``b`` name one file (module docstring)."""
    try:
        first, second = os.stat(a), os.stat(b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)
    return (first.st_dev, first.st_ino) == (second.st_dev, second.st_ino)


def replaced_input(outputs, inputs, fix="writing would replace; name another file"):
    """The first clash of an output with an input, as one sentence ending in ``fix``, or
    None. ``outputs``, ``inputs``: (what names it, e.g. an option, path) pairs; empty
    paths are skipped."""
    for written, path in outputs:
        for read, source in inputs:
            if path and source and same_file(path, source):
                return f"{written} {path}: is the {read} {source} file, an input that {fix}"
    return None


def write_whole(path, write):
    """``write(partial)``, ``partial`` a new file in ``path``'s folder with its extension
    (a figure's format follows it) and the permissions a new file gets, then renamed
    onto ``path`` (atomic within a folder); on any failure the partial file is removed
    and ``path`` is left as it was."""
    folder, name = os.path.split(os.path.abspath(path))
    descriptor, partial = tempfile.mkstemp(prefix=f".{name}.",
                                           suffix=".partial" + os.path.splitext(name)[1],
                                           dir=folder)
    os.close(descriptor)
    mask = os.umask(0)
    os.umask(mask)
    try:
        os.chmod(partial, 0o666 & ~mask)
        write(partial)
        os.replace(partial, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.remove(partial)
        raise


def write_text_whole(path, text):
    """``text`` (UTF-8) into ``path`` by write_whole."""
    def write(partial):
        with open(partial, "w", newline="", encoding="utf-8") as handle:
            handle.write(text)
    write_whole(path, write)
