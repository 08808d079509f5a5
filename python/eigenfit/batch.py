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
from ._api import EigenfitError
from ._results import Result

#: The functions a batch may run, by name (names pickle; functions of this module would too, but
#: a name keeps the task small and lets a new command join with one line).
FUNCTIONS: Dict[str, Callable[..., Result]] = {
    "simulate": _api.simulate,
    "estimate": _api.estimate,
    "discover": _api.discover,
    "compare": _api.compare,
    "campbell": _api.campbell,
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
        function: ``"simulate"``, ``"estimate"``, ``"discover"`` or ``"compare"``.
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
