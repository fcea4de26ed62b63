"""Unknowns from equations affine in them (p = M·q̇ + a), solved as a linear system.

The momenta of a Lagrangian quadratic in the velocities are affine in them, the mass matrix
their coefficients. SymPy's `solve` treats such a system as a general polynomial one: for
three coordinates (a pendulum whose bob carries a mass on a spring) it searched for
minutes without simplification. LU decomposition of the coefficient matrix takes
milliseconds. `solve` remains for equations that are not affine.

Every ending says what happened: a coefficient matrix singular at random points (the
equations do not determine the unknowns), SymPy finding no or several solutions, or a
CPU time limit running out — which is said as such, never as "no unique solution".
"""

from __future__ import annotations

import random
from collections.abc import Sequence

import mpmath
import sympy as sp

from mechbook.core.numeval import NotNumeric, evaluate, is_zero
from mechbook.core.timeout import Timeout, time_limit
from mechbook.errors import UnsupportedError

SINGULAR = 1e-20  # |det| against the product of the row norms (Hadamard's bound), 30 digits


def affine_parts(exprs: Sequence[sp.Expr],
                 unknowns: Sequence[sp.Symbol]) -> tuple[sp.Matrix, sp.Matrix] | None:
    """(J, b) with exprs = J·u + b when every ∂e/∂u is free of the unknowns (read off the
    expression, else decided at random points: core.numeval.is_zero), None otherwise."""
    J = sp.Matrix([[sp.diff(e, u) for u in unknowns] for e in exprs])
    zero = {u: sp.S.Zero for u in unknowns}
    for x in J:
        if x.has(*unknowns) and not all(is_zero(sp.diff(x, u)) for u in unknowns):
            return None
    J = J.xreplace(zero)  # a coefficient that only looked as if it held an unknown
    return J, sp.Matrix([e.xreplace(zero) for e in exprs])


def generically_singular(J: sp.Matrix, points: int = 2, seed: int = 20261201) -> bool:
    """det J = 0 at random points (every symbol in (0.3, 1.3), 30 digits), relative to
    Hadamard's bound; False where no point evaluates (nothing is claimed then)."""
    rng = random.Random(seed)
    symbols = sorted(J.free_symbols, key=lambda s: s.name)
    good = 0
    for _ in range(4 * points):
        pt = {s: sp.Float(rng.uniform(0.3, 1.3), 30) for s in symbols}
        try:
            with mpmath.workdps(30):
                A = mpmath.matrix([[mpmath.mpmathify(evaluate(x, pt)[0]) for x in row]
                                   for row in J.tolist()])
                bound = mpmath.fprod(mpmath.norm(A[i, :]) for i in range(A.rows))
                if bound == 0 or abs(mpmath.det(A)) > SINGULAR * bound:
                    return False
        except (NotNumeric, ZeroDivisionError, ValueError, TypeError, OverflowError):
            continue
        good += 1
        if good >= points:
            return True
    return False


def solve_unknowns(exprs: Sequence[sp.Expr], unknowns: Sequence[sp.Symbol], what: str,
                   seconds: float) -> dict[sp.Symbol, sp.Expr]:
    """{unknown: value} from exprs = 0: by LU when the equations are affine in the unknowns
    (J·u = −b), else by SymPy's solve; each within `seconds` of CPU. UnsupportedError
    beginning with `what` otherwise, saying whether the time ran out, the coefficients are
    singular or SymPy found no unique solution."""
    unknowns = list(unknowns)
    parts = affine_parts(exprs, unknowns)
    if parts is None:
        return solve_within(exprs, unknowns, what, seconds)
    J, b = parts
    names = ", ".join(map(str, unknowns))
    singular = UnsupportedError(f"{what}: the coefficient matrix ∂/∂({names}) is singular "
                                "(at random points), so the equations do not determine the "
                                "unknowns")
    if generically_singular(J):
        raise singular
    try:
        with time_limit(seconds):
            sol = J.LUsolve(-b)
    except Timeout:
        raise UnsupportedError(f"{what}: the linear solve ran past its time limit of "
                               f"{seconds:g} s of CPU (undecided, not unsolvable)") from None
    except (sp.matrices.exceptions.NonInvertibleMatrixError, ValueError, ZeroDivisionError):
        raise singular from None
    return dict(zip(unknowns, sol, strict=True))


def solve_within(exprs: Sequence[sp.Expr], unknowns: Sequence[sp.Symbol], what: str,
                 seconds: float) -> dict[sp.Symbol, sp.Expr]:
    """SymPy's solve for the unknowns within `seconds` of CPU; UnsupportedError beginning
    with `what` that says whether the time ran out or how many solutions SymPy found."""
    unknowns = list(unknowns)
    try:
        with time_limit(seconds):
            sol = sp.solve(list(exprs), unknowns, dict=True)
    except Timeout:
        raise UnsupportedError(f"{what}: SymPy's solve ran past its time limit of "
                               f"{seconds:g} s of CPU (undecided, not unsolvable)") from None
    except NotImplementedError as exc:
        raise UnsupportedError(f"{what}: SymPy's solve cannot ({exc})") from None
    if len(sol) != 1 or set(sol[0]) != set(unknowns):
        found = (f"{len(sol)} solutions" if len(sol) != 1 else
                 f"a solution leaving {', '.join(str(u) for u in unknowns if u not in sol[0])} "
                 "free")
        raise UnsupportedError(f"{what}: not uniquely solvable (SymPy's solve finds {found})")
    return sol[0]
