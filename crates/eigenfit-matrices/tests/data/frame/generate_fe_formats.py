#!/usr/bin/env python3
"""The plane frame of generate.py in the FE codes' own formats (issue 29, item 6).

* Nastran DMIG, written by pyNastran (an independent writer): `dmig/frame_small.pch` in small
  field (TIN = 1, 8-character fields) and `dmig/frame_large.pch` in large field (TIN = 2,
  16-character fields, D exponents), each with the frame's GRID cards and one DMIG per matrix
  (K0 the top tie, MAAX, one per parameter); `dmig/model_small.toml` and `dmig/model_large.toml`
  name them as `frame_small.pch#NAME`.
* Abaqus `*MATRIX OUTPUT` in the matrix input format, written here from the Abaqus manual's
  description (one entry a line, `row node, row dof, column node, column dof, value`, the lower
  triangle of a symmetric matrix, `**` comments): `abaqus/frame_*.mtx`, with `abaqus/nodes.csv`
  for the coordinates Abaqus does not write there, and `abaqus/model.toml`.

The DOFs are labelled (grid, component): 1 = x, 2 = y, 6 = rz — sorted by grid and component
they are the Matrix Market model's DOFs in the same order, so its `shapes.csv` applies.

    /work/venvs/matrices/bin/pip install numpy scipy pyNastran
    /work/venvs/matrices/bin/python generate_fe_formats.py      # after generate.py
"""
import os

import numpy as np
import scipy.io
from pyNastran.bdf.bdf import BDF

HERE = os.path.dirname(os.path.abspath(__file__))
COMPONENT = {"x": 1, "y": 2, "rz": 6}
PARAMS = ["story1", "story2", "story3", "beams"]

dofs = []  # (node, component, x, y) in model order
with open(os.path.join(HERE, "dofs.csv")) as fh:
    next(fh)
    for line in fh:
        _, node, d, x, y, _z = line.strip().split(",")
        dofs.append((int(node), COMPONENT[d], float(x), float(y)))
labels = [(n, c) for n, c, _, _ in dofs]
assert labels == sorted(labels), "the model's DOFs are in label order"


def read(name):
    return scipy.io.mmread(os.path.join(HERE, name)).toarray()


def full(a):
    # mmread of a `symmetric` file returns the whole matrix already.
    return a


matrices = {
    "K0": full(read("K0a.mtx")) + full(read("K0b.mtx")),
    "MAAX": full(read("M0.mtx")),
    "KSTORY1": full(read("K_story1_left.mtx")) + full(read("K_story1_rest.mtx")),
    "KSTORY2": full(read("K_story2.mtx")),
    "KSTORY3": full(read("K_story3.mtx")),
    "KBEAMS": full(read("K_beams.mtx")),
}
nodes = {}
for n, _, x, y in dofs:
    nodes[n] = (x, y)


def lower(a):
    """(row label, column label, value) of the lower triangle, by column."""
    out = []
    for j in range(a.shape[0]):
        for i in range(j, a.shape[0]):
            if a[i, j] != 0.0:
                out.append((labels[i], labels[j], a[i, j]))
    return out


os.makedirs(os.path.join(HERE, "dmig"), exist_ok=True)
for size, tin, tag in [(8, 1, "small"), (16, 2, "large")]:
    model = BDF(debug=False)
    for n, (x, y) in nodes.items():
        model.add_grid(n, [x, y, 0.0])
    for name, a in matrices.items():
        entries = lower(a)
        model.add_dmig(name, 6, tin, tin, 0, len(labels),
                       GCj=[e[1] for e in entries], GCi=[e[0] for e in entries],
                       Real=[e[2] for e in entries])
    model.write_bdf(os.path.join(HERE, "dmig", f"frame_{tag}.pch"), size=size, is_double=(tin == 2))
    pch = f"frame_{tag}.pch"
    text = f'''# The plane frame as Nastran DMIG ({tag} field), written by generate_fe_formats.py.
kind = "matrices"
name = "plane frame, DMIG {tag} field"
format = "dmig"
stiffness = "{pch}#K0"
mass = "{pch}#MAAX"
'''
    for p in PARAMS:
        text += f'''
[[parameter]]
name = "{p}"
nominal = 1.0
lower = 0.1
upper = 10.0
scale = "log"
stiffness = "{pch}#K{p.upper()}"
'''
    with open(os.path.join(HERE, "dmig", f"model_{tag}.toml"), "w") as fh:
        fh.write(text)

os.makedirs(os.path.join(HERE, "abaqus"), exist_ok=True)
files = {"K0": "frame_STIF_tie.mtx", "MAAX": "frame_MASS1.mtx"}
files.update({f"K{p.upper()}": f"frame_STIF_{p}.mtx" for p in PARAMS})
for name, a in matrices.items():
    with open(os.path.join(HERE, "abaqus", files[name]), "w") as fh:
        fh.write(f"** {name} of the plane frame, Abaqus matrix input format\n")
        for (ni, ci), (nj, cj), v in lower(a):
            fh.write(f"{ni},{ci}, {nj},{cj}, {v:.15e}\n")
with open(os.path.join(HERE, "abaqus", "nodes.csv"), "w") as fh:
    fh.write("node,x,y,z\n")
    for n, (x, y) in nodes.items():
        fh.write(f"{n},{x},{y},0\n")
text = '''# The plane frame as Abaqus *MATRIX OUTPUT files, written by generate_fe_formats.py.
kind = "matrices"
name = "plane frame, Abaqus matrix output"
format = "abaqus"
stiffness = "frame_STIF_tie.mtx"
mass = "frame_MASS1.mtx"
nodes = "nodes.csv"
'''
for p in PARAMS:
    text += f'''
[[parameter]]
name = "{p}"
nominal = 1.0
lower = 0.1
upper = 10.0
scale = "log"
stiffness = "frame_STIF_{p}.mtx"
'''
with open(os.path.join(HERE, "abaqus", "model.toml"), "w") as fh:
    fh.write(text)
print("written", len(labels), "DOFs")
