#!/usr/bin/env bash
# The project's whole test run, from a fresh machine: installs what the tests need when it is
# missing (Debian's OpenBLAS for the LAPACK backend), then runs every test suite.
# README's test command and .ci/run both call this script, so they cannot drift apart.
set -euo pipefail
cd "$(dirname "$0")/.."

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
if ! dpkg -s libopenblas-dev >/dev/null 2>&1; then
  echo "scripts/test.sh: installing libopenblas-dev (the LAPACK backend links it)" >&2
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq libopenblas-dev
fi

# Debian's Chromium: the HTML reports (`--report`) are rendered in a headless browser by
# crates/eigenfit-cli/tests/report.rs, which fails without it (EIGENFIT_SKIP_BROWSER=1 skips).
if ! command -v chromium >/dev/null 2>&1; then
  echo "scripts/test.sh: installing chromium (the HTML reports are checked in a headless browser)" >&2
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq chromium
fi

cargo test --workspace --all-features --exclude eigenfit-python

# The Python package (python/), as a user installs it: `pip install ./python` into a fresh virtual
# environment (pip builds the wheel with maturin), then its pytest suite. EIGENFIT_BIN is the
# binary cargo built above, which the tests compare the package's results with.
if ! python3 -c 'import ensurepip, venv' >/dev/null 2>&1; then
  echo "scripts/test.sh: installing python3-venv (the Python package is tested in a virtual environment)" >&2
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq python3-venv
fi
py_venv="$(mktemp -d)/venv"
trap 'rm -rf "$(dirname "$py_venv")"' EXIT
python3 -m venv "$py_venv"
# The wheel is built in cargo's dev profile into the target directory the tests above just built
# (MATURIN_PEP517_ARGS, maturin's pass-through to its PEP 517 build): most of it is already
# compiled there (the workspace crates and a few dependencies whose features differ are rebuilt:
# 262 CPU-s here), where the default release build compiles every crate again, dependencies
# included, at opt-level 3. `pip install ./python` for users is unchanged (release).
CARGO_TARGET_DIR="$PWD/target" MATURIN_PEP517_ARGS="--profile dev" \
  "$py_venv/bin/python" -m pip install --quiet --disable-pip-version-check ./python pytest numpy scipy dask distributed
py_status=0
EIGENFIT_BIN="$PWD/target/debug/eigenfit" "$py_venv/bin/python" -m pytest python/tests -p no:cacheprovider -q \
  || py_status=$?
if [ "$py_status" -eq 5 ]; then
  echo "scripts/test.sh: pytest collected no tests in python/tests: the Python suite is missing" >&2
  exit 1
fi
exit "$py_status"
