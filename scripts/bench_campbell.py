"""Campbell diagram timing: ROSS `run_campbell` against `eigenfit campbell`, same rotor file,
same speeds (50, linear 0-12000 rpm), 6 modes, same machine, after a warm-up; BENCH_REPEATS=N
runs N pairs (ROSS then eigenfit, back to back) and prints each pair's wall and CPU times and the
median of the pairs' wall-clock ratios.

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

REPEATS = int(os.environ.get("BENCH_REPEATS", "1"))

speeds = RPM * np.pi / 30
# Warm-up (imports, compiled code) on a rotor of its own: ROSS caches `run_modal` per rotor and
# speed (methodtools' lru_cache), so every timed run below loads a fresh rotor, with nothing cached.
rs.Rotor.load(FILE).run_campbell(speeds[:2], frequencies=6)
cmd = [EIGENFIT, "campbell", "--model", str(FILE), "--speeds", "0:12000:50", "--modes", "6", "--json"]
subprocess.run(cmd, check=True, capture_output=True)  # warm-up (page cache)


def children_cpu():
    t = os.times()
    return t.children_user + t.children_system


ratios = []
for rep in range(REPEATS):
    # One pair: ROSS then eigenfit, back to back, wall and CPU time of each.
    rotor = rs.Rotor.load(FILE)
    c0, t0 = time.process_time(), time.perf_counter()
    camp = rotor.run_campbell(speeds, frequencies=6)
    t_ross, c_ross = time.perf_counter() - t0, time.process_time() - c0
    k0, t0 = children_cpu(), time.perf_counter()
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    t_eig, c_eig = time.perf_counter() - t0, children_cpu() - k0
    ratios.append(t_ross / t_eig)
    print(
        f"ROSS run_campbell: {t_ross:.3f} s ({c_ross:.3f} s CPU); eigenfit campbell: {t_eig:.3f} s "
        f"({c_eig:.3f} s CPU); ratio {t_ross / t_eig:.1f}x (CPU {c_ross / max(c_eig, 1e-9):.1f}x)"
    )
if REPEATS > 1:
    print(f"median ratio of {REPEATS} pairs: {np.median(ratios):.1f}x (min {min(ratios):.1f}x, max {max(ratios):.1f}x)")
ours = np.array(json.loads(out)["frequencies_hz"])

wd = camp.wd / (2 * np.pi)  # (speeds, modes), tracked order
diffs = []
for k in range(len(RPM)):
    ross_sorted = np.sort(wd[k])
    # Nearest eigenfit frequency for each ROSS one (ROSS's list may hold non-lateral modes).
    diffs += [np.min(np.abs(ours[k] - f)) / f for f in ross_sorted if f > 0]
print(f"median / max relative distance of ROSS's frequencies to eigenfit's: {np.median(diffs):.2e} / {np.max(diffs):.2e}")
