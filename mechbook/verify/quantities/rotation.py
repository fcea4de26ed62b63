"""Rotating bodies: `rotation_matrix`, `precession_rate`, `identity`, `solution`.

These read a body's attitude (mechbook.model.attitude): its rotation matrix R (body
components -> space components), its angular velocity ω and inertia tensor, and the
rate names (`rates:`) a problem gives to the body components of ω, so Euler's equations,
conserved quadrics of free rotation (polhode, herpolhode) and the motion of ω relative to
the body can be stated as the book states them.
"""

from __future__ import annotations

import sympy as sp

from mechbook.model.attitude import rotation_matrix
from mechbook.verify.compare import Verdict, all_vanish, combine, equal
from mechbook.verify.context import Context
from mechbook.verify.registration import ESTIMATE, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

BODY = {"type": "string"}
VECTOR = {"oneOf": [{"enum": ["omega", "L", "e1", "e2", "e3", "x", "y", "z"]},
                    {"type": "array", "minItems": 3, "maxItems": 3,
                     "items": {"$ref": "#/$defs/expr"}}]}


def _body(ctx: Context) -> str:
    name = ctx.part.data.get("body")
    sys = ctx.system
    if name not in sys.inertias:
        raise ctx.part.error(("body",), f"no 3-D rigid body {name!r} (have "
                             f"{', '.join(sys.inertias) or 'none'})")
    if name not in sys.attitudes:
        raise ctx.part.error(("body",), f"body {name!r} has no attitude (`euler_angles` or "
                             "`rotation`)")
    return name


def on_shell(ctx: Context, expr: sp.Expr) -> sp.Expr:
    """Accelerations replaced by the engine's (needed only if expr has any)."""
    if expr.free_symbols & set(ctx.dyn.qdd):
        return expr.xreplace(dict(zip(ctx.dyn.qdd, ctx.dyn.accelerations, strict=True)))
    return expr


def with_momenta(ctx: Context, expr: sp.Expr) -> sp.Expr:
    """p_<q> in a book expression replaced by the engine's momenta ∂L/∂q̇."""
    sub = {ctx.names["p_" + c]: p for c, p in zip(ctx.system.coord_names, ctx.dyn.momenta,
                                                   strict=True) if ("p_" + c) in ctx.names}
    return expr.subs(sub)


@quantity('rotation_matrix',
          book='3×3 list: the matrix a_ij',
          how=('entry by entry at random attitudes: `transform: space_to_body` (default; '
               'a_ij carries space components to body components, Rᵀ) or `body_to_space` '
               "(R), R the product of the body's chain of rotations"),
          keys={"body": BODY, "transform": {"enum": ["space_to_body", "body_to_space"]}},
          crosschecks=("newton",))
def check_rotation_matrix(ctx: Context, val) -> Verdict:
    name = _body(ctx)
    R = rotation_matrix(ctx.system.attitudes[name])
    if ctx.part.data.get("transform", "space_to_body") == "space_to_body":
        R = R.T
    rows = ctx.as_list(val, ("book",))
    if len(rows) != 3 or any(not isinstance(r, list) or len(r) != 3 for r in rows):
        raise ctx.part.error(("book",), "a rotation matrix is a list of three rows of three")
    return combine([equal(ctx.parse(x, ("book", i, j)), R[i, j], ctx.sampler)
                    for i, row in enumerate(rows) for j, x in enumerate(row)])


def _vector(ctx: Context, name: str, spec, frame: str, key: str) -> sp.Matrix:
    """A named vector (omega, L, e1..e3, x..z) or three components, in `frame`'s axes."""
    sys = ctx.system
    R = rotation_matrix(sys.attitudes[name])
    w = sys.body_rates[name]
    if isinstance(spec, list):
        return sp.Matrix([ctx.parse(x, (key, i)) for i, x in enumerate(spec)])
    unit = {"1": 0, "2": 1, "3": 2, "x": 0, "y": 1, "z": 2}
    if spec == "omega":
        v = w
    elif spec == "L":
        v = sys.inertias[name] * w
    elif spec in ("e1", "e2", "e3"):
        v = sp.Matrix([1 if i == unit[spec[1]] else 0 for i in range(3)])
    else:  # a space axis, in body components
        v = R.T * sp.Matrix([1 if i == unit[spec] else 0 for i in range(3)])
    return R * v if frame == "space" else v


@quantity('precession_rate',
          book='expression: the angular rate of `vector:` about `axis:`',
          how=('n̂·(u × du/dt)/‖u − (u·n̂)n̂‖² in the axes of `frame:` (body: relative to '
               'the body, space: relative to space), du/dt along the motion (engine '
               'accelerations); equal to the book\'s as functions of the state at random '
               'states; `vector:`/`axis:` are omega, L, e1, e2, e3 (body axes), x, y, z '
               '(space axes) or three components in `frame:`\'s axes'),
          keys={"body": BODY, "vector": VECTOR, "axis": VECTOR,
                "frame": {"enum": ["body", "space"]}, "estimate": ESTIMATE},
          crosschecks=("newton",))
def check_precession_rate(ctx: Context, val) -> Verdict:
    name = _body(ctx)
    data = ctx.part.data
    frame = data.get("frame", "space")
    u = _vector(ctx, name, data.get("vector", "omega"), frame, "vector")
    n = _vector(ctx, name, data.get("axis", "L"), frame, "axis")
    du = on_shell(ctx, ctx.system.dt(u))
    nn = sp.sqrt(n.dot(n))
    perp = u - (u.dot(n) / nn**2) * n
    engine = n.dot(u.cross(du)) / (nn * perp.dot(perp))
    book = on_shell(ctx, ctx.parse(val, ("book",)))
    return equal(book, engine, ctx.sampler)


@quantity('state_identity',
          book='equation or list of equations between functions of the state',
          how=('each holds at random states (momenta `p_<q>` are ∂L/∂q̇, accelerations the '
               "engine's): kinematic relations such as a polhode's projection, or the rate "
               'names of a body'),
          keys={},
          crosschecks=("newton",))
def check_state_identity(ctx: Context, val) -> Verdict:
    vals = val if isinstance(val, list) else [val]
    out = []
    for i, v in enumerate(vals):
        sub = ("book", i) if isinstance(val, list) else ("book",)
        sides = [with_momenta(ctx, ctx.parse(x, sub)) for x in str(v).split("=")] \
            if str(v).count("=") == 1 else [with_momenta(ctx, ctx.parse(v, sub)), sp.S.Zero]
        state = set(ctx.system.q + ctx.system.qd + ctx.dyn.qdd)
        if not any(x.free_symbols & state for x in sides):
            raise ctx.part.error(sub, "an identity must involve the state")
        out.append(on_shell(ctx, sides[0] - sides[1]))
    return all_vanish(out, ctx.sampler)


@quantity('solution',
          book='`{rate name: f(t)}` for as many rate names as coordinates',
          how=('the book\'s functions of t are a motion of the system written in named '
               'rates (linear in the velocities): at random t, coordinates and constants, '
               'the velocities that give those rates make the engine\'s d(rate)/dt equal '
               'to the book\'s (Euler\'s equations, in Euler angles)'),
          keys={},
          crosschecks=("newton",))
def check_solution(ctx: Context, val) -> Verdict:
    sys = ctx.system
    funcs = ctx.as_map(val, ("book",))
    if len(funcs) != len(sys.q):
        raise ctx.part.error(("book",), f"give {len(sys.q)} rates (one per coordinate)")
    rates, books = [], []
    for k, v in funcs.items():
        expr = ctx.names.get(k)
        if expr is None or isinstance(expr, sp.Symbol) and expr not in sys.qd:
            raise ctx.part.error(("book", k), f"{k!r} is not a rate of the system")
        rates.append(expr)
        books.append(ctx.parse(v, ("book", k)))
    A = sp.Matrix([[sp.diff(r, v) for v in sys.qd] for r in rates])
    if any(sp.expand(r - sum((A[i, j] * v for j, v in enumerate(sys.qd)), sp.S.Zero)) != 0
           for i, r in enumerate(rates)):
        raise ctx.part.error(("book",), "the rates must be linear in the velocities")
    velocities = A.LUsolve(sp.Matrix(books))
    state = dict(zip(sys.qd, velocities, strict=True))
    out = []
    for r, b in zip(rates, books, strict=True):
        engine = on_shell(ctx, sys.dt(r)).subs(state)
        out.append(engine - sp.diff(b, sys.t))
    return all_vanish(out, ctx.sampler)
