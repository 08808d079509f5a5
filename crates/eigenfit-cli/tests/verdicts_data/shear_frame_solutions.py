"""Every exact solution of a 3-storey shear frame's inverse eigenvalue problem, by scipy.

The frame of tests/verdicts.rs: unit floor masses, storey stiffnesses k1 (ground-floor 1), k2, k3,
truth (1e4, 3e4, 2e4) N/m. Its three eigenvalues are matched from 3000 log-uniform starts in
[1e2, 1e6]^3 by scipy.optimize.least_squares (independent of eigenfit); the distinct exact
solutions (cost < 1e-14, 1e-4 apart) are written to shear_frame_solutions.json.

    python -m venv venv && venv/bin/pip install numpy scipy && venv/bin/python shear_frame_solutions.py
"""
import json
import pathlib

import numpy as np
from scipy.optimize import least_squares


def stiffness(k):
    k1, k2, k3 = k
    return np.array([[k1 + k2, -k2, 0.0], [-k2, k2 + k3, -k3], [0.0, -k3, k3]])


truth = np.array([1e4, 3e4, 2e4])
lam = np.sort(np.linalg.eigvalsh(stiffness(truth)))
rng = np.random.default_rng(0)
solutions = []
for _ in range(3000):
    start = rng.uniform(np.log(1e2), np.log(1e6), 3)
    fit = least_squares(
        lambda lk: np.sort(np.linalg.eigvalsh(stiffness(np.exp(lk)))) / lam - 1.0,
        start,
        xtol=1e-15,
        ftol=1e-15,
        gtol=1e-15,
    )
    if fit.cost < 1e-14:
        k = np.exp(fit.x)
        if not any(np.allclose(k, s, rtol=1e-4) for s in solutions):
            solutions.append(k)
solutions.sort(key=lambda k: k[0])
out = {
    "truth": truth.tolist(),
    "frequencies_hz": (np.sqrt(lam) / (2 * np.pi)).tolist(),
    "solutions": [k.tolist() for k in solutions],
    "generator": f"scipy {__import__('scipy').__version__}, numpy {np.__version__}",
}
pathlib.Path(__file__).with_suffix(".json").write_text(json.dumps(out, indent=1) + "\n")
print(len(solutions), "solutions")
