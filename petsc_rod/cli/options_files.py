"""The options files of a run as PETSc 3.18 reads them (the command line's -options_file,
the nested -options_file lines, PETSC_OPTIONS and the petscrc files), checked before
PETSc starts (petsc_rod/__main__.py): a file that includes itself, a missing or
unreadable file, a pipe, a byte-order mark or an -options_file without a path would
otherwise crash PETSc or give a misleading message. No PETSc here: it runs first."""

import os
import re

from petsc_rod import tables
from petsc_rod.tables import file_problem

# A UTF-8 byte-order mark: invisible in an editor, but PETSc reads it as part of the
# first option's name ("Unknown first token").
BOM = b"\xef\xbb\xbf"
# The names PETSc replaces in an options file's path besides environment variables
# (PetscStrreplace); a ${...} that is neither is left to PETSc.
PETSC_PATH_NAMES = {"HOMEDIRECTORY": lambda: os.path.expanduser("~"),
                    "WORKINGDIRECTORY": os.getcwd}


class OptionsFileError(Exception):
    """Why the options files cannot be read as PETSc would read them (one line)."""


def is_key(token):
    """Whether PETSc takes ``token`` for an option name (PetscOptionsValidKey): '-' or
    '--' then a letter, and not a number such as -inf."""
    name = token[2:] if token.startswith("--") else token[1:]
    if not token.startswith("-") or not name[:1].isalpha():
        return False
    try:
        float(token)
        return False
    except ValueError:
        return True


def is_options_file(token):
    return token.lower() == "-options_file"      # PETSc compares without case


def options_files(argv):
    """The paths PETSc reads after -options_file on the command line ``argv`` (argv[0]
    the program), in order, as PetscOptionsInsertArgs takes them; raises
    OptionsFileError for an -options_file with no path after it."""
    paths, k = [], 1
    while k < len(argv):
        token = argv[k]
        follows = argv[k + 1] if k + 1 < len(argv) else None
        if not is_key(token):
            k += 1
        elif is_options_file(token):
            if follows is None or follows.startswith("-"):
                raise OptionsFileError(f"{token} needs the path of a scene file after it "
                                       "(e.g. -options_file options/paper.opts)")
            paths.append(follows)
            k += 2
        else:
            k += 2 if follows is not None and not is_key(follows) else 1
    return paths


def environment_files(environ):
    """The paths after -options_file in PETSC_OPTIONS (a string of options, read by
    PETSc like the command line)."""
    return options_files(["petsc_rod"] + environ.get("PETSC_OPTIONS", "").split())


def petscrc_files(argv, environ):
    """The options files PETSc reads unasked, when they exist (~/.petscrc, .petscrc,
    petscrc in the working folder), unless -skip_petscrc is given."""
    given = argv[1:] + environ.get("PETSC_OPTIONS", "").split()
    if any(token.lower() == "-skip_petscrc" for token in given):
        return []
    return [path for path in (os.path.expanduser("~/.petscrc"), ".petscrc", "petscrc")
            if os.path.isfile(path)]


def expanded(path):
    """``path`` with the ${NAME} PETSc replaces (environment variables and its own
    names), or None when one of them is unknown here (the path is then left to PETSc)."""
    unknown = []

    def replace(match):
        name = match.group(1)
        if name in PETSC_PATH_NAMES:
            return PETSC_PATH_NAMES[name]()
        if name in os.environ:
            return os.environ[name]
        unknown.append(name)
        return match.group(0)
    result = re.sub(r"\$\{([^}]*)\}", replace, path)
    return None if unknown else result


def nested_files(path, text):
    """(line number, path) of the -options_file lines of options file ``path`` with
    contents ``text``, as PETSc reads a line: '#' starts a comment, the first word is the
    option and the second its value; raises OptionsFileError for one without a path."""
    nested = []
    for number, line in enumerate(text.splitlines(), 1):
        words = line.split("#", 1)[0].split()
        if words and is_options_file(words[0]):
            if len(words) < 2:
                raise OptionsFileError(f"{path} line {number}: {words[0]} needs the path of "
                                       "an options file after it")
            nested.append((number, words[1]))
    return nested


def read_options_file(path, reference, nested):
    """The text of options file ``path`` (``reference``: how it was named, for the
    message; ``nested``: named in another options file), after the checks PETSc would
    otherwise fail on without a clear message."""
    problem = file_problem(path)            # the check of every input file
    if problem.startswith("is a folder"):
        raise OptionsFileError(f"{reference}: is a folder, not a scene file")
    if problem.startswith("not a regular file"):
        raise OptionsFileError(
            f"{reference}: not a regular file (a pipe such as <(...), or a device): "
            "petsc_rod reads an options file before PETSc reads it again, which a pipe "
            "does not allow; write the options to a file and give its path")
    if problem == "no such file":
        raise OptionsFileError(f"{reference}: no such file" if nested else
                               f"{reference}: no such scene file; the scenes are in "
                               "options/ (e.g. options/paper.opts)")
    if problem:
        raise OptionsFileError(f"{reference}: {problem}")
    if os.stat(path).st_size > tables.MAX_TABLE_BYTES:
        raise OptionsFileError(f"{reference}: is {os.stat(path).st_size / 2**20:.3g} MiB, "
                               f"above the {tables.MAX_TABLE_BYTES / 2**20:.3g} MiB an input "
                               "file may hold; is it the right file?")
    try:
        with open(path, "rb") as scene:
            data = scene.read()
    except OSError as error:
        raise OptionsFileError(f"{reference}: cannot be read ({error.strerror})") from None
    if data.startswith(BOM):
        raise OptionsFileError(
            f"{reference}: starts with a UTF-8 byte-order mark (an invisible character "
            "some editors write), which PETSc would read as part of the first option; "
            "save the file as UTF-8 without a byte-order mark")
    return data.decode("utf-8", errors="replace")


def check_options_file(path, reference, open_files, require_options=True):
    """Check ``path`` and, depth first, the options files it includes: each must exist
    and be a regular file that PETSc can read, none may include itself through any chain
    of -options_file lines (PETSc would recurse until the stack overflows), and a scene
    file given by the user must hold an option. ``open_files``: the real paths of the
    files that include this one, outermost first."""
    text = read_options_file(path, reference, bool(open_files))
    real = os.path.realpath(path)
    if require_options and not any(line.split("#", 1)[0].strip()
                                   for line in text.splitlines()):
        raise OptionsFileError(f"{reference}: holds no option (empty, or only comments); a "
                               "scene file has one '-name value' per line (options/paper.opts)")
    chain = open_files + [real]
    for number, nested in nested_files(path, text):
        target = expanded(nested)
        if target is None:
            continue
        if os.path.realpath(target) in chain:
            loop = " -> ".join(chain[chain.index(os.path.realpath(target)):]
                               + [os.path.realpath(target)])
            raise OptionsFileError(f"{path} line {number}: -options_file {nested} makes the "
                                   f"options files include themselves ({loop}); remove "
                                   "that line")
        check_options_file(target, f"-options_file {nested} (in {path} line {number})",
                           chain, require_options=False)


def options_file_error(argv, environ=None):
    """Why the options files of command line ``argv`` (and of PETSC_OPTIONS and the
    petscrc files PETSc reads unasked) cannot be read ('' when they can): an
    -options_file without a path; a file missing, unreadable, not a regular file,
    starting with a UTF-8 byte-order mark, or one given by the user with no option in
    it (PETSc would read it as empty and run the default scene); a missing file that one
    of them includes; a file that includes itself, directly or through others."""
    environ = os.environ if environ is None else environ
    try:
        for path in options_files(argv):
            check_options_file(path, f"-options_file {path}", [])
    except OptionsFileError as error:
        return str(error)
    try:
        for path in environment_files(environ):
            check_options_file(path, f"-options_file {path}", [])
    except OptionsFileError as error:
        return f"PETSC_OPTIONS: {error}"
    try:
        for path in petscrc_files(argv, environ):
            check_options_file(path, path, [], require_options=False)
    except OptionsFileError as error:
        return f"{error} (PETSc reads {path} unasked; -skip_petscrc skips it)"
    return ""


def every_options_file(argv, environ=None):
    """The paths of the options files PETSc reads for command line ``argv`` (those of
    the command line, of PETSC_OPTIONS, the petscrc files, and those they include), each
    once; a file that cannot be read is left out (options_file_error says why)."""
    environ = os.environ if environ is None else environ
    found = []

    def visit(path):
        if path is None or not os.path.isfile(path) or any(
                os.path.samefile(path, seen) for seen in found):
            return
        found.append(path)
        try:
            with open(path, encoding="utf-8", errors="replace") as handle:
                nested = nested_files(path, handle.read())
        except (OSError, OptionsFileError):
            return
        for _, name in nested:
            visit(expanded(name))

    try:
        tops = (options_files(argv) + environment_files(environ)
                + petscrc_files(argv, environ))
    except OptionsFileError:
        return found
    for path in tops:
        visit(path)
    return found
