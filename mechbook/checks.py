"""One check per kind of answer: how a book's value is compared with the engine's result.

Every check takes the part's context and a value (the book's, or an erratum's corrected one)
and returns a Verdict. Checks never look at other answers and never feed a book value into
the engine: the engine's side is derived from the problem file alone.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import sympy as sp

from .analysis import Analysis
from .answers import Part
from .compare import (
    NUMERIC,
    ProofPolicy,
    Sampler,
    Verdict,
    all_vanish,
    combine,
    equal,
    match_multiset,
    value,
    vanishes,
)
from .errors import UnsupportedError
from .linear import LinearSystem
from .numeval import holds

CHECKS: dict[str, Callable[[Context, object], Verdict]] = {}


def check(name: str):
    def register(fn):
        CHECKS[name] = fn
        return fn

    return register


@dataclass
class Context:
    analysis: Analysis
    part: Part
    policy: ProofPolicy = NUMERIC

    def __post_init__(self):
        try:
            self.system = self.analysis.system(self.part.system)
        except KeyError as exc:  # no `system:` in a multi-system problem, or a wrong one
            raise self.part.error(("system",) if self.part.system else (),
                                  str(exc.args[0]) + "; name it with `system:`") from None
        self.names = self.part.names(self.system)
        for c in self.system.coord_names:  # momenta, for Hamiltonians: p_<coordinate>
            self.names.setdefault("p_" + c, sp.Symbol("p_" + c, real=True))
        for k, v in (self.part.data.get("define") or {}).items():  # e.g. alpha = theta - pi
            if k in self.names:
                raise self.part.error(("define", k), f"{k!r} is already a name")
            f = self.parse(v, ("define", k))
            self.names[k] = f
            self.names[k + "dot"] = self.system.dt(f)
            self.names[k + "ddot"] = self.system.dt(self.system.dt(f))
        conds = list(self.analysis.problem.conditions)
        conds += [self.parse(c, ("assume", i), relation=True)
                  for i, c in enumerate(self.part.data.get("assume", []))]
        base = dict(self.analysis.problem.values())
        base.update(self.part.key.symbol_values)
        self.sampler = Sampler(base, conds, policy=self.policy)

    @property
    def dyn(self):
        return self.analysis.dynamics(self.part.system)

    def parse(self, text, sub, equation=False, relation=False):
        return self.part.parse(text, sub, self.names, equation, relation)

    def point(self) -> dict:
        about = self.part.data.get("about")
        if about is None:
            return self.analysis.default_point(self.part.system)
        point = {}
        for k, v in about.items():
            if k not in self.system.coord_names:
                raise self.part.error(("about", k), f"{k!r} is not a coordinate")
            point[self.system.q[self.system.coord_names.index(k)]] = self.parse(v, ("about", k))
        return point

    def linear(self) -> LinearSystem:
        if "steady" in self.part.data:
            if "about" not in self.part.data:
                raise self.part.error(("steady",), "a steady motion needs `about:` for the "
                                      "coordinates that stay put")
            rates = {}
            for k, v in self.part.data["steady"].items():
                if k not in self.system.coord_names:
                    raise self.part.error(("steady", k), f"{k!r} is not a coordinate")
                rates[self.system.q[self.system.coord_names.index(k)]] = \
                    self.parse(v, ("steady", k))
            return self.analysis.steady_linear(self.part.system, rates, self.point())
        return self.analysis.linear(self.part.system, self.point())

    def as_list(self, val, sub) -> list:
        if isinstance(val, list):
            return val
        raise self.part.error(sub, "expected a list")

    def as_map(self, val, sub) -> dict:
        if isinstance(val, dict):
            return val
        raise self.part.error(sub, "expected a mapping")


_all = combine


def _strip_const(text):
    if isinstance(text, str):
        for tail in ("= constant", "= const", "=constant", "=const"):
            if text.rstrip().endswith(tail):
                return text.rstrip()[: -len(tail)]
    return text


def _linear_accelerations(lin: LinearSystem) -> dict:
    n = len(lin.q)
    rhs = lin.F - lin.C * sp.Matrix(lin.dyn.qd) - lin.K * lin.displacement()
    sol = lin.M.LUsolve(rhs)
    return {lin.dyn.qdd[i]: sol[i] for i in range(n)}


# ---- Lagrangian and equations of motion ----------------------------------------------------
@check("lagrangian")
def check_lagrangian(ctx: Context, val) -> Verdict:
    """Equal up to a total time derivative: the difference has vanishing Lagrange expressions.
    With `about:`, the engine's Lagrangian is first expanded to second order there."""
    book = ctx.parse(val, ("book",))
    engine = ctx.system.lagrangian
    if "about" in ctx.part.data:
        engine = ctx.analysis.equilibria(ctx.part.system).quadratic_lagrangian(ctx.point())
    diff = book - engine
    sys = ctx.system
    exprs = [sys.dt(sp.diff(diff, qd)) - sp.diff(diff, q) for q, qd in zip(sys.q, sys.qd,
                                                                           strict=True)]
    return all_vanish(exprs, ctx.sampler)


@check("eom")
def check_eom(ctx: Context, val) -> Verdict:
    """Each book equation holds once the engine's accelerations are substituted
    (the linearized ones when `about` is given)."""
    eqs = [ctx.parse(v, ("book", i), equation=True)
           for i, v in enumerate(ctx.as_list(val, ("book",)))]
    if "about" in ctx.part.data:
        acc = _linear_accelerations(ctx.linear())
    else:
        acc = dict(zip(ctx.dyn.qdd, ctx.dyn.accelerations, strict=True))
    out = []
    for i, e in enumerate(eqs):
        if not (e.free_symbols & set(ctx.dyn.qdd)):
            raise ctx.part.error(("book", i), "an equation of motion must contain an "
                                 "acceleration; a first integral is a 'conserved' part")
        out.append(e.subs(acc))
    return all_vanish(out, ctx.sampler)


@check("conserved")
def check_conserved(ctx: Context, val) -> Verdict:
    """d/dt of each book expression vanishes along the motion ('= const' may be written)."""
    vals = val if isinstance(val, list) else [val]
    out = []
    if "about" in ctx.part.data:
        acc = _linear_accelerations(ctx.linear())
    else:
        acc = dict(zip(ctx.dyn.qdd, ctx.dyn.accelerations, strict=True))
    for i, v in enumerate(vals):
        sub = ("book", i) if isinstance(val, list) else ("book",)
        e = ctx.parse(_strip_const(v), sub)
        if not (e.free_symbols & set(ctx.dyn.q + ctx.dyn.qd)):
            raise ctx.part.error(sub, "a conserved quantity must depend on the motion")
        out.append(ctx.system.dt(e).subs(acc))
    return all_vanish(out, ctx.sampler)


# ---- equilibria and stability --------------------------------------------------------------
def _engine_points(ctx: Context) -> list[dict]:
    return ctx.analysis.equilibria(ctx.part.system).symbolic


@check("equilibrium")
def check_equilibrium(ctx: Context, val) -> Verdict:
    """`at:` the point satisfies the equilibrium conditions; `where:` some engine equilibrium
    satisfies the book's equations. `stable:` also checks the stability there."""
    val = ctx.as_map(val, ("book",))
    eq = ctx.analysis.equilibria(ctx.part.system)
    if "at" in val:
        at = ctx.as_map(val["at"], ("book", "at"))
        point = {ctx.system.q[ctx.system.coord_names.index(k)]: ctx.parse(v, ("book", "at", k))
                 for k, v in at.items() if k in ctx.system.coord_names}
        if len(point) != len(ctx.system.q):
            raise ctx.part.error(("book", "at"), "give every coordinate of the point")
        verdicts = [all_vanish(eq.residual(point), ctx.sampler)]
        candidates = [point]
    elif "where" in val:
        where = [ctx.parse(w, ("book", "where", i), equation=True)
                 for i, w in enumerate(ctx.as_list(val["where"], ("book", "where")))]
        candidates = []
        for pt in _engine_points(ctx):
            if all(vanishes(w.subs(pt), ctx.sampler, symbolic=False).ok for w in where):
                candidates.append(pt)
        if not candidates:
            return Verdict(False, "numeric", "no equilibrium found by the engine satisfies "
                           f"{val['where']}; engine found {_engine_points(ctx)}")
        verdicts = [Verdict(True, "symbolic", f"engine equilibrium {candidates[0]}")]
    else:
        raise ctx.part.error(("book",), "an equilibrium answer gives 'at:' or 'where:'")
    verdict = _all(verdicts)
    if not verdict.ok:
        return verdict
    if "stable" in ctx.part.data:
        want = ctx.part.data["stable"]
        for pt in candidates:
            lin = ctx.analysis.linear(ctx.part.system, pt)
            for _ in range(4):
                got = lin.numeric_stability(ctx.sampler.draw())
                if (got == "stable") != want:
                    return Verdict(False, "numeric", f"engine finds the equilibrium {got}")
    return _all(verdicts)


@check("stability_condition")
def check_stability_condition(ctx: Context, val) -> Verdict:
    """The book's condition holds exactly where the engine finds the point stable, over
    parameter points drawn widely on both sides of the boundary."""
    cond = ctx.parse(val, ("book",), relation=True)
    lin = ctx.linear()
    wide = Sampler(ctx.sampler.base, ctx.sampler.conditions, spread=2.0, policy=ctx.policy)
    seen = {True: 0, False: 0}
    n = 0
    for _ in range(400):
        pt = wide.draw()
        got = lin.numeric_stability(pt)
        if got == "marginal":
            continue
        claim = holds(cond, pt)
        if claim != (got == "stable"):
            return Verdict(False, f"numeric({n + 1} points)",
                           f"book says {'stable' if claim else 'unstable'}, engine finds {got} "
                           f"at {{{', '.join(f'{k}={float(v):.4g}' for k, v in pt.items())}}}")
        seen[claim] += 1
        n += 1
        if n >= 60 and min(seen.values()) >= 10:
            break
    if min(seen.values()) == 0:
        return Verdict(False, "numeric", "sampling never crossed the stability boundary; "
                       "the check cannot discriminate (widen parameters)")
    return Verdict(True, f"numeric({n} points: {seen[True]} stable, {seen[False]} unstable)")


# ---- frequencies and modes -----------------------------------------------------------------
def _book_frequencies(ctx: Context, val) -> list[sp.Expr]:
    return [ctx.parse(v, ("book", i)) for i, v in enumerate(ctx.as_list(val, ("book",)))]


def _numbers(exprs, pt) -> list[float]:
    out = []
    for e in exprs:
        z = value(e, pt)
        out.append(z.real if abs(z.imag) <= 1e-12 * max(1, abs(z)) else float("nan"))
    return out


@check("frequencies")
def check_frequencies(ctx: Context, val) -> Verdict:
    """Multiset of normal angular frequencies (numeric eigh at random points; symbolic where
    SymPy can); `partial: true` allows the book to list a subset; `limit:` compares an
    asymptotic formula."""
    book = _book_frequencies(ctx, val)
    lin = ctx.linear()
    partial = bool(ctx.part.data.get("partial"))
    if "limit" in ctx.part.data:
        return _check_limit(ctx, book, lin)
    n = 0
    for _ in range(6):
        pt = ctx.sampler.draw()
        ok, why = match_multiset(_numbers(book, pt), list(lin.numeric_frequencies(pt)), partial)
        n += 1
        if not ok:
            return Verdict(False, f"numeric({n} points)", why)
    return Verdict(True, _symbolic_frequencies(ctx, book, lin, partial) or
                   f"numeric({n} points, eigensolver)")


def _symbolic_frequencies(ctx, book, lin, partial) -> str | None:
    """'symbolic' when, asked to prove (`--prove`), the engine's closed-form frequencies
    match the book's exactly; the numeric multiset comparison has already decided."""
    if not ctx.policy.prove:
        return None
    try:
        engine = list(lin.frequencies)
    except UnsupportedError:
        return None
    pt = ctx.sampler.draw()
    eng_vals = _numbers(engine, pt)
    used = set()
    for b in book:
        bv = _numbers([b], pt)[0]
        idx = [i for i in range(len(engine)) if i not in used
               and abs(eng_vals[i] - bv) <= 1e-8 * max(1, abs(bv))]
        if not idx or not vanishes(b**2 - engine[idx[0]] ** 2, ctx.sampler).method == "symbolic":
            return None
        used.add(idx[0])
    return "symbolic"


def _check_limit(ctx: Context, book, lin: LinearSystem) -> Verdict:
    def error(pt) -> float:
        eng = list(lin.numeric_frequencies(pt))
        worst = 0.0
        for b in _numbers(book, pt):  # one-to-one: each engine frequency matches once
            if not eng:
                return float("inf")
            nearest = min(range(len(eng)), key=lambda i, b=b: abs(eng[i] - b))
            worst = max(worst, abs(eng.pop(nearest) - b) / max(abs(b), 1e-300))
        return worst

    return _asymptotic(ctx, error)


def _asymptotic(ctx: Context, error) -> Verdict:
    """`limit: {parameter, to, order}`: the book's formula holds in a limit of the
    parameters. The relative error `error(point)` must fall as the parameter goes to 0 or ∞
    by decades, faster than 10^-order per decade (halved, for safety), and end below 1e-3."""
    spec = ctx.part.data["limit"]
    name = spec["parameter"]
    if name not in ctx.names or not isinstance(ctx.names[name], sp.Symbol):
        raise ctx.part.error(("limit", "parameter"), f"unknown parameter {name!r}")
    sym = ctx.names[name]
    order = spec.get("order", 0)
    to_zero = str(spec["to"]) == "0"
    base = ctx.sampler.default()
    errors = []
    for eps in (1e-3, 1e-4, 1e-5):
        pt = dict(base)
        pt[sym] = base[sym] * eps if to_zero else base[sym] / eps
        errors.append(error(pt))
    ratios = [errors[i + 1] / errors[i] if errors[i] > 1e-14 else 0.0 for i in range(2)]
    needed = 0.5 * 10.0 ** (-order)
    ok = errors[-1] < 1e-3 and all(r <= needed for r in ratios)
    detail = (f"relative error {errors[0]:.2g}, {errors[1]:.2g}, {errors[2]:.2g} as "
              f"{name} -> {spec['to']} by decades (needs decrease faster than x{needed:g})")
    return Verdict(ok, "numeric(asymptotic)", detail)


@check("period")
def check_period(ctx: Context, val) -> Verdict:
    """2π/ω for one of the engine's nonzero frequencies."""
    period = ctx.parse(val, ("book",))
    lin = ctx.linear()
    for _ in range(6):
        pt = ctx.sampler.draw()
        p = _numbers([period], pt)[0]
        freqs = [w for w in lin.numeric_frequencies(pt) if w > 0]
        if not any(abs(2 * np.pi / w - p) <= 1e-8 * p for w in freqs):
            return Verdict(False, "numeric", f"period {p:.10g} vs engine "
                           f"{[2 * np.pi / w for w in freqs]}")
    try:
        if ctx.policy.prove and any(vanishes(period - 2 * sp.pi / w, ctx.sampler).method
                                    == "symbolic" for w in lin.frequencies if w != 0):
            return Verdict(True, "symbolic")
    except UnsupportedError:
        pass
    return Verdict(True, "numeric(6 points)")


def _mode_residual(lin: LinearSystem, freq: sp.Expr, shape: sp.Matrix, pt: dict) -> float:
    M, C, K = lin.matrices(pt)
    w = _numbers([freq], pt)[0]
    u = np.array(_numbers(list(shape), pt))
    return _eig_residual(K, M, w**2, u) if np.any(u) else np.inf


def _eig_residual(K: np.ndarray, M: np.ndarray, w2: float, u: np.ndarray) -> float:
    """|(K − ω²M)u| relative to the size of its terms (norm-wise, robust to zero entries)."""
    r = (K - w2 * M) @ u
    scale = (np.linalg.norm(K, 2) + abs(w2) * np.linalg.norm(M, 2)) * np.linalg.norm(u)
    return float(np.linalg.norm(r) / max(scale, 1e-300))


@check("normal_modes")
def check_normal_modes(ctx: Context, val) -> Verdict:
    """Each (frequency, shape) satisfies (K − ω²M)·u = 0: shape up to scale and sign, and any
    vector of a degenerate eigenspace is accepted."""
    lin = ctx.linear()
    modes = ctx.as_list(val, ("book",))
    if "limit" in ctx.part.data:
        return _modes_limit(ctx, modes, lin)
    for _ in range(5):
        pt = ctx.sampler.draw()
        for i, mode in enumerate(modes):
            mode = ctx.as_map(mode, ("book", i))
            freq = ctx.parse(mode["frequency"], ("book", i, "frequency"))
            shape = _shape(ctx, mode.get("shape"), ("book", i, "shape"))
            if abs(_numbers([freq], pt)[0]) not in _near(lin.numeric_frequencies(pt),
                                                         _numbers([freq], pt)[0]):
                return Verdict(False, "numeric", f"mode {i}: frequency not an engine frequency")
            res = _mode_residual(lin, freq, shape, pt)
            if res > 1e-8:
                return Verdict(False, "numeric", f"mode {i}: (K - w^2 M) u relative residual "
                               f"{res:.3g}")
    return Verdict(True, "numeric(5 points)")


def _modes_limit(ctx: Context, modes: list, lin: LinearSystem) -> Verdict:
    """Modes in a limit of the parameters: each book mode must approach one engine mode, in
    frequency (relative error) and in shape (the sine of the angle between the shapes)."""
    parsed = []
    for i, mode in enumerate(modes):
        mode = ctx.as_map(mode, ("book", i))
        parsed.append((ctx.parse(mode["frequency"], ("book", i, "frequency")),
                       _shape(ctx, mode.get("shape"), ("book", i, "shape"))))

    def error(pt) -> float:
        w2, vecs = lin.numeric_modes(pt)
        free = list(range(len(w2)))
        worst = 0.0
        for freq, shape in parsed:
            w = _numbers([freq], pt)[0]
            u = np.array(_numbers(list(shape), pt))
            if not free or not np.any(u):
                return float("inf")
            best = float("inf")
            for j in free:
                v = vecs[:, j]
                cos = abs(u @ v) / (np.linalg.norm(u) * np.linalg.norm(v))
                sin = float(np.sqrt(max(0.0, 1.0 - cos**2)))
                dw = abs(np.sqrt(abs(w2[j])) - w) / max(abs(w), 1e-300)
                best_j = max(sin, dw)
                if best_j < best:
                    best, pick = best_j, j
            free.remove(pick)
            worst = max(worst, best)
        return worst

    return _asymptotic(ctx, error)


def _near(values, x, rtol=1e-8):
    return [x] if any(abs(v - x) <= rtol * max(1, abs(x)) for v in values) else []


def _shape(ctx: Context, shape, sub) -> sp.Matrix:
    shape = ctx.as_map(shape, sub)
    unknown = set(shape) - set(ctx.system.coord_names)
    if unknown:
        raise ctx.part.error(sub + (sorted(unknown)[0],), "not a coordinate")
    return sp.Matrix([ctx.parse(shape[c], sub + (c,)) if c in shape else 0
                      for c in ctx.system.coord_names])


@check("normal_coordinates")
def check_normal_coordinates(ctx: Context, val) -> Verdict:
    """A linear form c·q is a normal coordinate iff u = M⁻¹c is a mode: (K − ω²M)u = 0."""
    lin = ctx.linear()
    items = ctx.as_list(val, ("book",))
    rows = []
    for _ in range(5):
        pt = ctx.sampler.draw()
        M, C, K = lin.matrices(pt)
        rows = []
        for i, item in enumerate(items):
            item = ctx.as_map(item, ("book", i))
            form = ctx.parse(item["coordinate"], ("book", i, "coordinate"))
            c = sp.Matrix([sp.diff(form, q) for q in ctx.system.q])
            if any(s in ctx.system.q for x in c for s in x.free_symbols):
                raise ctx.part.error(("book", i, "coordinate"), "a normal coordinate is linear "
                                     "in the coordinates")
            cv = np.array(_numbers(list(c), pt))
            rows.append(cv)
            u = np.linalg.solve(M, cv)
            w2 = float(u @ K @ u / (u @ M @ u))
            if _eig_residual(K, M, w2, u) > 1e-8:
                return Verdict(False, "numeric", f"{item['coordinate']} is not a normal "
                               "coordinate (M^-1 c is not a mode)")
            if "frequency" in item:
                w = _numbers([ctx.parse(item["frequency"], ("book", i, "frequency"))], pt)[0]
                if abs(np.sqrt(max(w2, 0)) - w) > 1e-8 * max(1, w):
                    return Verdict(False, "numeric", f"{item['coordinate']}: frequency "
                                   f"{w:.10g}, engine {np.sqrt(max(w2, 0)):.10g}")
        if len(rows) == len(ctx.system.q) and np.linalg.matrix_rank(np.array(rows)) < len(rows):
            return Verdict(False, "numeric", "the normal coordinates are not independent")
    return Verdict(True, "numeric(5 points)")


@check("mode_count")
def check_mode_count(ctx: Context, val) -> Verdict:
    n = len(ctx.system.q)
    ok = isinstance(val, int) and val == n
    return Verdict(ok, "exact", f"book {val}, engine {n} degrees of freedom")


@check("mode_node")
def check_mode_node(ctx: Context, val) -> Verdict:
    """A point whose position (linear in the small displacements) stays put in the mode of a
    given frequency: ∇position · u = 0. The book's value fixes the point's parameter."""
    book = ctx.as_map(val, ("book",))
    lin = ctx.linear()
    subs = {ctx.names[k]: ctx.parse(v, ("book", k)) for k, v in book.items()}
    position = ctx.parse(ctx.part.data["position"], ("position",)).subs(subs)
    freq = ctx.parse(ctx.part.data["frequency"], ("frequency",))
    point = lin.point
    grad = [sp.diff(position, q).subs(point) for q in ctx.system.q]
    for _ in range(5):
        pt = ctx.sampler.draw()
        w2, vecs = lin.numeric_modes(pt)
        w = _numbers([freq], pt)[0]
        idx = [i for i, x in enumerate(w2) if abs(np.sqrt(max(x, 0)) - w) <= 1e-8 * max(1, w)]
        if not idx:
            return Verdict(False, "numeric", "frequency is not an engine frequency")
        g = np.array(_numbers(grad, pt))
        for i in idx:
            u = vecs[:, i]
            if abs(g @ u) > 1e-9 * (np.abs(g) @ np.abs(u)):
                return Verdict(False, "numeric", f"the point moves in that mode ({g @ u:.3g})")
    return Verdict(True, "numeric(5 points)")


# ---- driven and initial-value motion -------------------------------------------------------
def _time_functions(ctx: Context, val, sub) -> dict[sp.Symbol, sp.Expr]:
    """Book's {coordinate or defined name: f(t)} turned into coordinates where possible."""
    val = ctx.as_map(val, sub)
    define = ctx.part.data.get("define") or {}
    funcs = {}
    for name, text in val.items():
        if name not in ctx.system.coord_names and name not in define:
            raise ctx.part.error(sub + (name,), f"{name!r} is neither a coordinate nor defined")
        funcs[name] = ctx.parse(text, sub + (name,))
    return funcs


@check("steady_state")
def check_steady_state(ctx: Context, val) -> Verdict:
    """The book's particular solution satisfies the linearized driven equations (each
    equation whose coordinates the book gives must vanish)."""
    lin = ctx.linear()
    funcs = _time_functions(ctx, val, ("book",))
    return _residual_of_motion(ctx, lin, funcs)


def _coordinates_from(ctx: Context, funcs: dict) -> dict[sp.Symbol, sp.Expr]:
    """Coordinates as functions of t from the book's functions (and `define:` forms)."""
    define = ctx.part.data.get("define") or {}
    sys = ctx.system
    direct = {sys.q[sys.coord_names.index(k)]: v for k, v in funcs.items()
              if k in sys.coord_names}
    defined = {k: v for k, v in funcs.items() if k in define}
    if not defined:
        return direct
    unknowns = [q for q in sys.q if q not in direct]
    eqs = [ctx.parse(define[k], ("define", k)).subs(direct) - v for k, v in defined.items()]
    sol = sp.solve(eqs, unknowns, dict=True)
    if len(sol) != 1:
        raise ctx.part.error(("define",), "the defined coordinates do not determine the motion")
    direct.update(sol[0])
    return direct


def _residual_of_motion(ctx: Context, lin: LinearSystem, funcs: dict) -> Verdict:
    coords = _coordinates_from(ctx, funcs)
    t = ctx.system.t
    subs = {}
    for q, qd, qdd in zip(lin.dyn.q, lin.dyn.qd, lin.dyn.qdd, strict=True):
        if q in coords:
            f = coords[q]
            subs.update({q: f, qd: sp.diff(f, t), qdd: sp.diff(f, t, 2)})
    checked = []
    for e in lin.equations():
        r = e.subs(subs)
        if r.free_symbols & set(lin.dyn.q + lin.dyn.qd + lin.dyn.qdd):
            continue
        checked.append(r)
    if not checked:
        raise UnsupportedError("checking a motion that leaves every equation with unknown "
                               "coordinates (give the initial conditions instead)")
    return all_vanish(checked, ctx.sampler)


@check("motion")
def check_motion(ctx: Context, val) -> Verdict:
    """With `initial:`, compare with the modal solution of the linearized initial-value
    problem at several times; without, the book's general solution must satisfy the
    linearized equations for any values of its constants."""
    lin = ctx.linear()
    funcs = _time_functions(ctx, val, ("book",))
    if "initial" not in ctx.part.data:
        return _residual_of_motion(ctx, lin, funcs)
    if lin.gyroscopic or lin.driven:
        raise UnsupportedError("initial-value solution of a driven or gyroscopic system")
    init = ctx.as_map(ctx.part.data["initial"], ("initial",))
    sys = ctx.system
    define = ctx.part.data.get("define") or {}
    forms = {k: ctx.parse(v, ("define", k)) for k, v in define.items()}
    t = sys.t
    for _ in range(4):
        pt = ctx.sampler.draw()
        q0 = np.zeros(len(sys.q))
        v0 = np.zeros(len(sys.q))
        for k, text in init.items():
            x = _numbers([ctx.parse(text, ("initial", k))], pt)[0]
            if k in sys.coord_names:
                q0[sys.coord_names.index(k)] = x
            elif k.endswith("dot") and k[:-3] in sys.coord_names:
                v0[sys.coord_names.index(k[:-3])] = x
            else:
                raise ctx.part.error(("initial", k), "initial values are given for coordinates "
                                     "(x) and their velocities (xdot)")
        eq0 = np.array(_numbers([lin.point.get(q, 0) for q in sys.q], pt))
        w2, U = lin.numeric_modes(pt)
        Mn = lin.matrices(pt)[0]
        a = U.T @ Mn @ (q0 - eq0)
        b = U.T @ Mn @ v0
        for tv in (0.37, 1.3, 2.9, 7.1):
            eta = np.empty(len(w2))
            for k, x in enumerate(w2):
                if abs(x) < 1e-10 * max(1.0, np.max(np.abs(w2))):
                    eta[k] = a[k] + b[k] * tv
                elif x > 0:
                    w = np.sqrt(x)
                    eta[k] = a[k] * np.cos(w * tv) + b[k] * np.sin(w * tv) / w
                else:
                    raise UnsupportedError("motion about an unstable equilibrium")
            q = eq0 + U @ eta
            env = dict(pt)
            env[t] = sp.Float(tv, 30)
            env.update({sq: sp.Float(x, 30) for sq, x in zip(sys.q, q, strict=True)})
            for name, f in funcs.items():
                expected = (q[sys.coord_names.index(name)] if name in sys.coord_names
                            else _numbers([forms[name]], env)[0])
                got = _numbers([f], env)[0]
                scale = max(np.max(np.abs(q)), np.max(np.abs(q0)), 1e-300)
                if not abs(got - expected) <= 1e-8 * max(abs(expected), scale):
                    return Verdict(False, "numeric", f"{name}(t={tv}) = {got:.10g}, "
                                   f"engine {expected:.10g}")
    return Verdict(True, "numeric(4 points x 4 times, modal solution)")


# ---- named expressions ---------------------------------------------------------------------
@check("expression")
def check_expression(ctx: Context, val) -> Verdict:
    """An engine quantity named by `of:`; potentials compare up to an additive constant.
    At a state (`at:` coordinates and velocities, or a steady motion named by `steady:` and
    `about:`) the quantity's value there is compared instead, the constant included."""
    of = ctx.part.data.get("of")
    if of is None:
        raise ctx.part.error(("of",), "an 'expression' part names what it is with 'of:'")
    dyn = ctx.dyn
    state = _state(ctx)
    if of == "momenta":
        items = ctx.as_map(val, ("book",))
        out = []
        for k, v in items.items():
            if k not in ctx.system.coord_names:
                raise ctx.part.error(("book", k), "momenta are keyed by coordinate")
            engine = dyn.momenta[ctx.system.coord_names.index(k)]
            out.append(equal(ctx.parse(v, ("book", k)), _at(ctx, engine, state), ctx.sampler))
        return _all(out)
    book = ctx.parse(val, ("book",), equation=False)
    if of in ("potential", "quadratic_potential"):
        if of == "potential":
            engine = ctx.system.potential
        else:
            lin = ctx.linear()
            dq = lin.displacement()
            engine = (dq.T * lin.K * dq)[0, 0] / 2
        if state is not None:
            return equal(book, _at(ctx, engine, state), ctx.sampler)
        # up to a constant: gradients agree
        return all_vanish([sp.diff(book - engine, q) for q in ctx.system.q], ctx.sampler)
    if of == "quadratic_kinetic":
        lin = ctx.linear()
        qd = sp.Matrix(dyn.qd)
        engine = (qd.T * lin.M * qd)[0, 0] / 2
    elif of == "kinetic":
        engine = ctx.system.kinetic
    elif of == "energy_function":
        engine = dyn.energy_function
    else:
        return _check_hamiltonian(ctx, book, state)
    return equal(book, _at(ctx, engine, state), ctx.sampler)


def _check_hamiltonian(ctx: Context, book: sp.Basic, state: dict | None) -> Verdict:
    """H(q, p) is the Legendre transform of L exactly when, with p = ∂L/∂q̇ put in, it is the
    energy function h(q, q̇) and ∂H/∂p gives back q̇. Checking it this way needs no
    inversion of p(q̇), so Lagrangians not quadratic in the velocities (relativistic ones)
    are covered as well as the rest."""
    dyn = ctx.dyn
    momenta = {ctx.names["p_" + c]: p
               for c, p in zip(ctx.system.coord_names, dyn.momenta, strict=True)}
    value = equal(_at(ctx, book.subs(momenta), state),
                  _at(ctx, dyn.energy_function, state), ctx.sampler)
    if not value.ok or state is not None:
        return value
    velocities = all_vanish([sp.diff(book, p).subs(momenta) - v
                             for p, v in zip(momenta, dyn.qd, strict=True)], ctx.sampler)
    return combine([value, velocities])


def _state(ctx: Context) -> dict | None:
    """The state an `expression` part is evaluated at, or None (a function of the state).

    `at:` gives coordinates and velocities (`<coordinate>dot`) outright. `steady:` with
    `about:` names a steady motion (the other velocities zero), which is first confirmed to
    be one: a wrong rate or radius is a fail."""
    data = ctx.part.data
    if "at" in data:
        names = ctx.system.coord_names
        symbols = dict(zip(names, ctx.system.q, strict=True))
        symbols.update({n + "dot": v for n, v in zip(names, ctx.system.qd, strict=True)})
        state = {}
        for k, v in ctx.as_map(data["at"], ("at",)).items():
            if k not in symbols:
                raise ctx.part.error(("at", k), f"{k!r} is neither a coordinate nor a velocity")
            state[symbols[k]] = ctx.parse(v, ("at", k))
        return state
    if "steady" in data and ctx.part.quantity == "expression":
        ctx.linear()  # raises NotEquilibriumError unless this is a steady motion
        state = {v: sp.S.Zero for v in ctx.system.qd}
        state.update(ctx.point())
        for k, v in data["steady"].items():
            state[ctx.system.qd[ctx.system.coord_names.index(k)]] = ctx.parse(v, ("steady", k))
        return state
    return None


def _at(ctx: Context, expr: sp.Basic, state: dict | None) -> sp.Basic:
    if state is None:
        return expr
    out = expr.subs(state)
    left = out.free_symbols & set(ctx.system.q + ctx.system.qd)
    if left:
        raise ctx.part.error(("at",), "the state leaves " + ", ".join(sorted(map(str, left)))
                             + " unknown: give every coordinate and velocity it depends on")
    return out


@check("constraint_force")
def check_constraint_force(ctx: Context, val) -> Verdict:
    """The generalized force λ·∂f/∂q that constraint `constraint` exerts on `coordinate`, as
    a function of the state; `at:` fixes coordinates and velocities the constraint pins
    (e.g. {r: l, rdot: 0} for a string of length l)."""
    dyn = ctx.dyn
    names = [n for n, _ in ctx.system.constraints]
    cname = ctx.part.data.get("constraint")
    if cname not in names:
        raise ctx.part.error(("constraint",), f"no constraint {cname!r} (have {names})")
    coord = ctx.part.data.get("coordinate")
    if coord not in ctx.system.coord_names:
        raise ctx.part.error(("coordinate",), f"{coord!r} is not a coordinate")
    f = ctx.system.constraints[names.index(cname)][1]
    q = ctx.system.q[ctx.system.coord_names.index(coord)]
    engine = dyn.solved[dyn.multipliers[names.index(cname)]] * sp.diff(f, q)
    book = ctx.parse(val, ("book",))
    at = {}
    for k, v in (ctx.part.data.get("at") or {}).items():
        if k not in ctx.names or not isinstance(ctx.names[k], sp.Symbol):
            raise ctx.part.error(("at", k), f"{k!r} is not a coordinate or velocity")
        at[ctx.names[k]] = ctx.parse(v, ("at", k))
    engine = engine.subs(at)
    if "released" in ctx.part.data:
        engine = _on_energy_shell(ctx, engine, at)
    return equal(book.subs(at), engine, ctx.sampler)


def _on_energy_shell(ctx: Context, expr: sp.Basic, at: dict) -> sp.Basic:
    """expr at the state `at:` reached by the motion that started from `released:` (the
    velocities there zero unless given): the one velocity `at:` leaves open is fixed by the
    conservation of the energy function h (autonomous L, time-independent constraints, no
    other forces). h and expr must be even in that velocity, so its square is what counts."""
    sys, dyn = ctx.system, ctx.dyn
    if sys.lagrangian.has(sys.t) or any(f != 0 for f in sys.forces) or \
            any(c.has(sys.t) for _, c in sys.constraints):
        raise UnsupportedError("`released:` needs a conserved energy function (autonomous "
                               "Lagrangian, fixed constraints, no other forces)")
    names = sys.coord_names
    start = {v: sp.S.Zero for v in sys.qd}
    for k, v in ctx.as_map(ctx.part.data["released"], ("released",)).items():
        if k in names:
            start[sys.q[names.index(k)]] = ctx.parse(v, ("released", k))
        elif k.endswith("dot") and k[:-3] in names:
            start[sys.qd[names.index(k[:-3])]] = ctx.parse(v, ("released", k))
        else:
            raise ctx.part.error(("released", k), f"{k!r} is neither a coordinate nor a "
                                 "velocity")
    h = dyn.energy_function
    h0 = h.subs(start)
    if h0.free_symbols & set(sys.q + sys.qd):
        raise ctx.part.error(("released",), "give every coordinate of the starting state")
    h_at = h.subs(at)
    open_ = sorted((h_at.free_symbols | expr.free_symbols) & set(sys.qd), key=str)
    if len(open_) != 1 or h_at.free_symbols & set(sys.q):
        raise ctx.part.error(("at",), "`at:` must fix every coordinate and all velocities "
                             "but one, which the energy integral then fixes")
    v = open_[0]
    if sp.simplify(h_at - h_at.subs(v, -v)) != 0 or sp.simplify(expr - expr.subs(v, -v)) != 0:
        raise UnsupportedError("the energy integral fixes only the square of the open "
                               "velocity, and the quantity depends on its sign")
    poly = sp.Poly(sp.expand(h_at), v)
    if poly.degree() != 2:
        raise UnsupportedError("energy function not quadratic in the open velocity")
    a, c = poly.coeff_monomial(v**2), poly.coeff_monomial(1)
    v2 = (h0 - c) / a
    w = sp.Dummy("w", positive=True)  # w**2 stands for the velocity's square
    return sp.expand(expr.subs(v, w)).subs(w**2, v2).subs(w, sp.sqrt(v2))


# ---- phase-space flow (Liouville) ----------------------------------------------------------
PHASE_RTOL = 1e-8  # agreement required of a phase area
PHASE_POINTS = 3  # parameter points per phase-space check
REGION_SAMPLES = 2000  # phase points per parameter point in a region check
REGION_MARGIN = 1e-6  # points this close (relative) to a boundary are not judged


def _phase_box(ctx: Context):
    """The part's initial box (`region:` {q or p_q: [low, high]}, every coordinate and
    momentum) and its time (`time:`), as parsed expressions, in the order q…, p…."""
    names = list(ctx.system.coord_names) + ["p_" + c for c in ctx.system.coord_names]
    region = ctx.as_map(ctx.part.data.get("region"), ("region",))
    for k in region:
        if k not in names:
            raise ctx.part.error(("region", k), f"{k!r} is neither a coordinate nor a momentum "
                                 f"(have {', '.join(names)})")
    missing = [k for k in names if k not in region]
    if missing:
        raise ctx.part.error(("region",), "the initial box gives every coordinate and "
                             "momentum a range; missing " + ", ".join(missing))
    if "time" not in ctx.part.data:
        raise ctx.part.error(("time",), "a phase-space part names the elapsed time with 'time:'")
    state = set(ctx.system.q + ctx.system.qd + ctx.dyn.p) | {ctx.system.t}
    bounds = []
    for k in names:
        pair = ctx.as_list(region[k], ("region", k))
        if len(pair) != 2:
            raise ctx.part.error(("region", k), "a range is [low, high]")
        bounds.append([ctx.parse(v, ("region", k, i)) for i, v in enumerate(pair)])
    time = ctx.parse(ctx.part.data["time"], ("time",))
    for e, sub in [(time, ("time",))] + [(b, ("region", k)) for k, pair in zip(names, bounds,
                                                                             strict=True)
                                         for b in pair]:
        if e.free_symbols & state:
            raise ctx.part.error(sub, "the initial box and the time are constants (no "
                                 "coordinates, momenta or t)")
    return names, bounds, time


def _phase_numbers(ctx: Context, bounds, time, pt) -> tuple[np.ndarray, np.ndarray, float]:
    lo = np.array(_numbers([b[0] for b in bounds], pt))
    hi = np.array(_numbers([b[1] for b in bounds], pt))
    tv = _numbers([time], pt)[0]
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(lo < hi)
            and np.isfinite(tv)):
        raise ctx.part.error(("region",), f"the box is empty or not real at {pt}")
    return lo, hi, tv


def _flow(ctx: Context):
    from .phase import PhaseFlow  # scipy's integrator, only when a phase part is checked

    return PhaseFlow(ctx.system, ctx.dyn)


def _fmt_point(pt: dict) -> str:
    return "{" + ", ".join(f"{k}={float(v):.6g}" for k, v in
                           sorted(pt.items(), key=lambda kv: str(kv[0]))) + "}"


@check("phase_area")
def check_phase_area(ctx: Context, val) -> Verdict:
    """Area (one degree of freedom) of the image at `time:` of the `region:` box under the
    engine's flow in (q, p). Valid because the engine's side is a direct computation from
    the equations of motion alone: the box boundary is carried by the integrated flow
    (DOP853, rtol 1e-12, p ↔ q̇ through the engine's momenta) and the enclosed area is the
    shoelace sum, Romberg-extrapolated in the number of boundary points; no Liouville
    theorem is assumed, so a damped system's shrinking area is measured, not presumed.
    Compared at 3 parameter points to rtol 1e-8."""
    if len(ctx.system.q) != 1:
        raise UnsupportedError("phase-space area of more than one degree of freedom")
    from .phase import image_area

    book = ctx.parse(val, ("book",))
    _, bounds, time = _phase_box(ctx)
    flow = _flow(ctx)
    worst = 0.0
    for k in range(PHASE_POINTS):
        pt = ctx.sampler.draw()
        lo, hi, tv = _phase_numbers(ctx, bounds, time, pt)
        area, _ = image_area(flow, pt, lo, hi, tv)
        env = dict(pt)
        env[ctx.system.t] = sp.Float(tv, 30)
        b = value(book, env)
        rel = abs(b - area) / max(abs(area), 1e-300)
        if not (np.isfinite(rel) and abs(b.imag) <= 1e-12 * abs(b)) or rel > PHASE_RTOL:
            return Verdict(False, f"numeric({k + 1} points)",
                           f"book area {b.real:.12g}, image of the box {area:.12g} at t = "
                           f"{tv:.6g}, {_fmt_point(pt)}")
        worst = max(worst, rel)
    return Verdict(True, f"numeric({PHASE_POINTS} points, flow DOP853 rtol 1e-12, "
                   f"rtol {PHASE_RTOL:g})", f"worst relative {worst:.2g}")


def _truth(expr, env: dict, n_points: int):
    """Truth of a condition at many points (arrays in env) and whether any of its
    comparisons is within REGION_MARGIN (relative) of equality there."""
    if expr is sp.true or expr is sp.false:
        return np.full(n_points, bool(expr)), np.zeros(n_points, bool)
    if isinstance(expr, (sp.And, sp.Or)):
        parts = [_truth(a, env, n_points) for a in expr.args]
        truth = np.all if isinstance(expr, sp.And) else np.any
        return truth([p[0] for p in parts], axis=0), np.any([p[1] for p in parts], axis=0)
    if isinstance(expr, sp.Not):
        inner, near = _truth(expr.args[0], env, n_points)
        return ~inner, near
    if not isinstance(expr, sp.core.relational.Relational) or isinstance(expr, sp.Eq):
        raise ValueError(f"not an inequality: {expr}")
    args = list(env)
    sides = []
    for side in (expr.lhs, expr.rhs):
        fn = sp.lambdify(args, side, modules="numpy")
        with np.errstate(all="ignore"):
            sides.append(np.broadcast_to(np.asarray(fn(*env.values()), float), (n_points,)))
    lhs, rhs = sides
    ops = {"<": np.less, "<=": np.less_equal, ">": np.greater, ">=": np.greater_equal,
           "!=": np.not_equal}
    truth = ops[expr.rel_op](lhs, rhs)
    near = ~np.isfinite(lhs - rhs) | (np.abs(lhs - rhs) <= REGION_MARGIN *
                                      np.maximum(np.abs(lhs), np.abs(rhs)))
    return truth, near


@check("phase_region")
def check_phase_region(ctx: Context, val) -> Verdict:
    """The region of phase space the `region:` box occupies at `time:`, given as inequalities
    in the coordinates, momenta p_<q> and t. Valid because membership is decided pointwise
    without any formula for the image: a point X is in Φ_t(box) iff the engine's flow
    carried back, Φ_{-t}(X), lies in the box. At 3 parameter points, 2000 points drawn in a
    box covering the initial box and the image's bounding box (enlarged by a quarter on each
    side) must get the same verdict from the book's inequalities and from the flow; points
    within 1e-6 (relative) of either boundary are not judged. Any disagreement fails."""
    from .phase import image_bounds, in_box

    items = ctx.as_list(val, ("book",))
    conds = [ctx.parse(v, ("book", i), relation=True) for i, v in enumerate(items)]
    variables = ctx.system.q + ctx.dyn.p
    if not any(c.free_symbols & set(variables) for c in conds):
        raise ctx.part.error(("book",), "a region is given by inequalities in the "
                             "coordinates and momenta")
    names, bounds, time = _phase_box(ctx)
    flow = _flow(ctx)
    n = len(ctx.system.q)
    rng = np.random.default_rng(20261123)
    inside = judged = 0
    for k in range(PHASE_POINTS):
        pt = ctx.sampler.draw()
        lo, hi, tv = _phase_numbers(ctx, bounds, time, pt)
        ilo, ihi = image_bounds(flow, pt, lo, hi, tv)
        clo, chi = np.minimum(lo, ilo), np.maximum(hi, ihi)
        clo, chi = clo - (chi - clo) / 4, chi + (chi - clo) / 4
        X = clo + (chi - clo) * rng.uniform(size=(REGION_SAMPLES, 2 * n))
        X0q, X0p = flow.map(pt, X[:, :n], X[:, n:], 0.0, tv)
        X0 = np.column_stack((X0q, X0p))
        truth, near = in_box(X0, lo, hi, REGION_MARGIN)
        env = {ctx.system.t: sp.Float(tv, 30), **pt}
        env_arrays = {v: X[:, i] for i, v in enumerate(variables)}
        claim = np.ones(REGION_SAMPLES, bool)
        for i, c in enumerate(conds):
            try:
                ok, close = _truth(c.subs(env), env_arrays, REGION_SAMPLES)
            except ValueError as exc:
                raise ctx.part.error(("book", i), str(exc)) from None
            claim &= ok
            near |= close
        judge = ~near
        wrong = np.flatnonzero(judge & (claim != truth))
        if wrong.size:
            j = wrong[0]
            where = ", ".join(f"{nm}={x:.8g}" for nm, x in zip(names, X[j], strict=True))
            back = ", ".join(f"{x:.8g}" for x in X0[j])
            return Verdict(False, f"numeric({k + 1} points)",
                           f"at {where}, t={tv:.6g}: the book puts the point "
                           f"{'inside' if claim[j] else 'outside'} the region, but the flow "
                           f"carries it back to ({back}), {'inside' if truth[j] else 'outside'}"
                           f" the initial box ({wrong.size} of {judge.sum()} points disagree; "
                           f"{_fmt_point(pt)})")
        inside += int(np.sum(judge & truth))
        judged += int(np.sum(judge))
    if inside == 0 or inside == judged:
        return Verdict(False, "numeric", "the sampled points never straddle the region's "
                       "boundary; the check cannot discriminate")
    return Verdict(True, f"numeric({PHASE_POINTS} points x {REGION_SAMPLES} phase points, "
                   "flow DOP853 rtol 1e-12)", f"{inside} of {judged} judged points inside")


@check("force")
def check_force(ctx: Context, val) -> Verdict:
    raise UnsupportedError("constraint forces along a trajectory (Lagrange multipliers "
                           "combined with a first integral)")


@check("proof")
def check_proof(ctx: Context, val) -> Verdict:
    raise UnsupportedError("a proof in words")
