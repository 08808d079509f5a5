#!/usr/bin/env python3
"""Writes the corpus's clustered-spectrum matrices models (issue 28, repeated eigenvalues), each
larger than the dense solver's 4002 DOFs so the sparse solver must answer alone. Run from this
folder: python3 make_clusters.py"""
from pathlib import Path

N = 4100

def diagonal(name, values):
    lines = ["%%MatrixMarket matrix coordinate real symmetric", f"{N} {N} {N}"]
    lines += [f"{i + 1} {i + 1} {v:g}" for i, v in enumerate(values)]
    Path(name).write_text("\n".join(lines) + "\n")

# K = 1000·I, M = I: one eigenvalue of multiplicity 4100.
diagonal("cluster_k_repeated.mtx", [1000.0] * N)
# K = diag(1001, 1002, …): distinct eigenvalues 0.1 % apart, too close for shift-invert Lanczos.
diagonal("cluster_k_spread.mtx", [1001.0 + i for i in range(N)])
diagonal("cluster_m_identity.mtx", [1.0] * N)

for name, k in [("cluster_repeated.toml", "cluster_k_repeated.mtx"), ("cluster_spread.toml", "cluster_k_spread.mtx")]:
    Path(name).write_text(
        f"# Written by make_clusters.py: K from {k}, M = I ({N} DOFs), one parameter scaling K.\n"
        f'kind = "matrices"\nstiffness = "{k}"\nmass = "cluster_m_identity.mtx"\n\n'
        f'[[parameter]]\nname = "a"\nnominal = 0.0\nlower = -0.5\nupper = 1.0\nstiffness = "{k}"\n'
    )
