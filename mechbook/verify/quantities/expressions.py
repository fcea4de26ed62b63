"""Named engine quantities: `expression` (`of:` potential, kinetic, energy function,
Hamiltonian, momenta; as functions or at a state) and `constraint_force`.
"""

from __future__ import annotations

import sympy as sp

from mechbook.errors import UnsupportedError
from mechbook.verify.compare import Verdict, all_vanish, combine, equal
from mechbook.verify.context import Context
from mechbook.verify.registration import POINT, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

OF = ["potential", "kinetic", "quadratic_potential", "quadratic_kinetic", "energy_function",
      "hamiltonian", "momenta"]


def _potential_shift(data: dict) -> tuple:
    """A potential (not at a state) is compared up to an additive constant."""
    plain = data.get("of") in ("potential", "quadratic_potential")
    return ("shift",) if plain and "at" not in data and "steady" not in data else ()


@quantity('expression',
          book='expression, with `of:`',
          how=('`potential`, `quadratic_potential` (up to a constant), `kinetic`, '
               '`quadratic_kinetic`, `energy_function`, `hamiltonian` (momenta `p_<q>`),'
               ' `momenta`. With `at:` (coordinates and velocities `<q>dot`), or '
               '`steady:` + `about:` (a steady motion, confirmed to be one first), the '
               'value *at that state* is compared, constant included. A Hamiltonian is '
               'checked as the Legendre transform without inverting p(q̇): H(q, ∂L/∂q̇) '
               '= h(q, q̇) and ∂H/∂p = q̇'),
          keys={"of": {"enum": OF}, "at": POINT},
          equivalent=_potential_shift,
          crosschecks=("energy_integral",))
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
        return combine(out)
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


@quantity('constraint_force',
          book='expression',
          how=('the generalized force λ·∂f/∂q of constraint `constraint:` on coordinate '
               "`coordinate:` (λ·∂c/∂q̇ of a velocity constraint; a rolling contact's "
               "`<name>_1`, `<name>_2` are the friction along its tangents), as a function of "
               "the state on the constraint manifold, equals the book's (`at:` pins"
               ' the constrained coordinates, e.g. `{r: l, rdot: 0}`). `released: {q: '
               'q0, …}` names the state the motion started from (velocities zero unless '
               'given): the one velocity `at:` leaves open is then fixed by the energy '
               'integral'),
          keys={"constraint": {"type": "string"},
                "coordinate": {"type": "string"},
                "at": POINT,
                "released": POINT},
          crosschecks=("newton",))
def check_constraint_force(ctx: Context, val) -> Verdict:
    """The generalized force λ·∂f/∂q that constraint `constraint` exerts on `coordinate`, as
    a function of the state; `at:` fixes coordinates and velocities the constraint pins
    (e.g. {r: l, rdot: 0} for a string of length l)."""
    dyn = ctx.dyn
    names = [n for n, _ in list(ctx.system.constraints) + list(ctx.system.velocity_constraints)]
    cname = ctx.part.data.get("constraint")
    if cname not in names:
        raise ctx.part.error(("constraint",), f"no constraint {cname!r} (have {names})")
    coord = ctx.part.data.get("coordinate")
    if coord not in ctx.system.coord_names:
        raise ctx.part.error(("coordinate",), f"{coord!r} is not a coordinate")
    j = names.index(cname)
    i = ctx.system.coord_names.index(coord)
    # its row of A (∂g/∂q of a holonomic constraint, ∂c/∂q̇ of a velocity constraint)
    engine = dyn.solved[dyn.multipliers[j]] * dyn.velocity_jacobian[j, i]
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
