"""Floquet verdicts in double precision where they are certain, the 113-bit computation
everywhere else (issue 42).

A driven problem's check takes hundreds of verdicts near a stability boundary, and each
monodromy in 113-bit arithmetic (mechbook.numerics.floquet) costs milliseconds; in double
precision it costs microseconds. The screen integrates Φ = X(T) in double twice, at
heyoka's default tolerance (~2e-16) and at LOOSE_TOL, and once more with each parameter
and the period moved by NUDGE ulps in turn (the doubles of the 30-digit values are half
an ulp off them), and bounds Φ's error by the larger of SAFETY times the two
tolerances' difference and the summed moves (and at least SAFETY ε times Φ's size): a
conservative estimate, a hundred times the error of an integration ten thousand times
looser than the one used, or the move of every parameter sixteen times more off than it
is, all at once (Φ's response to such moves is linear).
It gives a verdict only where every multiplier consistent with that bound gives the same
verdict as the 113-bit computation, by margins far above that computation's own
thresholds; everywhere else it returns None and the 113-bit computation decides:

- **unstable**, any size: the multipliers lie in Bauer–Fike discs about Φ's eigenvalues,
  radius κ(V)·(the error bound); a connected group of discs lying wholly beyond
  |μ| = 1 + NEAR holds a multiplier there (for one degree of freedom the 2×2 formula
  μ = (tr ± √(tr² − 4 det))/2 is used instead, with det from Liouville's formula: sharp
  near a double root, where κ(V) is not). The 113-bit verdict there is unstable: it calls
  a multiplier marginal only within marginal_within(resolution, scale) ≤ 100·√(1e-20 ·
  MAX_SCALE) ≈ 3e-7 < NEAR of ±1 (any resolution it accepts), and on the circle only
  within on_circle ≤ 1e-14 of it.
- **stable**, one degree of freedom: the trace's bound keeps tr² < 4 det by
  MARGIN, so the multipliers are a complex pair, |μ|² = det Φ exactly, and det Φ is 1
  exactly where tr M⁻¹C ≡ 0 (no damping, no velocity terms) or below 1 − MARGIN where the
  Liouville exponent says so; the pair stays NEAR clear of ±1. The 113-bit verdict there
  is stable: its |μ| − 1 is half its determinant's mismatch, below its on_circle where
  Φ's entries are at most MAX_STABLE_SCALE (κ(Φ) ≤ 4·scale² for a 2×2 of determinant 1).
- **stable**, two or more degrees of freedom, only where the system has the structure
  that keeps a multiplier on the circle (without it one on the circle cannot be told from
  one 1e-20 off it in double precision: never decided): M q̈ + C q̇ + K q = 0 is Lagrange's
  equation of a quadratic Lagrangian ½q̇ᵀMq̇ + qᵀNq̇ − ½qᵀK′q exactly where M is
  symmetric, A = C − Ṁ antisymmetric and K − Kᵀ = Ȧ (`hamiltonian`, decided once by SymPy),
  and then Φ is similar, by the periodic change to (q, p), to a symplectic matrix: with μ
  its multipliers hold 1/μ̄. Each Bauer–Fike disc holds exactly one multiplier where the
  discs are disjoint (they move continuously from Φ's eigenvalues as the error is turned
  on); where the disc about λ, and its reflection in the circle (within r′ of λ), meet no
  other disc, the multiplier in it is its own reflection: on the circle. So: stable where
  every disc is so isolated and NEAR clear of ±1, with κ(V)·n ≤ KAPPA_N and Φ's entries at
  most MAX_STABLE_SCALE. The 113-bit verdict there is stable: its multipliers lie within
  κ·n·(resolution·scale) ≤ KAPPA_N·resolution·scale of the circle (Bauer–Fike about the
  exact ones), below its on_circle (1e3 times that), and more than NEAR from ±1.

The equations' constants are doubles here (a 1/3 is rounded, as a parameter is); where a
constant multiplies a parameter its rounding is one of the moves measured, and where it
multiplies none only the bound's floor (SAFETY ε) covers it. The screen assumes what the
113-bit path shows wherever it has been measured: that it
resolves Φ (Liouville's mismatch over κ(Φ) below 1e-20; 4e-36 to 2e-31 in the tests) at
points where double precision resolves Φ's entries to its bound and they are at most
MAX_SCALE. Where it would not, the 113-bit computation is no more than an unsupported
point, which a screened verdict then replaces: the only assumption the screen makes.
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from mechbook.errors import MechbookError
from mechbook.numerics.floquet import Floquet
from mechbook.numerics.hyexpr import Translator

LOOSE_TOL = 1e-12  # the second integration's tolerance: their difference bounds Φ's error
SAFETY = 100.0  # the bound: this many times that difference (and SAFETY·ε·‖Φ‖ at least)
EPS = float(np.finfo(float).eps)
NEAR = 1e-6  # a decided multiplier stays this clear of ±1 and of the unit circle
MARGIN = 1e-11  # 4 det − tr² beyond its bound: the pair is complex in both arithmetics
MAX_SCALE = 1e3  # Φ's largest entry above this: not screened (its growth costs digits)
MAX_STABLE_SCALE = 500.0  # a stable verdict: the 113-bit |μ| − 1 stays within its bound
MAX_BOUND = 1e-6  # an error bound above this: not screened (the integration is poor)
WORTH_IT = 4  # 2 or more degrees of freedom: screened once this many were unstable
NUDGE = 8  # ulps each parameter (and the period) is moved by to measure Φ's sensitivity
KAPPA_N = 250.0  # a stable verdict with 2+ degrees of freedom: κ(V)·n at most this


class Screen:
    """The double-precision monodromy of one Floquet system, and the verdicts it certifies.
    Built once per linear system; `verdict(values)` is 'stable', 'unstable' or None."""

    def __init__(self, floquet: Floquet):
        self.floquet = floquet
        self.n2 = 2 * floquet.lin.M.rows
        self._tight = self._loose = None
        self.broken = False  # heyoka refused the double system: every point escalates
        self.decided = 0
        self.escalated = 0
        self.unstable_seen = 0  # 113-bit verdicts 'unstable' (`note`)
        self._hamiltonian: bool | None = None  # Φ similar to a symplectic matrix

    def _build(self) -> bool:
        if self._tight is None and not self.broken:
            try:
                self._tight = self.floquet.taylor(Translator, "float64")
                self._loose = self.floquet.taylor(Translator, "float64", tol=LOOSE_TOL)
            except MechbookError:
                self.broken = True
        return not self.broken

    def _run(self, ta, pars: np.ndarray, T: float) -> np.ndarray | None:
        import heyoka as hy

        ta.pars[:] = pars
        ta.time = 0.0
        state = np.zeros(self.n2 * self.n2 + 1)
        state[: self.n2 * self.n2: self.n2 + 1] = 1.0
        ta.state[:] = state
        out = ta.propagate_until(T)
        if out[0] != hy.taylor_outcome.time_limit or not np.all(np.isfinite(ta.state)):
            return None
        return np.array(ta.state)

    def verdict(self, values: dict) -> str | None:
        """'stable' or 'unstable' where double precision certifies the 113-bit verdict
        (module docstring), None where it does not (the caller computes it in 113 bits).
        Where the screen is built, the period's checks (Floquet.checked_period) run first
        and raise as they do for the 113-bit monodromy; where it is not, nothing runs.
        Example: Mathieu's equation at q = 0.3: α = 0.4 (inside the first stable band)
        'stable', α = 1 (in the first tongue) 'unstable', α a relative 1e-13 from an edge
        None."""
        flo = self.floquet
        useful = self.n2 == 2 or self.unstable_seen >= WORTH_IT or self.symplectic
        if not (useful and self._build()):  # the 113-bit path raises what it raises
            self.escalated += 1
            return None
        T = flo.checked_period(values)  # the same checks the 113-bit monodromy makes
        got = self._decide(values, T)
        if got is None:
            self.escalated += 1
        else:
            self.decided += 1
        return got

    def _rounding(self, pars: np.ndarray, T: float, a: np.ndarray) -> tuple | None:
        """How far Φ and Liouville's exponent move when each parameter, and the period, is
        moved by NUDGE ulps in turn (summed): more than the rounding of the 30-digit values
        to doubles (half an ulp each) can move them, so the bound covers the Φ of the values
        the 113-bit computation integrates, not only of their doubles. None where a run
        fails."""
        dphi = ds = 0.0
        for i in range(len(pars) + 1):
            p, t = pars.copy(), T
            if i < len(pars):
                p[i] *= 1 + NUDGE * EPS
            else:
                t *= 1 + NUDGE * EPS
            c = self._run(self._tight, p, t)
            if c is None:
                return None
            dphi += float(np.max(np.abs(c[:-1] - a[:-1])))
            ds += abs(float(c[-1] - a[-1]))
        return dphi, ds

    @property
    def symplectic(self) -> bool:
        """Whether Φ is similar to a symplectic matrix (`hamiltonian`, decided once)."""
        if self._hamiltonian is None:
            self._hamiltonian = self.n2 > 2 and hamiltonian(self.floquet.lin)
        return self._hamiltonian

    def note(self, verdict: str) -> None:
        """A 113-bit verdict taken where the screen gave none: with two or more degrees of
        freedom and no symplectic structure the screen can only tell 'unstable', so it is
        built (two compiles) only once WORTH_IT such verdicts have been met."""
        if verdict == "unstable":
            self.unstable_seen += 1

    def _decide(self, values: dict, T) -> str | None:
        flo = self.floquet
        try:
            pars = np.array([float(values[s]) for s in flo.symbols], dtype=float)
            Tf = float(T)
        except (TypeError, ValueError, KeyError, OverflowError):
            return None
        if not (np.all(np.isfinite(pars)) and math.isfinite(Tf)):
            return None
        a, b = self._run(self._tight, pars, Tf), self._run(self._loose, pars, Tf)
        if a is None or b is None:
            return None
        n2 = self.n2
        phi = a[:-1].reshape(n2, n2).T  # the state is Φ column by column
        scale = float(np.max(np.abs(phi)))
        if not scale <= MAX_SCALE:
            return None
        # every verdict below is monotone in the bounds (a larger bound only widens the
        # intervals and discs it is decided on), so where the bounds without the parameters'
        # moves already decide nothing the full ones cannot either: escalated without the
        # len(pars) + 1 runs that measure the moves (most points near a boundary)
        if self._judge(phi, a, b, scale, (0.0, 0.0)) is None:
            return None
        moved = self._rounding(pars, Tf, a)
        if moved is None:
            return None
        return self._judge(phi, a, b, scale, moved)

    def _judge(self, phi: np.ndarray, a: np.ndarray, b: np.ndarray, scale: float,
               moved: tuple[float, float]) -> str | None:
        """The verdict from the tight and loose runs `a`, `b` (Φ = `phi`, its largest entry
        `scale`) and the moves of Φ and of Liouville's exponent under the parameters'
        nudges (`moved`): 'stable', 'unstable' or None (module docstring)."""
        flo = self.floquet
        bound = max(SAFETY * float(np.max(np.abs(a[:-1] - b[:-1]))), moved[0],
                    SAFETY * EPS * max(scale, 1.0))
        if bound > MAX_BOUND:
            return None
        s = float(a[-1])  # ∫ tr M⁻¹C dt: det Φ = exp(−s)
        ds = max(SAFETY * abs(s - float(b[-1])), moved[1], SAFETY * EPS * (1.0 + abs(s)))
        if flo.traceless:
            det_lo = det_hi = 1.0
        elif abs(s) + ds > 700:  # det Φ beyond a double's range
            return None
        else:
            det_lo, det_hi = math.exp(-s - ds), math.exp(-s + ds)
        if self.n2 == 2:
            return _two_by_two(phi, bound, det_lo, det_hi, flo.traceless, scale)
        got = _unstable_by_discs(phi, bound)
        if got is None and self.symplectic and scale <= MAX_STABLE_SCALE:
            return _stable_by_symmetry(phi, bound)
        return got


def hamiltonian(lin) -> bool:
    """Whether M q̈ + C q̇ + K q = 0 is Lagrange's equation of a quadratic Lagrangian
    ½q̇ᵀMq̇ + qᵀNq̇ − ½qᵀK′q (M, K′ symmetric): M symmetric, A = C − Ṁ antisymmetric and
    K − Kᵀ = Ȧ (then N = −A/2, K′ = K − Ȧ/2), each entry's difference simplified to 0
    by SymPy. The monodromy of such a system is similar to a symplectic one (its flow in
    q and p = Mq̇ + Nᵀq, the change periodic), so its multipliers come with 1/μ̄. False
    where SymPy does not reduce a difference to 0 (the screen then decides no stability).
    Example: m q̈ + k(t) q = 0 is; m q̈ + c q̇ + k q = 0 with c ≠ 0 is not."""
    t = lin.dyn.sys.t
    M, C, K = lin.M, lin.C, lin.K
    A = C - M.diff(t)
    n = M.rows
    try:
        return all(sp.simplify(e) == 0 for i in range(n) for j in range(n) for e in
                   (M[i, j] - M[j, i], A[i, j] + A[j, i],
                    K[i, j] - K[j, i] - sp.diff(A[i, j], t)))
    except (TypeError, ValueError, NotImplementedError, RecursionError):
        return False


def _discs(phi: np.ndarray, bound: float) -> tuple[np.ndarray, float, float] | None:
    """Φ's eigenvalues, the Bauer–Fike radius about each that holds the exact Φ's
    (‖ΔΦ‖₂ ≤ n·(entrywise bound), plus the eigensolver's own backward error, times κ(V)),
    and κ(V); None where the eigenvectors are not computed or κ is not finite."""
    n = phi.shape[0]
    try:
        lam, V = np.linalg.eig(phi)
        kappa = float(np.linalg.cond(V))
    except np.linalg.LinAlgError:
        return None
    if not math.isfinite(kappa):
        return None
    return lam, kappa * (n * bound + 100 * n * EPS * float(np.linalg.norm(phi, 2))), kappa


def _stable_by_symmetry(phi: np.ndarray, bound: float) -> str | None:
    """Two or more degrees of freedom, Φ similar to a symplectic matrix: 'stable' where
    every Bauer–Fike disc (radius r about λ) and its reflection in the unit circle (within
    r′ = r/((|λ| − r)|λ|) + ||λ|² − 1|/|λ| of λ) meet no other disc and stay NEAR clear of
    ±1, with κ(V)·n ≤ KAPPA_N (module docstring); else None."""
    n = phi.shape[0]
    discs = _discs(phi, bound)
    if discs is None or discs[2] * n > KAPPA_N:
        return None
    lam, r, _ = discs
    for k in range(n):
        size = abs(lam[k])
        if size <= 2 * r:
            return None
        reach = max(r, r / ((size - r) * size) + abs(size * size - 1) / size)
        if min(abs(lam[k] - 1), abs(lam[k] + 1)) - reach <= NEAR:
            return None
        if any(abs(lam[k] - lam[j]) <= reach + r for j in range(n) if j != k):
            return None
    return "stable"


def _two_by_two(phi: np.ndarray, bound: float, det_lo: float, det_hi: float,
                exact_det: bool, scale: float) -> str | None:
    """One degree of freedom: the multipliers from the trace's interval and Liouville's
    determinant (module docstring)."""
    tr = float(phi[0, 0] + phi[1, 1])
    dtr = 2 * bound + 4 * EPS * abs(tr)
    lo, hi = max(0.0, abs(tr) - dtr), abs(tr) + dtr  # |tr| of the exact Φ lies in [lo, hi]
    if lo * lo > 4 * det_hi + MARGIN:  # a real pair: the larger is (|tr| + √(tr² − 4d))/2
        big = (lo + math.sqrt(lo * lo - 4 * det_hi)) / 2
        return "unstable" if big > 1 + NEAR else None
    if hi * hi < 4 * det_lo - MARGIN:  # a complex pair, |μ|² = det Φ
        if det_lo > (1 + NEAR) ** 2:
            return "unstable"
        inside = exact_det or det_hi < 1 - MARGIN
        clear = det_lo + 1 - hi > NEAR * NEAR  # |μ ∓ 1|² = det ∓ tr + 1
        if inside and clear and scale <= MAX_STABLE_SCALE:
            return "stable"
    return None


def _unstable_by_discs(phi: np.ndarray, bound: float) -> str | None:
    """Two or more degrees of freedom: 'unstable' where a connected group of Bauer–Fike
    discs lies wholly beyond |μ| = 1 + NEAR (it holds as many multipliers as eigenvalues
    of Φ), else None."""
    n = phi.shape[0]
    discs = _discs(phi, bound)
    if discs is None:
        return None
    lam, r, _ = discs
    groups = []  # connected components of the union of discs
    for k in range(n):
        joined = [g for g in groups if any(abs(lam[k] - lam[j]) <= 2 * r for j in g)]
        merged = {k}.union(*joined) if joined else {k}
        groups = [g for g in groups if g not in joined] + [merged]
    for g in groups:
        if all(abs(lam[j]) - r > 1 + NEAR for j in g):
            return "unstable"
    return None
