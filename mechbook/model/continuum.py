"""A continuous system given by its Lagrangian density (`field:`): the field's names, its
domain, its boundaries, and whether the boundary conditions close.

The density ℒ is an expression in the field u, its first derivatives u_t, u_x, u_y (u_r,
u_theta on a disk or an annulus), its second space derivatives (a beam's u_xx), the
coordinates and the parameters. The domain is a segment 0 ≤ x ≤ L, a rectangle
0 ≤ x ≤ a, 0 ≤ y ≤ b, a disk r ≤ R or an annulus R1 ≤ r ≤ R2 (polar coordinates: the
action is ∫ℒ·r dr dθ). Each edge is `fixed` (u = 0), `free` (the natural conditions),
`clamped` (u = 0 and its normal derivative 0), `hinged` (u = 0 and the natural moment
condition) or elastic, `{mass: M, spring: k}` at a segment's end (a point Lagrangian
½M·u_t² − ½k·u² added there). A field equation of order 2m in the normal coordinate needs
m conditions at each edge: `fixed` gives one, `clamped` and `hinged` two, `free` and an
elastic end m. Conditions that do not close are an error at the edge's line.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

from mechbook.errors import ExpressionError
from mechbook.model.expr import parse
from mechbook.model.yamlio import Document

T = sp.Symbol("t", real=True)
MAX_TIME_ORDER = 2
MAX_SPACE_ORDER = 4
EDGES = {"segment": ("left", "right"), "rectangle": ("x0", "x1", "y0", "y1"),
         "disk": ("edge",), "annulus": ("inner", "outer")}
KINDS = ("fixed", "free", "clamped", "hinged")


@dataclass(frozen=True)
class Edge:
    """One edge: where it is (its coordinate's index and value), its outward sign and kind."""

    name: str
    axis: int  # index of the normal coordinate in `coords`
    at: sp.Expr  # the normal coordinate's value on the edge
    sign: int  # +1 where the outward normal points along the coordinate
    kind: str  # fixed, free, clamped, hinged or elastic
    mass: sp.Expr = sp.S.Zero  # elastic: the point mass and spring at a segment's end
    spring: sp.Expr = sp.S.Zero


@dataclass(eq=False)
class FieldModel:
    """A field's density, names and boundary, parsed: what the engine derives from."""

    name: str
    domain: str  # segment, rectangle, disk or annulus
    coords: tuple  # the space coordinates' symbols: (x,), (x, y) or (r, theta)
    size: tuple  # segment (L,), rectangle (a, b), disk (R,), annulus (R1, R2)
    density: sp.Expr
    edges: tuple  # Edge, ...
    names: dict = field(default_factory=dict)  # the jet's names and the coordinates
    jets: dict = field(default_factory=dict)  # (time order, space orders...) -> symbol
    path: tuple = ("field",)

    @property
    def polar(self) -> bool:
        return self.domain in ("disk", "annulus")

    def jet(self, orders: tuple) -> sp.Symbol:
        """The symbol of ∂_t^a ∂_1^b ∂_2^c u for orders (a, b, c[:dims])."""
        if orders not in self.jets:
            self.jets[orders] = sp.Symbol(jet_name(self.name, self.coord_names, orders),
                                          real=True)
        return self.jets[orders]

    @property
    def coord_names(self) -> tuple:
        return tuple(str(c) for c in self.coords)

    def space_order(self) -> int:
        """The highest space derivative in the density (1 for a membrane, 2 for a beam)."""
        return max((sum(o[1:]) for o, s in self.jets.items() if self.density.has(s)),
                   default=0)


def jet_name(name: str, coords: tuple, orders: tuple) -> str:
    """u, u_t, u_xx, u_ttxy, u_rtheta: the field's name and its derivatives' letters."""
    letters = "t" * orders[0] + "".join(c * k for c, k in zip(coords, orders[1:], strict=True))
    return f"{name}_{letters}" if letters else name


def _jets(name: str, coords: tuple) -> dict:
    dims = len(coords)
    out = {}
    for a in range(MAX_TIME_ORDER + 1):
        for b in range(MAX_SPACE_ORDER + 1):
            for c in range(MAX_SPACE_ORDER + 1 - b if dims == 2 else 1):
                orders = (a, b, c) if dims == 2 else (a, b)
                out[orders] = sp.Symbol(jet_name(name, coords, orders), real=True)
    return out


def _domain(doc: Document, spec: dict, params: dict, path: tuple) -> tuple:
    dom = spec["domain"]
    (kind, value), = dom.items()
    where = path + ("domain", kind)

    def size(text, sub=()):
        try:
            out = parse(text, params)
        except ExpressionError as exc:
            raise doc.error(where + sub, str(exc)) from None
        if out.free_symbols - set(params.values()):
            raise doc.error(where + sub, "a size is given by the parameters")
        return out

    if kind in ("segment", "disk"):
        sizes = (size(value),)
    else:
        sizes = tuple(size(v, (i,)) for i, v in enumerate(value))
    if kind in ("segment", "rectangle"):
        coords = (sp.Symbol("x", real=True),) + ((sp.Symbol("y", real=True),)
                                                 if kind == "rectangle" else ())
    else:
        coords = (sp.Symbol("r", positive=True), sp.Symbol("theta", real=True))
    return kind, coords, sizes


def _edges(kind: str, sizes: tuple) -> list:
    """(name, axis, at, sign) of each edge of the domain."""
    if kind == "segment":
        return [("left", 0, sp.S.Zero, -1), ("right", 0, sizes[0], 1)]
    if kind == "rectangle":
        return [("x0", 0, sp.S.Zero, -1), ("x1", 0, sizes[0], 1),
                ("y0", 1, sp.S.Zero, -1), ("y1", 1, sizes[1], 1)]
    if kind == "disk":
        return [("edge", 0, sizes[0], 1)]
    return [("inner", 0, sizes[0], -1), ("outer", 0, sizes[1], 1)]


def conditions_given(kind: str, half_order: int) -> int:
    """How many conditions an edge of this kind imposes where the equation has order
    2·half_order in the normal coordinate."""
    return {"fixed": 1, "clamped": 2, "hinged": 2}.get(kind, half_order)


def field_of(doc: Document, params: dict, path: tuple = ("field",)) -> FieldModel:
    """The problem's `field:` parsed and checked (SpecError with file and line when an
    expression does not parse or the boundary conditions do not close).

    >>> # field: {domain: {segment: L}, density: "rho*u_t**2/2 - tau*u_x**2/2",
    >>> #         boundary: {left: fixed, right: fixed}}
    """
    spec = doc.data
    for p in path:
        spec = spec[p]
    name = spec.get("name", "u")
    kind, coords, sizes = _domain(doc, spec, params, path)
    cnames = tuple(str(c) for c in coords)
    jets = _jets(name, cnames)
    names = dict(params)
    clash = [n for n in [*(str(s) for s in jets.values()), *cnames, "t"] if n in params]
    if clash:
        raise doc.error(path + ("name",), f"{clash[0]!r} is a parameter and a name of the "
                        "field; rename one")
    names.update({str(s): s for s in jets.values()})
    names.update({str(c): c for c in coords})
    names["t"] = T
    try:
        density = parse(spec["density"], names)
    except ExpressionError as exc:
        raise doc.error(path + ("density",), str(exc)) from None
    model = FieldModel(name, kind, coords, sizes, density, (), names, jets, path)
    high = [o for o, s in jets.items() if density.has(s) and (o[0] > 1 or sum(o) > 2 or
                                                             (o[0] and sum(o[1:])))]
    if high:
        raise doc.error(path + ("density",), f"{jet_name(name, cnames, high[0])}: a density "
                        "holds u_t and space derivatives of u up to the second, not "
                        "mixed ones with t")
    if not any(density.has(jets[o]) for o in jets if o[0] == 1):
        raise doc.error(path + ("density",), f"the density has no {name}_t: no kinetic "
                        "term, no motion")
    model.edges = tuple(_edge_specs(doc, spec, path, model, _edges(kind, sizes)))
    return model


def _edge_specs(doc: Document, spec: dict, path: tuple, model: FieldModel, edges: list):
    bound = spec.get("boundary") or {}
    allowed = {e[0] for e in edges} | {"all"}
    for k in bound:
        if k not in allowed:
            raise doc.error(path + ("boundary", k), f"no edge {k!r} on a {model.domain} "
                            f"(its edges: {', '.join(e[0] for e in edges)}, or all)")
    half = model.space_order()
    if half == 0:
        raise doc.error(path + ("density",), "the density has no space derivative of "
                        f"{model.name}: no field equation in space")
    order = "two" if half == 1 else "four"
    for name, axis, at, sign in edges:
        given = bound.get(name, bound.get("all"))
        where = path + ("boundary", name if name in bound else "all")
        if given is None:
            raise doc.error(path + ("boundary",), f"edge {name!r} has no boundary condition "
                            f"(one of {', '.join(KINDS)}, or {{mass, spring}})")
        if isinstance(given, dict):
            if model.domain != "segment":
                raise doc.error(where, "an elastic edge (a mass or a spring) is for a "
                                "segment's end")
            vals = {}
            for k in ("mass", "spring"):
                try:
                    vals[k] = parse(given.get(k, 0), model.names)
                except ExpressionError as exc:
                    raise doc.error(where + (k,), str(exc)) from None
                if vals[k].free_symbols - {p for p in model.names.values()
                                           if p not in model.jets.values()} - set(model.coords):
                    raise doc.error(where + (k,), "a constant of the parameters")
            yield Edge(name, axis, at, sign, "elastic", vals["mass"], vals["spring"])
            continue
        n = conditions_given(given, half)
        if n != half:
            raise doc.error(where, f"the boundary conditions do not close: the field "
                            f"equation is of order {order} in the normal coordinate, so "
                            f"each edge needs {half} condition{'s' if half > 1 else ''}; "
                            f"{given!r} gives {n}" +
                            (" (a beam's end: clamped, hinged or free)" if half == 2 else
                             " (fixed, free, or a mass or spring)"))
        yield Edge(name, axis, at, sign, given)
