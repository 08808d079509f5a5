"""A run-up measured on a ROSS rotor, for eigenfit's identification of bearing coefficients.

Run once, outside CI, in a virtual environment with ROSS (see scripts/ross_reference.py):

    /work/venvs/rotordyn/bin/python scripts/ross_runup_reference.py

It writes into crates/eigenfit-rotordynamics/tests/data/:
  * runup_nominal.toml: an asymmetric rotor (two different disks off centre) on two bearings
    with anisotropic, cross-coupled and damped coefficients, saved by ROSS `Rotor.save`: the
    model eigenfit starts from;
  * runup_truth.csv: ROSS's damped whirl frequencies (4 lowest lateral modes, Hz) at 6 speeds of
    the same rotor whose bearings' kxx, kyy, kxy, kyx, cxx, cyy are multiplied by known factors
    (the "measured" run-up), header speed_rpm,mode,frequency_hz,std_hz;
  * runup_truth.json: those factors, by eigenfit parameter name.

Bearing "DE" has coefficient tables that are cubic in speed, so ROSS's smoothing spline and any
factor on it are exact; bearing "NDE" has constant coefficients.
"""

import json
import pathlib
import warnings

import numpy as np
import ross as rs

warnings.filterwarnings("ignore")
OUT = pathlib.Path(__file__).resolve().parent.parent / "crates/eigenfit-rotordynamics/tests/data"
SPEEDS_RPM = [1000.0, 2500.0, 4000.0, 5500.0, 7000.0, 8500.0]
# The 4 lowest lateral modes: modes 5 and 6 of this rotor cross near 4000 rpm, and a fit of
# sorted frequencies through a crossing has a kinked residual in which Levenberg–Marquardt
# stalls from the nominal start (measured: see docs/rotordynamics.md).
MODES = 4
STD_HZ = 0.01
FACTORS = {
    "DE": {"kxx": 1.2, "kyy": 0.85, "kxy": 1.25, "kyx": 0.8, "cxx": 1.2, "cyy": 0.85},
    "NDE": {"kxx": 0.9, "kyy": 1.15, "kxy": 0.8, "kyx": 1.2, "cxx": 0.85, "cyy": 1.15},
}


def rotor(f):
    steel = rs.Material(name="steel_runup", rho=7810, E=211e9, G_s=81.2e9)
    shafts = [
        rs.ShaftElement(L=0.25, idl=0.0, odl=0.05, material=steel, n=i,
                        shear_effects=True, rotary_inertia=True, gyroscopic=True)
        for i in range(6)
    ]
    disks = [
        rs.DiskElement(n=2, m=32.59, Id=0.178, Ip=0.329, tag="Disk A"),
        rs.DiskElement(n=5, m=12.0, Id=0.05, Ip=0.09, tag="Disk B"),
    ]
    w = np.array([0.0, 300.0, 600.0, 900.0, 1200.0])
    s = w / 1000.0
    d = f["DE"]
    de = rs.BearingElement(
        n=0, tag="DE", frequency=w,
        kxx=d["kxx"] * 1.0e6 * (1 + 0.4 * s + 0.1 * s**3),
        kyy=d["kyy"] * 1.6e6 * (1 + 0.2 * s - 0.05 * s**2),
        kxy=d["kxy"] * 3.0e5 * (0.5 + s),
        kyx=d["kyx"] * -2.5e5 * (0.5 + s + 0.2 * s**2),
        cxx=d["cxx"] * 2500.0 * (1 + 0.3 * s),
        cyy=d["cyy"] * 3000.0 * (1 - 0.1 * s),
        cxy=200.0 * (1 + s), cyx=-150.0 * (1 + s),
    )
    n = f["NDE"]
    nde = rs.BearingElement(
        n=6, tag="NDE",
        kxx=n["kxx"] * 8.0e5, kyy=n["kyy"] * 1.3e6,
        kxy=n["kxy"] * 1.5e5, kyx=n["kyx"] * -1.2e5,
        cxx=n["cxx"] * 1800.0, cyy=n["cyy"] * 2200.0,
        cxy=100.0, cyx=-80.0,
    )
    return rs.Rotor(shafts, disks, [de, nde])


def lateral_frequencies(r, speed):
    modal = r.run_modal(speed=speed, num_modes=4 * MODES + 8, sparse=False)
    out = []
    for i in range(len(modal.wd)):
        if modal.shapes[i].mode_type != "Lateral" or modal.wd[i] <= 0:
            continue
        out.append(modal.wd[i] / (2 * np.pi))
        if len(out) == MODES:
            break
    return out


def main():
    ones = {b: {c: 1.0 for c in cs} for b, cs in FACTORS.items()}
    rotor(ones).save(OUT / "runup_nominal.toml")
    truth = rotor(FACTORS)
    rows = ["speed_rpm,mode,frequency_hz,std_hz"]
    for rpm in SPEEDS_RPM:
        for i, f in enumerate(lateral_frequencies(truth, rpm * np.pi / 30)):
            rows.append(f"{rpm},{i + 1},{float(f)!r},{STD_HZ}")
    (OUT / "runup_truth.csv").write_text("\n".join(rows) + "\n")
    names = {f"{c}_{b}": v for b, cs in FACTORS.items() for c, v in cs.items()}
    (OUT / "runup_truth.json").write_text(json.dumps({"ross_version": rs.__version__, "factors": names}, indent=1))
    print("wrote runup_nominal.toml, runup_truth.csv, runup_truth.json")


if __name__ == "__main__":
    main()
