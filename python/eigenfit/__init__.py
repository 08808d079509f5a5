"""eigenfit: finite-element model updating by eigenvalue sensitivity, from Python.

The engine is the Rust ``eigenfit`` library; each function runs the matching CLI command in this
process (no subprocess, the GIL released) and returns a typed result whose ``to_dict()`` is the
JSON the command-line tool prints for the same arguments.

    >>> import eigenfit
    >>> r = eigenfit.simulate(model="paper-rotor", stiffness=[1e5, 1e5], modes=2)
    >>> r.frequencies_hz                       # numpy array, Hz
    >>> e = eigenfit.estimate(model="paper-rotor", measured="examples/measured_no_effect.csv")
    >>> e.parameters                           # {"k_K1": …, "k_K2": …}

Two-plane rotors saved by ROSS: ``eigenfit.campbell(model="rotor.toml", speeds=(0, 12000, 50),
modes=6)``.

Batches on a Dask cluster: :mod:`eigenfit.batch`.
"""

from ._api import EXIT_NOT_CONVERGED, EigenfitError, bench, campbell, compare, discover, estimate, run, simulate
from ._native import version as _native_version
from .matrices import MatricesModel
from ._results import (
    BenchResult,
    CampbellResult,
    CompareResult,
    DiscoverResult,
    EstimateResult,
    Result,
    SimulateResult,
)

__version__: str = _native_version()

__all__ = [
    "simulate",
    "estimate",
    "discover",
    "compare",
    "bench",
    "campbell",
    "run",
    "MatricesModel",
    "EigenfitError",
    "EXIT_NOT_CONVERGED",
    "Result",
    "SimulateResult",
    "EstimateResult",
    "DiscoverResult",
    "CompareResult",
    "BenchResult",
    "CampbellResult",
    "__version__",
]
