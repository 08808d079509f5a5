"""Calibrate a fleet of rotors on a Dask cluster: one model file and one measurement per rotor.

Each pump of the fleet is the paper's test rig with its own manufacturing tolerance (shaft
diameter ±1 %, its own TOML file) and its own bearing stiffnesses, unknown to us; its "measured"
frequencies are the model's at the true stiffnesses with 0.05 % noise. eigenfit estimates every
pump's bearing stiffnesses on a dask.distributed LocalCluster, checks a sample against the serial
run (identical results), and reports how close the estimates are to the truth.

    python python/examples/fleet.py                 # 1,000 rotors, 2 worker processes
    python python/examples/fleet.py --rotors 100 --workers 4

The same code runs on a Slurm cluster: replace the LocalCluster by dask_jobqueue.SLURMCluster
(docs/python.md).
"""

from __future__ import annotations

import argparse
import logging
import re
import tempfile
import time
from pathlib import Path

import numpy as np
from dask.distributed import Client, LocalCluster

import eigenfit
import eigenfit.batch

REPO = Path(__file__).resolve().parents[2]
MODES = 6
NOISE = 5e-4  # relative standard deviation of a measured frequency


def make_fleet(n: int, folder: Path, rng: np.random.Generator):
    """Writes one model file per pump; returns the jobs and the true stiffnesses."""
    template = (REPO / "examples" / "rotor.toml").read_text(encoding="utf-8")
    jobs, truth = [], []
    for i in range(n):
        diameter = 0.014 * (1 + 0.01 * rng.uniform(-1, 1))
        text, count = re.subn(r"(?m)^diameter = 0\.014", f"diameter = {diameter!r}", template)
        assert count == 1, "examples/rotor.toml changed: no `diameter = 0.014` line to vary"
        model = folder / f"pump-{i:04d}.toml"
        model.write_text(text, encoding="utf-8")
        k = 10.0 ** rng.uniform(4.5, 6.0, size=2)
        f = eigenfit.simulate(model, stiffness=k, modes=MODES).frequencies_hz
        measured = {"frequency_hz": f * (1 + NOISE * rng.standard_normal(MODES)), "std_hz": NOISE * f}
        jobs.append({"model": model, "measured": measured})
        truth.append(k)
    return jobs, np.array(truth)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rotors", type=int, default=1000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--check", type=int, default=50, help="rotors re-run serially and compared")
    parser.add_argument(
        "--chunk-size", type=int, default=None, help="rotors per Dask task (default: automatic)"
    )
    args = parser.parse_args()
    rng = np.random.default_rng(2026)
    with tempfile.TemporaryDirectory(prefix="eigenfit-fleet-") as tmp:
        jobs, truth = make_fleet(args.rotors, Path(tmp), rng)
        # silence_logs: a worker's heartbeat racing the cluster's shutdown logs a harmless error;
        # failed jobs still reach us through gather.
        with (
            LocalCluster(
                n_workers=args.workers,
                threads_per_worker=1,
                dashboard_address=None,
                silence_logs=logging.CRITICAL,
            ) as cluster,
            Client(cluster) as client,
        ):
            started = time.perf_counter()
            results = eigenfit.batch.estimate_many(
                jobs, client=client, errors="return", chunk_size=args.chunk_size
            )
            seconds = time.perf_counter() - started
        started = time.perf_counter()
        serial = eigenfit.batch.estimate_many(jobs[: args.check], errors="return")
        serial_seconds = time.perf_counter() - started

    failed = [i for i, r in enumerate(results) if isinstance(r, eigenfit.EigenfitError)]
    ok = [i for i, r in enumerate(results) if i not in failed and r.converged]
    estimates = np.array([results[i].parameter_values for i in ok])
    rel = np.abs(estimates / truth[ok] - 1)
    same = all(
        (a.to_dict() == b.to_dict()) if isinstance(a, eigenfit.Result) else (a.message == b.message)
        for a, b in zip(results[: args.check], serial)
    )
    print(f"{args.rotors} rotors on {args.workers} Dask workers in {seconds:.1f} s")
    print(
        f"converged: {len(ok)}, not converged: {args.rotors - len(ok) - len(failed)}, failed: {len(failed)}"
    )
    if len(ok):
        print(
            f"|estimate/true - 1|: median {np.median(rel):.2e}, 95th percentile {np.percentile(rel, 95):.2e}"
        )
    print(
        f"first {args.check} identical to the serial run: {same} "
        f"(serial: {1e3 * serial_seconds / max(args.check, 1):.1f} ms per rotor; "
        f"on the cluster: {1e3 * seconds / args.rotors:.1f} ms per rotor)"
    )
    if not same:
        raise SystemExit(1)


if __name__ == "__main__":
    main()
