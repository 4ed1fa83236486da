#!/usr/bin/env bash
# The whole test suite: set up if needed, then every test serially, then the same files
# on 2 MPI ranks (rank 0 reports; rank 1's report goes to tests-rank1.log).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# Debian's headless Chromium renders the report page (tests/system/test_report_browser.py)
EXTRA_PACKAGES="chromium" source "$ROOT/scripts/setup.sh"
cd "$ROOT"
echo "== serial =="
python -m pytest -p no:cacheprovider --color=no "$@" tests
echo "== mpiexec -n 2 =="
status=0
mpiexec -n 1 python -m pytest -p no:cacheprovider --color=no "$@" tests \
  : -n 1 bash -c 'exec python -m pytest -p no:cacheprovider --color=no -q "$@" tests > tests-rank1.log 2>&1' \
    rank1 "$@" || status=$?
if [ "$status" -ne 0 ]; then
  echo "== rank 1 report (tests-rank1.log) =="
  tail -n 40 tests-rank1.log
fi
exit "$status"
