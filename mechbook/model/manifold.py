"""The states a constrained system can be in, and how many freedoms it has there.

A system with holonomic constraints g(q, t) = 0 and velocity constraints (differentiated
holonomic ones ġ, rolling, a skate's blade: c = A(q, t)·q̇ + b(q, t) = 0) moves on the set
of states where all of them hold. A claim about its motion — a first integral, an equation
of motion, a constraint force — is a claim about those states only: the solved
accelerations hold there and nowhere else, so a state drawn at random off it (f ≠ 0,
ḟ ≠ 0) contradicts a true answer. `StateManifold.project` moves a state onto the manifold
to the working precision: the coordinates by Gauss–Newton steps of least norm
(q ← q − Gᵀ(GGᵀ)⁻¹g, quadratically convergent from a nearby start), then the velocities by
the orthogonal projection onto A·q̇ + b = 0 (linear: one exact step). Both at 40 digits,
kept to 30: the residuals of a projected state are below 1e-28 of their scale.

Degrees of freedom (`freedoms`): n coordinates less the rank of the holonomic constraints'
Jacobian G are the configuration's freedoms; less, further, the rank the velocity
constraints add ([G; A_v]) are the velocity's freedoms — the independent virtual
displacements, what "degrees of freedom" means for a rolling body (Goldstein §1.3). Ranks
are taken at states on the manifold, in 40-digit arithmetic.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import mpmath
import sympy as sp

from mechbook.core.numeval import NotNumeric, evaluate, evaluate_mp, program
from mechbook.model.rolling import relative_velocity

DIGITS = 30  # the checks' working precision: a projected state is kept to it
WORK = 40  # digits of the iteration
ITERATIONS = 30
RANK_TOL = 30  # a singular value below 10^-RANK_TOL of the largest is zero at WORK digits

_FAULTS = (NotNumeric, ZeroDivisionError, ValueError, TypeError, OverflowError)


@dataclass(frozen=True)
class Freedoms:
    """The freedoms of a constrained system at a state: of its configuration (coordinates
    less independent holonomic constraints) and of its velocity (less, further, independent
    velocity constraints)."""

    configuration: int
    velocity: int


class StateManifold:
    """Where the states of `system` may be: its constraints, their Jacobians, projection."""

    def __init__(self, system):
        self.system = system
        self.q, self.qd, self.t = list(system.q), list(system.qd), system.t
        self.position = [g for _, g in system.constraints]
        self.position_names = [name for name, _ in system.constraints]
        self.velocity = [c for _, c in system.velocity_constraints]
        self.velocity_names = [name for name, _ in system.velocity_constraints]

    @property
    def empty(self) -> bool:
        return not (self.position or self.velocity)

    @cached_property
    def moving(self) -> bool:
        """Whether a constraint depends on t: a state is then a state at a time."""
        return any(c.has(self.t) for c in self.position + self.velocity)

    @cached_property
    def state(self) -> frozenset:
        """The symbols a state gives values to: coordinates and velocities."""
        return frozenset(self.q + self.qd)

    @cached_property
    def _jacobian(self) -> list[list[sp.Expr]]:
        return [[sp.diff(g, q) for q in self.q] for g in self.position]

    @cached_property
    def _rows(self) -> tuple[list[list[sp.Expr]], list[sp.Expr]]:
        """(A, b) of every velocity-level constraint c = A·q̇ + b: ġ, then the velocity
        constraints."""
        rows = [self.system.dt(g) for g in self.position] + list(self.velocity)
        rest = {v: sp.S.Zero for v in self.qd}
        return ([[sp.diff(c, v) for v in self.qd] for c in rows],
                [c.xreplace(rest) for c in rows])

    # ---- projection --------------------------------------------------------------------
    def project(self, point: dict, free: set | None = None,
                stated: float = 0.0) -> dict | None:
        """`point` (parameters, t if it has one, and a drawn state) with its coordinates
        and velocities moved onto the manifold (30-digit Floats; those it lacks start at
        0.5), or None where the iteration does not converge or leaves a coordinate's
        domain (the caller draws again). `free` (default: all) names the coordinates and
        velocities that may move: the others are a state someone stated, to the relative
        precision `stated` (a double's rounding leaves 1e-16: what cannot move is on the
        manifold when its residual is within that)."""
        env = {k: _mpf(v) for k, v in point.items()}
        env.setdefault(self.t, mpmath.mpf(0))
        free = self.state if free is None else frozenset(free)
        with mpmath.workdps(WORK):
            for x in self.q + self.qd:
                if x not in env:
                    env[x] = mpmath.mpf(0.5)
            try:
                if self.position and not self._settle_coordinates(env, free, stated):
                    return None
                if not self._inside(env):
                    return None
                if not self._settle_velocities(env, free, stated):
                    return None
            except _FAULTS:
                return None
        out = dict(point)
        for x in self.q + self.qd:
            out[x] = sp.Float(mpmath.nstr(env[x], DIGITS + 5), DIGITS)
        return out

    def settle(self, values: dict, q0, qd0, t0: float = 0.0,
               free: set | None = None) -> tuple[list[float], list[float]] | None:
        """(q0, q̇0) as floats, moved onto the manifold (only the `free` entries), for a
        simulation's start; None where that fails."""
        point = dict(values)
        point[self.t] = t0
        point.update({q: float(x) for q, x in zip(self.q, q0, strict=True)})
        point.update({v: float(x) for v, x in zip(self.qd, qd0, strict=True)})
        out = self.project(point, free, stated=1e-12)  # floats: stated to double precision
        if out is None:
            return None
        return [float(out[q]) for q in self.q], [float(out[v]) for v in self.qd]

    def _settle_coordinates(self, env: dict, free: frozenset, stated: float) -> bool:
        cols = [j for j, q in enumerate(self.q) if q in free]
        first = None
        for _ in range(ITERATIONS):
            g, scale = self._values(self.position, env)
            worst = max(abs(x) / s for x, s in zip(g, scale, strict=True))
            if worst < mpmath.mpf(10) ** (-DIGITS - 2):
                return True
            if not cols:  # nothing may move: on the manifold to the stated precision?
                return worst <= stated
            first = worst if first is None else first
            if worst > 1e6 * first:
                return False  # diverging: no configuration near this start
            G = _columns(self._matrix(self._jacobian, env), cols)
            step = _least_norm(G, mpmath.matrix(g))
            if not all(mpmath.isfinite(x) for x in step):
                return False
            for k, j in enumerate(cols):
                env[self.q[j]] -= step[k]
        return False

    def _settle_velocities(self, env: dict, free: frozenset, stated: float = 0.0) -> bool:
        """The velocities moved (the free ones, least norm) to A·q̇ + b = 0: one exact step;
        False where the free ones cannot make it hold."""
        A_expr, b_expr = self._rows
        if not A_expr:
            return True
        cols = [j for j, v in enumerate(self.qd) if v in free]
        A = self._matrix(A_expr, env)
        b = mpmath.matrix([evaluate_mp(x, env, WORK) for x in b_expr])
        _unit_rows(A, b)  # a constraint's scale (1e-12·(ẏ − ẋ)) is the author's, no rank
        v = mpmath.matrix([env[x] for x in self.qd])
        r = A * v + b
        if cols:
            step = _least_norm(_columns(A, cols), r)
            for k, j in enumerate(cols):
                env[self.qd[j]] = mpmath.re(v[j] - step[k])
        v = mpmath.matrix([env[x] for x in self.qd])
        left = A * v + b
        size = max([abs(x) for x in A] + [abs(x) for x in b] + [mpmath.mpf(1)])
        tol = max(mpmath.mpf(10) ** (-DIGITS - 2), mpmath.mpf(stated))
        return all(abs(x) <= tol * size * max([abs(y) for y in v] + [mpmath.mpf(1)])
                   for x in left)

    def _inside(self, env: dict) -> bool:
        """Every coordinate within its declared domain (a radius stays positive)."""
        domains = getattr(self.system, "domains", {})
        values = {k: float(v) for k, v in env.items()
                  if isinstance(k, sp.Symbol) and k not in self.state}
        for q in self.q:
            if q in domains and not domains[q].contains(float(env[q]), values):
                return False
            if q.is_positive and env[q] <= 0 or q.is_nonnegative and env[q] < 0:
                return False
        return True

    def _values(self, exprs: list, env: dict) -> tuple[list, list]:
        """Values and the magnitudes of what cancelled in them (the scale a residual is
        judged against), at the working precision."""
        vals, scales = [], []
        for e in exprs:
            v, m = program(e).run(env)
            if not (mpmath.isfinite(v) and mpmath.isfinite(m)):
                raise ValueError("not finite")
            vals.append(mpmath.re(v))
            scales.append(max(m, mpmath.mpf(10) ** -300))
        return vals, scales

    def _matrix(self, rows: list[list[sp.Expr]], env: dict):
        out = mpmath.matrix(len(rows), len(rows[0]) if rows else 0)
        for i, row in enumerate(rows):
            for j, x in enumerate(row):
                v = evaluate_mp(x, env, WORK) if x != 0 else mpmath.mpf(0)
                if not mpmath.isfinite(v):
                    raise ValueError("not finite")
                out[i, j] = mpmath.re(v)
        return out

    # ---- residuals and freedoms --------------------------------------------------------
    def residuals(self, point: dict) -> list[tuple[str, float]]:
        """(name, |value| relative to its scale) of each constraint at `point`: the
        holonomic ones, then the velocity-level ones (ġ named `<name>'`)."""
        env = {k: _mpf(v) for k, v in point.items()}
        env.setdefault(self.t, mpmath.mpf(0))
        _, b_expr = self._rows
        A_expr, _ = self._rows
        rows = ([g for g in self.position]
                + [sum((a * v for a, v in zip(row, self.qd, strict=True)), sp.S.Zero) + b
                   for row, b in zip(A_expr, b_expr, strict=True)])
        names = (self.position_names + [n + "'" for n in self.position_names]
                 + self.velocity_names)
        out = []
        for name, e in zip(names, rows, strict=True):
            v, m = evaluate(e, env, DIGITS)
            out.append((name, abs(v) / max(m, 1e-300) if m > 0 else abs(v)))
        return out

    def freedoms(self, point: dict) -> Freedoms:
        """The freedoms at `point` (a state on the manifold and the parameters)."""
        env = {k: _mpf(v) for k, v in point.items()}
        env.setdefault(self.t, mpmath.mpf(0))
        n = len(self.q)
        with mpmath.workdps(WORK):
            A_expr, _ = self._rows
            holonomic = _rank(self._matrix(self._jacobian, env)) if self.position else 0
            both = _rank(_unit_rows(self._matrix(A_expr, env))) if A_expr else 0
        return Freedoms(n - holonomic, n - both)


def _unit_rows(A, b=None):
    """A (and b) with every row of A scaled to unit length, in place (a zero row is left):
    a constraint multiplied by 1e-12 is the same constraint, and must weigh the same in a
    least-norm step, a residual's test and a rank. Returns A."""
    for i in range(A.rows):
        size = mpmath.sqrt(sum(abs(A[i, j]) ** 2 for j in range(A.cols)))
        if size == 0:
            continue
        for j in range(A.cols):
            A[i, j] /= size
        if b is not None:
            b[i] /= size
    return A


def _least_norm(G, r):
    """Gᵀ(GGᵀ + δ)⁻¹r: the least-norm step, δ = 10^(5 − WORK)·max|G|² keeping it defined
    where rows repeat (a redundant constraint, refused by `check_constraint_set` with its
    line) at no cost to a full-rank G's 30 digits."""
    size = max([abs(x) for x in G] + [mpmath.mpf(10) ** -300])
    GG = G * G.T
    for i in range(GG.rows):
        GG[i, i] += mpmath.mpf(10) ** (5 - WORK) * size**2
    return G.T * mpmath.lu_solve(GG, r)


def _columns(A, cols: list[int]):
    out = mpmath.matrix(A.rows, len(cols))
    for i in range(A.rows):
        for k, j in enumerate(cols):
            out[i, k] = A[i, j]
    return out


def _rank(A) -> int:
    if A.rows == 0:
        return 0
    s = mpmath.svd_r(A, compute_uv=False)
    top = max([abs(x) for x in s] + [mpmath.mpf(0)])
    if top == 0:
        return 0
    return sum(1 for x in s if abs(x) > mpmath.mpf(10) ** -RANK_TOL * top)


def _mpf(v):
    if isinstance(v, (mpmath.mpf, mpmath.mpc)):
        return v
    if isinstance(v, sp.Float):
        return mpmath.mpf(v._mpf_)
    if isinstance(v, sp.Basic):  # an exact number (pi/2): its value at the working precision
        return mpmath.mpf(sp.Float(sp.N(v, WORK), WORK)._mpf_)
    return mpmath.mpf(v)


def manifold_of(system) -> StateManifold | None:
    """The state manifold of a constrained system (None without constraints)."""
    m = StateManifold(system)
    return None if m.empty else m


def check_constraint_set(system, starts: int = 8) -> None:
    """SpecError (file:line, what is wrong) for constraints that are dependent at every
    state tried on the manifold (one repeats what the others say: its multiplier is not
    determined), and for a rolling contact whose point leaves the surface (its velocity
    along the normal does not vanish: the coordinates do not keep the body on it). Judged
    at states projected from random starts; where none projects, the engine judges later."""
    manifold = manifold_of(system)
    if manifold is None:
        return
    import random

    rng = random.Random(20261129)
    values = {k: sp.Float(v, DIGITS) for k, v in system.numeric_values().items()}
    states = []
    for _ in range(starts):
        start = {q: sp.Float(rng.uniform(-1, 1)) for q in manifold.q}
        start.update({v: sp.Float(rng.uniform(-1, 1)) for v in manifold.qd})
        point = manifold.project({**values, **start, manifold.t: sp.Float(rng.uniform(0, 1))})
        if point is not None:
            states.append(point)
    if not states:
        return
    n = len(manifold.q)
    holonomic = len(manifold.position)
    ranks = [manifold.freedoms(pt) for pt in states]
    if holonomic and all(n - f.configuration < holonomic for f in ranks):
        r = max(n - f.configuration for f in ranks)
        raise system.error(("constraints",), f"the constraints are dependent: their Jacobian "
                            f"has rank {r} for {holonomic} constraints at every state tried "
                            "(one repeats what the others say, and its multiplier is not "
                            "determined): remove the redundant one")
    rows = holonomic + len(manifold.velocity)
    if len(manifold.velocity) and all(n - f.velocity < rows for f in ranks):
        r = max(n - f.velocity for f in ranks)
        key = "rolling" if system.spec.get("rolling") else "velocity_constraints"
        raise system.error((key,), f"the velocity constraints are dependent: with the "
                            f"holonomic ones their rows have rank {r} for {rows} constraints "
                            "at every state tried (one repeats what the others say): remove "
                            "the redundant one")
    _contacts_stay_on(system, states)


def _contacts_stay_on(system, states: list[dict]) -> None:
    for i, spec in enumerate(system.spec.get("rolling") or []):
        v, n = relative_velocity(system, spec, ("rolling", i))
        normal = v.dot(n)
        worst = 0.0
        for pt in states:
            try:
                value, scale = evaluate(normal, pt, DIGITS)
            except _FAULTS:
                continue
            speed = max(float(abs(pt[x])) for x in system.qd) if system.qd else 1.0
            worst = max(worst, abs(value) / max(scale, speed, 1e-300))
        if worst > 1e-12:
            raise system.error(("rolling", i), f"rolling contact {spec['name']!r}: the "
                                f"contact point leaves the surface (its velocity along the "
                                f"normal, {sp.sstr(normal)[:100]}, is not zero): choose "
                                "coordinates that keep the body on the surface (its height a "
                                "function of the others), or add the holonomic constraint "
                                "that does")
