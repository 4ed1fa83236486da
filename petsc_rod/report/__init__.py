"""The report: one self-contained HTML page from a result file or a sweep's folder
(docs/sweeps.md)."""
