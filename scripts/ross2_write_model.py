"""Checks that `eigenfit estimate --write-model` on a ROSS 2 rotor writes a file ROSS 2.3 loads, and
that ROSS 2.3 and eigenfit read the written file alike: runs the eigenfit binary on the ROSS 2
run-up start file, loads the output with ROSS 2.3's `Rotor.load`, and records ROSS 2.3's lateral
damped frequencies of the written rotor at the run-up speeds.

    cargo build -p eigenfit-cli
    python3 -m venv /work/venvs/ross2 && /work/venvs/ross2/bin/pip install "ross-rotordynamics==2.3.0" "plotly<6"
    /work/venvs/ross2/bin/python scripts/ross2_write_model.py

Writes into crates/eigenfit-rotordynamics/tests/data/: runup_written.toml (the file eigenfit wrote)
and runup_written_ross2.json (ROSS 2.3's frequencies of it); the CLI test
`ross2_reads_the_written_model_as_eigenfit_does` checks eigenfit's frequencies of the same file.
"""

import json
import pathlib
import shutil
import subprocess
import tempfile
import warnings

import numpy as np
import ross as rs

warnings.filterwarnings("ignore")
ROOT = pathlib.Path(__file__).resolve().parent.parent
DATA = ROOT / "crates/eigenfit-rotordynamics/tests/data"
EIGENFIT = ROOT / "target/debug/eigenfit"
SPEEDS_RPM = [1000.0, 2500.0, 4000.0, 5500.0, 7000.0, 8500.0]
MODES = 4


def lateral_hz(rotor, rpm):
    m = rotor.run_modal(speed=rpm * np.pi / 30.0, num_modes=4 * MODES + 8, sparse=False)
    out = [m.wd[i] / (2 * np.pi) for i in range(len(m.wd)) if m.shapes[i].mode_type == "Lateral" and m.wd[i] > 0]
    return sorted(out)[:MODES]


def main():
    with tempfile.TemporaryDirectory() as tmp:
        out = pathlib.Path(tmp) / "written.toml"
        run = subprocess.run(
            [str(EIGENFIT), "estimate", "--model", str(DATA / "runup_start.toml"),
             "--measured", str(DATA / "runup_truth.csv"), "--write-model", str(out), "--json"],
            capture_output=True, text=True,
        )
        assert run.returncode in (0, 3), run.stderr
        written = rs.Rotor.load(out)  # ROSS 2.3 loads it
        shutil.copy(out, DATA / "runup_written.toml")
    result = {
        "ross_version": rs.__version__,
        "written_by": "eigenfit estimate --model runup_start.toml --measured runup_truth.csv --write-model",
        "speeds_rpm": SPEEDS_RPM,
        "lateral_hz": [lateral_hz(written, rpm) for rpm in SPEEDS_RPM],
    }
    (DATA / "runup_written_ross2.json").write_text(json.dumps(result, indent=1) + "\n")
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
