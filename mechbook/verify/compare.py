"""Deciding whether two expressions agree: symbolically if SymPy can, else numerically.

Numeric comparison evaluates at several random admissible points (parameters drawn around
their default values, honouring positivity and any `assume` conditions) with 30-digit
arithmetic, so a pass means agreement to far better than the stated tolerance at each point.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import mpmath
import numpy as np
import sympy as sp

from mechbook.core.numeval import NotNumeric, evaluate, evaluate_mp, evaluate_resolved, holds
from mechbook.core.words import plural
from mechbook.records import NUMERIC, ProofPolicy
from mechbook.verify.proof import FLOATS, OPEN, Budget, Proof, prove_zero

RTOL = 1e-10  # relative tolerance of a numeric comparison
# What an exact expression (no numbers below 30 digits in it) may leave at a 30-digit point,
# relative to its cancellation scale: rounding leaves ~1e-30 of it; 1e-10 would let an O(1)
# error through where 1e10-sized terms cancel (Symon 11-5: a wrong solution passed so)
EXACT_RTOL = 1e-20
POINTS = 6  # random points per numeric comparison
MANIFOLD_TRIES = 200  # starts that found no state on the constraint manifold, then give up
DIGITS = 30


@dataclass
class Verdict:
    ok: bool
    method: str  # 'symbolic' or 'numeric(N points, rtol)'
    detail: str = ""
    # what a pass is worth: the smallest wrong answer it would have rejected, in words
    # ("6 points at 30 digits, residual ≤ 1e-20 of its scale"); '' where the method says it
    power: str = ""
    # with --prove, why a pass is not proved (a fixed phrase of mechbook.verify.proof)
    unproved: str = ""


def symbolic_or(numeric: Verdict, proof, power: str) -> Verdict:
    """With --prove: `symbolic` with `power` where `proof` (a mechbook.verify.proof.Proof)
    holds, else the numeric pass with the proof's reason for not holding.

    Example: symbolic_or(Verdict(True, "numeric(5 points)"), Proof(True), "proved").method
    == "symbolic"."""
    if proof.ok:
        return Verdict(True, "symbolic", power=power)
    return Verdict(True, numeric.method, numeric.detail, numeric.power, unproved=proof.why)


def _derived_value(expr: sp.Basic, point: dict) -> tuple:
    """(real part, imaginary part) of a derived symbol's expression at `point`: compiled
    once and run in mpmath at 15 digits beyond DIGITS (the walk toward a limit asks for it
    at thousands of points: SymPy's subs and N cost 4 ms each there), as mpmath numbers
    (the checks on them are mpmath's comparisons, not SymPy's: a tenth of the time), SymPy's
    own evaluation where the compiled program has no number for a part; (None, None) where
    the value is not a number."""
    try:
        with mpmath.workdps(DIGITS + 15):
            v = evaluate_mp(expr, point, DIGITS + 15)
            return mpmath.re(v), mpmath.im(v)
    except NotNumeric:
        v = sp.N(expr.subs(point), DIGITS)
        re, im = v.as_real_imag()
        if not (re.is_number and im.is_number):
            return None, None
        return re, im


class Sampler:
    """Random admissible values for symbols: parameters, answer symbols and free variables."""

    def __init__(self, base: dict[sp.Symbol, float], conditions: Sequence[sp.Basic] = (),
                 seed: int = 20261122, spread: float = 0.5, policy: ProofPolicy = NUMERIC,
                 rtol: float = RTOL, fixed: Sequence[sp.Symbol] = (),
                 derived: dict[sp.Symbol, sp.Expr] | None = None, manifold=None,
                 approximate: bool = False):
        self.base = dict(base)
        self.conditions = list(conditions)
        self.rng = np.random.default_rng(seed)
        self.spread = spread
        self.policy = policy  # carried with the sampler to every comparison it serves
        self.rtol = rtol  # relative tolerance of `equal` and `vanishes` (a numeric estimate's)
        self.fixed = set(fixed)  # symbols kept at their base values (a numeric estimate)
        # symbols fixed by the others (a part's `restrict:`, a surface in parameter space):
        # computed after each draw, in order, so a later one may use an earlier one
        self.derived = dict(derived or {})
        # a constrained system's states (mechbook.model.manifold.StateManifold): a draw that
        # gives a coordinate or a velocity a value is moved onto the constraint manifold,
        # where the system's motion is (its solved accelerations hold nowhere else)
        self.manifold = manifold
        # the expressions compared hold a number written to more digits than a double (a
        # root to 36 digits): true to those digits, so an identity in it is not exact
        self.approximate = approximate
        self._budget: Budget | None = None

    def proof_budget(self) -> Budget:
        """The CPU seconds this part's proofs may still spend in `simplify` (one budget
        for every comparison the sampler serves, of `policy.seconds`)."""
        if self._budget is None:
            self._budget = Budget(self.policy.seconds)
        return self._budget

    def _complete(self, point: dict) -> dict | None:
        """The point with its derived symbols computed (None where one is not real)."""
        for sym, expr in self.derived.items():
            try:  # all 30 digits: a point exactly on a surface (a double root) stays on it
                re, im = _derived_value(expr, point)
            except (ZeroDivisionError, ValueError, TypeError, OverflowError):
                return None
            if re is None:
                return None
            if not (math.isfinite(float(re)) and abs(im) <= 1e-20 * max(1.0, abs(re))):
                return None
            if sym.is_positive and re <= 0:
                return None
            point[sym] = sp.Float(re, DIGITS)  # an mpf of 45 digits rounded to 30, as the
            # 45-digit Float it was once made into first
        return point

    def draw(self, variables: Iterable[sp.Symbol] = (), spread: float | None = None,
             tries: int = 2000) -> dict[sp.Symbol, sp.Float]:
        """One point satisfying every condition (raises if none is found). When the
        conditions exclude the neighbourhood of the default values, the spread is widened
        step by step (x4 each time), so an `assume:` far from the defaults still samples."""
        spread = self.spread if spread is None else spread
        # a condition may bound a state variable (an `assume:` such as r > 0): draw it too
        extra = set().union(*(c.free_symbols for c in self.conditions)) - set(self.base)
        # in a fixed order (by name, not a set's, which follows the process's hash seed):
        # the same seed gives the same points in every run
        variables = sorted(set(variables) | extra, key=sp.srepr)
        onto = self.manifold is not None and bool(self.manifold.state & set(variables))
        if onto and self.manifold.moving and self.manifold.t not in variables:
            variables.append(self.manifold.t)  # moving constraints: a state at a time
        missed = 0  # starts the projection onto the manifold could not bring onto it
        for attempt in range(tries):
            if attempt and attempt % (tries // 5) == 0:
                spread *= 4
            point = {}
            for sym, value in self.base.items():
                if sym in self.fixed:
                    point[sym] = value
                elif sym.is_positive:
                    point[sym] = value * math.exp(self.rng.uniform(-spread, spread))
                else:
                    point[sym] = value + self.rng.uniform(-1, 1) * max(1.0, abs(value)) * spread
            for v in variables:
                if v not in point:
                    point[v] = self.rng.uniform(0.1, 1.0) if v.is_nonnegative \
                        else self.rng.uniform(-1.0, 1.0)  # a radius declared positive
            point = self._complete({k: sp.Float(v, DIGITS) for k, v in point.items()})
            if point is not None and onto:
                point = self.manifold.project(point)
                if point is None:
                    missed += 1
                    if missed >= MANIFOLD_TRIES:
                        break
                    continue
            if point is not None and all(holds(c, point) for c in self.conditions):
                return point
        if self.manifold is not None:
            raise ValueError("no state on the constraint manifold found from random starts "
                             "(the constraints hold nowhere near them, or are dependent "
                             "there), or none that satisfies the stated conditions")
        raise ValueError("no admissible parameter point satisfies the stated conditions")

    def rounded(self) -> frozenset[sp.Symbol]:
        """The symbols whose drawn values are computed at 30 digits, not drawn exactly: a
        restriction's derived symbols and a state moved onto the constraint manifold. An
        identity holds at such a point only to that rounding, which no raised precision
        removes (a drawn value is a binary64 number: exact at any precision)."""
        moved = self.manifold.state if self.manifold is not None and not self.manifold.empty \
            else frozenset()
        return frozenset(self.derived) | frozenset(moved)

    def complete(self, point: dict) -> dict | None:
        """`point` with its derived (restricted) symbols recomputed, or None if one is not
        real there (for a caller that moved a parameter itself, e.g. towards a limit)."""
        return self._complete({k: v for k, v in point.items() if k not in self.derived})

    def widened(self, spread: float) -> Sampler:
        """The same sampler (conditions, derived symbols, policy) drawing with `spread`."""
        out = Sampler(self.base, self.conditions, spread=spread, policy=self.policy,
                      rtol=self.rtol, fixed=list(self.fixed), derived=self.derived,
                      manifold=self.manifold, approximate=self.approximate)
        out._budget = self.proof_budget()  # the same part: the same budget
        return out

    def default(self) -> dict[sp.Symbol, sp.Float]:
        """The default values (when they satisfy the conditions on the parameters alone;
        a condition on a state variable, such as r > 0, is for the states drawn later),
        with the derived (restricted) symbols computed."""
        point = self._complete({k: sp.Float(v, DIGITS) for k, v in self.base.items()})
        if point is not None and all(holds(c, point) for c in self.conditions
                                     if c.free_symbols <= set(point)):
            return point
        return {k: v for k, v in self.draw().items() if k in self.base}


def value(expr: sp.Basic, point: dict) -> complex:
    """expr at `point` as a complex number (NaN if it does not evaluate)."""
    return value_and_scale(expr, point)[0]


def value_and_scale(expr: sp.Basic, point: dict) -> tuple[complex, float]:
    """expr at `point` and the magnitude of what cancelled on the way (NaN if no value)."""
    try:
        return evaluate(expr, point, DIGITS)
    except NotNumeric:
        pass
    except (ZeroDivisionError, ValueError, TypeError, OverflowError):
        return complex(float("nan"), 0), float("nan")
    try:  # a part the fast evaluator does not know: let SymPy evaluate the whole
        v = complex(sp.N(expr.subs(point), DIGITS))
        return v, abs(v)
    except (TypeError, ValueError, ZeroDivisionError):
        return complex(float("nan"), 0), float("nan")


def _free_variables(exprs: Iterable[sp.Basic], known: dict) -> set[sp.Symbol]:
    out: set[sp.Symbol] = set()
    for e in exprs:
        out |= {s for s in e.free_symbols if s not in known}
    return out


PROVED = "proved symbolically"


def _proof(expr: sp.Basic, sampler: Sampler, symbolic: bool | None) -> Proof | None:
    """The proof attempt's result, or None where none is asked for."""
    return prove_zero(expr, sampler) if _prove(sampler, symbolic) else None


def vanishes(expr: sp.Basic, sampler: Sampler, symbolic: bool | None = None) -> Verdict:
    """Is `expr` identically zero (under the sampler's assumptions)? A symbolic proof is
    attempted after the numeric pass when `symbolic` (default: the sampler's policy)."""
    variables = _free_variables([expr], sampler.base)
    rtol = _residual_rtol(expr, sampler)
    exact_inputs = rtol == EXACT_RTOL and not _rounded_inputs(expr, sampler)
    worst = 0.0
    valid = 0
    for _ in range(POINTS * 3):
        if valid >= POINTS:
            break
        point = sampler.draw(variables)
        v, scale = value_and_scale(expr, point)
        if not (np.isfinite(v.real) and np.isfinite(v.imag) and np.isfinite(scale)):
            continue
        valid += 1
        rel = abs(v) / scale if scale > 0 else abs(v)
        if rtol == EXACT_RTOL and AMBIGUOUS * scale < abs(v) <= rtol * scale:
            # above 30 digits' rounding but under the tolerance: a real residual hidden by
            # what cancels? Decided with the precision raised until it stands clear
            deeper = _resolved(expr, point)
            if deeper:
                return Verdict(False, f"numeric({plural(valid, 'point')}, to {DEEP_DIGITS} digits)",
                               f"residual {abs(deeper):.3g} at {_fmt(point)} ({rel:.2g} of "
                               "the terms that cancel: under the tolerance, beyond 30 digits' "
                               "rounding)")
        elif exact_inputs and 0 < abs(v) <= AMBIGUOUS * scale:
            # the scale bounds what cancelled; 30 digits' real rounding may lie far below
            # it (1e-40 of it where a denominator cancels): a residual of 1e-28 of the
            # scale can be 1e10 above that rounding. Exact inputs: one run at twice the
            # digits tells rounding (it shrinks) from a residual (it stays)
            deeper = _resolved(expr, point, 2 * DIGITS)
            if deeper:
                return Verdict(False, f"numeric({plural(valid, 'point')}, to {2 * DIGITS} "
                               "digits)", f"residual {abs(deeper):.3g} at {_fmt(point)} "
                               f"({rel:.2g} of the terms that cancel, standing clear at "
                               f"{2 * DIGITS} digits: not rounding)")
        worst = max(worst, rel)
        if rel > rtol:
            return Verdict(False, f"numeric({plural(valid, 'point')})",
                           f"residual {abs(v):.3g} (relative {rel:.3g}) at {_fmt(point)}")
    if valid == 0:
        return Verdict(False, "numeric", "expression does not evaluate at any sample point")
    proof = _proof(expr, sampler, symbolic)
    if proof is not None and proof.ok:
        return Verdict(True, "symbolic", power=PROVED)
    if rtol != EXACT_RTOL:
        decided = ""
    elif exact_inputs:
        decided = f" (none above {CLEAR:g} of it at {2 * DIGITS} digits: exact inputs)"
    else:  # the inputs' own 30-digit rounding: below AMBIGUOUS of the scale it is that
        decided = (f" (under {AMBIGUOUS:g} of it undecided: inputs rounded, at {DIGITS} "
                   "digits or to their written digits)")
    return Verdict(True, f"numeric({plural(valid, 'point')}, rtol {rtol:g})",
                   f"worst relative {worst:.2g}",
                   power=f"{plural(valid, 'point')} at {DIGITS} digits, residual ≤ {rtol:g} "
                         f"of its scale{decided}",
                   unproved=proof.why if proof is not None else "")


# a residual above this fraction of its scale is more than 30 digits' rounding, of the
# arithmetic or of a point's computed values (a state projected onto a constraint manifold
# keeps its residuals below 1e-28 of their scale); below it, only exact inputs can tell
AMBIGUOUS = 1e-27
DEEP_DIGITS = 240  # how far the precision is raised to decide such a residual
MARGIN = 10  # digits a residual must stand clear of what cancels to count as one
CLEAR = 10.0 ** (MARGIN - 2 * DIGITS)  # the smallest residual, of its scale, 60 digits find


def _resolved(expr: sp.Basic, point: dict, max_digits: int = DEEP_DIGITS) -> complex:
    """expr at `point` with the precision raised (60 to `max_digits` digits) until the
    value stands 10 digits clear of what cancels in it; 0 if it never does (zero to that
    precision)."""
    try:
        return complex(evaluate_resolved(expr, point, 2 * DIGITS, max_digits, MARGIN))
    except (NotNumeric, ZeroDivisionError, ValueError, TypeError, OverflowError):
        return 0j


def _rounded_inputs(expr: sp.Basic, sampler: Sampler) -> bool:
    """Whether `expr` at a drawn point carries a rounding of its inputs that no raised
    precision removes: a symbol the sampler computes (Sampler.rounded), a number of 30
    digits in it, or one the key writes to its digits (Sampler.approximate)."""
    return sampler.approximate or bool(expr.free_symbols & sampler.rounded()) \
        or bool(expr.atoms(sp.Float))


def _residual_rtol(expr: sp.Basic, sampler: Sampler) -> float:
    """The bound on a residual relative to its scale: the sampler's for an estimate or an
    expression holding numbers of double precision (the engine's numeric roots), else
    EXACT_RTOL."""
    if sampler.rtol > RTOL:
        return sampler.rtol
    if isinstance(expr, sp.Basic) and any(f._prec < 90 for f in expr.atoms(sp.Float)):
        return sampler.rtol
    return min(sampler.rtol, EXACT_RTOL)


def _prove(sampler: Sampler, symbolic: bool | None) -> bool:
    return sampler.policy.prove if symbolic is None else symbolic


def all_vanish(exprs: Sequence[sp.Basic], sampler: Sampler,
               symbolic: bool | None = None) -> Verdict:
    """Does every expression vanish? All are tested numerically before any symbolic proof is
    tried, so a wrong one is reported at the cost of a few evaluations, not of simplify()."""
    verdicts = [vanishes(e, sampler, symbolic=False) for e in exprs]
    for v in verdicts:
        if not v.ok:
            return v
    if _prove(sampler, symbolic):  # the canonical forms for all first, then simplify
        proofs = _proofs(exprs, sampler)
        verdicts = [Verdict(True, "symbolic", power=PROVED) if p is not None and p.ok else
                    Verdict(v.ok, v.method, v.detail, v.power,
                            unproved=p.why if p is not None else "")
                    for p, v in zip(proofs, verdicts, strict=True)]
    return combine(verdicts)


def _proofs(exprs: Sequence[sp.Basic], sampler: Sampler) -> list[Proof | None]:
    """Each expression's proof, decided early: the canonical forms of all first; where one
    of them already refuses (not an identity, one branch of a root, floating-point numbers)
    the whole cannot be proved and no `simplify` is run for the others (Symon 12-22's
    steady motion: 6 s for one that could not change the verdict); otherwise `simplify` on
    the open ones in turn, none after the first that fails (Symon 12-06's motion: 4 s
    more). None: not attempted, the numeric verdict stands."""
    first = [prove_zero(e, sampler, canonical_only=True) for e in exprs]
    if any(not p.ok and p.why != OPEN for p in first):
        return [p if p.ok or p.why != OPEN else None for p in first]
    out: list[Proof | None] = []
    failed = False
    for e, p in zip(exprs, first, strict=True):
        if p.ok:
            out.append(p)
        elif failed:
            out.append(None)
        else:
            out.append(prove_zero(e, sampler))
            failed = not out[-1].ok
    return out


def combine(verdicts: Sequence[Verdict]) -> Verdict:
    """One verdict for several: the first failure, else a pass named by how it was decided."""
    for v in verdicts:
        if not v.ok:
            return v
    methods = {v.method.split("(")[0] for v in verdicts}
    method = "symbolic" if methods == {"symbolic"} else ("numeric" if "numeric" in methods else
                                                          ",".join(sorted(methods)))
    powers = list(dict.fromkeys(v.power for v in verdicts if v.power))  # once each, in order
    unproved = list(dict.fromkeys(v.unproved for v in verdicts if v.unproved))
    return Verdict(True, method, "; ".join(v.detail for v in verdicts if v.detail),
                   power="; ".join(powers), unproved="; ".join(unproved))


def equal(a: sp.Basic, b: sp.Basic, sampler: Sampler, symbolic: bool | None = None) -> Verdict:
    """Do a and b agree identically? Exact expressions must agree to 1e-20 of what cancels
    in a − b (30-digit arithmetic: a difference far below double precision, or between
    values of 1e-30, still fails); an estimate, or an expression holding double-precision
    numbers, to the sampler's relative tolerance."""
    variables = _free_variables([a, b], sampler.base)
    diff = a - b
    rtol = _residual_rtol(diff, sampler)
    exact = rtol < sampler.rtol
    worst = 0.0
    valid = 0
    for _ in range(POINTS * 3):
        if valid >= POINTS:
            break
        point = sampler.draw(variables)
        va, vb = value(a, point), value(b, point)
        if not all(np.isfinite([va.real, va.imag, vb.real, vb.imag])):
            continue
        if exact:
            d, scale = value_and_scale(diff, point)
            if not (np.isfinite(d.real) and np.isfinite(d.imag) and np.isfinite(scale)):
                continue
            rel = abs(d) / scale if scale > 0 else abs(d)
            size = max(abs(va), abs(vb))
            if rel <= rtol and abs(d) > rtol * size:
                # zero against what cancels in a − b, not against the values themselves:
                # decided with the precision raised until the difference stands clear
                deeper = _resolved(diff, point)
                if deeper and abs(deeper) > rtol * size:
                    return Verdict(False, f"numeric({plural(valid + 1, 'point')}, to {DEEP_DIGITS} "
                                   "digits)", f"{_num(va)} vs {_num(vb)} differ by "
                                   f"{abs(deeper):.3g} (relative {abs(deeper) / size:.2g}) "
                                   f"at {_fmt(point)}")
        else:
            rel = abs(va - vb) / max(abs(va), abs(vb), 1e-300)
        valid += 1
        worst = max(worst, rel)
        if rel > rtol:
            return Verdict(False, f"numeric({plural(valid, 'point')})",
                           f"{_num(va)} vs {_num(vb)} (relative {rel:.2g}) at {_fmt(point)}")
    if valid == 0:
        return Verdict(False, "numeric", "expressions do not evaluate at any sample point")
    proof = _proof(diff, sampler, symbolic)
    if proof is not None and proof.ok and _floats(a, b):  # SymPy may fold 0.1·x − x/10 to 0
        proof = Proof(False, FLOATS)
    if proof is not None and proof.ok:
        return Verdict(True, "symbolic", power=PROVED)
    return Verdict(True, f"numeric({plural(valid, 'point')}, rtol {rtol:g})",
                   f"worst relative {worst:.2g}",
                   power=(f"within the stated {sampler.rtol:.2g}" if sampler.rtol > RTOL else
                          f"{plural(valid, 'point')} at {DIGITS} digits, within {rtol:g}"),
                   unproved=proof.why if proof is not None else "")


def _floats(*exprs: sp.Basic) -> bool:
    return any(isinstance(e, sp.Basic) and e.atoms(sp.Float) for e in exprs)


def _num(z: complex) -> str:
    return f"{z.real:.10g}" if abs(z.imag) < 1e-14 * max(1, abs(z)) else f"{z:.6g}"


def at_point(point: dict) -> str:
    """Where a value was evaluated, for a failing verdict's message: " at {m=1.2, ...}"
    (every fail names its point). Example: at_point({x: 0.5}) == " at {x=0.5}"."""
    return " at " + _fmt(point)


def _fmt(point: dict) -> str:
    items = sorted(point.items(), key=lambda kv: kv[0].name)[:8]
    return "{" + ", ".join(f"{k}={float(v):.4g}" for k, v in items) + "}"


def match_multiset(book: Sequence[float], engine: Sequence[float], partial: bool = False,
                   rtol: float = 1e-8) -> tuple[bool, str]:
    """Compare two lists of numbers as multisets (book ⊆ engine if partial)."""
    if any(not np.isfinite(x) for x in book):
        return False, f"book value(s) not real and finite here: {_list(list(book))}"
    b = sorted(book)
    e = sorted(x for x in engine if np.isfinite(x))
    if not partial and len(b) != len(e):
        return False, f"book has {len(b)} values, engine {len(e)}: {_list(b)} vs {_list(e)}"
    scale = max([abs(x) for x in b + e] + [1e-300])
    free = list(e)
    for x in b:
        best = min(range(len(free)), key=lambda i: abs(free[i] - x), default=None)
        if best is None or abs(free[best] - x) > rtol * max(abs(x), 1e-3 * scale):
            return False, f"book value {x:.10g} not among engine values {_list(e)}"
        free.pop(best)
    return True, ""


def _list(xs: Sequence[float]) -> str:
    return "[" + ", ".join(f"{x:.8g}" for x in xs) + "]"
