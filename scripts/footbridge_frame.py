#!/usr/bin/env python3
"""A truss-girder footbridge as an FE code exports it: frame elements with massless rotations.

The benchmark of issue 29, item 7(a), built where the real footbridge model is not available:
a planar Warren truss girder (span 60 m, depth 2.5 m, 30 panels; steel hollow sections), every
member meshed into 3 Euler–Bernoulli frame elements (u, w, θ per node), lumped translational
mass only — so every rotation is a DOF **without mass**, as commercial codes export a frame with
lumped mass. Pinned at the left bottom node, on a roller at the right one whose horizontal
restraint is a spring (a bearing). 17 parameters, each a stiffness factor (or the spring):

    bottom chord in 4 segments, top chord in 4, verticals in 4 groups, diagonals in 4, bearing

    K(p) = Σ p_i K_i      M = M0 (lumped, rotations massless)

Written to --out: K1.mtx … K17.mtx, K0.mtx (empty: every member is a parameter), M0.mtx, dofs.csv (node,
direction x/z/ry, coordinates), model.toml, and the "measured" data computed here by scipy
(dense `scipy.linalg.eigh` on the statically condensed problem, an independent solver) at the
factors of `TRUTH`, with noise of the stated std added (seeded): measured.csv (5 modes,
frequency_hz, std_hz) and shapes.csv (vertical displacement at 58 channels: 29 bottom- and 29
top-chord panel nodes, unit length, noise std 0.01 per entry; `--shape-std 0.01`).

    /work/venvs/sci/bin/python scripts/footbridge_frame.py --out /tmp/footbridge

Needs numpy and scipy.
"""

import argparse
import os

import numpy as np
import scipy.io
import scipy.linalg
import scipy.sparse as sp

SPAN, DEPTH, PANELS, SPLIT = 60.0, 2.5, 30, 3
E, RHO = 210e9, 7850.0
# (area m², second moment m⁴) of the members: chords, verticals, diagonals.
SECTIONS = {"bottom": (8.0e-3, 6.0e-5), "top": (9.0e-3, 7.0e-5), "vertical": (3.0e-3, 1.2e-5),
            "diagonal": (3.5e-3, 1.5e-5)}
DECK_MASS = 600.0  # kg per metre of span, lumped on the bottom chord's nodes
BEARING = 5e7  # N/m, nominal horizontal stiffness of the right bearing
# True factors of the 17 parameters (the bearing's relative to BEARING, its nominal value).
TRUTH = [1.10, 0.95, 0.90, 1.05, 1.00, 1.08, 0.92, 0.97, 1.20, 0.85, 1.00, 1.15,
         0.90, 1.10, 1.05, 0.80, 0.60]
MODES, FREQ_STD_REL, SHAPE_STD = 5, 2e-3, 0.01


def frame_element(x1, z1, x2, z2, A, I):
    """Global 6×6 stiffness of a 2-D Euler–Bernoulli frame element (u, w, θ at each end)."""
    L = np.hypot(x2 - x1, z2 - z1)
    c, s = (x2 - x1) / L, (z2 - z1) / L
    a, b = E * A / L, E * I / L**3
    k = np.array([
        [a, 0, 0, -a, 0, 0],
        [0, 12 * b, 6 * L * b, 0, -12 * b, 6 * L * b],
        [0, 6 * L * b, 4 * L * L * b, 0, -6 * L * b, 2 * L * L * b],
        [-a, 0, 0, a, 0, 0],
        [0, -12 * b, -6 * L * b, 0, 12 * b, -6 * L * b],
        [0, 6 * L * b, 2 * L * L * b, 0, -6 * L * b, 4 * L * L * b]])
    t = np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])
    T = np.kron(np.eye(2), t)
    return T.T @ k @ T, L


def build():
    nodes = []  # (x, z)
    index = {}

    def node(x, z):
        key = (round(x, 9), round(z, 9))
        if key not in index:
            index[key] = len(nodes)
            nodes.append((x, z))
        return index[key]

    dx = SPAN / PANELS
    members = []  # (kind, segment 0..3, node a, node b)
    for i in range(PANELS):
        seg = 4 * i // PANELS
        members.append(("bottom", seg, (i * dx, 0.0), ((i + 1) * dx, 0.0)))
        members.append(("top", seg, (i * dx, DEPTH), ((i + 1) * dx, DEPTH)))
        # Warren diagonals, alternating.
        if i % 2 == 0:
            members.append(("diagonal", seg, (i * dx, 0.0), ((i + 1) * dx, DEPTH)))
        else:
            members.append(("diagonal", seg, (i * dx, DEPTH), ((i + 1) * dx, 0.0)))
    for i in range(PANELS + 1):
        members.append(("vertical", min(4 * i // (PANELS + 1), 3), (i * dx, 0.0), (i * dx, DEPTH)))
    elements = []  # (group, a, b, A, I)
    group_of = {"bottom": 0, "top": 4, "vertical": 8, "diagonal": 12}
    for kind, seg, p, q in members:
        ends = [node(p[0] + (q[0] - p[0]) * t / SPLIT, p[1] + (q[1] - p[1]) * t / SPLIT) for t in range(SPLIT + 1)]
        for a, b in zip(ends, ends[1:]):
            elements.append((group_of[kind] + seg, a, b) + SECTIONS[kind])
    n_nodes = len(nodes)
    full = 3 * n_nodes
    Ks = [np.zeros((full, full)) for _ in range(17)]
    mass = np.zeros(full)
    for g, a, b, A, I in elements:
        (x1, z1), (x2, z2) = nodes[a], nodes[b]
        k, L = frame_element(x1, z1, x2, z2, A, I)
        dofs = [3 * a, 3 * a + 1, 3 * a + 2, 3 * b, 3 * b + 1, 3 * b + 2]
        Ks[g][np.ix_(dofs, dofs)] += k
        for nd in (a, b):
            mass[3 * nd] += 0.5 * RHO * A * L
            mass[3 * nd + 1] += 0.5 * RHO * A * L
    for i in range(PANELS + 1):
        nd = index[(round(i * dx, 9), 0.0)]
        share = DECK_MASS * dx * (0.5 if i in (0, PANELS) else 1.0)
        mass[3 * nd] += share
        mass[3 * nd + 1] += share
    left, right = index[(0.0, 0.0)], index[(round(SPAN, 9), 0.0)]
    Ks[16][3 * right, 3 * right] += 1.0  # per N/m: the parameter is the stiffness itself
    fixed = {3 * left, 3 * left + 1, 3 * right + 1}
    free = [d for d in range(full) if d not in fixed]
    Ks = [k[np.ix_(free, free)] for k in Ks]
    M = np.diag(mass[free])
    names = ["x", "z", "ry"]
    dof_map = [(d // 3, names[d % 3], nodes[d // 3]) for d in free]
    return Ks, M, dof_map, nodes, index


def condensed_modes(K, M, count):
    """Lowest modes of K φ = λ M φ with massless DOFs, by static condensation (dense)."""
    m = np.diag(M)
    kept, massless = np.flatnonzero(m > 0), np.flatnonzero(m == 0)
    Kss = K[np.ix_(massless, massless)]
    X = scipy.linalg.solve(Kss, K[np.ix_(massless, kept)], assume_a="pos")
    Kc = K[np.ix_(kept, kept)] - K[np.ix_(kept, massless)] @ X
    lam, phi = scipy.linalg.eigh(Kc, M[np.ix_(kept, kept)], subset_by_index=[0, count - 1])
    full = np.zeros((K.shape[0], count))
    full[kept] = phi
    full[massless] = -X @ phi
    return lam, full


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True)
    ap.add_argument("--seed", type=int, default=29)
    args = ap.parse_args()
    Ks, M, dof_map, nodes, index = build()
    n = M.shape[0]
    os.makedirs(args.out, exist_ok=True)
    write = lambda name, A: scipy.io.mmwrite(os.path.join(args.out, name), sp.tril(sp.csc_matrix(A)).tocoo(), symmetry="symmetric")  # noqa: E731
    for i, k in enumerate(Ks, 1):
        write(f"K{i}.mtx", k)
    write("M0.mtx", M)
    # Node numbers as the DOF map gives them, counted from 0 in order of first appearance (what
    # a shapes CSV's `node` column refers to).
    order = {}
    with open(os.path.join(args.out, "dofs.csv"), "w") as f:
        f.write("dof,node,direction,x,y,z\n")
        for d, (nd, direction, (x, z)) in enumerate(dof_map, 1):
            order.setdefault(nd, len(order))
            f.write(f"{d},{nd + 1},{direction},{x:.6g},0,{z:.6g}\n")
    names = ([f"bottom{s + 1}" for s in range(4)] + [f"top{s + 1}" for s in range(4)]
             + [f"vertical{s + 1}" for s in range(4)] + [f"diagonal{s + 1}" for s in range(4)] + ["bearing"])
    lines = ["# Truss-girder footbridge (frame elements, massless rotations), generated by scripts/footbridge_frame.py",
             f"# {n} DOFs, {sum(1 for d in dof_map if d[1] == 'ry')} of them rotations without mass",
             'kind = "matrices"', 'name = "footbridge frame"', 'stiffness = "K0.mtx"', 'mass = "M0.mtx"',
             'dofs = "dofs.csv"']
    # Every member belongs to a parameter: K₀ holds nothing (an empty file of the model's size).
    with open(os.path.join(args.out, "K0.mtx"), "w") as f:
        f.write(f"%%MatrixMarket matrix coordinate real symmetric\n{n} {n} 0\n")
    for name, i in zip(names, range(1, 18)):
        nominal = BEARING if name == "bearing" else 1.0
        lines += ["", "[[parameter]]", f'name = "{name}"', f"nominal = {nominal:g}",
                  f"lower = {0.1 * nominal:g}", f"upper = {10 * nominal:g}", 'scale = "log"',
                  f'stiffness = "K{i}.mtx"'] + (['unit = "N/m"'] if name == "bearing" else [])
    with open(os.path.join(args.out, "model.toml"), "w") as f:
        f.write("\n".join(lines) + "\n")
    truth = TRUTH[:16] + [TRUTH[16] * BEARING]
    K = sum(p * k for p, k in zip(truth, Ks))
    lam, phi = condensed_modes(K, M, MODES)
    freq = np.sqrt(lam) / (2 * np.pi)
    rng = np.random.default_rng(args.seed)
    std = FREQ_STD_REL * freq
    noisy = freq + std * rng.standard_normal(MODES)
    with open(os.path.join(args.out, "measured.csv"), "w") as f:
        f.write(f"# scipy.linalg.eigh on the statically condensed model at the true factors, noise seed {args.seed}\n")
        f.write("mode,frequency_hz,std_hz\n")
        for k in range(MODES):
            f.write(f"{k + 1},{noisy[k]:.9g},{std[k]:.3g}\n")
    dx = SPAN / PANELS
    channels = []
    for z in (0.0, DEPTH):
        for i in range(1, PANELS):
            nd = index[(round(i * dx, 9), z)]
            d = next(j for j, (m, direction, _) in enumerate(dof_map) if m == nd and direction == "z")
            channels.append((order[nd], d))
    with open(os.path.join(args.out, "shapes.csv"), "w") as f:
        f.write("mode,node,direction,value\n")
        for k in range(MODES):
            s = np.array([phi[d, k] for _, d in channels])
            s = s / np.linalg.norm(s) + SHAPE_STD * rng.standard_normal(len(channels))
            for (nd, _), v in zip(channels, s):
                f.write(f"{k + 1},{nd},z,{v:.6g}\n")
    print(f"{args.out}: {n} DOFs ({sum(1 for d in dof_map if d[1] == 'ry')} massless), 17 parameters, "
          f"{len(channels)} channels; frequencies {np.round(freq, 4).tolist()} Hz")


if __name__ == "__main__":
    main()
