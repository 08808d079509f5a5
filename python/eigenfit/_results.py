"""Typed results. Each holds the command's JSON (the very object ``eigenfit … --json`` prints)
and reads its properties from it, so ``to_dict()`` equals the CLI's output by construction and
pickling is the JSON text (small, version-tolerant, safe to ship between Dask workers)."""

from __future__ import annotations

import copy
import json
from typing import Any, Dict, List, Optional

import numpy as np


def _array(value: Any) -> Optional[np.ndarray]:
    return None if value is None else np.asarray(value, dtype=float)


def _arrays(mapping: Optional[Dict[str, Any]]) -> Dict[str, np.ndarray]:
    return {k: np.asarray(v, dtype=float) for k, v in (mapping or {}).items()}


class Result:
    """Base of the result classes: the command's JSON with typed accessors.

    ``result["key"]`` reads any field of the JSON, including ones newer than this class.
    """

    #: The CLI subcommand this result comes from.
    command: str = ""

    def __init__(self, data: Dict[str, Any], exit_code: int = 0) -> None:
        self._data = data
        self._exit_code = int(exit_code)

    @classmethod
    def from_json(cls, text: str, exit_code: int = 0) -> "Result":
        """A result from the CLI's JSON text (``eigenfit … --json`` output)."""
        return cls(json.loads(text), exit_code)

    def to_dict(self) -> Dict[str, Any]:
        """The result as the CLI's JSON object (a deep copy: changing it leaves the result alone)."""
        return copy.deepcopy(self._data)

    def to_json(self) -> str:
        """The result as JSON text."""
        return json.dumps(self._data)

    @property
    def exit_code(self) -> int:
        """The CLI's exit code for this run: 0, or 3 for an estimation that did not converge."""
        return self._exit_code

    @property
    def model(self) -> str:
        """The model's label: the preset name or the model file path."""
        return str(self._data["model"])

    def __getitem__(self, key: str) -> Any:
        return copy.deepcopy(self._data[key])

    def keys(self) -> List[str]:
        """The fields of the JSON object."""
        return list(self._data)

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return self._data == other._data and self._exit_code == other._exit_code

    __hash__ = None  # type: ignore[assignment]  # mutable contents

    def __reduce__(self) -> Any:
        return (_restore, (type(self).__name__, json.dumps(self._data), self._exit_code))

    def __repr__(self) -> str:
        return f"{type(self).__name__}(model={self._data.get('model')!r})"


class SimulateResult(Result):
    """``eigenfit simulate``: natural frequencies at one point, or over a stiffness sweep."""

    command = "simulate"

    @property
    def solver(self) -> str:
        """The eigen-solver used."""
        return str(self._data["solver"])

    @property
    def frequencies_hz(self) -> Optional[np.ndarray]:
        """Natural frequencies (Hz), lowest first; None for a sweep."""
        return _array(self._data.get("frequencies_hz"))

    @property
    def parameters(self) -> Dict[str, float]:
        """The parameter values simulated (name → value); empty for a sweep."""
        return dict(self._data.get("parameters", {}))

    @property
    def sensitivities_hz(self) -> Dict[str, np.ndarray]:
        """∂f/∂p per parameter (Hz per unit), one value per mode; empty for a sweep."""
        return _arrays(self._data.get("sensitivities_hz"))

    @property
    def units(self) -> Dict[str, str]:
        """Each parameter's unit as declared (``""`` when none was); empty for a sweep."""
        return dict(self._data.get("units") or {})

    @property
    def mode_shapes(self) -> Optional[np.ndarray]:
        """Mass-normalised mode shapes (ΦᵀMΦ = I), shape (DOFs, modes): column k is mode k + 1,
        rows in the order of :attr:`dof_labels`; None unless asked for with ``shapes=True``."""
        shapes = self._data.get("mode_shapes")
        return None if shapes is None else np.asarray(shapes["shapes"], dtype=float).T

    @property
    def dof_labels(self) -> Optional[List[str]]:
        """The DOF of each row of :attr:`mode_shapes` (a planar rotor's ``v3``, ``theta3``; a
        matrices model's ``node:direction`` or ``dof1``…); None without shapes."""
        shapes = self._data.get("mode_shapes")
        return None if shapes is None else list(shapes["dofs"])

    @property
    def sweep_stiffness(self) -> Optional[np.ndarray]:
        """The swept stiffness values (N/m), or None without a sweep."""
        sweep = self._data.get("sweep")
        return None if sweep is None else np.asarray([row["stiffness"] for row in sweep], dtype=float)

    @property
    def sweep_frequencies_hz(self) -> Optional[np.ndarray]:
        """Frequencies over the sweep, shape (points, modes), or None without a sweep."""
        sweep = self._data.get("sweep")
        return None if sweep is None else np.asarray([row["frequencies_hz"] for row in sweep], dtype=float)


class EstimateResult(Result):
    """``eigenfit estimate``: updated parameters, their uncertainty and the iteration history.

    A run that did not converge, or whose fit is not acceptable, is still returned, with
    ``acceptable == False`` and ``exit_code == 3`` (the CLI's exit code)."""

    command = "estimate"

    @property
    def converged(self) -> bool:
        """Whether the update converged."""
        return bool(self._data["converged"])

    @property
    def acceptable(self) -> bool:
        """Whether the result can be used: converged, and a fit consistent with the data."""
        return bool(self._data.get("acceptable", self._data["converged"]))

    @property
    def unique(self) -> bool:
        """No other solution found fits the data as well (the exit code is 0 only when the
        result is ``acceptable`` and ``unique``)."""
        return bool(self._data.get("unique", True))

    @property
    def verdict(self) -> Optional[str]:
        """The CLI's verdict on the result, in words."""
        return self._data.get("verdict")

    @property
    def fit_quality(self) -> Optional[str]:
        """How well the fitted model matches the data (the CLI's label)."""
        return self._data.get("fit_quality")

    @property
    def p_value(self) -> Optional[float]:
        """p-value of the fit's χ² (with standard deviations given)."""
        return self._data.get("p_value")

    @property
    def parameter_status(self) -> Dict[str, str]:
        """What the data say about each parameter, in words (interval, bound, limit)."""
        return dict(self._data.get("parameter_status", {}))

    @property
    def termination(self) -> str:
        """Why the iteration stopped, in words (``termination_status`` and
        ``termination_reason`` give the two parts apart)."""
        t = self._data["termination"]
        return str(t["detail"]) if isinstance(t, dict) else str(t)

    @property
    def termination_status(self) -> str:
        """``converged``, ``best-found``, ``stopped`` or ``failed``."""
        return str(self._data["termination"]["status"])

    @property
    def termination_reason(self) -> str:
        """``tolerance``, ``exact-fit``, ``stationary``, ``restarts-used``, ``iteration-limit``,
        ``diverged``, ``stalled`` or ``budget-exhausted``."""
        return str(self._data["termination"]["reason"])

    @property
    def strategy(self) -> str:
        """The update strategy used."""
        return str(self._data["strategy"])

    @property
    def iterations(self) -> int:
        """Iterations taken."""
        return int(self._data["iterations"])

    @property
    def evaluations(self) -> int:
        """Model evaluations (eigen-solves) taken."""
        return int(self._data["evaluations"])

    @property
    def parameters(self) -> Dict[str, float]:
        """The estimated parameters (name → value)."""
        return dict(self._data["parameters"])

    @property
    def initial(self) -> Dict[str, float]:
        """The initial parameters (name → value)."""
        return dict(self._data["initial"])

    @property
    def parameter_values(self) -> np.ndarray:
        """The estimated parameters as an array, in the model's parameter order."""
        return np.asarray(list(self._data["parameters"].values()), dtype=float)

    @property
    def frequencies_hz(self) -> np.ndarray:
        """The updated model's frequencies (Hz) of the measured modes."""
        return np.asarray(self._data["frequencies_hz"], dtype=float)

    @property
    def measured_hz(self) -> np.ndarray:
        """The measured frequencies (Hz), in the same order."""
        return np.asarray(self._data["measured_hz"], dtype=float)

    @property
    def intervals(self) -> Dict[str, np.ndarray]:
        """95 % intervals per parameter ([low, high]); empty when no uncertainty was computed."""
        return _arrays(self._data.get("intervals"))

    @property
    def standard_deviations(self) -> Dict[str, float]:
        """Standard deviation per parameter; empty when no uncertainty was computed."""
        return dict(self._data.get("standard_deviations", {}))

    @property
    def identifiable(self) -> Dict[str, bool]:
        """Whether the data determine each parameter (an entry's bound, if any, is in
        ``result["identifiable"]``); empty when no uncertainty was computed."""
        return {k: v is True for k, v in (self._data.get("identifiable") or {}).items()}

    @property
    def units(self) -> Dict[str, str]:
        """Each parameter's unit as declared (``""`` when none was)."""
        return dict(self._data.get("units") or {})

    @property
    def covariance(self) -> Optional[np.ndarray]:
        """The parameters' covariance in physical units (entry (i, j) in unitᵢ·unitⱼ), rows and
        columns in the order of :attr:`parameters`; None when not computed (no std, no
        convergence) or not computable (rank-deficient)."""
        c = self._data.get("covariance")
        return None if c is None else np.asarray(c["matrix"], dtype=float)

    @property
    def correlation(self) -> Optional[np.ndarray]:
        """The parameters' correlation (ones on the diagonal), ordered as :attr:`covariance`;
        None when the covariance is."""
        c = self._data.get("correlation")
        return None if c is None else np.asarray(c["matrix"], dtype=float)

    @property
    def singular_values(self) -> Optional[np.ndarray]:
        """Singular values of the scaled Jacobian, when computed."""
        return _array(self._data.get("singular_values"))

    @property
    def condition_number(self) -> Optional[float]:
        """Condition number of the scaled Jacobian, when computed."""
        return self._data.get("condition_number")

    @property
    def history(self) -> List[Dict[str, Any]]:
        """One entry per iteration: parameters, frequencies and largest difference (Hz)."""
        return copy.deepcopy(self._data.get("history", []))

    def __repr__(self) -> str:
        return (
            f"EstimateResult(model={self._data.get('model')!r}, converged={self.converged}, "
            f"parameters={self.parameters!r})"
        )


class DiscoverResult(Result):
    """``eigenfit discover``: whether model and measurement disagree, and the effect that explains it."""

    command = "discover"

    @property
    def disagreement_significant(self) -> bool:
        """Whether the calibrated nominal model disagrees with the measurement beyond its noise."""
        return bool(self._data["disagreement_significant"])

    @property
    def explained(self) -> bool:
        """Whether the data are explained, by the noise or by the named effect(s); False (exit
        code 3) when a significant disagreement stays unexplained or the budget ran out."""
        return bool(self._data.get("explained", self._exit_code == 0))

    @property
    def calibrated_parameters(self) -> Dict[str, float]:
        """The nominal parameters calibrated before the search (name → value)."""
        return dict(self._data["calibrated_parameters"])

    @property
    def missing_effect(self) -> Optional[Dict[str, Any]]:
        """The selected effect (kind, location, value, unit, interval, …), or None."""
        return copy.deepcopy(self._data.get("missing_effect"))

    @property
    def runner_up(self) -> Optional[Dict[str, Any]]:
        """The second-best candidate, or None."""
        return copy.deepcopy(self._data.get("runner_up"))

    @property
    def p_value(self) -> Optional[float]:
        """p-value of the nominal model's misfit."""
        return self._data.get("p_value")


class BenchResult(Result):
    """``eigenfit bench``: one record per run, a summary per problem and strategy."""

    command = "bench"

    @property
    def records(self) -> List[Dict[str, Any]]:
        """One entry per (problem, strategy, start) run."""
        return copy.deepcopy(self._data["records"])

    @property
    def summary(self) -> List[Dict[str, Any]]:
        """One entry per problem and strategy: success rate, median evaluations, verdicts."""
        return copy.deepcopy(self._data["summary"])


class CompareResult(Result):
    """``eigenfit compare``: strategies over targets and initial guesses."""

    command = "compare"

    @property
    def runs(self) -> List[Dict[str, Any]]:
        """One entry per (target, initial guess, strategy) run."""
        return copy.deepcopy(self._data["runs"])

    @property
    def summary(self) -> List[Dict[str, Any]]:
        """One entry per strategy: convergence counts and iteration statistics."""
        return copy.deepcopy(self._data["summary"])

    @property
    def converged(self) -> np.ndarray:
        """Whether each run converged, in the order of ``runs``."""
        return np.asarray([r["converged"] for r in self._data["runs"]], dtype=bool)

    @property
    def estimates(self) -> np.ndarray:
        """Each run's final estimate, shape (runs, parameters)."""
        return np.asarray([r["estimate"] for r in self._data["runs"]], dtype=float)


def _float_array(key: str, doc: str) -> Any:
    """A read-only property: the JSON field ``key`` as a float array."""
    return property(lambda self: np.asarray(self._data[key], dtype=float), doc=doc)


class CampbellResult(Result):
    """``eigenfit campbell``: damped whirl frequencies of a two-plane rotor over speed."""

    command = "campbell"

    speeds_rpm = _float_array("speeds_rpm", "The rotor speeds (rpm).")
    frequencies_hz = _float_array(
        "frequencies_hz", "Damped natural frequencies (Hz), shape (speeds, modes), ascending at each speed."
    )
    log_dec = _float_array("log_dec", "Logarithmic decrements, shape (speeds, modes).")
    critical_speeds_rpm = _float_array(
        "critical_speeds_rpm",
        "Speeds (rpm) where a followed mode with damping ratio below 1/√2 crosses the 1× line, ascending "
        "(crossings by more heavily damped modes, which have no resonance peak: "
        "``result['overdamped_crossings']``).",
    )

    @property
    def whirl(self) -> List[List[str]]:
        """Whirl of each mode at each speed: ``forward``, ``backward`` or ``mixed``."""
        return copy.deepcopy(self._data["whirl"])


#: Result class by name, for unpickling (the name, not the class, travels in the pickle).
RESULT_CLASSES = {
    c.__name__: c
    for c in (SimulateResult, EstimateResult, DiscoverResult, CompareResult, CampbellResult, Result)
}


def _restore(class_name: str, text: str, exit_code: int) -> Result:
    return RESULT_CLASSES[class_name].from_json(text, exit_code)
