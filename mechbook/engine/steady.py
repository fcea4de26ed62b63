"""Steady motions: cyclic coordinates turning at constant rates, the others at rest.

A steady motion of a system with cyclic coordinates φ (absent from L, no force on them) has
the other coordinates fixed at q* and constant rates φ̇. It exists exactly when the
generalized forces on the other coordinates vanish there:
    E_i(q*, q̇ = (0, φ̇), q̈ = 0) = 0   for every non-cyclic i,
(the cyclic equations hold by themselves: their momenta depend on q and q̇ only). With one
rate left unknown — the others fixed by relations such as ω3 = ψ̇ + φ̇ cos θ — these
conditions are equations in that rate x; `SteadyFamily` returns them, their real roots at
given parameter values (for conditions polynomial in x after clearing denominators), and
whether any exists (the minimum spin of a top).

The effective potential of Routh's reduction, V_eff(q; p) = [Σ p_φ φ̇ − L] at q̇ = 0 with
φ̇ expressed by the momenta p_φ, is here too: the energy that remains for the non-cyclic
coordinates when the cyclic momenta are held (Symon's 'V'(θ) of the top).

Small oscillations and stability about a steady motion are `Analysis.steady_linear`
(Routh's reduction, mechbook.engine.routh); this module is shared with any system that
has cyclic coordinates (chapter 12's steady motions too).
"""

from __future__ import annotations

from dataclasses import dataclass

import mpmath
import sympy as sp

from mechbook.core.numeval import is_zero
from mechbook.core.timeout import Timeout, time_limit
from mechbook.engine.lagrange import Dynamics
from mechbook.errors import UnsupportedError

DIGITS = 30


def cyclic_check(dyn: Dynamics, coords: list[sp.Symbol]) -> None:
    """Refuse a coordinate that is not cyclic (present in L, or acted on by a force)."""
    sys = dyn.sys
    if sys.constraints:
        raise UnsupportedError("steady motions of a system with multiplier constraints")
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
            try:
                with time_limit(20):
                    sol = sp.solve(eqs, others, dict=True)
            except Timeout:
                sol = []
            if len(sol) != 1 or set(sol[0]) != set(others):
                raise UnsupportedError("steady motion: the `hold:` relations do not fix the "
                                       "other cyclic rates uniquely")
            rate_of.update(sol[0])
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
    try:
        with time_limit(30):
            sol = sp.solve(eqs, rates, dict=True)
    except Timeout:
        sol = []
    if len(sol) != 1:
        raise UnsupportedError("effective potential: the cyclic rates are not uniquely "
                               "solvable from their momenta (a chart singularity?)")
    routh = sum((p * v for p, v in zip(momenta, rates, strict=True)), sp.S.Zero) - L0
    return routh.subs(sol[0])
