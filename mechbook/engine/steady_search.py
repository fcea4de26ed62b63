"""Steady motions found numerically: how many lie in a region, and whether each is stable.

    roots_in     the distinct solutions of the steady conditions (mechbook.engine.steady)
                 inside boxes of the non-turning coordinates, by multistart root finding
    classify_at  stable / unstable / marginal at such a numeric root, from M, C, K taken
                 symbolically once and evaluated at the numbers
    classify     the linearized system's own verdict at a parameter point
"""

from __future__ import annotations

import numpy as np
import scipy.optimize
import sympy as sp

from mechbook.core.compile import compile_exprs
from mechbook.core.numeval import NotNumeric, evaluate
from mechbook.engine.equilibria import Equilibria
from mechbook.engine.linear import LinearSystem, classify_matrices


def classify_at(eq: Equilibria, root: dict, values: dict, rates: dict | None = None) -> str:
    """The stability of the steady motion found numerically at `root` ({q: float}), at
    fixed `rates` of the turning coordinates (or at rest in a reduced system): M, C, K are
    the derivatives of the equations of motion there, taken symbolically once and
    evaluated at the numbers (a numeric root is no exact equilibrium for `linearize`)."""
    at = dict(values)
    at.update({q: sp.Float(x, 30) for q, x in root.items()})
    M, C, K = (np.array([[_at(x, at) for x in row] for row in A.tolist()], dtype=float)
               for A in eq.steady_jacobians(rates or {}))
    return classify_matrices(M, C, K)


def _at(x: sp.Expr, at: dict) -> float:
    """A matrix entry at `at` in 30-digit arithmetic (numeval's one pass over the tree;
    SymPy's evalf where it cannot go), as a float: what `evalf(30)` gives, sooner."""
    try:
        return evaluate(x, at, 30)[0].real
    except (NotNumeric, ZeroDivisionError, ValueError, TypeError, OverflowError):
        return complex(sp.N(x.subs(at), 30)).real


def roots_in(conds: list[sp.Expr], unknowns: list[sp.Symbol], values: dict,
             boxes: list[dict], starts: int = 7, tol: float = 1e-10) -> list[np.ndarray]:
    """The distinct solutions of conds = 0 inside any of `boxes` ({q: (lo, hi)}; a missing
    coordinate ranges over (−π, π)), by Newton-type root finding from a grid of starting
    points in each box (`starts` per coordinate, at most 3000 per box). Solutions on a box's
    edge (within 1e-9 of its width) are not counted: a count is about the interior."""
    F = [sp.N(c.subs(values), 30) for c in conds]
    J = sp.Matrix(F).jacobian(unknowns)
    f_num, _ = compile_exprs(unknowns, F)
    j_num, _ = compile_exprs(unknowns, list(J))
    n, m = len(unknowns), len(F)
    found: list[np.ndarray] = []
    rng = np.random.default_rng(11)
    for box in boxes:
        ranges = [box.get(q, (-np.pi, np.pi)) for q in unknowns]
        # a positive range over decades (a distance) is searched on a geometric grid
        grids = [np.geomspace(lo, hi, starts + 2)[1:-1] if lo > 0 and hi > 100 * lo
                 else np.linspace(lo, hi, starts + 2)[1:-1] for lo, hi in ranges]
        mesh = np.array(np.meshgrid(*grids, indexing="ij")).reshape(n, -1).T
        if len(mesh) > 3000:
            mesh = mesh[rng.choice(len(mesh), 3000, replace=False)]
        width = np.array([hi - lo for lo, hi in ranges], dtype=float)
        for x0 in mesh:
            with np.errstate(all="ignore"):
                sol = scipy.optimize.root(
                    lambda x: np.asarray(f_num(x), float), x0, method="lm",
                    jac=lambda x: np.asarray(j_num(x), float).reshape(m, n))
            x = sol.x
            with np.errstate(all="ignore"):
                resid = np.asarray(f_num(x), float)
                jac = np.asarray(j_num(x), float).reshape(m, n)
            if not (np.all(np.isfinite(x)) and np.all(np.isfinite(resid))
                    and np.all(np.isfinite(jac))):
                continue
            # a root, not a place where the conditions are merely small (a potential that
            # decays far away): the Newton step from it must be negligible
            step = np.linalg.lstsq(jac, resid, rcond=None)[0]
            if not np.linalg.norm(step) <= tol * max(1.0, float(np.max(width))):
                continue
            inside = all(lo + 1e-9 * w < xi < hi - 1e-9 * w
                         for xi, (lo, hi), w in zip(x, ranges, width, strict=True))
            if inside and not any(np.allclose(x, f, rtol=1e-6, atol=1e-7 * np.max(width))
                                  for f in found):
                found.append(x)
    return found


def classify(lin: LinearSystem, values: dict) -> str:
    """'stable', 'unstable' or 'marginal' (the linearized system's own verdict)."""
    return lin.numeric_stability(values)
