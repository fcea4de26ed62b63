"""Quantities of nonlinear dynamics: `poincare` (the fixed points and period-n orbits of a
return map, their multipliers and stability), `bifurcation` (the parameter value where a
multiplier passes through −1 or +1) and `lyapunov` (the largest Lyapunov exponent).

An orbit, a bifurcation and chaos depend on the parameters, so each is judged at one
point: the problem's values (or an `estimate:`'s `values:`), with the part's `initial:` as
the start (the guess of Newton's method, or the trajectory's start). The return maps and
their derivatives come from mechbook.numerics.poincare, the exponent from
mechbook.numerics.lyapunov; every monodromy is cross-checked by finite differences of the
map before it is believed.
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from mechbook.core.compile import compile_exprs
from mechbook.errors import UnsupportedError
from mechbook.numerics.lyapunov import RESOLUTION, UnboundedMotion, largest_exponent
from mechbook.numerics.poincare import NEWTON_TOL, NoCrossing, ReturnMap, Section, stability
from mechbook.verify.compare import Verdict
from mechbook.verify.context import Context
from mechbook.verify.quantities.extremum import OVER
from mechbook.verify.quantities.trajectory import initial_state
from mechbook.verify.registration import ESTIMATE, EXPR, POINT, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

RTOL = 1e-8  # an exact value's tolerance (orbit points, multipliers, a bifurcation's value)
MONODROMY_RTOL = 1e-5  # the tangent flow's DPⁿ against finite differences of the map
STABLE_MARGIN = 1e-8  # |μ| − 1 allowed to a stable orbit (the flow is good to ~1e-10)
BISECTIONS = 60

SECTION = {"type": "object", "additionalProperties": False,
           "properties": {"period": EXPR, "phase": EXPR, "coordinate": {"type": "string"},
                          "value": EXPR, "direction": {"enum": ["up", "down"]},
                          "within": EXPR, "max_step": EXPR}}
ORBIT_KEYS = {"initial": POINT, "section": SECTION,
              "order": {"type": "integer", "minimum": 1, "maximum": 64}, "energy": EXPR,
              "estimate": ESTIMATE}


def _values(ctx: Context) -> tuple[dict, dict]:
    """(the part's point: every symbol at its value, the parameters as floats)."""
    pt = ctx.sampler.default()
    if pt is None:
        raise UnsupportedError("the problem's values do not satisfy its conditions")
    params = {k: float(v) for k, v in pt.items() if k in ctx.analysis.problem.values()}
    return pt, params


def _number(ctx: Context, text, sub: tuple, pt: dict) -> float:
    val = ctx.parse(text, sub).subs(pt)
    try:
        x = float(sp.N(val, 30))
    except TypeError:
        raise ctx.part.error(sub, "a number is expected here (at the problem's values)") \
            from None
    if not math.isfinite(x):
        raise ctx.part.error(sub, "a finite number is expected")
    return x


def _start(ctx: Context, pt: dict) -> np.ndarray:
    sys = ctx.system
    st = initial_state(ctx)
    return np.array([_number(ctx, str(st[s]), ("initial",), pt) for s in sys.q + sys.qd])


def _state_index(ctx: Context, name: str, sub: tuple) -> int:
    names = ctx.system.coord_names
    if name in names:
        return names.index(name)
    if name.endswith("dot") and name[:-3] in names:
        return len(names) + names.index(name[:-3])
    raise ctx.part.error(sub, f"{name!r} is neither a coordinate nor a velocity")


def _section(ctx: Context, pt: dict) -> Section:
    data = ctx.part.data.get("section")
    if not isinstance(data, dict):
        raise ctx.part.error((), "a return map needs `section:`: `{period: T}` (stroboscopic) "
                             "or `{coordinate: q, value: c, direction: up}` (a surface)")
    step = None
    if "max_step" in data:
        step = _number(ctx, data["max_step"], ("section", "max_step"), pt)
        if not step > 0:
            raise ctx.part.error(("section", "max_step"), "the longest step must be positive")
    if "period" in data:
        if "coordinate" in data:
            raise ctx.part.error(("section",), "a section is stroboscopic (`period:`) or a "
                                 "surface (`coordinate:`), not both")
        T = _number(ctx, data["period"], ("section", "period"), pt)
        if not T > 0:
            raise ctx.part.error(("section", "period"), "the period must be positive")
        phase = _number(ctx, data.get("phase", 0), ("section", "phase"), pt)
        return Section(period=T, phase=phase, max_step=step)
    if "coordinate" not in data:
        raise ctx.part.error(("section",), "name the section's `period:` or `coordinate:`")
    index = _state_index(ctx, data["coordinate"], ("section", "coordinate"))
    if any(e.has(ctx.system.t) for e in ctx.dyn.residuals):
        raise ctx.part.error(("section",), "a surface section needs an autonomous system (t "
                             "occurs in its equations, so a crossing's state alone does not "
                             "fix the next one): use a stroboscopic `period:`")
    within = _number(ctx, data.get("within", 1000), ("section", "within"), pt)
    if not within > 0:
        raise ctx.part.error(("section", "within"), "the time allowed must be positive")
    return Section(index=index, value=_number(ctx, data.get("value", 0), ("section", "value"),
                                              pt),
                   direction=-1 if data.get("direction") == "down" else 1, within=within,
                   max_step=step)


def _return_map(ctx: Context, params: dict, pt: dict, free=None) -> ReturnMap:
    """The part's return map at `params` (`free`: a parameter `_move` may change)."""
    section = _section(ctx, pt)
    conserved = ctx.analysis.reuse(("energy-conserved", ctx.part.system),
                                   lambda: bool(ctx.dyn.energy_conserved))
    rm = ReturnMap(ctx.system, ctx.dyn, params, section, conserved, free)
    _hold_energy(ctx, rm, params, pt)
    return rm


def _hold_energy(ctx: Context, rm: ReturnMap, params: dict, pt: dict) -> None:
    if "energy" in ctx.part.data:
        if rm.section.period is not None:
            raise ctx.part.error(("energy",), "an energy level applies to a surface section")
        rm.set_energy(_energy(ctx, params), _number(ctx, ctx.part.data["energy"],
                                                    ("energy",), pt))


def _move(ctx: Context, rm: ReturnMap, params: dict, pt: dict, sym, value: float) -> None:
    """The map's free parameter `sym` at `value` (the section and energy level with it)."""
    at = {**pt, sym: sp.Float(value, 30)}
    rm.move(value, _section(ctx, at))
    _hold_energy(ctx, rm, {**params, sym: value}, at)


def _energy(ctx: Context, params: dict):
    """y ↦ (h, ∇h): the engine's energy function and its gradient over the state."""
    sys, dyn = ctx.system, ctx.dyn
    if not dyn.energy_conserved:
        raise ctx.part.error(("energy",), "the energy function is not conserved here: an "
                             "energy level does not hold the orbit")
    sub = {k: sp.Float(v, 17) for k, v in params.items()}
    h = dyn.energy_function.xreplace(sub)
    state = list(sys.q) + list(sys.qd)
    fn, _ = compile_exprs([sys.t] + state, [h] + [sp.diff(h, s) for s in state])

    def energy(y):
        out = fn(np.concatenate(([0.0], y)))
        return float(out[0]), out[1:]

    return energy


def _orbit(ctx: Context, rm: ReturnMap, guess: np.ndarray, order: int,
           cross_check: bool = True):
    """Newton's orbit, its monodromy cross-checked by finite differences (unless not
    `cross_check`: then the second value is None)."""
    try:
        orbit = rm.orbit(guess, order)
    except NoCrossing as exc:
        raise ctx.part.error(("section",), f"{exc} from the start of `initial:`") from None
    if not cross_check:
        return orbit, None
    fd = rm.finite_difference(orbit.points[0], order)
    gap = float(np.max(np.abs(fd - orbit.jacobian)))
    scale = max(1.0, float(np.max(np.abs(orbit.jacobian))))
    if not gap <= MONODROMY_RTOL * scale:
        raise UnsupportedError(f"the return map's derivative from the variational equations "
                               f"and its finite differences disagree by {gap:.2g} (of "
                               f"{scale:.3g}): the map is not smooth enough here to judge")
    return orbit, gap / scale


def _close(a: complex, b: complex, rtol: float, scale: float) -> bool:
    return abs(a - b) <= rtol * max(abs(b), 1e-3 * scale)


def _match_multipliers(book: list, engine: np.ndarray, rtol: float) -> str:
    if len(book) != len(engine):
        return f"the book lists {len(book)} multipliers, the map has {len(engine)}"
    free = list(engine)
    scale = max(abs(x) for x in list(book) + free)
    for b in book:
        best = min(range(len(free)), key=lambda i: abs(free[i] - b))
        if not _close(free[best], b, rtol, scale):
            return f"multiplier {b:.10g} not among the map's {_fmt(engine)}"
        free.pop(best)
    return ""


def _fmt(mu) -> str:
    return "[" + ", ".join(f"{complex(m):.8g}" for m in mu) + "]"


def _point_error(ctx: Context, rm: ReturnMap, book: dict, points: list, pt: dict,
                 rtol: float) -> str:
    target = {}
    for k, v in ctx.as_map(book, ("book", "at")).items():
        target[_state_index(ctx, k, ("book", "at", k))] = _number(ctx, v, ("book", "at", k), pt)
    scale = max([abs(v) for v in target.values()] + [1e-300])
    for p in points:
        d = rm.difference(p, np.array([target.get(i, p[i]) for i in range(len(p))]))
        newton = 10 * NEWTON_TOL * (1 + float(np.max(np.abs(p))))  # where Newton stopped
        if all(abs(d[i]) <= rtol * max(abs(v), 1e-3 * scale) + newton
               for i, v in target.items()):
            return ""
    names = ctx.system.coord_names + [c + "dot" for c in ctx.system.coord_names]
    found = "; ".join(", ".join(f"{names[i]} = {p[i]:.10g}" for i in target) for p in points)
    return f"the orbit from `initial:` passes the section at {found}, not at the book's point"


@quantity('poincare',
          book='`{at: {q: value, qdot: value}, multipliers: [μ, ...], stable: true/false}` '
               '(any of them)',
          how=('Newton\'s method on the return map Pⁿ of `section:` (`{period: T, phase}`: '
               'stroboscopic; `{coordinate: q, value: c, direction: up|down}`: a surface, '
               'with `energy:` holding a conserved energy) from the guess `initial:`, '
               '`order:` n (default 1), at the problem\'s values (or `estimate:`\'s; where '
               'that orbit misses the book\'s point, Newton again from the book\'s point, '
               'which fails only where it finds no orbit or another): the '
               'orbit passes the book\'s point, its multipliers (eigenvalues of DPⁿ from '
               'the variational equations, on a surface without the energy\'s 1) are the '
               'book\'s, to 1e-8 (an estimate\'s rtol; a point also to Newton\'s '
               '1e-9·(1 + |x|)), and it is stable exactly when '
               'every |μ| ≤ 1 + 1e-8 (unstable beyond 1 + 1e-6; between: undecided). DPⁿ '
               'must agree with central differences of the map to 1e-5'),
          keys=ORBIT_KEYS, complex_values=True)
def check_poincare(ctx: Context, val) -> Verdict:
    book = ctx.as_map(val, ("book",))
    if not book or set(book) - {"at", "multipliers", "stable"}:
        raise ctx.part.error(("book",), "give the orbit's `at:`, `multipliers:` or `stable:`")
    pt, params = _values(ctx)
    rm = _return_map(ctx, params, pt)
    order = int(ctx.part.data.get("order", 1))
    orbit, gap = _orbit(ctx, rm, _start(ctx, pt), order)
    rtol = ctx.sampler.rtol if "estimate" in ctx.part.data else RTOL
    method = f"Newton on the return map (order {order}, {orbit.steps} steps)"
    if "at" in book:
        why = _point_error(ctx, rm, book["at"], orbit.points, pt, rtol)
        if why:
            # `initial:` is only Newton's guess: the map may have other orbits, and the
            # book's point may be one of them. Only Newton from the book's point itself
            # can contradict it.
            found, found_gap, refuted = _orbit_from_book(ctx, rm, book["at"], order, pt,
                                                         rtol, why)
            if refuted:
                return Verdict(False, method, refuted)
            orbit, gap = found, found_gap
            method += "; again from the book's point"
    if order > 1 and _has_shorter_period(rm, orbit, order):
        return Verdict(False, method, f"the orbit found has a period shorter than {order}")
    if "multipliers" in book:
        mus = [complex(sp.N(ctx.parse(m, ("book", "multipliers", i)).subs(pt), 30))
               for i, m in enumerate(ctx.as_list(book["multipliers"], ("book", "multipliers")))]
        why = _match_multipliers(mus, orbit.multipliers, rtol)
        if why:
            return Verdict(False, method, why)
    if "stable" in book:
        verdict = stability(orbit.multipliers, STABLE_MARGIN)
        if verdict is None:
            raise UnsupportedError(f"the largest |multiplier| {orbit.spectral_radius:.12g} is "
                                   "too near 1 to tell a stable orbit from an unstable one")
        if (verdict == "stable") != bool(book["stable"]):
            return Verdict(False, method, f"the orbit is {verdict} (multipliers "
                                          f"{_fmt(orbit.multipliers)})")
    return Verdict(True, method, power=(
        f"one point (the problem's values); orbit and multipliers to {rtol:g}; monodromy "
        f"confirmed by finite differences to {gap:.1g}"))


def _orbit_from_book(ctx: Context, rm: ReturnMap, at, order: int, pt: dict, rtol: float,
                     why: str):
    """(orbit, its monodromy gap, "") for the orbit Newton finds from the book's point (the
    coordinates it leaves out taken from `initial:`), where the orbit from `initial:` missed
    it; (None, None, why) where the book's point is no orbit: Newton from it finds none
    (Newton started on an orbit stops there at once) or goes to another one."""
    guess = _start(ctx, pt)
    for k, v in ctx.as_map(at, ("book", "at")).items():
        guess[_state_index(ctx, k, ("book", "at", k))] = _number(ctx, v, ("book", "at", k), pt)
    try:
        found = rm.orbit(guess, order)
    except (NoCrossing, UnsupportedError) as exc:
        return None, None, f"{why}, and Newton from the book's point finds no orbit ({exc})"
    again = _point_error(ctx, rm, at, found.points, pt, rtol)
    if again:
        return None, None, (f"{why}, and Newton from the book's point finds the orbit at "
                            f"{_where(ctx, at, found.points)}")
    orbit, gap = _orbit(ctx, rm, found.points[0], order)  # its monodromy cross-checked
    return orbit, gap, ""


def _where(ctx: Context, at, points: list) -> str:
    names = ctx.system.coord_names + [c + "dot" for c in ctx.system.coord_names]
    idx = [_state_index(ctx, k, ("book", "at", k)) for k in ctx.as_map(at, ("book", "at"))]
    return "; ".join(", ".join(f"{names[i]} = {p[i]:.10g}" for i in idx) for p in points)


def _has_shorter_period(rm: ReturnMap, orbit, order: int) -> bool:
    """Whether the orbit closes after a proper divisor of `order` iterations."""
    x = orbit.points[0]
    tol = 1e-7 * (1 + float(np.max(np.abs(x))))
    return any(float(np.max(np.abs(rm.difference(orbit.points[d], x)))) <= tol
               for d in range(1, order) if order % d == 0)


# ---- the onset of a bifurcation ----------------------------------------------------------
KINDS = {"period_doubling": -1.0, "fold": 1.0}  # the multiplier's value at the onset


@quantity('bifurcation',
          book='expression: the value of the parameter of `over:` where the bifurcation sets in',
          how=('the orbit of `poincare` (same `section:`, `initial:`, `order:`) followed '
               'through `over: {p: [lo, hi]}`, an interval of the parameter p (Newton from the '
               'nearest orbit found), on one side of the onset where a multiplier has passed '
               'μ0 = −1 (`kind: period_doubling`: Re μ < −1) or +1 (`kind: fold`, also a '
               'pitchfork: Re μ > 1), or where Newton finds no orbit (a fold\'s end); the '
               'change of side in the bracket '
               'bisected to 1e-12 and equal to the book\'s value to 1e-8 (an estimate\'s '
               'rtol); the monodromy on either side of it cross-checked by finite differences'),
          keys={**ORBIT_KEYS, "over": OVER, "kind": {"enum": list(KINDS)}})
def check_bifurcation(ctx: Context, val) -> Verdict:
    data = ctx.part.data
    pt, params = _values(ctx)
    over = data.get("over")
    if not isinstance(over, dict) or data.get("kind") not in KINDS:
        raise ctx.part.error((), "a bifurcation needs `over: {parameter: [lo, hi]}` and "
                             f"`kind:` ({' or '.join(KINDS)})")
    (name, bracket), = over.items()
    sym = next((s for s in params if str(s) == name), None)
    if sym is None:
        raise ctx.part.error(("over", name), f"{name!r} is not a parameter of the problem")
    lo, hi = (_number(ctx, v, ("over", name, i), pt) for i, v in enumerate(bracket))
    target, order = KINDS[data["kind"]], int(data.get("order", 1))
    guesses = {}
    rm = _return_map(ctx, params, pt, free=sym)  # compiled once, the parameter moved

    def side(p: float, cross_check: bool = False):
        """+1 before the onset, −1 past it, 0 where Newton finds no orbit."""
        near = min(guesses, key=lambda q: abs(q - p), default=None)
        guess = guesses[near] if near is not None else _start(ctx, pt)
        _move(ctx, rm, params, pt, sym, p)
        try:
            orbit, _ = _orbit(ctx, rm, guess, order, cross_check)
        except UnsupportedError:
            if cross_check:
                raise
            return 0
        guesses[p] = orbit.points[0]
        beyond = np.any(orbit.multipliers.real * target > 1)  # a multiplier past μ0
        return -1 if beyond else 1

    a, b = side(lo), side(hi)
    if a == 0 or a == b:
        raise UnsupportedError(f"no onset of a {data['kind'].replace('_', ' ')} between "
                               f"{lo:g} and {hi:g} from the orbit of `initial:` (the sides: "
                               f"{a}, {b}; 0 where Newton finds no orbit)")
    for _ in range(BISECTIONS):
        if abs(hi - lo) <= 1e-12 * max(abs(lo), abs(hi), 1e-300):
            break
        mid = (lo + hi) / 2
        if side(mid) == a:
            lo = mid
        else:
            hi = mid
    onset = (lo + hi) / 2
    for p in (lo, hi):  # the monodromy on either side of the onset, cross-checked
        if side(p, cross_check=True) == 0:
            raise UnsupportedError(f"no orbit found at {name} = {p:.12g} beside the onset")
    rtol = ctx.sampler.rtol if "estimate" in data else RTOL
    claimed = _number(ctx, val, ("book",), pt)
    method = f"continuation and bisection in {name} ({len(guesses)} orbits)"
    if abs(claimed - onset) > rtol * max(abs(onset), 1e-300):
        return Verdict(False, method, f"the {data['kind'].replace('_', ' ')} sets in at "
                                      f"{name} = {onset:.12g}, not {claimed:.12g}")
    return Verdict(True, method, power=f"one point; the onset to {rtol:g} (located to 1e-12)")


# ---- the largest Lyapunov exponent -------------------------------------------------------
def _max_step(ctx: Context, pt: dict) -> float:
    """`max_step:` (a drive in short pulses must not be stepped over), else no bound."""
    if "max_step" not in ctx.part.data:
        return math.inf
    h = _number(ctx, ctx.part.data["max_step"], ("max_step",), pt)
    if not h > 0:
        raise ctx.part.error(("max_step",), "the longest step must be positive")
    return h


CLAIMS = ("positive", "zero", "negative")


@quantity('lyapunov',
          book='positive (chaotic), zero (regular), negative, or the value of the largest '
               'exponent (`tolerance:` its ±, else 1e-8 of it)',
          how=('the tangent-map (Benettin) method along the motion from `initial:` over '
               '`time:` T at the problem\'s values (or `estimate:`\'s): one tangent vector of '
               'the variational equations renormalized in 64 windows; λ the growth over the '
               'second half per unit time, its spread s the difference of the last two '
               'quarters\' estimates, its resolution b = 8/T (a regular motion stays below). '
               'positive: passes where λ − s > b, fails only where the exponent is resolved '
               'negative (λ + s < −b); negative mirrors it; zero: |λ| + s ≤ b (fails where '
               '|λ| − s > b); a value v: passes where [λ − s, λ + s] lies within v ± '
               'tolerance, fails where it lies outside; otherwise unsupported, with the '
               '`time:` that would resolve it (a run of length T cannot tell zero from an '
               'exponent below b). An unbounded motion (a non-angle coordinate '
               'or a velocity past 1e4 times the start) is an error. `max_step:` bounds the '
               'steps (a drive in pulses shorter than the steps would be missed)'),
          literals=CLAIMS,
          keys={"initial": POINT, "time": EXPR, "tolerance": EXPR, "max_step": EXPR,
                "estimate": ESTIMATE})
def check_lyapunov(ctx: Context, val) -> Verdict:
    data = ctx.part.data
    pt, params = _values(ctx)
    if "time" not in data:
        raise ctx.part.error((), "a Lyapunov exponent needs `time:` (the run's length)")
    span = _number(ctx, data["time"], ("time",), pt)
    if not span > 0:
        raise ctx.part.error(("time",), "the run's length must be positive")
    y0 = _start(ctx, pt)
    stage = ctx.stage
    progress = None if stage is None else (
        lambda text: stage(f"part {ctx.part.name} (lyapunov): {text}"))
    try:
        run = largest_exponent(ctx.system, ctx.dyn, params, y0, span, progress=progress,
                               max_step=_max_step(ctx, pt))
    except UnboundedMotion as exc:
        raise ctx.part.error(("initial",), f"no Lyapunov exponent of a bounded motion: {exc}") \
            from None
    lam, s, b = run.estimate, run.spread, run.resolution
    method = f"Benettin (T = {span:g}: λ = {lam:.6g}, spread {s:.2g}, resolution {b:.2g})"
    if val in CLAIMS:
        return judge_exponent_sign(val, lam, s, b, span, method)
    claimed = _number(ctx, val, ("book",), pt)
    tol = (_number(ctx, data["tolerance"], ("tolerance",), pt) if "tolerance" in data
           else (ctx.sampler.rtol if "estimate" in data else RTOL) * max(abs(claimed), b))
    off = abs(lam - claimed)
    if off + s <= tol:  # all of [λ − s, λ + s] within the book's value ± tolerance
        return Verdict(True, method, power=f"the exponent to {tol:.2g}: |λ − v| + spread "
                                            f"{s:.2g} ≤ {tol:.2g}")
    if off - s > tol:  # all of [λ − s, λ + s] outside it
        return Verdict(False, method, f"λ = {lam:.10g} ± {s:.2g} (spread) lies outside "
                                      f"{claimed:.10g} ± {tol:.2g}")
    raise UnsupportedError(f"λ = {lam:.6g} with spread {s:.2g} neither lies within nor "
                           f"outside the claim {claimed:.6g} ± {tol:.2g} (T = {span:g}; a "
                           "longer `time:` converges further)")


def judge_exponent_sign(val: str, lam: float, s: float, b: float, span: float,
                        method: str) -> Verdict:
    """A sign claim judged against the run's resolution b = 8/T: `fail` only where the run
    resolves the opposite (a run of length T cannot tell zero from an exponent below b, so
    a weakly chaotic or sticky orbit claimed positive is unresolved, not contradicted).

    val: "positive", "zero" or "negative"; lam, s, b: the run's estimate, spread and
    resolution; span: its length T; method: the verdict's method text. Returns the
    Verdict; raises UnsupportedError (with b, λ, s, T and the `time:` that would resolve
    the claim) where the run can tell neither. Example:
    judge_exponent_sign("positive", -0.03, 0.002, 0.02, 400.0, "m").ok is False.
    """
    figures = f"λ = {lam:.4g}, spread {s:.2g}, T = {span:g}"
    if val == "zero":
        if abs(lam) + s <= b:
            # A zero pass bounds |λ|; it cannot tell zero from an exponent below b.
            return Verdict(True, method, power=f"zero to the run's resolution {b:.2g}: |λ| + "
                                                f"spread ≤ {b:.2g} (an exponent below it is "
                                                "not excluded; a longer `time:` resolves more)")
        if abs(lam) - s > b:
            return Verdict(False, method, f"the exponent is not zero at the run's resolution "
                                          f"{b:.2g}: λ = {lam:.6g} (spread {s:.2g})")
        raise UnsupportedError(f"the run cannot resolve the claim 'zero' at its resolution "
                               f"b = {b:.2g} ({figures}): {_longer(abs(lam) - s, b, span)}")
    sign = 1.0 if val == "positive" else -1.0
    if sign * lam - s > b:
        return Verdict(True, method, power=f"{val} beyond the run's resolution {b:.2g} and "
                                            f"spread {s:.2g}")
    if sign * lam + s < -b:
        other = "negative" if val == "positive" else "positive"
        return Verdict(False, method, f"the exponent is resolved {other}, not {val}: λ = "
                                      f"{lam:.6g} (spread {s:.2g}) beyond the run's "
                                      f"resolution {b:.2g}")
    side = "above" if val == "positive" else "below"
    bound = f"{b:.2g}" if val == "positive" else f"−{b:.2g}"
    raise UnsupportedError(f"the run resolves no exponent {side} the resolution b = {bound} "
                           f"({figures}); a {val} exponent of size below {b:.2g} is not "
                           f"excluded: {_longer(sign * lam - s, b, span)}")


def _longer(margin: float, b: float, span: float) -> str:
    """What run would resolve the claim: b = 8/T, so an exponent of size ε needs T > 8/ε."""
    if margin > 0:  # the run's own figures, if they hold, are resolved by T > 8/margin
        need = RESOLUTION / margin
        return (f"`time:` beyond {need:.4g} would resolve it if λ and its spread hold "
                f"(b = 8/T)")
    return (f"an exponent of size ε needs `time:` beyond 8/ε (b = 8/T; `time: {10 * span:g}` "
            f"resolves {b / 10:.2g})")
