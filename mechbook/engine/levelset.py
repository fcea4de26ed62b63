"""Motion on a level set of the first integrals, reduced to one degree of freedom.

When every coordinate but one (c) is cyclic and the system is autonomous and
conservative, the cyclic momenta P and the energy E are fixed by the initial state, and
Routh's reduction leaves one degree of freedom with energy
    E = m(c) ċ²/2 + V_eff(c; P)
(a term of the reduced Lagrangian linear in ċ is a total derivative for one coordinate).
The motion then runs between the turning points, the roots of V_eff(c) = E around the
initial c, with period T = 2∫ √(m/(2(E − V_eff))) dc, and each cyclic coordinate advances
over a period by 2∫ u(c) √(m/(2(E − V_eff))) dc, u the part of its rate free of ċ (the
part proportional to ċ integrates to zero over the back-and-forth). Quadratures are done
by the midpoint rule after c = mid − (half-width)·cos s, which removes the square-root
singularities at the turning points and leaves a smooth periodic integrand (exponential
convergence), in 50-digit arithmetic (or more: `orbit(..., dps=)`): a fast top's nutation
of 1e-12 rad is resolved as well as a slow one's.

The independent measurement of the same quantities by integrating the full equations is
mechbook.numerics.measure.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import mpmath
import sympy as sp

from mechbook.engine.affine import solve_within
from mechbook.engine.lagrange import Dynamics
from mechbook.engine.steady import cyclic_check
from mechbook.errors import UnsupportedError

DPS = 50
MAX_STEP = 0.02  # largest step of the search for a turning point, relative to 1 + |c0|
MAX_STEPS = 5000
ORBITS = 256  # orbits a level set keeps (the oldest dropped first)


KEPT = ("sin", "cos", "tan", "exp", "log", "sqrt", "sinh", "cosh", "tanh")
KEPT_VALUES = 64  # values each kept function remembers before it starts afresh


def kept_functions() -> dict:
    """mpmath's functions of one argument that remember their latest values by (argument,
    precision): a lambdified V_eff calls sin(θ) and cos(θ) a dozen times with the same θ
    (its terms are not collected, so that its arithmetic stays the expression's own), and
    each value is the same number mpmath would compute again."""
    def kept(f):
        memo: dict = {}

        def g(x):
            key = (x, mpmath.mp.prec)
            try:
                return memo[key]
            except (KeyError, TypeError):
                pass
            v = f(x)
            if len(memo) >= KEPT_VALUES:
                memo.clear()
            try:
                memo[key] = v
            except TypeError:  # an argument that cannot be a key
                pass
            return v

        return g

    return {name: kept(getattr(mpmath, name)) for name in KEPT}


class LevelSet:
    """The reduction of a system to its one non-cyclic coordinate `coordinate`."""

    def __init__(self, dyn: Dynamics, coordinate: sp.Symbol):
        sys = dyn.sys
        if sys.lagrangian.has(sys.t) or any(f != 0 for f in sys.forces):
            raise UnsupportedError("a level set of the energy needs an autonomous, "
                                   "conservative system")
        self.dyn, self.c = dyn, coordinate
        self.cyclic = [q for q in sys.q if q != coordinate]
        cyclic_check(dyn, self.cyclic)
        self.cdot = sys.qd[sys.q.index(coordinate)]
        self.rates = [sys.qd[sys.q.index(q)] for q in self.cyclic]
        self.P = [sp.Symbol(f"P_{q}", real=True) for q in self.cyclic]
        self.params = sorted(sys.problem.values(), key=str)
        self._orbits: dict = {}  # (state, values, dps) → Orbit, the ORBITS latest


    @cached_property
    def reduced(self) -> tuple[sp.Expr, sp.Expr, list[sp.Expr]]:
        """(m(c), V_eff(c; P), the cyclic rates' ċ-free parts u(c; P))."""
        L = self.dyn.L
        eqs = [p - sp.diff(L, v) for p, v in zip(self.P, self.rates, strict=True)]
        rates = solve_within(eqs, self.rates, "level set: the cyclic rates from their "
                             "momenta", 30) if eqs else {}
        R = (L - sum((p * v for p, v in zip(self.P, self.rates, strict=True)), sp.S.Zero)
             ).subs(rates)
        mass = sp.diff(R, self.cdot, 2)
        if mass.has(self.cdot):
            raise UnsupportedError("level set: the reduced Lagrangian is not quadratic in the "
                                   "velocity")
        V = -R.subs(self.cdot, 0)
        u = [rates[v].subs(self.cdot, 0) for v in self.rates]
        return mass, V, u

    @cached_property
    def numeric_functions(self):
        mass, V, u = self.reduced
        args = [self.c, *self.P, *self.params]
        modules = [kept_functions(), "mpmath"]
        return (sp.lambdify(args, mass, modules=modules),
                sp.lambdify(args, V, modules=modules),
                [sp.lambdify(args, x, modules=modules) for x in u])

    def orbit(self, state: dict, values: dict, dps: int = DPS) -> Orbit:
        """The orbit through `state` ({q: value, q̇: value}) at parameter `values`, computed
        in `dps`-digit arithmetic (a second, higher precision measures the first's error).
        Kept: the parts of one start (its turning points, excursion, frequency, mean rate)
        walk through the same points, and an orbit keeps what it computed (turning points,
        period)."""
        key = (frozenset(state.items()), frozenset(values.items()), dps)
        hit = self._orbits.get(key)
        if hit is None:
            hit = self._orbits[key] = self._new_orbit(state, values, dps)
            if len(self._orbits) > ORBITS:
                del self._orbits[next(iter(self._orbits))]
        return hit

    @cached_property
    def _momenta(self) -> list[sp.Expr]:
        return [sp.diff(self.dyn.L, v) for v in self.rates]

    def _new_orbit(self, state: dict, values: dict, dps: int) -> Orbit:
        dyn = self.dyn
        with mpmath.workdps(dps):
            pt = {k: mpmath.mpf(str(sp.N(v, dps))) for k, v in values.items()}
            full = {**{k: sp.Float(str(v), dps) for k, v in pt.items()},
                    **{k: sp.Float(str(sp.N(v, dps)), dps) for k, v in state.items()}}
            P = [sp.N(p.xreplace(full), dps) for p in self._momenta]
            E = sp.N(dyn.energy_function.xreplace(full), dps)
            if any(not x.is_number for x in [*P, E]):
                raise UnsupportedError("level set: the initial state leaves something unknown")
            params = [pt[p] for p in self.params]
            return Orbit(self, [mpmath.mpf(str(x)) for x in P], mpmath.mpf(str(E)),
                         mpmath.mpf(str(sp.N(full[self.c], dps))),
                         mpmath.mpf(str(sp.N(full.get(self.cdot, 0), dps))), params, dps)

    def orbit_at(self, energy, momenta: list, inside, values: dict, dps: int = DPS) -> Orbit:
        """The orbit of energy `energy` and cyclic momenta `momenta` (in `self.cyclic`'s
        order) that passes through c = `inside` (a point of the allowed region, not a
        turning point): an action or a frequency asked at a given energy rather than from a
        start. UnsupportedError if the motion cannot reach `inside` at that energy. Kept as
        `orbit`'s are, by the orbit's own numbers (the parts of one problem that ask at the
        same energy, momenta and parameters: an action, H(J) and its frequencies)."""
        with mpmath.workdps(dps):
            def mp(v):
                return mpmath.mpf(str(sp.N(v, dps)))

            params = [mp(values[p]) for p in self.params]
            P, E, c0 = [mp(x) for x in momenta], mp(energy), mp(inside)
            key = ("at", tuple(P), E, c0, tuple(params), dps)
            hit = self._orbits.get(key)
            if hit is not None:
                return hit
            orbit = Orbit(self, P, E, c0, mpmath.mpf(1), params, dps)  # ċ0 ≠ 0: both ways
            if not orbit.kinetic(orbit.c0) > 0:
                raise UnsupportedError(f"level set: at this energy the motion does not reach "
                                       f"{self.c} = {mpmath.nstr(orbit.c0, 8)}")
            self._orbits[key] = orbit
            if len(self._orbits) > ORBITS:
                del self._orbits[next(iter(self._orbits))]
            return orbit


@dataclass
class Orbit:
    level: LevelSet
    P: list
    E: object  # mpf
    c0: object
    cdot0: object
    params: list
    dps: int = DPS  # the working precision: turning points to 10^(5 - dps), quadratures
    # until two agree to 10^(30 - dps)
    # the quadratures' nodes (N, j): c, E − V_eff, √(m/(2(E − V_eff))), sin s: the period,
    # the action and an advance of one orbit take the same midpoints
    _nodes: dict = field(default_factory=dict, repr=False, compare=False)

    def _args(self, c):
        return [c, *self.P, *self.params]

    def kinetic(self, c):
        """E − V_eff(c): m ċ²/2 on the orbit (negative where the motion cannot go)."""
        _, V, _ = self.level.numeric_functions
        try:
            return self.E - V(*self._args(c))
        except (ZeroDivisionError, ValueError):
            return mpmath.mpf(-1)

    def _edge(self, direction: int):
        """The turning point reached moving from c0 in `direction`: steps that double
        from 1e-35 (a fast top's orbit is 1e-12 wide) up to MAX_STEP*(1 + |c0|), then
        steps of that size (so a forbidden region is not stepped over), then bisection."""
        with mpmath.workdps(self.dps):
            h = mpmath.mpf(10) ** (-(self.dps - 15))
            cap = MAX_STEP * (1 + abs(self.c0))
            inside, step = self.c0, h
            for _ in range(MAX_STEPS):
                c = inside + direction * step
                k = self.kinetic(c)
                if not mpmath.isfinite(k) or k < 0:
                    break
                inside = c
                step = min(2 * step, cap)
            else:
                far = self._runaway(inside, direction)
                if far is None:
                    return direction * mpmath.inf
                inside, c, k = far
            return self._refine(inside, c, self.kinetic(inside), k)

    def _runaway(self, inside, direction: int):
        """After the search's steps: None if the coordinate runs away to infinity — E − V_eff
        stays positive at points 10^3 to 10^60 times farther out (by factors of 10) and
        V_eff settles to a limit there (its last values agree to 1e-20 of E): an unbound
        orbit, whose turning point on this side is at infinity; else (inside, outside,
        E − V_eff there), the bracket of a turning point farther out. UnsupportedError
        where neither is seen (a coordinate that goes round, a potential without a limit)."""
        span = 1 + abs(self.c0)
        values = []
        for k in range(3, 61):
            c = self.c0 + direction * span * mpmath.mpf(10) ** k
            e = self.kinetic(c)
            if not (mpmath.isfinite(e) and e > 0):
                return inside, c, e
            inside = c
            values.append(self.E - e)
        size = abs(self.E) + abs(values[-1])
        if all(abs(v - values[-1]) <= size * mpmath.mpf(10) ** -20 for v in values[-5:]):
            return None
        raise UnsupportedError("level set: no turning point (the coordinate goes round, or "
                               "runs away without its potential settling to a limit)")

    def _refine(self, inside, outside, k_in, k_out):
        """The turning point between `inside` (E − V ≥ 0) and `outside` (E − V < 0, or no
        value): the Illinois method (regula falsi that halves a stale end's value, so both
        ends close in superlinearly) where E − V has a finite value at both ends, bisection
        where it has none (V_eff singular) or where the bracket did not halve in three
        steps; ~15 evaluations instead of bisection's ~170 to the same width."""
        tol = mpmath.mpf(10) ** (-(self.dps - 5))
        width, stale_side, stale = abs(outside - inside), 0, 0
        for _ in range(self.dps * 4):
            finite = mpmath.isfinite(k_out) and mpmath.isfinite(k_in) and k_in != k_out
            if finite and stale < 3:
                mid = inside + (outside - inside) * k_in / (k_in - k_out)
                if not (min(inside, outside) < mid < max(inside, outside)):
                    mid = (inside + outside) / 2
            else:
                mid = (inside + outside) / 2
            k = self.kinetic(mid)
            if mpmath.isfinite(k) and k >= 0:
                inside, k_in = mid, k
                if stale_side == +1:
                    k_out /= 2  # Illinois: the outside end has stayed: halve its value
                stale_side = +1
            else:
                outside, k_out = mid, k
                if stale_side == -1:
                    k_in /= 2
                stale_side = -1
            now = abs(outside - inside)
            if now <= abs(mid) * tol:
                break
            stale = 0 if now <= width / 2 else stale + 1
            if stale == 0:
                width = now
        return (inside + outside) / 2

    @cached_property
    def turning_points(self) -> tuple:
        """(c_min, c_max): with ċ0 = 0 one of them is c0 itself."""
        with mpmath.workdps(self.dps):
            if self.cdot0 == 0:
                k_plus = self.kinetic(self.c0 + mpmath.mpf(10) ** (-(self.dps - 15)))
                if mpmath.isfinite(k_plus) and k_plus > 0:
                    return self.c0, self._edge(+1)
                return self._edge(-1), self.c0
            return self._edge(-1), self._edge(+1)

    def _quad(self, weight) -> object:
        """2 ∫ weight(c, E − V(c)) √(m/(2(E − V))) dc between the turning points.

        With c = mid − half·cos s the integrand becomes weight·√(m/(2r(c))), r = (E − V)/
        ((c − lo)(hi − c)): smooth, even and 2π-periodic in s, so the midpoint rule on
        [0, π] converges exponentially; N is doubled until two results agree to
        10^(30 − dps), 1e-20 at 50 digits (E − V loses digits near the turning points of a
        very small orbit: 50 digits leave at least 20 there). What is left of the working
        precision is measured, where it matters, by computing the orbit at a second, higher
        one (mechbook.verify.quantities.trajectory). The nodes' values are kept on the
        orbit: its period, action and advances (their N the same at each doubling) evaluate
        E − V_eff and m once a node, the action's weight 2(E − V) is the node's own."""
        mass, _, _ = self.level.numeric_functions
        lo, hi = self.turning_points
        if not (mpmath.isfinite(lo) and mpmath.isfinite(hi)):
            raise UnsupportedError("level set: the orbit is unbound (the coordinate runs away "
                                   "to infinity): it has no period")
        with mpmath.workdps(self.dps):  # mid, half at full precision: c − lo tiny near s = 0
            mid, half = (lo + hi) / 2, (hi - lo) / 2

            nodes_seen = self._nodes

            def f(n, j):
                key = (n, j)
                hit = nodes_seen.get(key)
                if hit is None:
                    s = mpmath.pi * (j + mpmath.mpf(1) / 2) / n
                    c = mid - half * mpmath.cos(s)
                    k = self.kinetic(c)
                    if k <= 0:
                        raise UnsupportedError("level set: the motion leaves the allowed "
                                               "region between its turning points")
                    hit = nodes_seen[key] = (c, k, mpmath.sqrt(mass(*self._args(c)) / (2 * k)),
                                             mpmath.sin(s))
                c, k, root, sine = hit
                return weight(c, k) * root * half * sine

            total, n, previous = mpmath.mpf(0), 8, None
            nodes = [f(n, j) for j in range(n)]
            while True:
                total = mpmath.fsum(nodes) * mpmath.pi / n
                if previous is not None and abs(total - previous) <= \
                        mpmath.mpf(10) ** (30 - self.dps) * abs(total):
                    return 2 * total
                if n >= 4096:
                    raise UnsupportedError("level set: the period quadrature did not converge")
                previous = total
                # the midpoints of 3n cells reuse none of the n; simply recompute at 2n
                n *= 2
                nodes = [f(n, j) for j in range(n)]

    @cached_property
    def period(self):
        return self._quad(lambda c, k: mpmath.mpf(1))

    def time_to(self, target):
        """The time the motion takes from c0 to c = `target`, or None where it does not get
        there directly (the target lies behind the start or beyond the turning point
        ahead). ∫ √(m/(2(E − V_eff))) |dc| by tanh-sinh quadrature, which absorbs the
        inverse square root at a turning point c0 (a start from rest)."""
        mass, _, _ = self.level.numeric_functions
        lo, hi = self.turning_points
        with mpmath.workdps(self.dps):
            target = mpmath.mpf(target)
            ahead = hi if self.cdot0 > 0 or (self.cdot0 == 0 and self.c0 == lo) else lo
            if not min(self.c0, ahead) < target < max(self.c0, ahead) and target != self.c0:
                return None

            def f(c):
                k = self.kinetic(c)
                if k <= 0:
                    raise UnsupportedError("level set: the motion leaves the allowed region "
                                           "before the target")
                return mpmath.sqrt(mass(*self._args(c)) / (2 * k))

            value, err = mpmath.quad(f, sorted([self.c0, target]), error=True)
            if not err <= mpmath.mpf(10) ** (30 - self.dps) * abs(value):
                raise UnsupportedError("level set: the time quadrature did not converge")
            return value

    @cached_property
    def action(self):
        """J = (1/2π)∮ p dc over one libration (the 1/2π convention: J = E/ω for an
        oscillator). p = m·ċ plus a part of the reduced Lagrangian linear in ċ, a function
        of c alone whose ∮ over the back-and-forth vanishes; m·ċ² = 2(E − V_eff), so
        J = (1/2π)·2∫ 2(E − V_eff)·√(m/(2(E − V_eff))) dc, the period's quadrature with the
        weight 2(E − V_eff) (smooth after the same substitution)."""
        with mpmath.workdps(self.dps):
            return self._quad(lambda c, k: 2 * k) / (2 * mpmath.pi)

    def advance(self, coordinate: sp.Symbol):
        """How far a cyclic coordinate advances over one period."""
        i = self.level.cyclic.index(coordinate)
        u = self.level.numeric_functions[2][i]
        return self._quad(lambda c, k: u(*self._args(c)))
