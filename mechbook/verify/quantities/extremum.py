"""Where a quantity the engine computes is largest or smallest: `extremum`.

A part names what is maximized or minimized (`maximize:` or `minimize:`, one subject), the
variable it is taken over and where to look (`over: {omega: [lo, hi]}`, a parameter or an
answer symbol), and the book's location and value (`book: {at: ..., value: ...}`, either
or both). Subjects:

    amplitude: q       |A| of the steady response of a coordinate (or `define:` form) to
                       the harmonic force at `frequency:` (default: the variable itself)
    frequency: k       the k-th normal frequency, ascending (k = 1 the lowest)
    period: k          2π over it
    event: expr        with `initial:` (and `advance: q`): the time of the first sign
                       change of expr along the motion (or how far q has moved by then),
                       measured by integration; the variable may enter only the start
    energy_of: name    with `initial:` and `over: motion`: a part's energy along the
                       linearized motion (mechbook.engine.part_energy); its supremum (infimum)
                       over all later times, the maximum over the torus of mode phases

The engine's extremum is located by mechbook.engine.extremum (a grid over the interval for
the global candidate, golden sections, Newton on the derivative): to 30 digits and more
for the subjects computed in 60-digit arithmetic, and as well as the measurement allows
for a measured one. The claim that it is a maximum (or minimum) is checked by the global
scan and the sign of f″ there; a best value at an end of the interval, or a book location
elsewhere, fails. `limit:` compares an asymptotic formula as the other quantities do.
"""

from __future__ import annotations

import mpmath
import numpy as np
import sympy as sp

from mechbook.core.numeval import NotNumeric, evaluate_mp
from mechbook.core.words import plural
from mechbook.engine.extremum import Extremum, NoValue, locate, torus_maximum
from mechbook.engine.linear import mp_matrix, state_matrix
from mechbook.errors import UnsupportedError
from mechbook.numerics.measure import first_event, signal_functions
from mechbook.numerics.rhs import build_model
from mechbook.verify.asymptotic import asymptotic
from mechbook.verify.compare import Verdict
from mechbook.verify.context import Context
from mechbook.verify.quantities.parts import energy_at, linear_motion, part_energy_expr
from mechbook.verify.quantities.trajectory import initial_state
from mechbook.verify.registration import EXPR, LIMIT, POINT, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

POINTS = 3
DPS = 60
RTOL = 1e-20  # location and value, both sides in 60-digit arithmetic
MEASURED_RTOL = 1e-6  # a measured subject's value; its location to 1e-4 (the optimum is flat)
SUBJECT = {"type": "object", "minProperties": 1, "additionalProperties": False,
           "properties": {"amplitude": {"type": "string"},
                          "frequency": {"type": "integer", "minimum": 1},
                          "period": {"type": "integer", "minimum": 1},
                          "energy_of": {"type": "string"},
                          "event": EXPR, "advance": {"type": "string"}}}
OVER = {"oneOf": [{"const": "motion"},
                  {"type": "object", "minProperties": 1, "maxProperties": 1,
                   "additionalProperties": {"type": "array", "minItems": 2, "maxItems": 2,
                                            "items": EXPR}}]}


class _Subject:
    """The engine's function of the variable at one parameter point."""

    measured = False

    def __init__(self, ctx: Context, spec: dict, var: sp.Symbol | None):
        self.ctx, self.spec, self.var = ctx, spec, var
        kinds = [k for k in ("amplitude", "frequency", "period", "energy_of", "event")
                 if k in spec]
        if len(kinds) != 1:
            raise ctx.part.error((_key(ctx),), "name one thing to maximize or minimize: "
                                 "amplitude, frequency, period, event or energy_of")
        self.kind = kinds[0]
        if "advance" in spec and self.kind != "event":
            raise ctx.part.error((_key(ctx), "advance"), "`advance:` goes with `event:`")
        self.measured = self.kind == "event"

    # ---- 60-digit subjects of the linear system ---------------------------------------------
    def _matrices(self, pt: dict):
        lin = self.ctx.linear()
        dps = mpmath.mp.dps
        return lin, [mp_matrix(X, pt, dps) for X in (lin.M, lin.C, lin.K)]

    def frequencies(self, pt: dict) -> list:
        lin, (M, C, K) = self._matrices(pt)
        if lin.gyroscopic:
            lam = mpmath.eig(state_matrix(M, C, K), left=False, right=False)
            n = M.rows
            return sorted(abs(mpmath.im(x)) for x in sorted(lam, key=lambda x: -mpmath.im(x))[:n])
        L = mpmath.cholesky(M)
        Li = mpmath.inverse(L)
        S = Li * K * Li.T
        w2 = sorted(mpmath.eigsy((S + S.T) / 2)[0])
        if w2[0] < 0:
            raise NoValue("a squared frequency is negative (the point is unstable)")
        return [mpmath.sqrt(w) for w in w2]

    def amplitude(self, pt: dict):
        ctx = self.ctx
        lin, (M, C, K) = self._matrices(pt)
        if not lin.driven:
            raise ctx.part.error((_key(ctx), "amplitude"), "the linearized system has no "
                                 "driving force")
        name = self.spec["amplitude"]
        if name in lin.coord_names:
            row = [mpmath.mpf(int(c == name)) for c in lin.coord_names]
        elif name in (ctx.part.data.get("define") or {}):
            row = [evaluate_mp(g, pt, mpmath.mp.dps) for g in lin.gradient(ctx.names[name])]
        else:
            raise ctx.part.error((_key(ctx), "amplitude"), f"{name!r} is neither a coordinate "
                                 "nor a `define:` name")
        w = evaluate_mp(self.driving, pt, mpmath.mp.dps)
        t = lin.dyn.sys.t
        F = [f for f in lin.F]

        def force(tv):
            return [mpmath.re(evaluate_mp(f, {**pt, t: sp.Float(tv, mpmath.mp.dps)},
                                          mpmath.mp.dps)) for f in F]

        a, b = force(mpmath.mpf(0)), force(mpmath.pi / (2 * w))
        phasor = mpmath.matrix([a[i] - 1j * b[i] for i in range(len(F))])
        for tv in (mpmath.mpf("0.37") / w, mpmath.mpf("2.9") / w):
            got = force(tv)
            for i in range(len(F)):
                want = mpmath.re(phasor[i] * mpmath.expj(w * tv))
                if abs(got[i] - want) > mpmath.mpf(10) ** (-mpmath.mp.dps // 2) * (
                        max(abs(x) for x in phasor) + 1e-300):
                    raise UnsupportedError("steady response: the force is not harmonic at "
                                           "the driving frequency")
        H = K - w**2 * M + 1j * w * C
        X = mpmath.lu_solve(H, phasor)
        return abs(sum(row[i] * X[i] for i in range(len(row))))

    def value(self, pt: dict, x) -> mpmath.mpf:
        """The subject at the parameter point with the variable at x."""
        at = dict(pt)
        at[self.var] = sp.Float(x, mpmath.mp.dps)
        if self.kind == "amplitude":
            return self.amplitude(at)
        if self.kind in ("frequency", "period"):
            k = self.spec[self.kind]
            freqs = self.frequencies(at)
            if k > len(freqs):
                raise self.ctx.part.error((_key(self.ctx), self.kind), f"the system has "
                                          f"{len(freqs)} frequencies")
            w = freqs[k - 1]
            return w if self.kind == "frequency" else 2 * mpmath.pi / w
        return mpmath.mpf(self._measured(at))

    @property
    def driving(self) -> sp.Expr:
        ctx = self.ctx
        if "frequency" in ctx.part.data:
            return ctx.parse(ctx.part.data["frequency"], ("frequency",))
        return self.var

    # ---- a measured subject (an event along the full motion) ---------------------------------
    def prepare_measured(self, pt: dict) -> None:
        ctx, sys = self.ctx, self.ctx.system
        if self.var is not None and any(e.has(self.var) for e in ctx.dyn.residuals):
            raise UnsupportedError("a measured extremum over a parameter of the equations of "
                                   "motion (only over the start)")
        event = ctx.parse(self.spec["event"], (_key(ctx), "event"))
        params = {k: float(v) for k, v in pt.items() if k in sys.problem.values()}
        self._model = build_model(sys, ctx.dyn, params)
        self._fn = signal_functions(sys, ctx.dyn, pt, event.subs(pt))
        self._start = initial_state(ctx)
        name = self.spec.get("advance")
        if name is not None and name not in sys.coord_names:
            raise ctx.part.error((_key(ctx), "advance"), f"{name!r} is not a coordinate")
        self._advance = None if name is None else sys.coord_names.index(name)

    def _measured(self, at: dict) -> float:
        sys = self.ctx.system
        st = {k: complex(sp.N(v.subs(at), 20)).real for k, v in self._start.items()}
        q0 = np.array([st[q] for q in sys.q])
        qd0 = np.array([st[v] for v in sys.qd])
        t, y = first_event(self._model, self._fn, q0, qd0,
                           1.0 / (1.0 + float(np.max(np.abs(qd0)))))
        return t if self._advance is None else float(y[self._advance] - q0[self._advance])


def _key(ctx: Context) -> str:
    return "maximize" if "maximize" in ctx.part.data else "minimize"


def _setup(ctx: Context, val):
    data = ctx.part.data
    if ("maximize" in data) == ("minimize" in data):
        raise ctx.part.error((), "give `maximize:` or `minimize:` (what is extreme)")
    kind = "maximum" if "maximize" in data else "minimum"
    spec = ctx.as_map(data[_key(ctx)], (_key(ctx),))
    book = ctx.as_map(val, ("book",))
    if not book or set(book) - {"at", "value"}:
        raise ctx.part.error(("book",), "the book's extremum is `{at: location, value: "
                             "value}` (either or both)")
    over = data.get("over")
    if over is None:
        raise ctx.part.error((), "say what the extremum is over: `over: {variable: [from, "
                             "to]}` or `over: motion`")
    return kind, spec, book, over


@quantity('extremum',
          book='`{at: location, value: value}` (either or both)',
          how=('the engine locates the global maximum or minimum (`maximize:` or `minimize:` '
               'one of `amplitude: q` at `frequency:`, `frequency: k`, `period: k`, '
               '`event:` with `initial:` (measured), `energy_of: part` with `initial:`) over '
               '`over: {variable: [from, to]}` (a grid, golden sections, Newton on the '
               'derivative, in 60-digit arithmetic: location to 1e-30 and better) or, for a '
               "part's energy, over the whole later motion (`over: motion`, the maximum "
               'over the torus of mode phases); location and value equal the book\'s to '
               '1e-20 (measured: 1e-4 and 1e-6) at 3 points, f″ has the sign of the claim, '
               'a best value at an end of the interval fails; `limit:` for asymptotic '
               'formulas'),
          keys={"maximize": SUBJECT, "minimize": SUBJECT, "over": OVER, "frequency": EXPR,
                "initial": POINT, "limit": LIMIT})
def check_extremum(ctx: Context, val) -> Verdict:
    kind, spec, book, over = _setup(ctx, val)
    if over == "motion":
        return _over_motion(ctx, kind, spec, book)
    if not isinstance(over, dict) or len(over) != 1:
        raise ctx.part.error(("over",), "`over:` names one variable and its interval")
    (name, bounds), = over.items()
    var = ctx.names.get(name)
    if not isinstance(var, sp.Symbol) or var not in ctx.sampler.base:
        raise ctx.part.error(("over", name), f"{name!r} is not a parameter or answer symbol")
    lo_e, hi_e = (ctx.parse(b, ("over", name, i)) for i, b in enumerate(bounds))
    if lo_e.has(var) or hi_e.has(var):
        raise ctx.part.error(("over", name), "the interval's ends do not depend on the variable")
    at_e = ctx.parse(book["at"], ("book", "at")) if "at" in book else None
    value_e = ctx.parse(book["value"], ("book", "value")) if "value" in book else None
    for e, where in ((at_e, "at"), (value_e, "value")):
        if e is not None and e.has(var):
            raise ctx.part.error(("book", where), f"the book's {where} cannot depend on "
                                 f"{name} (the variable the extremum is over)")
    subject = _Subject(ctx, spec, var)
    bounds_seen: list = []
    dps = 20 if subject.measured else DPS
    res = 1e-11 if subject.measured else None

    def engine(pt) -> Extremum:
        if subject.measured:
            subject.prepare_measured(pt)
        with mpmath.workdps(dps):
            lo, hi = (mpmath.re(evaluate_mp(e, pt, dps)) for e in (lo_e, hi_e))
        bounds_seen[:] = [lo, hi]
        try:
            return locate(lambda x: subject.value(pt, x), lo, hi, kind, resolution=res,
                          dps=dps)
        except NoValue as exc:
            raise UnsupportedError(f"the {kind} over {name}: {exc}") from None

    def errors(pt, ext) -> tuple[float, float, str]:
        """Relative errors of the book's location and value, and a message."""
        with mpmath.workdps(dps):
            scale = max(abs(ext.x), mpmath.mpf(10) ** -30)
            e_at = e_val = 0.0
            parts = []
            if at_e is not None:
                b = _real(at_e, pt, dps)
                e_at = _relative(b, ext.x, scale)
                parts.append(f"at {mpmath.nstr(b, 15)} (engine {mpmath.nstr(ext.x, 15)})")
            if value_e is not None:
                b = _real(value_e, pt, dps)
                e_val = _relative(b, ext.value)
                parts.append(f"value {mpmath.nstr(b, 15)} (engine "
                             f"{mpmath.nstr(ext.value, 15)})")
            return e_at, e_val, "; ".join(parts)

    if "limit" in ctx.part.data:
        def error(pt) -> float:
            ext = engine(pt)
            if not ext.interior:
                return float("inf")
            return max(errors(pt, ext)[:2])

        return asymptotic(ctx, error, floor=None if subject.measured else 1e-40)
    tol_at = 1e-4 if subject.measured else RTOL
    tol_val = MEASURED_RTOL if subject.measured else RTOL
    worst_at = worst_val = 0.0
    for k in range(1, POINTS + 1):
        pt = ctx.sampler.draw()
        ext = engine(pt)
        if not ext.interior:
            return Verdict(False, f"numeric({plural(k, 'point')})",
                           f"the engine's {kind} over [{_n(bounds_seen[0])}, "
                           f"{_n(bounds_seen[1])}] is at an end of the interval ({name} = "
                           f"{_n(ext.x)}, value {_n(ext.value)}): the "
                           "book's point is not the extremum there, or widen `over:`")
        sign_ok = ext.curvature < 0 if kind == "maximum" else ext.curvature > 0
        if not sign_ok:
            return Verdict(False, f"numeric({plural(k, 'point')})", f"f'' = {_n(ext.curvature)} at "
                           f"{name} = {_n(ext.x)}: not a strict {kind}")
        e_at, e_val, msg = errors(pt, ext)
        worst_at, worst_val = max(worst_at, e_at), max(worst_val, e_val)
        if e_at > tol_at or e_val > tol_val:
            other = f"; other local {kind}s at {', '.join(_n(x) for x, _ in ext.others)}" \
                if ext.others else ""
            return Verdict(False, f"numeric({plural(k, 'point')})",
                           f"{kind} over {name}: {msg}: relative errors {e_at:.2g}, "
                           f"{e_val:.2g}{other}")
    what = " and ".join(w for w in ("at", "value") if w in book)
    how = "measured" if subject.measured else f"{DPS} digits"
    return Verdict(True, f"numeric({POINTS} points, {how})",
                   f"worst relative errors: location {worst_at:.2g}, value {worst_val:.2g}",
                   power=f"{POINTS} points ({how}): the {kind}'s {what} within "
                         f"{tol_at if 'at' in book else tol_val:g}, f'' of the claimed sign, "
                         "the global best over the interval")


def _over_motion(ctx: Context, kind: str, spec: dict, book: dict) -> Verdict:
    """The supremum (infimum) over all later times of a part's energy along the linearized
    motion: the maximum over the torus of the modes' phases."""
    if set(spec) != {"energy_of"}:
        raise ctx.part.error((_key(ctx),), "over the motion the subject is a part's energy "
                             "(`energy_of: name`)")
    if "at" in book or "value" not in book:
        raise ctx.part.error(("book",), "over the motion the book gives the extreme `value:` "
                             "(a time is not a location: the motion comes back near it)")
    energy = part_energy_expr(ctx, spec["energy_of"], (_key(ctx), "energy_of"))
    value_e = ctx.parse(book["value"], ("book", "value"))
    s = 1 if kind == "maximum" else -1

    def extreme(pt):
        motion = linear_motion(ctx, pt)
        n, y, W = motion.torus()
        at = energy_at(ctx, energy, pt)
        _, v = torus_maximum(lambda th: s * at(y(th)), n,
                             scan=lambda th: s * at.scan(2 * np.real(np.exp(1j * th) @ W)))
        return s * v

    def error(pt) -> float:
        with mpmath.workdps(45):
            e = extreme(pt)
            return _relative(_real(value_e, pt, 45), e)

    if "limit" in ctx.part.data:
        return asymptotic(ctx, error, floor=1e-30)
    worst = 0.0
    for k in range(1, POINTS + 1):
        pt = ctx.sampler.draw()
        err = error(pt)
        worst = max(worst, err)
        if not err <= RTOL:
            return Verdict(False, f"numeric({plural(k, 'point')})",
                           f"the {kind} of {spec['energy_of']}'s "
                           f"energy over the motion: relative error {err:.2g}")
    return Verdict(True, f"numeric({POINTS} points, torus of phases, 40 digits)",
                   f"worst relative {worst:.2g}",
                   power=f"{POINTS} points at 40 digits within {RTOL:g}")


def _real(e: sp.Expr, pt: dict, dps: int):
    try:
        v = evaluate_mp(e, pt, dps)
    except (NotNumeric, ZeroDivisionError, ValueError, TypeError) as exc:
        raise UnsupportedError(f"the book's value does not evaluate: {exc}") from None
    if abs(mpmath.im(v)) > mpmath.mpf(10) ** (-dps // 2) * max(1, abs(v)):
        return mpmath.nan
    return mpmath.re(v)


def _relative(book, engine, scale=None) -> float:
    """|book − engine| / scale (default |engine|); infinite where the book has no value."""
    if not mpmath.isfinite(book):
        return float("inf")
    scale = max(abs(engine) if scale is None else scale, mpmath.mpf(10) ** -300)
    return float(abs(book - engine) / scale)


def _n(x) -> str:
    return mpmath.nstr(x, 12)
