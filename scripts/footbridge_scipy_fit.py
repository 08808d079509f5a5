#!/usr/bin/env python3
"""An independent fit of the footbridge-like frame (issue 29, item 7a) by scipy, to check eigenfit's.

Builds the same matrices as `scripts/footbridge_frame.py` (its `build()`), reads the "measured"
data that script wrote (measured.csv, shapes.csv in --dir), and fits the 17 stiffness factors by
`scipy.optimize.least_squares` (trust-region reflective, bounds [0.1, 10] × nominal, in ln p as
eigenfit's log scale) on the residuals eigenfit's `estimate --shapes --shape-std 0.01` defines:

    frequency rows  ln(f_measured / f_model) / (std / f_measured)
    shape rows      (d/‖d‖ − s/‖s‖) / 0.01   (d turned so that dᵀs ≥ 0; 58 channels per mode)

with the model's modes from ARPACK's shift-invert `scipy.sparse.linalg.eigsh(K, M=M, sigma=0)` on
the full sparse pencil (M semi-definite: the massless rotations' eigenvalues are infinite, never
among the lowest), or with `--solver dense` from dense `scipy.linalg.eigh` on the static
condensation (10× slower) — no code shared with eigenfit — paired with the measured ones by MAC.

Each start is fitted with at most --max-nfev residual evaluations (the Jacobian's 17 differences
not counted by scipy): from eigenfit's estimate (--eigenfit FILE, its --json output), which checks
that eigenfit's point is a minimum scipy's own residuals agree with, and from the nominal values,
which checks that an independent optimiser reaches the same minimum. Prints for each start the χ²
reached, scipy's status (never claimed converged when the cap stopped it) and the factors beside
eigenfit's.

    /work/venvs/sci/bin/python scripts/footbridge_scipy_fit.py --dir /tmp/footbridge --eigenfit est.json
"""

import argparse
import csv
import json
import os
import sys
import time

import numpy as np
import scipy.optimize
import scipy.sparse as sp
import scipy.sparse.linalg as sla

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import footbridge_frame as fb  # noqa: E402

SHAPE_STD = 0.01
EXTRA_MODES = 3  # model modes beyond the measured ones that the MAC pairing may pick


def read_data(folder, channels_per_mode):
    freq, std = [], []
    with open(os.path.join(folder, "measured.csv")) as f:
        for row in csv.DictReader(line for line in f if not line.startswith("#")):
            freq.append(float(row["frequency_hz"]))
            std.append(float(row["std_hz"]))
    values = {}
    with open(os.path.join(folder, "shapes.csv")) as f:
        for row in csv.DictReader(f):
            values.setdefault(int(row["mode"]), []).append(float(row["value"]))
    shapes = [np.array(values[k + 1]) for k in range(len(freq))]
    assert all(len(s) == channels_per_mode for s in shapes)
    return np.array(freq), np.array(std), shapes


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dir", required=True, help="the folder footbridge_frame.py wrote")
    ap.add_argument("--eigenfit", help="eigenfit estimate --json output to compare with (and start from)")
    ap.add_argument("--start", choices=["both", "eigenfit", "nominal"], default="both",
                    help="where scipy starts: eigenfit's estimate, the nominal values, or both (default)")
    ap.add_argument("--max-nfev", type=int, default=40, help="residual evaluations per start (default 40)")
    ap.add_argument("--solver", choices=["eigsh", "dense"], default="eigsh")
    args = ap.parse_args()
    Ks, M, dof_map, nodes, index = fb.build()
    sparse_ks, sparse_m = [sp.csc_matrix(k) for k in Ks], sp.csc_matrix(M)
    # A fixed start vector: ARPACK's random one makes the residual, and its differences, noisy.
    start_vector = np.linspace(1.0, 2.0, M.shape[0])
    dx = fb.SPAN / fb.PANELS
    channels = []  # as footbridge_frame.py orders them: bottom chord, then top chord
    for z in (0.0, fb.DEPTH):
        for i in range(1, fb.PANELS):
            nd = index[(round(i * dx, 9), z)]
            channels.append(next(j for j, (m, d, _) in enumerate(dof_map) if m == nd and d == "z"))
    freq, std, shapes = read_data(args.dir, len(channels))
    nominal = np.array([1.0] * 16 + [fb.BEARING])
    measured_units = [d / np.linalg.norm(d) for d in shapes]
    evaluations = [0]

    def model(q):
        count = len(freq) + EXTRA_MODES
        if args.solver == "dense":
            K = sum(p * k for p, k in zip(nominal * np.exp(q), Ks))
            lam, phi = fb.condensed_modes(K, M, count)
        else:
            K = sum(p * k for p, k in zip(nominal * np.exp(q), sparse_ks)).tocsc()
            lam, phi = sla.eigsh(K, k=count, M=sparse_m, sigma=0, which="LM", tol=0, v0=start_vector)
            order = np.argsort(lam)
            lam, phi = lam[order], phi[:, order]
        return np.sqrt(lam) / (2 * np.pi), phi[channels]

    def pairing(s):
        """Model mode of each measured one: highest MAC, each model mode used once."""
        mac = np.array([[(d @ s[:, j]) ** 2 / (s[:, j] @ s[:, j]) for j in range(s.shape[1])]
                        for d in measured_units])
        taken, pairs = set(), []
        for k in range(len(freq)):
            j = max((j for j in range(s.shape[1]) if j not in taken), key=lambda j: mac[k, j])
            taken.add(j)
            pairs.append(j)
        return pairs, mac

    def residual(q):
        evaluations[0] += 1
        f, s = model(q)
        pairs, _ = pairing(s)
        rows = []
        for k, j in enumerate(pairs):
            rows.append(np.log(freq[k] / f[j]) / (std[k] / freq[k]))
        for k, j in enumerate(pairs):
            u = s[:, j] / np.linalg.norm(s[:, j])
            d = measured_units[k] * (1.0 if measured_units[k] @ u >= 0 else -1.0)
            rows.extend((d - u) / SHAPE_STD)
        return np.array(rows)

    bound = np.log(10.0)
    names = ([f"bottom{s + 1}" for s in range(4)] + [f"top{s + 1}" for s in range(4)]
             + [f"vertical{s + 1}" for s in range(4)] + [f"diagonal{s + 1}" for s in range(4)] + ["bearing"])
    theirs = None
    if args.eigenfit:
        with open(args.eigenfit) as f:
            out = json.load(f)
        theirs = out["parameters"]  # name → value
        print(f"eigenfit: chi2 {out['chi2']} on {out['dof']} dof")
    starts = []
    if args.start in ("both", "eigenfit"):
        if theirs is None:
            sys.exit("--start eigenfit needs --eigenfit FILE")
        q = np.log(np.array([theirs[n] for n in names]) / nominal)
        starts.append(("eigenfit's estimate", np.clip(q, -bound, bound)))
    if args.start in ("both", "nominal"):
        starts.append(("the nominal values", np.zeros(17)))
    for label, q0 in starts:
        r0 = residual(q0)
        chi2_start = float(r0 @ r0)
        evaluations[0] = 0
        start = time.process_time()
        fit = scipy.optimize.least_squares(residual, q0.copy(), bounds=(-bound, bound), method="trf",
                                           x_scale="jac", diff_step=1e-7, xtol=1e-10, ftol=1e-10, gtol=1e-8,
                                           max_nfev=args.max_nfev)
        cpu = time.process_time() - start
        chi2 = float(fit.fun @ fit.fun)
        factors = np.exp(fit.x)
        _, s = model(fit.x)
        pairs, mac = pairing(s)
        stopped = "stopped by --max-nfev: NOT converged" if fit.status == 0 else "converged"
        print(f"\nfrom {label}: chi2 {chi2_start:.4f} at the start -> {chi2:.4f} on {len(fit.fun) - 17} dof; "
              f"scipy status {fit.status} ({stopped}; {fit.message}); {fit.nfev} residual evaluations "
              f"({evaluations[0]} with the Jacobian's), {cpu:.1f} CPU-s")
        print(f"pairs {pairs}; MAC {[round(mac[k, j], 6) for k, j in enumerate(pairs)]}")
        for name, v, nom, truth in zip(names, factors * nominal, nominal, fb.TRUTH):
            line = f"  {name:10s} {v / nom:10.6f}  (true {truth:.2f})"
            if theirs is not None:
                line += f"  eigenfit {theirs[name] / nom:10.6f}  rel. diff {theirs[name] / v - 1:+.2e}"
            print(line)


if __name__ == "__main__":
    main()
