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

cargo test --workspace --all-features
