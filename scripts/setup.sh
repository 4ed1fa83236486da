#!/usr/bin/env bash
# Set up petsc_rod on Debian 12: Debian's PETSc/petsc4py, SLEPc/slepc4py (the modal
# analysis), mpi4py, h5py (MPI), matplotlib, scipy, pytest, setuptools and wheel (to build
# the wheel offline) from apt, when missing, and a virtual environment .venv that sees them.
# EXTRA_PACKAGES adds Debian packages (test.sh: chromium, for the report page's browser
# test). Safe to run again: it only does what is missing. Sourced by run.sh and test.sh.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
PACKAGES="python3-petsc4py python3-mpi4py python3-h5py-mpi python3-matplotlib python3-scipy \
python3-pytest python3-setuptools python3-wheel python3-venv openmpi-bin python3-slepc4py \
${EXTRA_PACKAGES:-}"

missing=""
for package in $PACKAGES; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" \
    || missing="$missing $package"
done
if [ -n "$missing" ]; then
  echo "setup: installing with apt:$missing"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing >/dev/null
fi

PETSC_ARCH_DIR="$(ls -d /usr/lib/petscdir/petsc3.*/*-real 2>/dev/null | sort -V | tail -n 1)"
if [ -z "$PETSC_ARCH_DIR" ]; then
  echo "setup: error: Debian's PETSc (real) is not under /usr/lib/petscdir; install python3-petsc4py" >&2
  exit 1
fi

SLEPC_ARCH_DIR="$(ls -d /usr/lib/slepcdir/slepc3.*/*-real 2>/dev/null | sort -V | tail -n 1)"
if [ -z "$SLEPC_ARCH_DIR" ]; then
  echo "setup: error: Debian's SLEPc (real) is not under /usr/lib/slepcdir; install python3-slepc4py" >&2
  exit 1
fi

VENV="$ROOT/.venv"
if [ ! -x "$VENV/bin/python" ]; then
  echo "setup: creating $VENV (Debian's /usr/bin/python3 with system site packages)"
  /usr/bin/python3 -m venv --system-site-packages "$VENV"
fi
SITE="$("$VENV/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')"
# petsc4py lives under PETSC_DIR, slepc4py under SLEPC_DIR, and this repository is the
# package's home.
printf '%s\n%s\n%s\n' "$PETSC_ARCH_DIR/lib/python3/dist-packages" \
  "$SLEPC_ARCH_DIR/lib/python3/dist-packages" "$ROOT" > "$SITE/petsc_rod.pth"
if ! grep -q "SLEPC_DIR" "$VENV/bin/activate"; then
  cat >> "$VENV/bin/activate" <<ACTIVATE
# petsc_rod environment: Debian's PETSc, and OpenMPI allowed as root and on few cores
export PETSC_DIR="$PETSC_ARCH_DIR" SLEPC_DIR="$SLEPC_ARCH_DIR"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1
ACTIVATE
fi
# The package byte-compiled: Python does it on a first import unless PYTHONDONTWRITEBYTECODE
# is set, and then compiles every module again at each start (docs/performance.md, "Where
# the remaining time goes"). Only what changed is compiled again; a read-only checkout
# just starts slower.
"$VENV/bin/python" -m compileall -q "$ROOT/petsc_rod" >/dev/null 2>&1 || true
# shellcheck disable=SC1091
source "$VENV/bin/activate"
