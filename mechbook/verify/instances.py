"""Statements "for all tensors of a kind": generic objects, and deciding an identity.

`for_all: {T: tensor, R: rotation, n: unit_vector}` makes each name a generic object whose
components are symbols: a general tensor has nine, a symmetric one six, a rotation three
(R = ((1 − b·b)1 + 2bb + 2[b]×)/(1 + b·b), every rotation but the half turns, which
follow by continuity), a unit vector two (inverse stereographic projection). Random values
of those symbols are random instances of the kind, drawn like any free variable by the
part's sampler. `orthogonal` is checked twice, on the rotations and on their negatives.

A statement (expressions that must vanish, and some that must not) is decided on random
instances. It is built once for the generic objects and evaluated at 12 random instances:
exactly, at rational points, when it is a rational function with rational coefficients
(rotations and unit vectors are), else in 30-digit arithmetic. When building it for the
generic objects takes too long (a determinant of rational functions of twelve symbols can
take minutes), it is built anew from each rational instance instead: numbers in, numbers
out. Then the generic statement is proved where that is cheap — a rational function's
numerator over a common denominator expanded to 0 (a polynomial normal form, in SymEngine:
core.rational; SymPy's `cancel` within a time limit for the largest), or, with `--prove`,
`simplify` — and the verdict says which of the three it got: symbolic, exact(…) or
numeric(…). Exact values at rational points are computed in SymEngine too. Symbols of
kind `variable` (differentiated or integrated in the statement) and the parameters stay
symbols while it is built from an instance: calculus acts on them the same way on either
path (mechbook.model.tensorfuncs refuses any other `for_all` object as its variable).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import sympy as sp
from sympy.matrices.utilities import dotprodsimp

from mechbook.core.algebra_reach import within_exact_reach
from mechbook.core.compile import as_expr
from mechbook.core.identity import decide_zero
from mechbook.core.numeval import holds
from mechbook.core.rational import (
    is_rational_function,
    to_symengine,
    values_at,
    vanishes_identically,
)
from mechbook.core.timeout import Timeout, time_limit
from mechbook.model.tensorfuncs import VARIABLE
from mechbook.verify.compare import Sampler, Verdict, value_and_scale
from mechbook.verify.proof import SIMPLIFY_SHARE, too_large_to_simplify

KINDS = ("scalar", "positive", "angle", "variable", "vector", "unit_vector", "tensor",
         "symmetric", "antisymmetric", "diagonal", "rotation", "orthogonal",
         "improper_rotation")
INSTANCES = 12  # random instances per identity
RTOL = 1e-20  # relative residual allowed in 30-digit arithmetic
CANCEL_SECONDS = 2.0  # the default budget of a symbolic proof by cancel()
BUILD_SECONDS = 6.0  # building the generic statement: longer, build from each instance


def _syms(name: str, labels: Sequence[str], positive: bool = False) -> list[sp.Symbol]:
    opts = {"positive": True} if positive else {"real": True}
    return [sp.Symbol(f"{name}.{label}", **opts) for label in labels]


def _rotation(name: str) -> sp.ImmutableMatrix:
    b = sp.Matrix(_syms(name, ("b1", "b2", "b3")))
    cross = sp.Matrix([[0, -b[2], b[1]], [b[2], 0, -b[0]], [-b[1], b[0], 0]])
    n2 = b.dot(b)
    return sp.ImmutableMatrix(((1 - n2) * sp.eye(3) + 2 * b * b.T + 2 * cross) / (1 + n2))


def generic(name: str, kind: str) -> list:
    """The generic object(s) of a kind: one per branch (two for `orthogonal`)."""
    if kind == "scalar":
        return [_syms(name, ("x",))[0]]
    if kind == "variable":  # kept a symbol while the statement is built (calculus)
        return [_syms(name, (VARIABLE,))[0]]
    if kind == "positive":
        return [_syms(name, ("x",), positive=True)[0]]
    if kind == "angle":  # drawn in (-3, 3) rad
        return [3 * _syms(name, ("x",))[0]]
    if kind == "vector":
        return [sp.ImmutableMatrix(_syms(name, ("1", "2", "3")))]
    if kind == "unit_vector":
        u, v = _syms(name, ("u", "v"))
        d = 1 + u**2 + v**2
        return [sp.ImmutableMatrix([2 * u / d, 2 * v / d, (1 - u**2 - v**2) / d])]
    if kind == "tensor":
        s = _syms(name, [f"{i}{j}" for i in "123" for j in "123"])
        return [sp.ImmutableMatrix(3, 3, s)]
    if kind == "symmetric":
        a = dict(zip(("11", "22", "33", "12", "13", "23"),
                     _syms(name, ("11", "22", "33", "12", "13", "23")), strict=True))
        return [sp.ImmutableMatrix([[a["11"], a["12"], a["13"]], [a["12"], a["22"], a["23"]],
                                    [a["13"], a["23"], a["33"]]])]
    if kind == "antisymmetric":
        w1, w2, w3 = _syms(name, ("23", "31", "12"))
        return [sp.ImmutableMatrix([[0, w3, -w2], [-w3, 0, w1], [w2, -w1, 0]])]
    if kind == "diagonal":
        return [sp.ImmutableMatrix(sp.diag(*_syms(name, ("11", "22", "33"))))]
    if kind == "rotation":
        return [_rotation(name)]
    if kind == "improper_rotation":
        return [-_rotation(name)]
    if kind == "orthogonal":
        r = _rotation(name)
        return [r, -r]
    raise ValueError(f"unknown kind {kind!r}; known: {', '.join(KINDS)}")


def branches(for_all: dict) -> list[dict]:
    """Every combination of the generic objects of `for_all` ({name: kind})."""
    names = list(for_all)
    choices = [generic(n, for_all[n]) for n in names]
    return [dict(zip(names, combo, strict=True)) for combo in itertools.product(*choices)]


# ---- deciding a statement ----------------------------------------------------------------
@dataclass
class Statement:
    """What a part claims, built from one set of names: `exprs` must vanish, each of
    `nonzero` must not (an eigenvector, the constant of an ellipsoid's equation)."""

    exprs: list
    labels: list[str]
    nonzero: list[tuple[str, sp.Basic]] = field(default_factory=list)


Names = Callable[[dict | None], dict]  # the names, generic (None) or at an instance
Build = Callable[[dict], Statement]


def generic_symbols(branch: dict) -> list[sp.Symbol]:
    """The symbols of a branch's generic objects (its instances' coordinates)."""
    out: set = set()
    for obj in branch.values():
        out |= obj.free_symbols
    return sorted(out, key=str)


def decide(names_at: Names, build: Build, symbols: Sequence[sp.Symbol],
           sampler: Sampler, memo: dict | None = None) -> Verdict:
    """Does the statement hold at every instance? It is built once for the generic objects
    (if that takes less than BUILD_SECONDS) and evaluated at random instances, exactly
    where it is rational; otherwise it is built anew from each rational instance. Then a
    symbolic attempt on the generic statement. Matrix algebra without SymPy's intermediate
    `dotprodsimp` (a `cancel` of every entry of a power or a 3×3 determinant): the same
    functions, unsimplified, in a fraction of the time."""
    with dotprodsimp(False):
        return _decide(names_at, build, symbols, sampler, memo)


def _decide(names_at: Names, build: Build, symbols: Sequence[sp.Symbol],
            sampler: Sampler, memo: dict | None) -> Verdict:
    memo = {} if memo is None else memo  # shared by the branches of one part
    generic = None
    if not memo.get("slow"):
        try:
            with time_limit(BUILD_SECONDS):
                generic = build(names_at(None))
        except Timeout:
            memo["slow"] = True  # the other branches are as slow: build from instances
    if generic is None:
        verdict = _per_instance(names_at, build, symbols, sampler)
    else:
        verdict = _evaluate(generic, symbols, sampler)
    if not verdict.ok:
        return verdict
    if generic is not None and _proved(generic, sampler):
        return Verdict(True, "symbolic", f"proved for the generic objects; also "
                       f"{verdict.method}", power="proved for the generic objects")
    return Verdict(True, verdict.method, verdict.detail or
                   ("no symbolic proof within the time allowed" if generic is None else ""),
                   power=verdict.power)


def _evaluate(st: Statement, symbols, sampler: Sampler) -> Verdict:
    """The generic statement at random instances: exact rational points when it is a
    rational function with rational coefficients, else 30-digit points (each residual
    judged against the size of what cancelled in it)."""
    exprs = [as_expr(e) for e in st.exprs]
    extra = [as_expr(e) for _, e in st.nonzero]
    variables = sorted(set(symbols) | (set().union(*(e.free_symbols for e in exprs + extra))
                                       - set(sampler.base)), key=str)
    exact = all(_rational(e) for e in exprs + extra)
    constant = not variables and not any(e.free_symbols for e in exprs + extra)
    if exact:  # exact rational arithmetic, in SymEngine (core.rational)
        fast, fast_extra = to_symengine(exprs), to_symengine(extra)
    valid = 0
    for _ in range(INSTANCES * 3):
        if valid >= INSTANCES or (constant and valid):
            break
        point = rational_point(sampler, variables) if exact else sampler.draw(variables)
        values = values_at(fast, point) if exact else \
            [value_and_scale(e, point) for e in exprs]
        checks = values_at(fast_extra, point) if exact else \
            [value_and_scale(e, point) for e in extra]
        if not all(_finite(v) for v in values + checks):
            continue
        valid += 1
        bad = _first_failure(st, values, checks, valid, point)
        if bad is not None:
            return bad
    if valid == 0:
        return Verdict(False, "numeric", "the statement does not evaluate at any instance")
    if constant:
        return Verdict(True, "exact" if exact else "numeric(30 digits)", "numbers only",
                       power="exact" if exact else _THIRTY)
    return Verdict(True, f"exact({valid} instances)" if exact else
                   f"numeric({valid} instances, 30 digits)",
                   power=(f"exact rational arithmetic at {valid} instances" if exact else
                          f"{valid} instances, {_THIRTY}"))


_THIRTY = "30 digits, each residual to 1e-10 of what cancels in it"


def _per_instance(
names_at: Names, build: Build, symbols, sampler: Sampler) -> Verdict:
    """Built anew from each rational instance (numbers in, numbers out): compared exactly
    when the numbers are rational, else to 30 digits."""
    valid = 0
    exact = True
    for _ in range(INSTANCES * 3):
        if valid >= INSTANCES:
            break
        point = rational_point(sampler, symbols)
        st = build(names_at(point))
        numbers = [as_expr(e).xreplace(point) for e in st.exprs]
        tests = [as_expr(e).xreplace(point) for _, e in st.nonzero]
        if not all(v.is_Rational for v in numbers + tests):
            exact = False
            numbers = [value_and_scale(v, {}) for v in numbers]
            tests = [value_and_scale(v, {}) for v in tests]
        if not all(_finite(v) for v in numbers + tests):
            continue
        valid += 1
        bad = _first_failure(st, numbers, tests, valid, point)
        if bad is not None:
            return bad
    if valid == 0:
        return Verdict(False, "numeric", "the statement does not evaluate at any instance")
    return Verdict(True, f"exact({valid} instances)" if exact else
                   f"numeric({valid} instances, 30 digits)",
                   power=(f"exact rational arithmetic at {valid} instances" if exact else
                          f"{valid} instances, {_THIRTY}"))


def _finite(v) -> bool:
    if isinstance(v, tuple):
        return bool(np.isfinite(abs(v[0])) and np.isfinite(v[1]))
    return not v.has(sp.zoo, sp.nan, sp.oo, -sp.oo)


def _first_failure(st: Statement, values: list, checks: list, valid: int,
                   point: dict) -> Verdict | None:
    """The first residual that is not zero, or the first must-not-vanish that does.
    A value is an exact number, or (value, scale) from a 30-digit evaluation."""
    for label, v in zip(st.labels, values, strict=True):
        if isinstance(v, tuple):
            z, scale = v
            rel = abs(z) / scale if scale > 0 else abs(z)
            if rel > RTOL and abs(z) > 1e-25:
                return Verdict(False, f"numeric({valid} instances)",
                               f"{label} is {_num(z)} (relative {rel:.2g}) at {_fmt(point)}")
        elif v != 0:
            return Verdict(False, f"exact({valid} instances)",
                           f"{label} is {v}, not 0, at {_fmt(point)}")
    for (label, _), v in zip(st.nonzero, checks, strict=True):
        zero = (abs(v[0]) <= 1e-12 * max(v[1], 1e-300)) if isinstance(v, tuple) else v == 0
        if zero:
            return Verdict(False, f"numeric({valid} instances)",
                           f"{label} vanishes at {_fmt(point)}")
    return None


def rational_point(sampler: Sampler, variables, tries: int = 200) -> dict:
    """Random admissible values, as exact rationals (conditions rechecked on them)."""
    for _ in range(tries):
        point = sampler.draw(variables)
        exact = {k: sp.Rational(str(float(v))).limit_denominator(10**6)
                 for k, v in point.items()}
        if all(holds(c, exact) for c in sampler.conditions):
            return exact
    raise ValueError("no rational instance satisfies the stated conditions")


def _rational(e: sp.Basic) -> bool:
    """A rational function of its symbols with rational coefficients."""
    return is_rational_function(e)


def _proved(st: Statement, sampler: Sampler) -> bool:
    """A symbolic proof for the generic objects, within the time allowed: `cancel` when the
    statement is rational, `expand`/`radsimp` for numbers, `simplify` only with --prove."""
    policy = sampler.policy
    exprs = [as_expr(e) for e in st.exprs]
    if not within_exact_reach(*exprs):  # SymPy's algebra would abort the process in gmp
        return False
    try:
        with time_limit(policy.seconds if policy.prove else CANCEL_SECONDS):
            if all(e == 0 for e in exprs):
                return True
            if not any(e.free_symbols for e in exprs):
                return all(sp.expand(e) == 0 or sp.radsimp(sp.expand(e)) == 0
                           for e in exprs)
            if all(_rational(e) for e in exprs):
                return all(e == 0 or _rational_zero(e) for e in exprs)
            if policy.prove:  # the exact canonical forms first, simplify for the rest
                return all(e == 0 or decide_zero(e).zero is True
                           or _trig_zero(e)
                           or _simplified_zero(e, SIMPLIFY_SHARE * policy.seconds)
                           for e in exprs)
    except Timeout:
        return False
    except Exception:  # noqa: BLE001 - SymPy's odd failures: the instances have decided
        return False
    return False


def _trig_zero(e: sp.Expr) -> bool:
    """e with each exp of an imaginary argument written cos x + i·sin x (Euler's formula,
    exact) decided 0 by the canonical forms: SymPy's own evaluation then turns
    cos(acos t) into t and sin(acos t) into √(1 − t²) (a rotation's eigenvalues e^{±iα},
    α = acos((tr R − 1)/2), Symon 10-19)."""
    if not any(a.args[0].has(sp.I) for a in e.atoms(sp.exp)):
        return False
    form = e.rewrite(sp.cos)
    return form == 0 or decide_zero(form).zero is True


def _simplified_zero(e: sp.Expr, seconds: float) -> bool:
    """simplify(e) == 0 within `seconds` (a share of the proof's time, as in
    mechbook.verify.proof: the simplify calls that prove finish well within it); none on
    an expression larger than any simplify has proved."""
    if too_large_to_simplify(e):
        return False
    try:
        with time_limit(seconds):
            return sp.simplify(e) == 0
    except Timeout:
        return False


def _rational_zero(e: sp.Expr) -> bool:
    """A rational function that vanishes identically: its numerator over a common
    denominator expands to 0 (SymEngine, milliseconds); SymPy's `cancel` within the time
    limit where it is too large for that."""
    zero = vanishes_identically(e)
    return zero if zero is not None else sp.cancel(sp.together(e)) == 0


def _num(z: complex) -> str:
    return f"{z.real:.10g}" if abs(z.imag) < 1e-14 * max(1, abs(z)) else f"{z:.6g}"


def _fmt(point: dict) -> str:
    items = sorted(point.items(), key=lambda kv: str(kv[0]))[:8]
    return "{" + ", ".join(f"{k}={float(v):.4g}" for k, v in items) + "}"
