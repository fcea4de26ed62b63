"""Asymptotic formulas (`limit: {parameter, to, order}`): the error's order measured as a
parameter is walked toward its limit. Shared by every quantity that takes `limit:`.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from mechbook.errors import MechbookError
from mechbook.verify.compare import Verdict
from mechbook.verify.context import Context

LIMIT_STEPS = tuple(10.0 ** (-1 - k / 2) for k in range(7))  # 1e-1 ... 1e-4, half decades
MORE_STEPS = tuple(10.0 ** (-4.5 - k / 2) for k in range(12))  # on to 1e-10 while needed
SMALL_ENOUGH = 1e-9  # an error this small ends the walk toward the limit


def asymptotic(ctx: Context, error, floor: float | None = None) -> Verdict:
    """`limit: {parameter, to, order}`: the book's formula holds in a limit of the
    parameters, to the stated order. The error `error(point)` (relative, from values exact
    to 50 digits) is measured as the parameter goes to 0 or ∞ in half decades from 1e-1 of
    its value, to 1e-4 and on (to 1e-10 at most, or as far as the engine computes) until
    the error is below 1e-9 of ε^order (the size of the last term claimed); over the last
    three steps it must fall like the parameter to a power of at least order + 0.5 (a
    formula right to order k errs like ε^(k+1); one wrong at order k errs like ε^k), ending
    below 1e-3 — or vanish (below 1e-30) there: exact. Walking on until the error is tiny
    against the claimed order's term is what rejects a coefficient of that order wrong by
    1e-6: its error stops falling faster than ε^k there. `floor` is the error function's
    resolution (1e-13 for one computed in double precision, 1e-40 at 50 digits): the walk
    goes past 1e-4 only when it is given, stops at it, and judges the steps above it; an
    error function with no stated floor (a simulation's) stops at 1e-4."""
    spec = ctx.part.data["limit"]
    name = spec["parameter"]
    if name not in ctx.names or not isinstance(ctx.names[name], sp.Symbol):
        raise ctx.part.error(("limit", "parameter"), f"unknown parameter {name!r}")
    sym = ctx.names[name]
    if sym in ctx.sampler.derived:
        raise ctx.part.error(("limit", "parameter"), f"{name!r} is computed by `restrict:` "
                             "from the others, so it cannot be walked toward the limit")
    order = spec.get("order", 0)
    to_zero = str(spec["to"]) == "0"
    base = ctx.sampler.default()
    errors = []
    steps = []
    for eps in LIMIT_STEPS + (MORE_STEPS if floor is not None else ()):
        if eps in MORE_STEPS and not (errors[-1] / steps[-1] ** order >= SMALL_ENOUGH
                                      and errors[-1] >= 10 * floor):
            break  # small enough against the claimed order's term, or at the resolution
        pt = dict(base)
        pt[sym] = sp.Float(base[sym] * eps if to_zero else base[sym] / eps, 30)
        pt = ctx.sampler.complete(pt)
        if eps in MORE_STEPS:  # beyond the usual walk: where the engine gives up, stop
            try:
                e = float(error(pt)) if pt is not None else float("nan")
            except (MechbookError, ZeroDivisionError, ValueError, OverflowError):
                break
            if not np.isfinite(e):
                break
            errors.append(e)
        else:
            errors.append(float(error(pt)) if pt is not None else float("nan"))
        steps.append(eps)
    if floor is not None:  # the steps at the error function's resolution say nothing
        while len(errors) > 3 and errors[-1] < 10 * floor and steps[-1] in MORE_STEPS:
            errors.pop()
            steps.pop()
    tail = errors[-3:]
    shown = ", ".join(f"{e:.2g}" for e in errors)
    if not all(np.isfinite(tail)):
        return Verdict(False, "numeric(asymptotic)", f"relative error {shown}: the formula "
                       "does not evaluate (or match) near the limit")
    if all(e < 1e-30 for e in tail):
        return Verdict(True, "numeric(asymptotic)", f"relative error {shown}: exact in the "
                       "limit's last steps", power="exact (below 1e-30) toward the limit")
    if not all(np.isfinite(tail)) or min(tail) <= 0:
        return Verdict(False, "numeric(asymptotic)", f"relative error {shown}")
    logs = np.log10(tail)
    slope = float(np.polyfit(np.log10(steps[-3:]), logs, 1)[0])
    ok = tail[-1] < 1e-3 and slope >= order + 0.5
    detail = (f"relative error {shown} as {name} -> {spec['to']} by half decades from 1e-1: "
              f"it falls like {name}**{slope:.2f} (needs {order + 0.5:g} or more)"
              if to_zero else
              f"relative error {shown} as {name} -> oo by half decades from x10: it falls "
              f"like (1/{name})**{slope:.2f} (needs {order + 0.5:g} or more)")
    return Verdict(ok, "numeric(asymptotic)", detail,
                   power=f"error falls like ε^{slope:.2f} toward the limit, to {tail[-1]:.1g} "
                         f"(order {order} claimed)")
