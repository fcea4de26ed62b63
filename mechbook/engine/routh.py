"""Routh's reduction: small oscillations about a steady motion.

A steady motion turns cyclic coordinates φ at constant rates while the others stay put.
Holding the conserved momenta p_φ = ∂L/∂φ̇ fixed, the remaining coordinates obey Lagrange's
equations with L' = L − Σ p_φ φ̇ (minus Routh's function), φ̇ eliminated through p_φ. The
steady motion is an equilibrium of L', and its small oscillations are those of L' — not of
the original potential, whose "equilibria" would ignore the centrifugal terms.
"""

from __future__ import annotations

import sympy as sp

from mechbook.core.expansion import trig_canonical
from mechbook.core.numeval import is_zero
from mechbook.core.rational import TooLarge, cancel
from mechbook.core.timeout import Timeout, time_limit
from mechbook.engine.affine import solve_within
from mechbook.errors import UnsupportedError
from mechbook.model.protocol import SystemLike
from mechbook.model.system import System


class ReducedSystem(SystemLike):
    """The system left after fixing the momenta of some cyclic coordinates.

    It keeps the contract of a system (mechbook.model.protocol.SystemLike): `reduced` is
    True, `full` the system it came from, `held_momenta` and `held` the fixed momenta.
    """

    def __init__(self, base: System, rates: dict[sp.Symbol, sp.Expr], point: dict,
                 simplify: bool = False, momenta: dict[sp.Symbol, sp.Expr] | None = None):
        """`rates` names the cyclic coordinates and their steady rates at `point`, which
        fix the momenta; or `momenta` gives the momenta directly (then only the keys of
        `rates` are used: steady motions at a fixed momentum, wherever they are)."""
        momenta_given = momenta
        self.base = base
        self.problem = base.problem
        self.name = base.name
        self.t = base.t
        self.small_params = base.small_params
        self.free_driven = base.free_driven
        self.constraints = []
        self.velocity_constraints = []
        self.spec = base.spec
        # the remaining coordinates' declared domains are not checked in a reduced system
        # (its equilibria are searched everywhere, as they always were)
        self.domains = {}
        cyc = list(rates)
        idx = [base.q.index(c) for c in cyc]
        for i, c in zip(idx, cyc, strict=True):
            if not is_zero(sp.diff(base.lagrangian, c)) or base.forces[i] != 0:
                raise UnsupportedError(f"steady motion: {c} is not a cyclic coordinate")
        if base.constraints or base.velocity_constraints:
            raise UnsupportedError("Routh's reduction of a system with multiplier constraints "
                                   "(a steady motion is then linearized in full: "
                                   "`reduce: false`)")
        keep = [i for i in range(len(base.q)) if i not in idx]
        self.q = [base.q[i] for i in keep]
        self.qd = [base.qd[i] for i in keep]
        self.qdd = [base.qdd[i] for i in keep]
        self.coord_names = [base.coord_names[i] for i in keep]
        self.forces = [base.forces[i] for i in keep]
        self.names = base.names
        L = trig_canonical(base.lagrangian, base.qd)  # exact; keeps the reduction small
        cyc_rates = [base.qd[i] for i in idx]
        momenta = [sp.diff(L, v) for v in cyc_rates]
        # the momenta's values at the steady motion: rates given, others at rest at `point`
        at_steady = {v: 0 for v in self.qd}
        at_steady.update(point)
        at_steady.update({base.qd[i]: rates[c] for i, c in zip(idx, cyc, strict=True)})
        simp = sp.simplify if simplify else (lambda e: e)  # for a reader only
        if momenta_given is not None:
            p_values = [sp.S(momenta_given[c]) for c in cyc]
        else:
            p_values = [simp(p.subs(at_steady)) for p in momenta]
        # the held momenta stay symbols P until the linear system is formed: their values
        # (large expressions for a rate given as a root of a quadratic, or the steady
        # motion's point and rate substituted) are put into the small matrices M, C, K and
        # the equilibrium conditions, not into L' and its derivatives (Equilibria puts
        # them back through `held`)
        symbols = [sp.Symbol(f"P_held_{c}", real=True) for c in cyc]
        rate_of = _solve_rates(momenta, symbols, cyc_rates, point, base.numeric_values())
        rate_of = {v: _smaller(e, _cancel(e)) for v, e in rate_of.items()}
        routh = sum((P * v for P, v in zip(symbols, cyc_rates, strict=True)), sp.S.Zero)
        reduced = (L - routh).subs(rate_of)
        self.lagrangian = simp(_smaller(reduced, _cancel(reduced)))
        self._held: dict[sp.Symbol, sp.Expr] = dict(zip(symbols, p_values, strict=True))
        self._held_momenta = dict(zip(cyc, p_values, strict=True))

    @property
    def reduced(self) -> bool:
        return True

    @property
    def full(self) -> System:
        return self.base

    @property
    def held_momenta(self) -> dict[sp.Symbol, sp.Expr]:
        """{cyclic coordinate taken out: its fixed momentum}."""
        return self._held_momenta

    @property
    def held(self) -> dict[sp.Symbol, sp.Expr]:
        """{P_held_<coordinate>: the momentum's value}: the held momenta stay symbols in
        the reduced Lagrangian until the linear system is formed."""
        return self._held

    def dt(self, expr):
        out = sp.diff(expr, self.t)
        for q, qd, qdd in zip(self.q, self.qd, self.qdd, strict=True):
            out += sp.diff(expr, q) * qd + sp.diff(expr, qd) * qdd
        return out

    def numeric_values(self) -> dict:
        return self.problem.values()


def _solve_rates(momenta: list, values: list, rates: list, point: dict,
                 numeric: dict) -> dict:
    """The cyclic rates as functions of the state from p = p_values. Momenta linear in the
    rates (L quadratic in the velocities) are solved as a linear system, without
    sp.solve's search; a Jacobian that is singular at the steady point is a chart
    singularity (z-x-z Euler angles at theta = 0) and is said so."""
    J = sp.Matrix([[sp.diff(p, v) for v in rates] for p in momenta])
    if not any(e.has(*rates) for e in J):
        at = J.subs(point).subs({k: v for k, v in numeric.items()})
        try:
            singular = abs(complex(sp.N(at.det()))) < 1e-12 * max(
                1.0, max(abs(complex(sp.N(x))) for x in at) ** len(rates))
        except (TypeError, ValueError):
            singular = False
        if singular:
            raise UnsupportedError("steady motion: the cyclic rates are not determined by "
                                   "their momenta at this point (a singular point of the "
                                   "coordinates, such as z-x-z Euler angles at theta = 0: "
                                   "use a chart regular there, e.g. `rotation:` x-y-z)")
        rest = [p.subs({v: 0 for v in rates}) for p in momenta]  # p = J·rates + rest
        sol = J.LUsolve(sp.Matrix([pv - r for pv, r in zip(values, rest, strict=True)]))
        return dict(zip(rates, sol, strict=True))
    return solve_within([p - pv for p, pv in zip(momenta, values, strict=True)], rates,
                        "steady motion: the cyclic rates from their momenta", 30)


CANCEL_GROWTH = 8.0  # an expansion this many times the expression's size is not cancelled


def _cancel(expr: sp.Expr, seconds: float = 5.0) -> sp.Expr:
    """expr as one rational function (common denominator, common factors cancelled): exact
    polynomial arithmetic, not simplify, and it keeps Routh's function small for the
    differentiations that follow; given up (expr unchanged) after `seconds`, or where the
    expanded numerator and denominator are CANCEL_GROWTH times the expression's size (the
    cancelled form came out larger than the expression on every such case measured, a
    steady top's Routhian: 1247 terms, 0.9 s, 284 -> 403 operations)."""
    try:
        with time_limit(seconds):
            return cancel(expr, CANCEL_GROWTH)  # SymPy's cancel, expanded by SymEngine
    except (Timeout, TooLarge, sp.PolynomialError):
        return expr


def _smaller(a: sp.Expr, b: sp.Expr) -> sp.Expr:
    """The one of two equal expressions with fewer operations."""
    return b if sp.count_ops(b) < sp.count_ops(a) else a
