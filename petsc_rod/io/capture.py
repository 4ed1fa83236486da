"""Standard error captured at the file-descriptor level, so that the messages C libraries
(PETSc, HDF5, MPI-IO) print themselves can be replaced by one line."""

import contextlib
import os
import sys
import tempfile


@contextlib.contextmanager
def stderr_captured():
    """Everything written to file descriptor 2 goes to a temporary file; yields a function
    that returns what was written so far."""
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile() as capture:
        os.dup2(capture.fileno(), 2)

        def text():
            sys.stderr.flush()
            size = os.fstat(capture.fileno()).st_size
            return os.pread(capture.fileno(), size, 0).decode("utf-8", errors="replace")
        try:
            yield text
        finally:
            sys.stderr.flush()
            os.dup2(saved, 2)
            os.close(saved)
