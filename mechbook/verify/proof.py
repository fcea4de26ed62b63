"""Symbolic proofs with `--prove`: canonical forms first, SymPy's `simplify` with what is left
of the part's budget, and a fixed phrase for why a passing part is not proved.

A proof is attempted only after the numeric comparison has passed. It is decided early
where none can exist (an estimate, numbers of double precision), then tried by the exact
canonical forms of mechbook.core.identity (milliseconds: SymEngine expansions reduced by
sin² + cos² = 1 and r² = R), which either prove the identity, or decide that it is not one
in free symbols (so that `simplify` is not run for nothing), or leave it open; only an open
one is handed to `simplify`, within the time the part has left. A `restrict:` symbol is
replaced by its expression first and a condition `x > y` on a symbol by x = y + δ, δ > 0,
so that what is proved is the statement on the admissible points, which is what the numeric
comparison sampled. Nothing numeric is ever called a proof.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import sympy as sp

from mechbook.core.algebra_reach import within_exact_reach
from mechbook.core.identity import decide_zero
from mechbook.core.timeout import Timeout, time_limit

# simplify is not tried on an expression of more operations (SymPy's count_ops) than this: the
# calls that proved had at most 2164 (Symon 12-10), six of the seven that ran to the limit
# 3362 to 48 533 (Symon 10-03, 11-03, 11-06 ×2, 11-08, 11-21; 12-06 had 1122)
MAX_SIMPLIFY_OPS = 3000

# why a passing part is not proved: one fixed phrase per reason (the method column's tail)
ESTIMATE = "an estimate (compared within its stated tolerance)"
FLOATS = "holds floating-point numbers (a numeric root or value)"
NOT_FREE = "not an identity in free symbols (holds where the conditions or constraints put them)"
BRANCH = "holds on one branch of a root only (a sign SymPy cannot fix)"
OPEN = "SymPy did not reduce it to 0 within the budget"
BUDGET = "the part's proof budget was spent"
TOO_LARGE = (f"too large for SymPy's simplify (over {MAX_SIMPLIFY_OPS} operations: none "
             "that large was proved within the budget)")
OUT_OF_REACH = "a rational exponent too large for exact algebra (decided numerically)"
BOUNDARY = "decided at a relation's boundary (crossings found numerically)"
LIMIT = "a limit: the error's order is measured numerically"
MEASURED = "measured by integration"
NO_PATH = "no symbolic proof path for this quantity's check"
NO_SIGN = "no sign proved for its conditions (positivity under the assumptions)"
EXACT = "decided exactly, with no identity to prove (a count)"
# the reasons no proof can remove: what is left is what a proof could reach ("expressible")
UNREACHABLE = (ESTIMATE, FLOATS, BOUNDARY, LIMIT, MEASURED, EXACT)

# one simplify call gets at most this share of the part's budget: over Symon and Lim with
# --prove-seconds 10 (2026-12-07), every simplify that proved an identity took at most 4.6 s
# of CPU (Symon 12-10 (a-general)), every one that did not ran to the 10 s limit (Symon
# 10-03, 11-03, 11-06 ×2, 11-08, 11-21, 12-06): 6 s keeps each proof and 4 s of each failure
SIMPLIFY_SHARE = 0.6
CACHE_SIZE = 512  # proof results kept per process (the same difference met again: an erratum)
_cache: dict = {}
# the canonical forms' decisions, by expression: the first pass (canonical_only) and the
# pass with simplify after it ask for the same one (11-05 (a): 6 s each, twice)
_decisions: dict = {}


@dataclass(frozen=True)
class Proof:
    """A proof attempt's result: `ok` (proved exactly) and, when not, the phrase why."""

    ok: bool
    why: str = ""


class Budget:
    """The CPU seconds a part's proofs may spend in `simplify` (the canonical forms are
    cheap and always tried)."""

    def __init__(self, seconds: float):
        self.seconds = seconds
        self.spent = 0.0

    def left(self) -> float:
        return max(0.0, self.seconds - self.spent)


def prove_zero(expr: sp.Basic, sampler, canonical_only: bool = False) -> Proof:
    """Is `expr` identically 0 on the sampler's admissible points, proved exactly?
    `canonical_only`: no `simplify` (a first pass over several expressions).

    Example: prove_zero(sin(x)**2 + cos(x)**2 - 1, sampler) == Proof(True)."""
    if expr == 0:
        return Proof(True)
    if sampler.rtol > 1e-10 or sampler.fixed:
        return Proof(False, ESTIMATE)
    expr = _on_admissible_points(expr, sampler)
    if expr.atoms(sp.Float):
        return Proof(False, FLOATS)
    key = (expr, canonical_only)
    if key in _cache:
        return _cache[key]
    decision = _decide(expr)
    if decision.zero is True:
        return _keep(key, Proof(True))
    if decision.zero is False:
        return _keep(key, Proof(False, NOT_FREE))
    if decision.why.startswith("a root's branch"):
        for alt in _rewritten(expr):
            if _decide(alt).zero is True:
                return _keep(key, Proof(True))
        return _keep(key, Proof(False, BRANCH))
    if canonical_only:
        return Proof(False, OPEN)
    if not within_exact_reach(expr):  # simplify would abort the process in gmp
        return _keep(key, Proof(False, OUT_OF_REACH))
    if too_large_to_simplify(expr):
        return _keep(key, Proof(False, TOO_LARGE))
    budget = sampler.proof_budget()
    seconds = min(budget.left(), SIMPLIFY_SHARE * sampler.policy.seconds)
    if seconds <= 0:
        return Proof(False, BUDGET)
    start = time.process_time()
    try:
        with time_limit(seconds):
            ok = sp.simplify(expr) == 0
    except Timeout:
        ok = False
    except Exception:  # noqa: BLE001 - SymPy's odd failures: the numeric verdict stands
        ok = False
    finally:
        budget.spent += time.process_time() - start
    return _keep(key, Proof(True) if ok else Proof(False, OPEN))


def _decide(expr: sp.Basic):
    """decide_zero(expr), once per process for each expression."""
    decision = _decisions.get(expr)
    if decision is None:
        if len(_decisions) >= CACHE_SIZE:
            _decisions.clear()
        decision = _decisions[expr] = decide_zero(expr)
    return decision


def factored_radicands(expr: sp.Basic) -> sp.Basic:
    """expr with each root of a sum written as the root of its factored form, so that
    SymPy's own rule takes out a square factor whose sign its assumptions know:
    √(k·a·(l + 2a)²) = (l + 2a)·√(k·a) for positive a, l (exact; nothing where the sign is
    unknown). Why: the canonical forms meet √(T²U) and T·√U as two roots tied only up to
    sign (one branch), and a sign is exactly what the admissible domain, written with
    positive δ, can give. `expr` itself where no radicand changes."""
    reps = {}
    for p in expr.atoms(sp.Pow):
        if p.exp.is_Rational and not p.exp.is_Integer and p.base.is_Add \
                and len(str(p.base)) <= MAX_RADICAND:
            new = sp.Pow(sp.factor(p.base), p.exp)
            if new != p:
                reps[p] = new
    return expr.xreplace(reps) if reps else expr


MAX_RADICAND = 2000  # characters of a radicand factored for its square factors
MAX_EXPAND = 5000  # characters of an expression SymPy expands for a branch's second try


def _rewritten(expr: sp.Basic):
    """The forms a one-branch remainder is tried again in (each exact): its radicands
    factored; expanded by SymPy first, which joins √x·x into x^(3/2) and √x/√x before the
    canonical forms merge roots (Symon 12-33's motion)."""
    alt = factored_radicands(expr)
    if alt is not expr:
        yield alt
    if len(str(expr)) <= MAX_EXPAND:
        expanded = sp.expand(expr)
        if expanded != expr:
            yield factored_radicands(expanded)


def too_large_to_simplify(expr: sp.Basic) -> bool:
    """More operations than any expression `simplify` has proved 0 within the budget."""
    return sp.count_ops(expr) > MAX_SIMPLIFY_OPS


def prove_sign(expr: sp.Basic, sampler, sign: int = 1) -> bool:
    """Is `expr` proved > 0 (sign 1) or < 0 (sign −1) at every admissible point? Each
    `restrict:` symbol replaced and each condition x > y turned into x = y + δ (δ > 0, the
    later conditions rewritten with it: the domain is exactly the admissible one); then
    over a common denominator numerator and denominator must each have a sign SymPy's
    assumptions prove (as written, factored or expanded: a sum of positive terms of
    positive symbols). Nothing numeric: a sign SymPy cannot show is not proved. Within the
    part's proof budget.

    Example: prove_sign(a**2 + a*b, sampler) is True for positive symbols a, b."""
    if sampler.rtol > 1e-10 or sampler.fixed:
        return False
    expr = _on_admissible_points(expr, sampler, compose=True)
    if expr.atoms(sp.Float) or expr.has(sp.nan, sp.zoo, sp.oo, -sp.oo, sp.I):
        return False
    budget = sampler.proof_budget()
    seconds = min(budget.left(), sampler.policy.seconds)
    if seconds <= 0:
        return False
    start = time.process_time()
    try:
        with time_limit(seconds):
            num, den = sp.together(sign * expr).as_numer_denom()
            n, d = _sign(num), _sign(den)
            return n != 0 and n == d
    except Timeout:
        return False
    except Exception:  # noqa: BLE001 - SymPy's odd failures: no sign proved
        return False
    finally:
        budget.spent += time.process_time() - start


def _sign(e: sp.Expr) -> int:
    """1 or −1 where SymPy's assumptions prove e > 0 or e < 0 (as written, factored or
    expanded), else 0."""
    for form in (lambda x: x, sp.factor, sp.expand):
        y = form(e)
        if y.is_positive:
            return 1
        if y.is_negative:
            return -1
    return 0


def _keep(key, proof: Proof) -> Proof:
    if len(_cache) >= CACHE_SIZE:
        _cache.clear()
    _cache[key] = proof
    return proof


def _on_admissible_points(expr: sp.Basic, sampler, compose: bool = False) -> sp.Basic:
    """expr with each `restrict:` symbol replaced by its expression (the latest first: it
    may use an earlier one), and each condition x > y (x < y) on a symbol x not in y by
    x = y + δ (y − δ) with δ > 0: an identity there holds on every admissible point.
    `compose` (a sign's proof, which needs the domain itself, not a larger one): each
    substitution is made in the later conditions too (I1 < I3, I3 < I2: I3 = I1 + δ1,
    I2 = I1 + δ1 + δ2), and c·x > y (c a positive rational) gives x = (y + δ)/c."""
    for sym in reversed(list(sampler.derived)):
        expr = expr.xreplace({sym: sampler.derived[sym]})
    conditions = list(sampler.conditions)
    for i, cond in enumerate(conditions):
        sub = _shift(cond, compose)
        if sub is not None and expr.has(sub[0]):
            expr = expr.xreplace({sub[0]: sub[1]})
        if sub is not None and compose:
            conditions[i + 1:] = [c.xreplace({sub[0]: sub[1]}) for c in conditions[i + 1:]]
    return expr


def _shift(cond: sp.Basic, scaled: bool = False) -> tuple[sp.Symbol, sp.Expr] | None:
    """(x, y + δ) for x > y or y < x, (x, y − δ) for x < y, with a fresh positive δ;
    `scaled`: also (x, (y + δ)/c) for c·x > y."""
    if not isinstance(cond, (sp.StrictGreaterThan, sp.StrictLessThan)):
        return None
    big, small = (cond.lhs, cond.rhs) if isinstance(cond, sp.StrictGreaterThan) \
        else (cond.rhs, cond.lhs)
    delta = _delta(cond, scaled)
    coeff, x = big.as_coeff_Mul()
    if scaled and x.is_Symbol and coeff.is_Rational and coeff > 0 and not small.has(x):
        return x, (small + delta) / coeff
    if big.is_Symbol and not small.has(big):
        return big, small + delta
    if small.is_Symbol and not big.has(small):
        return small, big - delta
    return None


_deltas: dict = {}


def _delta(cond: sp.Basic, scaled: bool) -> sp.Dummy:
    """The positive δ of a condition: the same one each time it is asked for, so that the
    same difference on the same conditions is the same expression (the proof cache and the
    decisions' cache are keyed by it: a fresh δ each time made every lookup miss, and
    Symon 12-10's motion, checked twice, spent its budget twice)."""
    key = (cond, scaled)
    if key not in _deltas:
        if len(_deltas) >= CACHE_SIZE:
            _deltas.clear()
        _deltas[key] = sp.Dummy("delta", positive=True)
    return _deltas[key]


def unproved_reason(method: str) -> str:
    """The phrase for a passing part whose check has no proof attempt of its own, read from
    how it was decided."""
    if method.startswith("boundary"):
        return BOUNDARY
    if "asymptotic" in method:
        return LIMIT
    if "simulated" in method or "integrat" in method or method.startswith("measured") \
            or ", measured)" in method or "DOP853" in method:  # a flow integrated
        return MEASURED
    if method.startswith("estimate("):  # at the book's numbers, within its precision
        return ESTIMATE
    if method == "exact":
        return EXACT
    return NO_PATH
