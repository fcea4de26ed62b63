"""Evaluating a SymPy expression at a point, fast, with a measure of its cancellation.

Checking that an expression vanishes needs its value at a point *and* a scale to judge that
value against: the sum of the magnitudes of everything that was added on the way (a rounding
error analysis's condition number). Expanding the expression to read off its terms costs far
more than the check itself on large equations of motion, so this module compiles an
expression once into a kept program (its nodes bottom-up, repeated subexpressions once) and
runs it at each point in mpmath arithmetic, carrying both the value and that magnitude.
Nothing here parses text: the input is an expression already built by the safe parser or
the engine.
"""

from __future__ import annotations

from collections import OrderedDict

import mpmath
import sympy as sp

from mechbook.core import special
from mechbook.core.secalc import derivative

_FUNCS = {
    sp.sin: mpmath.sin, sp.cos: mpmath.cos, sp.tan: mpmath.tan, sp.cot: mpmath.cot,
    sp.sec: mpmath.sec, sp.csc: mpmath.csc, sp.asin: mpmath.asin, sp.acos: mpmath.acos,
    sp.atan: mpmath.atan, sp.sinh: mpmath.sinh, sp.cosh: mpmath.cosh, sp.tanh: mpmath.tanh,
    sp.asinh: mpmath.asinh, sp.acosh: mpmath.acosh, sp.atanh: mpmath.atanh,
    sp.exp: mpmath.exp, sp.log: mpmath.log, sp.Abs: abs, sp.sign: mpmath.sign,
    sp.atan2: mpmath.atan2, sp.re: mpmath.re, sp.im: mpmath.im,
    sp.conjugate: mpmath.conj,
    # one argument: the complete integrals K(m), E(m) (m = k², as in SymPy and mpmath)
    sp.elliptic_k: mpmath.ellipk, sp.gamma: mpmath.gamma,
    # the incomplete integrals, E(m) and E(φ, m), Jacobi's functions, Bessel's and their
    # zeros: each refuses (DomainError, a ValueError: a singular point) a point outside
    # its real domain (mechbook.core.special)
    **special.MPMATH,
}


# functions whose value is all `Program.value` computes (no slope): defined, with their
# numeric derivative, wherever mpmath gives them a value
ELEMENTARY = frozenset((mpmath.sin, mpmath.cos, mpmath.tan, mpmath.cot, mpmath.sec,
                        mpmath.csc, mpmath.sinh, mpmath.cosh, mpmath.tanh, mpmath.exp,
                        abs, mpmath.sign, mpmath.re, mpmath.im, mpmath.conj))


class NotNumeric(ValueError):
    """The expression has a part this evaluator cannot give a number for."""


_NOT_FINITE = (sp.zoo, sp.nan, sp.oo, -sp.oo)


def evaluate(expr: sp.Basic, point: dict, digits: int = 30) -> tuple[complex, float]:
    """(value, magnitude) of expr at `point`: magnitude bounds what cancelled in sums.

    Raises NotNumeric for a free symbol missing from the point or an unknown function, and
    ZeroDivisionError or ValueError where the expression is singular at the point."""
    prog = program(expr)
    with mpmath.workdps(digits):
        v, m = prog.run(prog.values(point))
        return complex(v), float(m)


def evaluate_mp(expr: sp.Basic, point: dict, digits: int = 30):
    """expr at `point` as an mpmath number of `digits` digits (call inside a context of at
    least that precision to keep them); errors as for `evaluate`."""
    prog = program(expr)
    with mpmath.workdps(digits):
        return prog.value(prog.values(point))


def _value(expr: sp.Basic, point: dict, digits: int) -> complex:
    """`evaluate`'s value alone (a relation's side: its cancellation is not asked)."""
    prog = program(expr)
    with mpmath.workdps(digits):
        return complex(prog.value(prog.values(point)))


def mp_values(point: dict, digits: int = 30) -> dict:
    """The point's values as mpmath numbers of `digits` digits, converted once for the many
    expressions evaluated there (a matrix's entries) by `evaluate_mp_at`."""
    with mpmath.workdps(digits):
        return {k: _number(v) for k, v in point.items()}


def evaluate_mp_at(expr: sp.Basic, values: dict, digits: int = 30):
    """`evaluate_mp` at a point already converted by `mp_values` (at the same digits): the
    same number, without converting the point again for each expression."""
    prog = program(expr)
    with mpmath.workdps(digits):
        return prog.value(values)


def evaluate_resolved(expr: sp.Basic, point: dict, digits: int = 30, max_digits: int = 240,
                      margin: int = 10):
    """expr at `point` as an mpmath number, the working precision doubled (from `digits` up
    to `max_digits`) until the value stands `margin` digits clear of what cancelled on the
    way; 0 if it never does (it is zero to max_digits). For a value judged close to a
    boundary, where terms of size 1e24 cancel to 1e-25 and 30 digits leave only noise."""
    prog = program(expr)
    d = digits
    while True:
        with mpmath.workdps(d):
            v, m = prog.run(prog.values(point))
            if abs(v) > mpmath.mpf(10) ** (margin - d) * m:
                return v
        if d >= max_digits:
            return mpmath.mpf(0)
        d = min(2 * d, max_digits)


def _number(v):
    """A point's value (a SymPy, mpmath or Python number; never text) as an mpmath number."""
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return mpmath.mpf(v)
    if isinstance(v, complex):
        return mpmath.mpc(v)
    if isinstance(v, (mpmath.mpf, mpmath.mpc)):
        return v
    if not isinstance(v, sp.Basic):
        raise NotNumeric(f"not a number: {type(v).__name__}")
    if isinstance(v, sp.Float):
        return mpmath.mpf(v._mpf_)
    if v.is_real:
        return mpmath.mpf(sp.Float(v, mpmath.mp.dps)._mpf_)
    return mpmath.mpmathify(complex(v))


PROGRAMS = 4096  # expressions whose programs are kept (least recently used dropped first)
_programs: OrderedDict = OrderedDict()


def program(expr: sp.Basic) -> Program:
    """The evaluation program of `expr`, compiled once and kept: the same expression is
    evaluated at thousands of points (sampled conditions, scans, zero tests)."""
    hit = _programs.get(expr)
    if hit is not None:
        _programs.move_to_end(expr)
        return hit
    prog = Program(expr)
    _programs[expr] = prog
    if len(_programs) > PROGRAMS:
        _programs.popitem(last=False)
    return prog


# the instructions of a Program (see its docstring)
_SYMBOL, _CONST, _RAISE, _ADD, _MUL, _POWI, _POW, _FUNC, _SYMPY = range(9)
_NO_SLOPE = (abs, mpmath.sign, mpmath.re, mpmath.im, mpmath.conj)


class Program:
    """An expression flattened into a list of instructions in the order a bottom-up walk
    visits its nodes, each repeated subexpression once; `run` carries (value, magnitude)
    through them in mpmath arithmetic.

    Why: walking the SymPy tree at each point asks every node what it is (SymPy's
    properties and equality), which cost more than the arithmetic; the program asks once.
    Errors (a missing symbol, zoo, an unknown function) are raised when the walk reaches the
    node, in the order the recursive walk met them."""

    def __init__(self, expr: sp.Basic):
        self.code: list[tuple] = []
        self._consts: list[sp.Basic] = []
        self._const_prec: int | None = None
        self._const_values: list = []
        self._index: dict = {}
        self._emit(expr)
        del self._index
        self.symbols = list(dict.fromkeys(
            [ins[1] for ins in self.code if ins[0] == _SYMBOL]
            + [x for ins in self.code if ins[0] == _SYMPY for x in ins[1].free_symbols]))

    def values(self, point: dict) -> dict:
        """The point's values of this program's symbols as mpmath numbers (at the working
        precision): a point names every parameter and coordinate, an expression a few."""
        return {k: _number(point[k]) for k in self.symbols if k in point}

    def _emit(self, e: sp.Basic) -> int:
        hit = self._index.get(e)
        if hit is not None:
            return hit
        code = self.code
        if e.is_Symbol:
            ins = (_SYMBOL, e)
        elif e in _NOT_FINITE:  # zoo, nan, oo (d/dx 0**x = 0**x*log(0)): singular here
            ins = (_RAISE, ValueError, f"{e} in the expression")
        elif e.is_Number or e.is_NumberSymbol or e is sp.I:
            self._consts.append(e)
            ins = (_CONST, len(self._consts) - 1)
        elif e.is_Add:
            ins = (_ADD, tuple(self._emit(a) for a in e.args))
        elif e.is_Mul:
            ins = (_MUL, tuple(self._emit(a) for a in e.args))
        elif e.is_Pow:
            base, ex = self._emit(e.base), e.exp
            if ex.is_Integer and ex > 0:
                ins = (_POWI, base, int(ex))
            else:
                iex = int(ex) if ex.is_Integer else None
                half = int(ex.p) if ex.is_Rational and ex.q == 2 else None
                ins = (_POW, base, self._emit(ex), iex, half, bool(ex.is_Number))
        elif (f := _FUNCS.get(e.func)) is not None:
            ins = (_FUNC, f, tuple(self._emit(a) for a in e.args))
        elif isinstance(e, sp.Piecewise) or not e.args:
            ins = (_RAISE, NotNumeric, f"cannot evaluate {type(e).__name__}")
        else:  # anything else SymPy knows how to evaluate (rare): see _sympy_value
            ins = (_SYMPY, e)
        code.append(ins)
        self._index[e] = len(code) - 1
        return len(code) - 1

    def _constants(self) -> list:
        """The constants as mpmath numbers at the working precision (converted again when
        it changes: by binary precision, which two workprec calls of one dps can differ in)."""
        prec = mpmath.mp.prec
        if self._const_prec != prec:
            self._const_values = [mpmath.mpmathify(complex(c)) if c is sp.I else
                                  mpmath.mpf(sp.Float(c, precision=prec)._mpf_)
                                  for c in self._consts]
            self._const_prec = prec
        return self._const_values

    def value(self, pt: dict):
        """The value alone at `pt` (what `run` gives first, the same number): the
        magnitudes and the slopes of functions (a numeric derivative per call) are not
        carried, except for functions outside ELEMENTARY, whose slope's evaluation may
        refuse a point near the edge of their domain, as `run` does."""
        consts = self._constants()
        vals: list = []
        for ins in self.code:
            op = ins[0]
            if op == _SYMBOL:
                v = pt.get(ins[1])
                if v is None:
                    raise NotNumeric(f"no value for {ins[1]}")
            elif op == _CONST:
                v = consts[ins[1]]
            elif op == _ADD:
                v = mpmath.mpf(0)
                for a in ins[1]:
                    v += vals[a]
            elif op == _MUL:
                v = mpmath.mpf(1)
                for a in ins[1]:
                    v *= vals[a]
            elif op == _POWI:
                v = vals[ins[1]] ** ins[2]
            elif op == _POW:
                v = _power_value(vals[ins[1]], vals[ins[2]], ins[3], ins[4])
            elif op == _FUNC:
                args = [vals[a] for a in ins[2]]
                if ins[1] in ELEMENTARY:
                    v = ins[1](*args)
                else:
                    v, _ = _function(ins[1], args, [abs(a) for a in args])
            elif op == _RAISE:
                raise ins[1](ins[2])
            else:
                v, _ = _sympy_value(ins[1], pt)
            vals.append(v)
        return vals[-1]

    def run(self, pt: dict) -> tuple:
        """(value, magnitude) at `pt` (symbols to mpmath numbers), at the current precision."""
        consts = self._constants()
        vals: list = []
        mags: list = []
        for ins in self.code:
            op = ins[0]
            if op == _SYMBOL:
                v = pt.get(ins[1])
                if v is None:
                    raise NotNumeric(f"no value for {ins[1]}")
                m = abs(v)
            elif op == _CONST:
                v = consts[ins[1]]
                m = abs(v)
            elif op == _ADD:
                v, m = mpmath.mpf(0), mpmath.mpf(0)
                for a in ins[1]:
                    v += vals[a]
                    m += mags[a]
            elif op == _MUL:
                v, m = mpmath.mpf(1), mpmath.mpf(1)
                for a in ins[1]:
                    v *= vals[a]
                    m *= mags[a]
            elif op == _POWI:
                v, m = vals[ins[1]] ** ins[2], mags[ins[1]] ** ins[2]
            elif op == _POW:
                v, m = _power(vals[ins[1]], mags[ins[1]], vals[ins[2]], mags[ins[2]], *ins[3:])
            elif op == _FUNC:
                v, m = _function(ins[1], [vals[a] for a in ins[2]], [mags[a] for a in ins[2]])
            elif op == _RAISE:
                raise ins[1](ins[2])
            else:
                v, m = _sympy_value(ins[1], pt)
            vals.append(v)
            mags.append(m)
        return vals[-1], mags[-1]


def _power_value(vb, ve, iex, half):
    if iex is not None:
        return vb ** iex
    if half is not None and mpmath.im(vb) == 0 and vb >= 0:
        return mpmath.sqrt(vb) ** half
    return mpmath.power(vb, ve)


def _power(vb, mb, ve, me, iex, half, numeric_exponent):
    v = _power_value(vb, ve, iex, half)
    # first-order propagation: what the base's (and exponent's) cancellation can do
    m = abs(v) + abs(ve * v / vb) * mb if vb != 0 else abs(v)
    if not numeric_exponent and vb != 0:
        m += abs(v * mpmath.log(vb)) * me
    return v, m


def _function(f, args: list, mags: list):
    v = f(*args)
    if len(args) == 1 and f not in _NO_SLOPE:
        slope = abs(mpmath.diff(f, args[0]))
        return v, abs(v) + slope * mags[0]
    if f is mpmath.atan2:
        (y, x), (my, mx) = args, mags
        r2 = abs(x) ** 2 + abs(y) ** 2
        return v, abs(v) + ((abs(x) * my + abs(y) * mx) / r2 if r2 else 0)
    return v, abs(v) + sum(mags)


def _sympy_value(e: sp.Basic, pt: dict):
    """A node the program has no instruction for: the numbers substituted, SymPy asked."""
    subs = {k: sp.Float(str(v), mpmath.mp.dps) if mpmath.im(v) == 0 else
            sp.Float(str(mpmath.re(v))) + sp.I * sp.Float(str(mpmath.im(v)))
            for k, v in pt.items() if k in e.free_symbols}
    try:
        v = mpmath.mpmathify(complex(sp.N(e.subs(subs), mpmath.mp.dps)))
    except (TypeError, ValueError) as exc:
        raise NotNumeric(f"cannot evaluate {e}") from exc
    return v, abs(v)


def is_zero(expr: sp.Basic, points: int = 3, digits: int = 30, seed: int = 20261123) -> bool:
    """Is `expr` identically zero? Decided at random points (every free symbol drawn in
    (0.3, 1.3), so positive symbols stay positive), each value judged against its
    cancellation scale; True only if it vanishes to 1e-20 relative at every point.

    For the engine's structural questions (is this coordinate cyclic, is this matrix
    zero) where `simplify` would cost seconds: an expression that is not identically zero
    vanishes at a random point with probability zero. A point where it does not evaluate
    (a singularity) is redrawn; if none evaluates, the answer is 'not known to be zero'."""
    if expr == 0:
        return True
    if not isinstance(expr, sp.Basic):
        return False
    import random

    rng = random.Random(seed)
    symbols = sorted(expr.free_symbols, key=lambda s: s.name)
    good = 0
    for _ in range(points * 4):
        if good >= points:
            break
        point = {s: sp.Float(rng.uniform(0.3, 1.3), digits) for s in symbols}
        try:
            v, m = evaluate(expr, point, digits)
        except (NotNumeric, RecursionError):  # RecursionError: mpmath/SymPy on a hostile
            return False  # tower of functions; every point would be as deep and as slow
        except (ZeroDivisionError, ValueError, TypeError, OverflowError):
            continue
        if not (abs(v) == abs(v) and m == m):  # NaN
            continue
        if abs(v) > 1e-20 * max(m, 1e-300):
            return False
        good += 1
    return good >= points


def without_absent(expr: sp.Basic, symbols) -> sp.Basic:
    """expr with each of `symbols` it does not really depend on set to zero.

    A kinetic energy built from Cartesian positions keeps an azimuth φ or the time in
    cos²φ + sin²φ, and an unsimplified linearization keeps a coordinate in terms that
    cancel; dropping it (a substitution, exact once ∂/∂φ vanishes identically, decided
    numerically by `is_zero`) keeps cyclic coordinates, autonomous systems and linear
    equations recognisable without simplify. A symbol is kept where dropping it would
    land on a singularity. A symbol inside `sign(...)` is kept: a piecewise-constant
    function's derivative vanishes almost everywhere (a delta at each jump), so random
    points would call a pulsed drive (a kicked rotor's kicks) independent of t."""
    stepped = set().union(*(a.free_symbols for a in expr.atoms(sp.sign)))
    for s in symbols:
        if s in stepped:
            continue
        if expr.has(s) and is_zero(derivative(expr, s)):  # SymEngine's: core.secalc
            dropped = expr.xreplace({s: sp.S.Zero})
            if not dropped.has(sp.nan, sp.zoo, sp.oo, -sp.oo):
                expr = dropped
    return expr


_RELATIONS = {"<": lambda a, b: a < b, "<=": lambda a, b: a <= b, ">": lambda a, b: a > b,
              ">=": lambda a, b: a >= b, "!=": lambda a, b: a != b}


def holds(cond: sp.Basic, point: dict, digits: int = 30) -> bool:
    """Truth of a condition (relations joined by and/or/not) at `point`, by evaluating each
    side in mpmath: SymPy's own evaluation of `cond.subs(point)` consults its assumption
    system and costs milliseconds per relation, which sampling multiplies by thousands.
    A side that does not evaluate to a real number makes the relation false."""
    if cond is sp.true or cond is sp.false:
        return bool(cond)
    if isinstance(cond, sp.And):
        return all(holds(a, point, digits) for a in cond.args)
    if isinstance(cond, sp.Or):
        return any(holds(a, point, digits) for a in cond.args)
    if isinstance(cond, sp.Not):
        return not holds(cond.args[0], point, digits)
    if isinstance(cond, sp.core.relational.Relational) and cond.rel_op in _RELATIONS:
        try:
            a = _value(cond.lhs, point, digits)
            b = _value(cond.rhs, point, digits)
        except NotNumeric:
            return bool(cond.subs(point))  # what the evaluator does not know: SymPy decides
        except (ZeroDivisionError, ValueError, TypeError, OverflowError):
            return False
        tiny = 10.0 ** (5 - digits)
        if abs(a.imag) > tiny * max(1.0, abs(a)) or abs(b.imag) > tiny * max(1.0, abs(b)):
            return False
        return bool(_RELATIONS[cond.rel_op](a.real, b.real))
    return bool(cond.subs(point))
