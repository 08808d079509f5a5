"""Batches on a dask.distributed LocalCluster with two worker processes give the serial results."""

from __future__ import annotations

import numpy as np
import pytest

import eigenfit
import eigenfit.batch

distributed = pytest.importorskip("distributed")


def _fleet(n: int):
    """n paper rotors with different true bearing stiffnesses and their 'measured' frequencies."""
    rng = np.random.default_rng(18)
    jobs = []
    for _ in range(n):
        k = 10.0 ** rng.uniform(4.5, 5.5, size=2)
        f = eigenfit.simulate("paper-rotor", stiffness=k, modes=6).frequencies_hz
        jobs.append(
            {
                "model": "paper-rotor",
                "measured": {"frequency_hz": f * (1 + 1e-4 * rng.standard_normal(6)), "std_hz": 1e-4 * f},
            }
        )
    return jobs


@pytest.fixture(scope="module")
def client():
    # Worker processes (not threads), as on a real cluster: the tasks and results are pickled.
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as c,
    ):
        yield c


@pytest.fixture(scope="module")
def fleet():
    jobs = _fleet(12)
    return jobs, eigenfit.batch.estimate_many(jobs)


@pytest.mark.parametrize("chunk_size", [None, 1, 5])  # automatic (2 jobs), one per task, uneven
def test_cluster_results_equal_serial(client, fleet, chunk_size):
    jobs, serial = fleet
    on_cluster = eigenfit.batch.estimate_many(jobs, client=client, chunk_size=chunk_size)
    assert [r.to_dict() for r in on_cluster] == [r.to_dict() for r in serial]
    assert all(isinstance(r, eigenfit.EstimateResult) and r.converged for r in on_cluster)
    assert len(client.scheduler_info()["workers"]) == 2
    with pytest.raises(ValueError, match="chunk_size"):
        eigenfit.batch.estimate_many(jobs, client=client, chunk_size=0)


def test_cluster_failed_job_is_returned_or_raised(client):
    jobs = [
        {"model": "paper-rotor", "measured": {"frequency_hz": [30.3, 97.8, 306.4]}},
        {"model": "no-such-rotor", "measured": {"frequency_hz": [30.3, 97.8]}},
    ]
    results = eigenfit.batch.estimate_many(jobs, client=client, errors="return")
    assert isinstance(results[0], eigenfit.EstimateResult)
    assert isinstance(results[1], eigenfit.EigenfitError) and results[1].exit_code == 2
    with pytest.raises(eigenfit.EigenfitError, match="no preset named"):
        eigenfit.batch.estimate_many(jobs, client=client)


def test_common_arguments_and_other_functions(client):
    jobs = [{"stiffness": [1e5, 2e5]}, {"stiffness": [3e5, 4e4]}]
    on_cluster = eigenfit.batch.map("simulate", jobs, client=client, model="paper-rotor", modes=3)
    serial = [eigenfit.simulate("paper-rotor", modes=3, **j) for j in jobs]
    assert on_cluster == serial
    with pytest.raises(ValueError, match="unknown function"):
        eigenfit.batch.map("campbell-typo", jobs)


def test_a_bench_spread_on_the_cluster_equals_the_serial_bench(client):
    # Two problems × three strategies: six jobs, joined in the bench's order.
    problems = ["paper-table3", "shear-frame"]
    strategies = ["damped", "trf", "tmcmc:samples=100"]
    serial = eigenfit.bench(problems, strategies=strategies, starts=2, seed=4)
    for chunk_size in (None, 1, 4):
        spread = eigenfit.batch.bench(problems, strategies=strategies, starts=2, seed=4, client=client, chunk_size=chunk_size)
        assert isinstance(spread, eigenfit.BenchResult)
        assert spread.to_dict() == serial.to_dict()
        assert spread.exit_code == serial.exit_code
    # And without a cluster, one job after another.
    assert eigenfit.batch.bench(problems, strategies=strategies, starts=2, seed=4).to_dict() == serial.to_dict()
    with pytest.raises(TypeError, match="records"):
        eigenfit.batch.bench(problems, strategies=strategies, records="runs.jsonl")
