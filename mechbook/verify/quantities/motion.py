"""Motions of the linearized system: `steady_state` (driven) and `motion` (general or
from `initial:`).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from mechbook.core.identity import nonzero_determinant
from mechbook.engine import response
from mechbook.engine.linear import LinearSystem
from mechbook.errors import UnsupportedError
from mechbook.verify.compare import Verdict, all_vanish
from mechbook.verify.context import Context, numbers
from mechbook.verify.proof import OPEN
from mechbook.verify.registration import POINT, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity


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


@quantity('steady_state',
          book='`{q: f(t)}`',
          how='satisfies the linearized driven equations')
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
    for q, qd, qdd in zip(lin.q, lin.qd, lin.qdd, strict=True):
        if q in coords:
            f = coords[q]
            subs.update({q: f, qd: sp.diff(f, t), qdd: sp.diff(f, t, 2)})
    checked = []
    for e in lin.equations():
        r = e.xreplace(subs)  # symbols only: SymPy's subs, without its pattern search
        if r.free_symbols & set(lin.q + lin.qd + lin.qdd):
            continue
        checked.append(r)
    for q, moved in lin.dependent.items():  # on a constraint manifold: as the others make it
        if q in coords:
            r = (coords[q] - lin.point.get(q, 0) - moved).xreplace(subs)
            if not r.free_symbols & set(lin.q):
                checked.append(r)
    if not checked:
        raise UnsupportedError("checking a motion that leaves every equation with unknown "
                               "coordinates (give the initial conditions instead)")
    return all_vanish(checked, ctx.sampler)


@quantity('motion',
          book='`{q or defined name: f(t)}`',
          how=('with `initial:`, equals the solution of the linearized initial-value problem '
               '(driven, damped or gyroscopic too: matrix exponential, or DOP853 at rtol '
               '1e-13 with a force) at several times; without, satisfies the linearized '
               'equations for any value of its constants; with `--prove` and `initial:`, '
               '`symbolic` where the motion is proved to satisfy the linearized equations '
               'and the initial values exactly, det M decided nonzero (a unique solution)'),
          keys={"initial": POINT})
def check_motion(ctx: Context, val) -> Verdict:
    """With `initial:`, compare with the modal solution of the linearized initial-value
    problem at several times; without, the book's general solution must satisfy the
    linearized equations for any values of its constants."""
    lin = ctx.linear()
    funcs = _time_functions(ctx, val, ("book",))
    if "initial" not in ctx.part.data:
        return _residual_of_motion(ctx, lin, funcs)
    given_q, given_v = ctx.initial()
    sys = ctx.system
    define = ctx.part.data.get("define") or {}
    forms = {k: ctx.parse(v, ("define", k)) for k, v in define.items()}
    t = sys.t
    times = [0.37, 1.3, 2.9, 7.1]
    for _ in range(4):
        pt = ctx.sampler.draw()
        q0 = np.zeros(len(sys.q))
        v0 = np.zeros(len(sys.q))
        for i, x in given_q.items():
            q0[i] = numbers([x], pt)[0]
        for i, x in given_v.items():
            v0[i] = numbers([x], pt)[0]
        eq0 = np.array(numbers([lin.point.get(q, 0) for q in sys.q], pt))
        turn = np.array(numbers([sp.S(lin.velocity.get(q, 0)) for q in sys.q], pt))  # steady rates
        path = response.motion(lin, pt, q0 - eq0, v0 - turn, times)
        for tv, dq in zip(times, path, strict=True):
            q = eq0 + turn * tv + dq
            env = dict(pt)
            env[t] = sp.Float(tv, 30)
            env.update({sq: sp.Float(x, 30) for sq, x in zip(sys.q, q, strict=True)})
            for name, f in funcs.items():
                expected = (q[sys.coord_names.index(name)] if name in sys.coord_names
                            else numbers([forms[name]], env)[0])
                got = numbers([f], env)[0]
                scale = max(np.max(np.abs(path)), np.max(np.abs(q0 - eq0)), 1e-300)
                if not abs(got - expected) <= 1e-8 * max(abs(expected), scale):
                    return Verdict(False, "numeric", f"{name}(t={tv}) = {got:.10g}, "
                                   f"engine {expected:.10g}")
    how = "driven, DOP853 rtol 1e-13" if lin.driven else "matrix exponential"
    numeric = Verdict(True, f"numeric(4 points x 4 times, linear initial-value solution, {how})",
                      power="4 points x 4 times: each coordinate to 1e-8 of the motion's size")
    return _proved_initial_value(ctx, lin, funcs, numeric) if ctx.policy.prove else numeric


def _proved_initial_value(ctx: Context, lin: LinearSystem, funcs: dict,
                          numeric: Verdict) -> Verdict:
    """With `--prove`, after the numeric pass: the book's motion satisfies the linearized
    equations and the initial values exactly, and det M is not identically 0, so (the
    initial-value problem's solution being unique) it is that solution."""
    sys = ctx.system
    coords = _coordinates_from(ctx, funcs)
    if lin.dependent or set(lin.q) != set(sys.q) or set(coords) != set(sys.q):
        numeric.unproved = "not every coordinate is given as a function of t"
        return numeric
    if not nonzero_determinant(lin.M):
        numeric.unproved = "the mass matrix is not shown invertible (no uniqueness)"
        return numeric
    t = sys.t
    given_q, given_v = ctx.initial()
    start = []
    for i, q in enumerate(sys.q):
        start.append(coords[q].subs(t, 0) - given_q.get(i, 0))
        start.append(sp.diff(coords[q], t).subs(t, 0) - given_v.get(i, 0))
    equations = _residual_of_motion(ctx, lin, funcs)
    initial = all_vanish(start, ctx.sampler)
    if equations.method == "symbolic" and initial.method == "symbolic":
        return Verdict(True, "symbolic", power="proved symbolically: the linearized equations "
                       "and the initial values hold exactly (the solution is unique)")
    numeric.unproved = equations.unproved or initial.unproved or OPEN
    return numeric

