"""Turning Python keyword arguments into an ``eigenfit`` command line.

The mapping is mechanical so that a new CLI option is usable from Python without a change here:
``max_iterations=50`` becomes ``--max-iterations 50``, ``maps=True`` becomes ``--maps``, a list
becomes a comma-separated value, a pair of numbers in a list of targets becomes ``K1:K2``.
Only the inputs that are Python objects rather than files (a measured mapping, a ROSS ``Rotor``,
scipy.sparse matrices) need code: they are written to temporary files that live as long as the
call.
"""

from __future__ import annotations

import difflib
import os
import tempfile
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any, Optional

import numpy as np

from .matrices import MatricesModel

#: Options given as ``FROM:TO`` or ``FROM:TO:COUNT`` (a tuple in Python).
_COLON_OPTIONS = {"range", "sweep", "speeds"}
#: Options that repeat once per item (``--set a=1 --set b=2``); a mapping gives NAME=VALUE items.
_REPEATED_OPTIONS = {"set": "--set", "sets": "--set", "effect": "--effect", "effects": "--effect"}


class TempFiles:
    """A temporary folder for the files one call writes; removed when the call ends."""

    def __init__(self) -> None:
        self._dir: Optional[tempfile.TemporaryDirectory[str]] = None

    def path(self, name: str) -> Path:
        if self._dir is None:
            self._dir = tempfile.TemporaryDirectory(prefix="eigenfit-")
        return Path(self._dir.name) / name

    def __enter__(self) -> "TempFiles":
        return self

    def __exit__(self, *exc: object) -> None:
        if self._dir is not None:
            self._dir.cleanup()


def _number(x: Any) -> str:
    # repr() of a float round-trips exactly, so the CLI sees the very value the caller passed.
    if isinstance(x, (bool, np.bool_)):
        raise TypeError(f"expected a number, got {x!r}")
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    return repr(float(x))


def _scalar(x: Any) -> str:
    if isinstance(x, (str, os.PathLike)):
        return os.fspath(x)
    return _number(x)


def _list(value: Any) -> str:
    """A comma-separated list; items that are sequences themselves become ``a:b``."""
    items = []
    for item in value:
        if isinstance(item, (str, os.PathLike)) or np.ndim(item) == 0:
            items.append(_scalar(item))
        else:
            items.append(":".join(_number(v) for v in np.asarray(item).ravel()))
    return ",".join(items)


def check_keywords(function: str, command: str, keywords: Iterable[str], accepted: Iterable[str] = ()) -> None:
    """Raises ``TypeError`` naming the first keyword that is no option of ``eigenfit COMMAND``.

    A keyword ``max_iterations`` is the option ``--max-iterations``; ``set``/``sets`` and
    ``effect``/``effects`` are ``--set`` and ``--effect``. The message names the function, the
    keyword, the nearest valid one (a typo such as ``stifness``) and all of them, as Python's own
    "unexpected keyword argument" would, instead of the command line's usage text.
    ``accepted``: the function's own keywords (valid whatever the command's options are).
    """
    from . import _native

    names = _native.options(command)
    if names is None:
        return
    valid = {n.replace("-", "_") for n in names if n not in ("json", "help", "version")}
    valid |= {k for k, flag in _REPEATED_OPTIONS.items() if flag[2:] in names}
    valid |= set(accepted)
    for key in keywords:
        if key in valid:
            continue
        close = difflib.get_close_matches(key, sorted(valid), n=1)
        hint = f"; did you mean '{close[0]}'?" if close else ""
        raise TypeError(
            f"{function}() got an unexpected keyword argument '{key}'{hint} "
            f"Its keywords are: {', '.join(sorted(valid))}"
        )


def option_args(options: Mapping[str, Any]) -> list[str]:
    """CLI arguments for keyword options; ``None`` and ``False`` leave the option out."""
    args: list[str] = []
    for key, value in options.items():
        if value is None or value is False:
            continue
        flag = "--" + key.replace("_", "-")
        if key in _REPEATED_OPTIONS:
            flag = _REPEATED_OPTIONS[key]
            items = [f"{k}={_scalar(v)}" for k, v in value.items()] if isinstance(value, Mapping) else value
            if isinstance(items, str):
                items = [items]
            for item in items:
                args += [flag, str(item)]
        elif value is True:
            args.append(flag)
        elif key in _COLON_OPTIONS and not isinstance(value, str):
            args += [flag, ":".join(_number(v) for v in value)]
        elif isinstance(value, (str, os.PathLike)) or np.ndim(value) == 0:
            args += [flag, _scalar(value)]
        else:
            args += [flag, _list(value)]
    return args


def model_args(model: Any, tmp: TempFiles) -> list[str]:
    """``--preset NAME`` or ``--model FILE`` for a preset name, a model file or an in-memory model.

    A string naming an existing file (or containing a path separator or ending in ``.toml``) is a
    file; any other string is a preset name, so a typo in a preset name gets the CLI's list of
    presets rather than "file not found".
    """
    if isinstance(model, os.PathLike):
        return ["--model", os.fspath(model)]
    if isinstance(model, str):
        looks_like_file = os.path.exists(model) or os.sep in model or "/" in model or model.endswith(".toml")
        return ["--model", model] if looks_like_file else ["--preset", model]
    if isinstance(model, MatricesModel):
        # eigenfit.MatricesModel: its matrices and model file in the call's temporary folder.
        return ["--model", os.fspath(model.save(tmp.path("matrices")))]
    saved = _save_ross_rotor(model, tmp)
    if saved is not None:
        return ["--model", os.fspath(saved)]
    raise TypeError(f"model: expected a preset name or a model file path, got {type(model).__name__}")


def is_ross_rotor(model: Any) -> bool:
    """Whether `model` is a ROSS rotor object (checked by module, so ROSS need not be installed)."""
    return type(model).__module__.split(".")[0] == "ross" and hasattr(model, "save")


def _save_ross_rotor(model: Any, tmp: TempFiles) -> Optional[Path]:
    """A ROSS ``Rotor`` saved (``rotor.save``) to a temporary file for the CLI to read, or None."""
    if not is_ross_rotor(model):
        return None
    path = tmp.path("rotor.toml")
    model.save(path)
    return path


def measured_args(measured: Any, tmp: TempFiles) -> list[str]:
    """``--measured FILE`` for a CSV path or a mapping of arrays.

    The mapping needs ``frequency_hz`` and may give ``mode`` (counted from 1; default 1, 2, …) and
    ``std_hz``; it is written as the CLI's CSV, so the CLI's checks (and messages) apply to it.
    """
    if isinstance(measured, (str, os.PathLike)):
        return ["--measured", os.fspath(measured)]
    if not isinstance(measured, Mapping):
        raise TypeError(
            "measured: expected a CSV file path or a mapping with `mode`, `frequency_hz` "
            f"(and `std_hz`) arrays, got {type(measured).__name__}"
        )
    unknown = set(measured) - {"mode", "frequency_hz", "std_hz"}
    if unknown:
        raise ValueError(f"measured: unknown keys {sorted(unknown)}; expected mode, frequency_hz, std_hz")
    if "frequency_hz" not in measured:
        raise ValueError("measured: the mapping needs `frequency_hz`")
    freq = np.atleast_1d(np.asarray(measured["frequency_hz"], dtype=float))
    n = len(freq)
    mode = (
        np.arange(1, n + 1) if measured.get("mode") is None else np.atleast_1d(np.asarray(measured["mode"]))
    )
    columns: list[tuple[str, Iterable[Any]]] = [("mode", mode), ("frequency_hz", freq)]
    if measured.get("std_hz") is not None:
        columns.append(("std_hz", np.atleast_1d(np.asarray(measured["std_hz"], dtype=float))))
    for name, col in columns:
        if np.ndim(col) != 1 or len(col) != n:  # type: ignore[arg-type]
            raise ValueError(f"measured: `{name}` has {len(col)} values, `frequency_hz` has {n}")  # type: ignore[arg-type]
    for m in mode:
        if not float(m).is_integer():
            raise ValueError(f"measured: `mode` must hold whole numbers counted from 1, got {m!r}")
    path = tmp.path("measured.csv")
    lines = [",".join(name for name, _ in columns)]
    for row in zip(*(col for _, col in columns)):
        lines.append(",".join([str(int(row[0]))] + [repr(float(v)) for v in row[1:]]))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return ["--measured", os.fspath(path)]
