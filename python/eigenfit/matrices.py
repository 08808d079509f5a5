"""A ``kind = "matrices"`` model from scipy.sparse (or numpy) matrices.

    >>> import eigenfit
    >>> model = eigenfit.MatricesModel(
    ...     K0, M0,
    ...     parameters=[{"name": "zone1", "nominal": 1.0, "stiffness": K1, "lower": 0.05, "upper": 20.0,
    ...                  "scale": "log"}],
    ... )
    >>> eigenfit.simulate(model, modes=10).frequencies_hz
    >>> eigenfit.estimate(model, {"frequency_hz": measured}).parameters      # {"zone1": …}

K(p) = K0 + Σ pᵢ Kᵢ and M(p) = M0 + Σ pᵢ Mᵢ, as in a model file (docs/matrices.md). Every call
writes the matrices as Matrix Market files (the lower triangle, as ``scipy.io.mmwrite`` writes
a symmetric matrix) and the model file into the call's temporary folder, so the CLI's reader
and its checks (sizes, symmetry, finite entries) apply unchanged; :meth:`MatricesModel.save`
writes them to a folder of your choice for the CLI. Needs scipy.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, Optional

#: Keys of one parameter mapping (those of a model file's ``[[parameter]]`` table).
_PARAMETER_KEYS = {"name", "nominal", "lower", "upper", "scale", "unit", "stiffness", "mass"}


def _toml_string(s: str) -> str:
    return '"' + str(s).replace("\\", "\\\\").replace('"', '\\"') + '"'


def _sparse(name: str, matrix: Any) -> Any:
    import scipy.sparse as sp

    a = sp.csr_matrix(matrix) if not sp.issparse(matrix) else matrix
    if a.ndim != 2 or a.shape[0] != a.shape[1]:
        raise ValueError(f"{name}: the matrix must be square, got shape {a.shape}")
    return a


class MatricesModel:
    """A model given by its matrices, for :func:`eigenfit.simulate`, :func:`eigenfit.estimate`,
    :func:`eigenfit.discover` and :func:`eigenfit.compare` (pass it as ``model``).

    Args:
        stiffness: K0, a square scipy.sparse matrix (or anything ``scipy.sparse.csr_matrix``
            takes), symmetric.
        mass: M0, same size.
        parameters: one mapping per parameter with the keys of a model file's ``[[parameter]]``
            table: ``name``, ``nominal``, optional ``lower``, ``upper``, ``scale`` (``"log"`` or
            ``"linear"``), ``unit``, and the matrices ``stiffness`` (∂K/∂p) and ``mass`` (∂M/∂p).
        name: the model's name in reports.
        dof_map: optional rows ``(node, direction, x, y, z)``, one per DOF in order.
    """

    def __init__(
        self,
        stiffness: Any,
        mass: Any,
        parameters: Sequence[Mapping[str, Any]] = (),
        *,
        name: Optional[str] = None,
        dof_map: Optional[Sequence[Sequence[Any]]] = None,
    ) -> None:
        self.stiffness = _sparse("stiffness", stiffness)
        self.mass = _sparse("mass", mass)
        self.parameters = [dict(p) for p in parameters]
        self.name = name
        self.dof_map = None if dof_map is None else [tuple(row) for row in dof_map]
        for i, p in enumerate(self.parameters, 1):
            unknown = set(p) - _PARAMETER_KEYS
            if unknown:
                raise ValueError(f"parameter {i}: unknown keys {sorted(unknown)}; expected {sorted(_PARAMETER_KEYS)}")
            for key in ("name", "nominal"):
                if key not in p:
                    raise ValueError(f"parameter {i}: `{key}` is missing")
        if self.dof_map is not None:
            n = self.stiffness.shape[0]
            if len(self.dof_map) != n or any(len(row) != 5 for row in self.dof_map):
                raise ValueError(f"dof_map: expected {n} rows of (node, direction, x, y, z)")

    def save(self, folder: "str | os.PathLike[str]") -> Path:
        """Writes the matrices (``K0.mtx``, ``M0.mtx``, ``K1.mtx``, …) and ``model.toml`` into
        ``folder`` (created if needed); returns the model file's path."""
        import scipy.io
        import scipy.sparse as sp

        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)

        def write(file: str, matrix: Any) -> str:
            # One triangle under a `symmetric` header; the CLI refuses a matrix whose triangles
            # disagree only when both are stored, so an asymmetric input is written `general`.
            a = sp.csr_matrix(matrix)
            symmetric = (abs(a - a.T) > 1e-10 * abs(a).max()).nnz == 0 if a.nnz else True
            out = sp.tril(a).tocoo() if symmetric else a.tocoo()
            scipy.io.mmwrite(folder / file, out, symmetry="symmetric" if symmetric else "general")
            return file

        lines = ['kind = "matrices"']
        if self.name is not None:
            lines.append(f"name = {_toml_string(self.name)}")
        lines += [
            f"stiffness = {_toml_string(write('K0.mtx', self.stiffness))}",
            f"mass = {_toml_string(write('M0.mtx', self.mass))}",
        ]
        if self.dof_map is not None:
            rows = ["dof,node,direction,x,y,z"] + [
                f"{d},{int(node)},{direction},{float(x)!r},{float(y)!r},{float(z)!r}"
                for d, (node, direction, x, y, z) in enumerate(self.dof_map, 1)
            ]
            (folder / "dofs.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
            lines.append('dofs = "dofs.csv"')
        for i, p in enumerate(self.parameters, 1):
            lines += ["", "[[parameter]]", f"name = {_toml_string(p['name'])}", f"nominal = {float(p['nominal'])!r}"]
            for key in ("lower", "upper"):
                if p.get(key) is not None:
                    lines.append(f"{key} = {float(p[key])!r}")
            for key in ("scale", "unit"):
                if p.get(key) is not None:
                    lines.append(f"{key} = {_toml_string(p[key])}")
            if p.get("stiffness") is not None:
                lines.append(f"stiffness = {_toml_string(write(f'K{i}.mtx', _sparse(p['name'], p['stiffness'])))}")
            if p.get("mass") is not None:
                lines.append(f"mass = {_toml_string(write(f'M{i}.mtx', _sparse(p['name'], p['mass'])))}")
        path = folder / "model.toml"
        path.write_text("\n".join(lines) + "\n", encoding="utf-8")
        return path
