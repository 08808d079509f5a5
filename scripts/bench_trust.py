"""Issue #13's cases, timed: each must end (answer, honest verdict or clean error) in under 2 s.

    python3 scripts/bench_trust.py [path/to/eigenfit] [--repeat N]

Runs every case of the issue against the release binary (build it first with
`cargo build --release -p eigenfit-cli`), from `crates/eigenfit-cli/tests/trust_corpus/` (the
corpus the trust test asserts verdicts on) plus the large inputs generated here into a temporary
folder (a 10⁶-row CSV, 10⁵ materials, 10⁵ bearings). Prints, per case, the exit code and the best
wall time of N runs (default 3); ends with exit code 1 if any case took 2 s or more. A benchmark,
not a test: the times depend on the machine and its load, so they are reported, never asserted
in CI.
"""

import argparse
import pathlib
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
CORPUS = ROOT / "crates/eigenfit-cli/tests/trust_corpus"
PARSER = argparse.ArgumentParser()
PARSER.add_argument("eigenfit", nargs="?", default=str(ROOT / "target/release/eigenfit"))
PARSER.add_argument("--repeat", type=int, default=3)
OPTIONS = PARSER.parse_args()
EIGENFIT, REPEAT = OPTIONS.eigenfit, OPTIONS.repeat
LIMIT_S = 2.0
HIDDEN = str(ROOT / "examples/measured_hidden_effect.csv")
ROTOR = "three_disk_rotor.toml"


def big_inputs(tmp: pathlib.Path) -> dict:
    """The issue's large files: quadratic duplicate checks made these take minutes."""
    rows = tmp / "million_rows.csv"
    with rows.open("w") as f:
        f.write("mode,frequency_hz\n")
        f.writelines(f"{k},{10.0 + k}\n" for k in range(1, 1_000_001))
    base = (CORPUS / ROTOR).read_text()
    materials = tmp / "many_materials.toml"
    extra = "".join(f'\n[[material]]\nname = "m{i}"\nyoungs_modulus = 2e11\ndensity = 7800.0\n' for i in range(100_000))
    materials.write_text(base + extra)
    bearings = tmp / "many_bearings.toml"
    extra = "".join(f'\n[[bearing]]\nname = "b{i}"\nnode = {i % 25}\nstiffness = 1e6\n' for i in range(100_000))
    bearings.write_text(base + extra)
    return {"rows": str(rows), "materials": str(materials), "bearings": str(bearings)}


def cases(big: dict, tmp: pathlib.Path) -> list:
    stream = str(tmp / "runs.jsonl")
    compare = ["compare", "--preset", "paper-rotor", "--targets", "2e5:5e4", "--initials", "1e5:1e5"]
    return [
        ("stiff rotor, 2 modes with std, --initial 1e6,1e6",
         ["estimate", "--model", ROTOR, "--measured", "stiff_two_modes_std.csv", "--initial", "1e6,1e6"]),
        ("stiff rotor without std",
         ["estimate", "--model", ROTOR, "--measured", "stiff_two_modes.csv", "--initial", "1e6,1e6"]),
        ("symmetric rotor from 1e8,1e7 (mirror)",
         ["estimate", "--model", ROTOR, "--measured", "stiff_two_modes.csv", "--initial", "1e8,1e7"]),
        ("--initial 1e-6,1e15",
         ["estimate", "--model", ROTOR, "--measured", "stiff_two_modes_std.csv", "--initial", "1e-6,1e15"]),
        ("discover on the stiff rotor", ["discover", "--model", ROTOR, "--measured", "stiff_two_modes_std.csv"]),
        ("estimate, decimal slip", ["estimate", "--preset", "paper-rotor", "--measured", "decimal_slip.csv"]),
        ("discover, decimal slip", ["discover", "--preset", "paper-rotor", "--measured", "decimal_slip.csv"]),
        ("decreasing frequencies", ["estimate", "--preset", "ross-example", "--measured", "decreasing.csv"]),
        ("equal frequencies", ["estimate", "--preset", "ross-example", "--measured", "equal.csv"]),
        ("one outlier", ["estimate", "--preset", "ross-example", "--measured", "outlier.csv"]),
        ("1e300 Hz", ["estimate", "--preset", "ross-example", "--measured", "huge.csv"]),
        ("at the stiffness limit", ["estimate", "--preset", "paper-rotor", "--measured", "at_limit.csv"]),
        ("at the limit, with std", ["estimate", "--preset", "paper-rotor", "--measured", "at_limit_std.csv"]),
        ("hidden effect: poor fit", ["estimate", "--preset", "paper-rotor", "--measured", HIDDEN]),
        ("hidden effect: discover", ["discover", "--preset", "paper-rotor", "--measured", HIDDEN]),
        ("compare --stream (append)", compare + ["--quiet", "--stream", stream]),
        ("--grid 10000", ["compare", "--preset", "paper-rotor", "--targets", "2e5:5e4", "--grid", "10000"]),
        ("--sweep 1e2:1e9:1000000000", ["simulate", "--preset", "paper-rotor", "--sweep", "1e2:1e9:1000000000"]),
        ("--elements 10000", ["simulate", "--preset", "uniform-rotor", "--elements", "10000"]),
        ("--elements 20000", ["simulate", "--preset", "uniform-rotor", "--elements", "20000"]),
        ("point-mass@0=1e50", ["simulate", "--preset", "paper-rotor", "--effect", "point-mass@0=1e50"]),
        ("bearing-rotational-stiffness@0=1e50",
         ["simulate", "--preset", "paper-rotor", "--effect", "bearing-rotational-stiffness@0=1e50"]),
        ("diameter 1e300", ["simulate", "--model", "huge_diameter.toml"]),
        ("--decimals 400", compare + ["--decimals", "400"]),
        ("10⁶-row CSV", ["estimate", "--preset", "paper-rotor", "--measured", big["rows"]]),
        ("10⁵ materials", ["simulate", "--model", big["materials"]]),
        ("10⁵ bearings", ["simulate", "--model", big["bearings"]]),
        ("/dev/zero as --measured", ["estimate", "--preset", "paper-rotor", "--measured", "/dev/zero"]),
    ]


def main() -> int:
    slow = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        big = big_inputs(tmp)
        print(f"{'case':<48} {'exit':>4} {'best [s]':>9}")
        for name, args in cases(big, tmp):
            best, code = float("inf"), None
            for _ in range(REPEAT):
                t0 = time.perf_counter()
                try:
                    run = subprocess.run([EIGENFIT, *args], cwd=CORPUS, capture_output=True, timeout=60)
                    code = run.returncode
                except subprocess.TimeoutExpired:
                    code = "kill"
                best = min(best, time.perf_counter() - t0)
            print(f"{name:<48} {code:>4} {best:>9.3f}")
            if best >= LIMIT_S:
                slow.append(name)
    if slow:
        print(f"{len(slow)} case(s) at or over {LIMIT_S} s: {', '.join(slow)}")
    return 1 if slow else 0


if __name__ == "__main__":
    sys.exit(main())
