"""Run-ups computed by ROSS for the realistic checks of issue 16: bearings estimated from a start
30–50 % off, and discovery of a hidden effect on a two-plane rotor.

Run once, outside CI, in a virtual environment with ROSS (see scripts/ross_reference.py):

    /work/venvs/rotordyn/bin/python scripts/ross_realistic_runups.py

It writes into crates/eigenfit-rotordynamics/tests/data/ (ROSS's damped lateral whirl
frequencies, Hz, and whirl, header speed_rpm,mode,frequency_hz,std_hz,whirl; the 6 lowest
lateral modes with damping ratio below 0.35 — a run-up shows no peak for more damped ones —
numbered in ascending damped frequency; noise-free unless said otherwise):
  * compressor_start.toml: ROSS's compressor example (compressor.toml) with its two bearings'
    kxx and kyy tables multiplied by 1.4, 0.6 (Bearing 0) and 0.65, 1.45 (Bearing 13), saved by
    ROSS: what a user who does not know the bearings starts from;
  * compressor_runup.csv: the 6 lowest modes at 6 speeds of compressor.toml as it is (the truth);
  * runup_start.toml: the rotor of scripts/ross_runup_reference.py with all twelve coefficients
    (kxx kyy kxy kyx cxx cyy of both bearings) 30–50 % away from runup_truth's;
  * runup_truth6.csv: the 6 lowest modes (5 and 6 cross near 4000 rpm) at 10 speeds of the
    truth rotor (the factors of runup_truth.json);
  * discovery_*.csv: 6 modes at 6 speeds of runup_nominal.toml's rotor with a hidden effect,
    Gaussian noise of std_hz = 0.02 added (seeded): `disk` a 4 kg hub (Id 0.01, Ip 0.02 kg·m²)
    at node 4, `shaft` element 3 with E × 0.7, `clean` nothing hidden (the control);
  * realistic_runups.json: the factors, the hidden effects and the ROSS version.
"""

import importlib.util
import json
import pathlib
import warnings

import numpy as np
import ross as rs

warnings.filterwarnings("ignore")
HERE = pathlib.Path(__file__).resolve().parent
OUT = HERE.parent / "crates/eigenfit-rotordynamics/tests/data"
spec = importlib.util.spec_from_file_location("runup_ref", HERE / "ross_runup_reference.py")
ref = importlib.util.module_from_spec(spec)
spec.loader.exec_module(ref)

COMPRESSOR_START = {"Bearing 0": {"kxx": 1.4, "kyy": 0.6}, "Bearing 13": {"kxx": 0.65, "kyy": 1.45}}
COMPRESSOR_SPEEDS = [1000.0, 2500.0, 4000.0, 5500.0, 7000.0, 8500.0]
RUNUP_START = {
    "DE": {"kxx": 0.75, "kyy": 1.3, "kxy": 0.7, "kyx": 1.2, "cxx": 0.7, "cyy": 1.3},
    "NDE": {"kxx": 1.35, "kyy": 0.75, "kxy": 1.2, "kyx": 0.8, "cxx": 1.3, "cyy": 0.75},
}
RUNUP_SPEEDS = [500.0, 1000.0, 1750.0, 2500.0, 3250.0, 4000.0, 4750.0, 5500.0, 7000.0, 8500.0]
DISCOVERY_SPEEDS = [1000.0, 2500.0, 4000.0, 5500.0, 7000.0, 8500.0]
DISCOVERY_STD = 0.02
MODES = 6
# Modes damped beyond this show no resonance peak in a run-up and are not "measured".
ZETA_SHOWN = 0.35


def lateral(r, rpm, modes=MODES):
    """The `modes` lowest lateral modes a run-up shows: damped frequency (Hz) ascending and whirl
    (scripts/ross_reference.py's moving-node rule), leaving out modes damped beyond ZETA_SHOWN
    (no resonance peak: the compressor's seals add modes with damping ratios 0.5-0.95)."""
    modal = r.run_modal(speed=rpm * np.pi / 30, num_modes=4 * modes + 24, sparse=False)
    out = []
    nd = r.number_dof
    for i in range(len(modal.wd)):
        shape = modal.shapes[i]
        if shape.mode_type != "Lateral" or modal.wd[i] <= 0 or modal.damping_ratio[i] >= ZETA_SHOWN:
            continue
        evec = modal.evectors[:, i]
        amp = np.array([np.hypot(abs(evec[nd * n]), abs(evec[nd * n + 1])) for n in range(len(r.nodes))])
        kappas = [o.kappa for o, a in zip(shape.orbits, amp) if a >= 1e-6 * amp.max()]
        whirl = "forward" if all(k > 0 for k in kappas) else "backward" if all(k < 0 for k in kappas) else "mixed"
        out.append((float(modal.wd[i] / (2 * np.pi)), whirl))
    out.sort()
    return out[:modes]


def write_runup(name, r, speeds, std, rng=None):
    rows = ["speed_rpm,mode,frequency_hz,std_hz,whirl"]
    for rpm in speeds:
        for i, (f, whirl) in enumerate(lateral(r, rpm)):
            if rng is not None:
                f += rng.normal(0.0, std)
            rows.append(f"{rpm},{i + 1},{f!r},{std},{whirl}")
    (OUT / name).write_text("\n".join(rows) + "\n")
    print("wrote", name)


def scaled_bearing(b, factors):
    keys = ["kxx", "kyy", "kxy", "kyx", "cxx", "cyy", "cxy", "cyx", "mxx", "myy", "mxy", "myx"]
    args = {k: np.asarray(getattr(b, k)) * factors.get(k, 1.0) for k in keys}
    return rs.BearingElement(n=b.n, frequency=b.frequency, tag=b.tag, n_link=b.n_link,
                             scale_factor=b.scale_factor, **args)


def main():
    compressor = rs.Rotor.load(OUT / "compressor.toml")
    bearings = [scaled_bearing(b, COMPRESSOR_START[b.tag]) if b.tag in COMPRESSOR_START else b
                for b in compressor.bearing_elements]
    start = rs.Rotor(compressor.shaft_elements, compressor.disk_elements, bearings,
                     compressor.point_mass_elements)
    start.save(OUT / "compressor_start.toml")
    write_runup("compressor_runup.csv", compressor, COMPRESSOR_SPEEDS, 0.05)

    ref.rotor(RUNUP_START).save(OUT / "runup_start.toml")
    write_runup("runup_truth6.csv", ref.rotor(ref.FACTORS), RUNUP_SPEEDS, 0.01)

    ones = {b: {c: 1.0 for c in cs} for b, cs in ref.FACTORS.items()}
    nominal = ref.rotor(ones)
    hub = rs.DiskElement(n=4, m=4.0, Id=0.01, Ip=0.02, tag="hidden hub")
    with_hub = rs.Rotor(nominal.shaft_elements, nominal.disk_elements + [hub], nominal.bearing_elements)
    weak = rs.Material(name="steel_weak", rho=7810, E=0.7 * 211e9, G_s=0.7 * 81.2e9)
    shafts = [rs.ShaftElement(L=0.25, idl=0.0, odl=0.05, material=weak if i == 3 else s.material, n=i,
                              shear_effects=True, rotary_inertia=True, gyroscopic=True)
              for i, s in enumerate(nominal.shaft_elements)]
    with_crack = rs.Rotor(shafts, nominal.disk_elements, nominal.bearing_elements)
    rng = np.random.default_rng(16)
    write_runup("discovery_disk.csv", with_hub, DISCOVERY_SPEEDS, DISCOVERY_STD, rng)
    write_runup("discovery_shaft.csv", with_crack, DISCOVERY_SPEEDS, DISCOVERY_STD, rng)
    write_runup("discovery_clean.csv", nominal, DISCOVERY_SPEEDS, DISCOVERY_STD, rng)

    truth = {
        "ross_version": rs.__version__,
        "compressor_start_factors": COMPRESSOR_START,
        "runup_truth_over_start": {
            f"{c}_{b}": ref.FACTORS[b][c] / RUNUP_START[b][c] for b in RUNUP_START for c in RUNUP_START[b]
        },
        "hidden": {
            "discovery_disk.csv": {"kind": "disk", "node": 4, "m": 4.0, "Id": 0.01, "Ip": 0.02},
            "discovery_shaft.csv": {"kind": "shaft-stiffness", "element": 3, "E_factor": 0.7},
            "discovery_clean.csv": None,
        },
    }
    (OUT / "realistic_runups.json").write_text(json.dumps(truth, indent=1) + "\n")
    print("wrote realistic_runups.json")


if __name__ == "__main__":
    main()
