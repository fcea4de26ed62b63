"""Scattering on unbound orbits: `deflection_angle`, `closest_approach`, `time_delay`,
`cross_section`, `total_cross_section`, `capture`, `critical_impact_parameter`.

A part names the orbit by `impact_parameter:` b and `energy:` E, expressions in the
problem's parameters and the key's symbols (usually two answer symbols, `b` and `E`,
declared under `symbols:` with values the sampler varies), and optionally the radial
`coordinate:` (default: the coordinate whose partner is cyclic) and a `hard_core:` radius
a (V = ∞ for r < a: an impenetrable sphere, reflecting specularly). The system must reduce
to that radial coordinate and one cyclic angle (mechbook.engine.scattering); its
potential must vanish at infinity and E be above it, else the part is an error at its
line (`mechbook validate` and `mechbook check` refuse it before anything is judged).

Every value is taken at DPS and at DPS + 15 digits; a difference above 1e-30 is
`unsupported` (the quadrature did not reach its digits), never a fail. Book and engine are
compared at POINTS random points to RTOL.
"""

from __future__ import annotations

import math

import mpmath
import sympy as sp

from mechbook.core.numeval import NotNumeric, evaluate_mp, holds
from mechbook.engine.scattering import (
    DIGITS,
    DPS,
    Captured,
    Scattering,
    Unbound,
    checked,
    critical_impact_parameter,
)
from mechbook.engine.scattering_float import float_deflection
from mechbook.errors import UnsupportedError
from mechbook.verify.compare import Verdict
from mechbook.verify.context import Context
from mechbook.verify.registration import EXPR, NAME, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

POINTS = 6
RTOL = 1e-20  # book against engine (the engine's values hold 30 digits)
DERIVATIVE_RTOL = 1e-15  # dσ/dΩ: two central differences of dΘ/db must agree to this
STEPS = (10, 9)  # their steps: 1e-10·b and 1e-9·b
NEAR = 1e-8  # a capture relation is judged this far (relative) either side of b_c
SINGULAR = 1e-10  # |dΘ/db|·b or |sin Θ| below this: a rainbow or a glory
SCAN = 16  # impact parameters from b/100 to 100b on which one branch is confirmed
ORBIT = {"coordinate": {"type": "string"}, "impact_parameter": EXPR, "energy": EXPR,
         "hard_core": EXPR}
BEAM_ONLY = ("critical_impact_parameter", "total_cross_section")  # quantities of E alone
BEAM = {"coordinate": {"type": "string"}, "energy": EXPR, "hard_core": EXPR,
        "impact_parameter": EXPR}


class Beam:
    """What a scattering part refers to: the reduced system, b and E as expressions."""

    def __init__(self, ctx: Context, needs_b: bool = True):
        self.ctx = ctx
        data = ctx.part.data
        if "energy" not in data:
            raise ctx.part.error((), "a scattering part needs `energy:` (E, the energy at "
                                 "infinity)")
        if needs_b and "impact_parameter" not in data:
            raise ctx.part.error((), "a scattering part needs `impact_parameter:` (b)")
        self.E = ctx.parse(data["energy"], ("energy",))
        self.b = (ctx.parse(data["impact_parameter"], ("impact_parameter",))
                  if "impact_parameter" in data else None)
        core = ctx.parse(data["hard_core"], ("hard_core",)) if "hard_core" in data else None
        if core is not None and core.free_symbols - set(ctx.system.problem.values()):
            raise ctx.part.error(("hard_core",), "the hard core's radius is an expression in "
                                 "the problem's parameters")
        self.engine = _scattering(ctx, _radius(ctx), core)

    def at(self, pt: dict) -> tuple:
        """(b, E) at the point, as 30-digit numbers; an error at `energy:` if the orbit is
        bound there."""
        E = self._number(self.E, pt, "energy")
        b = self._number(self.b, pt, "impact_parameter") if self.b is not None else None
        if not E > 0:
            raise self.ctx.part.error(("energy",), f"E = {float(E):.6g} is not above the "
                                      "potential at infinity (0): a bound orbit, not a "
                                      "scattering one")
        if b is not None and not b > 0:
            raise self.ctx.part.error(("impact_parameter",), f"b = {float(b):.6g}: the "
                                      "impact parameter must be positive")
        return b, E

    def _number(self, expr, pt, key):
        try:
            v = evaluate_mp(expr, pt, DIGITS)
        except (NotNumeric, ZeroDivisionError, ValueError, TypeError):
            v = None
        if v is None or not mpmath.isfinite(v) or abs(mpmath.im(v)) > 1e-25 * abs(v):
            raise self.ctx.part.error((key,), f"`{key}:` has no real value at a sample point")
        return sp.Float(str(mpmath.re(v)), DIGITS)

    def value(self, pt: dict, b, E, what) -> object:
        """`what(orbit)` confirmed at two precisions (mechbook.engine.scattering.checked);
        an orbit that is not a scattering one is an error at the part's key."""
        try:
            return checked(self.engine, pt, b, E, what)[0]
        except Unbound as exc:
            raise self.ctx.part.error(("energy",), str(exc)) from None

    def points(self):
        """POINTS admissible points, each with its (b, E)."""
        for n in range(1, POINTS + 1):
            pt = self.ctx.sampler.draw()
            yield n, pt, *self.at(pt)


def _radius(ctx: Context) -> sp.Symbol:
    sys = ctx.system
    name = ctx.part.data.get("coordinate")
    if name is not None:
        if name not in sys.coord_names:
            raise ctx.part.error(("coordinate",), f"{name!r} is not a coordinate")
        return sys.q[sys.coord_names.index(name)]
    if len(sys.q) != 2:
        raise ctx.part.error((), "name the radial `coordinate:` (scattering reduces the "
                             "system to it and one cyclic angle)")
    for q, other in ((sys.q[0], sys.q[1]), (sys.q[1], sys.q[0])):
        if not ctx.dyn.L.has(other):
            return q
    raise ctx.part.error((), "no coordinate of this system is cyclic: name the radial "
                         "`coordinate:` of a central potential")


def _scattering(ctx: Context, radius, core) -> Scattering:
    key = ("scattering", ctx.part.system, str(radius), sp.srepr(core))
    return ctx.analysis.reuse(key, lambda: Scattering(ctx.dyn, radius, core))


def validate_orbit(ctx: Context) -> None:
    """The part's orbit at the default point is a scattering one: E above the potential
    at infinity, which vanishes (an error at the part's line otherwise)."""
    beam = Beam(ctx, needs_b=ctx.part.quantity not in BEAM_ONLY)
    pt = ctx.sampler.default()
    b, E = beam.at(pt)
    try:
        beam.engine.orbit(pt, b if b is not None else 1, E).P  # noqa: B018 - the checks
    except Unbound as exc:
        raise ctx.part.error(("energy",), str(exc)) from None


def _book(ctx: Context, expr, pt: dict):
    try:
        v = evaluate_mp(expr, pt, DIGITS)
    except (NotNumeric, ZeroDivisionError, ValueError, TypeError):
        return None
    if not mpmath.isfinite(v) or abs(mpmath.im(v)) > mpmath.mpf(10) ** -25 * max(1, abs(v)):
        return None
    return mpmath.re(v)


def _compare(ctx: Context, what: str, book, engine_of, how: str, floor=None) -> Verdict:
    """The book's expression against `engine_of(pt, b, E)` at POINTS points, to RTOL of
    the engine's value (or of `floor(beam, pt, b, E)`, a scale for a value that may be 0)."""
    beam = Beam(ctx)
    worst = 0.0
    with mpmath.workdps(DPS + 15):
        for n, pt, b, E in beam.points():
            eng = engine_of(beam, pt, b, E)
            val = _book(ctx, book, pt)
            if val is None:
                return Verdict(False, f"{how}({n} points)", f"the book's {what} has no real "
                               f"value at b = {float(b):.6g}, E = {float(E):.6g}")
            scale = max(abs(eng), floor(beam, pt, b, E) if floor else 0,
                        mpmath.mpf(10) ** -300)
            rel = abs(val - eng) / scale
            worst = max(worst, float(rel))
            if rel > RTOL:
                return Verdict(False, f"{how}({n} points)",
                               f"{what}: book {mpmath.nstr(val, 15)}, engine "
                               f"{mpmath.nstr(eng, 15)} (relative {float(rel):.2g}) at "
                               f"b = {float(b):.6g}, E = {float(E):.6g}")
    return Verdict(True, f"{how}({POINTS} points, {DIGITS} digits)",
                   f"worst relative {worst:.2g}",
                   power=f"{POINTS} points, each value to {RTOL:g} ({how} at {DPS} and "
                         f"{DPS + 15} digits, agreeing to 1e-{DIGITS})")


def _deflection(orbit):
    try:
        return orbit.deflection
    except Captured as exc:
        raise _CapturedFail(str(exc.capability)) from None


class _CapturedFail(Exception):
    pass


@quantity('deflection_angle',
          book='expression: the deflection angle Θ(b, E) at infinity (signed: positive '
               'away from the centre, negative towards it)',
          how=('Θ = π − 2∫_{r_min}^∞ u √(m/(2(E − V_eff))) dr on the orbit of impact '
               'parameter `impact_parameter:` and energy `energy:` (angular momentum '
               'b·√(2m∞E)), with r = r_min/(1 − w²) removing the turning point\'s '
               'singularity: tanh-sinh quadrature at 40 and 55 digits, which must agree to '
               '1e-30; 6 points to 1e-20. An orbit that falls in fails a finite angle; '
               'orbiting (a double root) is unsupported'),
          keys=ORBIT, validate=validate_orbit, crosschecks=("scattering",))
def check_deflection_angle(ctx: Context, val) -> Verdict:
    book = ctx.parse(val, ("book",))
    try:
        return _compare(ctx, "deflection angle", book,
                        lambda beam, pt, b, E: beam.value(pt, b, E, _deflection), "quadrature")
    except _CapturedFail as exc:
        return Verdict(False, "quadrature", f"{exc}: the book gives a deflection angle")


@quantity('closest_approach',
          book='expression: the distance of closest approach r_min(b, E)',
          how=('the largest root of E = V_eff(r) on the orbit from infinity (b, E as for '
               '`deflection_angle`), or the hard core\'s radius where the orbit reaches it: '
               'an inward search from 1e8 length scales, bisection and the Illinois method at '
               '90 digits; 6 points to 1e-20. An orbit that falls in fails'),
          keys=ORBIT, validate=validate_orbit, crosschecks=("scattering",))
def check_closest_approach(ctx: Context, val) -> Verdict:
    book = ctx.parse(val, ("book",))

    def r_min(orbit):
        t = orbit.turning
        if t.captured:
            raise _CapturedFail("the particle falls to the centre (captured)")
        return t.r

    try:
        return _compare(ctx, "closest approach", book,
                        lambda beam, pt, b, E: beam.value(pt, b, E, r_min), "root")
    except _CapturedFail as exc:
        return Verdict(False, "root", f"{exc}: the book gives a closest approach")


@quantity('time_delay',
          book='expression: the time delay τ(b, E) against the free straight line of the same '
               'b and E (negative: the orbit is ahead)',
          how=('τ = 2[∫_{r_min}^∞ √(m/(2(E − V_eff))) dr − ∫_b^∞ √(m∞/(2(E − Eb²/r²))) dr] '
               '(b, E as for `deflection_angle`), the singularity removed and the two '
               'integrals\' difference taken beyond 2 max(r_min, b), at 40 and 55 digits '
               'agreeing to 1e-30; 6 points to 1e-20 of max(|τ|, r_min/v∞). Unsupported where '
               'the potential falls like 1/r or slower (the delay grows like log R)'),
          keys=ORBIT, validate=validate_orbit, crosschecks=("scattering",))
def check_time_delay(ctx: Context, val) -> Verdict:
    book = ctx.parse(val, ("book",))

    def delay(orbit):
        try:
            return orbit.time_delay
        except Captured as exc:
            raise _CapturedFail(str(exc.capability)) from None

    def floor(beam, pt, b, E):
        return beam.value(pt, b, E, lambda o: o.r_min / o.speed)

    try:
        return _compare(ctx, "time delay", book,
                        lambda beam, pt, b, E: beam.value(pt, b, E, delay), "quadrature",
                        floor)
    except _CapturedFail as exc:
        return Verdict(False, "quadrature", f"{exc}: the book gives a time delay")


def _angle_names(ctx: Context) -> dict:
    name = ctx.part.data.get("scattering_angle")
    if name is None:
        return ctx.names
    if name in ctx.names:
        raise ctx.part.error(("scattering_angle",), f"{name!r} is already a name: the "
                             "scattering angle is a name of its own")
    return {**ctx.names, name: sp.Symbol(name, real=True)}


def _observed(theta):
    """The observed scattering angle χ ∈ [0, π] of a deflection Θ (cos χ = cos Θ)."""
    chi = abs(theta) % (2 * mpmath.pi)
    return 2 * mpmath.pi - chi if chi > mpmath.pi else chi


@quantity('cross_section',
          book='expression: the differential cross section dσ/dΩ, in b and E, or in the '
               'observed scattering angle χ ∈ [0, π] named by `scattering_angle:`',
          how=('(b/sin χ)|db/dχ| on the orbit of `impact_parameter:`, `energy:` (Θ as for '
               '`deflection_angle`, dΘ/db by central differences at 40 digits, steps 1e-10·b '
               'and 1e-9·b agreeing to 1e-15, Richardson-extrapolated), the book evaluated at '
               'the engine\'s χ; 6 points to 1e-15. Unsupported where it is singular: a '
               'rainbow (dΘ/db = 0), a glory (sin Θ = 0, b ≠ 0), or several impact parameters '
               'scattering into one angle (χ(b) not monotone, steps beyond 1e-12, on 16 '
               'values from b/100 to 100b, each Θ in double precision with an error bound, '
               'at 20 digits where the bound leaves the decision open)'),
          keys={**ORBIT, "scattering_angle": NAME}, names=_angle_names,
          validate=validate_orbit, crosschecks=("scattering",))
def check_cross_section(ctx: Context, val) -> Verdict:
    names = _angle_names(ctx)
    book = ctx.parse(val, ("book",), names=names)
    name = ctx.part.data.get("scattering_angle")
    chi_sym = names[name] if name else None
    beam = Beam(ctx)
    worst = 0.0
    with mpmath.workdps(DPS + 15):
        for n, pt, b, E in beam.points():
            chi, dsigma = _differential(beam, pt, b, E)
            at = {**pt, chi_sym: sp.Float(str(chi), DIGITS)} if chi_sym is not None else pt
            v = _book(ctx, book, at)
            if v is None:
                return Verdict(False, f"quadrature({n} points)", "the book's dσ/dΩ has no "
                               f"real value at χ = {float(chi):.6g}")
            rel = abs(v - dsigma) / abs(dsigma)
            worst = max(worst, float(rel))
            if rel > DERIVATIVE_RTOL:
                return Verdict(False, f"quadrature({n} points)",
                               f"dσ/dΩ: book {mpmath.nstr(v, 15)}, engine "
                               f"{mpmath.nstr(dsigma, 15)} (relative {float(rel):.2g}) at "
                               f"b = {float(b):.6g}, E = {float(E):.6g}, χ = {float(chi):.6g}")
    return Verdict(True, f"quadrature({POINTS} points)", f"worst relative {worst:.2g}",
                   power=f"{POINTS} points, each value to {DERIVATIVE_RTOL:g} (dΘ/db by two "
                         f"central differences agreeing to {DERIVATIVE_RTOL:g}); one branch "
                         f"of χ(b) confirmed on {SCAN} impact parameters from b/100 to 100b")


def _theta(beam: Beam, pt: dict, b, dps: int, E):
    try:
        return beam.engine.orbit(pt, b, E, dps).deflection
    except Captured:
        raise UnsupportedError("dσ/dΩ: the orbit falls in at b = "
                               f"{float(b):.6g}") from None


def _differential(beam: Beam, pt: dict, b, E) -> tuple:
    """(χ, dσ/dΩ) at the orbit (b, E); UnsupportedError where dσ/dΩ is singular. dΘ/db by
    central differences at two steps, STEPS[0]·b and STEPS[1]·b (four orbits at DPS
    digits, where Θ holds ~39: the rounding leaves ~1e-30/(b|dΘ/db|) of the slope): the
    two differ by c(h₂² − h₁²), c·h² the error of each, so their agreement to
    DERIVATIVE_RTOL bounds the smaller step's error by a hundredth of it (and the c·h₁²
    they measure is taken off: Richardson's extrapolation)."""
    d = DPS
    theta = beam.value(pt, b, E, lambda o: o.deflection)
    with mpmath.workdps(d):
        bb = mpmath.mpf(str(b))

        def slope(h):
            return (_theta(beam, pt, bb + h, d, E) - _theta(beam, pt, bb - h, d, E)) / (2 * h)

        h1, h2 = (mpmath.mpf(10) ** -k for k in STEPS)
        s1, s2 = slope(bb * h1), slope(bb * h2)
        if abs(s1 - s2) > DERIVATIVE_RTOL * abs(s1) + mpmath.mpf(10) ** -25:
            raise UnsupportedError(f"dσ/dΩ: dΘ/db not resolved (two estimates "
                                   f"{mpmath.nstr(s1, 10)}, {mpmath.nstr(s2, 10)})")
        s1 += (s1 - s2) * h1 ** 2 / (h2 ** 2 - h1 ** 2)  # the c·h₁² the two measure, removed
        chi = _observed(theta)
        if abs(s1) * bb < SINGULAR:
            raise UnsupportedError(f"dσ/dΩ: a rainbow angle (dΘ/db = 0) at b = {float(b):.6g}"
                                   ": the classical cross section is infinite there")
        if abs(mpmath.sin(theta)) < SINGULAR:
            raise UnsupportedError(f"dσ/dΩ: a glory angle (sin Θ = 0 with b ≠ 0) at b = "
                                   f"{float(b):.6g}: the classical cross section is infinite")
    _one_branch(beam, pt, b, E)
    with mpmath.workdps(DPS + 15):
        return chi, bb / (abs(mpmath.sin(chi)) * abs(s1))


def _one_branch(beam: Beam, pt: dict, b, E) -> None:
    """One impact parameter per angle, judged on SCAN impact parameters from b/100 to 100b:
    Θ(b) monotone (no step between neighbours above 1e-12 one way and another the other
    way), within [−π, π], and no orbit among them captured (next to b_c the deflection
    winds without bound, and every angle has infinitely many branches); otherwise dσ/dΩ is
    a sum over branches, which is not computed. Each Θ is taken in double precision with
    a bound on its error (mechbook.engine.scattering_float), and at 20 digits where that
    cannot say or where a step or |Θ| is within its bound of the threshold: the decision
    is the one the 20-digit values give."""
    why = None
    tiny, pi = 1e-12, math.pi
    with mpmath.workdps(20):
        bb = mpmath.mpf(str(b))
        orbits, thetas = [], []  # thetas: (Θ, a bound on its error; 0 for a 20-digit one)
        for k in range(SCAN):
            bk = bb * mpmath.mpf(10) ** (-2 + 4 * mpmath.mpf(k) / (SCAN - 1))
            orbit = beam.engine.orbit(pt, bk, E, 20)
            got = float_deflection(orbit)
            if got is None:
                try:
                    got = (orbit.deflection, 0.0)
                except Captured:
                    why = f"the orbit at b = {float(bk):.4g} is captured, and next to the " \
                          "capture the deflection winds without bound"
                    break
            orbits.append(orbit)
            thetas.append(got)

        def exact(i):
            if thetas[i][1]:
                thetas[i] = (orbits[i].deflection, 0.0)

        for i in range(len(thetas) - 1 if why is None else 0):  # a step near ±1e-12
            s = float(thetas[i + 1][0] - thetas[i][0])
            err = thetas[i][1] + thetas[i + 1][1]
            if err and (abs(s - tiny) <= err or abs(s + tiny) <= err):
                exact(i)
                exact(i + 1)
        for i, (t, err) in enumerate(thetas):
            if err and abs(abs(float(t)) - pi) <= err:
                exact(i)
        steps = [y[0] - x[0] for x, y in zip(thetas, thetas[1:], strict=False)]
        if why is None and any(s > tiny for s in steps) and any(s < -tiny for s in steps):
            why = "Θ(b) is not monotone"
        if why is None and any(abs(t) > mpmath.pi for t, _ in thetas):
            why = "|Θ(b)| exceeds π (the orbit winds round)"
    if why:
        raise UnsupportedError(f"dσ/dΩ: several impact parameters scatter into one angle "
                               f"between b/100 and 100b (b = {float(b):.6g}): {why}; the sum "
                               "over branches is not computed")


@quantity('total_cross_section',
          book='expression: the total cross section σ (`process: capture`: the capture '
               'cross section)',
          how=('scattering: σ = π R², R the radius beyond which no orbit is deflected, where '
               'one exists: the hard core\'s with a potential that vanishes identically '
               '(confirmed: Θ ≠ 0 at b = 0.999R, in double precision beyond its error bound '
               'or else at 40 and 55 digits); a potential that reaches to infinity '
               'deflects every b (Θ ≠ 0 at b = 1000R is shown) and fails a finite σ. '
               'capture: σ = π b_c² (`critical_impact_parameter`); 6 points to 1e-20'),
          keys={**BEAM, "process": {"enum": ["scattering", "capture"]}},
          validate=validate_orbit)
def check_total_cross_section(ctx: Context, val) -> Verdict:
    book = ctx.parse(val, ("book",))
    process = ctx.part.data.get("process", "scattering")
    if process == "capture":
        return _compare_beam(ctx, "capture cross section", book,
                             lambda beam, pt, E: mpmath.pi * _b_c(beam, pt, E) ** 2)

    def sigma(beam, pt, E):
        orbit = beam.engine.orbit(pt, 1, E)
        R = orbit.core
        if R is not None and beam.engine.potential_is_zero:
            b_in = sp.Float(str(R * mpmath.mpf("0.999")), DIGITS)
            try:
                quick = float_deflection(beam.engine.orbit(pt, b_in, E))
            except Unbound as exc:
                raise beam.ctx.part.error(("energy",), str(exc)) from None
            if quick is not None and abs(quick[0]) > quick[1]:
                return mpmath.pi * R ** 2  # Θ ≠ 0 beyond its bound: no 30 digits needed
            inside = beam.value(pt, b_in, E, lambda o: o.deflection)
            if inside == 0:
                raise UnsupportedError("σ: no deflection just inside the hard core's radius")
            return mpmath.pi * R ** 2
        far = sp.Float(str(1000 * orbit.scale), DIGITS)
        theta = beam.value(pt, far, E, lambda o: o.deflection)
        raise _Infinite(f"the potential reaches to infinity: an orbit at b = "
                        f"{float(far):.4g} is still deflected (Θ = {mpmath.nstr(theta, 5)}), "
                        "so the classical total cross section is infinite")

    try:
        return _compare_beam(ctx, "total cross section", book, sigma)
    except _Infinite as exc:
        return Verdict(False, "quadrature", str(exc))


class _Infinite(Exception):
    pass


def _b_c(beam: Beam, pt: dict, E):
    try:
        lo = critical_impact_parameter(beam.engine, pt, E, DPS)
        hi = critical_impact_parameter(beam.engine, pt, E, DPS + 15)
    except Unbound as exc:
        raise beam.ctx.part.error(("energy",), str(exc)) from None
    if abs(hi - lo) > mpmath.mpf(10) ** -DIGITS * max(abs(hi), 1):
        raise UnsupportedError("the critical impact parameter did not reach "
                               f"{DIGITS} digits")
    return hi


def _compare_beam(ctx: Context, what: str, book, engine_of) -> Verdict:
    """As `_compare`, for a quantity of the beam's energy alone (no b)."""
    beam = Beam(ctx, needs_b=False)
    worst = 0.0
    with mpmath.workdps(DPS + 15):
        for n in range(1, POINTS + 1):
            pt = ctx.sampler.draw()
            _, E = beam.at(pt)
            eng = engine_of(beam, pt, E)
            val = _book(ctx, book, pt)
            if val is None:
                return Verdict(False, f"quadrature({n} points)", f"the book's {what} has no "
                               "real value")
            rel = abs(val - eng) / max(abs(eng), mpmath.mpf(10) ** -300)
            if eng == 0 and val != 0:
                rel = mpmath.inf
            worst = max(worst, float(rel))
            if rel > RTOL:
                return Verdict(False, f"quadrature({n} points)",
                               f"{what}: book {mpmath.nstr(val, 15)}, engine "
                               f"{mpmath.nstr(eng, 15)} at E = {float(E):.6g}")
    return Verdict(True, f"quadrature({POINTS} points, {DIGITS} digits)",
                   f"worst relative {worst:.2g}",
                   power=f"{POINTS} points, each value to {RTOL:g} (at {DPS} and {DPS + 15} "
                         f"digits, agreeing to 1e-{DIGITS})")


@quantity('critical_impact_parameter',
          book='expression: b_c(E), below which the particle is captured (falls in)',
          how=('b_c = inf_r B(r), B(r) the impact parameter at which E = V_eff(r) (V_eff '
               'rises with b): a log grid over 24 decades of r (at full precision where '
               'double precision, allowed an error of 1e-9, leaves the least value possible), '
               'the minimum by golden sections, at 40 and 55 digits agreeing to 1e-30; 0 '
               'where no b is captured; 6 points to 1e-20'),
          keys=BEAM, validate=validate_orbit)
def check_critical_impact_parameter(ctx: Context, val) -> Verdict:
    book = ctx.parse(val, ("book",))
    return _compare_beam(ctx, "critical impact parameter", book,
                         lambda beam, pt, E: _b_c(beam, pt, E))


@quantity('capture',
          book='captured or scattered (the orbit of `impact_parameter:`, `energy:`), or a '
               'relation in them that holds exactly where the particle is captured',
          how=('a word: the orbit falls to r → 0 (no turning point on an inward search from '
               '1e8 length scales to 1e-30) at 6 points; a relation: at 6 points it holds '
               'exactly at the engine\'s verdict, and on either side of b_c '
               '(`critical_impact_parameter`) a relative 1e-8 away it holds just below and '
               'fails just above (`impact_parameter:` a symbol): a boundary moved by more '
               'than 1e-8 fails'),
          keys=ORBIT, literals=("captured", "scattered"), validate=validate_orbit)
def check_capture(ctx: Context, val) -> Verdict:
    beam = Beam(ctx)
    if val in ("captured", "scattered"):
        for n, pt, b, E in beam.points():
            falls = beam.engine.orbit(pt, b, E).turning.captured
            if falls != (val == "captured"):
                return Verdict(False, f"search({n} points)",
                               f"the orbit at b = {float(b):.6g}, E = {float(E):.6g} is "
                               f"{'captured' if falls else 'scattered'}")
        return Verdict(True, f"search({POINTS} points)",
                       power=f"{POINTS} points: the verdict at each")
    rel = ctx.parse(val, ("book",), relation=True)
    if not isinstance(beam.b, sp.Symbol):
        raise ctx.part.error(("impact_parameter",), "a capture relation needs "
                             "`impact_parameter:` to be a symbol (it is moved to b_c)")
    for n, pt, b, E in beam.points():
        falls = beam.engine.orbit(pt, b, E).turning.captured
        if holds(rel, pt) != falls:
            return Verdict(False, f"boundary({n} points)",
                           f"at b = {float(b):.6g}, E = {float(E):.6g} the orbit is "
                           f"{'captured' if falls else 'scattered'}, the relation says "
                           "otherwise")
        bc = _b_c(beam, pt, E)
        if bc == 0:
            continue
        for side, want in ((1 - NEAR, True), (1 + NEAR, False)):
            at = {**pt, beam.b: sp.Float(str(bc * side), DIGITS)}
            if holds(rel, at) != want:
                return Verdict(False, f"boundary({n} points)",
                               f"at b = b_c·{side:.8g} (b_c = {mpmath.nstr(bc, 12)}) the orbit "
                               f"is {'captured' if want else 'scattered'}, the relation says "
                               "otherwise")
    return Verdict(True, f"boundary({POINTS} points)",
                   power=f"{POINTS} points, the boundary b_c to {NEAR:g} either side")
