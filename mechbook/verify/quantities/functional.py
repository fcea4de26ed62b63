"""Quantities of a declared functional (`functional:`, mechbook/model/functional.py): the
Euler–Lagrange equations, the book's curve as an extremal meeting the end conditions, its
first integrals, the functional's value on it, and whether it is a minimum.

A curve is written in a part as `{y: "c*cosh(x/c)"}` (explicit, y(x)) or `{parameter:
theta, x: "a*(theta - sin(theta))", y: "a*(1 - cos(theta))"}` (parametric), with optional
`multipliers: {length: expr}` (λ of an isoperimetric constraint). `solve_for: {a: 0.57,
theta1: 2.4}` names the curve's constants fixed by the end conditions, each with a start
for Gauss–Newton at the problem's default values; `range: [0, theta1]` the parameter's
values at the two ends (default: the ends' x). At a sampled point the constants are
followed from the default values in straight steps, so a branch the start picks (the
shallow catenoid, not the deep one) is the branch checked everywhere.
"""

from __future__ import annotations

import mpmath
import sympy as sp

from mechbook.engine import curve as cv
from mechbook.engine.variational import (
    augmented,
    beltrami,
    euler_lagrange,
    noether,
    on_shell_rate,
    solved_top,
    top_derivatives,
)
from mechbook.errors import UnsupportedError
from mechbook.model.functional import Functional
from mechbook.verify.compare import Verdict, all_vanish, combine, equal
from mechbook.verify.context import Context, strip_const
from mechbook.verify.registration import EXPR, NAME, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

CURVE = {"type": "object", "minProperties": 1,
         "properties": {"parameter": NAME,
                        "multipliers": {"type": "object", "additionalProperties": EXPR}},
         "additionalProperties": EXPR}
RANGE = {"type": "array", "minItems": 2, "maxItems": 2, "items": EXPR}
CONSTANTS = {"type": "object", "maxProperties": 8,
             "propertyNames": {"pattern": "^[A-Za-z][A-Za-z0-9_]*$"},
             "additionalProperties": {"type": "number"}}
SYMMETRY = {"type": "object", "minProperties": 1, "additionalProperties": EXPR}
CURVE_KEYS = {"curve": CURVE, "range": RANGE, "solve_for": CONSTANTS}
POINTS = 2  # parameter points a curve is checked at: the default values and a draw
VANISH = 1e-18  # a residual at 30 digits, relative to what cancelled in it
STATIONARY = 1e-9  # |J′(0)| relative to |J(0)| + |J″(0)| on the perturbed curves
MINIMUM = ("minimum", "not a minimum")


def functional(ctx: Context) -> Functional:
    fn = ctx.analysis.functional()
    if fn is None:
        raise ctx.part.error(("quantity",), f"{ctx.part.quantity!r} needs a `functional:` "
                             "in the problem file")
    return fn


def jet_names(ctx: Context) -> dict:
    """The names a functional's answer may use: the part's, x, y, y′, …, the multipliers."""
    fn = ctx.analysis.functional()
    names = dict(ctx.names)
    if fn is not None:
        names.update(fn.names())
    return names


# ---- the equations and first integrals -----------------------------------------------------
@quantity('euler_lagrange',
          book='list of equations, one per function of the functional',
          how=('the Euler–Lagrange equations Σₖ(−d/dx)ᵏ ∂F̃/∂y⁽ᵏ⁾ = 0 of the `functional:` '
               '(F̃ = F + Σλ·G + Σμ·φ with its constraints\' multipliers `lambda_<name>`, '
               '`mu_<name>`), both sides solved for the highest derivatives (y″ of F(x, y, '
               'y′)), agree at random points of x, y, y′ and the parameters: any '
               'rearrangement or combination of the book\'s equations passes'),
          names=jet_names, needs_system=False)
def check_euler_lagrange(ctx: Context, val) -> Verdict:
    fn = functional(ctx)
    names = jet_names(ctx)
    book = [ctx.parse(v, ("book", i), equation=True, names=names)
            for i, v in enumerate(ctx.as_list(val, ("book",)))]
    if len(book) != len(fn.functions):
        raise ctx.part.error(("book",), f"give {len(fn.functions)} equation(s), one per "
                             "function")
    top = top_derivatives(fn)
    engine = solved_top(euler_lagrange(fn), top)
    try:
        theirs = solved_top([_lhs(e) for e in book], top)
    except UnsupportedError as exc:
        return Verdict(False, "symbolic", f"the book's equations: {exc.capability}")
    return combine([equal(theirs[s], engine[s], ctx.sampler) for s in top])


def _lhs(e) -> sp.Expr:
    return e.lhs - e.rhs if isinstance(e, sp.Equality) else e


@quantity('functional_integral',
          book='expression in x, y, y′ (`… = const` allowed)',
          how=('a first integral of the Euler–Lagrange equations: its total derivative, '
               'with y″ from the equations, vanishes at random points of x, y, y′ and the '
               'parameters, and it is a function of the engine\'s integral (their '
               'gradients in x, y, y′ are parallel): Beltrami\'s F̃ − y′·∂F̃/∂y′ when F '
               'holds no x, else Noether\'s Σ∂F̃/∂y′·(η − y′ξ) + F̃ξ of the generator '
               '`symmetry: {x: ξ, y: η}`, whose invariance is checked first'),
          keys={"symmetry": SYMMETRY}, names=jet_names, needs_system=False,
          equivalent=("function",))
def check_functional_integral(ctx: Context, val) -> Verdict:
    fn = functional(ctx)
    names = jet_names(ctx)
    book = ctx.parse(strip_const(val), ("book",), names=names)
    sym = ctx.part.data.get("symmetry")
    checks = []
    if sym is None:
        engine = beltrami(fn)
    else:
        known = [str(fn.x), *fn.functions]
        extra = sorted(set(sym) - set(known))
        if extra:
            raise ctx.part.error(("symmetry", extra[0]), "a generator's components are "
                                 f"given for {', '.join(known)}")
        comp = {k: ctx.parse(sym.get(k, "0"), ("symmetry", k), names=names) for k in known}
        residual, engine = noether(fn, comp[str(fn.x)], [comp[f] for f in fn.functions])
        invariant = all_vanish([residual], ctx.sampler)
        if not invariant.ok:
            return Verdict(False, invariant.method, "the generator is not a symmetry of the "
                           f"functional: {invariant.detail}")
        checks.append(invariant)
    jet = [fn.x, *fn.function_symbols(0), *fn.function_symbols(1)]
    if not any(sp.diff(book, s) != 0 for s in jet):
        return Verdict(False, "symbolic", "the book's integral is a constant")
    checks.append(all_vanish([on_shell_rate(fn, book)], ctx.sampler))
    gb = [sp.diff(book, s) for s in jet]
    ge = [sp.diff(engine, s) for s in jet]
    minors = [gb[i] * ge[j] - gb[j] * ge[i] for i in range(len(jet))
              for j in range(i + 1, len(jet))]
    checks.append(all_vanish(minors, ctx.sampler))
    return combine(checks)


# ---- a curve: its constants at a point -------------------------------------------------------
class CurveSpec:
    """A part's curve with its constants, range and multipliers, parsed once."""

    def __init__(self, ctx: Context, spec, sub: tuple):
        self.fn = fn = functional(ctx)
        spec = ctx.as_map(spec, sub)
        consts = ctx.as_map(ctx.part.data.get("solve_for") or {}, ("solve_for",))
        names = dict(ctx.names)
        for k in consts:
            if k in names or k in fn.names():
                raise ctx.part.error(("solve_for", k), f"{k!r} is already a name")
            names[k] = sp.Symbol(k, real=True)
        self.constants = [names[k] for k in consts]
        self.start = {names[k]: v for k, v in consts.items()}
        param = spec.get("parameter")
        x = str(fn.x)
        if param is None:
            s = fn.x
            xs = fn.x
            if x in spec:
                raise ctx.part.error(sub + (x,), f"an explicit curve gives the functions of "
                                     f"{x}; a parametric one names its `parameter:`")
        else:
            if param in names or param in fn.names():
                raise ctx.part.error(sub + ("parameter",), f"{param!r} is already a name")
            s = sp.Symbol(param, real=True)
            if x not in spec:
                raise ctx.part.error(sub, f"a parametric curve gives {x} as a function of "
                                     f"{param}")
        local = dict(names)
        local[str(s)] = s
        if param is not None:
            xs = ctx.parse(spec[x], sub + (x,), names=local)
        extra = sorted(set(spec) - {"parameter", "multipliers", x, *fn.functions})
        if extra:
            raise ctx.part.error(sub + (extra[0],), f"{extra[0]!r} is not a function of the "
                                 f"functional ({', '.join(fn.functions)})")
        missing = [f for f in fn.functions if f not in spec]
        if missing:
            raise ctx.part.error(sub, f"the curve gives every function ({missing[0]!r} is "
                                 "missing)")
        ys = [ctx.parse(spec[f], sub + (f,), names=local) for f in fn.functions]
        mults = {}
        bynames = {c.name: c for c in fn.constraints}
        for k, v in (spec.get("multipliers") or {}).items():
            if k not in bynames:
                raise ctx.part.error(sub + ("multipliers", k), f"{k!r} is not a constraint "
                                     "of the functional")
            if bynames[k].kind != "integral":
                raise ctx.part.error(sub + ("multipliers", k), "a holonomic constraint's "
                                     "multiplier is a function, found along the curve")
            mults[bynames[k].multiplier] = ctx.parse(v, sub + ("multipliers", k), names=names)
        self.multipliers = mults
        if "range" in ctx.part.data:
            ends = tuple(ctx.parse(v, ("range", i), names=names)
                         for i, v in enumerate(ctx.part.data["range"]))
        elif param is None:
            ends = (fn.ends[0].at, fn.ends[1].at)
        else:
            raise ctx.part.error(sub, "a parametric curve needs `range:`, its parameter's "
                                 "values at the two ends")
        self.curve = cv.Curve(s, xs, ys, ends, self.constants)
        self.names = names
        self.conditions = cv.conditions(fn, self.curve, mults)
        self.ctx = ctx

    def unknowns(self) -> list[sp.Symbol]:
        """The constants the end conditions fix (the multipliers not given follow)."""
        return self.constants

    def points(self) -> list[tuple[dict, dict | None]]:
        """(parameter values, the unknowns there or None) at the default values and at
        POINTS − 1 sampled ones; kept by the analysis, so the parts that share a curve
        (its extremal, value, minimum) solve its constants once."""
        key = ("functional curve", self.curve.x, tuple(self.curve.ys), self.curve.ends,
               tuple(sorted((str(k), v) for k, v in self.start.items())),
               tuple(sorted((str(k), v) for k, v in self.multipliers.items())),
               tuple(sorted((str(k), v) for k, v in self.ctx.sampler.base.items())),
               tuple(map(str, self.ctx.sampler.conditions)))
        return self.ctx.analysis.reuse(key, self._points)

    def _points(self) -> list[tuple[dict, dict | None]]:
        base = {k: sp.Float(v, 30) for k, v in self.ctx.sampler.base.items()}
        out = [(base, cv.solve_unknowns(self.conditions, self.curve, self.unknowns(),
                                        self.start, base) if self.unknowns() else {})]
        if out[0][1] is None:
            return out
        for _ in range(POINTS - 1):
            pt = self.ctx.sampler.draw()
            pt = {k: v for k, v in pt.items() if k in base}
            got = cv.continued(self.conditions, self.curve, self.unknowns(),
                               {**out[0][1]}, base, pt)
            out.append((pt, got))
        return out

    def at(self, params: dict, unknowns: dict) -> dict:
        """The point: parameters, constants, the multipliers (given or solved)."""
        pt = {**params, **unknowns}
        for m, e in self.multipliers.items():
            pt[m] = cv.mp_value(e, pt)
        pt.update(cv.multipliers_at(self.conditions, pt))
        return pt


def _solved_points(spec: CurveSpec) -> list[dict]:
    """The points where the constants were found; UnsupportedError if not at the default."""
    out = []
    for params, unknowns in spec.points():
        if unknowns is None:
            if not out:
                names = ", ".join(map(str, spec.unknowns()))
                raise UnsupportedError(f"no values of {names} near the key's start make the "
                                       "curve meet its end conditions at the default "
                                       "parameter values (Gauss–Newton did not converge)")
            continue
        out.append(spec.at(params, unknowns))
    return out


# ---- the extremal -----------------------------------------------------------------------------
@quantity('extremal',
          book='a curve: `{y: expr}` (y(x)) or `{parameter: s, x: expr, y: expr}`, with '
               '`multipliers:` if any, or `{implicit: G}` (G(x, y) = 0)',
          how=('the curve\'s constants `solve_for:` (and the isoperimetric multipliers it '
               'does not give) are solved by Gauss–Newton at 30 digits from the end conditions '
               '(each end\'s x, the fixed values, ∂F̃/∂y′ = 0 at a free end), the '
               'constraints\' integrals, and the Euler–Lagrange residuals at six interior '
               'points; every residual must then vanish to 1e-18 of its scale, at the '
               'default values and a sampled point (the constants followed there by '
               'continuation). Second computation: the functional on perturbed curves y + '
               'εη (η vanishing at fixed ends; two variations per function) at 30 digits: '
               'its first variation J′(0) (central difference, ε = 1e-5) vanishes to 1e-9 of |J| + '
               '|J″|. An implicit curve (one function, no constraints): the ends on it, and '
               'Euler–Lagrange with y′, y″ by implicit differentiation at six points of it '
               '(y by Newton from the chord)'),
          keys={"range": RANGE, "solve_for": CONSTANTS}, names=jet_names, needs_system=False)
def check_extremal(ctx: Context, val) -> Verdict:
    if isinstance(val, dict) and "implicit" in val:
        return _implicit_extremal(ctx, val)
    spec = CurveSpec(ctx, val, ("book",))
    if ctx.validate_only:
        return Verdict(True, "validated")
    try:
        points = _solved_points(spec)
    except UnsupportedError:
        not_extremal = _not_extremal_at_start(spec)
        if not_extremal is None:
            raise
        return not_extremal
    for pt in points:
        for name, v, scale in cv.residuals(spec.conditions, spec.curve, pt):
            if abs(v) > VANISH * scale:
                return Verdict(False, f"numeric({len(points)} points, 30 digits)",
                               f"{name} is {mpmath.nstr(abs(v), 3)} (scale "
                               f"{scale:.3g}) at {_fmt(pt)}")
    first = _first_variation(spec, points[0])
    if first is not None:
        return first
    solved = ", ".join(map(str, spec.unknowns() + spec.conditions.multipliers)) or "none"
    power = (f"{len(points)} parameter points (constants solved: {solved}); end conditions, "
             f"integrals and Euler–Lagrange at 6 interior points to {VANISH:g} of their "
             "scale; " + ("on a holonomic constraint: no perturbed curves" if any(
                 c.kind == "holonomic" for c in spec.fn.constraints) else
                 f"first variation on {2 * len(spec.fn.functions)} perturbed curves ≤ "
                 f"{STATIONARY:g}"))
    return Verdict(True, f"numeric({len(points)} points, 30 digits)", power=power)


def _implicit_extremal(ctx: Context, val: dict) -> Verdict:
    """`{implicit: G}`: the curve G(x, y) = 0 meets the fixed ends (its constants solved
    there) and the Euler–Lagrange residual, with y′ and y″ by implicit differentiation,
    vanishes at six points of it between the ends (y found by Newton from the chord)."""
    fn = functional(ctx)
    if len(fn.functions) != 1 or fn.order != 1 or fn.constraints:
        raise UnsupportedError("an implicit curve other than G(x, y) = 0 of one function of "
                               "an integrand F(x, y, y′) without constraints")
    extra = sorted(set(val) - {"implicit"})
    if extra:
        raise ctx.part.error(("book", extra[0]), "an implicit curve is `{implicit: G}`")
    consts = ctx.as_map(ctx.part.data.get("solve_for") or {}, ("solve_for",))
    names = dict(ctx.names)
    for k in consts:
        if k in names or k in fn.names():
            raise ctx.part.error(("solve_for", k), f"{k!r} is already a name")
        names[k] = sp.Symbol(k, real=True)
    constants = [names[k] for k in consts]
    x, y = fn.x, fn.jets[0][0]
    G = ctx.parse(val["implicit"], ("book", "implicit"), names={**names, str(x): x, str(y): y})
    if ctx.validate_only:
        return Verdict(True, "validated")
    if any(e.values[fn.functions[0]] is None for e in fn.ends):
        raise UnsupportedError("a free end of an implicit curve")
    ends = [G.xreplace({x: e.at, y: e.values[fn.functions[0]]}) for e in fn.ends]
    cond = cv.Conditions([f"the curve at end {i + 1}" for i in range(2)], ends, [], [], [],
                         [])
    E = euler_lagrange(fn)[0].xreplace(cv.implicit_jets(G, fn))
    curve = cv.Curve(x, x, [y], (fn.ends[0].at, fn.ends[1].at), constants)
    base = {k: sp.Float(v, 30) for k, v in ctx.sampler.base.items()}
    start = {names[k]: v for k, v in consts.items()}
    solved = cv.solve_unknowns(cond, curve, constants, start, base) if constants else {}
    if solved is None:
        raise UnsupportedError("no constants near the key's start put the ends on the curve")
    points = [{**base, **solved}]
    drawn = {k: v for k, v in ctx.sampler.draw().items() if k in base}
    again = cv.continued(cond, curve, constants, solved, base, drawn) if constants else {}
    if again is not None:
        points.append({**drawn, **again})
    for pt in points:
        for name, e in zip(cond.names, ends, strict=True):
            v, scale = cv.evaluate(e, pt, cv.DIGITS)
            if abs(v) > VANISH * max(scale, 1e-300):
                return Verdict(False, f"numeric({len(points)} points, 30 digits)",
                               f"{name}: G = {abs(v):.3g} at {_fmt(pt)}")
        xa, xb = (cv.mp_value(e.at, pt) for e in fn.ends)
        ya, yb = (cv.mp_value(e.values[fn.functions[0]], pt) for e in fn.ends)
        for t in cv.INTERIOR:
            t = mpmath.mpf(str(t))
            xt = xa + t * (xb - xa)
            yt = cv.on_implicit(G, fn, pt, xt, ya + t * (yb - ya))
            if yt is None:
                raise UnsupportedError(f"no point of the curve found at {x} = "
                                       f"{mpmath.nstr(xt, 8)} (Newton from the chord)")
            v, scale = cv.evaluate(E, {**pt, x: xt, y: yt}, cv.DIGITS)
            if abs(v) > VANISH * max(scale, 1e-300):
                return Verdict(False, f"numeric({len(points)} points, 30 digits)",
                               f"Euler–Lagrange at ({x}, {y}) = ({mpmath.nstr(xt, 8)}, "
                               f"{mpmath.nstr(yt, 8)}) is {abs(v):.3g} (scale {scale:.3g}) "
                               f"at {_fmt(pt)}")
    return Verdict(True, f"numeric({len(points)} points, 30 digits)",
                   power=f"{len(points)} parameter points: the ends on the curve and "
                         f"Euler–Lagrange (y′, y″ implicit) at 6 points of it to {VANISH:g} "
                         "of their scale; no perturbed curves")


def _not_extremal_at_start(spec: CurveSpec) -> Verdict | None:
    """Where no constants near the key's start meet the end conditions: a fail if the curve
    is no extremal at the start either (an Euler–Lagrange residual that does not vanish),
    else None (the part is then unsupported: an extremal the ends cannot be fitted to)."""
    base = {k: sp.Float(v, 30) for k, v in spec.ctx.sampler.base.items()}
    pt = spec.at(base, {k: mpmath.mpf(str(v)) for k, v in spec.start.items()})
    for name, e in zip(spec.conditions.el_names, spec.conditions.el, strict=True):
        v, scale = cv.evaluate(e, pt, cv.DIGITS)
        if abs(v) > VANISH * max(scale, 1e-300):
            return Verdict(False, "numeric(the key's start, 30 digits)",
                           "no constants near the key's start make the curve meet its end "
                           f"conditions, and it is no extremal there: {name} is "
                           f"{abs(v):.3g} (scale {scale:.3g}) at {_fmt(pt)}")
    return None


def _first_variation(spec: CurveSpec, pt: dict) -> Verdict | None:
    """A fail if the functional is not stationary at the curve on perturbed curves (none
    on a holonomic constraint: a perturbed curve leaves the surface)."""
    if any(c.kind == "holonomic" for c in spec.fn.constraints):
        return None
    F = augmented(spec.fn).xreplace({m: pt[m] for m in spec.fn.names().values() if m in pt})
    for p in cv.perturbed(spec.fn, spec.curve, pt, F):
        scale = abs(p.value) + abs(p.curvature)
        if abs(p.slope) > STATIONARY * scale:
            return Verdict(False, "numeric(perturbed curves, 30 digits)",
                           f"the first variation along {p.label} is "
                           f"{mpmath.nstr(p.slope, 3)} (J = {mpmath.nstr(p.value, 8)}, J″ = "
                           f"{mpmath.nstr(p.curvature, 3)}): the curve is not stationary")
    return None


def _fmt(pt: dict) -> str:
    return ", ".join(f"{k} = {mpmath.nstr(mpmath.re(v), 8)}" for k, v in
                     sorted(pt.items(), key=lambda kv: str(kv[0])) if not str(k).startswith("_"))


# ---- the value on the extremal ----------------------------------------------------------------
@quantity('functional_value',
          book='expression in the parameters and the curve\'s constants',
          how=('∫F dx along the curve `curve:` (its constants solved as for `extremal`; '
               '`constraint: <name>` integrates that constraint\'s G instead, e.g. a '
               'length) by tanh-sinh quadrature at 30 digits (integrable end singularities '
               'allowed), equal to the book\'s to 1e-15, at the default values and a '
               'sampled point'),
          keys={**CURVE_KEYS, "constraint": {"type": "string"}}, needs_system=False)
def check_functional_value(ctx: Context, val) -> Verdict:
    if "curve" not in ctx.part.data:
        raise ctx.part.error(("quantity",), "a `functional_value` part gives its `curve:`")
    spec = CurveSpec(ctx, ctx.part.data["curve"], ("curve",))
    book = ctx.parse(val, ("book",), names=spec.names)
    if ctx.validate_only:
        return Verdict(True, "validated")
    fn = spec.fn
    integrand = fn.integrand
    if "constraint" in ctx.part.data:
        which = {c.name: c for c in fn.constraints if c.kind == "integral"}
        name = ctx.part.data["constraint"]
        if name not in which:
            raise ctx.part.error(("constraint",), f"{name!r} is not an integral constraint "
                                 "of the functional")
        integrand = which[name].expr
    f_s = cv.functional_integrand(fn, spec.curve, integrand)
    points = _solved_points(spec)
    for pt in points:
        got, err = cv.integral(f_s, spec.curve, pt)
        want = cv.mp_value(book, pt)
        rel = abs(got - want) / max(abs(got), abs(want), mpmath.mpf(10) ** -300)
        if rel > 1e-15:
            return Verdict(False, f"numeric({len(points)} points, 30 digits)",
                           f"the functional is {mpmath.nstr(got, 15)} on the curve, the "
                           f"book's {mpmath.nstr(want, 15)} (relative {mpmath.nstr(rel, 3)})"
                           f" at {_fmt(pt)}")
    return Verdict(True, f"numeric({len(points)} points, 30 digits)",
                   power=f"{len(points)} parameter points, quadrature at 30 digits, "
                         "relative 1e-15")


# ---- a minimum ----------------------------------------------------------------------------------
@quantity('minimum',
          book='`minimum` or `not a minimum`',
          how=('decided at the default values and a sampled point: Legendre\'s matrix '
               'F̂_{y′y′} positive definite at 25 points along the curve `curve:` and no '
               'point conjugate to the start (the Jacobi field\'s determinant has no zero '
               'on (s_a, s_b]): a (weak) minimum; Legendre\'s matrix negative somewhere or '
               'a conjugate point inside: not a minimum; a conjugate point within 1e-6 of '
               'the end: undecided (unsupported). Second computation: on perturbed curves '
               'y + εη at 30 digits the value does not decrease for a minimum'),
          keys=CURVE_KEYS, literals=MINIMUM, needs_system=False)
def check_minimum(ctx: Context, val) -> Verdict:
    if val not in MINIMUM:
        raise ctx.part.error(("book",), "the book's verdict is `minimum` or `not a minimum`")
    if "curve" not in ctx.part.data:
        raise ctx.part.error(("quantity",), "a `minimum` part gives its `curve:`")
    spec = CurveSpec(ctx, ctx.part.data["curve"], ("curve",))
    if ctx.validate_only:
        return Verdict(True, "validated")
    if spec.fn.constraints:
        raise UnsupportedError("the second variation under a constraint (the Jacobi "
                               "condition of the constrained problem)")
    points = _solved_points(spec)
    verdicts = []
    for pt in points:
        sv = cv.second_variation(spec.fn, spec.curve, pt)
        sa, sb = sv.ends
        L = abs(sb - sa)
        if min(sv.legendre_min) < 0:
            engine, why = "not a minimum", "Legendre's matrix is not positive"
        elif sv.conjugate is not None and abs(sb - sv.conjugate) <= 1e-6 * L:
            raise UnsupportedError(f"a conjugate point at the end (s = {sv.conjugate:.8g}): "
                                   "the Jacobi condition is at its boundary")
        elif sv.conjugate is not None:
            engine, why = "not a minimum", f"a conjugate point at s = {sv.conjugate:.8g}"
        elif min(sv.legendre_min) > 0:
            engine, why = "minimum", "Legendre strict, no conjugate point on (s_a, s_b]"
        else:
            raise UnsupportedError("Legendre's matrix is singular along the curve")
        if engine != val:
            return Verdict(False, f"Legendre and Jacobi ({len(points)} points)",
                           f"{why} at {_fmt(pt)}: {engine}, the book says {val}")
        verdicts.append(why)
    detail = f"decided at {len(points)} sampled parameter points: {verdicts[0]}"
    if val == "minimum":
        F = spec.fn.integrand
        for p in cv.perturbed(spec.fn, spec.curve, points[0], F):
            if p.least_change < -STATIONARY * abs(p.value):
                return Verdict(False, "perturbed curves (30 digits)",
                               f"the functional decreases along {p.label} by "
                               f"{mpmath.nstr(-p.least_change, 3)}, though Legendre and "
                               "Jacobi say a minimum")
        detail += "; the value does not decrease on 2 perturbed curves per function"
    return Verdict(True, f"Legendre and Jacobi ({len(points)} points)", detail,
                   power=f"the verdict at {len(points)} sampled points ({detail})")
