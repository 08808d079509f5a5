#!/usr/bin/env python3
"""eigenfit's sparse solver against scipy's eigsh on the same Matrix Market files, in one run.

For each size, the stiffened plate of scripts/plate_matrices.py is generated into a temporary
folder (never committed), then each side runs in its own process:

- scipy:    mmread of every file, K = K0 + Σ p_i K_i, eigsh(K, 10, M, sigma=0) (ARPACK
            shift-invert on SuperLU), and the sensitivities dλ/dp_i = φᵀK_iφ;
- eigenfit: the `sparse_bench` example (MatricesModel::from_toml_file, assemble, the sparse
            solver's lowest 10 modes with their Sturm check, then modes + sensitivities through
            Sensitivities::compute, as `simulate` and every update iteration do).

Reported: CPU seconds (and wall seconds) for reading and for the solve with sensitivities, the
peak resident memory of each process (VmHWM), and the largest relative difference of the 10
frequencies. CPU time is the comparison: on a shared machine wall time measures the neighbours.
Both sides run single-threaded (OPENBLAS/OMP/MKL threads set to 1 for scipy; eigenfit's faer
factorisation runs sequentially).

    cargo build --release -p eigenfit-matrices --example sparse_bench
    nice -n 10 /work/venvs/h17/bin/python scripts/bench_sparse.py --dofs 10000,100000
    # against CHOLMOD + ARPACK too (pip install "scikit-sparse<0.5": Debian 12's SuiteSparse 5)
    python scripts/bench_sparse.py --dofs 100000 --peers superlu,cholmod
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def peak_kb():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1])
    return 0


def scipy_worker(folder, modes, peer="superlu"):
    """Runs in a child process: the scipy side on one model folder, one JSON line out. `peer`:
    `superlu` — eigsh's own shift-invert (SuperLU of K); `cholmod` — eigsh (ARPACK) with
    OPinv = CHOLMOD's Cholesky of K (scikit-sparse; supernodal, its own choice of ordering)."""
    import tomllib

    import numpy as np
    import scipy.io
    import scipy.sparse.linalg as sla

    with open(os.path.join(folder, "model.toml"), "rb") as f:
        spec = tomllib.load(f)
    t, c = time.perf_counter(), time.process_time()
    read = lambda name: scipy.io.mmread(os.path.join(folder, name)).tocsc()  # noqa: E731
    K0, M = read(spec["stiffness"]), read(spec["mass"])
    Ks = [read(p["stiffness"]) for p in spec["parameter"]]
    load_s, load_cpu_s = time.perf_counter() - t, time.process_time() - c
    p = [q["nominal"] for q in spec["parameter"]]
    t = time.perf_counter()
    K = (K0 + sum(pi * Ki for pi, Ki in zip(p, Ks))).tocsc()
    assemble_s = time.perf_counter() - t
    t, c = time.perf_counter(), time.process_time()
    if peer == "cholmod":
        from sksparse.cholmod import cholesky

        factor = cholesky(K)
        op = sla.LinearOperator(K.shape, matvec=lambda x: factor(x), dtype=float)
        lam, phi = sla.eigsh(K, modes, M, sigma=0, which="LM", OPinv=op)
    else:
        lam, phi = sla.eigsh(K, modes, M, sigma=0, which="LM")
    order = np.argsort(lam)
    lam, phi = lam[order], phi[:, order]
    modes_s = time.perf_counter() - t
    dlam = [[float(phi[:, k] @ (Ki @ phi[:, k])) for k in range(modes)] for Ki in Ks]
    with_sens_s, with_sens_cpu_s = time.perf_counter() - t, time.process_time() - c
    f = np.sqrt(np.maximum(lam, 0)) / (2 * np.pi)
    print(json.dumps({"load_s": load_s, "load_cpu_s": load_cpu_s, "modes_and_sensitivities_cpu_s": with_sens_cpu_s, "assemble_s": assemble_s, "modes_s": modes_s,
                      "modes_and_sensitivities_s": with_sens_s, "peak_rss_kb": peak_kb(),
                      "frequencies_hz": f.tolist(), "dlambda": dlam}))


SINGLE_THREAD = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


def run_json(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=SINGLE_THREAD).stdout
    return json.loads(out.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dofs", default="10000,100000", help="comma-separated sizes")
    ap.add_argument("--modes", type=int, default=10)
    ap.add_argument("--zones", default="2x3")
    ap.add_argument("--bench", default=os.path.join(ROOT, "target/release/examples/sparse_bench"))
    ap.add_argument("--peers", default="superlu",
                    help="comma-separated: superlu (scipy eigsh shift-invert), cholmod (ARPACK on CHOLMOD, scikit-sparse)")
    ap.add_argument("--scipy-worker", help=argparse.SUPPRESS)
    ap.add_argument("--peer", default="superlu", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.scipy_worker:
        return scipy_worker(args.scipy_worker, args.modes, args.peer)
    rows = []
    for dofs in (int(v) for v in args.dofs.split(",")):
        with tempfile.TemporaryDirectory(prefix="eigenfit-plate-") as folder:
            subprocess.run([sys.executable, os.path.join(HERE, "plate_matrices.py"), "--dofs", str(dofs),
                            "--zones", args.zones, "--out", folder], check=True, capture_output=True)
            ef = run_json([args.bench, os.path.join(folder, "model.toml"), str(args.modes)])
            for peer in args.peers.split(","):
                sp = run_json([sys.executable, __file__, "--scipy-worker", folder, "--modes", str(args.modes),
                               "--peer", peer])
                diff = max(abs(a / b - 1) for a, b in zip(ef["frequencies_hz"], sp["frequencies_hz"]))
                row = {"dofs": ef["dofs"], "nnz_upper": ef["nnz"], "peer": peer, "scipy": sp, "eigenfit": ef,
                       "max_rel_diff": diff}
                rows.append(row)
                print(f"{ef['dofs']:>8} DOFs  nnz {ef['nnz']:>9}  CPU seconds (wall in brackets): "
                      f"{peer}: read {sp['load_cpu_s']:.2f} ({sp['load_s']:.2f}), "
                      f"modes+sens {sp['modes_and_sensitivities_cpu_s']:.3f} ({sp['modes_and_sensitivities_s']:.3f}), "
                      f"peak {sp['peak_rss_kb'] / 1024:.0f} MB | "
                      f"eigenfit: read {ef['load_cpu_s']:.2f} ({ef['load_s']:.2f}), "
                      f"modes+sens {ef['modes_and_sensitivities_cpu_s']:.3f} ({ef['modes_and_sensitivities_s']:.3f}), "
                      f"warm modes {ef['warm_modes_cpu_s']:.3f}, peak {ef['peak_rss_kb'] / 1024:.0f} MB | "
                      f"CPU speed-up {sp['modes_and_sensitivities_cpu_s'] / ef['modes_and_sensitivities_cpu_s']:.2f}×, "
                      f"max rel. freq. diff {diff:.1e}", flush=True)
    json.dump(rows, sys.stderr)


if __name__ == "__main__":
    main()
