"""Tables of named columns read from text files (line types, attachments): a header row
naming the columns, then one row per entry; whitespace or commas separate the values,
'#' starts a comment; '-' leaves an optional column's value blank. Every failure is one RodInputError naming the option and the file.
"""

import numpy as np

from petsc_rod.errors import RodInputError

# A value left blank in an optional column (NaN in the table): a row that does not use it.
BLANK = "-"


def read_text(path, option):
    """The text of the file ``path`` given to ``option`` (RodInputError if it cannot be
    read)."""
    try:
        with open(path, encoding="utf-8", errors="replace") as handle:
            return handle.read()
    except FileNotFoundError:
        raise RodInputError(f"{option} {path}: no such file") from None
    except OSError as error:
        raise RodInputError(f"{option} {path}: cannot be read ({error.strerror})") from None


def numbered_rows(path, option):
    """[(line number from 1, words)] of the non-empty rows of the file ``path`` given to
    ``option``: '#' starts a comment, whitespace or commas separate the words."""
    lines = read_text(path, option).splitlines()
    rows = [(k + 1, line.split("#", 1)[0].replace(",", " ").split())
            for k, line in enumerate(lines)]
    return [(k, row) for k, row in rows if row]


def read_table(path, option, required, optional=(), text=("name",), content=None):
    """{column: values} from the file ``path`` given to ``option`` (or its ``content``,
    already read: a result file's copy): float arrays (m,), or lists of str for the
    columns in ``text``. Every column of ``required`` must be in the header; a column
    outside ``required`` and ``optional`` is refused (a misspelt name would otherwise be
    ignored), as are a repeated column, a row of another length, a value that is not a
    number, and a table without rows."""
    def refuse(what):
        raise RodInputError(f"{option} {path}: {what}")

    lines = (read_text(path, option) if content is None else content).splitlines()
    rows = [line.split("#", 1)[0].replace(",", " ").split() for line in lines]
    rows = [row for row in rows if row]
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
    for number, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            refuse(f"row {number} has {len(row)} values for {len(header)} columns")
        for name, value in zip(header, row):
            columns[name].append(value)
    table = {}
    for name, values in columns.items():
        if name in text:
            table[name] = values
            continue
        blank = np.array([v == BLANK for v in values])
        if np.any(blank) and name in required:
            refuse(f"column {name} is required in every row; row "
                   f"{int(np.flatnonzero(blank)[0]) + 2} leaves it blank ('{BLANK}')")
        try:
            table[name] = np.array([np.nan if v == BLANK else float(v) for v in values])
        except ValueError:
            bad = next(v for v in values if v != BLANK and not _is_number(v))
            refuse(f"column {name}: '{bad}' is not a number")
        if np.any(np.isnan(table[name]) & ~blank):
            refuse(f"column {name} holds a value that is not a number")
    return table


def _is_number(text):
    try:
        float(text)
    except ValueError:
        return False
    return True
