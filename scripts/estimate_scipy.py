#!/usr/bin/env python3
"""The scipy path for `eigenfit estimate` on a `kind = "matrices"` model: the reference that
issue 17's "Done when" compares against (same files, same least-squares problem).

    K(p) = K0 + Σ p_i K_i,  M(p) = M0 + Σ p_i M_i          (the model.toml Contract)
    r_k(p) = ln(f_k(p) / f_k,measured)                      (eigenfit's default `relative`
                                                             residual, modes paired by order)

minimised by scipy.optimize.least_squares (trust-region reflective, bounds from the model file)
in the parameters' scaled form (ln p for `scale = "log"`), with the analytic Jacobian from the
mode shapes: dλ_k/dp_i = φ_kᵀ (K_i − λ_k M_i) φ_k (M-normalised φ), df/f = dλ / (2λ). Every
evaluation is one `eigsh(K, n, M, sigma=0)` (ARPACK shift-invert on SuperLU) plus those
products; the Jacobian is computed at the same eigen-solve as the residual (cached by p).

Prints one JSON line: the parameters by name, evaluations (eigen-solves), iterations, CPU and
wall seconds for reading and for the fit, the peak memory. Single-threaded BLAS, as eigenfit's
sparse path:

    OPENBLAS_NUM_THREADS=1 python scripts/estimate_scipy.py /tmp/plate-1e5/model.toml \\
        /tmp/plate-1e5/measured.csv

Needs numpy and scipy (not needed by eigenfit itself). Run outside CI.
"""

import argparse
import json
import os
import time
import tomllib

import numpy as np
import scipy
import scipy.io
import scipy.optimize
import scipy.sparse.linalg as sla

from bench_sparse import peak_kb  # scripts/ beside this file


def read_measured(path):
    """`mode,frequency_hz[,std_hz]` → (mode numbers from 1, frequencies)."""
    modes, freqs = [], []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#") or line.startswith("mode"):
                continue
            cols = line.split(",")
            modes.append(int(cols[0]))
            freqs.append(float(cols[1]))
    return np.array(modes), np.array(freqs)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("model", help="model.toml (kind = \"matrices\")")
    ap.add_argument("measured", help="measured.csv: mode,frequency_hz")
    args = ap.parse_args()
    folder = os.path.dirname(os.path.abspath(args.model))

    t, c = time.perf_counter(), time.process_time()
    with open(args.model, "rb") as f:
        spec = tomllib.load(f)
    read = lambda name: scipy.io.mmread(os.path.join(folder, name)).tocsc()  # noqa: E731
    K0, M0 = read(spec["stiffness"]), read(spec["mass"])
    params = spec["parameter"]
    Ks = [read(p["stiffness"]) if "stiffness" in p else None for p in params]
    Ms = [read(p["mass"]) if "mass" in p else None for p in params]
    modes, measured = read_measured(args.measured)
    load_s, load_cpu_s = time.perf_counter() - t, time.process_time() - c

    log = [p.get("scale", "linear") == "log" for p in params]
    to_p = lambda s: np.array([np.exp(v) if lg else v for v, lg in zip(s, log)])  # noqa: E731
    to_s = lambda p: np.array([np.log(v) if lg else v for v, lg in zip(p, log)])  # noqa: E731
    lower = to_s([p.get("lower", 1e-300 if lg else -np.inf) for p, lg in zip(params, log)])
    upper = to_s([p.get("upper", np.inf) for p in params])
    count = int(modes.max())
    stats = {"solves": 0}
    cache = {}

    def solve(s):
        key = tuple(s)
        if key not in cache:
            p = to_p(s)
            K = K0 + sum(pi * Ki for pi, Ki in zip(p, Ks) if Ki is not None)
            M = M0 + sum(pi * Mi for pi, Mi in zip(p, Ms) if Mi is not None)
            lam, phi = sla.eigsh(K.tocsc(), count, M.tocsc(), sigma=0, which="LM")
            order = np.argsort(lam)
            lam, phi = lam[order][modes - 1], phi[:, order][:, modes - 1]
            stats["solves"] += 1
            # d ln f / d s_i = dλ/dp_i · dp_i/ds_i / (2λ)
            jac = np.empty((len(lam), len(p)))
            for i, (Ki, Mi) in enumerate(zip(Ks, Ms)):
                d = np.zeros(len(lam))
                if Ki is not None:
                    d += np.einsum("ik,ik->k", phi, Ki @ phi)
                if Mi is not None:
                    d -= lam * np.einsum("ik,ik->k", phi, Mi @ phi)
                jac[:, i] = d * (p[i] if log[i] else 1.0) / (2.0 * lam)
            cache.clear()
            cache[key] = (lam, jac)
        return cache[key]

    def residual(s):
        lam = solve(s)[0]
        return np.log(np.sqrt(lam) / (2 * np.pi) / measured)

    t, c = time.perf_counter(), time.process_time()
    s0 = to_s([p["nominal"] for p in params])
    fit = scipy.optimize.least_squares(residual, s0, jac=lambda s: solve(s)[1], bounds=(lower, upper),
                                       method="trf", x_scale=1.0, xtol=1e-12, ftol=1e-12, gtol=1e-12)
    fit_s, fit_cpu_s = time.perf_counter() - t, time.process_time() - c
    p = to_p(fit.x)
    f = np.sqrt(solve(fit.x)[0]) / (2 * np.pi)
    print(json.dumps({
        "solver": f"scipy {scipy.__version__} least_squares(trf) on eigsh(K, {count}, M, sigma=0)",
        "parameters": {q["name"]: float(v) for q, v in zip(params, p)},
        "frequencies_hz": f.tolist(),
        "max_rel_diff": float(np.max(np.abs(f / measured - 1.0))),
        "status": int(fit.status), "message": fit.message,
        "evaluations": stats["solves"], "nfev": int(fit.nfev), "njev": int(fit.njev or 0),
        "load_s": load_s, "load_cpu_s": load_cpu_s, "fit_s": fit_s, "fit_cpu_s": fit_cpu_s,
        "peak_rss_kb": peak_kb(),
    }))


if __name__ == "__main__":
    main()
