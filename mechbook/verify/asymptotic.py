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
    parameters, to the stated order. The error `error(point)` (relative) is measured as the
    parameter goes to 0 or ∞ in half decades from 1e-1 of its value, to 1e-4 and on (to
    1e-10 at most, or as far as the engine computes) until the error is below 1e-9 of
    ε^order (the size of the last term claimed); over the last three steps it must fall
    like the parameter to a power of at least order + 0.5 (a formula right to order k errs
    like ε^(k+1); one wrong at order k errs like ε^k), ending below 1e-3 — or vanish there,
    below the error's resolution: exact to that resolution. Walking on until the error is
    tiny against the claimed order's term is what rejects a coefficient of that order wrong
    by 1e-6 (or 1e-8): its error stops falling faster than ε^k there.

    The resolution is what the arithmetic behind the error can tell from zero: `floor`, a
    constant (1e-13 for an error computed in double precision, 1e-40 at 50 digits), or,
    where `error` returns (error, resolution), measured at each step (a value computed at
    two precisions). The walk goes past 1e-4 only when a resolution is known, stops where
    the error reaches it, and judges the steps above it; an error function with none (a
    simulation's) stops at 1e-4 and cannot be found exact."""
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
    errors: list[float] = []
    resolutions: list[float] = []  # nan: unknown
    steps: list[float] = []

    def measure(pt) -> tuple[float, float]:
        if pt is None:
            return float("nan"), float("nan")
        got = error(pt)
        e, r = got if isinstance(got, tuple) else (got, floor)
        return float(e), float("nan") if r is None else max(float(r), floor or 0.0)

    for eps in LIMIT_STEPS + MORE_STEPS:
        if eps in MORE_STEPS and not (np.isfinite(resolutions[-1])
                                      and errors[-1] / steps[-1] ** order >= SMALL_ENOUGH
                                      and errors[-1] >= 10 * resolutions[-1]):
            break  # small enough against the claimed order's term, at the resolution, or
            # no resolution known to walk on with
        pt = dict(base)
        pt[sym] = sp.Float(base[sym] * eps if to_zero else base[sym] / eps, 30)
        pt = ctx.sampler.complete(pt)
        if eps in MORE_STEPS:  # beyond the usual walk: where the engine gives up, stop
            try:
                e, r = measure(pt)
            except (MechbookError, ZeroDivisionError, ValueError, OverflowError):
                break
            if not np.isfinite(e):
                break
        else:
            e, r = measure(pt)
        errors.append(e)
        resolutions.append(r)
        steps.append(eps)
    # the steps at the error's resolution say nothing about its order
    while len(errors) > 3 and steps[-1] in MORE_STEPS and errors[-1] < 10 * resolutions[-1]:
        errors.pop()
        resolutions.pop()
        steps.pop()
    tail, res = errors[-3:], resolutions[-3:]
    shown = ", ".join(f"{e:.2g}" for e in errors)
    if not all(np.isfinite(tail)):
        return Verdict(False, "numeric(asymptotic)", f"relative error {shown}: the formula "
                       "does not evaluate (or match) near the limit")
    if all(np.isfinite(r) and e < 10 * r for e, r in zip(tail, res, strict=True)):
        worst = max(10 * r for r in res)
        below = f"below {worst:.0e}" + (" (and 1e-30)" if worst <= 1e-30 else "")
        return Verdict(True, "numeric(asymptotic)",
                       f"relative error {shown}: at the resolution of its arithmetic "
                       f"({max(res):.0e}) in the limit's last steps",
                       power=f"exact toward the limit to the resolution: {below} at the "
                             "last steps (the error's order is not measured below it)")
    if min(tail) <= 0:
        return Verdict(False, "numeric(asymptotic)", f"relative error {shown}: zero with no "
                       "resolution stated, nothing can be told from it")
    logs = np.log10(tail)
    slope = float(np.polyfit(np.log10(steps[-3:]), logs, 1)[0])
    ok = tail[-1] < 1e-3 and slope >= order + 0.5
    detail = (f"relative error {shown} as {name} -> {spec['to']} by half decades from 1e-1: "
              f"it falls like {name}**{slope:.2f} (needs {order + 0.5:g} or more)"
              if to_zero else
              f"relative error {shown} as {name} -> oo by half decades from x10: it falls "
              f"like (1/{name})**{slope:.2f} (needs {order + 0.5:g} or more)")
    known = [r for r in res if np.isfinite(r)]
    resolution = f"; resolution {max(known):.0e}" if known else ""
    # a term of the claimed order off by δ (relative to the value at the default, scaled as
    # ε^order) adds δ·ε^order to the error: above ~10 times the error left at the last
    # step it would bend the slope below order + 0.5
    shows = 10 * tail[-1] / steps[-1] ** order
    return Verdict(ok, "numeric(asymptotic)", detail,
                   power=f"error falls like ε^{slope:.2f} toward the limit, to {tail[-1]:.1g} "
                         f"(order {order} claimed{resolution}): a term of order {order} "
                         f"wrong by more than ~{shows:.0e} of the value would show")
