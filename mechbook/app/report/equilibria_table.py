"""The equilibria table of a system's section, from what the check found and linearized.

Rows: the closed-form equilibria the check's SymPy search returned (those that exist at
the default values: real and inside the coordinates' domains, mechbook.engine.existence)
and every other point the check linearized about. For a point with a stored linear system
the row gives, at the default values: stability, each mode's frequency or, for a mode that
grows, its rate (mechbook.engine.growth), and the mode shapes as a matrix (columns,
largest entry 1). The frequencies of a one-degree-of-freedom system are also given exactly,
√(K/M).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
import sympy as sp

from mechbook.app.output.mathml import math
from mechbook.app.report.derivation import StoredSystem, same_point
from mechbook.core.numeval import NotNumeric, evaluate
from mechbook.engine.existence import existing
from mechbook.engine.growth import growth_rates
from mechbook.engine.linear import classify_matrices
from mechbook.engine.state_space import classify_exponents
from mechbook.errors import MechbookError

MAX_ROWS = 8


def equilibria_rows(page, sys_, view: StoredSystem, values: dict) -> tuple[list, list]:
    """(rows of the table, why each closed-form solution left out does not exist)."""
    found = page.step(f"equilibria ({sys_.name})", lambda: view.equilibria) or []
    points, left_out = existing(found, sys_, values)
    linears = page.step(f"linear systems ({sys_.name})", lambda: view.linears) or []
    rows, used = [], set()
    for point in points:
        lin = next((i for i, lin in enumerate(linears) if lin.steady is None
                    and i not in used and same_point(lin.point, point, values)), None)
        if lin is not None:
            used.add(lin)
        rows.append((point, linears[lin] if lin is not None else None))
    for i, lin in enumerate(linears):
        if i not in used:
            rows.append((lin.point, lin))
    out = []
    for point, lin in rows[:MAX_ROWS]:
        out.append(page.step(f"equilibrium {sys_.name} {len(out) + 1}",
                             lambda point=point, lin=lin: _row(page, sys_, point, lin, values))
                   or {"point": math(point), "kind": "", "stability": "", "frequencies": "",
                       "modes": "", "exact": "", "mck": ""})
    if len(rows) > MAX_ROWS:
        page.notes.append(f"equilibria ({sys_.name}): {len(rows) - MAX_ROWS} more not shown")
    return out, left_out


def _row(page, sys_, point: dict, lin, values: dict) -> dict:
    row = {"point": page.show(point), "kind": "equilibrium", "stability": "",
           "frequencies": "", "modes": "", "exact": "", "mck": "",
           "values": _numbers(sys_, point, values)}
    if lin is None:
        row["stability"] = "not linearized by the check"
        return row
    if lin.steady is not None or lin.rates:
        row["kind"] = "steady motion"
    if lin.first_order:
        return _first_order_row(row, lin)
    try:
        M, C, K = lin.matrices(values)
    except MechbookError:
        row["stability"] = "in the answer's own symbols: no numbers at the default values"
        return row
    with np.errstate(all="ignore"):
        row["stability"] = classify_matrices(M, C, K)
        freqs = lin.numeric.get("frequencies")
        if freqs is None or len(freqs) != M.shape[0]:
            freqs = _frequencies(M, C, K)
        rates = growth_rates(M, C, K)
    row["frequencies"] = _modes_text(freqs, rates)
    row["mck"] = page.step("M, C and K", lambda: _matrices(page, lin, M, C, K)) or ""
    if not np.any(C) and row["stability"] in ("stable", "marginal") and M.shape[0] > 1:
        row["modes"] = _shapes(M, K)
    if M.shape[0] == 1 and not np.any(C) and row["stability"] == "stable":
        exact = sp.Eq(sp.Symbol("omega_1"), sp.sqrt(lin.K[0, 0] / lin.M[0, 0]),
                      evaluate=False)
        row["exact"] = page.step("exact frequency", lambda: page.show(exact)) or ""
    return row


def _matrices(page, lin, M, C, K) -> str:
    """M·δq̈ + C·δq̇ + K·δq = 0 about the point: M and K (and C where it is not zero) as
    derived, simplified for reading, each with its numbers at the default values."""
    shown = [("M", lin.M, M), ("K", lin.K, K)]
    if np.any(C):
        shown.insert(1, ("C", lin.C, C))
    cells = []
    for name, exact, numbers in shown:
        num = sp.Matrix(numbers.shape[0], numbers.shape[1],
                        [sp.Float(float(f"{x:.6g}"), 6) for x in numbers.flatten()])
        cells.append(f'<div class="matrix"><span class="name">{name} =</span>'
                     f"{page.show(exact)}<span class=\"note\">=</span>{math(num)}</div>")
    return "".join(cells)


def _first_order_row(row: dict, lin) -> dict:
    """A first-order linearization's row, from the numbers the check stored at the default
    values: its exponents decide the stability, its oscillating pairs give frequencies."""
    real, imag = lin.numeric.get("exponents_real"), lin.numeric.get("exponents_imag")
    if real is None or imag is None:
        row["stability"] = "in the answer's own symbols: no numbers at the default values"
        return row
    row["stability"] = classify_exponents(np.asarray(real) + 1j * np.asarray(imag))
    freqs = lin.numeric.get("frequencies")
    row["frequencies"] = [f"ω = {float(w):.6g}" if np.isfinite(w) else "unstable"
                          for w in (freqs if freqs is not None else [])]
    return row


def _numbers(sys_, point: dict, values: dict) -> list[float] | None:
    """The point's coordinates as numbers at the default values (None where not)."""
    out = []
    for q in sys_.q:
        v = point.get(q, sp.S.Zero)
        try:
            z, _ = evaluate(v, values)
        except (NotNumeric, TypeError, ValueError, ZeroDivisionError, OverflowError):
            return None
        if abs(z.imag) > 1e-9 * max(1.0, abs(z.real)):
            return None
        out.append(z.real)
    return out


def _frequencies(M, C, K) -> np.ndarray:
    n = M.shape[0]
    if not np.any(C):
        w2 = scipy.linalg.eigh(K, M, eigvals_only=True)
        return np.where(w2 >= 0, np.sqrt(np.abs(w2)), np.nan)
    A = np.block([[np.zeros((n, n)), np.eye(n)],
                  [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    lam = np.linalg.eigvals(A)
    return np.sort(np.abs(lam.imag))[::2][:n]


def _modes_text(freqs, rates) -> list[str]:
    out = []
    for i, w in enumerate(freqs):
        rate = float(rates[i]) if i < len(rates) else 0.0
        if rate > 0:
            out.append(f"grows like e^({rate:.4g} t)")
        elif np.isfinite(w):
            out.append(f"ω = {float(w):.6g}")
        else:
            out.append("unstable")
    return out


def _shapes(M, K) -> str:
    """The mode shapes (columns, largest entry 1) as a matrix."""
    _, vecs = scipy.linalg.eigh(K, M)
    shapes = np.real(vecs)
    big = shapes[np.abs(shapes).argmax(axis=0), range(shapes.shape[1])]
    shapes = shapes / np.where(big != 0, big, 1.0)
    return math(sp.Matrix(shapes.shape[0], shapes.shape[1],
                          [sp.Float(round(x, 4), 4) for x in shapes.flatten()]))
