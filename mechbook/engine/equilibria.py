"""Static equilibria of a system, and the linearization about one (or a steady motion).

The equations of motion E(q, q̇, q̈, t) = 0 at rest (q̇ = q̈ = 0, small parameters off) give
the equilibrium conditions; SymPy's solve finds the closed-form equilibria (within time
limits: a search no part asked for gets a budget) and a root finder the numeric ones.
`linearize` expands E to first order about a point and returns the `LinearSystem`
M·δq̈ + C·δq̇ + K·δq = F(t); a point that is not an equilibrium is refused
(NotEquilibriumError: the answer that named it is wrong).
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
import scipy.optimize
import sympy as sp

from mechbook.core.compile import compile_exprs
from mechbook.core.expansion import EPS, expand_lagrangian
from mechbook.core.numeval import without_absent
from mechbook.core.secalc import derivative, either, same, to_sympy
from mechbook.core.timeout import Timeout, cpu_time, time_limit, try_simplify
from mechbook.engine.constrained import equilibrium_conditions, linearize_on_manifold, residual_at
from mechbook.engine.existence import clip_ranges, inside
from mechbook.engine.flat_roots import FlatRoots, jacobian_scale
from mechbook.engine.lagrange import Dynamics
from mechbook.engine.linear import LinearSystem
from mechbook.engine.residual import is_zero, show_point
from mechbook.errors import NotEquilibriumError, UnsupportedError


class Equilibria:
    """Static equilibria of a system (autonomous equations, q̇ = 0) and linearization."""

    def __init__(self, dyn: Dynamics):
        self.dyn = dyn
        self.sys = dyn.sys
        self._solved: list[dict] | None = None
        self._gave_up_at: float | None = None
        self._jacobians: dict[tuple, list[sp.Matrix]] = {}

    @property
    def solved(self) -> list[dict] | None:
        """The closed-form equilibria if a search for them has ended, else None (nothing
        is searched for here: for what a check derived, engine.derive)."""
        return self._solved

    def steady_jacobians(self, rates: dict) -> list[sp.Matrix]:
        """∂E/∂q̈, ∂E/∂q̇, ∂E/∂q of the equations of motion E (a reduced system's momenta
        put back) with the coordinates turning at `rates` ({q: rate}), the other rates,
        the accelerations and the small parameters zero: the M, C, K of a steady motion as
        functions of the coordinates, taken symbolically once per `rates`."""
        key = tuple(sorted((str(q), sp.srepr(v)) for q, v in rates.items()))
        if key not in self._jacobians:
            dyn = self.dyn
            sub = {v: sp.S(rates.get(q, 0)) for q, v in zip(dyn.q, dyn.qd, strict=True)}
            sub.update({a: sp.S.Zero for a in dyn.qdd})
            sub.update({s: sp.S.Zero for s in dyn.sys.small_params})
            res = [e.xreplace(dyn.sys.held) for e in dyn.residuals]
            self._jacobians[key] = [sp.Matrix([[sp.diff(e, v) for v in vs] for e in res])
                                    .xreplace(sub) for vs in (dyn.qdd, dyn.qd, dyn.q)]
        return self._jacobians[key]

    @cached_property
    def conditions(self) -> list[sp.Expr]:
        """What vanishes at an equilibrium, in the `unknowns`: E_i(q, 0, 0) with small
        parameters switched off; with multiplier constraints, E(q, 0, 0) − A(q)ᵀλ and the
        constraints g(q) (mechbook.engine.constrained)."""
        if self.dyn.constrained:
            return equilibrium_conditions(self)[0]
        return self.rest_residuals()

    @cached_property
    def unknowns(self) -> list[sp.Symbol]:
        """The coordinates, and the constraints' multipliers where there are constraints."""
        return list(self.dyn.q) + (list(self.dyn.multipliers) if self.dyn.constrained else [])

    def rest_residuals(self) -> list[sp.Expr]:
        """E_i(q, 0, 0) with small parameters switched off (no constraint forces)."""
        if "_rest" in self.__dict__:
            return self.__dict__["_rest"]
        zero = {v: sp.S.Zero for v in self.dyn.qd + self.dyn.qdd}
        zero.update({s: sp.S.Zero for s in self.sys.small_params})
        held = self.sys.held  # a reduced system's momenta, put back
        conds = [without_absent(e.xreplace(zero).xreplace(held), [self.sys.t])
                 for e in self.dyn.residuals]
        if any(c.has(self.sys.t) for c in conds):
            raise UnsupportedError("static equilibria of a non-autonomous system")
        free = {s for syms in self.sys.free_driven for s in syms}
        if any(c.free_symbols & free for c in conds):
            raise UnsupportedError("static equilibria with an arbitrary driven coordinate")
        self.__dict__["_rest"] = conds
        return conds

    SIMPLIFY_SECONDS = 5.0  # per condition, before solving
    SOLVE_SECONDS = 10.0

    @property
    def symbolic(self) -> list[dict]:
        """Equilibria SymPy can find in closed form (possibly incomplete for trig equations),
        with the full time limits: what an answer part asks for."""
        return self.within(None)

    def within(self, budget: float | None) -> list[dict]:
        """`symbolic`, but giving up (returning []) once `budget` seconds are spent on
        simplifying and solving: for searches no part asked for (the loose cross-checks).
        A result found once is kept; a search cut short is tried again with more time."""
        if self._solved is not None:
            return self._solved
        if budget is not None and self._gave_up_at is not None and budget <= self._gave_up_at:
            return []
        deadline = None if budget is None else cpu_time() + budget

        def limit(cap: float) -> float:
            return cap if deadline is None else min(cap, deadline - cpu_time())

        conds = []
        for c in self.conditions:  # simplified first: solve finds more this way
            seconds = limit(self.SIMPLIFY_SECONDS)
            if seconds <= 0:
                self._gave_up_at = budget
                return []
            conds.append(try_simplify(c, seconds))
        try:
            seconds = limit(self.SOLVE_SECONDS)
            if seconds <= 0:
                raise Timeout("no time left")
            with time_limit(seconds):
                sols = sp.solve(conds, self.unknowns, dict=True)
        except (Timeout, NotImplementedError):
            if deadline is not None and cpu_time() >= deadline - 1e-3:
                self._gave_up_at = budget  # cut short by the budget: may retry with more
                return []
            self._solved = []
            return []
        q = set(self.dyn.q)
        self._solved = [{k: v for k, v in s.items() if k in q} for s in sols
                        if len(s) == len(self.unknowns)
                        and all(v.is_real is not False for v in s.values())]
        return self._solved

    def numeric(self, values: dict, search: dict | None = None,
                starts: int = 7) -> list[np.ndarray]:
        """Equilibria at `values` by root finding from a grid of starting points (the
        coordinates only; with constraints the multipliers are unknowns too, each start
        taking them by least squares from the force left at rest there)."""
        q = self.dyn.q
        unknowns = self.unknowns
        conds = [c.subs(values) for c in self.conditions]
        F = sp.Matrix(conds)
        J = F.jacobian(unknowns)
        n = len(unknowns)
        f_num, _ = compile_exprs(unknowns, list(F))
        jac, _ = compile_exprs(unknowns, list(J))
        start_lambda = self._multiplier_start(values)

        def j_num(x):
            return jac(x).reshape(n, n)
        ranges = [search.get(v, (-np.pi, np.pi)) if search else (-np.pi, np.pi) for v in q]
        ranges = clip_ranges(self.sys, q, ranges, values)  # only inside the coordinates' domains
        grids = [np.linspace(lo, hi, starts) for lo, hi in ranges]
        found: list[np.ndarray] = []
        mesh = np.array(np.meshgrid(*grids, indexing="ij")).reshape(len(q), -1).T
        if len(mesh) > 2000:
            mesh = mesh[np.random.default_rng(0).choice(len(mesh), 2000, replace=False)]
        starts = [np.concatenate([x0, start_lambda(x0)]) for x0 in mesh]
        flat = FlatRoots(lambda x: np.concatenate([np.asarray(f_num(x), float),
                                                   np.asarray(j_num(x), float).ravel()]), n,
                         jacobian_scale(lambda X: np.array([j_num(x) for x in X]),
                                        np.array(starts)),
                         lambda: (conds, unknowns))
        kept: list[np.ndarray] = []  # whole solutions (multipliers too), for flat_roots
        for x0 in starts:
            with np.errstate(all="ignore"):
                sol = scipy.optimize.root(lambda x: np.asarray(f_num(x), float), x0,
                                          jac=lambda x: np.asarray(j_num(x), float))
                if not (np.all(np.isfinite(sol.x)) and
                        np.max(np.abs(f_num(sol.x))) < 1e-10):
                    continue
            if any(np.allclose(sol.x[: len(q)], f, atol=1e-7) for f in found):
                continue
            full = flat.polished(sol.x)  # a flat root's point moved onto it
            x = full[: len(q)]
            if not inside(self.sys, q, x, values):
                continue
            if any(np.allclose(x, f, atol=1e-7) for f in found):
                continue
            if flat.spurious(full) or any(flat.same(k, full) for k in kept):
                continue  # beside a flat root, not one; or one the arithmetic cannot part
            found.append(x)
            kept.append(full)
        return found

    def _multiplier_start(self, values: dict):
        """x0 ↦ starting multipliers (least squares of Aᵀλ = E at x0); none without
        constraints."""
        if not self.dyn.constrained:
            return lambda x0: np.zeros(0)
        if self.sys.velocity_constraints:
            raise UnsupportedError("numeric equilibria with velocity constraints (their rest "
                                   "points come in families: give the point)")
        q = self.dyn.q
        A = self.dyn.constraint_jacobian.subs(values)
        E = [r.subs(values) for r in self.rest_residuals()]
        a_num, _ = compile_exprs(q, list(A))
        e_num, _ = compile_exprs(q, E)
        m = A.rows

        def start(x0):
            with np.errstate(all="ignore"):
                At = np.asarray(a_num(x0), float).reshape(m, len(q)).T
                lam = np.linalg.lstsq(At, np.asarray(e_num(x0), float), rcond=None)[0]
            return np.where(np.isfinite(lam), lam, 0.0)

        return start

    def quadratic_lagrangian(self, point: dict) -> sp.Expr:
        """L expanded to second order about `point` (see mechbook.expansion)."""
        dyn = self.dyn
        return expand_lagrangian(dyn.L, dyn.q, dyn.qd, point, self.sys.small_params, 2)

    def residual(self, point: dict) -> list[sp.Expr]:
        """What must vanish if `point` is an equilibrium (with constraints: each constraint
        and the force along the constraint manifold)."""
        if self.dyn.constrained:
            return residual_at(self, point)
        return [c.subs(point) for c in self.conditions]

    def _conservative(self) -> bool:
        """L alone decides the motion: no forces, constraints, small parameters or time."""
        sys = self.sys
        return (not self.dyn.constrained and not sys.small_params and not sys.free_driven
                and all(f == 0 for f in sys.forces) and not self.dyn.L.has(sys.t))

    def _linearize_lagrangian(self, point: dict) -> LinearSystem:
        """The linear system from L's second derivatives at (point, q̇ = 0): with
        A = ∂²L/∂q̇∂q̇, B = ∂²L/∂q̇∂q, C = ∂²L/∂q∂q there, Lagrange's equations of the
        quadratic part of L are A·δq̈ + (B − Bᵀ)·δq̇ − C·δq = ∂L/∂q (which must vanish: an
        equilibrium or steady motion). Far cheaper than expanding the equations of motion
        when L is large (Routh's reduced Lagrangian of an unsymmetrical body)."""
        dyn = self.dyn
        n = len(dyn.q)
        at = dict(point)
        at.update({q: at.get(q, sp.S.Zero) for q in dyn.q})
        rest = {v: sp.S.Zero for v in dyn.qd}
        held = self.sys.held  # Routh's held momenta: symbols until now
        names = set(dyn.L.free_symbols).union(*(getattr(v, "free_symbols", set()) for v in
                                                 (*at.values(), *held.values())))

        def build(conv):  # in SymEngine, its entries brought back to SymPy once; or SymPy
            parts = second_derivatives(dyn.L, dyn.q, dyn.qd, at, rest, held, conv)
            return parts if conv is same else [[to_sympy(x, names) for x in p] for p in parts]

        force, A, B, C = either(build)
        bad = [g for g in force if not is_zero(g, self.sys.numeric_values())]
        if bad:
            raise NotEquilibriumError(f"the point {show_point(point)} is not an equilibrium "
                                      f"(or steady motion): a generalized force "
                                      f"{sp.sstr(bad[0])[:120]} "
                                      "is left there")
        simp = (lambda x: try_simplify(x, 5)) if dyn.simplify else (lambda x: x)
        A = sp.Matrix(n, n, [simp(x) for x in A])
        B, C = sp.Matrix(n, n, B), sp.Matrix(n, n, C)
        return LinearSystem(dyn, dict(point), A, (B - B.T).applyfunc(simp),
                            (-C).applyfunc(simp), sp.zeros(n, 1))

    def linearize(self, point: dict, velocity: dict | None = None,
                  given: dict | None = None) -> LinearSystem:
        """First-order expansion of the equations of motion about `point` (q̇ = 0), or, with
        `velocity`, about the uniform motion q*(t) = point + velocity·t (a steady motion
        kept in all its coordinates: δq of a uniformly turning coordinate is its deviation
        from the uniform turn). The coefficients must then be free of t (the motion is a
        symmetry orbit, e.g. a cyclic coordinate or a rotation of the whole system).
        `given` ({parameter: expression}) restricts the parameters to a surface on which
        the point is an equilibrium (an answer's `restrict:`): the zeroth order must vanish
        there; M, C, K and F stay in the original parameters. A system with multiplier
        constraints is linearized on its constraint manifold (mechbook.engine.constrained)."""
        if self.dyn.constrained:
            return linearize_on_manifold(self, point, velocity, given)
        if not velocity and not given and self._conservative():
            return self._linearize_lagrangian(point)
        zeroth, M, C, K, F = self.expand(point, velocity, given)
        bad = [z for z in zeroth if not is_zero(z, self.sys.numeric_values())]
        if bad:
            raise NotEquilibriumError(f"the point {show_point(point)} is not an equilibrium "
                                      f"(or steady motion): a generalized force "
                                      f"{sp.sstr(bad[0])[:120]} "
                                      "is left there")
        return LinearSystem(self.dyn, dict(point), M, C, K, F, dict(velocity or {}))

    def expand(self, point: dict, velocity: dict | None = None, given: dict | None = None
               ) -> tuple[list, sp.Matrix, sp.Matrix, sp.Matrix, sp.Matrix]:
        """The residuals E (without constraint forces) to first order about `point` (and the
        uniform motion at `velocity`): (zeroth order, M, C, K, F), not yet required to be an
        equilibrium."""
        dyn = self.dyn
        velocity = dict(velocity or {})
        t = self.sys.t
        # a point or rate given by a long expression (an orbit parametrized by an answer's
        # symbol) stands in as a plain symbol while differentiating, and is put back at the
        # end: differentiating through it would multiply its size many times over
        holders: dict[sp.Symbol, sp.Expr] = dict(self.sys.held)

        def held(value, tag: str) -> sp.Expr:
            value = sp.S(value)
            if value.is_Atom or sp.count_ops(value) <= 4:
                return value
            for sym, v in holders.items():  # equal rates stay equal (a rigid rotation)
                if v == value:
                    return sym
            sym = sp.Symbol(f"held_{tag}_{len(holders)}", real=True)
            holders[sym] = value
            return sym

        sub = {}
        for q, v in zip(dyn.q, dyn.qd, strict=True):
            sub[q] = (held(point.get(q, 0), q.name) + held(velocity.get(q, 0), v.name) * t
                      + EPS * q)
            sub[v] = held(velocity.get(q, 0), v.name) if q in velocity else sp.S.Zero
            sub[v] += EPS * v
        sub.update({v: EPS * v for v in dyn.qdd})
        sub.update({s: EPS * s for s in self.sys.small_params})
        lin = []
        zeroth = []
        for e in dyn.residuals:
            e_sub = e.xreplace(sub)  # a pure replacement: xreplace, 100x cheaper than subs
            zeroth.append(e_sub.xreplace({EPS: sp.S.Zero}))
            # d/dε by SymEngine (SymPy's where it cannot): SymPy's diff of the substituted
            # residuals was three quarters of this expansion (a rolling body's: 0.1 s each)
            lin.append(derivative(e_sub, EPS).xreplace({EPS: sp.S.Zero}))
        zeroth = [z.xreplace(holders) for z in zeroth]
        if velocity:  # zeroth order must vanish along the whole uniform motion
            zeroth = [z.subs(t, sp.Rational(7, 5)) for z in zeroth] + \
                     [z.subs(t, sp.Rational(-3, 7)) for z in zeroth]
        if given:
            zeroth = [z.subs(given) for z in zeroth]
        n = len(dyn.q)
        raw = {name: sp.Matrix(n, n, lambda i, j, v=v: sp.diff(lin[i], v[j]))
               for name, v in (("M", dyn.qdd), ("C", dyn.qd), ("K", dyn.q))}
        rest = sp.Matrix([lin[i] - sum((raw["M"][i, j] * dyn.qdd[j] + raw["C"][i, j] * dyn.qd[j]
                                        + raw["K"][i, j] * dyn.q[j]) for j in range(n))
                          for i in range(n)])
        t = [self.sys.t]
        state = t + dyn.q + dyn.qd + dyn.qdd  # F depends on t only, once terms cancel
        if dyn.simplify:
            def simp(x, absent=t):
                return try_simplify(without_absent(x, absent), 5)
        else:
            def simp(x, absent=t):
                return without_absent(x, absent)
        M, C, K = (raw[k].applyfunc(simp).xreplace(holders) for k in ("M", "C", "K"))
        F = (-rest).applyfunc(lambda x: simp(sp.expand(x), state)).xreplace(holders)
        bad = set().union(*(x.free_symbols for x in F)) & set(dyn.q + dyn.qd + dyn.qdd)
        if bad:
            raise UnsupportedError("linearization: nonlinear remainder")  # pragma: no cover
        if velocity and any(x.has(self.sys.t) for A in (M, C, K) for x in A):
            raise UnsupportedError("linearization about a uniform motion whose linear "
                                   "equations have time-dependent coefficients")
        return zeroth, M, C, K, F


def second_derivatives(L, q, qd, at: dict, rest: dict, held: dict, conv) -> tuple:
    """(∂L/∂q at the point, A, B, C row by row) of `_linearize_lagrangian`, in the algebra
    `conv` converts to (SymEngine's or SymPy's: both have diff and xreplace). Each second
    derivative from the smallest expression that still holds it: A from L at the point (a
    function of q̇), C and the force from L at rest, B from ∂L/∂q̇ at rest."""
    L = conv(L)
    q, qd = [conv(x) for x in q], [conv(x) for x in qd]
    at, rest, held = ({conv(k): conv(v) for k, v in d.items()} for d in (at, rest, held))
    L_at, L_rest = L.xreplace(at), L.xreplace(rest)
    b = [L.diff(v).xreplace(rest) for v in qd]
    dq = [L_rest.diff(x) for x in q]
    force = [g.xreplace(at).xreplace(held) for g in dq]
    dv = [L_at.diff(v) for v in qd]
    A = [dv[i].diff(v).xreplace(rest).xreplace(held) for i in range(len(q)) for v in qd]
    B = [b[i].diff(x).xreplace(at).xreplace(held) for i in range(len(q)) for x in q]
    C = [dq[i].diff(x).xreplace(at).xreplace(held) for i in range(len(q)) for x in q]
    return force, A, B, C
