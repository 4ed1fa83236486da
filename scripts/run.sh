#!/usr/bin/env bash
# The main job: set up if needed, then solve the default scene (the paper's benchmark)
# on 2 ranks. Extra arguments go to petsc_rod, e.g. scripts/run.sh -rod_al_monitor
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
source "$ROOT/scripts/setup.sh"
cd "$ROOT"
exec mpiexec -n 2 python -m petsc_rod -options_file options/paper.opts -rod_output paper.h5 "$@"
