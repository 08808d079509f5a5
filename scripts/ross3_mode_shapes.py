"""ROSS 3's lateral mode shapes (each shaft node's complex x and y amplitude) and its orbits'
semi-axes, for eigenfit-rotordynamics' test of `shapes::RotorShapes` against ROSS.

Run once, outside CI, with ROSS 3 (see scripts/ross3_reference.py for the virtual environment):

    /work/venvs/ross3/bin/python scripts/ross3_mode_shapes.py

It reads the rotor files ROSS 3 saved (crates/eigenfit-rotordynamics/tests/data/ross3/
compressor.toml, pchip_speed.toml) back with `Rotor.load` and writes ross3_mode_shapes.json
beside them: per file and speed, the lowest lateral modes of `run_modal(sparse=False)` by damped
frequency with, per shaft node, x and y (re, im) of the eigenvector and ROSS's `Orbit` major
and minor axes and whirl. A shape is defined up to a complex factor; the test removes it.
"""

import json
import pathlib
import warnings

import numpy as np
import ross as rs

warnings.filterwarnings("ignore")
DATA = pathlib.Path(__file__).resolve().parent.parent / "crates/eigenfit-rotordynamics/tests/data/ross3"
MODES = 6
SPEEDS_RPM = [0.0, 3000.0, 9000.0]


def shapes(rotor, rpm):
    modal = rotor.run_modal(speed=rpm * np.pi / 30.0, num_modes=4 * MODES + 8, sparse=False)
    out = []
    for i in np.argsort(modal.wd):
        shape = modal.shapes[i]
        if shape.mode_type != "Lateral" or modal.wd[i] <= 0:
            continue
        nd = modal.number_dof
        vec = modal.modes[:, i]
        nodes = []
        for orbit in shape.orbits:
            x, y = vec[nd * orbit.node], vec[nd * orbit.node + 1]
            nodes.append(
                {
                    "node": int(orbit.node),
                    "x": [float(x.real), float(x.imag)],
                    "y": [float(y.real), float(y.imag)],
                    "major": float(orbit.major_axis),
                    "minor": float(orbit.minor_axis),
                    "whirl": orbit.whirl,
                }
            )
        out.append({"frequency_hz": float(modal.wd[i] / (2 * np.pi)), "whirl": shape.whirl, "nodes": nodes})
        if len(out) == MODES:
            break
    return out


def main():
    result = {"ross_version": rs.__version__, "files": {}}
    for name in ["compressor.toml", "pchip_speed.toml"]:
        rotor = rs.Rotor.load(DATA / name)
        result["files"][name] = [{"speed_rpm": rpm, "modes": shapes(rotor, rpm)} for rpm in SPEEDS_RPM]
    (DATA / "ross3_mode_shapes.json").write_text(json.dumps(result, separators=(",", ":")) + "\n")


if __name__ == "__main__":
    main()
