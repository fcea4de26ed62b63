"""A law kept while a parameter changes slowly: `adiabatic_invariant`.

The book's value is a function f of the oscillation's amplitude (an answer symbol named by
`amplitude:`, the amplitude of `coordinate:`) and of the slowly varying quantity (a free
driven coordinate, `slow: {r: [r0, r1]}`, with the range a simulated change covers) that
stays constant. Two checks (mechbook.engine.adiabatic):

  exact       f is a function of the engine's action J = π√(MK)A² of the frozen, linearized
              oscillation: f_A·J_r − f_r·J_A = 0 at 6 random points (30 digits, 1e-20 of
              its terms), r anywhere in the range; so any exponent or factor wrong in f fails
  simulated   at one point the full nonlinear equations are integrated while r moves from
              r0 to r1 over 200 periods, from rest at amplitude A0 (the `amplitude:`
              symbol's value there); f(A1, r1) must equal f(A0, r0) to SIM_RTOL, and so must
              J: the slow change really keeps the action

Both hold in the small-oscillation limit the book works in; a constant added to f, or a
constant factor, is the same law. With `invariant: action` the book's f is the action
itself, in the 1/2π convention of the `action` quantity: f must equal J/(2π) = √(MK)A²/2
(= E/ω) at the same 6 points to 1e-20, so J and 2J, or the area ∮p dq = 2πJ, differ; the
simulated change is checked as before.
"""

from __future__ import annotations

import random

import sympy as sp

from mechbook.core.words import plural
from mechbook.engine.adiabatic import frozen, simulate
from mechbook.errors import UnsupportedError
from mechbook.verify.compare import Verdict, value_and_scale
from mechbook.verify.context import Context
from mechbook.verify.registration import EXPR, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

POINTS = 6
RTOL = 1e-20
SIM_RTOL = 1e-3  # the simulated change (200 periods, amplitude ~0.01): measured ~1e-6
SLOW = {"type": "object", "minProperties": 1, "maxProperties": 1,
        "additionalProperties": {"type": "array", "minItems": 2, "maxItems": 2, "items": EXPR}}


@quantity('adiabatic_invariant',
          book='expression f(amplitude, slow variable) that stays constant',
          how=('f is a function of the action J = π√(MK)A² of the frozen linearized '
               'oscillation of `coordinate:` (amplitude A the symbol `amplitude:`, the slow '
               'variable a free driven coordinate held fixed): f_A·J_r − f_r·J_A = 0 at 6 '
               'points to 1e-20, r anywhere in `slow: {r: [r0, r1]}`; and a simulation of '
               'the full equations with r moved from r0 to r1 over 200 periods keeps f and J '
               'to 1e-3. With `invariant: action`, f must be the action itself, J/(2π) = '
               '√(MK)A²/2 = E/ω (1/2π convention), at the 6 points to 1e-20'),
          keys={"coordinate": {"type": "string"}, "amplitude": {"type": "string"},
                "slow": SLOW, "invariant": {"enum": ["function", "action"]}},
          equivalent=("shift", "scale"))
def check_adiabatic_invariant(ctx: Context, val) -> Verdict:
    data, sys = ctx.part.data, ctx.system
    book = ctx.parse(val, ("book",))
    name = data.get("coordinate")
    if name not in sys.coord_names:
        raise ctx.part.error(("coordinate",), "name the oscillating `coordinate:`")
    amp = ctx.names.get(data.get("amplitude"))
    if not isinstance(amp, sp.Symbol) or amp not in ctx.sampler.base:
        raise ctx.part.error(("amplitude",), "name the answer symbol that is the amplitude")
    slow_spec = ctx.as_map(data.get("slow"), ("slow",))
    (slow_name, (lo_t, hi_t)), = slow_spec.items()
    slow = ctx.names.get(slow_name)
    if not isinstance(slow, sp.Symbol):
        raise ctx.part.error(("slow",), f"{slow_name!r} is not a free driven coordinate")
    r0_e, r1_e = ctx.parse(lo_t, ("slow", slow_name, 0)), ctx.parse(hi_t, ("slow", slow_name, 1))
    motion = set(sys.q) | set(sys.qd) | set(ctx.dyn.qdd) | {sys.t}
    motion |= {s for t in sys.free_driven for s in t if s != slow}
    if book.free_symbols & motion:
        return Verdict(False, "exact", "the law may use the amplitude, the slow variable and "
                       "constants only, not " + ", ".join(sorted(map(str, book.free_symbols
                                                                     & motion))))
    if not (book.has(amp) and book.has(slow)):
        return Verdict(False, "exact", f"the law must involve both {amp} and {slow}")
    osc = frozen(ctx.dyn, sys.q[sys.coord_names.index(name)], slow, ctx.point())
    J = osc.action(amp)
    fa, fr, ja, jr = sp.diff(book, amp), sp.diff(book, slow), sp.diff(J, amp), sp.diff(J, slow)
    rng = random.Random(20261126)
    worst = 0.0
    itself = data.get("invariant", "function") == "action"
    for k in range(1, POINTS + 1):
        pt = ctx.sampler.draw()
        r0, r1 = (value_and_scale(e, pt)[0].real for e in (r0_e, r1_e))
        if not (r0 > 0 and r1 > 0):
            raise ctx.part.error(("slow",), "the slow range's ends must be positive numbers")
        at = dict(pt)
        at[slow] = sp.Float(r0 + (r1 - r0) * rng.random(), 30)
        if itself:  # the action itself, (1/2π)∮p dq: a value, not a function of it
            got, s1 = value_and_scale(book, at)
            want, s2 = value_and_scale(J / (2 * sp.pi), at)
            rel = abs(got - want) / max(abs(want), s1, s2, 1e-300)
            worst = max(worst, rel)
            if not rel <= RTOL:
                return Verdict(False, f"exact({k} points)",
                               f"not the action J = {sp.sstr(J / (2 * sp.pi))} (1/2π∮p dq): "
                               f"the book's {got.real:.12g}, the action {want.real:.12g} at "
                               f"{slow} = {float(at[slow]):.6g}")
            continue
        one, s1 = value_and_scale(fa * jr, at)
        two, s2 = value_and_scale(fr * ja, at)
        scale = max(abs(one) + abs(two), s1, s2, 1e-300)
        rel = abs(one - two) / scale
        worst = max(worst, rel)
        if not rel <= RTOL:
            return Verdict(False, f"exact({plural(k, 'point')})",
                           f"not a function of the action J = {sp.sstr(J)}: f_A·J_r − f_r·J_A "
                           f"is {rel:.2g} of its terms at {slow} = {float(at[slow]):.6g}")
    return _simulated(ctx, book, J, amp, slow, r0_e, r1_e, worst, itself)


def _simulated(ctx: Context, book, J, amp, slow, r0_e, r1_e, worst: float,
               itself: bool = False) -> Verdict:
    pt = ctx.sampler.default()
    r0, r1 = (value_and_scale(e, pt)[0].real for e in (r0_e, r1_e))
    a0 = value_and_scale(amp, pt)[0].real
    point = ctx.point()
    q = ctx.system.q[ctx.system.coord_names.index(ctx.part.data["coordinate"])]
    q_star = value_and_scale(sp.S(point.get(q, 0)), pt)[0].real
    values = {k: v for k, v in pt.items() if k in ctx.system.problem.values()}
    try:
        run = simulate(ctx.dyn, slow, values, r0, r1, a0, q_star)
    except UnsupportedError as exc:
        raise UnsupportedError(f"the simulated slow change: {exc.capability}") from None

    def ratio(expr) -> float:
        before = value_and_scale(expr, {**pt, amp: sp.Float(run.a0, 30),
                                        slow: sp.Float(run.r0, 30)})[0].real
        after = value_and_scale(expr, {**pt, amp: sp.Float(run.a1, 30),
                                       slow: sp.Float(run.r1, 30)})[0].real
        return after / before - 1

    kept_f, kept_j = ratio(book), ratio(J)
    detail = (f"exact: worst {worst:.2g}; simulated {slow} {run.r0:.4g} -> {run.r1:.4g} over "
              f"{run.periods} periods, amplitude {run.a0:.4g} -> {run.a1:.6g}: the book's law "
              f"changed by {kept_f:.2g}, the action by {kept_j:.2g}")
    if not (abs(kept_f) <= SIM_RTOL and abs(kept_j) <= SIM_RTOL):
        return Verdict(False, "simulated", detail)
    what = "the action itself" if itself else "a function of the action"
    return Verdict(True, f"exact({POINTS} points, 30 digits) and simulated", detail,
                   power=f"{what} at {POINTS} points to {RTOL:g}; kept to "
                         f"{abs(kept_f):.1g} (stated {SIM_RTOL:g}) by a simulated slow change")
