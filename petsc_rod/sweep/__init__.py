"""Load-case sweeps: one command runs a set of cases that differ in any -rod_* options,
each in the same process on the ranks given, warm-started from the nearest converged
case, and writes one result file per case and a summary table (docs/sweeps.md)."""
