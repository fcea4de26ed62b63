"""Asymptotic formulas (`limit: {parameter, to, order}`): the error's order measured as a
parameter is walked toward its limit. Shared by every quantity that takes `limit:`.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from mechbook.errors import MechbookError, UnsupportedError
from mechbook.verify.compare import Verdict
from mechbook.verify.context import Context

LIMIT_STEPS = tuple(10.0 ** (-1 - k / 2) for k in range(7))  # 1e-1 ... 1e-4, half decades
MORE_STEPS = tuple(10.0 ** (-4.5 - k / 2) for k in range(12))  # on to 1e-10 while needed
SMALL_ENOUGH = 1e-9  # an error this small ends the walk toward the limit
RESOLVE = 1e-6  # a pass resolves a term of the claimed order wrong by this (relative)


def asymptotic(ctx: Context, error, floor: float | None = None) -> Verdict:
    """`limit: {parameter, to, order}`: the book's formula holds in a limit of the
    parameters, to the stated order k. The error `error(point)` (relative) is measured as
    the parameter goes to 0 or ∞ in half decades from 1e-1 of its value, to 1e-4, and on
    (to 1e-10 at most, or as far as the engine computes) while it is above 1e-9 of ε^k
    and above ten times its resolution. The rule (docs/answers.md, *The walk's rule*):
    steps at the resolution (error below ten times it) are not judged; over the last three
    steps above it the error must fall like ε^s, s ≥ k + 0.5, ending below 1e-3, or the part
    fails; the smallest wrong term of order k that would show (δ, ten times the error left
    over ε^k) must be 1e-6 or less where a resolution is known, or the part is unsupported
    with the δ reached. An error at the resolution at every step is exact to it.

    The resolution is what the arithmetic behind the error can tell from zero: `floor`, a
    constant (1e-13 for an error computed in double precision, 1e-40 at 50 digits), or,
    where `error` returns (error, resolution), measured at each step (a value computed at
    two precisions, the offsets at which an engine gave no verdict). An error function with
    none (a simulation's) stops at 1e-4, passes with the δ it reached and cannot be found
    exact."""
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
    return judge_walk(name, spec["to"], to_zero, order, steps, errors, resolutions)


def judge_walk(name: str, to, to_zero: bool, order: int, steps: list, errors: list,
               resolutions: list) -> Verdict:
    """The verdict on a walk (see `asymptotic`): the steps above the error's resolution are
    judged, the steps at it only bound what a wrong term could have hidden.

    Parameters: the limit's parameter name, `to` (0 or oo), whether it goes to zero, the
    claimed order, and per step ε, the relative error and its resolution (nan: unknown).
    Returns the Verdict; raises UnsupportedError where the order or the claimed order's
    coefficient is not resolved. Example: errors 0.3ε³ at ε = 1e-1 … 1e-4 with a
    resolution of 1e-40, order 2: a pass, "error falls like ε^3.00"."""
    shown = ", ".join(f"{e:.2g}" for e in errors)
    at_floor = [bool(np.isfinite(r) and e < 10 * r) for e, r in
                zip(errors, resolutions, strict=True)]
    judged = [k for k in range(len(errors)) if not at_floor[k]]
    known = [r for r in resolutions if np.isfinite(r)]
    if any(not np.isfinite(errors[k]) for k in judged[-3:]):
        return Verdict(False, "numeric(asymptotic)", f"relative error {shown}: the formula "
                       "does not evaluate (or match) near the limit")

    def term(k: int) -> float:  # a term of the claimed order wrong by more than this shows
        return 10 * max(errors[k], 10 * resolutions[k] if at_floor[k] else 0.0) \
            / steps[k] ** order

    if not judged:  # at the resolution at every step: exact to it
        shows = min(term(k) for k in range(len(errors)))
        worst = max(10 * r for r in resolutions)
        below = f"below {worst:.0e}" + (" (and 1e-30)" if worst <= 1e-30 else "")
        detail = (f"relative error {shown}: at the resolution of its arithmetic "
                  f"({max(resolutions):.0e}) at every step")
        power = (f"exact toward the limit to the resolution: {below} at every step (a term "
                 f"of order {order} wrong by more than ~{shows:.0e} of the value would show)")
        return _resolved(shows, detail, power, order)
    if min(errors[k] for k in judged[-3:]) <= 0:
        return Verdict(False, "numeric(asymptotic)", f"relative error {shown}: zero with no "
                       "resolution stated, nothing can be told from it")
    bound = len(judged) == 1
    if bound and judged[0] + 1 >= len(errors):
        raise UnsupportedError(f"relative error {shown}: one step only, its order is not "
                               "measured")
    idx = judged[-3:] if not bound else [judged[0], judged[0] + 1]
    ys = [errors[k] if not at_floor[k] else 10 * resolutions[k] for k in idx]
    slope = float(np.polyfit(np.log10([steps[k] for k in idx]), np.log10(ys), 1)[0])
    last = idx[-1]
    floor_note = ""
    if judged[-1] + 1 < len(errors):  # the walk went on to the resolution: not judged there
        floor_note = (f"; at the resolution from the {len(errors) - judged[-1] - 1} last "
                      f"step{'s' if len(errors) - judged[-1] > 2 else ''} (not judged)")
    steps_word = ("the last step above the resolution and the first at it (a bound)" if bound
                  else f"the {len(idx)} last steps above the resolution" if floor_note
                  else f"the {len(idx)} last steps")
    detail = (f"relative error {shown} as {name} -> {to} by half decades from 1e-1: "
              f"it falls like {name}**{slope:.2f}{' at least' if bound else ''} over "
              f"{steps_word} (needs {order + 0.5:g} or more){floor_note}"
              if to_zero else
              f"relative error {shown} as {name} -> oo by half decades from x10: it falls "
              f"like (1/{name})**{slope:.2f}{' at least' if bound else ''} over {steps_word} "
              f"(needs {order + 0.5:g} or more){floor_note}")
    if not (ys[-1] < 1e-3 and slope >= order + 0.5):
        if bound:  # a bound only: the order may be higher than measured
            raise UnsupportedError(f"{detail}: too few steps above the resolution to "
                                   "measure the order")
        return Verdict(False, "numeric(asymptotic)", detail)
    # a term of the claimed order off by δ (relative to the value at the default, scaled as
    # ε^order) adds δ·ε^order to the error: above ~10 times the error left at the last
    # judged step (or the resolution at a step after it) it would bend the slope below
    # order + 0.5
    shows = min(term(k) for k in range(last, len(errors)))
    resolution = f"; resolution {max(known):.0e}" if known else ""
    power = (f"error falls like ε^{slope:.2f} toward the limit, to {errors[judged[-1]]:.1g} "
             f"(order {order} claimed{resolution}): a term of order {order} wrong by more "
             f"than ~{shows:.0e} of the value would show")
    if not known:  # no resolution (a simulation's error): the walk stops at 1e-4
        return Verdict(True, "numeric(asymptotic)", detail, power=power)
    return _resolved(shows, detail, power, order)


def _resolved(shows: float, detail: str, power: str, order: int) -> Verdict:
    """A pass where the walk resolved a term of the claimed order to RESOLVE; unsupported,
    with the resolution reached, where the arithmetic's floor came first."""
    if shows > RESOLVE:
        raise UnsupportedError(
            f"the claimed order's coefficient is not resolved: {detail}; a term of order "
            f"{order} wrong by less than ~{shows:.0e} of the value would not show before the "
            f"error reached its arithmetic's resolution (a pass needs {RESOLVE:g})")
    return Verdict(True, "numeric(asymptotic)", detail, power=power)
