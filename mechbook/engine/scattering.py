"""Scattering on an unbound orbit: deflection, closest approach, capture.

A system whose coordinates are one radial coordinate r and one cyclic angle (a particle in
a plane in a central potential, or anything the level-set reduction brings to that form,
mechbook.engine.levelset) has, at angular momentum P and energy E,
    E = m(r) ṙ²/2 + V_eff(r; P),   θ̇ = u(r; P).
An orbit that comes in from r = ∞ with impact parameter b and energy E (V_eff → 0 there)
has P = b·p∞, p∞ = √(2 m∞ E) the momentum at infinity (m∞ = m(∞)): the angular momentum
about the centre of a straight line at distance b. It turns at r_min, the largest root
of E = V_eff(r; P) (or on a hard core of radius a: V = ∞ for r < a, a specular
reflection), and the deflection angle is
    Θ = π − 2 ∫_{r_min}^∞ u(r) √(m/(2(E − V_eff))) dr,
signed: positive away from the centre (repulsion), negative towards it. With
r = r_min/(1 − w²) the turning point's 1/√ singularity is gone (dr ∝ w dw) and r = ∞ is
w = 1: the integrand is bounded on [0, 1], integrated by tanh-sinh quadrature at two
working precisions whose difference is the result's measured error.

The time delay against the free straight line of the same b and E is the difference of the
two orbits' ∫ dt/dr, taken as one convergent integral far out (`Orbit.time_delay`).

Capture: V_eff is increasing in P² (the centrifugal term), so at each r there is a largest
b, B(r), for which E > V_eff(r); the particle falls to r → 0 exactly when b < b_c =
inf_r B(r), the critical impact parameter (√(α/E) for V = −α/r²).
"""

from __future__ import annotations

import math
import sys
import warnings
from dataclasses import dataclass
from functools import cached_property

import mpmath
import numpy as np
import sympy as sp
from scipy.optimize import brentq

from mechbook.engine.lagrange import Dynamics
from mechbook.engine.levelset import LevelSet
from mechbook.errors import UnsupportedError

DPS = 40  # the working precision of one evaluation (a second one at DPS + 15 checks it)
DIGITS = 30  # digits a result must keep at both precisions
FAR = 10 ** 8  # the inward search for r_min starts this many length scales out
STEP = mpmath.mpf("0.98")  # its geometric step (a barrier narrower than 2 % of r is missed)
MAX_STEPS = 6000
ORBITS = 4096  # orbits a Scattering keeps (their values computed once), then forgets
ROUGH = 1e-9  # the relative error a double-precision value of V_eff is allowed (b_c's grid)
GOLDEN = 3  # golden sections per digit for b_c (its bracket to 10^-(dps·0.63))


def float_grid(r0: float) -> np.ndarray:
    """The inward search's points below r0 in double precision, r0·STEPⁿ for n = 1 …
    MAX_STEPS (the same numbers wherever the search is taken in double precision)."""
    return r0 * np.cumprod(np.full(MAX_STEPS, float(STEP)))


class Unbound(Exception):
    """The orbit is not a scattering orbit (bound, or the potential does not vanish far
    out): the caller turns it into an error at the part's key."""


@dataclass(frozen=True)
class Turning:
    """Where an orbit from infinity turns: `r` (None if it falls in), `on_core` (it turns
    on the hard core, not at a root of E = V_eff)."""

    r: object
    on_core: bool = False
    below: object = None  # on a core: the root of E = V_eff inside it (None if none)

    @property
    def singular(self):
        """Where the integrands' 1/√ singularity is: the turning point, or on a core the
        root inside it (near a grazing orbit, just below the core), or None."""
        return self.below if self.on_core else self.r

    @property
    def captured(self) -> bool:
        return self.r is None


class Scattering:
    """The reduction of a system to its radial coordinate `radius` and one cyclic angle,
    with an optional hard core (an expression in the parameters)."""

    def __init__(self, dyn: Dynamics, radius: sp.Symbol, hard_core: sp.Expr | None = None):
        self.level = LevelSet(dyn, radius)
        if len(self.level.cyclic) != 1:
            raise UnsupportedError("scattering needs one radial coordinate and one cyclic "
                                   f"angle; this system has {len(self.level.cyclic) + 1} "
                                   "coordinates")
        self.angle = self.level.cyclic[0]
        self.r = radius
        self.hard_core = hard_core
        mass, V, u = self.level.reduced
        P = self.level.P[0]
        if sp.diff(V, P, 3) != 0 or sp.diff(V, P).subs(P, 0) != 0:
            raise UnsupportedError("scattering: the effective potential is not even and "
                                   "quadratic in the angular momentum")
        self.P = P
        self._orbits: dict[tuple, Orbit] = {}  # (params, b, E, dps) -> its Orbit

    @cached_property
    def functions(self):
        mass, V, u = self.level.reduced
        args = [self.r, self.P, *self.level.params]
        core = [] if self.hard_core is None else [sp.lambdify(self.level.params,
                                                              self.hard_core, "mpmath")]
        return (sp.lambdify(args, mass, "mpmath"), sp.lambdify(args, V, "mpmath"),
                sp.lambdify(args, u[0], "mpmath"), core)

    @cached_property
    def float_kinetic(self):
        """V_eff(r, P, params) in double precision (None where it has no such form)."""
        _, V, _ = self.level.reduced
        try:
            return sp.lambdify([self.r, self.P, *self.level.params], V, "math")
        except Exception:  # noqa: BLE001 - a function math lacks: the search stays exact
            return None

    @cached_property
    def float_functions(self):
        """(m, V_eff, dV_eff/dr, u) of (r, P, params) in NumPy, for arrays of r (None where
        the expressions have no NumPy form): mechbook.engine.scattering_float's."""
        mass, V, u = self.level.reduced
        args = [self.r, self.P, *self.level.params]
        try:
            return tuple(sp.lambdify(args, f, "numpy")
                         for f in (mass, V, sp.diff(V, self.r), u[0]))
        except Exception:  # noqa: BLE001 - a function NumPy lacks: the decisions stay exact
            return None

    @cached_property
    def float_parts(self):
        """(v0, c2) of (r, params) in double precision, V_eff = v0 + c2 P² (None where they
        have no such form): the capture grid's."""
        _, V, _ = self.level.reduced
        args = [self.r, *self.level.params]
        try:
            return (sp.lambdify(args, V.subs(self.P, 0), "math"),
                    sp.lambdify(args, sp.diff(V, self.P, 2) / 2, "math"))
        except Exception:  # noqa: BLE001 - a function math lacks: the grid stays exact
            return None

    @cached_property
    def potential_is_zero(self) -> bool:
        """Whether V_eff at P = 0 (the potential alone) vanishes identically: a finite range
        is then the hard core's."""
        _, V, _ = self.level.reduced
        return sp.simplify(V.subs(self.P, 0)) == 0

    def orbit(self, point: dict, b, E, dps: int = DPS) -> Orbit:
        """The scattering orbit of impact parameter `b` and energy `E` (numbers) at the
        parameter `point`, in `dps`-digit arithmetic; Unbound if it is not one. The same
        numbers at the same precision give the same Orbit (its values computed once: the
        parts of a problem draw the same points, and its cross-check asks them again)."""
        with mpmath.workdps(dps):
            params = [_mp(point[p], dps) for p in self.level.params]
            b, E = _mp(b, dps), _mp(E, dps)
            key = (tuple(params), b, E, dps)
            orbit = self._orbits.get(key)
            if orbit is None:
                if len(self._orbits) >= ORBITS:
                    self._orbits.clear()
                orbit = self._orbits[key] = Orbit(self, params, b, E, dps)
            return orbit


def _mp(value, dps: int):
    """A number as an mpf: a SymPy Float exactly (its binary value, the same at every
    precision above its own, so two precisions see the same orbit), else to `dps` digits.
    Numbers only (a Python or mpmath number, or SymPy's): never text."""
    if isinstance(value, bool | int):
        value = sp.Integer(value)
    elif isinstance(value, float | mpmath.mpf):
        value = sp.Float(value)
    elif not isinstance(value, sp.Basic):
        raise TypeError(f"a number, not {type(value).__name__}")
    if isinstance(value, sp.Float) and value._prec <= mpmath.mp.prec:
        return mpmath.mpf(value._mpf_)
    return mpmath.mpf(str(sp.N(value, dps)))


@dataclass
class Orbit:
    scattering: Scattering
    params: list
    b: object
    E: object
    dps: int
    critical: object = None  # b_c at this orbit's E (critical_impact_parameter), once found

    def _f(self, name: str):
        m, V, u, core = self.scattering.functions
        return {"m": m, "V": V, "u": u}[name]

    def mass(self, r):
        return self._f("m")(r, self.P, *self.params)

    def veff(self, r, P=None):
        return self._f("V")(r, self.P if P is None else P, *self.params)

    def kinetic(self, r):
        """E − V_eff(r): m ṙ²/2 (negative where the orbit cannot go)."""
        try:
            return self.E - self.veff(r)
        except (ZeroDivisionError, ValueError):
            return mpmath.mpf(-1)

    @cached_property
    def core(self):
        _, _, _, core = self.scattering.functions
        return core[0](*self.params) if core else None

    @cached_property
    def scale(self):
        """A length to start from: the hard core, the impact parameter, or 1."""
        return max(self.core or 0, abs(self.b), mpmath.mpf(1) if self.b == 0 else 0)

    @cached_property
    def m_inf(self):
        with mpmath.workdps(self.dps):
            far = self.scale * mpmath.mpf(10) ** (2 * DIGITS)
            m = self._f("m")(far, 0, *self.params)
            m2 = self._f("m")(far * 10 ** 5, 0, *self.params)
            if not (mpmath.isfinite(m) and m > 0 and abs(m - m2) <= abs(m) *
                    mpmath.mpf(10) ** (-DIGITS)):
                raise Unbound("the radial mass has no positive limit far out")
            return m

    @cached_property
    def P(self):
        """The angular momentum b·√(2 m∞ E), after the checks that this is a scattering
        orbit: the potential vanishes far out, and E > 0 above it."""
        with mpmath.workdps(self.dps):
            if not self.E > 0:
                raise Unbound(f"E = {mpmath.nstr(self.E, 8)} is not above the potential at "
                              "infinity (0): the orbit is bound, not a scattering one")
            far1 = self.scale * mpmath.mpf(10) ** 20
            far2 = self.scale * mpmath.mpf(10) ** 40
            v1, v2 = (self._f("V")(r, 0, *self.params) for r in (far1, far2))
            if not (abs(v2) <= abs(self.E) * mpmath.mpf(10) ** -15 and abs(v2) <= abs(v1)):
                raise Unbound(f"the potential does not vanish at infinity (V = "
                              f"{mpmath.nstr(v2, 8)} at r = 1e40 length scales): no "
                              "scattering orbit")
            return self.b * mpmath.sqrt(2 * self.m_inf * self.E)

    @cached_property
    def turning(self) -> Turning:
        """The turning point of the orbit from infinity: an inward geometric search from
        FAR length scales out, refined by bisection to the working precision."""
        with mpmath.workdps(self.dps):
            self.P  # noqa: B018 - the checks of an unbound orbit first
            r = self.scale * FAR
            for _ in range(3):
                if self.kinetic(r) > 0:
                    break
                r *= FAR
            else:
                raise UnsupportedError("scattering: E − V_eff is not positive far out")
            core = self.core
            tiny = self.scale * mpmath.mpf(10) ** (-DIGITS)
            r = self._descend(r, core, tiny)
            for _ in range(MAX_STEPS):
                nxt = r * STEP
                if core is not None and nxt <= core:
                    if self.kinetic(core) > 0:
                        return Turning(core, True, self._root_inside(core, tiny))
                    return Turning(self._bisect(core, r))
                if nxt < tiny:
                    return Turning(None)
                k = self.kinetic(nxt)
                if not (mpmath.isfinite(k) and k > 0):
                    return Turning(self._bisect(nxt, r))
                r = nxt
            raise UnsupportedError("scattering: no turning point found in the search")

    def _descend(self, r, core, tiny):
        """The search's steps in double precision (a fiftieth of the cost): the last r
        before E − V_eff is not positive, before the core or before `tiny`, from which the
        search goes on at the working precision; a step the double-precision values
        misjudged near the root is taken again there (r moved back out until allowed).
        From the core down (`core` None) it finds the root inside the core the same way."""
        fns = self.scattering.float_functions
        if fns is None:
            return r
        args = [float(self.P), *(float(p) for p in self.params)]
        E, x, stop = float(self.E), float(r), float(max(core or 0, tiny))
        grid = float_grid(x)
        grid = grid[:int(np.argmax(grid <= stop)) if grid[-1] <= stop else grid.size]
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                k = E - np.broadcast_to(np.asarray(fns[1](grid, *args), dtype=float),
                                        grid.shape)
            except (ZeroDivisionError, ValueError, OverflowError, TypeError):
                return r
        bad = ~(np.isfinite(k) & (k > 0))
        last = (int(np.argmax(bad)) if bad.any() else grid.size) - 1
        if last >= 0:
            x = float(grid[last])
        back = mpmath.mpf(x)
        while back < r and not self.kinetic(back) > 0:
            back = back / STEP
        return min(back, r)

    def _root_inside(self, core, tiny):
        """The largest root of E = V_eff below the core (the orbit never gets there, but
        a grazing orbit's integrands are nearly singular at it), or None. Only where the
        substitutions start (any point below the core makes them exact): to half the
        working precision, without the Illinois steps a turning point needs."""
        r = self._descend(core, None, tiny)
        for _ in range(MAX_STEPS):
            nxt = r * STEP
            if nxt < tiny:
                return None
            k = self.kinetic(nxt)
            if not (mpmath.isfinite(k) and k > 0):
                return self._bisect(nxt, r, refine=False)
            r = nxt
        return None

    def _float_bracket(self, lo, hi):
        """[lo, hi] narrowed to 1e-13 around the root of E − V_eff found by Brent's method in
        double precision, if E − V_eff at the working precision is not positive at its lower
        end and positive at its upper one (else [lo, hi] as given)."""
        fn = self.scattering.float_kinetic
        if fn is None:
            return lo, hi
        args = [float(self.P), *(float(p) for p in self.params)]
        E = float(self.E)

        def k(x):
            return E - fn(x, *args)

        try:
            a, b = float(lo), float(hi)
            if not (k(a) <= 0 < k(b)):
                return lo, hi
            x = brentq(k, a, b, xtol=1e-300, rtol=4 * sys.float_info.epsilon)
        except (ZeroDivisionError, ValueError, OverflowError, TypeError, RuntimeError):
            return lo, hi
        lo2 = max(lo, mpmath.mpf(x * (1 - 1e-13)))
        hi2 = min(hi, mpmath.mpf(x * (1 + 1e-13)))
        k_lo, k_hi = self.kinetic(lo2), self.kinetic(hi2)
        if lo2 < hi2 and not (mpmath.isfinite(k_lo) and k_lo > 0) and \
                mpmath.isfinite(k_hi) and k_hi > 0:
            return lo2, hi2
        return lo, hi

    def _bisect(self, lo, hi, refine: bool = True):
        """The root of E − V_eff between `lo` (not allowed) and `hi` (allowed): bisection,
        then the Illinois method at twice the working precision (an error δ in r_min moves
        the deflection integral by ~√δ, so r_min needs twice the digits of Θ). The
        bisection starts from the double-precision root's bracket where the working
        precision confirms it (`_float_bracket`). `refine` False: the bisection's end."""
        tol = mpmath.mpf(10) ** (-(self.dps // 2))
        lo, hi = self._float_bracket(lo, hi)
        while hi - lo > hi * tol:
            mid = (lo + hi) / 2
            k = self.kinetic(mid)
            if mpmath.isfinite(k) and k > 0:
                hi = mid
            else:
                lo = mid
        if not refine:
            return hi
        with mpmath.workdps(2 * self.dps + 10):
            k_lo, k_hi = self.kinetic(lo), self.kinetic(hi)
            if not (mpmath.isfinite(k_lo) and k_lo < 0):
                return hi  # no value below the root (V_eff singular): the bisection's end
            side = 0
            for _ in range(200):
                if hi - lo <= hi * mpmath.mpf(10) ** (-(2 * self.dps + 5)):
                    break
                mid = hi - k_hi * (hi - lo) / (k_hi - k_lo)
                if not lo < mid < hi:
                    mid = (lo + hi) / 2
                k = self.kinetic(mid)
                if k == 0:
                    return mid
                if mpmath.isfinite(k) and k > 0:
                    hi, k_hi = mid, k
                    if side == 1:
                        k_lo /= 2
                    side = 1
                else:
                    lo, k_lo = mid, k
                    if side == -1:
                        k_hi /= 2
                    side = -1
            return hi

    @property
    def r_min(self):
        t = self.turning
        if t.captured:
            raise Captured("the particle falls to the centre (captured): there is no "
                           "closest approach or deflection")
        return t.r

    @cached_property
    def deflection(self):
        """Θ = π − 2∫ u √(m/(2(E − V_eff))) dr from r_min to ∞ (signed)."""
        with mpmath.workdps(self.dps):
            rmin = self.r_min
            t = self.turning
            if not t.on_core:  # a simple root: E − V_eff has a nonzero slope there
                h = rmin * mpmath.mpf(10) ** (-self.dps // 3)
                slope = (self.kinetic(rmin + h) - self.kinetic(rmin)) / h
                if not slope * rmin > abs(self.E) * mpmath.mpf(10) ** -12:
                    raise UnsupportedError("scattering: orbiting (E − V_eff has a double "
                                           "root at the turning point): the deflection "
                                           "diverges")
            # r = rs/(1 − w²) from the singular point rs (the turning point, or on a core
            # the root inside it): the integral runs from w_lo (0 at a turning point) to 1;
            # at a root the integrand is even in w: below w0 its value at w0 stands for it
            # (an error of O(w0³)); on the core it is regular and needs no help
            rs = t.singular if t.singular is not None else rmin
            with mpmath.workdps(self.dps + 15):
                w_lo = mpmath.sqrt(1 - rs / rmin) if t.on_core else mpmath.mpf(0)
            w0 = 0 if t.on_core else mpmath.mpf(10) ** (-(self.dps // 3))
            with mpmath.workdps(self.dps + 15):  # a node rounded to w = 1 (r = ∞): below
                w1 = 1 - mpmath.mpf(10) ** (-(self.dps + 5))
            fm, fV, fu, _ = self.scattering.functions
            P, params, E, two_rs = self.P, self.params, self.E, 2 * rs
            ctx, inner = mpmath.mp, self.dps + 15  # E − V_eff is small near r_min

            def integrand(w):
                w = min(max(w, w0), w1)  # the integrand is bounded at both ends
                saved = ctx.prec
                ctx.dps = inner
                try:
                    one = (1 - w) * (1 + w)
                    r = max(rs / one, rmin)
                    k = _room(fV, E, r, P, params, "scattering")
                    return (fu(r, P, *params) * mpmath.sqrt(fm(r, P, *params) / (2 * k))
                            * two_rs * w / (one * one))
                finally:
                    ctx.prec = saved

            total = mpmath.quad(integrand, [w_lo, 1])
            return mpmath.pi - 2 * total


    @cached_property
    def speed(self):
        """v∞ = √(2E/m∞)."""
        with mpmath.workdps(self.dps):
            return mpmath.sqrt(2 * self.E / self.m_inf)

    @cached_property
    def time_delay(self):
        """τ = 2[∫_{r_min}^∞ √(m/(2(E − V_eff))) dr − ∫_b^∞ √(m∞/(2(E − Eb²/r²))) dr], the
        time the orbit takes beyond the free straight line of the same b and E: split at
        X = 2 max(r_min, b); the free part to X in closed form, √(X² − b²)/v∞; the orbit's
        part to X after r = r_min + (X − r_min)w² (the turning point's singularity gone);
        beyond X the difference of the two, after r = X/(1 − u). Defined where the
        potential falls faster than 1/r (else the delay grows like log R): refused there."""
        with mpmath.workdps(self.dps):
            rmin = self.r_min
            far = self.scale * mpmath.mpf(10) ** 20
            if abs(far * self.veff(far, 0)) > abs(self.E) * self.scale * \
                    mpmath.mpf(10) ** -10:
                raise UnsupportedError("time delay: the potential falls like 1/r or slower, "
                                       "so the delay grows like log R without a limit")
            X = 2 * max(rmin, self.b)
            m_inf, E, b = self.m_inf, self.E, self.b

            fm, fV, _, _ = self.scattering.functions
            P, params = self.P, self.params
            ctx, inner = mpmath.mp, self.dps + 15

            def dt_dr(r):
                k = _room(fV, E, r, P, params, "time delay")
                return mpmath.sqrt(fm(r, P, *params) / (2 * k))

            t = self.turning  # r = rs + (X − rs)w² from the singular point, as for Θ
            rs = t.singular if t.singular is not None else rmin
            with mpmath.workdps(self.dps + 15):
                w_lo = mpmath.sqrt((rmin - rs) / (X - rs))
            w0 = 0 if t.on_core else mpmath.mpf(10) ** (-(self.dps // 3))

            span = X - rs
            with mpmath.workdps(self.dps + 15):
                u1 = 1 - mpmath.mpf(10) ** (-(self.dps + 5))

            def near(w):
                w = max(w, w0)
                saved = ctx.prec
                ctx.dps = inner
                try:
                    return dt_dr(max(rs + span * w * w, rmin)) * 2 * span * w
                finally:
                    ctx.prec = saved

            def beyond(u):
                # √(m/2k) − √(m∞/2k0) without the cancellation of two numbers near
                # √(m∞/2E) far out: (m·k0 − m∞·k)/(2k·k0) over their sum, with
                # k0 − k = V_eff − Eb²/r², a difference of two small numbers there
                with mpmath.workdps(self.dps + 15):
                    one = 1 - min(u, u1)  # a node rounded to u = 1 (r = ∞)
                    r = X / one
                    centrifugal = E * (b / r) ** 2
                    v = self.veff(r)
                    k, k0, m = E - v, E - centrifugal, self.mass(r)
                    if not k > 0:
                        raise UnsupportedError("time delay: the orbit leaves the allowed "
                                               "region beyond its turning point")
                    top = m * (v - centrifugal) + (m - m_inf) * k
                    total = mpmath.sqrt(m / (2 * k)) + mpmath.sqrt(m_inf / (2 * k0))
                    return top / (2 * k * k0) / total * X / one ** 2

            inside = mpmath.quad(near, [w_lo, 1])
            outside = mpmath.quad(beyond, [0, 1])
            free = mpmath.sqrt(X * X - b * b) / self.speed
            return 2 * (inside + outside - free)


def _room(fV, E, r, P, params, what: str):
    """E − V_eff(r) on an orbit's integration path, where it must be positive (beyond the
    turning point): UnsupportedError naming `what` otherwise."""
    try:
        k = E - fV(r, P, *params)
    except (ZeroDivisionError, ValueError):
        k = -1
    if not k > 0:
        raise UnsupportedError(f"{what}: the orbit leaves the allowed region beyond its "
                               "turning point")
    return k


class Captured(UnsupportedError):
    """The orbit falls to the centre: the quantity asked for does not exist there."""

    def __init__(self, reason: str):
        super().__init__(reason)


def checked(scattering: Scattering, point: dict, b, E, what) -> tuple:
    """`what(orbit)` at DPS and at DPS + 15 digits; (value at the higher, their difference):
    UnsupportedError if they differ by more than 10^-DIGITS of the value (the quadrature
    did not reach its digits)."""
    lo = what(scattering.orbit(point, b, E, DPS))
    with mpmath.workdps(DPS + 15):
        hi = what(scattering.orbit(point, b, E, DPS + 15))
        diff = abs(hi - lo)
        if diff > mpmath.mpf(10) ** (-DIGITS) * max(abs(hi), 1):
            raise UnsupportedError(f"scattering: the quadrature did not reach {DIGITS} digits "
                                   f"(two precisions differ by {mpmath.nstr(diff, 3)})")
        return hi, diff


def critical_impact_parameter(scattering: Scattering, point: dict, E, dps: int = DPS):
    """b_c = inf_r B(r), B(r) the b at which E = V_eff(r; b·p∞) (0 where no b is captured,
    a potential less singular than −1/r²): a log grid of r over 24 decades at `dps`
    digits (only where double precision, with a generous error, leaves B's least value
    possible: `_candidates`), then the minimum refined by golden sections. Kept per
    orbit: the capture parts of a problem ask for the same b_c at the same points."""
    orbit = scattering.orbit(point, 1, E, dps)
    if scattering.hard_core is not None:
        raise UnsupportedError("capture with a hard core: the core reflects every orbit")
    if orbit.critical is None:
        orbit.critical = _critical(orbit, dps)
    return orbit.critical


def _critical(orbit: Orbit, dps: int):
    with mpmath.workdps(dps):
        orbit.P  # noqa: B018 - an unbound orbit
        p_inf = mpmath.sqrt(2 * orbit.m_inf * orbit.E)

        def B(r):
            v0 = orbit.veff(r, 0)
            c2 = orbit.veff(r, 1) - v0  # V_eff = v0 + c2 P²
            if not c2 > 0:
                raise UnsupportedError("scattering: the centrifugal term is not positive")
            room = orbit.E - v0
            return mpmath.sqrt(room / c2) / p_inf if room > 0 else mpmath.mpf(0)

        grid = [mpmath.mpf(10) ** (mpmath.mpf(k) / 10) for k in range(-120, 121)]
        values: dict[int, object] = {}

        def value(j):
            if j not in values:
                values[j] = B(grid[j])
            return values[j]

        candidates = _candidates(orbit, grid)
        i = min(candidates if candidates is not None else range(len(grid)), key=value)
        if value(i) == 0:
            return mpmath.mpf(0)
        if i == 0:  # still falling towards r → 0: the infimum is the limit there
            if value(0) < value(1) * mpmath.mpf("0.999"):
                return mpmath.mpf(0)
            return value(0)
        if i == len(grid) - 1:
            raise UnsupportedError("scattering: B(r) keeps falling far out")
        lo, hi = mpmath.log(grid[i - 1]), mpmath.log(grid[i + 1])
        g = (mpmath.sqrt(5) - 1) / 2
        a, c = hi - g * (hi - lo), lo + g * (hi - lo)
        fa, fc = B(mpmath.exp(a)), B(mpmath.exp(c))
        for _ in range(GOLDEN * dps):  # the bracket 0.46·0.618ⁿ: B's error its square
            if fa < fc:
                hi, c, fc = c, a, fa
                a = hi - g * (hi - lo)
                fa = B(mpmath.exp(a))
            else:
                lo, a, fa = a, c, fc
                c = lo + g * (hi - lo)
                fc = B(mpmath.exp(c))
        return min(fa, fc)


def _candidates(orbit: Orbit, grid: list):
    """The grid's indices where B may be least, by double precision: B² = (E − v0)/c2
    (V_eff = v0 + c2 P², each lambdified on its own, so c2 is no difference), each of
    E − v0 and c2 within ROUGH of its size (generous: a term of V_eff may cancel another);
    an index whose least B² is above another's largest is out. None where double precision
    has no value (every index is then taken at full precision). Ascending, so that the
    first least one stays first."""
    fns = orbit.scattering.float_parts
    if fns is None:
        return None
    v0f, c2f = fns
    try:
        params = [float(p) for p in orbit.params]
        E = float(orbit.E)
        lows, highs = [], []
        for r in grid:
            x = float(r)
            v0, c2 = v0f(x, *params), c2f(x, *params)
            room = E - v0
            e_room, e_c2 = ROUGH * (abs(E) + abs(v0)), ROUGH * abs(c2)
            if not (math.isfinite(room) and math.isfinite(c2) and c2 > 0):
                return None
            lows.append(max(room - e_room, 0.0) / (c2 + e_c2))
            highs.append(max(room + e_room, 0.0) / (c2 - e_c2))
    except (ZeroDivisionError, ValueError, OverflowError, TypeError):
        return None
    top = min(highs)
    return [j for j, low in enumerate(lows) if low <= top]
