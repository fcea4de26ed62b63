"""Loads beyond gravity and springs: torques on bodies, attracting point masses, averaging.

* `torques:` a torque N on a body, given by components in body or space axes, does work
  N·ω, so its generalized force on coordinate k is Q_k = N·∂ω/∂q̇_k (ω in the same axes).
  Components may depend on the state and on t (a jet's constant axial torque; a magnetic
  torque k L × B, which depends on the velocities).
* `attractors:` a point mass M' at a given place attracts every particle exactly
  (V = −G M' m/|r − r'|) and every 3-D rigid body through its monopole and quadrupole
  terms (MacCullagh's formula, accurate to order (size/distance)²):
  V = −G M' m/d − G M' (tr I − 3 d̂·I_s·d̂)/(2 d³), with d the vector from the attractor to
  the body's centre of mass and I_s = R·I·Rᵀ the inertia tensor in space axes.
* `average:` the Lagrangian averaged over a parameter (an angle, over its period), as a
  problem does when a fast orbital motion is averaged out (Symon 11-18). Trigonometric
  polynomials in the angle are averaged exactly by their Fourier constant term; anything
  else by SymPy's integral, within a time limit.
"""

from __future__ import annotations

import symengine as se
import sympy as sp

from mechbook.core.secalc import to_sympy
from mechbook.core.timeout import Timeout, hard_time_limit
from mechbook.model.attitude import rotation_matrix


def torque_forces(sys, torques: list) -> list[sp.Expr]:
    """Generalized forces Q_k = N·∂ω/∂q̇_k of the `torques:` list."""
    out = [sp.S.Zero] * len(sys.q)
    for i, spec in enumerate(torques):
        sub = ("torques", i)
        body = spec["body"]
        if body not in sys.body_rates or sys.body_rates[body] is None:
            raise sys.error(sub + ("body",), f"no 3-D rigid body {body!r} with an attitude or "
                             "an angular velocity vector")
        N = sp.Matrix([sys.parse(x, sub + ("components", j))
                       for j, x in enumerate(spec["components"])])
        omega = sys.body_rates[body]
        if spec.get("axes", "body") == "space":
            if body not in sys.attitudes:
                raise sys.error(sub + ("axes",), "space-axis torque components need the "
                                 "body's attitude (`euler_angles` or `rotation`)")
            omega = rotation_matrix(sys.attitudes[body]) * omega
        for k, v in enumerate(sys.qd):
            out[k] += N.dot(omega.diff(v))
    return out


def attractor_potential(sys, attractors: dict) -> sp.Expr:
    """V of every particle and 3-D body in the field of the attracting point masses."""
    total = sp.S.Zero
    bodies = set(sys.spec.get("rigid_bodies") or {})
    for name, spec in attractors.items():
        sub = ("attractors", name)
        M = sys.parse(spec["mass"], sub + ("mass",))
        if "G" in spec:
            G = sys.parse(spec["G"], sub + ("G",))
        elif "G" in sys.params:
            G = sys.params["G"].symbol
        else:
            raise sys.error(sub, "an attractor needs the gravitational constant: a parameter "
                             "'G' or the attractor's own 'G'")
        at = sp.Matrix([sys.parse(x, sub + ("position", i))
                        for i, x in enumerate(spec.get("position", [0, 0, 0]))])
        if not sys.positions:
            raise sys.error(sub, "an attractor acts on particles or rigid bodies; none given")
        for obj, r in sys.positions.items():
            if r.rows != at.rows:
                raise sys.error(sub + ("position",), f"{obj}'s position has {r.rows} "
                                 f"components, the attractor's {at.rows}")
            d = r - at
            dist = sp.sqrt(d.dot(d))
            total += -G * M * sys.masses[obj] / dist
            if obj not in bodies or obj not in sys.inertias:
                continue
            if obj not in sys.attitudes:
                raise sys.error(sub, f"the attraction on body {obj!r} depends on its "
                                 "orientation: give the body `euler_angles` or `rotation`")
            R = rotation_matrix(sys.attitudes[obj])
            inertia = R * sys.inertias[obj] * R.T
            quad = inertia.trace() * d.dot(d) - 3 * (d.T * inertia * d)[0, 0]
            total += -G * M * quad / (2 * dist**5)
    return total


INTEGRAL_SECONDS = 5.0  # CPU; an average SymPy can do at all it does in about a second


def average_over(sys, expr: sp.Expr, spec: dict) -> sp.Expr:
    """`expr` averaged over each parameter of `spec` ({alpha: [lo, hi]})."""
    for name, bounds in spec.items():
        sub = ("average", name)
        if name not in sys.params:
            raise sys.error(sub, "averaging is over a declared parameter (an angle)")
        x = sys.params[name].symbol
        lo, hi = (sys.parse(b, sub + (i,)) for i, b in enumerate(bounds))
        expr = _average(expr, x, lo, hi)
        if expr is None:
            raise sys.error(sub, f"could not average over {name} (not a trigonometric "
                             "polynomial, and SymPy's integral found no closed form within "
                             f"its time limit of {INTEGRAL_SECONDS:g} s of CPU)")
    return expr


def _average(expr: sp.Expr, x: sp.Symbol, lo: sp.Expr, hi: sp.Expr) -> sp.Expr | None:
    if not expr.has(x):
        return expr
    if sp.simplify(hi - lo - 2 * sp.pi) == 0:
        out = _fourier_constant(expr, x)
        if out is not None:
            return out
    try:  # a repeating alarm: one that SymPy swallows (a finalizer, a C callback) recurs
        with hard_time_limit(INTEGRAL_SECONDS):
            out = sp.integrate(expr, (x, lo, hi)) / (hi - lo)
    except Timeout:
        return None
    return None if out.has(sp.Integral) or out.has(x) else out


def _fourier_constant(expr: sp.Expr, x: sp.Symbol) -> sp.Expr | None:
    """The mean over a period 2π of a trigonometric polynomial in x: write sines and
    cosines as exponentials and keep the terms free of x; None if expr is not of that form
    (x elsewhere than in sin/cos arguments linear in x with integer coefficients)."""
    trig = [f for f in expr.atoms(sp.sin, sp.cos) if f.has(x)]
    for f in trig:
        arg = sp.expand(f.args[0])
        k = arg.coeff(x)
        if arg.has(x) and (not k.is_integer or (arg - k * x).has(x)):
            return None
    expr = _pythagoras_in_roots(expr, x)
    trig = [f for f in expr.atoms(sp.sin, sp.cos) if f.has(x)]
    dummies = {f: sp.Dummy() for f in trig}
    stripped = expr.subs(dummies)
    if stripped.has(x) or not stripped.is_polynomial(*dummies.values()):
        return None  # e.g. 1/sqrt(a + b*cos(x)): expanding it would run for minutes
    fast = _laurent_constant(expr, x)
    if fast is not None:
        return fast
    wave = sp.expand(expr.rewrite(sp.exp), power_exp=True, mul=True, multinomial=True)
    keep = sp.S.Zero
    for term in sp.Add.make_args(wave):
        if not term.has(x):
            keep += term
            continue
        rest = sp.powsimp(term)
        factors = sp.Mul.make_args(rest)
        freq = sp.S.Zero
        for f in factors:
            base, power = f.as_base_exp()
            if base == sp.E or isinstance(base, sp.exp):
                exponent = power if base == sp.E else base.args[0] * power
                freq += sp.expand(exponent).coeff(x)
            elif f.has(x):
                return None
        if freq == 0:
            keep += term.subs(x, 0)
    return sp.expand(keep.rewrite(sp.cos))


def _laurent_constant(expr: sp.Expr, x: sp.Symbol) -> sp.Expr | None:
    """The constant term in x of a trigonometric polynomial in x (its sines and cosines of
    k·x + c, k an integer), by SymEngine. As on SymPy's path (_fourier_constant), every
    sine and cosine is written in exponentials: with z = e^{ix}, cos(kx + c) is
    (z^k e^{ic} + z^-k e^{-ic})/2 (sin: the same with a minus, over 2i), and those of other
    arguments u as (e^{iu} ± e^{-iu})/2(i), so that sin²u + cos²u cancels as it does there;
    the whole is expanded as a Laurent polynomial in z, its terms free of z kept, and
    written back in cosines as SymPy's path writes them: the same expression, in C++ (0.56 s
    to 0.02 s for a rigid body's averaged attraction, Symon 11-18). None where expr holds a
    function other than sines and cosines, or SymEngine cannot: SymPy's path does it."""
    if any(not isinstance(f, (sp.sin, sp.cos)) for f in expr.atoms(sp.Function)):
        return None  # tan, exp, …: SymPy's path writes them in exponentials as well
    try:
        z = se.Dummy("z")
        stand = {f: sp.Dummy() for f in expr.atoms(sp.sin, sp.cos)}
        waves = {}
        for f, d in stand.items():
            arg = sp.expand(f.args[0])
            k = arg.coeff(x) if arg.has(x) else sp.S.Zero
            phase = se.exp(se.I * se.sympify(arg - k * x))
            up, down = z**int(k) * phase, z**int(-k) / phase
            waves[se.sympify(d)] = (up + down) / 2 if isinstance(f, sp.cos) else \
                (up - down) / (2 * se.I)
        wave = se.expand(se.sympify(expr.xreplace(stand)).xreplace(waves))
        terms = wave.args if isinstance(wave, se.Add) else (wave,)
        keep = se.Add(*[t for t in terms if z not in t.free_symbols])
        out = to_sympy(keep, expr.free_symbols)
    except Exception:  # noqa: BLE001 - SymEngine's conversion or expansion failed
        return None
    if out.has(x, *stand.values()):
        return None
    return sp.expand(sp.expand(out, power_exp=True).rewrite(sp.cos))


def _pythagoras_in_roots(expr: sp.Expr, x: sp.Symbol) -> sp.Expr:
    """expr with each root or other non-integer power of a base in x replaced by its value
    where sin² + cos² = 1 removes x from the base: the distance sqrt(r²cos²x + r²sin²x) of
    a body on a circle is r, and the rest is then a trigonometric polynomial."""
    reps = {}
    for p in expr.atoms(sp.Pow):
        if not p.base.has(x) or p.exp.is_Integer:
            continue
        base = sp.expand(p.base)
        for f in base.atoms(sp.sin):
            if f.has(x):
                base = sp.expand(base.subs(f**2, 1 - sp.cos(f.args[0])**2))
        if not base.has(x):
            reps[p] = sp.Pow(base, p.exp)
    return expr.xreplace(reps) if reps else expr
