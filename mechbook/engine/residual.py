"""Whether a residual of the equilibrium conditions is zero: shared by the free and the
constrained search (mechbook.engine.equilibria, mechbook.engine.constrained)."""

from __future__ import annotations

import numpy as np
import sympy as sp

from mechbook.core.numeval import NotNumeric, evaluate


def is_zero(expr: sp.Expr, values: dict, points: int = 5) -> bool:
    """Zero symbolically, or (when SymPy cannot tell) to 25 digits at random points around
    the default values; a residual left by a numerically found point is zero to 1e-9."""
    if expr == 0:
        return True
    if _numerically_zero(expr, values):
        return True
    rng = np.random.default_rng(7)
    for _ in range(points):
        env = {}
        for sym in expr.free_symbols:
            base = values.get(sym, 1.0)
            factor = float(np.exp(rng.uniform(-0.3, 0.3)))
            env[sym] = sp.Float(base * factor if sym.is_positive or sym not in values
                                else base + rng.uniform(-0.3, 0.3), 40)
        try:
            v, scale = evaluate(expr, env, 40)
        except (NotNumeric, TypeError, ValueError, ZeroDivisionError, OverflowError):
            return False
        if not abs(v) <= 1e-25 * max(scale, 1e-300):
            return False
    return True


def _numerically_zero(expr: sp.Expr, values: dict) -> bool:
    """A residual left by a numerically found point (floats), zero to rounding."""
    if not expr.has(sp.Float):
        return False
    try:
        return abs(evaluate(expr, {k: sp.Float(v, 30) for k, v in values.items()})[0]) < 1e-9
    except (NotNumeric, TypeError, ValueError, ZeroDivisionError, OverflowError):
        return False


def show_point(point: dict) -> str:
    """A point as {q = value, ...} for messages."""
    return "{" + ", ".join(f"{k} = {sp.sstr(v)}" for k, v in point.items()) + "}"
