"""A solution of the Hamilton–Jacobi equation: `hamilton_jacobi`.

The book's S(q, α, t) (the coordinates by name, `t`, the separation constants `constants:`
as symbols of the key, the parameters) is checked twice:

  equation  H(q, ∂S/∂q, t) + ∂S/∂t = 0 identically, H the engine's Hamiltonian (its
            momenta p_<q> replaced by ∂S/∂q): at random q, t, α and parameters in 30-digit
            arithmetic to 1e-20 of its terms (mechbook.verify.compare.vanishes; SymPy's
            proof where it reduces the residual to 0), so the separation constants enter as
            the book says;
  motion    the motion that S generates is the engine's: from `start:` (the coordinates at
            t = 0) with the momenta p = ∂S/∂q there and β = ∂S/∂α, the engine's equations are
            integrated (DOP853 at 1e-12) and at 6 times the coordinates must keep
            ∂S/∂α = β and the momenta p = ∂S/∂q to 1e-7 of their terms. The times run to
            `duration:` or, by default, to just before the first momentum changes sign (where
            a branch of S written with a square root stops describing the motion).

A complete integral needs as many constants as coordinates; fewer is an error at the part.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from mechbook.errors import UnsupportedError
from mechbook.numerics.integrators import integrate
from mechbook.numerics.measure import first_event, signal_functions
from mechbook.numerics.rhs import build_model
from mechbook.verify.compare import Verdict, value_and_scale, vanishes
from mechbook.verify.context import Context
from mechbook.verify.registration import EXPR, POINT, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

TIMES = 6
MOTION_RTOL = 1e-7  # the integration's 1e-12 leaves ~1e-10 of the terms
TOLERANCE = 1e-12


@quantity('hamilton_jacobi',
          book='expression S(q, α, t): a complete integral, `constants:` its α',
          how=('H(q, ∂S/∂q, t) + ∂S/∂t = 0 identically (30 digits, 1e-20 of its terms, at '
               'random q, t, α; SymPy\'s proof where it reduces to 0); and from `start:` with '
               'p = ∂S/∂q and β = ∂S/∂α there, the engine\'s integrated motion keeps ∂S/∂α = '
               'β and p = ∂S/∂q at 6 times to 1e-7 (until `duration:`, or until a momentum '
               'first changes sign)'),
          keys={"constants": {"type": "array", "minItems": 1, "items": {"type": "string"}},
                "start": POINT, "duration": EXPR},
          equivalent=("shift",))  # S + a constant is the same complete integral
def check_hamilton_jacobi(ctx: Context, val) -> Verdict:
    sys, dyn, data = ctx.system, ctx.dyn, ctx.part.data
    if sys.forces and any(f != 0 for f in sys.forces):
        raise UnsupportedError("Hamilton–Jacobi with non-conservative forces")
    alphas = []
    for i, name in enumerate(data.get("constants") or []):
        sym = ctx.names.get(name)
        if not isinstance(sym, sp.Symbol) or sym in sys.q:
            raise ctx.part.error(("constants", i), f"{name!r} is not a symbol of the key")
        alphas.append(sym)
    if len(alphas) != len(sys.q):
        raise ctx.part.error(("constants",), f"a complete integral has one constant per "
                             f"coordinate: {len(sys.q)}, not {len(alphas)}")
    S = ctx.parse(val, ("book",))
    stray = S.free_symbols & (set(sys.qd) | set(dyn.qdd))
    if stray:
        return Verdict(False, "exact", "S is a function of the coordinates, the constants and "
                       "t, not of " + ", ".join(sorted(map(str, stray))))
    grad = [sp.diff(S, q) for q in sys.q]
    H = dyn.hamiltonian.xreplace(dict(zip(dyn.p, grad, strict=True)))
    residual = vanishes(H + sp.diff(S, sys.t), ctx.sampler)
    if not residual.ok:
        return Verdict(False, residual.method, "H(q, ∂S/∂q, t) + ∂S/∂t is not 0: "
                       + residual.detail)
    ok, motion = _motion(ctx, S, grad, alphas)
    if not ok:
        return Verdict(False, "integrated", motion)
    return Verdict(True, f"{residual.method} and integrated", motion,
                   power=f"the Hamilton–Jacobi residual ({residual.power or residual.method});"
                         f" the generated motion at {TIMES} times to {MOTION_RTOL:g}")


def _motion(ctx: Context, S, grad: list, alphas: list) -> tuple[bool, str]:
    """The motion ∂S/∂α = β against the engine's integration: (agrees, what was found)."""
    sys, dyn, data = ctx.system, ctx.dyn, ctx.part.data
    if "start" not in data:
        raise ctx.part.error((), "give `start:` (the coordinates at t = 0 where the motion "
                             "that S generates is compared with the engine's)")
    pt = ctx.sampler.default()
    start = {}
    for k, v in ctx.as_map(data["start"], ("start",)).items():
        if k not in sys.coord_names:
            raise ctx.part.error(("start", k), f"{k!r} is not a coordinate")
        start[sys.q[sys.coord_names.index(k)]] = ctx.parse(v, ("start", k))
    at0 = dict(pt)
    at0[sys.t] = sp.S.Zero
    for q in sys.q:
        at0[q] = sp.Float(value_and_scale(start.get(q, sp.S.Zero), pt)[0].real, 30)
    p0 = [value_and_scale(g, at0)[0] for g in grad]
    if any(not np.isfinite(v) or abs(v.imag) > 1e-12 * (1 + abs(v.real)) for v in p0):
        raise ctx.part.error(("start",), "∂S/∂q is not real at `start:` (outside the region "
                             "the book's S describes)")
    betas = [value_and_scale(sp.diff(S, a), at0)[0].real for a in alphas]
    velocity = dyn.velocities_of_momenta
    atp = {**at0, **{p: sp.Float(v.real, 30) for p, v in zip(dyn.p, p0, strict=True)}}
    qd0 = np.array([value_and_scale(velocity[v], atp)[0].real for v in sys.qd])
    q0 = np.array([float(at0[q]) for q in sys.q])
    params = {k: float(v) for k, v in pt.items() if k in sys.problem.values()}
    model = build_model(sys, dyn, params)
    scale = 1.0 / (1.0 + float(np.max(np.abs(qd0))))
    if "duration" in data:
        T = value_and_scale(ctx.parse(data["duration"], ("duration",)), pt)[0].real
        if not T > 0:
            raise ctx.part.error(("duration",), "the duration must be a positive time")
    else:
        product = sp.Mul(*dyn.momenta)
        try:
            t1, _ = first_event(model, signal_functions(sys, dyn, pt, product), q0, qd0,
                                scale, max_chunks=12)
            T = 0.9 * t1
        except UnsupportedError:
            T = 10 * scale
    times = [T * (j + 1) / TIMES for j in range(TIMES)]
    # the span a little past T: t_eval's last point stays inside it
    run = integrate(model, (0.0, T * (1 + 1e-6)), q0, qd0, t_eval=times, rtol=TOLERANCE,
                    atol=TOLERANCE)
    found = [int(np.argmin(np.abs(np.asarray(run.t) - t))) for t in times]
    if not run.success or any(abs(run.t[j] - t) > 1e-9 * T for j, t in zip(found, times,
                                                                          strict=True)):
        raise UnsupportedError(f"the motion that S generates: the integration failed "
                               f"({run.message})")
    worst = 0.0
    for j, t in zip(found, times, strict=True):
        at = dict(pt)
        at[sys.t] = sp.Float(t, 30)
        at.update({q: sp.Float(float(run.q[i, j]), 30) for i, q in enumerate(sys.q)})
        at.update({v: sp.Float(float(run.qd[i, j]), 30) for i, v in enumerate(sys.qd)})
        checks = [(sp.diff(S, a) - b, f"∂S/∂{a} = β") for a, b in zip(alphas, betas,
                                                                      strict=True)]
        checks += [(g - p, f"p_{q} = ∂S/∂{q}") for g, p, q in zip(grad, dyn.momenta, sys.q,
                                                                  strict=True)]
        for expr, what in checks:
            v, s = value_and_scale(expr, at)
            rel = abs(v) / max(s, 1e-300)
            worst = max(worst, rel)
            if not rel <= MOTION_RTOL:
                return False, (f"the engine's motion breaks {what} at t = {t:.6g}: off "
                               f"by {rel:.2g} of its terms")
    return True, (f"the generated motion agrees with the engine's at {TIMES} times up to "
            f"t = {T:.4g} (worst {worst:.2g})")
