"""A curve of a functional, numerically: its constants from the end conditions, the
Euler–Lagrange residual along it, the functional's value on it, the Jacobi field, and the
functional on perturbed curves near it — all at 30 digits (mpmath), but the Jacobi field's
integration (float64, DOP853 at rtol 1e-11: only the sign of its determinant counts).

A curve is given by a parameter s: x(s) and yᵢ(s) (an explicit curve y(x) has s = x), its
ends at s = s_a and s = s_b, and constants fixed by the end conditions (the cycloid's a and
θ₁). Along it the jets are y′ = (dy/ds)/(dx/ds), y″ = (dy′/ds)/(dx/ds), …, so any
expression in x, y, y′, … becomes one in s. The functional on the curve is ∫F̂ ds with
F̂ = F(x(s), y(s), y_s/x_s)·x_s: a functional of y(s) in its own right, whose Jacobi
equation and perturbations y + εη (η(s_a) = η(s_b) = 0 at a fixed end) are the curve's.
"""

from __future__ import annotations

from dataclasses import dataclass

import mpmath
import numpy as np
import sympy as sp

from mechbook.core import mpmemo
from mechbook.core.backends import FEW_CALLS_BACKEND
from mechbook.core.compile import compile_exprs
from mechbook.core.numeval import evaluate, evaluate_mp
from mechbook.engine.variational import augmented, euler_lagrange
from mechbook.errors import UnsupportedError
from mechbook.model.functional import Functional

DIGITS = 30
NEWTON_STEPS = 40  # Gauss–Newton iterations for the constants at one point
CONTINUATION = 4  # steps from the default parameter values to a sampled point
ON_THE_WAY = 12  # digits of the constants at the continuation's points before the last
JACOBI_START = 1e-3  # the Jacobi field starts this fraction of the range inside
JACOBI_CALLS = 20000  # right-hand sides the Jacobi field may take
INTERIOR = (0.13, 0.29, 0.41, 0.58, 0.71, 0.87)  # fractions of [s_a, s_b] sampled


@dataclass
class Curve:
    """x(s), yᵢ(s) on [s_a, s_b] (expressions in s, the parameters and the constants)."""

    s: sp.Symbol
    x: sp.Expr
    ys: list[sp.Expr]
    ends: tuple[sp.Expr, sp.Expr]
    constants: list[sp.Symbol]


def jets_on(curve: Curve, fn: Functional, upto: int) -> dict[sp.Symbol, sp.Expr]:
    """{x: x(s), y: y(s), y′: y_s/x_s, …} up to the `upto`-th derivative."""
    xs = sp.diff(curve.x, curve.s)
    out: dict[sp.Symbol, sp.Expr] = {fn.x: curve.x}
    for jet, y in zip(fn.jets, curve.ys, strict=True):
        d = y
        for k in range(upto + 1):
            out[jet[k]] = d
            d = sp.diff(d, curve.s) / xs
    return out


def along(expr: sp.Expr, curve: Curve, fn: Functional) -> sp.Expr:
    """`expr` (in x, the jets) as a function of the curve's parameter s."""
    used = [k for jet in fn.jets for k, sym in enumerate(jet) if sym in expr.free_symbols]
    return expr.xreplace(jets_on(curve, fn, max(used, default=0)))


def mp_value(expr: sp.Expr, point: dict):
    """expr at `point` in 30-digit arithmetic (an mpmath number)."""
    return evaluate_mp(expr, point, DIGITS)


def fast(expr: sp.Expr):
    """(f, symbols): expr as an mpmath function of its free symbols (SymPy's lambdify of
    an expression the safe parser and the engine built; cse), evaluated at the working
    precision: ten times faster than numeval's program, for the many evaluations of a
    quadrature or an iteration (the verdicts' residuals keep numeval's scale). Its
    elementary functions remember their values (mechbook.core.mpmemo: the perturbed
    curves' quadratures share their nodes), the same numbers bit for bit."""
    key = expr
    hit = _FAST.get(key)
    if hit is None:
        syms = sorted(expr.free_symbols, key=str)
        hit = (sp.lambdify(syms, expr, modules=[mpmemo.NAMESPACE, "mpmath"], cse=True),
               syms)
        _FAST[key] = hit
    return hit


_FAST: dict = {}


def fast_value(expr: sp.Expr, point: dict):
    """expr at `point` (mpmath numbers) by `fast`, the precision doubled (30 to 240 digits)
    where it divides by zero: near a singular end 1 − cos θ at θ = 1e-40 is 0 at 30
    digits. 0 where even 240 digits do not resolve it (a quadrature node within 1e-200 of
    the end, whose weight is as small)."""
    f, syms = fast(expr)
    digits = mpmath.mp.dps
    while digits <= 8 * DIGITS:
        try:
            with mpmath.workdps(digits):
                v = f(*[_mp(point[k]) for k in syms])
            if mpmath.isfinite(v):
                return v
        except (ZeroDivisionError, ValueError, OverflowError):
            pass
        digits *= 2
    return mpmath.mpf(0)


def _mp(x):
    """x as an mpmath number: a SymPy number's decimal string parsed at the working
    precision, once per precision (a quadrature asks for the same parameters at every node;
    SymPy's printing was a tenth of its time)."""
    if not isinstance(x, sp.Basic):
        return x
    key = (type(x), x, mpmath.mp.prec)
    hit = _MP.get(key)
    if hit is None:
        if len(_MP) >= 4096:
            _MP.clear()
        hit = _MP[key] = mpmath.mpf(str(x))
    return hit


_MP: dict = {}


def integral(expr_s: sp.Expr, curve: Curve, point: dict):
    """∫ expr_s ds over [s_a, s_b] at `point` by tanh-sinh quadrature (integrable end
    singularities allowed), 30 digits: (value, error estimate)."""
    with mpmath.workdps(DIGITS):
        a = mp_value(curve.ends[0], point)
        b = mp_value(curve.ends[1], point)
        pt = dict(point)
        fn, syms = fast(expr_s)
        at = syms.index(curve.s) if curve.s in syms else None
        args: dict = {}  # the arguments at a precision, converted once (not at every node)

        def f(s):
            digits = mpmath.mp.dps  # fast_value's first try, its arguments the same numbers
            with mpmath.workdps(digits):
                held = args.get(mpmath.mp.prec)
                if held is None:
                    held = args[mpmath.mp.prec] = [_mp(pt[k]) if k != curve.s else None
                                                   for k in syms]
                if at is not None:
                    held[at] = s
                try:
                    v = fn(*held)
                    if mpmath.isfinite(v):
                        return mpmath.re(v)
                except (ZeroDivisionError, ValueError, OverflowError):
                    pass
            pt[curve.s] = s  # no value at the working precision: fast_value's more digits
            return mpmath.re(fast_value(expr_s, pt))

        return mpmath.quad(f, [a, (a + b) / 2, b], error=True)


def functional_integrand(fn: Functional, curve: Curve, integrand: sp.Expr | None = None):
    """F̂(s) = F(x(s), y(s), y′(s))·x_s: the integrand of ∫ds (F by default)."""
    F = fn.integrand if integrand is None else integrand
    return along(F, curve, fn) * sp.diff(curve.x, curve.s)


@dataclass
class Conditions:
    """What fixes a curve's unknowns and what an extremal must satisfy: the end conditions
    (x(s_e) = x_e, a fixed value, or a free end's natural condition ∂F̃/∂y′ = 0) and the
    isoperimetric integrals' values, which fix the constants; the Euler–Lagrange residuals
    at interior points, affine in the multipliers not given, which fix those (a holonomic
    constraint's μ(x)·∇φ projected out of them, and φ = 0 there). Each a named
    residual, zero on an extremal that meets them."""

    names: list[str]
    pointwise: list[sp.Expr]  # end conditions, evaluated at a point
    integrals: list[tuple[str, sp.Expr, sp.Expr]]  # (name, integrand in s, value)
    el_names: list[str]
    el: list[sp.Expr]  # Euler–Lagrange residuals at interior points
    multipliers: list[sp.Symbol]  # those not given: solved from `el` (linear)


def conditions(fn: Functional, curve: Curve, multipliers: dict) -> Conditions:
    """The curve's residuals (see `Conditions`), with the multipliers `multipliers` gives
    substituted (the rest stay symbols, solved for from the Euler–Lagrange residuals)."""
    Ft = augmented(fn).xreplace(multipliers)
    names, exprs = [], []
    for i, end in enumerate(fn.ends):
        at = {curve.s: curve.ends[i]}
        names.append(f"{fn.x} at end {i + 1}")
        exprs.append(curve.x.xreplace(at) - end.at)
        for f, jet, y in zip(fn.functions, fn.jets, curve.ys, strict=True):
            value = end.values[f]
            if value is not None:
                names.append(f"{f} at end {i + 1}")
                exprs.append(y.xreplace(at) - value)
            elif fn.order != 1:
                raise UnsupportedError("a free end of an integrand with y″")
            else:
                names.append(f"natural condition dF/d{jet[1]} = 0 at end {i + 1}")
                exprs.append(along(sp.diff(Ft, jet[1]), curve, fn).xreplace(at))
    unknown = [c.multiplier for c in fn.constraints
               if c.kind == "integral" and c.multiplier not in multipliers]
    if any(e.has(m) for e in exprs for m in unknown):
        raise UnsupportedError("a free end's natural condition with a multiplier the curve "
                               "does not give (give it in `multipliers:`)")
    integrals = [(f"integral {c.name}", functional_integrand(fn, curve, c.expr), c.value)
                 for c in fn.constraints if c.kind == "integral"]
    holonomic = [c for c in fn.constraints if c.kind == "holonomic"]
    Ft = Ft.xreplace({c.multiplier: 0 for c in holonomic})
    el = sp.Matrix([along(e, curve, fn) for e in euler_lagrange(fn, Ft)])
    on = []  # the curve on each holonomic surface, and E with μ·∇φ projected out
    if holonomic:
        G = sp.Matrix([[along(sp.diff(c.expr, y), curve, fn) for c in holonomic]
                       for y in fn.function_symbols(0)])
        el = el - G * (G.T * G).inv() * (G.T * el)
        on = [(c.name, along(c.expr, curve, fn)) for c in holonomic]
    el_names, el_exprs = [], []
    for t in INTERIOR:
        s_t = curve.ends[0] + (curve.ends[1] - curve.ends[0]) * sp.Rational(str(t))
        where = f"at s = s_a + {t}·(s_b − s_a)"
        for f, e in zip(fn.functions, el, strict=True):
            el_names.append(f"Euler–Lagrange ({f}{', μ·∇φ projected out' if on else ''}) "
                            + where)
            el_exprs.append(e.xreplace({curve.s: s_t}))
        for name, phi in on:
            el_names.append(f"holonomic constraint {name} {where}")
            el_exprs.append(phi.xreplace({curve.s: s_t}))
    return Conditions(names, exprs, integrals, el_names, el_exprs, unknown)


def multipliers_at(cond: Conditions, point: dict) -> dict:
    """The multipliers not given, by least squares from the Euler–Lagrange residuals (affine
    in them) at `point` (parameters and constants); {} if there are none."""
    if not cond.multipliers:
        return {}
    zero = {m: mpmath.mpf(0) for m in cond.multipliers}
    with mpmath.workdps(DIGITS + 10):
        b = mpmath.matrix([mpmath.re(fast_value(e, {**point, **zero})) for e in cond.el])
        A = mpmath.matrix(len(cond.el), len(cond.multipliers))
        for j, m in enumerate(cond.multipliers):
            one = dict(zero)
            one[m] = mpmath.mpf(1)
            for i, e in enumerate(cond.el):
                A[i, j] = mpmath.re(fast_value(e, {**point, **one})) - b[i]
        sol = mpmath.lu_solve(A.T * A, -(A.T * b))
    return {m: sol[j] for j, m in enumerate(cond.multipliers)}


def residuals(cond: Conditions, curve: Curve, point: dict) -> list[tuple[str, object, float]]:
    """(name, value, scale) of every residual at `point` (parameters, constants and
    unknown multipliers given): a scale is the magnitude of what cancelled."""
    out = []
    for name, e in zip(cond.names + cond.el_names, cond.pointwise + cond.el, strict=True):
        v, m = evaluate(e, point, DIGITS)
        out.append((name, mpmath.mpc(v), max(m, 1e-300)))
    for name, e, value in cond.integrals:
        got, err = integral(e, curve, point)
        want = mp_value(value, point)
        out.append((name, mpmath.mpc(got - want), float(abs(got) + abs(want)) + 1e-300))
    return out


def solve_unknowns(cond: Conditions, curve: Curve, unknowns: list[sp.Symbol],
                   start: dict, params: dict, digits: int = DIGITS - 2) -> dict | None:
    """The unknowns (constants, multipliers) that make every residual vanish at the
    parameter values `params`, by Gauss–Newton at 30 digits from `start`, until a step is
    below 10^−digits of them (28 digits; a point on the way of a continuation needs
    fewer); None if it does not converge. The Jacobian by forward differences at the start
    and wherever a step did not halve the residual, else by Broyden's update (the secant
    condition J·Δu = Δr: one residual vector a step instead of one per unknown more; the
    steps then shrink superlinearly, and the answer is still where r = 0)."""
    u = mpmath.matrix([mpmath.mpf(str(start[k])) for k in unknowns])
    with mpmath.workdps(DIGITS + 10):
        J = before = last = None
        for _ in range(NEWTON_STEPS):
            pt = {**params, **dict(zip(unknowns, u, strict=True))}
            try:
                r = _vector(cond, curve, pt)
                if J is not None and mpmath.norm(r) <= mpmath.norm(before) / 2:
                    J += (r - before - J * last) * last.T / mpmath.fsum(x * x for x in last)
                else:
                    J = _jacobian(cond, curve, unknowns, u, pt, r)
                step = mpmath.lu_solve(J.T * J + mpmath.eye(len(unknowns)) *
                                       mpmath.mpf(10) ** -40, -(J.T * r))
            except (ZeroDivisionError, ValueError, TypeError, ArithmeticError):
                return None
            u += step
            before, last = r, step
            if mpmath.norm(step) <= mpmath.mpf(10) ** -digits * (1 + mpmath.norm(u)):
                return dict(zip(unknowns, u, strict=True))
    return None


def _jacobian(cond: Conditions, curve: Curve, unknowns: list[sp.Symbol], u, pt: dict, r):
    """∂r/∂u at `pt` by forward differences: the O(h) = 1e-12 error in J slows Newton by a
    factor 1e-12 a step, and the answer is where r = 0 (one residual vector a column, not
    two)."""
    J = mpmath.matrix(len(r), len(unknowns))
    for j, k in enumerate(unknowns):
        h = mpmath.mpf(10) ** -12 * max(1, abs(u[j]))
        up = dict(pt)
        up[k] = u[j] + h
        col = (_vector(cond, curve, up) - r) / h
        for i in range(len(r)):
            J[i, j] = col[i]
    return J


def _vector(cond: Conditions, curve: Curve, pt: dict):
    out = [mpmath.re(fast_value(e, pt)) for e in cond.pointwise]
    for _, e, value in cond.integrals:
        out.append(integral(e, curve, pt)[0] - mpmath.re(fast_value(value, pt)))
    return mpmath.matrix(out)


def continued(cond: Conditions, curve: Curve, unknowns: list[sp.Symbol], start: dict,
              base: dict, target: dict) -> dict | None:
    """The unknowns at the parameter values `target`, followed from their values `start` at
    `base` in CONTINUATION straight steps (so a branch chosen at the default values is the
    branch met at the sampled point); None where the branch is lost."""
    if not unknowns:
        return {}
    at, before = solve_unknowns(cond, curve, unknowns, start, base, ON_THE_WAY), None
    for k in range(1, CONTINUATION + 1):
        if at is None:
            return None
        t = mpmath.mpf(k) / CONTINUATION
        params = {p: base[p] + t * (target[p] - base[p]) for p in target}
        # the points on the way only keep to the branch: ON_THE_WAY digits, far below the
        # extrapolation's own error; the target to the full 28
        digits = DIGITS - 2 if k == CONTINUATION else ON_THE_WAY
        # Newton from the branch extrapolated along the equal steps (off by the steps'
        # square, not by a step: three iterations fewer of eight), else from the last point
        found = None
        if before is not None:
            ahead = {u: 2 * at[u] - before[u] for u in unknowns}
            found = solve_unknowns(cond, curve, unknowns, ahead, params, digits)
        if found is None:
            found = solve_unknowns(cond, curve, unknowns, at, params, digits)
        at, before = found, at
    return at


# ---- the Jacobi field, Legendre's condition ------------------------------------------------
def reparametrized(fn: Functional, curve: Curve, integrand: sp.Expr | None = None):
    """(F̂(s, Y, Y_s), Y, Y_s): the functional on the curve as one of the functions Y(s),
    with x(s) kept (its Legendre matrix and Jacobi equation are the curve's in s)."""
    if fn.order != 1:
        raise UnsupportedError("the second variation of an integrand with y″")
    F = fn.integrand if integrand is None else integrand
    n = len(fn.functions)
    Y = [sp.Symbol(f"_Y{i}", real=True) for i in range(n)]
    Ys = [sp.Symbol(f"_Ys{i}", real=True) for i in range(n)]
    xs = sp.diff(curve.x, curve.s)
    sub = {fn.x: curve.x}
    for i in range(n):
        sub[fn.jets[i][0]] = Y[i]
        sub[fn.jets[i][1]] = Ys[i] / xs
    return F.xreplace(sub) * xs, Y, Ys


class _Stiff(Exception):
    """The Jacobi field's integration exceeded its budget of steps."""


@dataclass
class SecondVariation:
    """Legendre's matrix along the curve (its smallest eigenvalue at interior points) and
    the Jacobi field's first zero after s_a (None if none on (s_a, s_b])."""

    legendre_min: list[float]
    conjugate: float | None
    ends: tuple[float, float]


def second_variation(fn: Functional, curve: Curve, point: dict,
                     integrand: sp.Expr | None = None) -> SecondVariation:
    """Legendre's condition and the Jacobi field of the curve at `point` (parameters and
    constants): the field h with h(s_a) = 0, h_s(s_a) = 1 (a matrix of n columns for n
    functions) solves d/ds(P̂h_s + R̂ᵀh) = R̂h_s + Q̂h; a zero of det h in (s_a, s_b] is a
    point conjugate to s_a."""
    from scipy.integrate import solve_ivp

    Fh, Y, Ys = reparametrized(fn, curve, integrand)
    n = len(Y)
    on = {Y[i]: curve.ys[i] for i in range(n)}
    on.update({Ys[i]: sp.diff(curve.ys[i], curve.s) for i in range(n)})
    P = [[sp.diff(Fh, a, b).xreplace(on) for b in Ys] for a in Ys]
    R = [[sp.diff(Fh, a, b).xreplace(on) for b in Ys] for a in Y]
    Q = [[sp.diff(Fh, a, b).xreplace(on) for b in Y] for a in Y]
    fixed = {k: v for k, v in point.items() if k != curve.s}
    flat = [e.xreplace({k: sp.Float(str(v), DIGITS) for k, v in fixed.items()})
            for M in (P, R, Q) for row in M for e in row]
    f, _ = compile_exprs([curve.s], flat, FEW_CALLS_BACKEND)
    sa = float(mpmath.re(mp_value(curve.ends[0], fixed)))
    sb = float(mpmath.re(mp_value(curve.ends[1], fixed)))
    L = sb - sa

    def mats(s):
        v = np.asarray(f(np.array([s])), dtype=float).ravel()
        k = n * n
        return (v[:k].reshape(n, n), v[k:2 * k].reshape(n, n), v[2 * k:].reshape(n, n))

    legendre = []
    for t in np.linspace(0.02, 0.98, 25):
        Pm = mats(sa + t * L)[0]
        legendre.append(float(np.min(np.linalg.eigvalsh((Pm + Pm.T) / 2))))
    if not all(np.isfinite(legendre)):
        raise UnsupportedError("Legendre's matrix is not finite along the curve")
    s0 = sa + JACOBI_START * L  # a singular end (the cycloid's cusp) is stepped over
    P0, R0, _ = mats(s0)
    h0 = np.zeros((n, n))
    pi0 = P0 @ np.eye(n) + R0.T @ h0

    calls = [0]

    def rhs(s, z):
        calls[0] += 1
        if calls[0] > JACOBI_CALLS:
            raise _Stiff
        h, pi = z[:n * n].reshape(n, n), z[n * n:].reshape(n, n)
        Pm, Rm, Qm = mats(s)
        hs = np.linalg.solve(Pm, pi - Rm.T @ h)
        return np.concatenate([hs.ravel(), (Rm @ hs + Qm @ h).ravel()])

    def det(s, z):
        return np.linalg.det(z[:n * n].reshape(n, n))

    det.terminal = True
    det.direction = 0
    z0 = np.concatenate([h0.ravel(), pi0.ravel()])
    s1 = s0 + JACOBI_START * L  # past the start's own zero of h before zeros are sought
    try:
        first = solve_ivp(rhs, (s0, s1), z0, method="DOP853", rtol=1e-11,
                          atol=1e-14 * abs(L))
        run = first
        if first.status == 0:
            run = solve_ivp(rhs, (s1, sb), first.y[:, -1], method="DOP853", rtol=1e-11,
                            atol=1e-14 * abs(L), events=det)
    except _Stiff:
        raise UnsupportedError(f"the Jacobi equation took more than {JACOBI_CALLS} steps "
                               "(a singular or stiff coefficient along the curve)") from None
    if run.status == -1:
        raise UnsupportedError(f"the Jacobi equation could not be integrated ({run.message})")
    zeros = run.t_events[0]
    return SecondVariation(legendre, float(zeros[0]) if len(zeros) else None, (sa, sb))


# ---- perturbed curves ----------------------------------------------------------------------
def bump(k: int, t: sp.Expr, free: tuple[bool, bool]) -> sp.Expr:
    """The k-th variation η(t), t ∈ [0, 1]: vanishing to second order at a fixed end (so
    y + εη stays where y does near a singular end, the cycloid's cusp), free at a free one."""
    w = (t**2 if not free[0] else 1) * ((1 - t)**2 if not free[1] else 1)
    return w * sp.cos((k - 1) * sp.pi * t)


@dataclass
class Perturbed:
    """The functional near the curve along one variation: J(0), J′(0), J″(0), and the
    smaller of J(±ε) − J(0)."""

    label: str
    value: object
    slope: object
    curvature: object
    least_change: object


def perturbed(fn: Functional, curve: Curve, point: dict, integrand: sp.Expr,
              eps: float = 1e-5, modes: int = 2) -> list[Perturbed]:
    """J(y + εη) for η each of `modes` variations of each function in turn (fixed ends
    kept), amplitude a tenth of the curve's size, at ε = 0, ±eps, 30 digits: J′(0) by the
    central difference (error ε²·J‴/6, 1e-11 of J), J″(0) by the second difference."""
    Fh, Y, Ys = reparametrized(fn, curve, integrand)
    t = (curve.s - curve.ends[0]) / (curve.ends[1] - curve.ends[0])
    e = sp.Symbol("_eps", real=True)
    out = []
    zero = None
    size = _size(fn, curve, point)
    for i, f in enumerate(fn.functions):
        free = tuple(end.values[f] is None for end in fn.ends)
        for k in range(1, modes + 1):
            eta = size * bump(k, t, free)
            sub = {}
            for j in range(len(Y)):
                y = curve.ys[j] + (e * eta if j == i else 0)
                sub[Y[j]] = y
                sub[Ys[j]] = sp.diff(y, curve.s)
            J = Fh.xreplace(sub)
            vals = {m: integral(J, curve, {**point, e: mpmath.mpf(m) * eps})[0]
                    for m in (-1, 1)}
            if zero is None:
                zero = integral(J, curve, {**point, e: mpmath.mpf(0)})[0]
            with mpmath.workdps(DIGITS):
                slope = (vals[1] - vals[-1]) / (2 * eps)
                curv = (vals[1] - 2 * zero + vals[-1]) / eps**2
                least = min(vals[1] - zero, vals[-1] - zero)
            out.append(Perturbed(f"{f} + ε·η{k}", zero, slope, curv, least))
    return out


def _size(fn: Functional, curve: Curve, point: dict):
    """A length for the variations: the span of x and of the functions over the curve."""
    pt = dict(point)
    span = mpmath.mpf(0)
    with mpmath.workdps(DIGITS):
        a, b = mp_value(curve.ends[0], pt), mp_value(curve.ends[1], pt)
        for expr in [curve.x, *curve.ys]:
            vals = []
            for t in np.linspace(0, 1, 9):
                pt[curve.s] = a + (b - a) * mpmath.mpf(float(t))
                try:
                    vals.append(mpmath.re(mp_value(expr, pt)))
                except (ZeroDivisionError, ValueError):
                    continue
            if vals:
                span = max(span, max(vals) - min(vals))
    return sp.Float(str(span / 10 if span else 1), DIGITS)


# ---- an implicit curve G(x, y) = 0 ---------------------------------------------------------
def implicit_jets(G: sp.Expr, fn: Functional) -> dict[sp.Symbol, sp.Expr]:
    """{y′: −G_x/G_y, y″: −(G_xx + 2G_xy·y′ + G_yy·y′²)/G_y} of the curve G(x, y) = 0 (one
    function): the jets as functions of the point (x, y) on it."""
    x, y = fn.x, fn.jets[0][0]
    gy = sp.diff(G, y)
    yp = -sp.diff(G, x) / gy
    ypp = -(sp.diff(G, x, 2) + 2 * sp.diff(G, x, y) * yp + sp.diff(G, y, 2) * yp**2) / gy
    return {fn.jets[0][1]: yp, fn.jets[0][2]: ypp}


def on_implicit(G: sp.Expr, fn: Functional, point: dict, x_value, y_start):
    """The y of G(x, y) = 0 at x = `x_value`, by Newton at 30 digits from `y_start` (the
    chord between the ends picks the branch); None if Newton does not converge."""
    x, y = fn.x, fn.jets[0][0]
    f = G.xreplace({x: x_value})
    df = sp.diff(G, y).xreplace({x: x_value})
    pt = dict(point)
    with mpmath.workdps(DIGITS + 10):
        v = mpmath.mpf(y_start)
        for _ in range(NEWTON_STEPS):
            pt[y] = v
            try:
                step = fast_value(f, pt) / fast_value(df, pt)
            except ZeroDivisionError:
                return None
            v -= mpmath.re(step)
            if abs(step) <= mpmath.mpf(10) ** -(DIGITS + 5) * (1 + abs(v)):
                return v
    return None
