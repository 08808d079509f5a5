"""Real measured modal data as eigenfit fixtures, and the scipy reference they are checked against.

Two laboratory data sets from the SMU package (Y. Wang, X. Dong, D. Li, Y. Otsuki, "SMU: MATLAB
Package for Structural Model Updating", https://github.com/ywang-structures/Structural-Model-Updating,
commit 474892b89325979a1304ceaf6b70958f9b26318d, GPL-3.0):

* four_storey_gatech/: a 4-storey laboratory shear frame on a shake table (Georgia Tech),
  Examples/FourStoryStructure/Experiment/FourStoryStructure.mat: `test_frequency` (4 identified
  natural frequencies, Hz) and `test_mode` (4x4 identified mode shapes, one column per mode).
* eighteen_storey_edefense/: the one-third scale 18-storey steel frame tested on the E-Defense
  shaking table (NIED, Japan), Examples/EighteenStoryStructure/Experiment/ExpModalInfo_18DOF.mat:
  `freqExp` (3 identified frequencies, Hz), `psiExp_m` (6x3 shapes at `measDOFs` 3, 6, ..., 18).

The models are the ones the SMU examples update (FourStoryStructureExperiment.m and
EighteenStoryStructureExp.m): lumped floor masses, one inter-storey stiffness per storey. The
18-storey model's 18 storey stiffnesses are grouped here into three zones of six storeys (a factor
on the SMU nominal values each), since 3 frequencies and 18 shape entries cannot determine 18.

    python generate.py --mat-dir /path/to/Structural-Model-Updating   # re-read the .mat files
    python generate.py                                                 # from source.json

writes, per data set: source.json (the values as read from the .mat, only with --mat-dir),
model.toml, K*.mtx, M0.mtx, dofs.csv, measured.csv (frequencies only: the source gives no
standard deviations), shapes.csv and reference.json: every distinct minimum scipy's
least_squares finds from many log-uniform starts (independent of eigenfit) of

  (a) the frequencies alone: r_k = ln(f_k,measured / f_k(p)), modes paired by order;
  (b) frequencies and shapes with eigenfit's documented default weights (docs/test-data.md,
      "The objective with shapes"): r_k / 0.005 for each frequency, and for each mode the
      unit-length measured shape (turned to point the model's way) minus the unit-length model
      shape at the sensors, divided by 0.05; modes paired by order (the MAC pairing eigenfit
      uses gives the same pairs at these minima: checked below).

The minima's chi2 are sums of squared residuals with those weights.
"""

import argparse
import json
import pathlib

import numpy as np
import scipy
from scipy.linalg import eigh
from scipy.optimize import least_squares

HERE = pathlib.Path(__file__).parent
SOURCE = "https://github.com/ywang-structures/Structural-Model-Updating"
COMMIT = "474892b89325979a1304ceaf6b70958f9b26318d"


def shear_stiffness(k):
    """SMU's assemblyK: storey i joins floor i-1 and floor i; storey 1 joins floor 1 to ground."""
    n = len(k)
    a = np.zeros((n, n))
    a[0, 0] += k[0]
    for i in range(1, n):
        a[i - 1, i - 1] += k[i]
        a[i, i] += k[i]
        a[i - 1, i] -= k[i]
        a[i, i - 1] -= k[i]
    return a


def storey_matrix(n, i, k):
    """dK/dk_i for storey i (from 0) times k."""
    e = np.zeros(n)
    e[i] = k
    return shear_stiffness(e)


def write_mtx(path, a):
    rows = [(i + 1, j + 1, a[i, j]) for j in range(a.shape[0]) for i in range(j, a.shape[0]) if a[i, j] != 0.0]
    if not rows:
        rows = [(1, 1, 0.0)]
    text = "%%MatrixMarket matrix coordinate real symmetric\n"
    text += f"% written by generate.py (this folder)\n{a.shape[0]} {a.shape[0]} {len(rows)}\n"
    text += "".join(f"{i} {j} {float(v)!r}\n" for i, j, v in rows)
    path.write_text(text)


def modes(k_full, m):
    w, v = eigh(shear_stiffness(k_full), np.diag(m))
    return np.sqrt(w) / (2 * np.pi), v


def minima(residual, lower, upper, starts, rng, same=1e-4):
    """Distinct minima of ½‖r‖² over ln p from log-uniform starts, best first."""
    found = []
    for _ in range(starts):
        s = rng.uniform(np.log(lower), np.log(upper))
        fit = least_squares(residual, s, bounds=(np.log(lower), np.log(upper)), xtol=1e-15, ftol=1e-15, gtol=1e-15)
        p = np.exp(fit.x)
        chi2 = float(fit.fun @ fit.fun)
        for f in found:
            if np.allclose(p, f["p"], rtol=same):
                f["starts"] += 1
                break
        else:
            found.append({"p": p, "chi2": chi2, "starts": 1})
    found.sort(key=lambda f: f["chi2"])
    return found


def dataset(name, src, m, k_nominal, groups, labels, unit, lower, upper, sensors, title, starts):
    """Writes one data set's fixtures. `groups[j]`: the storeys (from 0) parameter j scales;
    parameter j is the storey stiffness itself (unit `unit`) when `k_nominal` is given per
    parameter, else a factor on the storeys' nominal stiffnesses."""
    out = HERE / name
    out.mkdir(exist_ok=True)
    n = len(m)
    f = np.array(src["frequencies_hz"])
    shapes = np.array(src["shapes"])  # rows: sensors, columns: modes
    storey_k, nominal = k_nominal
    np_ = len(groups)

    def full(p):
        k = np.zeros(n)
        for j, g in enumerate(groups):
            for i in g:
                k[i] = p[j] * storey_k[i]
        return k

    write_mtx(out / "K0.mtx", np.zeros((n, n)))
    write_mtx(out / "M0.mtx", np.diag(m))
    toml = f'# {title}\n# Written by ../generate.py from {SOURCE} (commit {COMMIT[:7]}); see README.md.\n'
    toml += f'kind = "matrices"\nname = "{title}"\nstiffness = "K0.mtx"\nmass = "M0.mtx"\ndofs = "dofs.csv"\n'
    for j, g in enumerate(groups):
        a = sum(storey_matrix(n, i, storey_k[i]) for i in g)
        write_mtx(out / f"K_{labels[j]}.mtx", a)
        toml += (
            f'\n[[parameter]]\nname = "{labels[j]}"\nnominal = {nominal[j]!r}\nlower = {lower!r}\n'
            f'upper = {upper!r}\nscale = "log"\nunit = "{unit}"\nstiffness = "K_{labels[j]}.mtx"\n'
        )
    (out / "model.toml").write_text(toml)
    # DOF i is floor i's lateral displacement: node i (floor number), direction x; the
    # coordinates are the floor number (only used to tell nodes apart).
    (out / "dofs.csv").write_text(
        "dof,node,direction,x,y,z\n" + "".join(f"{i + 1},{i + 1},x,0,0,{i + 1}\n" for i in range(n))
    )
    (out / "measured.csv").write_text(
        f"# {title}: identified natural frequencies, {SOURCE} (commit {COMMIT[:7]}), no std given\n"
        "mode,frequency_hz\n" + "".join(f"{i + 1},{float(v)!r}\n" for i, v in enumerate(f))
    )
    (out / "shapes.csv").write_text(
        "mode,node,direction,value\n"
        + "".join(
            f"{j + 1},{int(s)},x,{float(shapes[r, j])!r}\n" for j in range(shapes.shape[1]) for r, s in enumerate(sensors)
        )
    )

    nm = len(f)
    sens = np.array(sensors)  # model node from 0 = DOF index

    def r_freq(lp):
        fr, _ = modes(full(np.exp(lp)), m)
        return np.log(f / fr[:nm])

    def r_shapes(lp):
        fr, v = modes(full(np.exp(lp)), m)
        rows = [np.log(f / fr[:nm]) / 0.005]
        for j in range(nm):
            s = v[sens, j]
            u = s / np.linalg.norm(s)
            d = shapes[:, j] / np.linalg.norm(shapes[:, j])
            if d @ u < 0:
                d = -d
            rows.append((d - u) / 0.05)
        return np.concatenate(rows)

    def mac_pairs(p):
        """For each measured mode, the model mode (from 0, among the lowest 2m+2) of highest MAC."""
        _, v = modes(full(p), m)
        out = []
        for j in range(nm):
            d = shapes[:, j]
            macs = [(d @ v[sens, k]) ** 2 / (d @ d * (v[sens, k] @ v[sens, k])) for k in range(min(2 * nm + 2, n))]
            out.append(int(np.argmax(macs)))
        return out

    rng = np.random.default_rng(0)
    lo, hi = np.full(np_, lower), np.full(np_, upper)
    fmin = minima(r_freq, lo, hi, starts, rng)
    smin = minima(r_shapes, lo, hi, starts, rng)
    for s in smin:
        s["mac_pairs_in_order"] = mac_pairs(s["p"]) == list(range(nm))

    def plain(found):
        return [
            {
                "parameters": dict(zip(labels, map(float, s["p"]))),
                "chi2": s["chi2"],
                "starts": s["starts"],
                **({"mac_pairs_in_order": s["mac_pairs_in_order"]} if "mac_pairs_in_order" in s else {}),
                "frequencies_hz": modes(full(s["p"]), m)[0][:nm].tolist(),
            }
            for s in found
        ]

    ref = {
        "what": "distinct minima from log-uniform starts within the model's bounds, best first (generate.py)",
        "starts": starts,
        "frequencies_only": plain(fmin),
        "frequencies_and_shapes": plain(smin),
        "generator": f"scipy {scipy.__version__}, numpy {np.__version__}",
    }
    (out / "reference.json").write_text(json.dumps(ref, indent=1) + "\n")
    print(name, "frequency minima:", [round(s["chi2"], 12) for s in fmin][:8])
    print(name, "shape-fit minima:", [round(s["chi2"], 4) for s in smin][:8])


def read_mat(mat_dir):
    import scipy.io

    root = pathlib.Path(mat_dir) / "Examples"
    four = scipy.io.loadmat(root / "FourStoryStructure/Experiment/FourStoryStructure.mat")
    e18 = scipy.io.loadmat(root / "EighteenStoryStructure/Experiment/ExpModalInfo_18DOF.mat")
    return {
        "four_storey_gatech": {
            "file": "Examples/FourStoryStructure/Experiment/FourStoryStructure.mat",
            "frequencies_hz": four["test_frequency"].ravel().tolist(),
            "shapes": four["test_mode"].tolist(),
        },
        "eighteen_storey_edefense": {
            "file": "Examples/EighteenStoryStructure/Experiment/ExpModalInfo_18DOF.mat",
            "frequencies_hz": e18["freqExp"].ravel().tolist(),
            "damping_ratios": e18["dampExp"].ravel().tolist(),
            "measured_dofs": e18["measDOFs"].ravel().tolist(),
            "shapes": e18["psiExp_m"].tolist(),
        },
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mat-dir", help="a checkout of Structural-Model-Updating to read the .mat files from")
    ap.add_argument("--starts", type=int, default=1000)
    args = ap.parse_args()
    if args.mat_dir:
        for name, src in read_mat(args.mat_dir).items():
            (HERE / name).mkdir(exist_ok=True)
            src = {"source": SOURCE, "commit": COMMIT, **src}
            (HERE / name / "source.json").write_text(json.dumps(src, indent=1) + "\n")
    four = json.loads((HERE / "four_storey_gatech/source.json").read_text())
    # FourStoryStructureExperiment.m: floor weight 12.060 lb (mass 12.060/386.088 lbf·s²/in),
    # nominal storey stiffness 10 lbf/in. Parameters: the four storey stiffnesses in lbf/in.
    dataset(
        "four_storey_gatech",
        four,
        m=np.full(4, 12.060 / 386.088),
        k_nominal=(np.ones(4), [10.0] * 4),
        groups=[[0], [1], [2], [3]],
        labels=["k1", "k2", "k3", "k4"],
        unit="lbf/in",
        lower=1.0,
        upper=100.0,
        sensors=[0, 1, 2, 3],
        title="4-storey laboratory shear frame (Georgia Tech, SMU)",
        starts=args.starts,
    )
    e18 = json.loads((HERE / "eighteen_storey_edefense/source.json").read_text())
    # EighteenStoryStructureExp.m: storey stiffnesses (kN/m) and floor weights (kN, mass = W/9.8 t).
    k18 = np.array([1155, 1092, 1073, 1028, 1028, 990, 963, 938, 876, 840, 824, 788, 712, 660, 619, 562, 491, 363]) * 1e2
    w18 = np.array([208] * 11 + [206] * 6 + [202], dtype=float)
    dataset(
        "eighteen_storey_edefense",
        e18,
        m=w18 / 9.8,
        k_nominal=(k18, [1.0] * 3),
        groups=[list(range(0, 6)), list(range(6, 12)), list(range(12, 18))],
        labels=["storeys_1_6", "storeys_7_12", "storeys_13_18"],
        unit="",
        lower=0.1,
        upper=10.0,
        sensors=[d - 1 for d in e18["measured_dofs"]],
        title="1/3-scale 18-storey steel frame (E-Defense, SMU), three stiffness zones",
        starts=args.starts // 2,
    )


if __name__ == "__main__":
    main()
