"""Whether a configuration can be reached on a level set of the first integrals.

With the energy function h and some cyclic momenta conserved, a motion can pass through a
configuration q* exactly when some velocity there has those momenta and that energy. At q*
the energy function is quadratic in the velocities, h = ½ q̇ᵀAq̇ + bᵀq̇ + c (A positive
definite), the momenta are linear in them, p = P q̇ + p0, and holonomic constraints allow
only J q̇ + ∂f/∂t = 0. Over that affine set of velocities h takes every value from its
least one up, so q* is reachable exactly when h_min ≤ E — the inequality "effective
potential ≤ energy" of Routh's reduction, found without reducing (constraints and all) by
one linear solve of the minimization's KKT system, in mpmath.
"""

from __future__ import annotations

from functools import cached_property

import mpmath
import sympy as sp

from mechbook.core.numeval import evaluate_mp
from mechbook.engine.lagrange import Dynamics
from mechbook.errors import UnsupportedError


class Access:
    """The least energy at a configuration with some momenta held (see module docstring)."""

    def __init__(self, dyn: Dynamics, momenta: list[sp.Symbol]):
        self.dyn = dyn
        if not dyn.energy_conserved:
            raise UnsupportedError("accessibility from the first integrals: the energy "
                                   "function is not conserved")
        for q in momenta:
            if q not in dyn.cyclic:
                raise UnsupportedError(f"accessibility: the momentum of {q} is not conserved "
                                       f"({q} is not cyclic)")
        self.momenta = list(momenta)

    @cached_property
    def _pieces(self):
        """A, b, c of h, the rows of P and p0 for the held momenta, J and ∂f/∂t."""
        dyn, sys = self.dyn, self.dyn.sys
        qd = list(dyn.qd)
        zero = {v: 0 for v in qd}
        h = sp.expand(dyn.energy_function)
        A = [[sp.diff(h, a, b) for b in qd] for a in qd]
        b = [sp.diff(h, a).subs(zero) for a in qd]
        c = h.subs(zero)
        P = []
        for q in self.momenta:
            p = dyn.momenta[dyn.q.index(q)]
            P.append(([sp.diff(p, a) for a in qd], p.subs(zero)))
        J = [([sp.diff(f, q) for q in dyn.q], sp.diff(f, sys.t)) for _, f in sys.constraints]
        J += [([sp.diff(k, v) for v in qd], k.subs(zero))  # A(q, t)·q̇ + b = 0 likewise
              for _, k in sys.velocity_constraints]
        for expr in [c, *b, *(x for row in A for x in row)]:
            if expr.has(*qd):
                raise UnsupportedError("accessibility: the energy function is not quadratic "
                                       "in the velocities")
        return A, b, c, P, J

    def least_energy(self, config: dict, held: dict, values: dict, dps: int = 40):
        """min h over the velocities at `config` ({q: value}) with the momenta `held`
        ({q: value}) and the constraints' velocities; mpmath at `dps` digits."""
        A, b, c, P, J = self._pieces
        n = len(self.dyn.q)
        with mpmath.workdps(dps):
            env = {**values, **{k: sp.Float(v, dps) if not isinstance(v, sp.Float) else v
                                for k, v in config.items()}}

            def num(e):
                v = evaluate_mp(sp.S(e), env, dps)
                if abs(mpmath.im(v)) > mpmath.mpf(10) ** (-dps // 2) * max(1, abs(v)):
                    raise ValueError("a value is not real")
                return mpmath.re(v)

            rows = [([num(x) for x in grad], -num(p0) + num(held[q]))
                    for q, (grad, p0) in zip(self.momenta, P, strict=True)]
            rows += [([num(x) for x in grad], -num(ft)) for grad, ft in J]
            m = len(rows)
            K = mpmath.zeros(n + m, n + m)
            rhs = mpmath.zeros(n + m, 1)
            for i in range(n):
                for j in range(n):
                    K[i, j] = num(A[i][j])
                rhs[i] = -num(b[i])
            for k, (grad, d) in enumerate(rows):
                for j in range(n):
                    K[n + k, j] = K[j, n + k] = grad[j]
                rhs[n + k] = d
            try:
                sol = mpmath.lu_solve(K, rhs)
            except ZeroDivisionError:
                raise UnsupportedError("accessibility: the held momenta and constraints do "
                                       "not fix a unique least-energy velocity") from None
            v = [sol[i] for i in range(n)]
            quad = sum(K[i, j] * v[i] * v[j] for i in range(n) for j in range(n)) / 2
            return quad + sum(num(b[i]) * v[i] for i in range(n)) + num(c)

    def on_constraints(self, config: dict, values: dict, dps: int = 40) -> float:
        """The largest |f(q*)| of the holonomic constraints (0 without any)."""
        worst = 0.0
        env = {**values, **config}
        for _, f in self.dyn.sys.constraints:
            worst = max(worst, float(abs(evaluate_mp(f, env, dps))))
        return worst
