#!/usr/bin/env python3
"""A stiffened plate as Matrix Market files: an eigenfit `matrices` model of any size.

The plate (1.5 m × 1.0 m × 5 mm steel, simply supported on all edges) is modelled as a grillage:
Euler–Bernoulli beams along x and y between neighbouring nodes, each carrying its strip of plate
in bending (D·h) and torsion (D(1 − ν)·h), consistent mass. Three DOFs per node (w, θx, θy).
Two stiffeners along x and one along y (steel flats 8 × 40 mm) are welded on off-centre
(y = 0.25·LY and 0.6·LY, x = 0.6·LX), as on a real structure: with the stiffeners placed
symmetrically (y = LY/3, 2LY/3, x = LX/2; `--symmetric`) the plate is nearly doubly symmetric,
the zones mirrored about a centre line give the same frequencies to 6e-5 at 10⁴ DOFs, and
frequencies alone cannot tell those zones apart. The plate is split into ZX × ZY zones whose
bending stiffness is a parameter each:

    K(p) = K0 + Σ p_i K_i    (K0: stiffeners; K_i: the plate strips of zone i; p_i = 1 nominal)
    M    = M0                (no mass parameter)

Written: K0.mtx, M0.mtx, K1.mtx … (symmetric, lower triangle, as scipy.io.mmwrite writes it),
model.toml (the eigenfit model file) and, with --measured, measured.csv: the lowest frequencies
at the parameter values given, computed by scipy (ARPACK shift-invert), an independent solver.

    python scripts/plate_matrices.py --dofs 100000 --out /tmp/plate-1e5
    python scripts/plate_matrices.py --dofs 1000 --out crates/eigenfit-matrices/tests/data/plate \\
        --measured 1.25,0.8,1.1,0.9

Needs numpy and scipy (not needed by eigenfit itself).
"""

import argparse
import json
import math
import os
import sys

import numpy as np
import scipy.io
import scipy.sparse as sp
import scipy.sparse.linalg as sla

LX, LY, T = 1.5, 1.0, 0.005
E, NU, RHO = 210e9, 0.3, 7850.0
STIFFENER_W, STIFFENER_H = 0.008, 0.040
# Stiffener lines as fractions of LY (along x) and of LX (along y): off-centre, and the
# symmetric layout of the first versions (--symmetric).
STIFFENERS = {"off-centre": ((0.25, 0.6), 0.6), "symmetric": ((1 / 3, 2 / 3), 0.5)}


def grid_size(dofs):
    """nx × ny nodes (ny/nx ≈ LY/LX) with about `dofs` free DOFs (3 per node, edge w fixed)."""
    nx = max(4, round(math.sqrt(dofs / 3.0 * LX / LY)))
    ny = max(4, round(dofs / 3.0 / nx))
    return nx, ny


def beam_blocks(L, EI, GJ, rhoA, rhoIp):
    """Bending (w, θ) 4×4 and torsion 2×2 element matrices, stacked per element (arrays)."""
    L = np.asarray(L, float)
    c = EI / L**3
    kb = np.stack([
        np.stack([12 * c, 6 * L * c, -12 * c, 6 * L * c], -1),
        np.stack([6 * L * c, 4 * L**2 * c, -6 * L * c, 2 * L**2 * c], -1),
        np.stack([-12 * c, -6 * L * c, 12 * c, -6 * L * c], -1),
        np.stack([6 * L * c, 2 * L**2 * c, -6 * L * c, 4 * L**2 * c], -1),
    ], -2)
    m = rhoA * L / 420.0
    mb = np.stack([
        np.stack([156 * m, 22 * L * m, 54 * m, -13 * L * m], -1),
        np.stack([22 * L * m, 4 * L**2 * m, 13 * L * m, -3 * L**2 * m], -1),
        np.stack([54 * m, 13 * L * m, 156 * m, -22 * L * m], -1),
        np.stack([-13 * L * m, -3 * L**2 * m, -22 * L * m, 4 * L**2 * m], -1),
    ], -2)
    g = GJ / L
    kt = np.stack([np.stack([g, -g], -1), np.stack([-g, g], -1)], -2)
    mt = rhoIp * L / 6.0
    mt = np.stack([np.stack([2 * mt, mt], -1), np.stack([mt, 2 * mt], -1)], -2)
    return kb, mb, kt, mt


def scatter(dofs, blocks, n):
    """Σ over elements of blocks[e] at dofs[e] (dofs: E×k, blocks: E×k×k) as a CSR matrix."""
    k = dofs.shape[1]
    rows = np.repeat(dofs, k, axis=1).ravel()
    cols = np.tile(dofs, (1, k)).ravel()
    vals = blocks.reshape(len(dofs), -1).ravel()
    return sp.coo_matrix((vals, (rows, cols)), shape=(n, n)).tocsr()


def build(dofs, zx, zy, layout="off-centre"):
    nx, ny = grid_size(dofs)
    hx, hy = LX / (nx - 1), LY / (ny - 1)
    node = lambda i, j: i * ny + j  # noqa: E731
    n_all = 3 * nx * ny
    D = E * T**3 / (12 * (1 - NU**2))
    # Beams along x: nodes (i, j)–(i + 1, j); bending uses (w, θy), torsion θx.
    ii, jj = np.meshgrid(np.arange(nx - 1), np.arange(ny), indexing="ij")
    ax, bx = node(ii, jj).ravel(), node(ii + 1, jj).ravel()
    # Beams along y: nodes (i, j)–(i, j + 1); bending uses (w, θx), torsion θy.
    ii2, jj2 = np.meshgrid(np.arange(nx), np.arange(ny - 1), indexing="ij")
    ay, by = node(ii2, jj2).ravel(), node(ii2, jj2 + 1).ravel()
    # Tributary widths: half a strip on the edges.
    wx = np.where((jj.ravel() == 0) | (jj.ravel() == ny - 1), hy / 2, hy)
    wy = np.where((ii2.ravel() == 0) | (ii2.ravel() == nx - 1), hx / 2, hx)

    def strips(a, b, L, width, bend, twist):
        EI, GJ = D * width, D * (1 - NU) * width
        rhoA = RHO * T * width
        rhoIp = RHO * T * width * (width**2 + T**2) / 12.0 / 2.0  # shared by the two directions
        kb, mb, kt, mt = beam_blocks(np.full(len(a), L), EI, GJ, rhoA, rhoIp)
        bdofs = np.stack([3 * a, 3 * a + bend, 3 * b, 3 * b + bend], -1)
        tdofs = np.stack([3 * a + twist, 3 * b + twist], -1)
        return bdofs, kb, mb, tdofs, kt, mt

    X = strips(ax, bx, hx, wx, 2, 1)
    Y = strips(ay, by, hy, wy, 1, 2)
    # Zone of each strip by its midpoint.
    mid_x = np.concatenate([(ii.ravel() + 0.5) * hx, ii2.ravel() * hx])
    mid_y = np.concatenate([jj.ravel() * hy, (jj2.ravel() + 0.5) * hy])
    zone = np.minimum((mid_x / LX * zx).astype(int), zx - 1) * zy + np.minimum((mid_y / LY * zy).astype(int), zy - 1)
    ne_x = len(ax)
    bd = np.concatenate([X[0], Y[0]])
    kb = np.concatenate([X[1], Y[1]])
    mb = np.concatenate([X[2], Y[2]])
    td = np.concatenate([X[3], Y[3]])
    kt = np.concatenate([X[4], Y[4]])
    mt = np.concatenate([X[5], Y[5]])
    zones = []
    for z in range(zx * zy):
        sel = zone == z
        zones.append(scatter(bd[sel], kb[sel], n_all) + scatter(td[sel], kt[sel], n_all))
    M = scatter(bd, mb, n_all) + scatter(td, mt, n_all)
    # Stiffeners: flats on the lines y = along_x·LY (along x) and x = along_y·LX (along y).
    EIs = E * STIFFENER_W * STIFFENER_H**3 / 12.0
    GJs = E / (2 * (1 + NU)) * STIFFENER_H * STIFFENER_W**3 / 3.0
    rhoAs = RHO * STIFFENER_W * STIFFENER_H
    rhoIps = RHO * STIFFENER_W * STIFFENER_H * (STIFFENER_W**2 + STIFFENER_H**2) / 12.0
    K0 = sp.csr_matrix((n_all, n_all))

    def stiffener(K0, M, a, b, L, bend, twist):
        """K0, M with a stiffener's beams a[e]–b[e] added: bending on (w, θ_bend), torsion on θ_twist."""
        kb_s, mb_s, kt_s, mt_s = beam_blocks(np.full(len(a), L), EIs, GJs, rhoAs, rhoIps)
        bdofs = np.stack([3 * a, 3 * a + bend, 3 * b, 3 * b + bend], -1)
        tdofs = np.stack([3 * a + twist, 3 * b + twist], -1)
        K0 = K0 + scatter(bdofs, kb_s, n_all) + scatter(tdofs, kt_s, n_all)
        return K0, M + scatter(bdofs, mb_s, n_all) + scatter(tdofs, mt_s, n_all)

    along_x, along_y = STIFFENERS[layout]
    for frac in along_x:
        sel = np.arange(nx - 1) * ny + round(frac * (ny - 1))
        K0, M = stiffener(K0, M, ax[sel], bx[sel], hx, 2, 1)
    sel = round(along_y * (nx - 1)) * (ny - 1) + np.arange(ny - 1)
    K0, M = stiffener(K0, M, ay[sel], by[sel], hy, 1, 2)
    # Simply supported edges: w = 0 on the boundary nodes.
    ix, jy = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    edge = ((ix == 0) | (ix == nx - 1) | (jy == 0) | (jy == ny - 1)).ravel()
    fixed = 3 * np.flatnonzero(edge)
    keep = np.setdiff1d(np.arange(n_all), fixed)
    cut = lambda A: sp.csr_matrix(A[keep][:, keep])  # noqa: E731
    coords = np.stack([ix.ravel() * hx, jy.ravel() * hy], -1)
    dof_map = [(k // 3, "z rx ry".split()[k % 3], *coords[k // 3]) for k in keep]
    return cut(K0), cut(M), [cut(Z) for Z in zones], dof_map, (nx, ny)


def lowest(K, M, count):
    """Lowest `count` eigenvalues and M-normalised vectors by ARPACK shift-invert at σ = 0."""
    lam, phi = sla.eigsh(K.tocsc(), count, M.tocsc(), sigma=0, which="LM")
    order = np.argsort(lam)
    return lam[order], phi[:, order]


def write_shapes(path, phi, dof_map, nx, ny, count):
    """shapes.csv: w of every mode at `count` interior nodes spread over the plate (an
    a × b grid of sensors, a·b = count, a/b ≈ nx/ny), node counted from 0 in the order nodes
    first appear in the DOF map (as `--shapes` reads it)."""
    a = max(1, round(np.sqrt(count * nx / ny)))
    while count % a:
        a -= 1
    b = count // a
    order, w_dof = {}, {}
    for d, (nd, direction, _, _) in enumerate(dof_map):
        order.setdefault(nd, len(order))
        if direction == "z":
            w_dof[nd] = d
    sensors = []
    for i in range(a):
        for j in range(b):
            ix = 1 + round((i + 0.5) * (nx - 2) / a - 0.5)
            jy = 1 + round((j + 0.5) * (ny - 2) / b - 0.5)
            sensors.append(ix * ny + jy)
    with open(path, "w") as f:
        f.write("mode,node,direction,value\n")
        for k in range(phi.shape[1]):
            for nd in sensors:
                f.write(f"{k + 1},{order[nd]},z,{phi[w_dof[nd], k]:.12g}\n")


def hz(lam):
    return np.sqrt(np.maximum(lam, 0)) / (2 * np.pi)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dofs", type=int, required=True, help="approximate number of DOFs")
    ap.add_argument("--zones", default="2x2", help="zones ZXxZY (default 2x2: 4 parameters)")
    ap.add_argument("--out", required=True, help="output folder")
    ap.add_argument("--measured", help="P1,P2,…: write measured.csv (scipy) at these zone factors")
    ap.add_argument("--modes", type=int, default=10, help="modes in measured.csv (default 10)")
    ap.add_argument("--dof-map", action="store_true", help="also write dofs.csv (node, direction, x, y, z)")
    ap.add_argument("--shapes", type=int, default=0,
                    help="with --measured: also write shapes.csv, w of every measured mode at this many "
                         "sensors (a grid of interior nodes; implies --dof-map)")
    ap.add_argument("--symmetric", action="store_true",
                    help="stiffeners on the centre lines (a nearly doubly symmetric plate: mirrored zones fit alike)")
    ap.add_argument("--reference", action="store_true",
                    help="also write scipy_reference.json: nominal frequencies and df/dp by scipy")
    args = ap.parse_args()
    args.dof_map = args.dof_map or args.shapes > 0
    zx, zy = (int(v) for v in args.zones.lower().split("x"))
    layout = "symmetric" if args.symmetric else "off-centre"
    K0, M, zones, dof_map, (nx, ny) = build(args.dofs, zx, zy, layout)
    os.makedirs(args.out, exist_ok=True)
    write = lambda name, A: scipy.io.mmwrite(os.path.join(args.out, name), sp.tril(A).tocoo(), symmetry="symmetric")  # noqa: E731
    write("K0.mtx", K0)
    write("M0.mtx", M)
    lines = [
        "# Stiffened plate (grillage), generated by scripts/plate_matrices.py",
        f"# --dofs {args.dofs} --zones {args.zones}{' --symmetric' * args.symmetric}: {nx}×{ny} nodes, {K0.shape[0]} DOFs, "
        f"{layout} stiffeners",
        'kind = "matrices"',
        f'name = "stiffened plate {K0.shape[0]} DOFs"',
        'stiffness = "K0.mtx"',
        'mass = "M0.mtx"',
    ]
    if args.dof_map:
        lines.append('dofs = "dofs.csv"')
        with open(os.path.join(args.out, "dofs.csv"), "w") as f:
            f.write("dof,node,direction,x,y,z\n")
            for d, (nd, direction, x, y) in enumerate(dof_map, 1):
                f.write(f"{d},{nd + 1},{direction},{x:.6g},{y:.6g},0\n")
    for z, Z in enumerate(zones, 1):
        write(f"K{z}.mtx", Z)
        lines += ["", "[[parameter]]", f'name = "zone{z}"', "nominal = 1.0", "lower = 0.05", "upper = 20.0",
                  'scale = "log"', f'stiffness = "K{z}.mtx"']
    with open(os.path.join(args.out, "model.toml"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"{args.out}: {K0.shape[0]} DOFs, {len(zones)} zones, nnz(K) lower = {sp.tril(K0 + sum(zones)).nnz}")
    if args.reference:
        K = K0 + sum(zones)
        lam, phi = lowest(K, M, args.modes)
        f = hz(lam)
        # df/dp = (dλ/dp) / (8π² f), dλ/dp = φᵀ K_i φ (M-normalised φ, mass independent of p).
        sens = {f"zone{i}": [float(phi[:, k] @ (Z @ phi[:, k]) / (8 * np.pi**2 * f[k])) for k in range(args.modes)]
                for i, Z in enumerate(zones, 1)}
        with open(os.path.join(args.out, "scipy_reference.json"), "w") as fh:
            json.dump({"generator": f"scripts/plate_matrices.py --dofs {args.dofs} --zones {args.zones} --reference",
                       "solver": f"scipy {scipy.__version__} eigsh(K, {args.modes}, M, sigma=0)",
                       "frequencies_hz": f.tolist(), "sensitivities_hz": sens}, fh, indent=1)
    if args.measured:
        p = [float(v) for v in args.measured.split(",")]
        if len(p) != len(zones):
            sys.exit(f"--measured: {len(p)} values for {len(zones)} zones")
        K = K0 + sum(pi * Z for pi, Z in zip(p, zones))
        lam, phi = lowest(K, M, args.modes)
        if args.shapes:
            write_shapes(os.path.join(args.out, "shapes.csv"), phi, dof_map, nx, ny, args.shapes)
        with open(os.path.join(args.out, "measured.csv"), "w") as f:
            f.write(f"# scipy eigsh(K, {args.modes}, M, sigma=0) at zone factors {args.measured}\n")
            f.write("mode,frequency_hz\n")
            for k, f_hz in enumerate(hz(lam), 1):
                f.write(f"{k},{f_hz:.12g}\n")
        with open(os.path.join(args.out, "truth.json"), "w") as f:
            json.dump({"parameters": dict((f"zone{i}", v) for i, v in enumerate(p, 1))}, f)


if __name__ == "__main__":
    main()
