"""Reference rotors and modal results from ROSS for eigenfit-rotordynamics' tests.

Run once, outside CI, in a virtual environment with ROSS:

    python3 -m venv /work/venvs/rotordyn
    /work/venvs/rotordyn/bin/pip install ross-rotordynamics "plotly<6"
    /work/venvs/rotordyn/bin/python scripts/ross_reference.py

It writes into crates/eigenfit-rotordynamics/tests/data/:
  * rotor files saved by ROSS `Rotor.save` (TOML and JSON): ROSS's compressor example,
    rotor_example, and a rotor with speed-dependent cross-coupled bearings, a support point
    mass, tapered/hollow elements, an Euler-Bernoulli element and an axial force;
  * a "version 3" copy of the latter whose bearing tables are keyed `speed` instead of
    `frequency` (ROSS 3 spelling);
  * ross_reference.json: for every rotor and several speeds, ROSS's damped natural frequencies
    (Hz), damping ratios, log decrements and whirl of the lowest lateral modes
    (ROSS >= 1.5 also has axial and torsional DOFs; their modes are dropped here because
    eigenfit's model is lateral, 4 DOF per node, and they are uncoupled from the lateral ones).

The speed-dependent bearing coefficients are cubic polynomials in speed: ROSS fits tables with
scipy's smoothing UnivariateSpline, eigenfit with an interpolating cubic; on a cubic both are
exact, so the comparison tests the element formulation, not the curve fit.
"""

import json
import pathlib
import warnings

import numpy as np
import ross as rs

warnings.filterwarnings("ignore")
OUT = pathlib.Path(__file__).resolve().parent.parent / "crates/eigenfit-rotordynamics/tests/data"
OUT.mkdir(parents=True, exist_ok=True)
LATERAL_MODES = 8
COEFFICIENTS = ["kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy", "mxx", "mxy", "myx", "myy"]


def speed_bearing_rotor():
    steel = rs.Material(name="steel_ref", rho=7810, E=211e9, G_s=81.2e9)
    shafts = []
    geometry = [
        # L, idl, odl, idr, odr, shear, rotary
        (0.25, 0.0, 0.05, 0.0, 0.05, True, True),
        (0.25, 0.0, 0.05, 0.0, 0.06, True, True),  # tapered
        (0.25, 0.01, 0.06, 0.02, 0.07, True, True),  # hollow, tapered
        (0.25, 0.02, 0.07, 0.02, 0.07, False, False),  # Euler-Bernoulli, no rotary inertia
        (0.25, 0.0, 0.06, 0.0, 0.05, True, True),
        (0.25, 0.0, 0.05, 0.0, 0.05, True, True),
    ]
    for i, (L, idl, odl, idr, odr, shear, rot) in enumerate(geometry):
        shafts.append(
            rs.ShaftElement(
                L=L, idl=idl, odl=odl, idr=idr, odr=odr, material=steel, n=i,
                shear_effects=shear, rotary_inertia=rot, gyroscopic=True,
                axial_force=2000.0 if i == 4 else 0.0,
                shear_method_calc="hutchinson" if i == 5 else "cowper",
            )
        )
    disks = [
        rs.DiskElement(n=2, m=32.59, Id=0.178, Ip=0.329, tag="Disk A"),
        rs.DiskElement(n=4, m=20.0, Id=0.1, Ip=0.18, tag="Disk B"),
    ]
    w = np.array([0.0, 200.0, 400.0, 600.0, 800.0, 1000.0])
    s = w / 1000.0
    b0 = rs.BearingElement(
        n=0, tag="DE",
        kxx=1.0e6 * (1 + 0.5 * s + 0.2 * s**2 - 0.1 * s**3),
        kyy=1.4e6 * (1 + 0.3 * s + 0.1 * s**3),
        kxy=2.0e5 * (s + 0.5 * s**2),
        kyx=-2.0e5 * (s + 0.5 * s**2),
        cxx=500.0 * (1 + s), cyy=600.0 * (1 + 0.5 * s**2),
        cxy=50.0 * s, cyx=-40.0 * s,
        frequency=w,
    )
    b1 = rs.BearingElement(n=6, n_link=7, tag="NDE", kxx=8.0e5, kyy=1.1e6, cxx=300.0, cyy=350.0)
    support = rs.BearingElement(n=7, tag="NDE support", kxx=5.0e7, kyy=6.0e7, cxx=1000.0, cyy=1200.0)
    mass = rs.PointMass(n=7, m=5.0, tag="NDE housing")
    return rs.Rotor(shafts, disks, [b0, b1, support], [mass])


def lateral_modes(rotor, speed):
    modal = rotor.run_modal(speed=speed, num_modes=4 * LATERAL_MODES + 8, sparse=False)
    out = []
    for i in range(len(modal.wd)):
        shape = modal.shapes[i]
        if shape.mode_type != "Lateral" or modal.wd[i] <= 0:
            continue
        # ROSS's whirl counts every node, also the nodes of the mode shape whose orbit is
        # round-off; the same rule over the nodes that move (amplitude >= 1e-6 of the largest):
        evec = modal.evectors[:, i]
        nd = rotor.number_dof
        amp = np.array([np.hypot(abs(evec[nd * n]), abs(evec[nd * n + 1])) for n in range(len(rotor.nodes))])
        kappas = [o.kappa for o, a in zip(shape.orbits, amp) if a >= 1e-6 * amp.max()]
        moving = "forward" if all(k > 0 for k in kappas) else "backward" if all(k < 0 for k in kappas) else "mixed"
        out.append(
            {
                "frequency_hz": modal.wd[i] / (2 * np.pi),
                "damping_ratio": modal.damping_ratio[i],
                "log_dec": modal.log_dec[i],
                "whirl": shape.whirl.lower(),
                "whirl_moving_nodes": moving,
            }
        )
        if len(out) == LATERAL_MODES:
            break
    return out


def main():
    rotors = {
        "compressor": (rs.compressor_example(), [0.0, 300.0, 600.0, 900.0, 1200.0]),
        "rotor_example": (rs.rotor_example(), [0.0, 200.0, 500.0, 1000.0]),
        "speed_bearing": (speed_bearing_rotor(), [0.0, 150.0, 450.0, 700.0, 950.0]),
    }
    reference = {"ross_version": rs.__version__, "rotors": {}}
    for name, (rotor, speeds) in rotors.items():
        rotor.save(OUT / f"{name}.toml")
        rotor.save(OUT / f"{name}.json")
        reference["rotors"][name] = {
            "speeds_rad_s": speeds,
            "modes": [lateral_modes(rotor, w) for w in speeds],
            # The coefficients ROSS used at each speed (its smoothing-spline fit of the tables),
            # so a test can check the element formulation apart from the curve fit.
            "bearing_coefficients": [
                {
                    b.tag: {c: float(getattr(b, f"{c}_interpolated")(w)) for c in COEFFICIENTS}
                    for b in rotor.bearing_elements
                }
                for w in speeds
            ],
        }
    # ROSS 3 spelling: bearing tables over `speed`.
    text = (OUT / "speed_bearing.toml").read_text()
    (OUT / "speed_bearing_v3.toml").write_text(text.replace("\nfrequency = ", "\nspeed = "))
    (OUT / "ross_reference.json").write_text(json.dumps(reference, indent=1))
    print("wrote", sorted(p.name for p in OUT.iterdir()))


if __name__ == "__main__":
    main()
