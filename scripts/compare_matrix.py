"""Compare two runs of scripts/stability_matrix.py: every case's outcome, reason,
iterations, residual and error, by case name and ranks.

    python scripts/compare_matrix.py OLD/cases.csv NEW/cases.csv

Prints one line per case that differs (or is in one file only) with the columns that
differ; the wall time is not compared. Exit 0 when every case agrees, 1 otherwise.
"""

import argparse
import csv
import sys

IGNORED = {"wall_time"}


def read(path):
    """{(case, ranks): row} of a cases.csv."""
    with open(path, newline="") as handle:
        return {(row["case"], row["ranks"]): row for row in csv.DictReader(handle)}


def compare(old_path, new_path):
    """Lines saying how the cases of the two files differ (none when they agree)."""
    old, new = read(old_path), read(new_path)
    lines = []
    for key in list(old) + [key for key in new if key not in old]:
        name = f"{key[0]} ({key[1]} rank(s))"
        if key not in new or key not in old:
            lines.append(f"{name}: only in {old_path if key in old else new_path}")
            continue
        changed = [f"{column} {old[key].get(column)!r} -> {new[key].get(column)!r}"
                   for column in sorted(set(old[key]) | set(new[key]))
                   if column not in IGNORED and old[key].get(column) != new[key].get(column)]
        if changed:
            lines.append(f"{name}: " + "; ".join(changed))
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old")
    parser.add_argument("new")
    args = parser.parse_args(argv)
    lines = compare(args.old, args.new)
    for line in lines:
        print(line)
    print(f"{args.old} vs {args.new}: "
          + (f"{len(lines)} case(s) differ" if lines else "every case agrees (wall time aside)"))
    return 1 if lines else 0


if __name__ == "__main__":
    sys.exit(main())
