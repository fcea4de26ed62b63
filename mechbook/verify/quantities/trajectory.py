"""Quantities of the nonlinear motion from a given start: `turning_points`, `excursion`,
`motion_frequency`, `mean_rate`, `event_time`.

A part gives the start (`initial:` coordinates and velocities, zero unless given) and the
oscillating `coordinate:` (or `signal:`, any function of the state, for turning points).
Where every other coordinate is cyclic, the motion lies on a level set of the cyclic
momenta and the energy and is reduced to one degree of freedom (mechbook.engine.levelset):
turning points, period and the advance of the cyclic coordinates per period are then
computed in 50-digit arithmetic and compared at 1e-10 (asymptotic formulas with `limit:`).
Otherwise they are measured by integrating the full equations (mechbook.numerics.measure,
DOP853 at 1e-12) and compared at MEASURE_RTOL = 1e-7, the stated accuracy of that
measurement.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import sympy as sp

from mechbook.core.numeval import NotNumeric, evaluate_mp
from mechbook.core.words import plural
from mechbook.engine.levelset import LevelSet
from mechbook.errors import UnsupportedError
from mechbook.numerics.measure import MEASURE_RTOL, first_event, measure, signal_functions
from mechbook.numerics.rhs import build_model
from mechbook.verify.asymptotic import asymptotic
from mechbook.verify.compare import Verdict, at_point, match_multiset
from mechbook.verify.context import Context, numbers
from mechbook.verify.registration import ESTIMATE, EXPR, LIMIT, POINT, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

LEVEL_RTOL = 1e-10
EVENT_RTOL = 1e-15  # an event time by the level set's quadrature (resolved to 1e-20)
LEVEL_DPS = 50  # the level set's working precision
CHECK_DPS = 70  # a second precision for `limit:`: the difference is the first's error
LEVEL_POINTS = 6
MEASURED_POINTS = 3
START = {"initial": POINT, "coordinate": {"type": "string"}}


class Motion:
    """What a trajectory part refers to: its start, coordinate and how it is computed."""

    def __init__(self, ctx: Context):
        self.ctx = ctx
        data, sys = ctx.part.data, ctx.system
        self.start = initial_state(ctx)
        name = data.get("coordinate")
        self.of = None
        if "signal" in data:
            self.of = ctx.parse(data["signal"], ("signal",))
            self.coordinate = None
        elif name in sys.coord_names:
            self.coordinate = sys.q[sys.coord_names.index(name)]
        else:
            raise ctx.part.error(("coordinate",), "name the oscillating `coordinate:` (or "
                                 "give `of:`)")
        self.level = None
        if self.coordinate is not None:
            try:
                self.level = _level(ctx, self.coordinate)
            except UnsupportedError:
                self.level = None
        self.rtol = ctx.sampler.rtol if "estimate" in data else (
            LEVEL_RTOL if self.level else MEASURE_RTOL)

    def state(self, pt: dict) -> dict:
        return {k: v.subs(pt) for k, v in self.start.items()}

    def orbit(self, pt: dict, dps: int = LEVEL_DPS):
        return self.level.orbit(self.state(pt), pt, dps)

    def measured(self, pt: dict):
        ctx, sys = self.ctx, self.ctx.system
        params = {k: float(v) for k, v in pt.items() if k in sys.problem.values()}
        model = build_model(sys, ctx.dyn, params)
        signal = self.of if self.of is not None else self.coordinate
        stray = signal.free_symbols - set(sys.q + sys.qd) - {sys.t} - set(pt)
        if stray:
            raise ctx.part.error(("signal",), "unknown in `signal:`: " + ", ".join(map(str, stray)))
        fn = signal_functions(sys, ctx.dyn, pt, signal.subs(pt))
        st = self.state(pt)
        q0 = np.array([float(st[q]) for q in sys.q])
        qd0 = np.array([float(st[v]) for v in sys.qd])
        q0, qd0 = ctx.settled(q0, qd0, pt)  # a constrained system starts on its manifold
        scale = 1.0 / (1.0 + float(np.max(np.abs(qd0))))
        return measure(model, fn, q0, qd0, scale)

    def points(self) -> int:
        return LEVEL_POINTS if self.level else MEASURED_POINTS


def initial_state(ctx: Context) -> dict:
    """The initial state of `initial:` (coordinates and velocities; the rest zero)."""
    data, sys = ctx.part.data, ctx.system
    if "initial" not in data:
        raise ctx.part.error((), "a trajectory quantity needs `initial:` (the start)")
    start = {}
    for k, v in ctx.as_map(data["initial"], ("initial",)).items():
        if k in sys.coord_names:
            sym = sys.q[sys.coord_names.index(k)]
        elif k.endswith("dot") and k[:-3] in sys.coord_names:
            sym = sys.qd[sys.coord_names.index(k[:-3])]
        else:
            raise ctx.part.error(("initial", k), f"{k!r} is neither a coordinate nor a velocity")
        start[sym] = ctx.parse(v, ("initial", k))
    for sym in sys.q + sys.qd:
        start.setdefault(sym, sp.S.Zero)
    return start


def _level(ctx: Context, coordinate) -> LevelSet:
    def build() -> LevelSet:
        level = LevelSet(ctx.dyn, coordinate)
        level.reduced  # noqa: B018 - derive now: an unsupported reduction falls back here
        return level

    return ctx.analysis.reuse(("level-set", ctx.part.system, str(coordinate)), build)


def _book_values(ctx: Context, val) -> list:
    vals = val if isinstance(val, list) else [val]
    return [ctx.parse(v, ("book", i) if isinstance(val, list) else ("book",))
            for i, v in enumerate(vals)]


def _compare(ctx: Context, motion: Motion, book: list, engine_of, what: str,
             partial: bool = False, precise=None) -> Verdict:
    """Book values against engine values (a function of the parameter point), at random
    points; with `limit:` the relative error must fall by decades, both sides taken at
    CHECK_DPS digits (`precise(point, dps)`: the engine's values as mpmath numbers) and
    the engine's resolution measured as the difference from LEVEL_DPS digits."""
    if "limit" in ctx.part.data:
        if motion.level is None or precise is None:
            raise UnsupportedError("an asymptotic trajectory formula needs the level-set "
                                   "reduction (every other coordinate cyclic)")

        def error(pt) -> tuple[float, float]:
            with mpmath.workdps(CHECK_DPS):
                eng = precise(pt, CHECK_DPS)
                coarse = precise(pt, LEVEL_DPS)
                tiny = mpmath.mpf(10) ** -300
                resolution = max(abs(a - b) / max(abs(b), tiny)
                                 for a, b in zip(coarse, eng, strict=True))
                worst = mpmath.mpf(0)
                for b in _at_start_mp(motion.start, book, pt):
                    if b is None:
                        return float("inf"), float(resolution)
                    worst = max(worst, min(abs(e - b) for e in eng) / max(abs(b), tiny))
                return float(worst), max(float(resolution), 1e-60)

        return asymptotic(ctx, error)
    how = "level set" if motion.level else "measured"
    for n in range(1, motion.points() + 1):
        pt = ctx.sampler.draw()
        eng = engine_of(pt)
        ok, why = match_multiset(_at_start(motion.start, book, pt), eng, partial, rtol=motion.rtol)
        if not ok:
            return Verdict(False, f"{how}({plural(n, 'point')})", f"{what}: {why}" + at_point(pt))
    return Verdict(True, f"{how}({plural(motion.points(), 'point')}, rtol {motion.rtol:g})",
                   power=(f"within the stated {motion.rtol:g}" if "estimate" in ctx.part.data
                          else f"{plural(motion.points(), 'point')}, each value to {motion.rtol:g} "
                               f"({how})"))


def _at_start_mp(start: dict, book: list, pt: dict) -> list:
    """Book values at the parameter point at CHECK_DPS digits (None where one is not a
    finite real number), functions of the state evaluated at the start."""
    state = {k: v.subs(pt) for k, v in start.items()}
    out = []
    for b in book:
        try:
            v = evaluate_mp(sp.S(b).subs(state), pt, CHECK_DPS)
        except (NotNumeric, ZeroDivisionError, ValueError, TypeError):
            out.append(None)
            continue
        if not mpmath.isfinite(v) or abs(mpmath.im(v)) > mpmath.mpf(10) ** -40 * max(1, abs(v)):
            out.append(None)
        else:
            out.append(mpmath.re(v))
    return out


def _at_start(start: dict, book: list, pt: dict) -> list[float]:
    """Book values at the parameter point; a value may use functions of the state (first
    integrals such as L²/2T), evaluated at the start."""
    state = {k: v.subs(pt) for k, v in start.items()}
    return numbers([sp.S(b).subs(state) for b in book], pt)


def _extremes(motion: Motion, pt: dict) -> list[float]:
    if motion.level is not None and motion.of is None:
        lo, hi = motion.orbit(pt).turning_points
        return [float(lo), float(hi)]
    m = motion.measured(pt)
    return [m.low, m.high]


def _precise(motion: Motion, of):
    """(point, dps) ↦ the engine's values on the level set at dps digits (mpmath numbers);
    None where the signal is not the coordinate itself (no level set for it)."""
    if motion.level is None or motion.of is not None:
        return None

    def values(pt: dict, dps: int) -> list:
        with mpmath.workdps(dps):
            return of(motion.orbit(pt, dps))

    return values


KEYS = {**START, "partial": {"type": "boolean"}, "limit": LIMIT, "estimate": ESTIMATE}


@quantity('turning_points',
          book='list of the turning values of the coordinate (or of `signal:`)',
          how=('the least and greatest values of the coordinate (or of the function `signal:` of '
               'the state) over the motion from `initial:`: roots of V_eff = E on the level '
               'set of the first integrals (50 digits, rtol 1e-10) or, with other '
               'non-cyclic coordinates, measured by integration (rtol 1e-7); a subset with '
               '`partial: true`'),
          keys={**KEYS, "signal": EXPR},
          crosschecks=("trajectory",))
def check_turning_points(ctx: Context, val) -> Verdict:
    motion = Motion(ctx)
    return _compare(ctx, motion, _book_values(ctx, val), lambda pt: _extremes(motion, pt),
                    "turning points", bool(ctx.part.data.get("partial")),
                    _precise(motion, lambda o: list(o.turning_points)))


@quantity('excursion',
          book='expression: greatest minus least value of the coordinate (or of `signal:`)',
          how='as `turning_points`, the difference of the two (its own relative error)',
          keys={**KEYS, "signal": EXPR},
          crosschecks=("trajectory",))
def check_excursion(ctx: Context, val) -> Verdict:
    motion = Motion(ctx)

    def engine(pt):
        if motion.level is not None and motion.of is None:
            lo, hi = motion.orbit(pt).turning_points
            return [float(hi - lo)]
        lo, hi = _extremes(motion, pt)
        return [hi - lo]

    return _compare(ctx, motion, _book_values(ctx, val), engine, "excursion",
                    precise=_precise(motion, lambda o: [o.turning_points[1]
                                                        - o.turning_points[0]]))


@quantity('motion_frequency',
          book='expression: 2π over the period of the oscillation of the coordinate',
          how=('2π/T for the period T of the nonlinear oscillation of the coordinate from '
               '`initial:` (level-set quadrature, or measured by integration)'),
          keys=KEYS,
          crosschecks=("trajectory", "trajectory_period"))
def check_motion_frequency(ctx: Context, val) -> Verdict:
    motion = Motion(ctx)

    def engine(pt):
        if motion.level is not None:
            return [float(2 * math.pi / motion.orbit(pt).period)]
        return [2 * math.pi / motion.measured(pt).period()]

    return _compare(ctx, motion, _book_values(ctx, val), engine, "frequency",
                    precise=_precise(motion, lambda o: [2 * mpmath.pi / o.period]))


@quantity('mean_rate',
          book='expression: the mean rate of coordinate `rate:` over a period',
          how=('how far the coordinate `rate:` advances over one period of the oscillating '
               '`coordinate:`, divided by the period (level-set quadratures, or measured by '
               'integration)'),
          keys={**KEYS, "rate": {"type": "string"}},
          crosschecks=("trajectory", "trajectory_period", "trajectory_advance"))
def check_mean_rate(ctx: Context, val) -> Verdict:
    motion = Motion(ctx)
    name = ctx.part.data.get("rate")
    if name not in ctx.system.coord_names:
        raise ctx.part.error(("rate",), "`rate:` names the coordinate whose mean rate is given")
    q = ctx.system.q[ctx.system.coord_names.index(name)]

    def engine(pt):
        if motion.level is not None:
            orbit = motion.orbit(pt)
            return [float(orbit.advance(q) / orbit.period)]
        m = motion.measured(pt)
        return [m.advance(ctx.system.q.index(q)) / m.period()]

    return _compare(ctx, motion, _book_values(ctx, val), engine, "mean rate",
                    precise=_precise(motion, lambda o: [o.advance(q) / o.period]))



@quantity('event_time',
          book='expression: the time of the event (or, with `advance:`, how far that '
               'coordinate has moved by then)',
          how=('the first t > 0 at which `event:` (a function of the state and t) changes '
               'sign along the motion from `initial:`, measured by integrating the full '
               'equations (DOP853 at 1e-12; rtol 1e-7, or an `estimate:`\'s); an event '
               '`c − c1` of a level-set coordinate reached directly: the time by 50-digit '
               'quadrature at 6 points to 1e-15, and measured at one'),
          keys={"initial": POINT, "event": EXPR, "advance": {"type": "string"},
                "estimate": ESTIMATE})
def check_event_time(ctx: Context, val) -> Verdict:
    sys = ctx.system
    if "event" not in ctx.part.data:
        raise ctx.part.error((), "an event time needs `event:` (what changes sign)")
    event = ctx.parse(ctx.part.data["event"], ("event",))
    start = initial_state(ctx)
    name = ctx.part.data.get("advance")
    if name is not None and name not in sys.coord_names:
        raise ctx.part.error(("advance",), f"{name!r} is not a coordinate")
    rtol = ctx.sampler.rtol if "estimate" in ctx.part.data else MEASURE_RTOL
    points = 1 if "estimate" in ctx.part.data else MEASURED_POINTS  # an estimate: one point
    book = _book_values(ctx, val)
    exact = None
    if name is None and "estimate" not in ctx.part.data:
        exact = _event_by_quadrature(ctx, event, start, book)
        if exact is not None and not exact.ok:
            return exact
        if exact is not None:
            points = 1  # the measurement at one point now cross-checks the quadrature
    for n in range(1, points + 1):
        pt = ctx.sampler.draw()
        st = {k: v.subs(pt) for k, v in start.items()}
        q0 = np.array([float(st[q]) for q in sys.q])
        qd0 = np.array([float(st[v]) for v in sys.qd])
        q0, qd0 = ctx.settled(q0, qd0, pt)  # a constrained system starts on its manifold
        signal = event.subs(pt)

        def run(pt=pt, signal=signal, q0=q0, qd0=qd0):
            params = {k: float(v) for k, v in pt.items() if k in sys.problem.values()}
            model = build_model(sys, ctx.dyn, params)
            fn = signal_functions(sys, ctx.dyn, pt, signal)
            return first_event(model, fn, q0, qd0, 1.0 / (1.0 + float(np.max(np.abs(qd0)))))

        key = ("first_event", sys.name, sp.srepr(signal), q0.tobytes(), qd0.tobytes(),
               tuple(sorted((str(k), sp.srepr(sp.S(v))) for k, v in pt.items())))
        t, y = ctx.analysis.reuse(key, run)
        if name is None:
            engine = t
        else:
            i = sys.coord_names.index(name)
            engine = float(y[i] - q0[i])
        ok, why = match_multiset(_at_start(start, book, pt), [engine], rtol=rtol)
        if not ok:
            return Verdict(False, f"measured({plural(n, 'point')})", f"event: {why}" + at_point(pt))
    if exact is not None:
        return Verdict(True, f"{exact.method} and measured(1 point, rtol {rtol:g})",
                       exact.detail, power=exact.power)
    return Verdict(True, f"measured({plural(points, 'point')}, rtol {rtol:g})",
                   power=f"{plural(points, 'point')}, measured by integration to {rtol:g}")


def _event_by_quadrature(ctx: Context, event, start: dict, book: list) -> Verdict | None:
    """An event `c − c1` (c a coordinate whose motion reduces to a level set, c1 free of
    the state) reached directly from the start: the time is the level set's quadrature
    ∫ √(m/(2(E − V_eff))) dc in 50 digits (resolved against 60), compared at EVENT_RTOL (1e-15) at
    LEVEL_POINTS points. None where this does not apply (then it is measured)."""
    sys = ctx.system
    state = set(sys.q) | set(sys.qd) | {sys.t}
    coords = [q for q in sys.q if event.has(q)]
    if len(coords) != 1 or len(book) != 1:
        return None
    c = coords[0]
    target = c - event
    if target.free_symbols & state or sp.diff(event, c) != 1:
        return None
    try:
        level = _level(ctx, c)
    except UnsupportedError:
        return None
    worst = 0.0
    for n in range(1, LEVEL_POINTS + 1):
        pt = ctx.sampler.draw()
        st = {k: v.subs(pt) for k, v in start.items()}
        c1 = evaluate_mp(target, pt, CHECK_DPS)
        try:
            times = [level.orbit(st, pt, d).time_to(c1) for d in (LEVEL_DPS, CHECK_DPS)]
        except UnsupportedError:
            return None
        if times[0] is None:
            return None  # not reached directly: the measurement decides
        want = _at_start_mp(start, book, pt)[0]
        with mpmath.workdps(CHECK_DPS):
            if abs(times[0] - times[1]) > mpmath.mpf(10) ** -20 * abs(times[1]):
                return None
            if want is None:
                return Verdict(False, f"level set({n} points)", "event: the book's time is "
                               "not a finite real number here")
            rel = float(abs(want - times[1]) / abs(times[1]))
        worst = max(worst, rel)
        if not rel <= EVENT_RTOL:
            return Verdict(False, f"level set({n} points)",
                           f"event: the book's time {mpmath.nstr(want, 12)}, the quadrature's "
                           f"{mpmath.nstr(times[1], 12)} (relative {rel:.2g})")
    return Verdict(True, f"level set({LEVEL_POINTS} points, rtol {EVENT_RTOL:g})",
                   f"the time by quadrature, worst relative difference {worst:.2g}",
                   power=f"{LEVEL_POINTS} points, the level set's time quadrature to "
                         f"{EVENT_RTOL:g}; measured by integration at 1 point")
