"""Tables of named columns read from text files (line types, attachments): a header row
naming the columns, then one row per entry; whitespace or commas separate the values,
'#' starts a comment; '-' leaves an optional column's value blank. Every failure is one RodInputError naming the option and the file.
"""

import os
import stat

import numpy as np

from petsc_rod.errors import RodInputError

# A value left blank in an optional column (NaN in the table): a row that does not use it.
BLANK = "-"
# The largest input table read, bytes: a seabed grid of a million points is about 30 MiB;
# a file far larger is not a table (and is read whole on every rank).
MAX_TABLE_BYTES = 256 * 2**20


def file_problem(path):
    """Why ``path`` cannot be read as an input file, '' when it can: missing, a folder,
    or not a regular file. A FIFO blocks its reader until a writer comes (for ever, and
    deaf to SIGTERM while it waits in open) and a device such as /dev/zero never ends, so
    every input file is checked with os.stat (through links) before it is opened: the
    tables, the restart file, a sweep's cases, the options files."""
    try:
        info = os.stat(path)
    except FileNotFoundError:
        return "no such file"
    except OSError as error:
        return f"cannot be read ({error.strerror})"
    if stat.S_ISDIR(info.st_mode):
        return "is a folder, not a file"
    if not stat.S_ISREG(info.st_mode):
        return ("not a regular file (a pipe such as <(...), a FIFO or a device): "
                "petsc_rod reads only files that end; write it to a file and give its path")
    return ""


def check_input_file(path, option, largest=None):
    """Refuse (RodInputError naming ``option``) an input file ``path`` that file_problem
    refuses, or one above ``largest`` bytes (None: MAX_TABLE_BYTES; inf for a file read
    in slices, a restart file)."""
    largest = MAX_TABLE_BYTES if largest is None else largest
    problem = file_problem(path)
    if not problem and os.stat(path).st_size > largest:
        problem = (f"is {os.stat(path).st_size / 2**20:.3g} MiB, above the "
                   f"{largest / 2**20:.3g} MiB an input table may hold; is it the right file?")
    if problem:
        raise RodInputError(f"{option} {path}: {problem}")


def read_text(path, option):
    """The text of the file ``path`` given to ``option`` (RodInputError if it cannot be
    read, is not a regular file or is larger than MAX_TABLE_BYTES)."""
    check_input_file(path, option)
    try:
        with open(path, encoding="utf-8", errors="replace") as handle:
            text = handle.read(MAX_TABLE_BYTES + 1)       # a file that grew since
    except OSError as error:
        raise RodInputError(f"{option} {path}: cannot be read ({error.strerror})") from None
    if len(text) > MAX_TABLE_BYTES:
        check_input_file(path, option)
    return text


def numbered_rows(path, option, content=None):
    """[(line number from 1, words)] of the non-empty rows of the file ``path`` given to
    ``option`` (or of its ``content``, already read): '#' starts a comment, whitespace
    or commas separate the words."""
    lines = (read_text(path, option) if content is None else content).splitlines()
    rows = [(k + 1, line.split("#", 1)[0].replace(",", " ").split())
            for k, line in enumerate(lines)]
    return [(k, row) for k, row in rows if row]


def read_table(path, option, required, optional=(), text=("name",), content=None):
    """{column: values} from the file ``path`` given to ``option`` (or its ``content``,
    already read: a result file's copy): float arrays (m,), or lists of str for the
    columns in ``text``. Every column of ``required`` must be in the header; a column
    outside ``required`` and ``optional`` is refused (a misspelt name would otherwise be
    ignored), as are a repeated column, a row of another length, a value that is not a
    number, and a table without rows; a row is named by its line in the file (comments
    and blank lines counted)."""
    def refuse(what):
        raise RodInputError(f"{option} {path}: {what}")

    numbered = numbered_rows(path, option, content)
    rows = [row for _, row in numbered]
    lines = [number for number, _ in numbered[1:]]      # of the rows after the header
    if not rows:
        refuse("is empty; give a header row naming the columns, then one row per entry")
    header = [name.lower() for name in rows[0]]
    known = list(required) + list(optional)
    for name in header:
        if name not in known:
            refuse(f"unknown column '{name}'; the columns are {', '.join(known)}")
    if len(set(header)) != len(header):
        refuse("a column is named twice in the header")
    missing = [name for name in required if name not in header]
    if missing:
        refuse(f"the header has no column {', '.join(missing)} (it names "
               f"{' '.join(header)}); the required columns are {', '.join(required)}")
    if len(rows) == 1:
        refuse("has a header but no rows")
    columns = {name: [] for name in header}
    for number, row in zip(lines, rows[1:]):
        if len(row) != len(header):
            refuse(f"line {number} has {len(row)} values for {len(header)} columns")
        for name, value in zip(header, row):
            columns[name].append(value)
    table = {}
    for name, values in columns.items():
        if name in text:
            table[name] = values
            continue
        blank = np.array([v == BLANK for v in values])
        if np.any(blank) and name in required:
            refuse(f"column {name} is required in every row; line "
                   f"{lines[int(np.flatnonzero(blank)[0])]} leaves it blank ('{BLANK}')")
        try:
            table[name] = np.array([np.nan if v == BLANK else float(v) for v in values])
        except ValueError:
            k = next(k for k, v in enumerate(values) if v != BLANK and not is_number(v))
            refuse(f"line {lines[k]}, column {name}: '{values[k]}' is not a number")
        if np.any(np.isnan(table[name]) & ~blank):
            refuse(f"column {name} holds a value that is not a number")
    return table


def is_number(text):
    """Whether ``text`` reads as a float."""
    try:
        float(text)
    except ValueError:
        return False
    return True
