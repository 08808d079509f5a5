"""The functions: each builds the command line from its arguments and runs it in-process."""

from __future__ import annotations

import os
from typing import Any, Mapping, Optional, Sequence, Type, TypeVar, Union

from . import _native
from ._args import TempFiles, check_keywords, is_ross_rotor, measured_args, model_args, option_args
from ._results import (
    BenchResult,
    CampbellResult,
    CompareResult,
    DiscoverResult,
    EstimateResult,
    Result,
    SimulateResult,
)

#: A preset name (``"paper-rotor"``), a model file path, or (once the CLI reads ROSS files) a
#: ROSS ``Rotor``.
Model = Union[str, "os.PathLike[str]", Any]
#: A measured-frequencies CSV path, or a mapping with ``mode``, ``frequency_hz`` and ``std_hz``.
Measured = Union[str, "os.PathLike[str]", Mapping[str, Any]]

R = TypeVar("R", bound=Result)

#: Exit code of an estimation that did not converge: its result is still returned.
EXIT_NOT_CONVERGED = 3


class EigenfitError(Exception):
    """A failed eigenfit call: ``message`` is the CLI's message, ``exit_code`` its exit code
    (2 bad input: arguments, files, data; 1 internal failure)."""

    def __init__(self, message: str, exit_code: int) -> None:
        super().__init__(message, exit_code)
        self.message = message
        self.exit_code = exit_code

    def __str__(self) -> str:
        return self.message


def run(args: Sequence[str], result_class: Type[R]) -> R:
    """Runs ``eigenfit ARGS… --json`` in this process and wraps its JSON in ``result_class``.

    This is what every function here calls; use it for CLI options that have no keyword yet.
    Raises :class:`EigenfitError` with the CLI's message and exit code on failure; exit code 3
    (not converged or not acceptable) returns the result, unless there is none (a budget spent
    before the fit could start): then it raises with exit code 3.
    """
    code, text = _native.run_json([os.fspath(a) for a in args])
    if code == 0 or (code == EXIT_NOT_CONVERGED and text.startswith("{")):
        return result_class.from_json(text, code)  # type: ignore[return-value]
    raise EigenfitError(text, code)


def _call(
    command: str,
    result_class: Type[R],
    model: Model,
    measured: Optional[Measured],
    options: Mapping[str, Any],
) -> R:
    # A misspelled keyword is a TypeError naming it, before any file is written or work done.
    check_keywords(command, command, options)
    with TempFiles() as tmp:
        args = [command] + model_args(model, tmp)
        if measured is not None:
            args += measured_args(measured, tmp)
        args += option_args(options)
        try:
            return run(args, result_class)
        except EigenfitError as e:
            if is_ross_rotor(model) and e.exit_code == 2:
                # The message names a temporary file the user never saw: say what it was.
                raise EigenfitError(
                    f"model: the ROSS Rotor, saved with rotor.save() for eigenfit to read: {e.message}",
                    e.exit_code,
                ) from None
            raise


def simulate(
    model: Model,
    stiffness: Optional[Sequence[float]] = None,
    *,
    modes: int = 4,
    set: Optional[Mapping[str, float]] = None,
    effects: Optional[Sequence[str]] = None,
    sweep: Optional[Sequence[float]] = None,
    solver: Optional[str] = None,
    **options: Any,
) -> SimulateResult:
    """Natural frequencies of a model, as ``eigenfit simulate``.

    Args:
        model: a preset name (``"paper-rotor"``, ``"ross-example"``, ``"uniform-rotor"``) or a
            model file path.
        stiffness: bearing stiffnesses K1, K2, … in N/m (default: the model's values).
        modes: number of modes.
        set: parameter overrides, name → value.
        effects: what-if effects, ``"KIND[@LOCATION]=VALUE"`` each.
        sweep: ``(from, to, count)``: every bearing at the same log-spaced stiffness.
        solver: eigen-solver backend (``auto``, ``banded``, ``dense``, ``lapack``).
        **options: any other ``eigenfit simulate`` option, ``elements=200`` → ``--elements 200``;
            ``shapes=True`` adds the mass-normalised mode shapes (``result.mode_shapes``, an
            array of DOFs × modes, rows named by ``result.dof_labels``).

    Returns:
        SimulateResult; ``to_dict()`` is the CLI's JSON.

    Raises:
        TypeError: a keyword that is no option of ``eigenfit simulate`` (named, with the nearest).
    """
    return _call(
        "simulate",
        SimulateResult,
        model,
        None,
        {
            "stiffness": stiffness,
            "modes": modes,
            "set": set,
            "effect": effects,
            "sweep": sweep,
            "solver": solver,
            **options,
        },
    )


def estimate(
    model: Model,
    measured: Measured,
    *,
    strategy: Optional[str] = None,
    initial: Optional[Sequence[float]] = None,
    residual: Optional[str] = None,
    max_iterations: Optional[int] = None,
    solver: Optional[str] = None,
    **options: Any,
) -> EstimateResult:
    """Update the model's bearing stiffnesses to match measured frequencies, as ``eigenfit estimate``.

    Args:
        model: a preset name or a model file path.
        measured: a CSV path (``mode,frequency_hz[,std_hz]``) or a mapping with ``frequency_hz``
            and optionally ``mode`` (counted from 1) and ``std_hz`` arrays.
        strategy: ``newton``, ``p-step`` or ``damped`` (the CLI's default).
        initial: initial stiffnesses (default: the model's values).
        residual: residual of the damped strategy: ``relative``, ``hz`` or ``eigenvalue``.
        max_iterations: iteration limit.
        solver: eigen-solver backend.
        **options: any other ``eigenfit estimate`` option.

    Returns:
        EstimateResult. A run that did not converge or whose fit is not acceptable is returned
        too, with ``acceptable == False`` and ``exit_code == 3``.

    Raises:
        EigenfitError: bad input (exit code 2) or an internal failure (1).
    """
    return _call(
        "estimate",
        EstimateResult,
        model,
        measured,
        {
            "strategy": strategy,
            "initial": initial,
            "residual": residual,
            "max_iterations": max_iterations,
            "solver": solver,
            **options,
        },
    )


def discover(
    model: Model, measured: Measured, *, solver: Optional[str] = None, **options: Any
) -> DiscoverResult:
    """Find where model and measurement disagree and name the missing effect, as ``eigenfit discover``.

    Args:
        model: a preset name or a model file path.
        measured: a CSV path or a mapping (see :func:`estimate`).
        solver: eigen-solver backend.
        **options: any other ``eigenfit discover`` option, e.g. ``assumed_std=0.002``,
            ``write_model="augmented.toml"``.
    """
    return _call("discover", DiscoverResult, model, measured, {"solver": solver, **options})


def compare(
    model: Model,
    targets: Sequence[Sequence[float]],
    *,
    grid: Optional[int] = None,
    initials: Optional[Sequence[Sequence[float]]] = None,
    strategies: Optional[Sequence[str]] = None,
    solver: Optional[str] = None,
    **options: Any,
) -> CompareResult:
    """Compare update strategies over targets and initial guesses, as ``eigenfit compare``.

    Args:
        model: a preset name or a model file path.
        targets: target stiffness sets, e.g. ``[(2e5, 5e4)]``.
        grid: a log grid of initial guesses with this many points per parameter (``range=(lo, hi)``
            sets its range), or
        initials: explicit initial guesses, e.g. ``[(1e5, 1e5), (1e6, 1e4)]``.
        strategies: e.g. ``["newton", "damped"]`` (default: all).
        solver: eigen-solver backend.
        **options: any other ``eigenfit compare`` option (``decimals``, ``std_hz``, ``modes``, …).
    """
    return _call(
        "compare",
        CompareResult,
        model,
        None,
        {
            "targets": targets,
            "grid": grid,
            "initials": initials,
            "strategies": strategies,
            "solver": solver,
            **options,
        },
    )


def bench(
    problems: Sequence[Union[str, "os.PathLike[str]"]],
    *,
    strategies: Optional[Sequence[str]] = None,
    starts: Optional[int] = None,
    seed: Optional[int] = None,
    budget: Optional[int] = None,
    **options: Any,
) -> BenchResult:
    """Strategies × problems × starts, as ``eigenfit bench`` (docs/strategies.md).

    Args:
        problems: built-in names (``paper-table3``, ``shear-frame``, …) or problem-file paths.
        strategies: registered names with settings after colons, e.g. ``["damped", "trf",
            "tmcmc:samples=500"]`` (a strategy registered in this process by a Rust program is
            found too).
        starts: starts per problem and strategy; seed: their seed; budget: evaluations per run.
        **options: any other ``eigenfit bench`` option (``records``, ``plot``, ``max_iterations``).

    Returns:
        BenchResult (exit code 3 when some problem and strategy never reached the truth).
    """
    args = ["bench", "--problems", ",".join(os.fspath(p) for p in problems)]
    check_keywords("bench", "bench", options)
    args += option_args(
        {"strategies": strategies, "starts": starts, "seed": seed, "budget": budget, **options}
    )
    return run(args, BenchResult)


def campbell(
    model: Model,
    speeds: Union[str, Sequence[float]],
    *,
    modes: int = 6,
    **options: Any,
) -> CampbellResult:
    """Campbell diagram of a two-plane rotor (a ROSS rotor file or ``Rotor``), as ``eigenfit campbell``.

    Args:
        model: a rotor file saved by ROSS ``Rotor.save`` (TOML or JSON), or a ROSS ``Rotor``.
        speeds: ``(from, to, count)`` in rpm, linearly spaced, or the CLI's ``"FROM:TO:COUNT"``.
        modes: number of modes per speed.
        **options: any other ``eigenfit campbell`` option, e.g. ``plot="out/"``.

    Returns:
        CampbellResult; ``to_dict()`` is the CLI's JSON.
    """
    return _call("campbell", CampbellResult, model, None, {"speeds": speeds, "modes": modes, **options})
