"""Batches of eigenfit calls, serially or on a ``dask.distributed`` cluster.

Each job is the keyword arguments of one call, e.g. ``{"model": "pump-17.toml", "measured":
{"frequency_hz": [...], "std_hz": [...]}}``. The jobs run one task each; every task is the same
deterministic computation as the serial call, so the results are identical (the tests check
this). A measured mapping travels with its task; a model or CSV *path* must be readable on the
workers (a shared file system on a cluster).

    from dask.distributed import Client, LocalCluster
    import eigenfit.batch
    with Client(LocalCluster(n_workers=2)) as client:
        results = eigenfit.batch.estimate_many(jobs, client=client)
"""

from __future__ import annotations

from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Union

from . import _api
from ._api import EXIT_NOT_CONVERGED, EigenfitError
from ._results import BenchResult, Result

#: The functions a batch may run, by name (names pickle; functions of this module would too, but
#: a name keeps the task small and lets a new command join with one line).
FUNCTIONS: Dict[str, Callable[..., Result]] = {
    "simulate": _api.simulate,
    "estimate": _api.estimate,
    "discover": _api.discover,
    "compare": _api.compare,
    "campbell": _api.campbell,
    "bench": _api.bench,
}


def _run_job(function: str, job: Mapping[str, Any], errors: str) -> Union[Result, EigenfitError]:
    try:
        return FUNCTIONS[function](**job)
    except EigenfitError as e:
        if errors == "return":
            return e
        raise


def _run_chunk(function: str, jobs: List[Dict[str, Any]], errors: str) -> List[Union[Result, EigenfitError]]:
    return [_run_job(function, job, errors) for job in jobs]


def map(
    function: str,
    jobs: Iterable[Mapping[str, Any]],
    *,
    client: Optional[Any] = None,
    errors: str = "raise",
    chunk_size: Optional[int] = None,
    **common: Any,
) -> List[Union[Result, EigenfitError]]:
    """Runs ``eigenfit.<function>(**common, **job)`` for every job; results in the jobs' order.

    Args:
        function: ``"simulate"``, ``"estimate"``, ``"discover"``, ``"compare"``, ``"campbell"``
            or ``"bench"``.
        jobs: keyword arguments per call.
        client: a ``dask.distributed.Client``; None runs the jobs here, one after another.
        errors: ``"raise"`` (the first failed job raises :class:`EigenfitError`) or ``"return"``
            (a failed job's place in the list holds its :class:`EigenfitError`, so one bad pump
            does not cost the fleet's results).
        chunk_size: jobs per Dask task. A calibration takes milliseconds, about what Dask spends
            scheduling one task, so jobs travel in chunks; the default gives every worker thread
            about four chunks (balance against overhead). 1 sends one task per job.
        **common: keyword arguments shared by every job (a job's own value wins).
    """
    if function not in FUNCTIONS:
        raise ValueError(f"unknown function `{function}`; available: {', '.join(FUNCTIONS)}")
    if errors not in ("raise", "return"):
        raise ValueError(f"errors must be 'raise' or 'return', not {errors!r}")
    merged = [{**common, **job} for job in jobs]
    if client is None:
        return [_run_job(function, job, errors) for job in merged]
    if chunk_size is None:
        threads = max(1, sum(client.nthreads().values()))
        chunk_size = max(1, -(-len(merged) // (4 * threads)))
    if chunk_size < 1:
        raise ValueError(f"chunk_size must be at least 1, not {chunk_size}")
    chunks = [merged[i : i + chunk_size] for i in range(0, len(merged), chunk_size)]
    n = len(chunks)
    # pure=False: two identical chunks are still two tasks (Dask would otherwise merge them by key).
    futures = client.map(_run_chunk, [function] * n, chunks, [errors] * n, pure=False)
    return [result for chunk in client.gather(futures) for result in chunk]


def estimate_many(
    jobs: Iterable[Mapping[str, Any]],
    *,
    client: Optional[Any] = None,
    errors: str = "raise",
    chunk_size: Optional[int] = None,
    **common: Any,
) -> List[Union[Result, EigenfitError]]:
    """:func:`eigenfit.estimate` for every job (``model``, ``measured`` and options); see :func:`map`.

    A job that does not converge is returned like any other, with ``converged == False``.
    """
    return map("estimate", jobs, client=client, errors=errors, chunk_size=chunk_size, **common)


def bench(
    problems: Iterable[str],
    *,
    strategies: Iterable[str],
    starts: Optional[int] = None,
    seed: Optional[int] = None,
    client: Optional[Any] = None,
    chunk_size: Optional[int] = None,
    **options: Any,
) -> BenchResult:
    """:func:`eigenfit.bench` spread over a Dask cluster: one job per problem and strategy.

    A run's start depends on the seed and its number only (a sampler's seed is seed + start), so
    each problem and strategy run alone gives the records and the summary line the whole bench
    gives them; they are joined in the bench's order (problem, then strategy, then start). The
    result equals ``eigenfit.bench(problems, strategies=…, starts=…, seed=…)`` run here (the
    tests check this), exit code 3 when some problem and strategy never reached the truth.

    Args:
        problems: built-in names or problem-file paths (readable on the workers).
        strategies: registered names with settings after colons.
        starts, seed: as :func:`eigenfit.bench`.
        client, chunk_size: as :func:`map` (None runs the jobs here, one after another).
        **options: other ``eigenfit bench`` options shared by every job (``budget``,
            ``max_iterations``); ``records``, ``plot`` and ``report`` write files per job and are
            refused here.
    """
    for name in ("records", "plot", "report"):
        if name in options:
            raise TypeError(f"eigenfit.batch.bench() does not take `{name}`: every job would write it")
    problems, strategies = list(problems), list(strategies)
    if not problems or not strategies:
        raise ValueError("bench needs at least one problem and one strategy")
    jobs = [{"problems": [p], "strategies": [s]} for p in problems for s in strategies]
    parts = map("bench", jobs, client=client, chunk_size=chunk_size, starts=starts, seed=seed, **options)
    data = [part.to_dict() for part in parts]  # errors="raise": every part is a result
    merged: Dict[str, Any] = {
        "problems": [],
        "strategies": [],
        "starts": data[0]["starts"],
        "seed": data[0]["seed"],
        "records": [],
        "summary": [],
    }
    for d in data:
        for info in d["problems"]:
            if info not in merged["problems"]:
                merged["problems"].append(info)
        for s in d["strategies"]:
            if s not in merged["strategies"]:
                merged["strategies"].append(s)
        merged["records"].extend(d["records"])
        merged["summary"].extend(d["summary"])
    failed = any(s["success_rate"] == 0.0 for s in merged["summary"])
    return BenchResult(merged, EXIT_NOT_CONVERGED if failed else 0)
