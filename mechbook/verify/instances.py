"""Statements "for all tensors of a kind": generic objects, and deciding an identity.

`for_all: {T: tensor, R: rotation, n: unit_vector}` makes each name a generic object whose
components are symbols: a general tensor has nine, a symmetric one six, a rotation three
(R = ((1 − b·b)1 + 2bb + 2[b]×)/(1 + b·b), every rotation but the half turns, which
follow by continuity), a unit vector two (inverse stereographic projection). Random values
of those symbols are random instances of the kind, drawn like any free variable by the
part's sampler. `orthogonal` is checked twice, on the rotations and on their negatives.

An identity (expressions that must vanish) is decided on random instances: exactly, in
rational arithmetic, when every expression is a rational function with rational
coefficients (rotations and unit vectors are rational in their symbols); otherwise in
30-digit arithmetic. Then SymPy tries to prove it for the generic object itself — `cancel`
of a rational function (a bounded-time polynomial normal form, not `simplify`), or, with
`--prove`, `simplify` — and the verdict says which of the three it got.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np
import sympy as sp

from mechbook.core.numeval import holds
from mechbook.core.timeout import Timeout, time_limit
from mechbook.verify.compare import Sampler, Verdict, value_and_scale

KINDS = ("scalar", "positive", "angle", "vector", "unit_vector", "tensor", "symmetric",
         "antisymmetric", "diagonal", "rotation", "orthogonal", "improper_rotation")
INSTANCES = 12  # random instances per identity
RTOL = 1e-20  # relative residual allowed in 30-digit arithmetic
CANCEL_SECONDS = 2.0  # the default budget of a symbolic proof by cancel()


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


# ---- deciding that expressions vanish --------------------------------------------------
def _rational(e: sp.Basic) -> bool:
    """A rational function of its symbols with rational coefficients (exact instances)."""
    if e.atoms(sp.NumberSymbol) or e.atoms(sp.Function) or e.has(sp.I):
        return False
    if any(not a.is_Rational for a in e.atoms(sp.Number)):
        return False
    return all(p.exp.is_Integer for p in e.atoms(sp.Pow))


def _rational_point(sampler: Sampler, variables, tries: int = 200) -> dict:
    for _ in range(tries):
        point = sampler.draw(variables)
        exact = {k: sp.Rational(str(float(v))).limit_denominator(10**6)
                 for k, v in point.items()}
        if exact and all(holds(c, exact) for c in sampler.conditions):
            return exact
        if not exact:
            return exact
    raise ValueError("no rational instance satisfies the stated conditions")


def vanish_on_instances(exprs: Sequence[sp.Basic], sampler: Sampler,
                        labels: Sequence[str] | None = None) -> Verdict:
    """Do all `exprs` vanish identically in their free symbols? Exact or 30-digit random
    instances decide; a symbolic proof is then attempted (see the module's docstring)."""
    exprs = [sp.sympify(e) for e in exprs]
    labels = list(labels or [f"#{i + 1}" for i in range(len(exprs))])
    variables = sorted(set().union(*(e.free_symbols for e in exprs)) - set(sampler.base),
                       key=str)
    if not any(e.free_symbols for e in exprs):
        return _constants(exprs, labels)
    exact = all(_rational(e) for e in exprs)
    valid = 0
    for _ in range(INSTANCES * 3):
        if valid >= INSTANCES:
            break
        if exact:
            point = _rational_point(sampler, variables)
            values = []
            for e in exprs:
                v = e.xreplace(point)
                if v.has(sp.zoo, sp.nan, sp.oo, -sp.oo):
                    values = None
                    break
                values.append(v)
            if values is None:
                continue
            valid += 1
            for label, v in zip(labels, values, strict=True):
                if v != 0:
                    return Verdict(False, f"exact({valid} instances)",
                                   f"{label} is {v} at {_fmt(point)}")
            continue
        point = sampler.draw(variables)
        results = [value_and_scale(e, point) for e in exprs]
        if not all(np.isfinite(abs(v)) and np.isfinite(s) for v, s in results):
            continue
        valid += 1
        for label, (v, scale) in zip(labels, results, strict=True):
            rel = abs(v) / scale if scale > 0 else abs(v)
            if rel > RTOL and abs(v) > 1e-25:
                return Verdict(False, f"numeric({valid} instances)",
                               f"{label} is {_num(v)} (relative {rel:.2g}) at {_fmt(point)}")
    if valid == 0:
        return Verdict(False, "numeric", "the statement does not evaluate at any instance")
    how = f"exact({valid} instances)" if exact else \
        f"numeric({valid} instances, 30 digits)"
    if _proved(exprs, exact, sampler):
        return Verdict(True, "symbolic", f"proved for the generic objects; also {how}")
    return Verdict(True, how, "no symbolic proof within the time allowed" if exact else "")


def _constants(exprs: Sequence[sp.Basic], labels: Sequence[str]) -> Verdict:
    """Numbers (no symbol left): zero as SymPy writes them, or to 30 digits."""
    if all(e == 0 for e in exprs):
        return Verdict(True, "symbolic", "zero exactly (numbers only)")
    for label, e in zip(labels, exprs, strict=True):
        v, scale = value_and_scale(e, {})
        if not np.isfinite(abs(v)) or abs(v) > RTOL * max(scale, 1.0):
            return Verdict(False, "numeric(30 digits)", f"{label} is {_num(v)}, not 0")
    try:
        with time_limit(CANCEL_SECONDS):
            if all(sp.expand(e) == 0 or sp.radsimp(sp.expand(e)) == 0 for e in exprs):
                return Verdict(True, "symbolic", "numbers only, zero exactly")
    except Timeout:
        pass
    except Exception:  # noqa: BLE001 - the 30-digit values have decided
        pass
    return Verdict(True, "numeric(30 digits)", "numbers only, equal to 30 digits")


def _proved(exprs: Sequence[sp.Basic], exact: bool, sampler: Sampler) -> bool:
    policy = sampler.policy
    try:
        if exact:
            with time_limit(policy.seconds if policy.prove else CANCEL_SECONDS):
                return all(e == 0 or sp.cancel(sp.together(e)) == 0 for e in exprs)
        if policy.prove:
            with time_limit(policy.seconds):
                return all(e == 0 or sp.simplify(e) == 0 for e in exprs)
    except Timeout:
        return False
    except Exception:  # noqa: BLE001 - SymPy's odd failures: the instances have decided
        return False
    return False


def _num(z: complex) -> str:
    return f"{z.real:.10g}" if abs(z.imag) < 1e-14 * max(1, abs(z)) else f"{z:.6g}"


def _fmt(point: dict) -> str:
    items = sorted(point.items(), key=lambda kv: str(kv[0]))[:8]
    return "{" + ", ".join(f"{k}={float(v):.4g}" for k, v in items) + "}"
