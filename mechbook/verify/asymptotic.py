"""Asymptotic formulas (`limit: {parameter, to, order}`): the error's order measured as a
parameter is walked toward its limit. Shared by every quantity that takes `limit:`.
"""

from __future__ import annotations

import mpmath
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
    books: list = []  # the book's values at each step, where the error function gives them
    coefficient: list = [None]  # the book's own order-k coefficient, once measured

    def measure(pt) -> tuple[float, float]:
        if pt is None:
            books.append(None)
            return float("nan"), float("nan")
        got = error(pt)
        got = got if isinstance(got, tuple) else (got, floor)
        e, r = got[:2]
        books.append(got[2] if len(got) > 2 else None)
        return float(e), float("nan") if r is None else max(float(r), floor or 0.0)

    for eps in LIMIT_STEPS + MORE_STEPS:
        if eps == MORE_STEPS[0]:
            coefficient[0] = book_coefficient(steps, books, order)
        small = SMALL_ENOUGH * min(1.0, coefficient[0] or 1.0)
        if eps in MORE_STEPS and not (np.isfinite(resolutions[-1])
                                      and errors[-1] / steps[-1] ** order >= small
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
    if coefficient[0] is None and len(steps) <= len(LIMIT_STEPS):
        coefficient[0] = book_coefficient(steps, books, order)
    return judge_walk(name, spec["to"], to_zero, order, steps, errors, resolutions,
                      coefficient[0])


FIT_STEPS = 5  # the book's values at the walk's steps 1e-2 … 1e-4 fix its coefficients
ZERO_COEFFICIENT = 1e-12  # a fitted coefficient below this is the book's zero (fit noise)


def book_coefficient(steps: list, books: list, order: int) -> float | None:
    """The book's own coefficient of ε^order, relative to its value in the limit: the
    polynomial of degree FIT_STEPS − 1 through the book's values at the walk's steps 1e-2 …
    1e-4 (30 digits each), its ε^order coefficient over its constant; the smallest over the
    values a step reports (a relation's boundary at each of its crossings). None where the
    error function reports no values, a step has none, their number changes, or every
    coefficient is the book's zero (below ZERO_COEFFICIENT). Example: values
    2ω0(1 + ε/20 − 6.25e-4 ε²), order 2: 6.25e-4."""
    if order < 1:
        return None
    idx = [k for k, e in enumerate(steps) if 1e-4 * 0.9 <= e <= 1e-2 * 1.1][:FIT_STEPS]
    if len(idx) < FIT_STEPS or any(not books[k] or None in books[k] for k in idx) or \
            len({len(books[k]) for k in idx}) != 1:
        return None
    found = []
    with mpmath.workdps(50):
        xs = [mpmath.mpf(steps[k]) for k in idx]
        V = mpmath.matrix([[x ** j for j in range(FIT_STEPS)] for x in xs])
        for j in range(len(books[idx[0]])):
            ys = mpmath.matrix([mpmath.mpf(sp.Float(books[k][j], 30)._mpf_) for k in idx])
            a = mpmath.lu_solve(V, ys)
            if a[0] == 0 or order >= FIT_STEPS:
                return None
            c = abs(a[order] / a[0])
            if c >= ZERO_COEFFICIENT:
                found.append(float(c))
    return min(found) if found else None


def judge_walk(name: str, to, to_zero: bool, order: int, steps: list, errors: list,
               resolutions: list, coefficient: float | None = None) -> Verdict:
    """The verdict on a walk (see `asymptotic`): the steps above the error's resolution are
    judged, the steps at it only bound what a wrong term could have hidden.

    Parameters: the limit's parameter name, `to` (0 or oo), whether it goes to zero, the
    claimed order, and per step ε, the relative error and its resolution (nan: unknown).
    Returns the Verdict; raises UnsupportedError where the order or the claimed order's
    coefficient is not resolved. Example: errors 0.3ε³ at ε = 1e-1 … 1e-4 with a
    resolution of 1e-40, order 2: a pass, "error falls like ε^3.00".

    `coefficient`: the book's own coefficient of the claimed order, relative to its value
    (`book_coefficient`); a pass then needs δ ≤ 1e-6 of it (of the value where it is 1 or
    more, or unknown): a claimed coefficient moved by 1e-6 of itself must show."""
    needed = RESOLVE * min(1.0, coefficient or 1.0)
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
        return _resolved(shows, detail, power, order, needed, coefficient)
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
    if coefficient:
        power += (f" ({shows / coefficient:.0e} of the book's own order-{order} coefficient, "
                  f"{coefficient:.2g} of the value)")
    if not known:  # no resolution (a simulation's error): the walk stops at 1e-4
        return Verdict(True, "numeric(asymptotic)", detail, power=power)
    return _resolved(shows, detail, power, order, needed, coefficient)


def _resolved(shows: float, detail: str, power: str, order: int, needed: float = RESOLVE,
              coefficient: float | None = None) -> Verdict:
    """A pass where the walk resolved a term of the claimed order to `needed` (RESOLVE of
    the value, or of the book's own coefficient where that is smaller); unsupported, with
    the resolution reached, where the arithmetic's floor came first."""
    if shows > needed:
        own = (f" ({shows / coefficient:.0e} of the book's own order-{order} coefficient, "
               f"{coefficient:.2g})" if coefficient else "")
        raise UnsupportedError(
            f"the claimed order's coefficient is not resolved: {detail}; a term of order "
            f"{order} wrong by less than ~{shows:.0e} of the value{own} would not show "
            f"before the error reached its arithmetic's resolution (a pass needs "
            f"{needed:.0e}: {RESOLVE:g} of "
            f"{'that coefficient' if needed < RESOLVE else 'the value'})")
    return Verdict(True, "numeric(asymptotic)", detail, power=power)
