"""A functional J = ∫F(x, y, y′, y″, …) dx a problem declares (`functional:`), as symbols.

    functional:
      independent: x                       # the variable of integration
      functions: [y]                       # the dependent functions (several: a parametric
      integrand: "sqrt((1 + yp**2)/(2*g*y))"  # curve, a path in space)
      ends: [{x: 0, y: 0}, {x: X, y: Y}]   # a function's value, or `free` (natural end)
      constraints:
        - {name: length, integral: "sqrt(1 + yp**2)", value: l}   # isoperimetric
        - {name: sphere, holonomic: "x**2 + y**2 + z**2 - R**2"}   # on the curve

A function `y` is written with its derivatives `yp` (y′) and `ypp` (y″). The integrand must
be differentiable in the derivatives twice (Euler–Lagrange needs ∂F/∂y′, Legendre's
condition ∂²F/∂y′²): a kink such as Abs(yp) is refused at its line. Nothing here is derived
beyond those two checks: mechbook.engine.variational derives the equations.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

from mechbook.errors import ExpressionError
from mechbook.model.expr import parse
from mechbook.model.yamlio import Document

MAX_ORDER = 2  # the highest derivative an integrand may hold (y″)
# what a derivative of a differentiable integrand never holds
KINKS = (sp.Abs, sp.sign, sp.Heaviside, sp.DiracDelta, sp.Piecewise, sp.Min, sp.Max,
         sp.floor, sp.ceiling, sp.frac, sp.Derivative, sp.Subs)
FREE = "free"  # an end where a function's value is left free (a natural boundary condition)


def derivative_name(name: str, k: int) -> str:
    """The name of the k-th derivative of function `name` (y, yp, ypp, …)."""
    return name + "p" * k


@dataclass
class End:
    """One end: the independent variable's value there, and each function's value (None: free)."""

    at: sp.Expr
    values: dict[str, sp.Expr | None]
    path: tuple


@dataclass
class Constraint:
    """An isoperimetric constraint ∫G dx = value (multiplier the constant lambda_<name>) or a
    holonomic one φ = 0 on the curve (multiplier the function mu_<name> of x)."""

    name: str
    kind: str  # 'integral' or 'holonomic'
    expr: sp.Expr  # G, or φ
    value: sp.Expr | None
    multiplier: sp.Symbol
    path: tuple


@dataclass
class Functional:
    """The declared functional with its symbols: x, the functions' jets (y, y′, …, y⁽²ⁿ⁾ for
    the Euler–Lagrange equation of order 2n), the ends and the constraints."""

    x: sp.Symbol
    functions: list[str]
    jets: list[list[sp.Symbol]]  # jets[i][k]: the k-th derivative of function i
    integrand: sp.Expr
    order: int  # the highest derivative F holds (1 or 2)
    ends: list[End]
    constraints: list[Constraint] = field(default_factory=list)
    path: tuple = ("functional",)

    def names(self) -> dict[str, sp.Basic]:
        """The names an answer may use: x, the functions, their derivatives, multipliers."""
        out: dict[str, sp.Basic] = {str(self.x): self.x}
        for name, jet in zip(self.functions, self.jets, strict=True):
            out.update({derivative_name(name, k): s for k, s in enumerate(jet)})
        out.update({str(c.multiplier): c.multiplier for c in self.constraints})
        return out

    def function_symbols(self, k: int = 0) -> list[sp.Symbol]:
        """The k-th derivatives of all functions, in order."""
        return [jet[k] for jet in self.jets]


def functional_of(doc: Document, names: dict[str, sp.Basic]) -> Functional | None:
    """The problem's `functional:` built from its data (None if it declares none), the
    problem's `names` (parameters) available; SpecError with file and line on any fault."""
    data = doc.data.get("functional")
    if data is None:
        return None
    root = ("functional",)
    taken = dict(names)

    def claim(name: str, path: tuple) -> sp.Symbol:
        if name in taken or name == "pi":
            raise doc.error(path, f"{name!r} is already a name (a parameter, another "
                            "function or its derivative yp, ypp)")
        taken[name] = sp.Symbol(name, real=True)
        return taken[name]

    x = claim(data["independent"], root + ("independent",))
    functions = list(data["functions"])
    jets = []
    for i, f in enumerate(functions):
        jets.append([claim(derivative_name(f, k), root + ("functions", i))
                     for k in range(2 * MAX_ORDER + 1)])
    constraints = []
    for i, c in enumerate(data.get("constraints") or []):
        path = root + ("constraints", i)
        kind = [k for k in ("integral", "holonomic") if k in c]
        if len(kind) != 1:
            raise doc.error(path, "a constraint is either `integral:` (with `value:`) or "
                            "`holonomic:`")
        kind = kind[0]
        if (kind == "integral") != ("value" in c):
            raise doc.error(path, "`value:` goes with `integral:` (∫G dx = value)")
        prefix = "lambda_" if kind == "integral" else "mu_"
        mult = claim(prefix + c["name"], path + ("name",))
        constraints.append(Constraint(c["name"], kind, None, None, mult, path))
    allowed = {str(x): x}
    for f, jet in zip(functions, jets, strict=True):
        allowed.update({derivative_name(f, k): jet[k] for k in range(MAX_ORDER + 1)})
    allowed.update(names)

    def expr(text, path, extra=allowed):
        try:
            return parse(text, extra)
        except ExpressionError as exc:
            raise doc.error(path, str(exc)) from None

    integrand = expr(data["integrand"], root + ("integrand",))
    order = _order(integrand, jets)
    if order > MAX_ORDER:
        raise doc.error(root + ("integrand",), f"derivatives up to the {MAX_ORDER}nd only")
    _differentiable(doc, integrand, jets, root + ("integrand",))
    for c, spec in zip(constraints, data.get("constraints") or [], strict=True):
        if c.kind == "integral":
            c.expr = expr(spec["integral"], c.path + ("integral",))
            order = max(order, _order(c.expr, jets))  # F̃ = F + λG holds both
            _differentiable(doc, c.expr, jets, c.path + ("integral",))
            c.value = expr(spec["value"], c.path + ("value",), names)
        else:
            point = {str(x): x, **{f: jet[0] for f, jet in zip(functions, jets, strict=True)},
                     **names}
            c.expr = expr(spec["holonomic"], c.path + ("holonomic",), point)
    order = max(order, 1)  # F(x, y) alone: its Euler–Lagrange equation is F_y = 0
    ends = [_end(doc, e, root + ("ends", i), x, functions, names, expr)
            for i, e in enumerate(data["ends"])]
    return Functional(x, functions, jets, integrand, order, ends, constraints, root)


def _order(expr: sp.Expr, jets: list[list[sp.Symbol]]) -> int:
    """The highest derivative of any function in `expr` (0: none)."""
    used = expr.free_symbols
    return max((k for jet in jets for k, s in enumerate(jet) if s in used), default=0)


def _differentiable(doc: Document, expr: sp.Expr, jets, path: tuple) -> None:
    """SpecError at `path` unless `expr` is twice differentiable in every derivative it holds
    (its derivatives free of Abs, sign, Piecewise, …)."""
    for jet in jets:
        for s in jet[1:MAX_ORDER + 1]:
            if s not in expr.free_symbols and not expr.has(sp.Derivative):
                continue
            first = sp.diff(expr, s)
            for d in (first, sp.diff(first, s)):
                bad = [k.__name__ for k in KINKS if d.has(k)]
                if bad:
                    raise doc.error(path, f"the integrand is not differentiable in {s} (its "
                                    f"derivative in {s} holds {bad[0]}): the Euler–Lagrange "
                                    "equation needs ∂F/∂y′ and Legendre's condition ∂²F/∂y′²")


def _end(doc: Document, spec: dict, path: tuple, x: sp.Symbol, functions: list[str],
         names: dict, expr) -> End:
    """One end: `{x: value, y: value or free, …}`: x and every function named."""
    missing = [n for n in [str(x), *functions] if n not in spec]
    if missing:
        raise doc.error(path, f"an end gives {str(x)!r} and every function ({missing[0]!r} "
                        "is missing; write `free` for a value left free)")
    extra = sorted(set(spec) - {str(x), *functions})
    if extra:
        raise doc.error(path + (extra[0],), f"{extra[0]!r} is neither the independent "
                        "variable nor a function")
    at = expr(spec[str(x)], path + (str(x),), names)
    values = {f: None if spec[f] == FREE else expr(spec[f], path + (f,), names)
              for f in functions}
    return End(at, values, path)
