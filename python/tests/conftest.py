"""Shared fixtures: the repository's example files and the `eigenfit` binary to compare against."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path
from typing import Any, Callable, Dict, List, Tuple

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"


def _find_binary() -> Path | None:
    """EIGENFIT_BIN (scripts/test.sh sets it to the binary cargo just built), else a cargo build
    in the checkout, else `eigenfit` on PATH."""
    env = os.environ.get("EIGENFIT_BIN")
    if env:
        path = Path(env)
        if not path.is_file():
            raise RuntimeError(f"EIGENFIT_BIN={env}: no such file")
        return path
    for profile in ("debug", "release"):
        path = REPO / "target" / profile / "eigenfit"
        if path.is_file():
            return path
    found = shutil.which("eigenfit")
    return Path(found) if found else None


@pytest.fixture(scope="session")
def examples() -> Path:
    return EXAMPLES


@pytest.fixture(scope="session")
def cli() -> Callable[[List[str]], Tuple[Dict[str, Any], int]]:
    """Runs the `eigenfit` binary with `--json`; returns its parsed stdout and exit code."""
    binary = _find_binary()
    if binary is None:
        pytest.skip("no eigenfit binary: build it with `cargo build -p eigenfit-cli` or set EIGENFIT_BIN")

    def run(args: List[str]) -> Tuple[Dict[str, Any], int]:
        done = subprocess.run(
            [str(binary), *args, "--json", "--quiet"], capture_output=True, text=True, cwd=REPO
        )
        assert done.returncode in (0, 3), (
            f"eigenfit {' '.join(args)} failed ({done.returncode}): {done.stderr}"
        )
        return json.loads(done.stdout), done.returncode

    return run
