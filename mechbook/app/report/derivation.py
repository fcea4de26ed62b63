"""One system's results as the check stored them, read back for the report on demand.

`StoredSystem` wraps the store's text and arrays of a system (mechbook.engine.derive
.computed): the Lagrangian, Lagrange's equations, momenta, the equilibria SymPy found and
every linear system the check built (its point, M, C, K, and the numbers at the default
values). Each item is read back (mechbook.app.report.stored) the first time it is asked
for; an item the check did not derive is None, and the page derives it only if that is
cheap, or says it is not shown.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import sympy as sp

from mechbook.app.report.stored import matrix, read
from mechbook.core.numeval import NotNumeric, evaluate
from mechbook.errors import MechbookError

_LINEAR = re.compile(r"linear_(\d+)/point")


@dataclass
class Linear:
    """A linear system the check built: M·δq̈ + C·δq̇ + K·δq = F about `point`, or (with
    velocity constraints) first order, E·ż = Â·z (M, C, K None; engine.state_space)."""

    point: dict  # {coordinate symbol: value}
    M: sp.Matrix | None
    C: sp.Matrix | None
    K: sp.Matrix | None
    steady: dict | None  # held momenta of a steady motion (Routh), None for an equilibrium
    numeric: dict  # the arrays stored for it (M, K, frequencies, growth_rates)
    first_order: bool = False  # E, Â stored instead; `rates` the steady motion's, if one
    rates: dict | None = None

    def matrices(self, values: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """M, C, K at `values` (30 digits, core.numeval); MechbookError where a symbol has
        no value there (a point in an answer's own symbols)."""
        if self.first_order:
            raise MechbookError("a first-order linearization (velocity constraints) has no "
                                "M, C, K")
        out = []
        for A in (self.M, self.C, self.K):
            left = A.free_symbols - set(values)
            if left:
                raise MechbookError("the linear system keeps "
                                    f"{', '.join(sorted(map(str, left)))} without a value")
            try:
                out.append(np.array([[evaluate(x, values)[0].real for x in row]
                                     for row in A.tolist()], float).reshape(A.shape))
            except (NotNumeric, TypeError, ValueError, ZeroDivisionError, OverflowError):
                raise MechbookError("the linear system has no finite value here") from None
        return out[0], out[1], out[2]


class StoredSystem:
    """The stored results of one system, read back lazily with the system's names."""

    def __init__(self, entry: dict | None, names: dict):
        entry = entry or {}
        self.text: dict[str, str] = dict(entry.get("symbolic") or {})
        self.arrays: dict = dict(entry.get("numeric") or {})
        self.notes: dict[str, str] = dict(entry.get("notes") or {})
        self.names = names

    def get(self, key: str):
        """The stored item `key` read back, or None (not stored, or unreadable)."""
        text = self.text.get(key)
        if text is None:
            return None
        return read(text, self.names)

    @cached_property
    def equilibria(self) -> list[dict]:
        found = self.get("equilibria")
        return [self._point(p) for p in found] if isinstance(found, list) else []

    @cached_property
    def linears(self) -> list[Linear]:
        out = []
        for key in sorted(self.text, key=_index):
            m = _LINEAR.fullmatch(key)
            if not m:
                continue
            tag = f"linear_{m.group(1)}"
            numeric = {k.split("/", 1)[1]: v for k, v in self.arrays.items()
                       if k.startswith(tag + "/")}
            try:
                point = self._point(self.get(key))
                if f"{tag}/Ahat" in self.text:  # first order: its numbers are stored
                    rates = self.get(f"{tag}/rates")
                    out.append(Linear(point, None, None, None, None, numeric, True,
                                      rates if isinstance(rates, dict) else None))
                    continue
                M, C, K = (matrix(self.get(f"{tag}/{x}")) for x in ("M", "C", "K"))
                steady = self.get(f"{tag}/steady_momenta")
            except MechbookError:
                continue
            out.append(Linear(point, M, C, K, steady if isinstance(steady, dict) else None,
                              numeric))
        return out

    def linear_at(self, point: dict, values: dict, steady: bool = False) -> Linear | None:
        """The stored linear system about `point` (the same expressions, or the same
        numbers at `values`)."""
        for lin in self.linears:
            if (lin.steady is not None or bool(lin.rates)) != steady:
                continue
            if same_point(lin.point, point, values):
                return lin
        return None

    @staticmethod
    def _point(value) -> dict:
        if not isinstance(value, dict):
            raise MechbookError("not a point")
        return dict(value)


def same_point(a: dict, b: dict, values: dict) -> bool:
    """Whether two points are one: equal expressions, or equal numbers at `values`."""
    if set(map(str, a)) != set(map(str, b)):
        return False
    by_name = {str(k): v for k, v in b.items()}
    for k, v in a.items():
        w = by_name[str(k)]
        if sp.srepr(v) == sp.srepr(w):
            continue
        try:
            x, _ = evaluate(v - w, values)
        except (NotNumeric, TypeError, ValueError, ZeroDivisionError, OverflowError):
            return False
        scale = max(1.0, abs(complex(evaluate(v, values)[0])))
        if abs(x) > 1e-12 * scale:
            return False
    return True


def _index(key: str) -> tuple:
    m = re.match(r"linear_(\d+)/", key)
    return (int(m.group(1)) if m else -1, key)
