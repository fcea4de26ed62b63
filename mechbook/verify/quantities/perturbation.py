"""`perturbation`: a perturbation-theory formula (Symon §12-5), written in the text's own
index notation, judged against the exact perturbed system as the small parameter → 0.

The part names the small parameter (`limit: {parameter, to: 0, order}`) and what the
formula approximates (`approximates:`). The book's expression may use, besides the problem's names:

    W0(j)        unperturbed squared frequencies, j = 1..f in ascending order
    omega0(j)    sqrt(W0(j))
    Wp(j, r)     perturbation coefficients W'_jr: AᵀK(ε)A − diag(W0), A the unperturbed
                 normal modes (AᵀMA = 1)
    b(j, r)      friction coefficients AᵀC(ε)A (Eq. 12-63)
    K0(k, l)     the unperturbed stiffness ∂²V0/∂x_k∂x_l at the unperturbed equilibrium
    dV(k), d2V(k, l)   first and second derivatives of V' = V − V0 there
    d3V0(k, l, m)      third derivatives of V0 there
    Delta, Delta_star(k)   det K0, and det K0 with column k replaced by −dV (Problem 12-11)
    sum(expr, r, n1, ...)  Σ over r = 1..f of expr, leaving out r = n1, ...
    delta(j, r)  Kronecker's delta

and index names (`indices:`, default j, r, s). `approximates:` is one of

    squared_frequency   ω² of mode `mode:` (the perturbed mode that starts as unperturbed
                        mode `mode`, 1-based ascending)
    component           C_j of that mode in unperturbed normal coordinates (unit vector,
                        C_mode > 0); `component:` a number, or an index name for every
                        j ≠ mode
    exponent            the complex exponent p (e^{pt}) of that mode with friction
    damped_component    C_j of the damped mode, scaled to C_mode = 1 (complex)
    equilibrium         x0_k of the perturbed equilibrium (`component:` k or an index)
    stiffness           K'_kl = ∂²V/∂x_k∂x_l at the new equilibrium − K0 (`component:`
                        [k, l], numbers or index names)
    group               the approximate squared frequencies of a group of nearly degenerate
                        modes (`group: [j...]`): `reference:` + the eigenvalues of the
                        book's matrix (entries in indices `component: [j, r]`)

The error is |book − exact| (relative to the unperturbed value when that exceeds 1) and must
fall like ε^(order + 1) (mechbook.verify.asymptotic). The unperturbed
system is the one at ε = 0, or at `unperturbed:` values (a splitting that scales with ε).
"""

from __future__ import annotations

from functools import partial

import mpmath
import sympy as sp
from sympy.core.function import AppliedUndef

from mechbook.engine import perturbation as pert
from mechbook.errors import UnsupportedError
from mechbook.model.expr import Operator
from mechbook.verify.asymptotic import asymptotic
from mechbook.verify.context import Context
from mechbook.verify.registration import EXPR, LIMIT, POINT, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

KINDS = ("squared_frequency", "component", "exponent", "damped_component", "equilibrium",
         "stiffness", "group")
INDEX = {"oneOf": [{"type": "integer", "minimum": 1},
                   {"type": "string", "pattern": "^[A-Za-z][A-Za-z0-9_]*$"}]}
TABLES = ("W0", "omega0", "Wp", "b", "K0", "dV", "d2V", "d3V0", "Delta_star")


def _sum(f: int, expr, r, *excluded):
    if not isinstance(r, sp.Symbol):
        raise ValueError("the second argument is the summation index")
    skip = {int(x) for x in excluded}
    return sp.Add(*[expr.subs(r, k) for k in range(1, f + 1) if k not in skip])


def _names(ctx: Context) -> tuple[dict, list[sp.Symbol]]:
    f = len(ctx.system.q)
    names = dict(ctx.names)
    idx = []
    # the text's notation must not hide a name of the problem or key (a parameter `b` read
    # as the friction table b(j, r), or the other way round): refused, with the way out
    own = list(TABLES) + ["Delta", "sum", "delta"]
    taken = [t for t in own if t in names]
    if taken:
        raise ctx.part.error(("quantity",), f"{', '.join(map(repr, taken))} is a name of the "
                             "problem or key and also the text's notation here ("
                             + ", ".join(own) + "): rename the parameter or symbol")
    for name in ctx.part.data.get("indices", ["j", "r", "s"]):
        if name in names:
            raise ctx.part.error(("indices",), f"index {name!r} is already a name of the "
                                 "problem or key: choose other index names (`indices:`)")
        names[name] = sp.Symbol(name, integer=True)
        idx.append(names[name])
    for t in TABLES:
        arity = {"W0": 1, "omega0": 1, "dV": 1, "Delta_star": 1, "d3V0": 3}.get(t, 2)
        names[t] = Operator(t, sp.Function(t), (arity, arity))
    names["Delta"] = DELTA
    names["sum"] = Operator("sum", partial(_sum, f), (2, 2 + f))
    names["delta"] = Operator("delta", sp.KroneckerDelta, (2, 2))
    return names, idx


class _Tables:
    """The numbers behind W0(j), Wp(j, r), ... at one parameter point."""

    def __init__(self, ctx: Context, pt: dict, unperturbed: dict):
        self.ctx, self.pt = ctx, pt
        self.unperturbed = {**pt, **unperturbed}
        self._split = None
        self._v = None

    @property
    def s(self) -> pert.Split:
        """The linear system in unperturbed normal coordinates (about the part's point,
        which must stay an equilibrium of the perturbed system)."""
        if self._split is None:
            self._split = pert.split(self.ctx.linear(), self.pt,
                                     {k: v for k, v in self.unperturbed.items()
                                      if k not in self.pt or self.pt[k] != v})
        return self._split

    def potential_derivatives(self) -> dict:
        """dV, d2V (of V' = V − V0), K0 and d3V0 at the unperturbed equilibrium (the part's
        `about:` point, which the perturbation may move)."""
        if self._v is None:
            sys = self.ctx.system
            q = list(sys.q)
            point = self.ctx.point()
            at = {x: sp.S(point.get(x, 0)).subs(self.pt) for x in q}
            V = sys.potential
            d1, hess = pert.potential_derivatives(V, tuple(q))  # symbolic, once per potential
            d3 = pert.third_derivatives(V, tuple(q))
            d2 = hess.tolist()
            pt, un = self.pt, self.unperturbed  # numbers: xreplace is subs here
            n = range(len(q))
            self._v = {
                "dV": {(k,): d1[k].xreplace(pt) - d1[k].xreplace(un) for k in n},
                "d2V": {(k, m): d2[k][m].xreplace(pt) - d2[k][m].xreplace(un) for k in n
                        for m in n},
                "K0": {(k, m): d2[k][m].xreplace(un) for k in n for m in n},
                "d3V0": {(k, m, i): d3[k][m][i].xreplace(un) for k in n for m in n
                         for i in n},
                "at": at, "V": V, "hessian": d2, "q": q}
        return self._v

    def number(self, name: str, args: tuple[int, ...]):
        i = [a - 1 for a in args]
        f = len(self.ctx.system.q)
        if any(a < 0 or a >= f for a in i):
            raise UnsupportedError(f"{name}{args}: index out of range 1..{f}")
        if name == "W0":
            return self.s.W0[i[0]]
        if name == "omega0":
            return mpmath.sqrt(self.s.W0[i[0]])
        if name == "Wp":
            return self.s.Wp[i[0], i[1]]
        if name == "b":
            return self.s.b[i[0], i[1]]
        v = self.potential_derivatives()
        if name == "Delta_star":
            K0 = self.k0()
            for r in range(K0.rows):
                K0[r, i[0]] = -self.at(v["dV"][(r,)])
            return mpmath.det(K0)
        return self.at(v[name][tuple(i)])

    def at(self, expr):
        """expr at the unperturbed equilibrium, DPS digits."""
        v = self.potential_derivatives()
        return _mp(sp.S(expr).subs(v["at"]))

    def k0(self):
        v = self.potential_derivatives()
        n = len(v["q"])
        K0 = mpmath.matrix(n, n)
        for k in range(n):
            for m in range(n):
                K0[k, m] = self.at(v["K0"][(k, m)])
        return K0

    def evaluate(self, expr: sp.Expr):
        """The book's expression, its tables replaced by numbers, at DPS digits."""
        def swap(e):
            return _number(self.number(e.func.__name__, tuple(int(a) for a in e.args)))

        with mpmath.workdps(pert.DPS):
            out = expr.replace(lambda e: isinstance(e, AppliedUndef)
                               and e.func.__name__ in TABLES
                               and all(a.is_Integer for a in e.args), swap)
            if out.has(DELTA):
                out = out.subs(DELTA, _number(mpmath.det(self.k0())))
            out = out.subs(self.pt)
            if any(isinstance(e, AppliedUndef) for e in out.atoms(sp.Function)):
                raise UnsupportedError("a table is used with an index that is not a number")
            return _mp(out)


def _mp(expr: sp.Expr):
    """A SymPy number as an mpmath number at DPS digits (never through a double)."""
    z = sp.N(expr, pert.DPS)
    re, im = z.as_real_imag()
    if not (re.is_number and im.is_number):
        raise UnsupportedError(f"does not evaluate to a number: {expr}")
    if not (re.is_finite and im.is_finite):  # nan or zoo: a table entry divided by 0
        raise UnsupportedError(f"does not evaluate to a finite number: {expr}")
    re = mpmath.mpf(sp.Float(re, pert.DPS)._mpf_)
    return re if im == 0 else mpmath.mpc(re, mpmath.mpf(sp.Float(im, pert.DPS)._mpf_))


DELTA = sp.Symbol("Delta_det")


def _number(z) -> sp.Expr:
    z = mpmath.mpmathify(z)
    re = sp.Float(mpmath.nstr(mpmath.re(z), pert.DPS), pert.DPS)
    if mpmath.im(z) == 0:
        return re
    return re + sp.I * sp.Float(mpmath.nstr(mpmath.im(z), pert.DPS), pert.DPS)


def _indices(ctx: Context, spec, names: dict, count: int) -> list:
    """`component:` as a list of `count` items: numbers (0-based) or index symbols."""
    spec = spec if isinstance(spec, list) else [spec]
    if len(spec) != count:
        raise ctx.part.error(("component",), f"expected {count} index(es)")
    out = []
    for c in spec:
        if isinstance(c, int):
            out.append(c - 1)
        elif isinstance(names.get(c), sp.Symbol) and names[c].is_integer:
            out.append(names[c])
        else:
            raise ctx.part.error(("component",), f"{c!r} is neither a number nor an index")
    return out


def _assignments(idx: list, f: int, mode: int, avoid_mode: bool) -> list[dict]:
    """Every assignment of numbers to the index symbols among `idx` (skipping the mode's
    own number when `avoid_mode`)."""
    syms = [x for x in idx if isinstance(x, sp.Symbol)]
    out = [{}]
    for s in syms:
        out = [{**a, s: k} for a in out for k in range(f) if not (avoid_mode and k == mode)]
    return out


@quantity('perturbation',
          book='expression in the text\'s perturbation notation',
          how=('the formula (W0(j), Wp(j, r), b(j, r), sum(expr, r, excluded...), ...; '
               '`approximates:` what, `mode:` which mode) against the exact value '
               '(50 digits) as `limit:`\'s parameter → 0: the error must fall like '
               'ε^(order + 1) (see mechbook/verify/quantities/perturbation.py)'),
          keys={"limit": LIMIT, "approximates": {"enum": list(KINDS)},
                "mode": {"type": "integer", "minimum": 1},
                "component": {"oneOf": [INDEX, {"type": "array", "items": INDEX}]},
                "indices": {"type": "array", "items": {"type": "string"}},
                "group": {"type": "array", "items": {"type": "integer", "minimum": 1}},
                "reference": EXPR, "unperturbed": POINT},
          names=lambda ctx: _names(ctx)[0],
          complex_values=True)
def check_perturbation(ctx: Context, val):
    for key in ("limit", "approximates"):
        if key not in ctx.part.data:
            raise ctx.part.error((), f"a perturbation part needs `{key}:`")
    names, _ = _names(ctx)
    book = ctx.parse(val, ("book",), names=names)
    spec = ctx.part.data
    kind = spec["approximates"]
    f = len(ctx.system.q)
    mode = spec.get("mode", 1) - 1
    unperturbed = _unperturbed(ctx)

    def error(pt) -> float:
        base = {k: sp.S(v).subs(pt) for k, v in unperturbed.items()}
        T = _Tables(ctx, pt, base)
        with mpmath.workdps(pert.DPS):
            return float(_error(ctx, kind, book, T, names, f, mode))

    return asymptotic(ctx, error, floor=1e-40)


def _unperturbed(ctx: Context) -> dict:
    """{parameter: its unperturbed value} (`unperturbed:`, default the limit's parameter
    at 0)."""
    spec = ctx.part.data
    out = {}
    for k, v in (spec.get("unperturbed") or {spec["limit"]["parameter"]: 0}).items():
        sym = ctx.names.get(k)
        if not isinstance(sym, sp.Symbol):
            raise ctx.part.error(("unperturbed", k), f"unknown parameter {k!r}")
        out[sym] = ctx.parse(v, ("unperturbed", k))
    return out


def formula_difference(ctx: Context, a: sp.Expr, b: sp.Expr):
    """pt ↦ the largest relative difference of two formulas in the text's notation, their
    tables filled at pt, over every value 1..f of the index names they use (an index value
    where either has no value, e.g. a zero denominator W0(j) − W0(1) at j = 1, is skipped):
    how far apart two answers are, without the engine's exact value."""
    import itertools

    _, idx = _names(ctx)
    f = len(ctx.system.q)
    used = [i for i in idx if a.has(i) or b.has(i)]
    unperturbed = _unperturbed(ctx)

    def error(pt) -> float:
        T = _Tables(ctx, pt, {k: sp.S(v).subs(pt) for k, v in unperturbed.items()})
        worst = mpmath.mpf(0)
        with mpmath.workdps(pert.DPS):
            for values in itertools.product(range(1, f + 1), repeat=len(used)):
                at = dict(zip(used, values, strict=True))
                try:
                    va, vb = T.evaluate(a.subs(at)), T.evaluate(b.subs(at))
                except (ZeroDivisionError, ValueError, TypeError, UnsupportedError):
                    continue
                if not (mpmath.isfinite(va) and mpmath.isfinite(vb)):
                    continue
                worst = max(worst, abs(va - vb) / max(1, abs(va)))
        return float(worst)

    return error


def _error(ctx, kind, book, T: _Tables, names, f, mode):

    if kind in ("squared_frequency", "component", "exponent", "damped_component", "group"):
        s = T.s
    if kind == "squared_frequency":
        w, _ = pert.exact_eigen(s)
        return abs(T.evaluate(book) - w[mode]) / max(1, abs(s.W0[mode]))
    if kind == "component":
        _, V = pert.exact_eigen(s)
        sign = 1 if V[mode, mode] > 0 else -1
        (c,) = _indices(ctx, ctx.part.data.get("component", mode + 1), names, 1)
        worst = mpmath.mpf(0)
        for a in _assignments([c], f, mode, avoid_mode=True):
            j = a.get(c, c) if isinstance(c, sp.Symbol) else c
            got = T.evaluate(book.subs({k: v + 1 for k, v in a.items()}))
            worst = max(worst, abs(got - sign * V[j, mode]))
        return worst
    if kind in ("exponent", "damped_component"):
        p, vec = pert.exact_damped(s, mode)
        if kind == "exponent":
            return abs(T.evaluate(book) - p) / max(1, abs(p))
        (c,) = _indices(ctx, ctx.part.data.get("component", mode + 1), names, 1)
        worst = mpmath.mpf(0)
        for a in _assignments([c], f, mode, avoid_mode=True):
            j = a.get(c, c) if isinstance(c, sp.Symbol) else c
            worst = max(worst, abs(T.evaluate(book.subs({k: v + 1 for k, v in a.items()}))
                                   - vec[j]))
        return worst
    if kind in ("equilibrium", "stiffness"):
        v = T.potential_derivatives()
        x0 = pert.perturbed_equilibrium(v["V"], v["q"], T.pt, v["at"])  # V at T.pt there
        comps = _indices(ctx, ctx.part.data.get("component"), names,
                         1 if kind == "equilibrium" else 2)
        worst = mpmath.mpf(0)
        for a in _assignments(comps, f, mode, avoid_mode=False):
            ks = [a[c] if isinstance(c, sp.Symbol) else c for c in comps]
            got = T.evaluate(book.subs({k: v + 1 for k, v in a.items()}))
            if kind == "equilibrium":
                exact = x0[ks[0]] - T.at(v["q"][ks[0]])
                scale = 1
            else:
                at = {q: sp.Float(mpmath.nstr(x, pert.DPS), pert.DPS)
                      for q, x in zip(v["q"], x0, strict=True)}
                hess = v["hessian"][ks[0]][ks[1]].xreplace(T.pt)
                exact = (_mp(hess.subs(at))
                         - T.number("K0", tuple(k + 1 for k in ks)))
                scale = max(1, max(abs(T.number("K0", (i + 1, i + 1))) for i in range(f)))
            worst = max(worst, abs(got - exact) / scale)
        return worst
    if kind == "group":
        group = [g - 1 for g in ctx.part.data.get("group", [])]
        if len(group) < 2 or any(g >= f for g in group):
            raise ctx.part.error(("group",), "a group of at least two modes 1..f")
        j, r = _indices(ctx, ctx.part.data.get("component"), names, 2)
        if not (isinstance(j, sp.Symbol) and isinstance(r, sp.Symbol)):
            raise ctx.part.error(("component",), "give the matrix's two index names")
        n = len(group)
        Mx = mpmath.matrix(n, n)
        for a, ga in enumerate(group):
            for c, gc in enumerate(group):
                Mx[a, c] = mpmath.re(T.evaluate(book.subs({j: ga + 1, r: gc + 1})))
        ref = T.evaluate(ctx.parse(ctx.part.data.get("reference", 0), ("reference",),
                                   names=names))
        approx = sorted(mpmath.re(ref) + x for x in mpmath.eig(Mx, left=False, right=False))
        w, _ = pert.exact_eigen(s)
        exact = sorted(w[g] for g in group)
        return max(abs(x - y) for x, y in zip(approx, exact, strict=True)) / max(
            1, max(abs(s.W0[g]) for g in group))
    raise ctx.part.error(("approximates",), f"unknown kind {kind!r}")
