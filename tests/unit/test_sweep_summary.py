"""The sweep's summary files (sweep/summary.py; no PETSc): a case value that a
spreadsheet would run as a formula is written as text, one that holds HTML is shown, not
run, in summary.md, and numbers stay as they are."""

import csv

from petsc_rod.sweep import summary

# Values a hostile case file could give (each refused by petsc_rod as that case's bad
# input, but shown in the table all the same).
HOSTILE = ['=HYPERLINK("http://x","y")', "+1+cmd|' /C calc'!A0", "-2+3", "@SUM(A1)",
           "\t=1", "\r=1", "<script>alert(1)</script>", "a|b&c"]
SAFE = ["-1157,0,1000", "1e-3", "+5", "plain"]


def records():
    return [{"name": f"c{k}", "options": {"rod_end_position": value}, "code": 2,
             "start": "", "file": None} for k, value in enumerate(HOSTILE + SAFE)]


def test_formulas_are_written_as_text_in_the_csv(tmp_path):
    header, rows = summary.table(records(), ["rod_end_position"])
    path = tmp_path / "summary.csv"
    summary.write_csv(path, header, rows)
    with open(path, newline="", encoding="utf-8") as f:
        read = list(csv.reader(f))
    assert read[0] == header
    cells = [row[1] for row in read[1:]]
    for value, written in zip(HOSTILE[:6], cells):
        assert written == "'" + value, (value, written)
    assert cells[6:8] == HOSTILE[6:8]           # no formula start: as given
    assert cells[8:] == SAFE                    # numbers and plain text unchanged
    assert not list(tmp_path.glob("*.partial"))


def test_html_is_escaped_in_the_markdown(tmp_path):
    header, rows = summary.table(records(), ["rod_end_position"])
    path = tmp_path / "summary.md"
    summary.write_markdown(path, header, rows, title="Sweep <i>x</i>")
    text = path.read_text(encoding="utf-8")
    assert "<" not in text and ">" not in text
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in text
    assert "a\\|b&amp;c" in text
    # one line per row: a tab or a line break in a value does not break the table
    assert text.count("\n| ") == 1 + len(HOSTILE + SAFE)
    assert "# Sweep &lt;i&gt;x&lt;/i&gt;" in text
