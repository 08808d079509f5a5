#!/usr/bin/env python3
"""A plane frame with massless rotations, written as a `kind = "matrices"` model (issue 29).

Three storeys, two bays (columns at x = 0, 4, 8 m, floors every 3 m), Euler-Bernoulli frame
elements (axial + bending), base fixed. Each free node has ux, uy, rz; the floor mass is lumped
on the translations only, so the 9 rotations have no mass: M is positive semi-definite, as
frame models exported from FE codes are.

Parameters: the columns' stiffness of each storey (story1..story3, scales on EI and EA) and
the beams' (beams). K0 is a tie between the top corners. The files show the
model file's lists: the nominal stiffness is split into two files summed, and story1's
derivative is written as two files (its left and its right columns) summed too.

The measured data are computed here, independently of eigenfit: scipy.linalg.eig of the full
(K, M) pencil with singular M, whose infinite eigenvalues are discarded — no condensation.
`measured.csv` holds the 5 lowest frequencies at the truth, `shapes.csv` the mode shapes at
the ux and uy DOFs of every free node (the model's node numbering, from 0), `reference.json`
the nominal frequencies and d f / d p by central differences of the full problem.

    python3 -m venv /work/venvs/matrices && /work/venvs/matrices/bin/pip install numpy scipy
    /work/venvs/matrices/bin/python generate.py
"""
import json
import os

import numpy as np
import scipy.linalg

HERE = os.path.dirname(os.path.abspath(__file__))
E = 2.1e11
COL = dict(A=6.0e-3, I=5.0e-5)      # a HEB-ish column
BEAM = dict(A=5.0e-3, I=8.0e-5)
FLOOR_MASS = 6000.0                 # kg per node and direction
TRUTH = {"story1": 0.85, "story2": 1.1, "story3": 0.95, "beams": 1.2}
PARAMS = list(TRUTH)

xs = [0.0, 4.0, 8.0]
levels = [0.0, 3.0, 6.0, 9.0]
nodes = {}  # (ix, level) -> node id from 1
for lv in range(len(levels)):
    for ix in range(len(xs)):
        nodes[(ix, lv)] = len(nodes) + 1
free = [key for key in nodes if key[1] > 0]
dof_of = {}
dof_rows = []
for key in free:
    for d in ("x", "y", "rz"):
        dof_of[(nodes[key], d)] = len(dof_of)
        dof_rows.append((nodes[key], d, xs[key[0]], levels[key[1]]))
n = len(dof_of)


def frame_element(x1, y1, x2, y2, A, I):
    L = np.hypot(x2 - x1, y2 - y1)
    c, s = (x2 - x1) / L, (y2 - y1) / L
    ea, ei = E * A / L, E * I
    k = np.zeros((6, 6))
    k[0, 0] = k[3, 3] = ea
    k[0, 3] = k[3, 0] = -ea
    b = np.array([[12, 6 * L, -12, 6 * L], [6 * L, 4 * L * L, -6 * L, 2 * L * L],
                  [-12, -6 * L, 12, -6 * L], [6 * L, 2 * L * L, -6 * L, 4 * L * L]]) * ei / L**3
    idx = [1, 2, 4, 5]
    for a in range(4):
        for bb in range(4):
            k[idx[a], idx[bb]] = b[a, bb]
    t = np.zeros((6, 6))
    r = np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])
    t[:3, :3] = r
    t[3:, 3:] = r
    return t.T @ k @ t


def assemble(elements):
    K = np.zeros((n, n))
    for (a, b, props) in elements:
        ke = frame_element(xs[a[0]], levels[a[1]], xs[b[0]], levels[b[1]], **props)
        dofs = [dof_of.get((nodes[a], d)) for d in ("x", "y", "rz")] + \
               [dof_of.get((nodes[b], d)) for d in ("x", "y", "rz")]
        for i, di in enumerate(dofs):
            for j, dj in enumerate(dofs):
                if di is not None and dj is not None:
                    K[di, dj] += ke[i, j]
    return K


groups = {p: [] for p in PARAMS}
story1_left = []
for lv in range(1, len(levels)):
    for ix in range(len(xs)):
        element = ((ix, lv - 1), (ix, lv), COL)
        groups[f"story{lv}"].append(element)
        if lv == 1 and ix == 0:
            story1_left.append(element)
    for ix in range(len(xs) - 1):
        groups["beams"].append(((ix, lv), (ix + 1, lv), BEAM))
Kp = {p: assemble(groups[p]) for p in PARAMS}
M = np.zeros((n, n))
for key in free:
    for d in ("x", "y"):
        M[dof_of[(nodes[key], d)], dof_of[(nodes[key], d)]] = FLOOR_MASS


def stiffness(values):
    return sum(values[p] * Kp[p] for p in PARAMS)


def write_mtx(name, A, comment):
    rows = [(i, j, A[i, j]) for j in range(n) for i in range(j, n) if A[i, j] != 0.0]
    with open(os.path.join(HERE, name), "w") as fh:
        fh.write("%%MatrixMarket matrix coordinate real symmetric\n")
        fh.write(f"% {comment}\n")
        fh.write(f"{n} {n} {len(rows)}\n")
        for i, j, v in rows:
            fh.write(f"{i + 1} {j + 1} {v:.17g}\n")


zero = np.zeros((n, n))
# K0: a tie between the top corners (not updated), written as two halves the model file sums.
brace = np.zeros((n, n))
top_left, top_right = dof_of[(nodes[(0, 3)], "x")], dof_of[(nodes[(2, 3)], "x")]
kb = 1.0e6
brace[top_left, top_left] = kb
brace[top_right, top_right] = kb
brace[top_left, top_right] = brace[top_right, top_left] = -kb
write_mtx("K0a.mtx", brace * 0.5, "half of a top-floor tie (N/m), summed with K0b.mtx")
write_mtx("K0b.mtx", brace * 0.5, "the other half")
left = assemble(story1_left)
write_mtx("K_story1_left.mtx", left, "story1: the left column")
write_mtx("K_story1_rest.mtx", Kp["story1"] - left, "story1: the other columns")
for p in PARAMS[1:]:
    write_mtx(f"K_{p}.mtx", Kp[p], f"d K / d {p}")
write_mtx("M0.mtx", M, "lumped floor mass on ux, uy; rotations massless")
# A candidate for discover: an added mass at the top-right node, x and y.
Mc = np.zeros((n, n))
for d in ("x", "y"):
    i = dof_of[(nodes[(2, 3)], d)]
    Mc[i, i] = 1.0
write_mtx("Mc.mtx", Mc, "candidate: 1 kg at the top-right node (x, y)")

with open(os.path.join(HERE, "dofs.csv"), "w") as fh:
    fh.write("dof,node,direction,x,y,z\n")
    for k, (node, d, x, y) in enumerate(dof_rows):
        fh.write(f"{k + 1},{node},{d},{x},{y},0\n")


# The tie is part of K at every parameter value.
Kp_brace = brace


def frequencies_full(values, count=5, shapes=False):
    lam, vec = scipy.linalg.eig(stiffness(values) + Kp_brace, M)
    finite = np.isfinite(lam) & (np.abs(lam) < 1e30)
    lam, vec = lam[finite].real, vec[:, finite].real
    order = np.argsort(lam)[:count]
    f = np.sqrt(lam[order]) / (2 * np.pi)
    return (f, vec[:, order]) if shapes else f


f_truth, phi = frequencies_full(TRUTH, shapes=True)
with open(os.path.join(HERE, "measured.csv"), "w") as fh:
    fh.write("# scipy.linalg.eig of the full (K, M) pencil (M singular), truth "
             + ", ".join(f"{k}={v}" for k, v in TRUTH.items()) + "\n")
    fh.write("mode,frequency_hz\n")
    for i, f in enumerate(f_truth):
        fh.write(f"{i + 1},{f:.12g}\n")
# Shapes at ux, uy of every free node; model node = order of first appearance in dofs.csv.
model_node = {}
for node, d, x, y in dof_rows:
    model_node.setdefault(node, len(model_node))
with open(os.path.join(HERE, "shapes.csv"), "w") as fh:
    fh.write("mode,node,direction,value\n")
    for m in range(phi.shape[1]):
        v = phi[:, m] / np.abs(phi[:, m]).max()
        for key in free:
            for d in ("x", "y"):
                fh.write(f"{m + 1},{model_node[nodes[key]]},{d},{v[dof_of[(nodes[key], d)]]:.10g}\n")

nominal = {p: 1.0 for p in PARAMS}
f0 = frequencies_full(nominal)
sens = {}
for p in PARAMS:
    h = 1e-6
    up, down = dict(nominal), dict(nominal)
    up[p] += h
    down[p] -= h
    sens[p] = list((frequencies_full(up) - frequencies_full(down)) / (2 * h))
with open(os.path.join(HERE, "reference.json"), "w") as fh:
    json.dump({"dofs": n, "massless": [k + 1 for k, r in enumerate(dof_rows) if r[1] == "rz"],
               "frequencies_hz": list(f0), "sensitivities_hz": sens, "truth": TRUTH,
               "truth_frequencies_hz": list(f_truth)}, fh, indent=1)

model = f'''# Three-storey, two-bay plane frame: 27 DOFs, its 9 rotations massless.
# Written by generate.py (beside this file).
kind = "matrices"
name = "plane frame, massless rotations"
stiffness = ["K0a.mtx", "K0b.mtx"]
mass = "M0.mtx"
dofs = "dofs.csv"
'''
for p in PARAMS:
    files = '["K_story1_left.mtx", "K_story1_rest.mtx"]' if p == "story1" else f'"K_{p}.mtx"'
    model += f'''
[[parameter]]
name = "{p}"
nominal = 1.0
lower = 0.1
upper = 10.0
scale = "log"
stiffness = {files}
'''
model += '''
[[candidate]]
name = "added-mass-top-right"
mass = "Mc.mtx"
lower = 0.0
upper = 5000.0
'''
with open(os.path.join(HERE, "model.toml"), "w") as fh:
    fh.write(model)
print("dofs", n, "f0", f0, "truth", f_truth)
