"""Campbell diagram timing: ROSS `run_campbell` against `eigenfit campbell`, same rotor file,
same speeds (50, linear 0-12000 rpm), 6 modes, same machine, one run each after a warm-up.

    /work/venvs/rotordyn/bin/python scripts/bench_campbell.py [path/to/eigenfit]
    # ROSS 3 on the compressor ROSS 3 saved:
    BENCH_FILE=crates/eigenfit-rotordynamics/tests/data/ross3/compressor.toml \
        OPENBLAS_NUM_THREADS=1 /work/venvs/ross3/bin/python scripts/bench_campbell.py [path/to/eigenfit]
    # eigenfit solves the speeds in parallel (rayon); RAYON_NUM_THREADS=1 for one thread.

Prints both wall times, their ratio, and how far eigenfit's frequencies are from ROSS's
(ROSS's lateral modes, sorted per speed; ROSS also has axial/torsional DOFs whose modes are
dropped, and fits bearing tables with a smoothing spline, see docs/rotordynamics.md).
"""

import json
import pathlib
import subprocess
import sys
import time
import warnings

import numpy as np
import ross as rs

warnings.filterwarnings("ignore")
ROOT = pathlib.Path(__file__).resolve().parent.parent
import os

FILE = ROOT / os.environ.get("BENCH_FILE", "crates/eigenfit-rotordynamics/tests/data/compressor.toml")
EIGENFIT = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "target/release/eigenfit")
RPM = np.linspace(0.0, 12000.0, 50)

rotor = rs.Rotor.load(FILE)
speeds = RPM * np.pi / 30
rotor.run_campbell(speeds[:2], frequencies=6)  # warm-up (imports, caches)
t0 = time.perf_counter()
camp = rotor.run_campbell(speeds, frequencies=6)
t_ross = time.perf_counter() - t0

cmd = [EIGENFIT, "campbell", "--model", str(FILE), "--speeds", "0:12000:50", "--modes", "6", "--json"]
subprocess.run(cmd, check=True, capture_output=True)  # warm-up (page cache)
t0 = time.perf_counter()
out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
t_eig = time.perf_counter() - t0
ours = np.array(json.loads(out)["frequencies_hz"])

print(f"ROSS run_campbell: {t_ross:.3f} s; eigenfit campbell: {t_eig:.3f} s; ratio {t_ross / t_eig:.1f}x")
wd = camp.wd / (2 * np.pi)  # (speeds, modes), tracked order
diffs = []
for k in range(len(RPM)):
    ross_sorted = np.sort(wd[k])
    # Nearest eigenfit frequency for each ROSS one (ROSS's list may hold non-lateral modes).
    diffs += [np.min(np.abs(ours[k] - f)) / f for f in ross_sorted if f > 0]
print(f"median / max relative distance of ROSS's frequencies to eigenfit's: {np.median(diffs):.2e} / {np.max(diffs):.2e}")
