"""Writes the universal-file fixtures of tests/data/uff with pyuff, an independent UFF writer.

Run once, outside CI, from the repository root:
    python3 -m venv /tmp/uffenv && /tmp/uffenv/bin/pip install pyuff scipy
    /tmp/uffenv/bin/python tests/data/uff/generate.py

Outputs (committed):
* pyuff_datasets.unv + .json: datasets 164, 15, 2411, 55 (real 6-DOF and complex 3-DOF modes)
  and an ASCII FRF (58, to be skipped), with the values pyuff was given in the JSON.
* symmetric_rotor.unv + .json: a "test engineer's export" of symmetric_rotor.toml with
  bearings drive_end = 2.5e5 N/m, free_end = 0.8e5 N/m: three modes at five accelerometer
  nodes (coordinates in mm, dataset 164), horizontal channels too, noise on frequencies (0.1 %)
  and shapes (2 % of the largest entry), each shape scaled arbitrarily as test systems do.
  The modes come from a separate Euler-Bernoulli finite-element model written here in numpy
  (Hermite elements, consistent mass), not from eigenfit.
"""
import json
import os

import numpy as np
import pyuff
import scipy.linalg

HERE = os.path.dirname(os.path.abspath(__file__))


def rotor_modes(k_de, k_nde):
    """Modes of symmetric_rotor.toml: 10 elements, Ø14 mm steel, 1 kg disks at nodes 2 and 8."""
    E, rho, D, L, ne = 2.1e11, 7850.0, 0.014, 0.5, 10
    I, A, le = np.pi * D**4 / 64, np.pi * D**2 / 4, L / ne
    n = 2 * (ne + 1)
    K, M = np.zeros((n, n)), np.zeros((n, n))
    ke = E * I / le**3 * np.array([[12, 6 * le, -12, 6 * le], [6 * le, 4 * le**2, -6 * le, 2 * le**2],
                                    [-12, -6 * le, 12, -6 * le], [6 * le, 2 * le**2, -6 * le, 4 * le**2]])
    me = rho * A * le / 420 * np.array([[156, 22 * le, 54, -13 * le], [22 * le, 4 * le**2, 13 * le, -3 * le**2],
                                         [54, 13 * le, 156, -22 * le], [-13 * le, -3 * le**2, -22 * le, 4 * le**2]])
    for e in range(ne):
        K[2 * e:2 * e + 4, 2 * e:2 * e + 4] += ke
        M[2 * e:2 * e + 4, 2 * e:2 * e + 4] += me
    M[4, 4] += 1.0
    M[16, 16] += 1.0
    K[0, 0] += k_de
    K[20, 20] += k_nde
    lam, phi = scipy.linalg.eigh(K, M)
    return np.sqrt(lam) / (2 * np.pi), phi, le


def symmetric_rotor():
    rng = np.random.default_rng(14)
    f, phi, le = rotor_modes(2.5e5, 0.8e5)
    sensor_nodes = [0, 2, 5, 8, 10]
    labels = [101, 102, 103, 104, 105]
    z_mm = [1000.0 * le * i for i in sensor_nodes]
    path = os.path.join(HERE, "symmetric_rotor.unv")
    if os.path.exists(path):
        os.remove(path)
    uff = pyuff.UFF(path)
    uff.write_sets(pyuff.prepare_164(units_code=5, units_description="mm (milli newton)", temp_mode=1,
                                     length=1000.0, force=1000.0, temp=1.0, temp_offset=273.15), mode="add")
    # A geometry node nobody measured (label 900) must not disturb the mapping.
    uff.write_sets(pyuff.prepare_2411(node_nums=np.array(labels + [900]), def_cs=np.zeros(6, int),
                                      disp_cs=np.zeros(6, int), color=np.full(6, 8),
                                      x=np.zeros(6), y=np.zeros(6), z=np.array(z_mm + [650.0])), mode="add")
    written = []
    scales = [1.0, -3.7, 0.02]
    for k in range(3):
        y = phi[[2 * i for i in sensor_nodes], k]
        y = y + 0.02 * np.abs(y).max() * rng.standard_normal(len(y))
        y = y * scales[k]
        x = 0.4 * y + 0.05 * np.abs(y).max() * rng.standard_normal(len(y))  # horizontal plane: ignored
        freq = f[k] * (1 + 0.001 * rng.standard_normal())
        uff.write_sets(pyuff.prepare_55(id1="symmetric rotor, impact test", id2="mode %d" % (k + 1), id3="NONE",
                                        id4="NONE", id5="NONE", model_type=1, analysis_type=2, data_ch=2,
                                        spec_data_type=12, data_type=2, n_data_per_node=3, r1=x, r2=y,
                                        r3=np.zeros(len(y)), node_nums=np.array(labels), load_case=1,
                                        mode_n=k + 1, freq=freq, modal_m=0.0, modal_damp_vis=0.01,
                                        modal_damp_his=0.0), mode="add")
        written.append({"mode": k + 1, "frequency_hz": freq, "y": list(y), "x": list(x)})
    with open(os.path.join(HERE, "symmetric_rotor.json"), "w") as fh:
        json.dump({"truth": {"k_drive_end": 2.5e5, "k_free_end": 0.8e5},
                   "noise_free_frequencies_hz": list(f[:3]), "labels": labels, "z_m": [z / 1000 for z in z_mm],
                   "modes": written}, fh, indent=1)


def datasets():
    path = os.path.join(HERE, "pyuff_datasets.unv")
    if os.path.exists(path):
        os.remove(path)
    uff = pyuff.UFF(path)
    labels = np.array([1, 2, 3])
    xyz = np.array([[0.0, 0.1, 0.25], [0.5, -0.2, 1.0], [1.5, 2.5, -3.0]])
    uff.write_sets(pyuff.prepare_15(node_nums=labels, def_cs=np.zeros(3, int), disp_cs=np.zeros(3, int),
                                    color=np.ones(3, int), x=xyz[:, 0], y=xyz[:, 1], z=xyz[:, 2]), mode="add")
    uff.write_sets(pyuff.prepare_2411(node_nums=np.array([10, 11]), def_cs=np.zeros(2, int),
                                      disp_cs=np.zeros(2, int), color=np.ones(2, int), x=np.array([1.0 / 3, 7.0]),
                                      y=np.array([-2.0 / 7, 0.0]), z=np.array([1e-3, 123.456])), mode="add")
    r = np.array([[0.1, -0.2, 0.3, 1e-3, -2e-3, 3e-3], [1.5, 2.5, -3.5, 0.0, 0.0, 0.25],
                  [-1e-4, 2e4, 0.0, 0.0, 1.0, -1.0]])
    uff.write_sets(pyuff.prepare_55(id1="real mode", id2="NONE", id3="NONE", id4="NONE", id5="NONE",
                                    model_type=1, analysis_type=2, data_ch=3, spec_data_type=8, data_type=2,
                                    n_data_per_node=6, r1=r[:, 0], r2=r[:, 1], r3=r[:, 2], r4=r[:, 3], r5=r[:, 4],
                                    r6=r[:, 5], node_nums=labels, load_case=1, mode_n=4, freq=123.25, modal_m=2.5,
                                    modal_damp_vis=0.02, modal_damp_his=0.0), mode="add")
    c = np.array([[1 + 1j, 0.5 - 0.1j, 0.0], [2 + 2j, -1 + 0.3j, 0.1j]])
    eig = -0.02 * 2 * np.pi * 50 + 1j * 2 * np.pi * 50 * np.sqrt(1 - 0.02**2)
    uff.write_sets(pyuff.prepare_55(id1="complex mode", id2="NONE", id3="NONE", id4="NONE", id5="NONE",
                                    model_type=1, analysis_type=3, data_ch=2, spec_data_type=8, data_type=5,
                                    n_data_per_node=3, r1=c[:, 0], r2=c[:, 1], r3=c[:, 2], node_nums=labels[:2],
                                    load_case=1, mode_n=5, eig=eig, modal_a=0j, modal_b=0j), mode="add")
    freq = np.arange(0, 10.0)
    uff.write_sets(pyuff.prepare_58(binary=0, id1="an FRF", func_type=4, rsp_node=1, rsp_dir=2, ref_node=1,
                                    ref_dir=2, num_pts=10, abscissa_spacing=1, abscissa_min=0.0, abscissa_inc=1.0,
                                    data=freq * (1 + 1j), x=freq, ord_data_type=5, rsp_ent_name="pt",
                                    ref_ent_name="pt", abscissa_spec_data_type=18, ordinate_spec_data_type=12,
                                    orddenom_spec_data_type=13), mode="add")
    with open(os.path.join(HERE, "pyuff_datasets.json"), "w") as fh:
        json.dump({"nodes": {str(l): list(p) for l, p in zip(labels, xyz)} | {"10": [1.0 / 3, -2.0 / 7, 1e-3],
                                                                             "11": [7.0, 0.0, 123.456]},
                   "real_mode": {"number": 4, "frequency_hz": 123.25, "modal_mass": 2.5, "damping_ratio": 0.02,
                                 "values": r.tolist()},
                   "complex_mode": {"number": 5, "eigenvalue": [eig.real, eig.imag],
                                    "re": c.real.tolist(), "im": c.imag.tolist()}}, fh, indent=1)


if __name__ == "__main__":
    datasets()
    symmetric_rotor()
