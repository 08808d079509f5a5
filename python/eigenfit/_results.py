"""Typed results. Each holds the command's JSON (the very object ``eigenfit … --json`` prints)
and reads its properties from it, so ``to_dict()`` equals the CLI's output by construction and
pickling is the JSON text (small, version-tolerant, safe to ship between Dask workers)."""

from __future__ import annotations

import copy
import html
import json
import math
from typing import Any, Dict, List, Optional

import numpy as np


def _array(value: Any) -> Optional[np.ndarray]:
    return None if value is None else np.asarray(value, dtype=float)


def _arrays(mapping: Optional[Dict[str, Any]]) -> Dict[str, np.ndarray]:
    return {k: np.asarray(v, dtype=float) for k, v in (mapping or {}).items()}


def _esc(value: Any) -> str:
    """``value`` as HTML text (``& < > " '`` escaped)."""
    return html.escape(str(value), quote=True)


def _number(value: Optional[float], digits: int) -> str:
    """``value`` to ``digits`` significant digits as the CLI's HTML report shows it: plain in
    [1e-3, 1e5), else ``1.2346 × 10⁵``; ``—`` for none."""
    if value is None or not math.isfinite(value):
        return "—"
    if value == 0:
        return "0"
    exponent = math.floor(math.log10(abs(value)))
    if -3 <= exponent < 5:
        return f"{value:.{max(digits - 1 - exponent, 0)}f}"
    mantissa, exp = f"{value:.{digits - 1}e}".split("e")
    sup = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
    return f"{mantissa} × 10{str(int(exp)).translate(sup)}"


def _cell(value: Any, digits: int = 6) -> str:
    """A table cell: a number with its exact value in ``data-value``, else text."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return f"<td>{_esc('—' if value is None else value)}</td>"
    if isinstance(value, int):
        return f'<td class="num" data-value="{float(value)!r}">{value}</td>'
    return f'<td class="num" data-value="{float(value)!r}">{_esc(_number(float(value), digits))}</td>'


def _table(cls: str, caption: str, head: List[str], rows: List[List[str]]) -> str:
    """An HTML table of class ``cls``; ``rows`` hold cells made by :func:`_cell`."""
    out = [f'<table class="{_esc(cls)}"><caption>{_esc(caption)}</caption><thead><tr>']
    out += [f"<th>{_esc(h)}</th>" for h in head]
    out.append("</tr></thead><tbody>")
    out += ["<tr>" + "".join(r) + "</tr>" for r in rows]
    out.append("</tbody></table>")
    return "".join(out)


def _unit(units: Dict[str, Any], name: str) -> str:
    """The unit the JSON states for ``name`` (``–`` for a dimensionless one), else a note."""
    unit = units.get(name)
    if unit is None:
        return "as the model declares"
    return "–" if unit in ("", "-") else str(unit)


def _effect_label(effect: Dict[str, Any]) -> str:
    """``kind@location`` as the CLI names an effect (``kind`` alone without a location)."""
    location = effect.get("location")
    return str(effect.get("kind")) + ("" if location is None else f"@{location}")


def _verdict_html(word: str, good: bool) -> str:
    colour = "#009e73" if good else "#d55e00"
    return (
        f'<p class="verdict {"good" if good else "bad"}" style="border-left:.4em solid {colour};'
        f'padding-left:.6em"><b>Verdict:</b> <span class="word">{_esc(word)}</span></p>'
    )


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

    def _html_body(self) -> str:
        """The tables of this kind of result (the scalar fields for the base class)."""
        rows = [
            [_cell(k), _cell(v)]
            for k, v in self._data.items()
            if v is None or isinstance(v, (str, int, float, bool))
        ]
        return _table("fields", "Fields", ["field", "value"], rows)

    def _repr_html_(self) -> str:
        """The result as HTML for notebooks: the same tables as the CLI's ``--report`` page
        (its plots and provenance are in that page only). Every text is HTML-escaped."""
        title = f"eigenfit {self.command or 'result'}: {self._data.get('model', '')}"
        return f'<div class="eigenfit-result"><h3>{_esc(title)}</h3>{self._html_body()}</div>'


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
    def data_rank(self) -> Optional[Dict[str, Any]]:
        """Whether the data determine the parameters, decided by rank: ``counted`` (what was
        counted, in words), ``rows`` (frequencies and shape components), ``parameters``,
        ``rank`` (of the weighted Jacobian of all the data at the estimate) and
        ``null_directions`` (the parameter combinations the data cannot tell apart, in words;
        empty at full rank). None from a run-up estimate, which does not report it."""
        return copy.deepcopy(self._data.get("data_rank"))

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

    def _html_body(self) -> str:
        d = self._data
        units = d.get("units") or {}
        intervals = d.get("intervals") or {}
        status = d.get("parameter_status") or {}
        initial = d.get("initial") or {}
        at_limit = set(d.get("at_limit") or [])
        rows = []
        for name, value in d["parameters"].items():
            iv = intervals.get(name) or [None, None]
            estimate = (
                _cell(f"— (on a limit at {_number(value, 6)})") if name in at_limit else _cell(value, 6)
            )
            rows.append(
                [
                    _cell(name),
                    _cell(_unit(units, name)),
                    _cell(initial.get(name), 4),
                    estimate,
                    _cell(iv[0], 4),
                    _cell(iv[1], 4),
                    _cell(status.get(name, "")),
                ]
            )
        rank = d.get("data_rank")
        rank_html = ""
        if rank:
            unseen = rank.get("null_directions") or []
            rank_html = (
                f'<p class="data-rank">The data ({_esc(str(rank["counted"]))}) determine {int(rank["rank"])} of '
                f'{int(rank["parameters"])} parameter directions'
                + (f'; they cannot tell apart changes along: {_esc("; ".join(unseen))}' if unseen else "")
                + ".</p>"
            )
        parts = [
            _verdict_html(str(d.get("verdict")), self.acceptable and self.unique),
            rank_html,
            _table(
                "parameters",
                "Estimated parameters with 95 % intervals",
                ["parameter", "unit", "initial", "estimate", "95 % interval from", "to", "what the data say"],
                rows,
            ),
        ]
        # The measured mode numbers: the keys of ``pairing`` (measured → model mode), in order.
        paired = sorted(int(k) for k in (d.get("pairing") or {}))
        numbers = (
            paired if len(paired) == len(d["measured_hz"]) else list(range(1, len(d["measured_hz"]) + 1))
        )
        modes = [
            [_cell(n), _cell(m, 7), _cell(f, 7), _cell(f - m, 3)]
            for n, m, f in zip(numbers, d["measured_hz"], d["frequencies_hz"])
        ]
        parts.append(
            _table(
                "modes",
                "Measured and model frequencies at the estimate",
                ["mode", "measured [Hz]", "model [Hz]", "model − measured [Hz]"],
                modes,
            )
        )
        return "".join(parts)


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

    def _html_body(self) -> str:
        d = self._data
        units = d.get("units") or {}
        effects = []
        for e in d.get("missing_effects") or []:
            iv = e.get("interval") or [None, None]
            value = e.get("value")
            effects.append(
                [
                    _cell(e.get("label") or _effect_label(e)),
                    _cell(e.get("unit") if isinstance(value, (int, float)) else "–"),
                    _cell(value, 5) if isinstance(value, (int, float)) else _cell("on"),
                    _cell(iv[0], 4),
                    _cell(iv[1], 4),
                    _cell(e.get("delta_aicc"), 4),
                ]
            )
        refitted = d.get("refitted_parameters") or {}
        params = []
        for name, value in d["calibrated_parameters"].items():
            r = refitted.get(name) or {}
            iv = r.get("interval") or [None, None]
            params.append(
                [
                    _cell(name),
                    _cell(_unit(units, name)),
                    _cell(value, 6),
                    _cell(r.get("value"), 6),
                    _cell(iv[0], 4),
                    _cell(iv[1], 4),
                ]
            )
        return "".join(
            [
                _verdict_html("explained" if self.explained else "not explained", self.explained),
                _table(
                    "effects",
                    "Missing effects, strongest first",
                    ["effect", "unit", "value", "95 % interval from", "to", "ΔAICc [–]"],
                    effects,
                ),
                _table(
                    "parameters",
                    "The model's parameters: calibrated alone, and refitted with the named effects",
                    ["parameter", "unit", "calibrated", "refitted", "95 % interval from", "to"],
                    params,
                ),
            ]
        )


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

    def _html_body(self) -> str:
        rows = [
            [
                _cell(s["problem"]),
                _cell(s["strategy"]),
                _cell(s["runs"]),
                _cell(100.0 * s["success_rate"], 3),
                _cell(s["median_evaluations"], 4),
                _cell(s.get("median_evaluations_success"), 4),
                _cell(", ".join(f"{k} {v}" for k, v in (s.get("verdicts") or {}).items())),
            ]
            for s in self._data["summary"]
        ]
        return _table(
            "summary",
            "Success rate and model evaluations per problem and strategy",
            [
                "problem",
                "strategy",
                "runs",
                "success [%]",
                "median evaluations",
                "median evaluations (successes)",
                "verdicts",
            ],
            rows,
        )


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

    def _html_body(self) -> str:
        rows = [
            [
                _cell(k["rpm"], 6),
                _cell(k["rpm"] / 60.0, 6),
                _cell(k["whirl"]),
                _cell(k["log_dec"], 4),
                _cell(k["damping_ratio"], 3),
            ]
            for k in self._data.get("critical_speeds") or []
        ]
        return _table(
            "critical-speeds",
            "Critical speeds: where a followed mode crosses the 1× line",
            ["speed [rpm]", "frequency [Hz]", "whirl", "log decrement [–]", "damping ratio ζ [–]"],
            rows,
        )


#: Result class by name, for unpickling (the name, not the class, travels in the pickle).
# Every result class by name, for unpickling; taken from the subclasses so that a new result
# (BenchResult was missed when listed by hand) cannot be left out.
RESULT_CLASSES = {c.__name__: c for c in (Result, *Result.__subclasses__())}


def _restore(class_name: str, text: str, exit_code: int) -> Result:
    return RESULT_CLASSES[class_name].from_json(text, exit_code)
