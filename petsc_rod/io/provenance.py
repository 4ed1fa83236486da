"""Which program wrote a result: the package version and the git commit of its checkout.

``commit()`` runs git once and remembers the answer; __main__ asks before MPI starts,
since forking a process under MPI is not safe everywhere.
"""

import functools
import os

from petsc_rod import __version__

REPOSITORY = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def version():
    return __version__


@functools.lru_cache(maxsize=None)
def commit():
    """The commit of the checkout the package runs from, with '+modified' when tracked
    files differ from it; 'unknown' outside a git checkout of its own (e.g. installed
    into another repository's tree) or without git."""
    import subprocess               # here: a run without a result file runs no git

    def git(*args):
        return subprocess.run(["git", "-C", REPOSITORY, *args], capture_output=True,
                              text=True, timeout=20, check=True).stdout.strip()
    try:
        if os.path.realpath(git("rev-parse", "--show-toplevel")) != os.path.realpath(REPOSITORY):
            return "unknown"
        head = git("rev-parse", "HEAD")
        modified = git("status", "--porcelain", "--untracked-files=no")
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return head + ("+modified" if modified else "")
