#!/usr/bin/env bash
# Run every scene of options/ into a folder and compare each result file with a baseline's.
#
#   scripts/compare_scenes.sh OUT [BASELINE] [SCENE ...]
#
# Runs `python -m petsc_rod -options_file options/X.opts -rod_output OUT/X.h5` on 1 rank
# and on 2 ranks (OUT/X.np2.h5), one run at a time, each stopped after TIMEOUT seconds
# (default 300); OUT/runs.tsv gets a line per run: scene, ranks, exit code, wall time
# (s). With BASELINE (a folder made the same way, from the commit to compare with), each
# file is compared with BASELINE's by scripts/compare_results.py (RTOL, default 0: bit
# for bit) and each exit code with BASELINE/runs.tsv. SCENE names (e.g. twist) restrict
# the run to those scenes; RANKS="1" runs on one rank only.
# Exit 0 when every run's file and exit code match the baseline, 1 otherwise.
# The stability matrix is compared apart (it takes minutes, and writes its table into
# the document it is given):
#   python scripts/stability_matrix.py --out DIR --document COPY_OF_docs/stability.md
#   python scripts/compare_matrix.py BASELINE/matrix/cases.csv DIR/cases.csv
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [ $# -lt 1 ]; then
  sed -n '2,18p' "$0"; exit 2
fi
OUT="$(mkdir -p "$1" && cd "$1" && pwd)"; shift
BASELINE=""
if [ $# -ge 1 ]; then BASELINE="$(cd "$1" && pwd)"; shift; fi
source "$ROOT/scripts/setup.sh"
set +u
cd "$ROOT"
SCENES=("$@")
if [ ${#SCENES[@]} -eq 0 ]; then
  for file in options/*.opts; do SCENES+=("$(basename "$file" .opts)"); done
fi
RANKS="${RANKS:-1 2}"
TIMEOUT="${TIMEOUT:-300}"
RTOL="${RTOL:-0}"
: > "$OUT/runs.tsv"
failed=0
for scene in "${SCENES[@]}"; do
  for ranks in $RANKS; do
    if [ "$ranks" = 1 ]; then name="$scene.h5"; launcher=(python);
    else name="$scene.np$ranks.h5"; launcher=(mpiexec -n "$ranks" python); fi
    rm -f "$OUT/$name"
    start=$(date +%s.%N)
    code=0
    timeout "$TIMEOUT" "${launcher[@]}" -m petsc_rod -options_file "options/$scene.opts" \
      -rod_output "$OUT/$name" > "$OUT/$scene.np$ranks.log" 2>&1 || code=$?
    seconds=$(python -c "print(f'{$(date +%s.%N) - $start:.1f}')")
    printf '%s\t%s\t%s\t%s\n' "$scene" "$ranks" "$code" "$seconds" >> "$OUT/runs.tsv"
    echo "$scene on $ranks rank(s): exit $code in $seconds s"
    [ -n "$BASELINE" ] || continue
    expected=$(awk -v s="$scene" -v n="$ranks" '$1 == s && $2 == n {print $3}' \
               "$BASELINE/runs.tsv" 2>/dev/null || true)
    if [ -n "$expected" ] && [ "$expected" != "$code" ]; then
      echo "  exit code $code, the baseline's $expected"; failed=1
    fi
    if [ -f "$BASELINE/$name" ] || [ -f "$OUT/$name" ]; then
      python "$ROOT/scripts/compare_results.py" --rtol "$RTOL" "$BASELINE/$name" "$OUT/$name" \
        | sed 's/^/  /' || failed=1
    fi
  done
done
[ -z "$BASELINE" ] || echo "compare_scenes: $([ $failed = 0 ] && echo "every scene as the baseline" || echo "DIFFERENCES (above)")"
exit $failed
