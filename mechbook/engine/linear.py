"""Small oscillations: the linear system about an equilibrium or a steady motion.

The equations of motion E(q, q̇, q̈, t) = 0 are expanded (mechbook.engine.equilibria) to first
order about a point q* with
q̇ = q̈ = 0, counting parameters declared `small` (a driving amplitude, say) as first-order too:
    M·δq̈ + C·δq̇ + K·δq = F(t),    δq = q − q*.
C holds gyroscopic (antisymmetric) and damping (symmetric) terms. With C = 0 the normal
frequencies are the roots of det(K − ω²M) = 0 and numerically `scipy.linalg.eigh(K, M)`; with
gyroscopic terms they are the roots of det(K − ω²M + iωC) = 0 and numerically the imaginary
parts of the state-space eigenvalues.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import scipy.linalg
import symengine as se
import sympy as sp
from sympy.matrices.utilities import dotprodsimp

from mechbook.core.compile import compile_exprs
from mechbook.core.numeval import (
    NotNumeric,
    evaluate,
    evaluate_mp,
    evaluate_mp_at,
    is_zero,
    mp_values,
)
from mechbook.core.secalc import to_sympy
from mechbook.core.timeout import Timeout, time_limit, try_simplify
from mechbook.engine.lagrange import Dynamics
from mechbook.errors import MechbookError, UnsupportedError

ZERO_TOL = 1e-9  # |ω²| below this (relative) is beyond what double precision decides:
# such a value is decided again at 50 digits (numeric_frequencies) or 40 (numeric_stability),
# never set to zero here
ZERO_CLUSTER = 1e-6  # |p| below this (relative) is a zero exponent split by rounding
MARGIN_DIGITS = 12  # at dps digits, |ω²| below 10^(MARGIN_DIGITS − dps) of the largest is 0


def secular_determinant(A: sp.Matrix) -> sp.Expr:
    """det A as an expanded polynomial in its entries' symbols: Berkowitz's division-free
    algorithm (no denominators that vanish where the polynomial does not, as SymEngine's
    det leaves; SymPy's Bareiss with its intermediate simplification took 25 s for six
    coupled pendulums, Lim 2055, this 0.1 s), expanded by SymEngine: the proof of a book
    frequency substitutes ω² into it (mechbook.verify.quantities.oscillations)."""
    with dotprodsimp(False):  # SymPy's intermediate cancel: 96 s on Symon 12-23's 4×4
        det = A.det(method="berkowitz")
    try:
        return to_sympy(se.expand(se.sympify(det)), A.free_symbols)
    except Exception:  # noqa: BLE001 - a function SymEngine does not know: SymPy's expand
        return sp.expand(det)


def zero_below(dps: int) -> float:
    """The relative size under which an ω² computed with `dps` digits is zero: what that
    arithmetic cannot tell from zero, with MARGIN_DIGITS to spare (1e-38 at 50 digits)."""
    return 10.0 ** (MARGIN_DIGITS - dps)


@dataclass
class LinearSystem:
    """M·δq̈ + C·δq̇ + K·δq = F(t) about `point`."""

    dyn: Dynamics
    point: dict
    M: sp.Matrix
    C: sp.Matrix
    K: sp.Matrix
    F: sp.Matrix
    velocity: dict = field(default_factory=dict)  # uniform rates of a steady motion kept
    # in full (mechbook.engine.equilibria.Equilibria.linearize); empty about a rest point
    # On a constraint manifold (multiplier constraints): M, C, K, F are over the independent
    # coordinates `coords` (a subset of the system's), and δq = embedding·δs gives every
    # coordinate's displacement (mechbook.engine.constrained); None otherwise.
    coords: list | None = None
    embedding: sp.Matrix | None = None
    _compiled: tuple | None = field(default=None, repr=False, compare=False)
    first_order = False  # second order: M, C, K (mechbook.engine.state_space: first order)

    @property
    def q(self) -> list:
        """The coordinates of the linear system (the independent ones on a constraint
        manifold)."""
        return list(self.coords) if self.coords is not None else self.dyn.q

    def _rates(self, of: list) -> list:
        if self.coords is None:
            return of
        return [of[self.dyn.q.index(c)] for c in self.coords]

    @property
    def qd(self) -> list:
        return self._rates(self.dyn.qd)

    @property
    def qdd(self) -> list:
        return self._rates(self.dyn.qdd)

    @property
    def coord_names(self) -> list[str]:
        return [str(q) for q in self.q] if self.coords is not None else \
            list(self.dyn.sys.coord_names)

    @property
    def dependent(self) -> dict:
        """{dependent coordinate: its linear displacement in the independent ones}, empty
        without constraints."""
        if self.embedding is None:
            return {}
        return dependent_displacements(self.dyn.q, self.coords, self.embedding,
                                       self.displacement())

    def gradient(self, form: sp.Expr) -> list[sp.Expr]:
        """The gradient at the point of a function of the coordinates, over the linear
        system's coordinates (on a constraint manifold: through the embedding δq = N·δs)."""
        grad = [sp.diff(form, q).subs(self.point) for q in self.dyn.q]
        if self.embedding is None:
            return grad
        return [sum((grad[i] * self.embedding[i, j] for i in range(len(grad))), sp.S.Zero)
                for j in range(len(self.coords))]

    def displacement(self) -> sp.Matrix:
        return sp.Matrix([q - self.point.get(q, 0) for q in self.q])

    def equations(self) -> list[sp.Expr]:
        """Linear equations (each = 0) in the original coordinate symbols."""
        dq = self.displacement()
        lhs = self.M * sp.Matrix(self.qdd) + self.C * sp.Matrix(self.qd) + self.K * dq
        return [sp.expand(e) for e in lhs - self.F]

    @cached_property
    def gyroscopic(self) -> bool:
        """C ≠ 0 (velocity terms: gyroscopic or damping), decided numerically."""
        return not all(is_zero(c) for c in self.C)

    @cached_property
    def driven(self) -> bool:
        """F(t) ≠ 0 (a force that does not depend on the displacements)."""
        return not all(is_zero(f) for f in self.F)

    # ---- symbolic frequencies ------------------------------------------------------------
    @cached_property
    def squared_frequencies(self) -> list[sp.Expr]:
        """Roots w = ω² of det(K − w M) = 0 with multiplicity (no gyroscopic terms)."""
        if self.gyroscopic:
            raise UnsupportedError("ω² roots of a gyroscopic system (use `frequencies`)")
        w = sp.Symbol("w")
        try:
            with time_limit(30):  # the determinant too: of 8 coordinates it runs for hours
                poly = sp.Poly(sp.factor((self.K - w * self.M).det()), w)
                roots = sp.roots(poly, w)
        except Timeout:
            raise UnsupportedError("closed-form roots of the secular equation (its "
                                   "determinant and roots ran past their time limit of 30 s "
                                   "of CPU)") from None
        if sum(roots.values()) != poly.degree():
            raise UnsupportedError("closed-form roots of the secular equation")
        out = []
        for r, mult in roots.items():
            out += [try_simplify(r, 5)] * mult
        return out

    @cached_property
    def frequencies(self) -> list[sp.Expr]:
        """Symbolic normal angular frequencies ω ≥ 0 (with multiplicity); with gyroscopic
        terms, the roots real and non-negative at the system's own values
        (`frequencies_at` for a point that also names an answer key's symbols)."""
        return self.frequencies_at(self.dyn.sys.numeric_values())

    def frequencies_at(self, values: dict) -> list[sp.Expr]:
        """The symbolic frequencies; a gyroscopic system's secular equation has 2n roots in
        ω, and the n kept are those real and non-negative at `values`, which must give
        every symbol of the roots a number (a steady motion's rate or tilt named by an
        answer key is not among the system's parameters): UnsupportedError otherwise."""
        if not self.gyroscopic:
            return ascending([try_simplify(sp.sqrt(r), 5) for r in self.squared_frequencies],
                             values)
        keep = []
        for r, mult in self._gyroscopic_roots.items():
            left = sorted(map(str, r.free_symbols - set(values)))
            if left:
                raise UnsupportedError("choosing the real roots of a gyroscopic system's "
                                       f"secular equation needs values of {', '.join(left)}")
            if r == 0:  # ω = 0 is its own pair (±0): a zero exponent of multiplicity m
                keep += [sp.S.Zero] * ((mult + 1) // 2)  # is m/2 zero frequencies
                continue
            v = _entry(r, values, 30)
            if abs(v.imag) < 1e-9 * (1 + abs(v)) and v.real >= -1e-12:
                keep += [try_simplify(r, 5)] * mult
        if len(keep) != len(self.q):
            raise UnsupportedError("closed-form frequencies of a gyroscopic system")
        return ascending(keep, values)

    @cached_property
    def _gyroscopic_roots(self) -> dict:
        """{root ω: multiplicity} of det(K − ω²M + iωC) = 0."""
        om = sp.Symbol("omega_root", positive=True)
        try:
            with time_limit(30):  # the determinant too (it can run for hours)
                det = sp.expand((self.K - om**2 * self.M + sp.I * om * self.C).det())
                return sp.roots(sp.Poly(det, om), om)
        except Timeout:
            raise UnsupportedError("closed-form frequencies of a gyroscopic system (the "
                                   "determinant and roots ran past their time limit of 30 s "
                                   "of CPU)") from None

    # ---- numeric -------------------------------------------------------------------------
    def matrices(self, values: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """M, C, K at `values`, each entry evaluated in 30-digit arithmetic (core.numeval:
        one memoized pass over the expression, so a large entry — Routh's reduction with a
        steady rate given as a root — costs milliseconds, not minutes of evalf)."""
        def num(A):
            left = sorted(map(str, A.free_symbols - set(values)))
            if self.dyn.sys.t.name in left:  # a driven coordinate: not one matrix but M(t)...
                raise UnsupportedError("the linearized equations have time-dependent "
                                       "coefficients (M, C, K depend on t)")
            if left:  # e.g. a point that names a symbol the system gives no value
                raise MechbookError(f"the linearized system keeps {', '.join(left)} without a "
                                    "numeric value")
            try:
                return np.array([[_entry(x, values, 30).real for x in row]
                                 for row in A.tolist()], dtype=float).reshape(A.shape)
            except TypeError:  # zoo, nan: not a number at this point
                raise MechbookError("the linearized system has no finite value at this "
                                    "point") from None

        return num(self.M), num(self.C), num(self.K)

    def numeric_modes(self, values: dict) -> tuple[np.ndarray, np.ndarray]:
        """(ω², modes as columns) by the generalized symmetric eigensolver, M-normalized."""
        M, C, K = self.matrices(values)
        if np.any(C):
            raise UnsupportedError("real normal modes of a gyroscopic or damped system")
        w2, vecs = scipy.linalg.eigh(K, M)
        return w2, vecs

    def numeric_frequencies(self, values: dict) -> np.ndarray:
        """Normal angular frequencies at `values` (NaN marks an unstable, imaginary one).

        `scipy.linalg.eigh(K, M)` in double precision, after a diagonal scaling that makes
        M's diagonal one; when the problem is ill-conditioned there (cond(M) or the spread
        of the eigenvalues beyond 1e6, or gyroscopic terms spanning many decades) the
        eigenvalues are recomputed with 50-digit mpmath arithmetic (bench/extremes.py).
        A zero frequency is one 50 digits cannot tell from zero (`zero_below`): an ω²
        that double precision leaves near zero (a spread beyond 1e6) is always
        recomputed, so a frequency 1e-5 of the largest stays what it is.
        A mass matrix that is not positive definite (a coordinate chart's singular point,
        z-x-z Euler angles at θ = 0) has no normal frequencies: MechbookError.
        """
        M, C, K = self.matrices(values)
        n = M.shape[0]
        if not np.any(C):
            d = 1.0 / np.sqrt(np.abs(np.diag(M)))
            Ms, Ks = M * np.outer(d, d), K * np.outer(d, d)
            try:
                w2 = scipy.linalg.eigh(Ks, Ms, eigvals_only=True)
            except np.linalg.LinAlgError:
                raise MechbookError("the mass matrix is not positive definite here (a "
                                    "singular point of the coordinates?): no normal "
                                    "frequencies") from None
            if _ill_conditioned(Ms, w2) or _near_zero(w2):  # decided at 50 digits
                w2 = self.precise_squared(values)
                scale = max(1e-300, float(np.max(np.abs(w2))))
                w2 = np.where(np.abs(w2) <= zero_below(50) * scale, 0.0, w2)
            return np.where(w2 >= 0, np.sqrt(np.abs(w2)), np.nan)
        Minv = np.linalg.inv(M)
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
        lam = np.linalg.eigvals(A)
        mags = np.abs(lam[np.abs(lam) > 0])
        if np.linalg.cond(M) > 1e6 or (len(mags) and mags.max() > 1e6 * mags.min()):
            lam = self.precise_state_eigenvalues(values)
        lam = lam[np.argsort(-lam.imag)]
        return np.sort(np.abs(lam.imag[:n]))

    def _mp_matrices(self, values: dict, dps: int = 50):
        import mpmath

        with mpmath.workdps(dps):
            return tuple(mpmath.matrix([[mpmath.re(x) for x in row] for row in
                                        mp_matrix(X, values, dps).tolist()])
                         for X in (self.M, self.C, self.K))

    def mp_state_matrix(self, values: dict, dps: int = 50):
        """The first-order (state-space) matrix at `values`, in mpmath at `dps` digits."""
        import mpmath

        with mpmath.workdps(dps):
            return state_matrix(*(mp_matrix(X, values, dps) for X in (self.M, self.C, self.K)))

    def precise_squared(self, values: dict, dps: int = 50) -> np.ndarray:
        """ω² by Cholesky reduction and a symmetric eigensolver in mpmath."""
        import mpmath

        with mpmath.workdps(dps):
            M, _, K = self._mp_matrices(values, dps)
            L = mpmath.cholesky(M)
            Linv = mpmath.inverse(L)
            A = Linv * K * Linv.T
            A = (A + A.T) / 2
            w2 = mpmath.eigsy(A, eigvals_only=True)
            return np.sort(np.array([float(x) for x in w2]))

    def mode_frequency(self, c: sp.Matrix, values: dict, dps: int = 50) -> float:
        """ω of the mode u = M⁻¹c (c: a normal coordinate's gradient) from its Rayleigh
        quotient u·K·u / u·M·u at `dps` digits. In double precision a zero mode's
        quotient is rounding, ~1e-16 of K, and its root ~1e-8 (lim-2047's rigid rotation
        came out 1.41e-8 on an AVX-512 machine); at 50 digits ~1e-25. Example:
        `lin.mode_frequency(sp.Matrix([m, M, m]), values)` is 0.0 for a rigid rotation."""
        import mpmath

        with mpmath.workdps(dps):
            M, K, cv = (mp_matrix(X, values, dps) for X in (self.M, self.K, c))
            u = mpmath.lu_solve(M, cv)
            w2 = (u.T * K * u)[0] / (u.T * M * u)[0]
            return float(mpmath.sqrt(max(mpmath.re(w2), 0)))

    def precise_state_eigenvalues(self, values: dict, dps: int = 50) -> np.ndarray:
        """Eigenvalues of the first-order (state-space) form in mpmath."""
        import mpmath

        with mpmath.workdps(dps):
            A = state_matrix(*self._mp_matrices(values, dps))
            lam = mpmath.eig(A, left=False, right=False)
            return np.array([complex(x) for x in lam])

    def fast_matrices(self, values: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """M, C, K at `values` in double precision through the compile layer (compiled once):
        for sweeps over many parameter points (stability over a parameter space), where
        `matrices`' 30-digit evaluation would dominate."""
        if self._compiled is None:
            syms = sorted(set().union(*(A.free_symbols for A in (self.M, self.C, self.K))),
                          key=lambda x: x.name)
            entries = [x for A in (self.M, self.C, self.K) for x in A]
            try:
                fn, _ = compile_exprs(syms, entries)
            except UnsupportedError:
                fn = None
            self._compiled = (syms, fn)
        syms, fn = self._compiled
        if fn is None or any(x not in values for x in syms):
            return self.matrices(values)
        with np.errstate(all="ignore"):
            out = np.asarray(fn(np.array([float(values[x]) for x in syms])), dtype=float)
        if not np.all(np.isfinite(out)):
            return self.matrices(values)
        n = self.M.rows
        return (out[: n * n].reshape(n, n), out[n * n: 2 * n * n].reshape(n, n),
                out[2 * n * n:].reshape(n, n))

    def numeric_stability(self, values: dict) -> str:
        """'stable', 'unstable' or 'marginal' from the linearized system at `values`: in
        double precision, or at 40 digits (`precise_stability`) where an ω² lies within
        ZERO_TOL of zero, which double precision cannot decide (a stiff spring beside a
        soft one at a parameter ratio of 1e8 is stable, not marginal)."""
        M, C, K = self.fast_matrices(values)
        if not decided_in_double(M, C, K):
            return self.precise_stability(values)
        return classify_matrices(M, C, K)

    def precise_stability(self, values: dict, dps: int = 40) -> str:
        """'stable', 'unstable' or 'marginal' with M, C, K and the eigenvalues in mpmath at
        `dps` digits: for a point close to a stability boundary, where an exponent or ω² is
        a relative 1e-8 from zero and double precision's thresholds cannot tell."""
        import mpmath

        with mpmath.workdps(dps):
            M, C, K = self._mp_matrices(values, dps)
            return classify_mp(M, C, K, dps)

    @cached_property
    def stability_condition(self) -> sp.Basic:
        """Sufficient and (without gyroscopic terms) necessary condition: K positive definite."""
        if self.gyroscopic:
            raise UnsupportedError("symbolic stability condition with gyroscopic terms")
        K = self.K
        minors = [try_simplify(K[:k, :k].det(), 5) for k in range(1, K.rows + 1)]
        return sp.And(*[mi > 0 for mi in minors])


def dependent_displacements(q: list, coords: list, embedding: sp.Matrix,
                            ds: sp.Matrix) -> dict:
    """{dependent coordinate: its displacement δq_i = Σ_j N_ij δs_j} on a constraint
    manifold, δs the independent coordinates' displacements."""
    return {x: sum((embedding[i, j] * ds[j] for j in range(len(coords))), sp.S.Zero)
            for i, x in enumerate(q) if x not in coords}


def classify_matrices(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> str:
    """'stable', 'unstable' or 'marginal' for M·q̈ + C·q̇ + K·q = 0 (numbers)."""
    n = M.shape[0]
    if not np.any(C):
        w2 = scipy.linalg.eigh(K, M, eigvals_only=True)
        scale = float(np.max(np.abs(w2)))  # relative: no unit of ω² is special
        if np.any(w2 < -ZERO_TOL * scale):
            return "unstable"
        return "marginal" if np.any(np.abs(w2) <= ZERO_TOL * scale) else "stable"
    A = np.block([[np.zeros((n, n)), np.eye(n)],
                  [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    lam = np.linalg.eigvals(A)
    scale = float(np.max(np.abs(lam)))  # relative, as above
    # exponents at zero (a symmetry: an ignorable coordinate kept in the linearization, a
    # family of steady motions) split by rounding into a tiny cluster whose real parts mean
    # nothing; they are neutral here (their polynomial growth is `secular_growth`'s
    # question), and the verdict rests on the others
    live = lam[np.abs(lam) > ZERO_CLUSTER * scale]
    if np.any(live.real > 1e-8 * scale):
        return "unstable"
    return "stable"


def decided_in_double(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> bool:
    """Does `classify_matrices`' verdict stand on values double precision resolves? False
    when, without velocity terms, some ω² lies within ZERO_TOL of zero (relative to the
    largest): its sign and whether it is zero are for more digits to say. With velocity
    terms the verdict stands (a zero cluster of exponents is neutral by design)."""
    if np.any(C):
        return True
    try:
        w2 = scipy.linalg.eigh(K, M, eigvals_only=True)
    except (np.linalg.LinAlgError, ValueError):
        return True  # no verdict in double; classify_matrices says what it can
    scale = float(np.max(np.abs(w2)))
    return scale == 0 or not np.any(np.abs(w2) <= ZERO_TOL * scale)


def classify_mp(M, C, K, dps: int) -> str:
    """`classify_matrices` in mpmath at `dps` digits (call inside that precision): ω² (or
    an exponent's real part) counts as zero below 10^(12 - dps) of the largest; an exponent
    within 10^(-dps/4) of zero (a symmetry's zero cluster, split by rounding) is neutral."""
    import mpmath

    n = M.rows
    tiny = mpmath.mpf(10) ** (12 - dps)
    if all(C[i, j] == 0 for i in range(n) for j in range(n)):
        L = mpmath.cholesky(M)
        Linv = mpmath.inverse(L)
        A = Linv * K * Linv.T
        w2 = mpmath.eigsy((A + A.T) / 2, eigvals_only=True)
        scale = max([abs(x) for x in w2] + [mpmath.mpf(1)])
        if any(x < -tiny * scale for x in w2):
            return "unstable"
        return "marginal" if any(abs(x) <= tiny * scale for x in w2) else "stable"
    lam = mpmath.eig(state_matrix(M, C, K), left=False, right=False)
    scale = max([abs(x) for x in lam] + [mpmath.mpf(1)])
    live = [x for x in lam if abs(x) > mpmath.mpf(10) ** (-dps / 4) * scale]
    return "unstable" if any(mpmath.re(x) > tiny * scale for x in live) else "stable"


def mp_matrix(A: sp.Matrix, values: dict, dps: int):
    """A at `values` as an mpmath matrix of `dps` digits: each entry by numeval's walk
    (milliseconds even for Routh's large reduced matrices), SymPy's evalf where the walk
    cannot go; UnsupportedError for an entry that gives no finite number."""
    import mpmath

    out = mpmath.matrix(A.rows, A.cols)
    with mpmath.workdps(dps):
        converted = mp_values(values, dps)  # once for all the entries
        for i in range(A.rows):
            for j in range(A.cols):
                x = A[i, j]
                if x != 0:  # a zero entry stays the matrix's exact zero
                    out[i, j] = _mp_entry(x, values, dps, converted)
    return out


def _mp_entry(x: sp.Expr, values: dict, dps: int, converted: dict | None = None):
    import mpmath

    try:
        v = (evaluate_mp(x, values, dps) if converted is None else
             evaluate_mp_at(x, converted, dps))
        if mpmath.isfinite(v):
            return mpmath.mpf(v) if mpmath.im(v) == 0 else v
    except (NotNumeric, ZeroDivisionError, ValueError, TypeError, OverflowError):
        pass
    x = sp.N(sp.S(x).subs(values), dps)
    if not x.is_number or x.has(sp.zoo, sp.nan, sp.oo, -sp.oo):
        raise UnsupportedError(f"a matrix entry does not evaluate to a number ({x})")
    re, im = x.as_real_imag()
    real = mpmath.mpf(sp.Float(re, dps)._mpf_)
    return real if im == 0 else mpmath.mpc(real, mpmath.mpf(sp.Float(im, dps)._mpf_))


def state_matrix(M, C, K):
    """[[0, 1], [−M⁻¹K, −M⁻¹C]] from mpmath M, C, K (at the working precision): ẋ = A x
    for x = (q, q̇), whose eigenvalues are the exponents p of e^{pt}."""
    import mpmath

    n = M.rows
    Minv = mpmath.inverse(M)
    A = mpmath.zeros(2 * n, 2 * n)
    MK, MC = -Minv * K, -Minv * C
    for i in range(n):
        A[i, n + i] = 1
        for j in range(n):
            A[n + i, j], A[n + i, n + j] = MK[i, j], MC[i, j]
    return A


def ascending(exprs: list[sp.Expr], values: dict) -> list[sp.Expr]:
    """Symbolic frequencies in the order the numeric ones come in (`numeric_frequencies`:
    ascending), by their real values at `values` (30 digits); one that does not evaluate
    there goes last, in its text's order, so the order is defined and kept."""
    def key(e: sp.Expr):
        try:
            v = _entry(e, values, 30)
        except (NotNumeric, ZeroDivisionError, ValueError, TypeError, OverflowError,
                MechbookError):
            return (1, 0.0, str(e))
        re = float(v.real) if isinstance(v, complex) else float(v)
        return (0, re, str(e)) if re == re else (1, 0.0, str(e))
    return sorted(exprs, key=key)


def _entry(x: sp.Expr, values: dict, digits: int, exact: bool = False):
    """One matrix entry at `values` (numeval's walk; SymPy's evalf where it cannot go).
    With `exact`, an mpmath number at `digits` instead of a Python complex."""
    import mpmath

    try:
        if exact:
            return mpmath.mpmathify(evaluate_mp(x, values, digits))
        return evaluate(x, values, digits)[0]
    except (NotNumeric, ZeroDivisionError, ValueError, TypeError):
        v = sp.N(sp.S(x).subs(values), digits)
        return mpmath.mpc(complex(v)) if exact else complex(v)


def _near_zero(w2: np.ndarray) -> bool:
    """Some ω² within ZERO_TOL of zero against the largest, an exact 0.0 included: double
    precision cannot say whether it is zero (3 + 3e-16 rounds to 3 + 4.4e-16)."""
    scale = float(np.max(np.abs(w2)))
    return scale > 0 and bool(np.any(np.abs(w2) <= ZERO_TOL * scale))


def _ill_conditioned(M: np.ndarray, w2: np.ndarray) -> bool:
    nonzero = np.abs(w2[np.abs(w2) > 0])
    spread = nonzero.max() / nonzero.min() if len(nonzero) else 1.0
    return bool(np.linalg.cond(M) > 1e6 or spread > 1e6)
