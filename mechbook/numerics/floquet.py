"""Floquet theory of a linearization with periodic coefficients: the monodromy matrix over
one period, its multipliers and exponents, and the stability verdict they give.

For M(t)·δq̈ + C(t)·δq̇ + K(t)·δq = 0 with period T (mechbook.engine.periodic) the state
x = (δq, δq̇) obeys ẋ = A(t)·x, A = [[0, 1], [−M⁻¹K, −M⁻¹C]]. The fundamental matrix X(t),
X(0) = 1, is integrated over one period by heyoka's Taylor method in 113-bit (quadruple)
arithmetic at its machine tolerance (~1e-34): Φ = X(T), the monodromy matrix. Its
eigenvalues μ (the multipliers; exponents log μ / T) decide stability: every |μ| ≤ 1.

Deciding "on the unit circle" honestly:
- Liouville's formula det Φ = exp(−∫₀ᵀ tr(M⁻¹C) dt) is integrated alongside (one more
  variable) and compared with det Φ. An error E of Φ moves det Φ by det Φ·tr(Φ⁻¹E), so the
  relative mismatch measures Φ's relative error times the determinant's condition
  κ(Φ) = ‖Φ‖‖Φ⁻¹‖: the mismatch over κ(Φ) is the measured resolution of Φ (its relative
  error as Liouville sees it). For a well-conditioned Φ the two agree; for a strongly
  unstable one (|μ| ~ 1e19 and 1e-19) κ(Φ) is ~1e38 and the raw mismatch says nothing of Φ
  itself. det Φ, Φ⁻¹ and the multipliers are taken with the digits that condition needs
  (`digits_for`), so the mismatch is Φ's, never the determinant's rounding. A verdict, any
  verdict, needs the resolution below RESOLVED; where it is not the point has no verdict
  (UnsupportedError with the numbers). Until issue 41 a multiplier 1e-6 off the circle
  gave "unstable" whatever the mismatch: a verdict whose own accuracy test had failed.
- A multiplier near ±1 is marginal (a tongue's edge, or a zero exponent of a symmetry):
  rounding splits a double root there by the square root of Φ's error (its resolution, at
  least the arithmetic's 1e-34, times the size of Φ: ~1e-17), so within 100 times that
  (and at least MARGINAL, 1e-15) nothing can be told (`marginal_within`). Until issue 41 the
  bound was a fixed 1e-13: 10⁴ times the split, it hid a boundary's last decades from the
  walk toward a limit (mechbook.verify.boundary_limit).
- Otherwise unstable iff some |μ| > 1 + ON_CIRCLE(Φ's absolute error, the resolution times
  the size of Φ). Off the edges the multipliers
  of a stable conservative system sit on the circle to the arithmetic's precision, and an
  unstable one's leave it like the square root of the distance to the boundary: 1e-8 from
  a tongue's edge they are ~1e-5 off it, far above the resolution.

heyoka is optional (`pip install 'mechbook[taylor]'`); without it Floquet multipliers are
unsupported, with that reason.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import mpmath
import numpy as np
import sympy as sp

from mechbook.core.backends import FEW_CALLS_BACKEND
from mechbook.core.compile import compile_exprs
from mechbook.core.numeval import NotNumeric, evaluate_mp
from mechbook.engine import periodic
from mechbook.engine.linear import LinearSystem
from mechbook.errors import MechbookError, UnsupportedError
from mechbook.numerics.hyexpr import Translator, solve_spd

DPS = 40  # mpmath digits for the period, the parameters and the eigenvalues of Φ
RESOLVED = 1e-20  # the largest Liouville mismatch at which a verdict is given
MARGINAL = 1e-15  # at least this close to ±1 a multiplier is marginal (no verdict)
PRECISION = 1e-34  # 113-bit arithmetic's relative rounding


def marginal_within(resolution: float, scale: float) -> float:
    """How near ±1 a multiplier is marginal: 100 times the split rounding can give a
    double root there, the square root of Φ's error (its measured resolution, at least the
    arithmetic's, times the size of Φ's entries), and at least MARGINAL."""
    return max(MARGINAL, 100 * (max(resolution, PRECISION) * max(scale, 1.0)) ** 0.5)


SHORTEST = 1e-9  # T·rate below this: Φ = I + O(T·rate) puts every multiplier within 1e-9
# of 1, where the integration's rounding decides its side: nothing can be told (an error)
LONGEST = 1e5  # T·√rate above this: one period holds more oscillations of the fastest motion
# than a monodromy in 113-bit arithmetic integrates in a check's time (a Kapitza pivot
# driven at amplitude 1e90 looped in heyoka until the time limit): an error, at once
ARITHMETIC = "Taylor integration (heyoka) in 113-bit arithmetic"
RATE_MARGIN = 2.0  # the double-precision rate passes a guard only this far inside its limit


def on_circle(resolution: float, scale: float = 1.0) -> float:
    """How far |μ| may exceed 1 and still count as on the circle: a thousand times Φ's
    absolute error (its resolution times the size of its entries), and at least 1e-24."""
    return max(1e-24, 1e3 * resolution * max(scale, 1.0))


def digits_for(scale: float, n: int) -> int:
    """Decimal digits with which det Φ, Φ⁻¹ and Φ's eigenvalues lose nothing of Φ's own
    accuracy: an n×n determinant of entries up to `scale` that is ~1 cancels about
    n·log10(scale) digits."""
    return DPS + 5 + int(n * max(0.0, mpmath.log10(max(scale, 1.0))))


@dataclass
class Multipliers:
    """The monodromy's eigenvalues at one parameter point, and how well Φ is known."""

    values: list  # mpmath complex numbers
    period: object  # mpf
    resolution: float  # |det Φ / exp(−∫tr M⁻¹C) − 1| / κ(Φ): Φ's relative error
    seconds: float = 0.0
    scale: float = 1.0  # the largest entry of Φ in magnitude
    mismatch: float = 0.0  # |det Φ / exp(−∫tr M⁻¹C) − 1| itself
    condition: float = 1.0  # κ(Φ) = ‖Φ‖‖Φ⁻¹‖ (infinity norm), the determinant's condition

    def exponents(self) -> list:
        """Characteristic exponents log(μ)/T (real parts: growth rates)."""
        with mpmath.workdps(DPS):
            return [mpmath.log(m) / self.period for m in self.values]

    def largest(self) -> float:
        return float(max(abs(m) for m in self.values))

    def verdict(self) -> str:
        """'stable', 'unstable' or 'marginal' (see the module's docstring)."""
        if not self.resolution <= RESOLVED:
            raise UnsupportedError(
                f"Floquet multipliers not resolved: det Φ differs from Liouville's "
                f"exp(−∫tr M⁻¹C dt) by a relative {self.mismatch:.2g}, which over the "
                f"determinant's condition κ(Φ) = {self.condition:.2g} leaves Φ known to "
                f"{self.resolution:.2g} (needs {RESOLVED:g}; the largest |μ| is "
                f"{self.largest():.3g})")
        with mpmath.workdps(DPS):
            near = marginal_within(self.resolution, self.scale)
            edge = [m for m in self.values if min(abs(m - 1), abs(m + 1)) < near]
            off = [m for m in self.values if m not in edge]
            if any(abs(m) - 1 > on_circle(self.resolution, self.scale) for m in off):
                return "unstable"
            return "marginal" if edge else "stable"


@dataclass
class Floquet:
    """The monodromy of one time-periodic linear system, compiled once (heyoka, 113 bits)
    and evaluated at any parameter point."""

    lin: LinearSystem
    period: sp.Expr
    symbols: list = field(default_factory=list)  # the parameters, in heyoka's par[] order
    _ta: object = field(default=None, repr=False)
    compile_seconds: float = 0.0
    _at_zero: list | None = field(default=None, repr=False)  # M, K, C at t = 0
    traceless: bool = False  # tr M⁻¹C ≡ 0 (set by `taylor`): det Φ = 1 exactly
    _checked: tuple | None = field(default=None, repr=False)  # the last point's period
    _quick: object = field(default=None, repr=False)  # M, K, C at t = 0 compiled (double)

    @classmethod
    def of(cls, lin: LinearSystem, period: sp.Expr | None = None) -> Floquet:
        """Floquet's form of `lin`; the period detected from the coefficients unless given
        (a given one is verified at each point)."""
        if not periodic.time_dependent(lin):
            raise UnsupportedError("Floquet multipliers of a linearization whose "
                                   "coefficients do not depend on t (use its exponents)")
        return cls(lin, period if period is not None else periodic.period(lin))

    def __post_init__(self):
        t = self.lin.dyn.sys.t
        used = set().union(*(A.free_symbols for A in (self.lin.M, self.lin.C, self.lin.K)),
                           self.period.free_symbols)
        self.symbols = sorted(used - {t}, key=lambda s: s.name)
        self.declared = False

    # ---- building the integrator --------------------------------------------------------
    def _integrator(self):
        if self._ta is None:
            start = time.perf_counter()
            self._ta = self.taylor(_QuadTranslator, "real128")
            self.compile_seconds = time.perf_counter() - start
        return self._ta

    def taylor(self, translator: type, fp: str, **options):
        """heyoka's integrator of X' = A(t)X and Liouville's ∫tr M⁻¹C dt, in the floating
        type `fp` ("real128"; "float64" for the double-precision screen,
        mechbook.numerics.floquet_screen) with constants from `translator`; `options` go to
        heyoka (`tol`). Parameters in `self.symbols` order, the state column by column."""
        try:
            import heyoka as hy
        except ImportError:
            raise UnsupportedError("Floquet multipliers need heyoka's Taylor integrator "
                                   "(pip install 'mechbook[taylor]')") from None
        lin = self.lin
        n = lin.M.rows
        if any(not sp.simplify(lin.M[i, j] - lin.M[j, i]) == 0
               for i in range(n) for j in range(i + 1, n)):
            raise UnsupportedError("Floquet multipliers with a mass matrix that is not "
                                   "symmetric")
        dtype = hy.real128 if fp == "real128" else np.float64
        symbols = {lin.dyn.sys.t: hy.time}
        symbols.update({s: hy.par[i] for i, s in enumerate(self.symbols)})
        tr = translator(symbols)

        def entry(e):
            return None if e == 0 else tr(e)

        M = [[entry(lin.M[i, j]) for j in range(n)] for i in range(n)]
        C = [[entry(lin.C[i, j]) for j in range(n)] for i in range(n)]
        K = [[entry(lin.K[i, j]) for j in range(n)] for i in range(n)]
        names = [f"x{i}_{j}" for j in range(2 * n) for i in range(2 * n)]
        X = list(hy.make_vars(*names, "liouville"))
        s = X.pop()
        zero = hy.expression(dtype(0))
        ode = []
        for j in range(2 * n):  # column j of X: positions Q, velocities V
            Q, V = X[2 * n * j: 2 * n * j + n], X[2 * n * j + n: 2 * n * (j + 1)]
            rhs = [_dot([(K[i][k], Q[k]) for k in range(n)] + [(C[i][k], V[k])
                                                                 for k in range(n)])
                   for i in range(n)]
            acc = solve_spd(M, [None if r is None else -r for r in rhs], _is_none)
            ode += [(Q[i], V[i]) for i in range(n)]
            ode += [(V[i], zero if acc[i] is None else acc[i]) for i in range(n)]
        # Liouville: d/dt log det X = tr A = −tr(M⁻¹C); s carries ∫ tr(M⁻¹C) dt
        cols = [solve_spd(M, [C[i][j] for i in range(n)], _is_none) for j in range(n)]
        diag = [cols[j][j] for j in range(n) if cols[j][j] is not None]
        self.traceless = not diag  # tr M⁻¹C ≡ 0: det Φ = 1 exactly, s stays 0
        ode.append((s, hy.sum(diag) if diag else zero))
        state = np.zeros(len(ode), dtype=dtype)
        pars = np.zeros(len(self.symbols), dtype=dtype)
        try:
            return hy.taylor_adaptive(ode, state, pars=pars, fp_type=dtype, **options)
        except (ValueError, RuntimeError, TypeError) as exc:
            raise UnsupportedError(f"Floquet multipliers: heyoka refused the system ({exc})"
                                   ) from None

    # ---- one parameter point ------------------------------------------------------------
    def period_at(self, values: dict):
        with mpmath.workdps(DPS):
            try:
                T = evaluate_mp(self.period, values, DPS)
            except (NotNumeric, ZeroDivisionError, ValueError, TypeError) as exc:
                raise MechbookError(f"the period {self.period} has no value here ({exc})"
                                    ) from None
            if mpmath.im(T) != 0 and abs(mpmath.im(T)) > 1e-30 * abs(T):
                raise MechbookError(f"the period {self.period} is not real here")
            T = abs(mpmath.re(T))
            if not mpmath.isfinite(T) or T == 0:
                raise MechbookError(f"the period {self.period} is not a finite positive "
                                    "number here")
            quick = self._rate_in_double(values)
            if quick is not None and float(T) * quick > RATE_MARGIN * SHORTEST and \
                    RATE_MARGIN * float(T) * math.sqrt(quick) < LONGEST:
                return T  # both guards pass, far from their limits
            rate = self._rate(values)
            if T * rate < SHORTEST:
                raise MechbookError(
                    f"the period {self.period} = {mpmath.nstr(T, 3)} is too short to be "
                    f"resolved here: over it the state moves by about "
                    f"{mpmath.nstr(T * rate, 2)} of itself (the system's rates are "
                    f"~{mpmath.nstr(rate, 3)} per unit time), so every multiplier is 1 to "
                    f"within the integration's resolution; give the coefficients' period")
            if T * mpmath.sqrt(rate) > LONGEST:
                raise MechbookError(
                    f"the period {self.period} = {mpmath.nstr(T, 3)} holds about "
                    f"{mpmath.nstr(T * mpmath.sqrt(rate) / (2 * mpmath.pi), 2)} oscillations "
                    f"of the system's fastest motion (rates ~{mpmath.nstr(rate, 3)}): more "
                    f"than one monodromy in {ARITHMETIC} can integrate; check the period "
                    f"and the size of the coefficients")
            return T

    def _rate(self, values: dict) -> mpmath.mpf:
        """The largest rate of the linearized motion at t = 0 (1 + the largest entry of
        M⁻¹K and M⁻¹C there): a period T with T·rate below SHORTEST leaves Φ = I to the
        integration's resolution, and its multipliers tell nothing."""
        if self._at_zero is None:  # M, K, C at t = 0, once (SymPy's LUsolve at every
            t = self.lin.dyn.sys.t  # point was 40 % of a driven problem's check)
            self._at_zero = [A.xreplace({t: 0}) for A in (self.lin.M, self.lin.K, self.lin.C)]
        at = {s: values[s] for s in self.symbols if s in values}
        try:
            with mpmath.workdps(30):
                M, K, C = (mpmath.matrix([[evaluate_mp(x, at, 30) for x in A.row(i)]
                                          for i in range(A.rows)]) for A in self._at_zero)
                cols = [mpmath.lu_solve(M, X.column(j)) for X in (K, C)
                        for j in range(X.cols)]  # M⁻¹K and M⁻¹C, column by column
                big = max([abs(complex(x)) for R in cols for x in R] + [0.0])
        except (NotNumeric, TypeError, ValueError, ZeroDivisionError, KeyError):
            return mpmath.mpf(1)
        return mpmath.mpf(1) + (mpmath.mpf(big) if math.isfinite(big) else 0)

    def _rate_in_double(self, values: dict) -> float | None:
        """`_rate` in double precision (M, K, C at t = 0 compiled once, M solved by LAPACK):
        enough to pass both guards where T·rate and T·√rate lie RATE_MARGIN inside their
        limits (the point's check then costs microseconds); None where it is not to be
        trusted (a value missing or not finite, M far from invertible: κ(M) > 1e8), and the
        30-digit `_rate` decides."""
        if self._quick is None:
            t = self.lin.dyn.sys.t
            mats = [A.xreplace({t: 0}) for A in (self.lin.M, self.lin.K, self.lin.C)]
            try:
                f, _ = compile_exprs(self.symbols, [e for A in mats for e in A],
                                     FEW_CALLS_BACKEND)
            except (UnsupportedError, TypeError, ValueError):
                f = False
            self._quick = f
        if self._quick is False or any(s not in values for s in self.symbols):
            return None
        n = self.lin.M.rows
        try:
            x = np.array([float(values[s]) for s in self.symbols], dtype=float)
            v = np.asarray(self._quick(x), dtype=float).ravel()
        except (TypeError, ValueError, OverflowError, ZeroDivisionError):
            return None
        if v.size != 3 * n * n or not np.all(np.isfinite(v)):
            return None
        M, K, C = (v[k * n * n:(k + 1) * n * n].reshape(n, n) for k in range(3))
        if not np.linalg.cond(M) <= 1e8:
            return None
        big = float(np.max(np.abs(np.linalg.solve(M, np.hstack([K, C])))))
        return 1.0 + big if math.isfinite(big) else None

    def checked_period(self, values: dict):
        """The period at `values` (`period_at`), a declared one verified there, and every
        parameter given: what any monodromy needs first, at 113 bits or in double."""
        key = tuple(values.get(s) for s in self.symbols)
        if self._checked is not None and self._checked[0] == key:
            return self._checked[1]  # the screen asked first, then the 113-bit monodromy
        T = self.period_at(values)
        if self.declared and not periodic.declared_period_holds(self.lin, self.period, values):
            raise UnsupportedError(f"the declared period {self.period} is not a period of "
                                   "the coefficients here")
        for s in self.symbols:
            if s not in values:
                raise MechbookError(f"the linearized system keeps {s} without a value")
        self._checked = (key, T)
        return T

    def monodromy(self, values: dict) -> tuple[mpmath.matrix, object, object]:
        """(Φ, its entries exact as integrated; T; the Liouville exponent ∫tr M⁻¹C dt)."""
        import heyoka as hy

        ta = self._integrator()
        n2 = 2 * self.lin.M.rows
        T = self.checked_period(values)
        with mpmath.workdps(DPS):
            pars = [hy.real128(mpmath.nstr(_mp(values[s]), 36)) for s in self.symbols]
            ta.pars[:] = np.array(pars, dtype=hy.real128)
            state = np.zeros(n2 * n2 + 1, dtype=hy.real128)
            for j in range(n2):
                state[n2 * j + j] = hy.real128(1)
            ta.time = hy.real128(0)
            ta.state[:] = state
            out = ta.propagate_until(hy.real128(mpmath.nstr(T, 36)))
            if out[0] != hy.taylor_outcome.time_limit:
                raise MechbookError(f"Floquet: the integration over one period stopped "
                                    f"({out[0]})")
        with mpmath.workdps(60):  # a real128 printed to 36 digits, read back exactly
            y = [mpmath.mpf(str(v)) for v in ta.state]
            phi = mpmath.matrix(n2, n2)
            for j in range(n2):
                for i in range(n2):
                    phi[i, j] = y[n2 * j + i]
            return phi, T, y[-1]

    def multipliers(self, values: dict) -> Multipliers:
        start = time.perf_counter()
        phi, T, exponent = self.monodromy(values)
        scale = float(max(abs(x) for x in phi))
        with mpmath.workdps(digits_for(scale, phi.rows)):
            liouville = mpmath.exp(-exponent)
            det = mpmath.det(phi)
            mismatch = abs(det / liouville - 1) if liouville != 0 else mpmath.inf
            try:
                condition = mpmath.mnorm(phi, 1) * mpmath.mnorm(mpmath.inverse(phi), 1)
            except ZeroDivisionError:
                condition = mpmath.inf
            mu = mpmath.eig(phi, left=False, right=False)
        resolution = float(mismatch / condition) if mpmath.isfinite(condition) else \
            float("inf")
        with mpmath.workdps(DPS):
            mu = [+m for m in mu]
        return Multipliers(mu, T, resolution, time.perf_counter() - start, scale,
                           float(mismatch), float(condition))

    def stability(self, values: dict) -> str:
        """'stable', 'unstable' or 'marginal' at `values` (see Multipliers.verdict)."""
        return self.multipliers(values).verdict()


def _mp(x):
    if isinstance(x, sp.Basic):
        return mpmath.mpf(sp.Float(x, DPS)._mpf_) if x.is_real is not False else \
            mpmath.mpf(sp.Float(sp.re(x), DPS)._mpf_)
    return mpmath.mpf(x)


def _is_none(e) -> bool:
    return e is None


def _dot(pairs: list) -> object | None:
    terms = [a * b for a, b in pairs if a is not None]
    if not terms:
        return None
    out = terms[0]
    for x in terms[1:]:
        out = out + x
    return out


class _QuadTranslator(Translator):
    """SymPy → heyoka with every constant in 113-bit precision (the base translator's are
    doubles: a coefficient 1/3 would be wrong by 1e-17)."""

    def number(self, x) -> object:
        if isinstance(x, sp.Basic) and x.is_Rational:
            return self.hy.expression(self.hy.real128(int(x.p))) / \
                self.hy.expression(self.hy.real128(int(x.q))) if x.q != 1 else \
                self.hy.expression(self.hy.real128(int(x.p)))
        return self.hy.expression(self.hy.real128(str(sp.Float(x, 36))))

    def _walk(self, e: sp.Basic):
        if e is sp.pi:
            return self.number(sp.pi.evalf(40))
        if e is sp.E:
            return self.number(sp.E.evalf(40))
        return super()._walk(e)
