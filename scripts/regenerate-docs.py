#!/usr/bin/env python3
"""Re-runs the commands whose output the docs quote, so every number in them is measured.

A quoted output is marked in the Markdown by a comment naming the command:

    <!-- regen: eigenfit compare ... | sed -n 1,14p -->
    ```
    (output, replaced)
    ```

or, for Markdown the command prints itself (tables):

    <!-- regen-md: cargo run --release -q --example paper_tables -->
    (output, replaced)
    <!-- end regen -->

Commands run with bash from the repository root, with target/release (the `eigenfit` binary)
first on PATH, or the folder EIGENFIT_BIN_DIR names (a debug build prints the same numbers).
`--cli-only` regenerates the `regen:` blocks only (the CLI's output, which the test
crates/eigenfit-cli/tests/docs_output.rs checks), not the `regen-md` ones (release-built examples,
peer scripts). Usage:
    cargo build --release -p eigenfit-cli && cargo build --release --examples && scripts/regenerate-docs.py README.md docs/*.md
"""
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.environ.get("EIGENFIT_BIN_DIR", os.path.join(ROOT, "target", "release"))
ENV = dict(os.environ, PATH=os.path.abspath(BIN) + os.pathsep + os.environ["PATH"])

CODE = re.compile(r"(<!-- regen: (.+?) -->\n```[^\n]*\n)(.*?)(```)", re.S)
MD = re.compile(r"(<!-- regen-md: (.+?) -->\n)(.*?)(<!-- end regen -->)", re.S)


def run(cmd: str) -> str:
    out = subprocess.run(["bash", "-c", cmd], cwd=ROOT, env=ENV, capture_output=True, text=True)
    if out.returncode not in (0, 3):
        sys.exit(f"`{cmd}` failed ({out.returncode}):\n{out.stderr}")
    return out.stdout if out.stdout.endswith("\n") else out.stdout + "\n"


cli_only = "--cli-only" in sys.argv[1:]
for path in (a for a in sys.argv[1:] if a != "--cli-only"):
    text = open(path, encoding="utf-8").read()
    new = CODE.sub(lambda m: m.group(1) + run(m.group(2)) + m.group(4), text)
    if not cli_only:
        new = MD.sub(lambda m: m.group(1) + run(m.group(2)) + m.group(4), new)
    if new != text:
        open(path, "w", encoding="utf-8").write(new)
        print(f"updated {path}")
