"""Checks that `eigenfit estimate --write-model` writes a file ROSS 3 loads, with the estimated
tables: runs the eigenfit binary on the PCHIP rotor's start file and run-up (from
scripts/ross3_reference.py), loads the written file with ROSS 3's `Rotor.load`, and compares ROSS 3's
run_modal on it with the true rotor's at the run-up speeds.

    cargo build -p eigenfit-cli
    /work/venvs/ross3/bin/python scripts/ross3_write_model.py

Writes crates/eigenfit-rotordynamics/tests/data/ross3/write_model_check.json (the numbers it
measured; the CLI test checks the same file with eigenfit alone).
"""

import json
import pathlib
import subprocess
import tempfile
import warnings

import numpy as np
import ross as rs

warnings.filterwarnings("ignore")
ROOT = pathlib.Path(__file__).resolve().parent.parent
DATA = ROOT / "crates/eigenfit-rotordynamics/tests/data/ross3"
EIGENFIT = ROOT / "target/debug/eigenfit"
RPM = np.pi / 30.0


def lateral_hz(rotor, rpm):
    m = rotor.run_modal(speed=rpm * RPM, num_modes=40, sparse=False)
    out = [m.wd[i] / (2 * np.pi) for i in np.argsort(m.wd) if m.shapes[i].mode_type == "Lateral" and m.wd[i] > 0]
    return out[:4]


def main():
    result = {"ross_version": rs.__version__, "files": {}}
    with tempfile.TemporaryDirectory() as tmp:
        for name in ["out.toml", "out.json"]:
            out = pathlib.Path(tmp) / name
            run = subprocess.run(
                [str(EIGENFIT), "estimate", "--model", str(DATA / "pchip_speed_start.toml"),
                 "--measured", str(DATA / "pchip_speed_runup.csv"), "--write-model", str(out), "--json"],
                capture_output=True, text=True,
            )
            assert run.returncode == 0, run.stderr
            report = json.loads(run.stdout)
            written = rs.Rotor.load(out)  # ROSS 3 loads it
            version = (json.loads(out.read_text()) if name.endswith(".json") else __import__("toml").loads(out.read_text()))["ross_version"]
            truth = rs.Rotor.load(DATA / "pchip_speed.toml")
            worst = 0.0
            for rpm in range(2000, 9001, 1000):
                a, b = lateral_hz(written, rpm), lateral_hz(truth, rpm)
                worst = max(worst, max(abs(x - y) / y for x, y in zip(a, b)))
            result["files"][name] = {
                "loaded_by_ross": True,
                "ross_version_written": version,
                "eigenfit_scales": report["scales"],
                "worst_relative_frequency_difference_to_truth": worst,
            }
            print(name, result["files"][name])
    (DATA / "write_model_check.json").write_text(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
