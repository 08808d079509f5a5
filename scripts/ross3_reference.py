"""Rotor files saved by ROSS 3 and ROSS 3's modal and Campbell results, for eigenfit-rotordynamics'
tests (ROSS 3 reads bearing tables by PCHIP or linear interpolation with linear extrapolation from
the end slope, over `speed`, over whirl `frequency`, or over both).

Run once, outside CI, in a virtual environment with ROSS 3 (Python >= 3.12):

    ~/.pyenv/versions/3.12.1/bin/python -m venv /work/venvs/ross3
    /work/venvs/ross3/bin/pip install ross-rotordynamics
    /work/venvs/ross3/bin/python scripts/ross3_reference.py

It writes into crates/eigenfit-rotordynamics/tests/data/ross3/:
  * compressor.toml, compressor.json: ROSS 3's `compressor_example()` as `Rotor.save` writes it
    (bearing and seal tables over `speed`, PCHIP);
  * pchip_speed.toml: a rotor whose bearing tables over `speed` are not polynomials (non-monotone,
    with a flat stretch), so PCHIP's shape rules and its end-slope extrapolation matter;
  * linear_speed.json: the same rotor with `interpolation = "linear"`;
  * frequency_table.toml: a bearing whose coefficients are a table over whirl `frequency` (as a
    magnetic bearing or a squeeze-film damper), beside one over `speed`;
  * grid_table.toml: a bearing with a 2-D table over `speed` and `frequency`;
  * pchip_speed_start.toml and pchip_speed_runup.csv: the PCHIP rotor with its bearings' kxx,
    kyy off (DE x0.7, NDE x1.35), and the true rotor's 4 lowest lateral whirl frequencies from
    2000 to 9000 rpm (ROSS 3's run_modal; std_hz 1e-3 Hz) for `estimate --write-model`;
  * ross3_reference.json: for every file, read back by `Rotor.load`, ROSS 3's damped frequencies
    (Hz), damping ratios and log decrements of the lowest lateral modes at speeds inside and outside
    the tables: `run_modal(sparse=False)` for speed tables; for whirl-frequency and 2-D tables
    `run_modal(matched_whirl=True, whirl_rtol=1e-13)` (each mode at its own whirl frequency,
    iterated to the fixed point; ROSS's default tolerance 1e-3 stops short of it); and
    `run_campbell` on the compressor and the frequency-table rotor (its modal results per speed).

ROSS (>= 1.5) also has axial and torsional DOFs; their modes are dropped (eigenfit's model is
lateral, 4 DOF per node, and they are uncoupled from the lateral ones).
"""

import json
import pathlib
import warnings

import numpy as np
import ross as rs

warnings.filterwarnings("ignore")
OUT = pathlib.Path(__file__).resolve().parent.parent / "crates/eigenfit-rotordynamics/tests/data/ross3"
OUT.mkdir(parents=True, exist_ok=True)
LATERAL_MODES = 8
RPM = np.pi / 30.0


def shafts():
    steel = rs.Material(name="steel_ref3", rho=7810, E=211e9, G_s=81.2e9)
    geometry = [
        # L, idl, odl, idr, odr
        (0.25, 0.0, 0.05, 0.0, 0.05),
        (0.25, 0.0, 0.05, 0.0, 0.06),
        (0.25, 0.01, 0.06, 0.02, 0.07),
        (0.25, 0.02, 0.07, 0.02, 0.07),
        (0.25, 0.0, 0.06, 0.0, 0.05),
        (0.25, 0.0, 0.05, 0.0, 0.05),
    ]
    return [
        rs.ShaftElement(L=L, idl=idl, odl=odl, idr=idr, odr=odr, material=steel, n=i)
        for i, (L, idl, odl, idr, odr) in enumerate(geometry)
    ]


def disks():
    return [
        rs.DiskElement(n=2, m=32.59, Id=0.178, Ip=0.329, tag="Disk A"),
        rs.DiskElement(n=4, m=20.0, Id=0.1, Ip=0.18, tag="Disk B"),
    ]


# Speeds (rad/s) of the speed tables: 100-1000 rad/s, unevenly spaced.
SPEED_AXIS = np.array([100.0, 250.0, 400.0, 600.0, 800.0, 1000.0])


def speed_table_rotor(interpolation):
    """Bearing tables over speed that are not polynomials: a maximum inside (PCHIP sets a zero
    slope there), a flat stretch, a sign change in the cross terms."""
    b0 = rs.BearingElement(
        n=0, tag="DE",
        kxx=[1.0e6, 1.3e6, 1.45e6, 1.4e6, 1.2e6, 1.1e6],
        kyy=[1.4e6, 1.4e6, 1.4e6, 1.6e6, 2.1e6, 2.3e6],
        kxy=[-1.0e5, 0.0, 1.5e5, 3.0e5, 6.0e5, 6.5e5],
        kyx=[1.0e5, 0.0, -1.5e5, -3.0e5, -6.0e5, -6.5e5],
        cxx=[500.0, 620.0, 700.0, 760.0, 780.0, 790.0],
        cyy=[600.0, 580.0, 610.0, 700.0, 820.0, 1000.0],
        cxy=[40.0, 20.0, -10.0, -30.0, -35.0, -60.0],
        cyx=[-40.0, -20.0, 10.0, 30.0, 35.0, 60.0],
        speed=SPEED_AXIS,
        interpolation=interpolation,
    )
    b1 = rs.BearingElement(
        n=6, tag="NDE",
        kxx=[8.0e5, 8.4e5, 9.0e5, 9.9e5, 1.05e6, 1.08e6],
        kyy=[1.1e6, 1.15e6, 1.2e6, 1.3e6, 1.3e6, 1.35e6],
        cxx=[300.0, 320.0, 330.0, 345.0, 350.0, 352.0],
        cyy=[350.0, 360.0, 380.0, 390.0, 420.0, 430.0],
        speed=SPEED_AXIS,
        interpolation=interpolation,
    )
    return rs.Rotor(shafts(), disks(), [b0, b1])


def off_rotor(de, nde):
    """The PCHIP rotor with kxx and kyy of DE times `de`, of NDE times `nde`."""
    rotor = speed_table_rotor("pchip")
    bearings = []
    for b, f in zip(rotor.bearing_elements, [de, nde]):
        args = {c: list(getattr(b, c)) for c in ["kxx", "kyy", "kxy", "kyx", "cxx", "cyy", "cxy", "cyx"]}
        args["kxx"] = [v * f for v in args["kxx"]]
        args["kyy"] = [v * f for v in args["kyy"]]
        bearings.append(rs.BearingElement(n=b.n, tag=b.tag, speed=SPEED_AXIS, interpolation="pchip", **args))
    return rs.Rotor(shafts(), disks(), bearings)


# Whirl frequencies (rad/s) of the frequency tables: 50-900 rad/s.
FREQUENCY_AXIS = np.array([50.0, 150.0, 300.0, 500.0, 700.0, 900.0])


def frequency_table_rotor():
    """A bearing whose stiffness rises and damping falls with the whirl frequency (a magnetic
    bearing's controller), beside a fluid-film bearing tabulated over speed."""
    magnetic = rs.BearingElement(
        n=0, tag="AMB",
        kxx=[6.0e5, 7.0e5, 9.0e5, 1.2e6, 1.4e6, 1.5e6],
        kyy=[6.5e5, 7.5e5, 9.5e5, 1.25e6, 1.45e6, 1.55e6],
        cxx=[900.0, 850.0, 700.0, 500.0, 380.0, 300.0],
        cyy=[950.0, 880.0, 720.0, 520.0, 400.0, 320.0],
        frequency=FREQUENCY_AXIS,
    )
    b1 = rs.BearingElement(
        n=6, tag="NDE",
        kxx=[8.0e5, 8.4e5, 9.0e5, 9.9e5, 1.05e6, 1.08e6],
        kyy=[1.1e6, 1.15e6, 1.2e6, 1.3e6, 1.3e6, 1.35e6],
        kxy=[0.0, 2.0e4, 5.0e4, 8.0e4, 1.2e5, 1.5e5],
        kyx=[0.0, -2.0e4, -5.0e4, -8.0e4, -1.2e5, -1.5e5],
        cxx=[300.0, 320.0, 330.0, 345.0, 350.0, 352.0],
        cyy=[350.0, 360.0, 380.0, 390.0, 420.0, 430.0],
        speed=SPEED_AXIS,
    )
    return rs.Rotor(shafts(), disks(), [magnetic, b1])


GRID_SPEED = np.array([0.0, 300.0, 600.0, 900.0, 1200.0])
GRID_FREQUENCY = np.array([50.0, 200.0, 400.0, 700.0])


def grid_table_rotor():
    """A bearing with a 2-D table over speed (rows) and whirl frequency (columns)."""
    s = GRID_SPEED[:, None] / 1000.0
    f = GRID_FREQUENCY[None, :] / 1000.0
    grid = rs.BearingElement(
        n=0, tag="Grid",
        kxx=1.0e6 * (1.0 + 0.4 * s + 0.6 * f**2 + 0.3 * np.sin(3 * s * f)),
        kyy=1.2e6 * (1.0 + 0.2 * s + 0.8 * f - 0.2 * f**2),
        kxy=2.0e5 * s * (1.0 + f),
        kyx=-2.0e5 * s * (1.0 + f),
        cxx=600.0 * (1.0 + 0.5 * s - 0.4 * f),
        cyy=650.0 * (1.0 + 0.3 * s - 0.3 * f),
        speed=GRID_SPEED,
        frequency=GRID_FREQUENCY,
    )
    b1 = rs.BearingElement(n=6, tag="NDE", kxx=9.0e5, kyy=1.2e6, cxx=320.0, cyy=380.0)
    return rs.Rotor(shafts(), disks(), [grid, b1])


def lateral(modal):
    """The lowest LATERAL_MODES lateral modes with positive damped frequency, by frequency."""
    out = []
    order = np.argsort(modal.wd)
    for i in order:
        if modal.shapes[i].mode_type != "Lateral" or modal.wd[i] <= 0:
            continue
        out.append(
            {
                "frequency_hz": float(modal.wd[i] / (2 * np.pi)),
                "damping_ratio": float(modal.damping_ratio[i]),
                "log_dec": float(modal.log_dec[i]),
            }
        )
    return out[:LATERAL_MODES]


def modal(rotor, speed, matched):
    if matched:
        m = rotor.run_modal(
            speed=speed, num_modes=2 * (LATERAL_MODES + 8), sparse=False,
            matched_whirl=True, whirl_rtol=1e-13, whirl_max_iter=200,
        )
    else:
        m = rotor.run_modal(speed=speed, num_modes=4 * LATERAL_MODES + 8, sparse=False)
    return lateral(m)


def main():
    files = {
        "compressor.toml": (rs.compressor_example(), False),
        "compressor.json": (rs.compressor_example(), False),
        "pchip_speed.toml": (speed_table_rotor("pchip"), False),
        "linear_speed.json": (speed_table_rotor("linear"), False),
        "frequency_table.toml": (frequency_table_rotor(), True),
        "grid_table.toml": (grid_table_rotor(), True),
    }
    speeds_rpm = {
        # The compressor's tables start at 2000-3000 rpm: 0 and 1000 rpm are extrapolated
        # below, 15 000 rpm above.
        "compressor": [0.0, 1000.0, 3000.0, 6000.0, 9000.0, 15000.0],
        # Tables over 100-1000 rad/s (955-9549 rpm): 0 and 12 000 rpm are outside.
        "other": [0.0, 1500.0, 3000.0, 5000.0, 7000.0, 9000.0, 12000.0],
    }
    reference = {"ross_version": rs.__version__, "files": {}}
    for name, (rotor, matched) in files.items():
        path = OUT / name
        path.unlink(missing_ok=True)
        rotor.save(path)
        loaded = rs.Rotor.load(path)  # the file must load in ROSS; the numbers are its own
        rpms = speeds_rpm["compressor" if name.startswith("compressor") else "other"]
        reference["files"][name] = {
            "matched_whirl": matched,
            "speeds_rpm": rpms,
            "modes": [modal(loaded, rpm * RPM, matched) for rpm in rpms],
        }
        print(name, "done")
    # A run-up of the PCHIP rotor and a start with its bearings off.
    truth = rs.Rotor.load(OUT / "pchip_speed.toml")
    rows = ["speed_rpm,mode,frequency_hz,std_hz"]
    for rpm in range(2000, 9001, 1000):
        for mode, m in enumerate(lateral(truth.run_modal(speed=rpm * RPM, num_modes=40, sparse=False))[:4]):
            rows.append(f"{rpm},{mode + 1},{m['frequency_hz']!r},0.001")
    (OUT / "pchip_speed_runup.csv").write_text("\n".join(rows) + "\n")
    start_path = OUT / "pchip_speed_start.toml"
    start_path.unlink(missing_ok=True)
    off_rotor(0.7, 1.35).save(start_path)
    # Campbell diagrams: ROSS 3's run_campbell (its modal results at each speed).
    campbell = {}
    for name, count, matched in [("compressor.toml", 6, False), ("frequency_table.toml", 6, True)]:
        loaded = rs.Rotor.load(OUT / name)
        rpms = np.linspace(0.0, 12000.0, 7)
        kwargs = dict(matched_whirl=True, whirl_rtol=1e-13, whirl_max_iter=200) if matched else {}
        result = loaded.run_campbell(rpms * RPM, frequencies=2 * count + 8, **kwargs)
        campbell[name] = {
            "speeds": "0:12000:7",
            "modes": count,
            "matched_whirl": matched,
            "frequencies_hz": [
                [m["frequency_hz"] for m in lateral(result.modal_results[w])][:count]
                for w in rpms * RPM
            ],
        }
    reference["campbell"] = campbell
    (OUT / "ross3_reference.json").write_text(json.dumps(reference, indent=1))
    print("wrote", sorted(p.name for p in OUT.iterdir()))


if __name__ == "__main__":
    main()
