"""Steady motions: where they are, and at which rates (Symon §11-5, §12-6).

A steady motion turns some coordinates at constant rates while the others stay put; with no
rates it is an equilibrium. This module says where steady motions are; counting them in a
region and judging each one's stability from numbers is mechbook.engine.steady_search, and
small oscillations about a given one are `Analysis.steady_linear` (Routh's reduction,
mechbook.engine.routh, or the motion kept in full). Nothing here knows a particular system:
chapter 11's tops and chapter 12's orbits and three bodies use the same functions.

    steady_residuals   the equations of motion along q*(t) = point + rates·t (q̈ = 0): all
                       zero, at two times, exactly when that uniform motion is steady
    constrained_steady_residuals  the same with constraints: the constraints kept along
                       it, and the residual within what the constraint forces can supply
    steady_conditions  the conditions on the non-turning coordinates at fixed rates, or at
                       fixed cyclic momenta (the equilibria of Routh's reduced system)
    SteadyFamily       steady motions at a given point with one cyclic rate x unknown (the
                       others fixed by `hold:` relations such as ω3 = ψ̇ + φ̇ cos θ): the
                       conditions as functions of x, their real roots at given parameter
                       values (polynomial in x after clearing denominators), so whether any
                       exists (the minimum spin of a top)
    effective_potential  Routh's V_eff(q; p) = [Σ p_φ φ̇ − L] at q̇ = 0 with φ̇ expressed by
                       the momenta: the energy left for the non-cyclic coordinates when the
                       cyclic momenta are held (Symon's V'(θ) of the top)
"""

from __future__ import annotations

from dataclasses import dataclass

import mpmath
import sympy as sp

from mechbook.core.numeval import is_zero
from mechbook.engine.affine import solve_within
from mechbook.engine.equilibria import Equilibria
from mechbook.engine.lagrange import Dynamics
from mechbook.engine.routh import ReducedSystem
from mechbook.errors import UnsupportedError

DIGITS = 30
TIMES = (sp.Rational(7, 5), sp.Rational(-3, 7))  # a steady motion's residual vanishes at all t


def _uniform_motion(dyn: Dynamics, rates: dict, point: dict) -> dict:
    """The substitution q = point + rates·t, q̇ = rates, q̈ = 0, small parameters 0."""
    t = dyn.sys.t
    sub = {}
    for q, v, a in zip(dyn.q, dyn.qd, dyn.qdd, strict=True):
        sub[q] = sp.S(point.get(q, 0)) + sp.S(rates.get(q, 0)) * t
        sub[v] = sp.S(rates.get(q, 0))
        sub[a] = sp.S.Zero
    sub.update({s: sp.S.Zero for s in dyn.sys.small_params})
    return sub


def steady_residuals(dyn: Dynamics, rates: dict, point: dict) -> list[sp.Expr]:
    """E_i along q*(t) = point + rates·t, q̇ = rates, q̈ = 0 (small parameters off), at two
    times: every one vanishes exactly when that uniform motion solves the equations."""
    sys = dyn.sys
    sub = _uniform_motion(dyn, rates, point)
    out = []
    for e in dyn.residuals:
        e = e.xreplace(sub)
        out += [e.subs(sys.t, tv) for tv in TIMES] if e.has(sys.t) else [e]
    return out


def constrained_steady_residuals(dyn: Dynamics, rates: dict, point: dict) -> list[sp.Expr]:
    """What must vanish along q*(t) = point + rates·t for a system with constraints, at two
    times: the holonomic constraints g and every velocity-level row A·q̇ + b (the motion
    keeps its constraints), and the residual E less its part some multipliers could supply,
    E·det(G) − Aᵀ·adj(G)·A·E with G = A·Aᵀ (zero exactly where E = Aᵀλ for some λ: the
    constraint forces can make the motion, however large they must be)."""
    sys = dyn.sys
    sub = _uniform_motion(dyn, rates, point)
    E = sp.Matrix([e.xreplace(sub) for e in dyn.residuals])
    A = dyn.velocity_jacobian.xreplace(sub)
    kept = [g.xreplace(sub) for _, g in sys.constraints] + \
        [c.xreplace(sub) for c in dyn.velocity_rows]
    G = A * A.T
    free = E * G.det() - A.T * (G.adjugate() * (A * E))
    out = []
    for e in kept + list(free):
        out += [e.subs(sys.t, tv) for tv in TIMES] if e.has(sys.t) else [e]
    return out


def reduced_at(sys, momenta: dict) -> ReducedSystem:
    """The system left when the cyclic coordinates `momenta` names keep those momenta."""
    return ReducedSystem(sys, {c: sp.S.Zero for c in momenta}, {}, momenta=momenta)


def steady_conditions(sys, rates: dict | None = None, momenta: dict | None = None
                      ) -> tuple[list[sp.Expr], list[sp.Symbol], Equilibria]:
    """The conditions on the non-turning coordinates for a steady motion, those
    coordinates, and the Equilibria object that linearizes about one: at fixed `rates`
    (E_i with q̇ = rates), at fixed cyclic `momenta` (the equilibrium conditions of Routh's
    reduced system), or neither (static equilibria)."""
    if momenta:
        reduced = reduced_at(sys, momenta)
        eq = Equilibria(Dynamics(reduced))
        return eq.conditions, list(reduced.q), eq
    dyn = Dynamics(sys)
    rates = rates or {}
    free = [q for q in dyn.q if q not in rates]
    conds = []
    for e in steady_residuals(dyn, rates, {q: q for q in free}):
        if e.has(sys.t):
            raise UnsupportedError("steady motions of a non-autonomous system")
        if e != 0:
            conds.append(e)
    return conds, free, Equilibria(dyn)


def cyclic_check(dyn: Dynamics, coords: list[sp.Symbol]) -> None:
    """Refuse a coordinate that is not cyclic (present in L, or acted on by a force)."""
    sys = dyn.sys
    if sys.constraints or sys.velocity_constraints:
        raise UnsupportedError("steady motions at fixed cyclic momenta of a system with "
                               "multiplier constraints (give the motion's `steady:` rates)")
    for c in coords:
        i = sys.q.index(c)
        if not is_zero(sp.diff(dyn.L, c)) or sys.forces[i] != 0:
            raise UnsupportedError(f"steady motion: {c} is not a cyclic coordinate")


@dataclass
class SteadyFamily:
    """Steady motions at `point` (non-cyclic coordinates at rest there) whose cyclic rates
    are fixed by `hold` equations (in the velocities) except one, the `unknown`'s rate x.

    `rates` gives every cyclic rate as a function of x; `conditions` the generalized forces
    on the non-cyclic coordinates as functions of x (all zero at a steady motion)."""

    dyn: Dynamics
    point: dict
    unknown: sp.Symbol  # the coordinate whose rate is x
    x: sp.Symbol
    rates: dict  # cyclic velocity symbol -> expression in x
    conditions: list[sp.Expr]
    state: dict  # the steady state: point, velocities (at rest or rates in x)

    @classmethod
    def build(cls, dyn: Dynamics, point: dict, unknown: sp.Symbol,
              hold: list[sp.Expr]) -> SteadyFamily:
        sys = dyn.sys
        if sys.lagrangian.has(sys.t):
            raise UnsupportedError("steady motions of a non-autonomous system")
        moving = [q for q in sys.q if q not in point]
        if unknown not in moving:
            raise UnsupportedError(f"steady motion: {unknown} is held in `about:`")
        cyclic_check(dyn, moving)
        x = sp.Symbol("x_steady", real=True)
        rate_of = {sys.qd[sys.q.index(unknown)]: x}
        others = [sys.qd[sys.q.index(q)] for q in moving if q != unknown]
        at_rest = {sys.qd[sys.q.index(q)]: sp.S.Zero for q in point}
        eqs = [h.subs(point).subs(at_rest).subs(rate_of) for h in hold]
        if len(eqs) != len(others):
            raise UnsupportedError(f"steady motion: {len(others)} other cyclic rate(s) need as "
                                   f"many `hold:` relations, {len(eqs)} given")
        if others:
            rate_of.update(solve_within(eqs, others, "steady motion: the other cyclic "
                                        "rates from the `hold:` relations", 20))
        state = dict(point)
        state.update(at_rest)
        state.update(rate_of)
        state.update({a: sp.S.Zero for a in sys.qdd})
        conds = []
        for q, e in zip(sys.q, dyn.residuals, strict=True):
            if q in point:
                conds.append(e.subs(state))
        steady = {k: v for k, v in state.items() if k not in sys.qdd}
        return cls(dyn, dict(point), unknown, x, rate_of, conds, steady)

    def residuals_at(self, rate: sp.Expr) -> list[sp.Expr]:
        """The conditions with x = rate (zero iff that rate is a steady motion)."""
        return [c.subs(self.x, rate) for c in self.conditions]

    def polynomials(self, values: dict) -> list[sp.Poly]:
        """The conditions at numeric `values` as polynomials in x (numerators), dropping
        those identically zero; UnsupportedError if one is not polynomial in x."""
        out = []
        for c in self.conditions:
            num = sp.together(c.subs(values)).as_numer_denom()[0]
            num = sp.expand(num)
            if num == 0:
                continue
            try:
                poly = sp.Poly(num, self.x)
            except sp.PolynomialError:
                raise UnsupportedError("steady rates of a condition not polynomial in the "
                                       "rate") from None
            if any(not c.is_number for c in poly.all_coeffs()):
                raise UnsupportedError("steady rates: the condition does not evaluate at the "
                                       "sampled values")
            out.append(poly)
        return out

    def real_rates(self, values: dict) -> list[float]:
        """The real rates x at `values` that make every condition vanish (sorted)."""
        polys = self.polynomials(values)
        if not polys:
            raise UnsupportedError("steady rates: every rate is a steady motion here")
        first = min(polys, key=lambda p: p.degree())
        roots = real_roots(first)
        keep = []
        for r in roots:
            if all(_small(p, r) for p in polys):
                keep.append(r)
        return sorted(keep)


def real_roots(poly: sp.Poly) -> list[float]:
    """Real roots of a numeric polynomial (30-digit arithmetic)."""
    coeffs = [mpmath.mpf(str(sp.re(sp.N(c, DIGITS)))) for c in poly.all_coeffs()]
    while coeffs and coeffs[0] == 0:
        coeffs.pop(0)
    if len(coeffs) <= 1:
        return []
    with mpmath.workdps(DIGITS):
        try:
            roots = mpmath.polyroots(coeffs, maxsteps=200, extraprec=60)
        except mpmath.libmp.NoConvergence:
            raise UnsupportedError("steady rates: the polynomial roots did not converge") \
                from None
        scale = max(abs(r) for r in roots) if roots else 1
        return [float(mpmath.re(r)) for r in roots
                if abs(mpmath.im(r)) <= mpmath.mpf(10) ** (-DIGITS // 2) * max(1, scale)]


def polynomial_roots(expr: sp.Expr, x: sp.Symbol, values: dict) -> list[float]:
    """Real roots in x of expr (an equation's left side minus right side) at `values`."""
    num = sp.expand(sp.together(expr.subs(values)).as_numer_denom()[0])
    if num == 0:
        raise UnsupportedError("the equation holds for every rate")
    if num.free_symbols - {x}:
        raise ValueError("the equation has symbols other than the rate: "
                         + ", ".join(sorted(map(str, num.free_symbols - {x}))))
    try:
        poly = sp.Poly(num, x)
    except sp.PolynomialError:
        raise UnsupportedError("steady rates: the equation is not polynomial in the rate") \
            from None
    return sorted(real_roots(poly))


def _small(poly: sp.Poly, r: float) -> bool:
    coeffs = [complex(sp.N(c, DIGITS)) for c in poly.all_coeffs()]
    deg = len(coeffs) - 1
    val = sum(c * r ** (deg - i) for i, c in enumerate(coeffs))
    scale = sum(abs(c) * abs(r) ** (deg - i) for i, c in enumerate(coeffs))
    return abs(val) <= 1e-9 * max(scale, 1e-300)


def effective_potential(dyn: Dynamics, cyclic: list[sp.Symbol],
                        momenta: list[sp.Symbol]) -> sp.Expr:
    """V_eff(q; p) = [Σ p φ̇ − L] with the other velocities zero and φ̇ from p = ∂L/∂φ̇."""
    sys = dyn.sys
    cyclic_check(dyn, cyclic)
    rates = [sys.qd[sys.q.index(c)] for c in cyclic]
    rest = {v: sp.S.Zero for v in sys.qd if v not in rates}
    L0 = dyn.L.subs(rest)
    eqs = [p - sp.diff(L0, v) for p, v in zip(momenta, rates, strict=True)]
    sol = solve_within(eqs, rates, "effective potential: the cyclic rates from their "
                       "momenta (not unique: a chart singularity?)", 30)
    routh = sum((p * v for p, v in zip(momenta, rates, strict=True)), sp.S.Zero) - L0
    return routh.subs(sol)
