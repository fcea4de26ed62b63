"""The Taylor backend: heyoka's adaptive Taylor method on the engine's equations.

Why: Taylor's method compiled through LLVM (heyoka.py) is at the work–precision front for
smooth, non-stiff motion at tight tolerances — 10⁴ pendulum periods at tol 1e-15 in a
tenth of a second with the energy held to ~1e-14 — and it detects events on its own dense
output. The equations are the engine's, M q̈ = f (+ A q̈ + b = 0), brought to the form a
Taylor step is cheapest in by `taylor_form` — the accelerations solved by LDLᵀ in SymPy
(M is symmetric positive definite; with constraints the multipliers come from the Schur
complement A M⁻¹ Aᵀ, also SPD), small entries trigsimp'd, every parameter-only
subexpression one derived heyoka runtime parameter — and translated by `hyexpr`: the
pendulum's right-hand side is par[0]·sin q₀, as short as heyoka written by hand, and a
10⁴-period run costs what heyoka's own propagate_grid costs. One system compiles once
per process: the integrators are cached on the model by tolerance and event set, and
heyoka's own in-memory LLVM cache reuses the machine code for a model rebuilt at other
parameter values. heyoka is optional (`pip install 'mechbook[taylor]'`); without it,
`available()` is False and callers use the SciPy methods.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import sympy as sp

from mechbook.core.optional import require
from mechbook.errors import MissingDependencyError, UnsupportedError
from mechbook.numerics.hyexpr import Translator
from mechbook.numerics.integrator_base import Integrator, IntegratorError, Trajectory
from mechbook.numerics.rhs import Model
from mechbook.numerics.taylor_form import Hoisted, accelerations

DEFAULT_TOL = 2.0 ** -52  # heyoka's own default: machine epsilon
COMPACT_OPS = 2000  # above this many SymPy operations, heyoka's compact mode (faster compile)


def available() -> bool:
    """Is heyoka installed (without importing it: that costs 0.3 s)?"""
    import importlib.util

    return importlib.util.find_spec("heyoka") is not None


def _hy():
    try:
        return require("heyoka", "taylor", "the Taylor method")
    except MissingDependencyError as exc:  # unsupported here: callers may go another way
        raise UnsupportedError(str(exc)) from None


@dataclass
class TaylorSystem:
    """The heyoka form of one model's equations (`taylor_form`: solved in SymPy, the
    parameter-only subexpressions hoisted into derived runtime parameters)."""

    ode: list  # [(variable, right-hand side)] for y = (q, q̇)
    variables: list
    translator: Translator
    hoisted: Hoisted  # heyoka's par[i] is hoisted.derived[i], an expression in `params`
    params: list  # the parameter symbols, sorted by name
    pars: list[float]  # their values
    compact: bool
    build_seconds: float
    compile_seconds: dict = field(default_factory=dict)  # tol -> seconds of the first compile

    def translate(self, expr: sp.Expr):
        """A SymPy expression in (t, q, q̇) and the parameters as a heyoka expression on
        this system's par[] (new parameter combinations are appended)."""
        out = self.hoisted(expr)
        known = self.translator.symbols
        for i, s in enumerate(self.hoisted.symbols):
            if s not in known:
                known[s] = _hy().par[i]
        return self.translator(out)

    def par_values(self, fp_type=float, base: dict | None = None) -> np.ndarray:
        """heyoka's par[] at the parameters' values (`base`, {symbol: value}, overriding
        them), each rounded once from 40 digits to `fp_type`."""
        at = dict(zip(self.params, self.pars, strict=True))
        at.update(base or {})
        try:
            values = self.hoisted.values(at)
        except ValueError as exc:  # e.g. √(k − m) with k < m: no real equation to integrate
            raise UnsupportedError(f"Taylor backend: {exc}") from None
        if fp_type is float:
            return np.array([float(x) for x in values], dtype=float)
        return np.array([fp_type(sp.sstr(x, full_prec=True)) for x in values], dtype=fp_type)


def system_of(model: Model) -> TaylorSystem:
    """Build (once per model) the heyoka ODE of `model`."""
    cached = model.cache.get("taylor_system")
    if cached is not None:
        return cached
    hy = _hy()
    start = time.perf_counter()
    src = model.source
    n = len(src.q)
    used = set().union(*(e.free_symbols for e in (*src.M, *src.f, *src.A, *src.b)))
    params = sorted((p for p in src.values if p in used), key=str)
    qv = hy.make_vars(*[f"q{i}" for i in range(n)])
    vv = hy.make_vars(*[f"v{i}" for i in range(n)])
    qv = [qv] if n == 1 else list(qv)
    vv = [vv] if n == 1 else list(vv)
    symbols = {src.t: hy.time}
    symbols.update(zip(src.q, qv, strict=True))
    symbols.update(zip(src.qd, vv, strict=True))
    hoisted = Hoisted(frozenset([src.t, *src.q, *src.qd]), frozenset(src.values))
    ts = TaylorSystem([], qv + vv, Translator(symbols), hoisted, params,
                      [src.values[p] for p in params], False, 0.0)
    acc = [ts.translate(a) for a in accelerations(src.M, src.f, src.A, src.b, n)]
    ts.ode = list(zip(qv, vv, strict=True)) + list(zip(vv, acc, strict=True))
    ops = sum(sp.count_ops(e) for e in (*src.M, *src.f, *src.A, *src.b))
    ts.compact = ops > COMPACT_OPS
    ts.build_seconds = time.perf_counter() - start
    model.cache["taylor_system"] = ts
    return ts


def integrator(model: Model, tol: float = DEFAULT_TOL, *, nt_events=(), t_events=(),
               key: object = None, fp_type=float):
    """A heyoka taylor_adaptive for `model` at `tol` (cached on the model under `key`
    when given: the same events reuse it, state and time reset by the caller)."""
    hy = _hy()
    ts = system_of(model)
    cache = model.cache.setdefault("taylor", {})
    ck = (tol, key, fp_type)
    if key is not None and ck in cache:
        return cache[ck]
    start = time.perf_counter()
    n2 = len(ts.variables)
    kw = {"tol": tol, "compact_mode": ts.compact}
    state = np.zeros(n2)
    if fp_type is not float:
        kw = {"tol": fp_type(tol), "compact_mode": ts.compact, "fp_type": fp_type}
        state = np.zeros(n2, dtype=fp_type)
    if nt_events:
        kw["nt_events"] = list(nt_events)
    if t_events:
        kw["t_events"] = list(t_events)
    try:
        ta = hy.taylor_adaptive(ts.ode, state, **kw)
    except (ValueError, RuntimeError, TypeError) as exc:  # heyoka refused the system
        raise UnsupportedError(f"Taylor backend: {exc}") from None
    # heyoka sized par[] to the indices the equations and events use: the first ones
    ta.pars[:] = ts.par_values(fp_type)[: len(ta.pars)]
    ts.compile_seconds.setdefault(tol, time.perf_counter() - start)
    if key is not None:
        cache[ck] = ta
    return ta


def compile_seconds(model: Model) -> float:
    """Seconds spent building and compiling this model's Taylor integrators (first ones)."""
    ts = model.cache.get("taylor_system")
    return 0.0 if ts is None else ts.build_seconds + sum(ts.compile_seconds.values())


def reset(ta, t0: float, y0: np.ndarray) -> None:
    """Rewind a cached integrator to (t0, y0), in its own floating-point type."""
    kind = type(ta.time)  # float, or heyoka's real128
    ta.time = kind(float(t0))
    ta.state[:] = y0
    if ta.with_events:
        ta.reset_cooldowns()


def propagate(model: Model, t_span, y0: np.ndarray, tol: float = DEFAULT_TOL, t_eval=None,
              max_points: int = 200_001):
    """Integrate over t_span: (t, y (2n × N), success, message, steps). Records at t_eval,
    or at every step (at most max_points, evenly thinned) without it."""
    hy = _hy()
    ta = integrator(model, tol, key="plain")
    t0, t1 = map(float, t_span)
    reset(ta, t0, np.asarray(y0, float))
    if t_eval is not None:
        grid = np.asarray(t_eval, float)
        steps = 0
        if len(grid) and grid[0] > t0:
            out = ta.propagate_until(float(grid[0]))
            steps += int(out[3])
            if out[0] != hy.taylor_outcome.time_limit:
                return _failed(t0, y0, out[0], steps)
        res = ta.propagate_grid(grid)
        steps += int(res[3])
        ys = np.asarray(res[5]).T
        ok = res[0] == hy.taylor_outcome.time_limit
        if not ok:
            good = np.all(np.isfinite(ys), axis=0)
            k = int(np.argmin(good)) if not good.all() else ys.shape[1]
            return grid[:k], ys[:, :k], False, f"Taylor integration stopped: {res[0]}", steps
        return grid, ys, True, "Taylor integration reached the end", steps
    out = ta.propagate_until(t1, c_output=True)
    co = out[4]
    ok = out[0] == hy.taylor_outcome.time_limit
    times = np.asarray(co.times) if co is not None else np.array([t0])
    if len(times) > max_points:
        times = times[np.unique(np.linspace(0, len(times) - 1, max_points).astype(int))]
    ys = np.asarray(co(times)).T if co is not None else np.asarray(y0, float)[:, None]
    return times, ys, bool(ok), ("Taylor integration reached the end" if ok else
                                 f"Taylor integration stopped: {out[0]}"), int(out[3])


def _failed(t0, y0, outcome, steps):
    return (np.array([t0]), np.asarray(y0, float)[:, None], False,
            f"Taylor integration stopped: {outcome}", steps)


def event_expression(model: Model, expr: sp.Expr):
    """A SymPy function of (t, q, q̇) and the parameters as a heyoka expression."""
    return system_of(model).translate(expr)


def turning_points(model: Model, rate: sp.Expr, y0: np.ndarray, time_scale: float,
                   extremes: int, tol: float, max_chunks: int = 400):
    """Times and states where `rate` (d signal/dt on the motion, SymPy) changes sign, from
    t = 0 until `extremes` are found: [(t, state, direction)], direction −1 where the rate
    falls through zero (a maximum of the signal), +1 where it rises, 0 if unknown."""
    hy = _hy()
    hits: list = []

    def record(ta, t, d_sgn):
        ta.update_d_output(t)
        sign = {hy.event_direction.negative: -1, hy.event_direction.positive: +1}
        hits.append((float(t), np.array(ta.d_output, float), sign.get(d_sgn, 0)))

    ev = hy.nt_event(event_expression(model, rate), record)
    ta = integrator(model, tol, nt_events=[ev])  # the callback is per call: not cached
    reset(ta, 0.0, np.asarray(y0, float))
    t0 = 0.0
    found: list = []
    for _ in range(max_chunks):
        hits.clear()
        out = ta.propagate_until(t0 + time_scale)
        if out[0] != hy.taylor_outcome.time_limit:
            raise UnsupportedError(f"measurement: the Taylor integration failed: {out[0]}")
        found.extend(h for h in hits if h[0] > 1e-12 * max(1.0, abs(time_scale)))
        t0 = float(ta.time)
        if len(found) >= extremes:
            return found
        if not hits:
            time_scale *= 1.5
    raise UnsupportedError(f"measurement: fewer than {extremes} turning points in "
                           f"{max_chunks} chunks")


def first_crossing(model: Model, signal: sp.Expr, y0: np.ndarray, time_scale: float,
                   tol: float, max_chunks: int = 400) -> tuple[float, np.ndarray]:
    """(t, state) at the first t > 0 where `signal` changes sign (a terminal event)."""
    hy = _hy()
    ev = hy.t_event(event_expression(model, signal))
    ta = integrator(model, tol, t_events=[ev])
    reset(ta, 0.0, np.asarray(y0, float))
    t0 = 0.0
    floor = 1e-12 * max(1.0, time_scale)
    for _ in range(max_chunks):
        out = ta.propagate_until(t0 + time_scale)
        if out[0] == hy.taylor_outcome.time_limit:
            t0 = float(ta.time)
            time_scale *= 1.5
            continue
        if out[0] in (hy.taylor_outcome.err_nf_state, hy.taylor_outcome.step_limit):
            raise UnsupportedError(f"measurement: the Taylor integration failed: {out[0]}")
        if float(ta.time) > floor:  # a terminal event (not the start itself)
            return float(ta.time), np.array(ta.state, float)
        t0 = float(ta.time)
    raise UnsupportedError(f"measurement: the event did not happen in {max_chunks} chunks")


def propagate_batch(model: Model, states: np.ndarray, t_end: float, tol: float = DEFAULT_TOL,
                    pars: np.ndarray | None = None, grid: np.ndarray | None = None):
    """Many runs of one system at once (heyoka's batch mode, SIMD lanes): `states` (N × 2n)
    from t = 0 to t_end (or sampled on `grid`), `pars` (N × P) overriding the parameter
    values per run. Returns (N × 2n) end states, or (N × len(grid) × 2n) samples."""
    hy = _hy()
    ts = system_of(model)
    states = np.atleast_2d(np.asarray(states, float))
    N, n2 = states.shape
    lanes = max(1, int(hy.recommended_simd_size()))
    cache = model.cache.setdefault("taylor", {})
    key = ("batch", tol, lanes)
    if key not in cache:
        start = time.perf_counter()
        cache[key] = hy.taylor_adaptive_batch(ts.ode, np.zeros((n2, lanes)), tol=tol,
                                              compact_mode=ts.compact)
        ts.compile_seconds.setdefault(("batch", tol), time.perf_counter() - start)
    ta = cache[key]
    P = len(ta.pars)  # heyoka's par[] (derived from the parameters), as the ODE uses it
    if pars is None:
        per_run = np.tile(ts.par_values()[:P], (N, 1))
    else:  # each run's parameter values, then their derived combinations
        rows = np.atleast_2d(np.asarray(pars, float))
        per_run = np.array([ts.par_values(base=dict(zip(ts.params, r, strict=True)))[:P]
                            for r in rows]).reshape(N, P)
    out = np.full((N, n2) if grid is None else (N, len(grid), n2), np.nan)
    for lo in range(0, N, lanes):
        hi = min(N, lo + lanes)
        block = np.zeros((n2, lanes))
        block[:, : hi - lo] = states[lo:hi].T
        block[:, hi - lo:] = states[lo:lo + 1].T  # pad with a copy of a real run
        ta.set_time(np.zeros(lanes))
        ta.state[:] = block
        if P:
            pb = np.zeros((P, lanes))
            pb[:, : hi - lo] = per_run[lo:hi].T
            pb[:, hi - lo:] = per_run[lo:lo + 1].T
            ta.pars[:] = pb
        if grid is None:
            ta.propagate_until(float(t_end))
            out[lo:hi] = np.asarray(ta.state).T[: hi - lo]
        else:
            g = np.repeat(np.asarray(grid, float)[:, None], lanes, axis=1)
            res = ta.propagate_grid(g)
            samples = np.asarray(res[-1])  # (len(grid), n2, lanes)
            out[lo:hi] = np.transpose(samples, (2, 0, 1))[: hi - lo]
    return out


def crossings_batch(model: Model, weights: np.ndarray, offset: tuple[float, float],
                    states: np.ndarray, t_end: float, tol: float = DEFAULT_TOL
                    ) -> list[np.ndarray]:
    """Upward zero crossings of the linear signal weights·y − (a + b t), offset = (a, b),
    from each of `states` (N × 2n) over [0, t_end], in heyoka's batch mode (all starts in
    SIMD lanes at once): one array of crossing times per start. The period measurement of
    `crosscheck.amplitude` for many amplitudes of one mode."""
    hy = _hy()
    ts = system_of(model)
    states = np.atleast_2d(np.asarray(states, float))
    N, n2 = states.shape
    terms = [float(w) * v for w, v in zip(weights, ts.variables, strict=True) if w != 0]
    a, b = map(float, offset)
    expr = hy.sum(terms) - (a + b * hy.time) if terms else hy.expression(0.0)
    hits: list = []

    def record(ta, t, d_sgn, lane):
        hits.append((float(t), int(lane)))

    lanes = max(1, int(hy.recommended_simd_size()))
    ev = hy.nt_event_batch(expr, record, direction=hy.event_direction.positive)
    ta = hy.taylor_adaptive_batch(ts.ode, np.zeros((n2, lanes)), tol=tol,
                                  compact_mode=ts.compact, nt_events=[ev])
    if len(ta.pars):
        ta.pars[:] = np.tile(ts.par_values()[: len(ta.pars), None], (1, lanes))
    out: list[list[float]] = [[] for _ in range(N)]
    for lo in range(0, N, lanes):
        hi = min(N, lo + lanes)
        block = np.repeat(states[lo:lo + 1].T, lanes, axis=1)
        block[:, : hi - lo] = states[lo:hi].T
        ta.set_time(np.zeros(lanes))
        ta.state[:] = block
        ta.reset_cooldowns()
        hits.clear()
        ta.propagate_until(float(t_end))
        for t, lane in hits:
            if lane < hi - lo and t > 0:
                out[lo + lane].append(t)
    return [np.sort(np.array(x)) for x in out]


class TaylorMethod(Integrator):
    """heyoka's adaptive Taylor method behind the Integrator interface (`integrate(...,
    method="taylor")`): options `tol` (default machine epsilon; `rtol` is taken for it
    when `tol` is not given), `max_points`."""

    adaptive = True

    def solve(self, model, t_span, q0, qd0, t_eval=None, events=None) -> Trajectory:
        if events:
            raise IntegratorError("the taylor method takes no solve_ivp events (its own "
                                  "events: taylor.turning_points, taylor.first_crossing)")
        tol = float(self.options.get("tol") or self.options.get("rtol") or DEFAULT_TOL)
        y0 = np.concatenate((q0, qd0)).astype(float)
        before = compile_seconds(model)
        start = time.perf_counter()
        t, y, ok, message, steps = propagate(
            model, t_span, y0, tol, t_eval, int(self.options.get("max_points") or 200_001))
        compile_s = compile_seconds(model) - before
        n = model.n
        settings = {"method": self.name, "tol": tol, "steps": steps,
                    "compile_s": compile_s,
                    "integrate_s": time.perf_counter() - start - compile_s}
        return Trajectory(t, y[:n], y[n:], self.name, settings, 0, ok, message)



__all__ = ["DEFAULT_TOL", "TaylorMethod", "available", "compile_seconds", "crossings_batch",
           "first_crossing", "integrator",
           "propagate", "propagate_batch", "system_of", "turning_points"]
