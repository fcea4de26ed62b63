"""A linear system over a grid of parameter values: derived once, compiled once, batched.

`LinearSystem` evaluates M, C, K with 30-digit substitution at one point; a sweep instead
compiles the entries of M(p), C(p), K(p) once with the parameters as arguments (the compile
layer's batch entry, SymEngine LLVM) and evaluates them for a whole block of points at a
time, then solves every point's eigenproblem with NumPy's stacked (batched) solvers:

    no velocity terms   Cholesky of the diagonally scaled M, then `eigvalsh` of
                        L⁻¹ K L⁻ᵀ: ω² for each point (the same scaling as
                        `LinearSystem.numeric_frequencies`; a nonzero ω² within ZERO_TOL
                        of the largest is zero in float64, and its point counts as one
                        float64 cannot resolve, below)
    gyroscopic/damped   `eigvals` of the state-space matrix [[0, I], [−M⁻¹K, −M⁻¹C]]

Points where the matrices do not evaluate (a steady motion that does not exist there, say)
or M is not positive definite come out undefined (NaN, stability code UNDEFINED); points the
float64 path cannot resolve (cond(M) or the spread of ω² beyond 1e6, as in
`LinearSystem.numeric_frequencies`) are counted, and recomputed with 50 digits while there
are few of them (`PRECISE_LIMIT`), where ω² is zero only below what those digits resolve
(`linear.zero_below`). `precise_*` give the 30-digit path at single points, for
the accuracy statement a sweep prints (float64 against 30 digits at sampled points).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import sympy as sp

from mechbook.core.compile import DEFAULT_BACKEND, compile_batch
from mechbook.engine.linear import ZERO_TOL, LinearSystem, zero_below
from mechbook.errors import InputError, UnsupportedError

STABLE, MARGINAL, UNSTABLE, UNDEFINED = 1, 0, -1, -2
STABILITY_NAMES = {STABLE: "stable", MARGINAL: "marginal", UNSTABLE: "unstable",
                   UNDEFINED: "undefined"}
ILL_CONDITIONED = 1e6  # cond(M) or spread of |ω²| beyond this: float64 is not trusted
PRECISE_LIMIT = 200  # per block: ill-conditioned points recomputed with 50 digits
GROWTH_TOL = 1e-8  # a state-space eigenvalue with Re λ above this × max|λ| grows


@dataclass(frozen=True)
class Axis:
    """One swept parameter: N values from lo to hi (evenly, or evenly in log)."""

    name: str
    lo: float
    hi: float
    n: int
    log: bool = False

    def values(self) -> np.ndarray:
        if self.n == 1:
            return np.array([self.lo])
        if self.log:
            return np.geomspace(self.lo, self.hi, self.n)
        return np.linspace(self.lo, self.hi, self.n)

    def text(self) -> str:
        return f"{self.name}={self.lo:g}:{self.hi:g}:{self.n}" + (":log" if self.log else "")


def parse_axis(text: str) -> Axis:
    """`NAME=LO:HI:N` or `NAME=LO:HI:N:log` (numbers only; nothing is evaluated)."""
    name, sep, rng = text.partition("=")
    bits = rng.split(":")
    if not sep or not name.strip() or len(bits) not in (3, 4):
        raise InputError(f"{text!r}: expected NAME=LO:HI:N (or NAME=LO:HI:N:log)")
    try:
        lo, hi, n = float(bits[0]), float(bits[1]), int(bits[2])
    except ValueError:
        raise InputError(f"{text!r}: LO and HI must be numbers, N an integer") from None
    log = len(bits) == 4
    if log and bits[3].strip() != "log":
        raise InputError(f"{text!r}: the fourth field may only be 'log'")
    if n < 1 or not (np.isfinite(lo) and np.isfinite(hi)):
        raise InputError(f"{text!r}: N must be at least 1 and LO, HI finite")
    if log and (lo <= 0 or hi <= 0):
        raise InputError(f"{text!r}: a log axis needs LO, HI > 0")
    return Axis(name.strip(), lo, hi, n, log)


@dataclass
class Grid:
    """The points of a sweep: the axes' outer product (C order, last axis fastest), every
    other parameter at a fixed value. `block(start, stop)` is the (k, P) array of rows
    start..stop-1 in the order of `symbols`."""

    axes: list[Axis]
    symbols: list[sp.Symbol]  # every argument of the compiled functions, in column order
    fixed: dict[sp.Symbol, float]  # values of the symbols no axis sweeps

    def __post_init__(self):
        names = [str(s) for s in self.symbols]
        for a in self.axes:
            if a.name not in names:
                raise InputError(f"{a.name!r} is not a parameter here (parameters: "
                                 f"{', '.join(names)})")
        if len({a.name for a in self.axes}) != len(self.axes):
            raise InputError("a parameter is swept twice")
        self._cols = [names.index(a.name) for a in self.axes]
        self._values = [a.values() for a in self.axes]
        swept = {names[c] for c in self._cols}
        missing = [str(s) for s in self.symbols if str(s) not in swept and s not in self.fixed]
        if missing:
            raise InputError(f"no value for {', '.join(missing)}")

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(a.n for a in self.axes)

    @property
    def size(self) -> int:
        return int(np.prod(self.shape, dtype=np.int64))

    def coords(self) -> dict[str, np.ndarray]:
        return {a.name: v for a, v in zip(self.axes, self._values, strict=True)}

    def block(self, start: int, stop: int) -> np.ndarray:
        idx = np.unravel_index(np.arange(start, stop), self.shape)
        X = np.empty((stop - start, len(self.symbols)))
        for j, s in enumerate(self.symbols):
            if j not in self._cols:
                X[:, j] = float(self.fixed[s])
        for k, c in enumerate(self._cols):
            X[:, c] = self._values[k][idx[k]]
        return X

    def values_at(self, flat: int) -> dict[sp.Symbol, float]:
        """One point as {symbol: float}, for the 30-digit path."""
        row = self.block(flat, flat + 1)[0]
        return {s: float(x) for s, x in zip(self.symbols, row, strict=True)}


@dataclass
class Block:
    """What one block of points gave: arrays over the block's points."""

    frequencies: np.ndarray | None = None  # (k, n), ascending, NaN for an unstable mode
    stability: np.ndarray | None = None  # (k,) int8 codes
    growth: np.ndarray | None = None  # (k,) largest exponential growth rate (0 if none)
    ill: int = 0  # points float64 could not resolve
    precise: int = 0  # of those, recomputed with 50 digits
    notes: list[str] = field(default_factory=list)

    def keep(self, want: Sequence[str], freq: np.ndarray, stab: np.ndarray,
             growth: np.ndarray) -> Block:
        """The block with the results `want` asks for."""
        if "frequencies" in want:
            self.frequencies = freq
        if "stability" in want:
            self.stability, self.growth = stab, growth
        return self


def relations(cond) -> list:
    """The relations (a < b, …) a condition is built of with And / Or / Not."""
    if isinstance(cond, (sp.And, sp.Or, sp.Not)):
        return [r for a in cond.args for r in relations(a)]
    if isinstance(cond, sp.core.relational.Relational):
        return [cond]
    return []


def truth(cond, margins: dict, size: int) -> np.ndarray:
    """A condition's truth at `size` points, given each relation's margin lhs − rhs there
    (False where a margin is NaN: a point where the condition cannot be told holds none)."""
    if isinstance(cond, sp.And):
        return np.logical_and.reduce([truth(a, margins, size) for a in cond.args])
    if isinstance(cond, sp.Or):
        return np.logical_or.reduce([truth(a, margins, size) for a in cond.args])
    if isinstance(cond, sp.Not):
        return ~truth(cond.args[0], margins, size) & _decided(cond.args[0], margins, size)
    if cond is sp.true or cond is sp.false:
        return np.full(size, cond is sp.true)
    m = margins[cond]
    if isinstance(cond, sp.StrictLessThan):
        return m < 0
    if isinstance(cond, sp.LessThan):
        return m <= 0
    if isinstance(cond, sp.StrictGreaterThan):
        return m > 0
    if isinstance(cond, sp.GreaterThan):
        return m >= 0
    if isinstance(cond, sp.Ne):
        return np.isfinite(m) & (m != 0)
    raise UnsupportedError(f"mapping the relation {cond} over a grid")


def _decided(cond, margins: dict, size: int) -> np.ndarray:
    rels = relations(cond)
    if not rels:
        return np.ones(size, dtype=bool)
    return np.logical_and.reduce([np.isfinite(margins[r]) for r in rels])


def condition_mask(conditions: Sequence, symbols: Sequence[sp.Symbol], X: np.ndarray,
                   backend: str = DEFAULT_BACKEND) -> np.ndarray:
    """Where every condition holds, at the rows of X (columns in `symbols` order)."""
    rels = [r for c in conditions for r in relations(c)]
    size = X.shape[0]
    if not rels:
        return np.logical_and.reduce([np.full(size, bool(c)) for c in conditions]) \
            if conditions else np.ones(size, dtype=bool)
    cols = compile_batch(list(symbols), [r.lhs - r.rhs for r in rels], backend)(X)
    margins = {r: cols[:, i] for i, r in enumerate(rels)}
    return np.logical_and.reduce([truth(c, margins, size) for c in conditions])


def sweepable(free: set, symbols: Sequence[sp.Symbol], t: sp.Symbol) -> None:
    """UnsupportedError unless a linear system's entries depend on the swept symbols only
    (no t: an autonomous system; no symbol without a value)."""
    if t in free:
        raise UnsupportedError("a sweep of a linear system with time-dependent "
                               "coefficients (not autonomous)")
    unknown = sorted(str(s) for s in free - set(symbols))
    if unknown:
        raise UnsupportedError(f"sweeping: the linear system depends on {', '.join(unknown)}"
                               ", which is not a parameter")


class LinearSweep:
    """M(p), C(p), K(p) of one linear system compiled once for stacked evaluation."""

    def __init__(self, lin: LinearSystem, symbols: Sequence[sp.Symbol],
                 backend: str = DEFAULT_BACKEND):
        self.lin = lin
        self.symbols = list(symbols)
        self.n = len(lin.q)
        mats = (lin.M, lin.C, lin.K)
        free = set().union(*(m.free_symbols for m in mats))
        sweepable(free, self.symbols, lin.dyn.sys.t)
        self.gyroscopic = lin.gyroscopic
        # the point itself (and a steady motion's momenta): where they are not real, the
        # equilibrium does not exist, whatever finite values M, C, K take there
        where = [sp.S(v) for v in lin.point.values()]
        where += [sp.S(v) for v in lin.dyn.sys.held_momenta.values()]
        where = [w for w in where if w.free_symbols]
        unknown = sorted(str(s) for s in set().union(set(), *(w.free_symbols for w in where))
                         - set(self.symbols))
        if unknown:
            raise UnsupportedError(f"sweeping: the point depends on {', '.join(unknown)}, "
                                   "which is not a parameter")
        entries = [e for m in mats for e in m] + where
        self._fn = compile_batch(self.symbols, entries, backend)
        self._where = len(where)

    def matrices(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """M, C, K of shape (k, n, n) at the k rows of X."""
        n = self.n
        raw = self._fn(np.asarray(X, dtype=float))
        out = raw[:, : 3 * n * n].reshape(-1, 3, n, n)
        if self._where:
            gone = ~np.all(np.isfinite(raw[:, 3 * n * n:]), axis=1)
            out = out.copy()
            out[gone] = np.nan  # no such point here
        return out[:, 0], out[:, 1], out[:, 2]

    # ---- float64, stacked ----------------------------------------------------------------
    def evaluate(self, X: np.ndarray, want: Sequence[str] = ("frequencies", "stability"),
                 precise: bool = True) -> Block:
        """Frequencies and/or stability at the rows of X (see the module docstring)."""
        M, C, K = self.matrices(X)
        k = M.shape[0]
        ok = np.all(np.isfinite(M), axis=(1, 2)) & np.all(np.isfinite(C), axis=(1, 2)) \
            & np.all(np.isfinite(K), axis=(1, 2))
        block = Block()
        freq = np.full((k, self.n), np.nan)
        stab = np.full(k, UNDEFINED, dtype=np.int8)
        growth = np.full(k, np.nan)
        if self.gyroscopic:
            ill = self._state_space(M, C, K, ok, freq, stab, growth)
        else:
            ill = self._symmetric(M, K, ok, freq, stab, growth)
        block.ill = int(ill.sum())
        if precise and 0 < block.ill <= PRECISE_LIMIT:
            for i in np.flatnonzero(ill):
                values = {s: float(x) for s, x in zip(self.symbols, X[i], strict=True)}
                try:
                    freq[i] = self.precise_frequencies(values, dps=50)
                    block.precise += 1
                except (ValueError, ZeroDivisionError, ArithmeticError, TypeError):
                    pass  # kept at float64, and counted as such
            if block.precise < block.ill:
                block.notes.append(f"{block.ill - block.precise} ill-conditioned points kept "
                                   "at float64 (the 50-digit path failed there)")
        elif block.ill:
            block.notes.append(f"{block.ill} ill-conditioned points kept at float64 (more "
                               f"than {PRECISE_LIMIT} in a block to recompute)")
        return block.keep(want, freq, stab, growth)

    def _symmetric(self, M, K, ok, freq, stab, growth) -> np.ndarray:
        """ω² by the scaled Cholesky reduction; returns the ill-conditioned mask."""
        k = M.shape[0]
        ill = np.zeros(k, dtype=bool)
        diag = np.abs(np.diagonal(M, axis1=1, axis2=2))
        ok &= np.all(diag > 0, axis=1)
        if not ok.any():
            return ill
        idx = np.flatnonzero(ok)
        d = 1.0 / np.sqrt(diag[idx])
        D = d[:, :, None] * d[:, None, :]
        Ms, Ks = M[idx] * D, K[idx] * D
        Ms = (Ms + Ms.transpose(0, 2, 1)) / 2
        m_eig = np.linalg.eigvalsh(Ms)
        pd = m_eig[:, 0] > 0
        idx, Ms, Ks, m_eig = idx[pd], Ms[pd], Ks[pd], m_eig[pd]
        if not len(idx):
            return ill
        L = np.linalg.cholesky(Ms)
        Linv = np.linalg.inv(L)
        A = Linv @ Ks @ Linv.transpose(0, 2, 1)
        w2 = np.linalg.eigvalsh((A + A.transpose(0, 2, 1)) / 2)
        # frequencies: LinearSystem.numeric_frequencies's zero tolerance
        scale = np.maximum(1e-300, np.max(np.abs(w2), axis=1))
        w2f = np.where(np.abs(w2) < ZERO_TOL * scale[:, None], 0.0, w2)
        freq[idx] = np.where(w2f >= 0, np.sqrt(np.abs(w2f)), np.nan)
        # stability: LinearSystem.numeric_stability's tolerance (scale at least 1)
        s1 = np.maximum(1.0, np.max(np.abs(w2), axis=1))
        unstable = np.any(w2 < -ZERO_TOL * s1[:, None], axis=1)
        marginal = np.any(np.abs(w2) <= ZERO_TOL * s1[:, None], axis=1)
        stab[idx] = np.where(unstable, UNSTABLE, np.where(marginal, MARGINAL, STABLE))
        growth[idx] = np.sqrt(np.maximum(-w2[:, 0], 0.0)) * unstable
        cond = m_eig[:, -1] / m_eig[:, 0]
        ill[idx] = (cond > ILL_CONDITIONED) | (_spread(np.abs(w2)) > ILL_CONDITIONED)
        return ill

    def _state_space(self, M, C, K, ok, freq, stab, growth) -> np.ndarray:
        """Eigenvalues of [[0, I], [−M⁻¹K, −M⁻¹C]]; returns the ill-conditioned mask."""
        k, n = M.shape[0], self.n
        ill = np.zeros(k, dtype=bool)
        with np.errstate(all="ignore"):
            cond = np.where(ok[:, None, None], M, np.eye(n))
            cond = np.linalg.cond(cond)
        ok &= np.isfinite(cond) & (cond < 1e15)
        idx = np.flatnonzero(ok)
        if not len(idx):
            return ill
        Mi, Ci, Ki = M[idx], C[idx], K[idx]
        A = np.zeros((len(idx), 2 * n, 2 * n))
        A[:, :n, n:] = np.eye(n)
        A[:, n:, :n] = -np.linalg.solve(Mi, Ki)
        A[:, n:, n:] = -np.linalg.solve(Mi, Ci)
        lam = np.linalg.eigvals(A)
        order = np.argsort(-lam.imag, axis=1)
        top = np.take_along_axis(lam, order, axis=1)[:, :n]
        freq[idx] = np.sort(np.abs(top.imag), axis=1)
        mag = np.abs(lam)
        scale = np.maximum(1.0, mag.max(axis=1))
        re = lam.real.max(axis=1)
        stab[idx] = np.where(re > GROWTH_TOL * scale, UNSTABLE, STABLE)
        growth[idx] = np.maximum(re, 0.0) * (re > GROWTH_TOL * scale)
        ill[idx] = (cond[idx] > ILL_CONDITIONED) | (_spread(mag) > ILL_CONDITIONED)
        return ill

    # ---- the high-precision path, one point at a time --------------------------------------
    def precise_frequencies(self, values: dict, dps: int = 30) -> np.ndarray:
        """Frequencies at one point with `dps` digits throughout: the matrices substituted
        symbolically (not through the compiled function), the eigenproblem in mpmath."""
        if self.gyroscopic:
            lam = self.lin.precise_state_eigenvalues(values, dps)
            lam = lam[np.argsort(-lam.imag)]
            return np.sort(np.abs(lam.imag[: self.n]))
        w2 = self.lin.precise_squared(values, dps)
        scale = max(1e-300, float(np.max(np.abs(w2))))  # zero: what dps digits cannot
        w2 = np.where(np.abs(w2) <= zero_below(dps) * scale, 0.0, w2)  # tell from zero
        return np.where(w2 >= 0, np.sqrt(np.abs(w2)), np.nan)

    def precise_stability(self, values: dict, dps: int = 30) -> tuple[int, np.ndarray]:
        """(stability code, spectrum) at one point with `dps` digits: the spectrum is ω²
        ascending, or the state-space eigenvalues."""
        if self.gyroscopic:
            lam = self.lin.precise_state_eigenvalues(values, dps)
            scale = max(1.0, float(np.max(np.abs(lam))))
            return (UNSTABLE if lam.real.max() > GROWTH_TOL * scale else STABLE), lam
        w2 = np.sort(self.lin.precise_squared(values, dps))
        s1 = float(np.max(np.abs(w2)))  # as LinearSystem.precise_stability: relative, at
        tiny = zero_below(dps) * s1  # what dps digits resolve
        if np.any(w2 < -tiny):
            return UNSTABLE, w2
        if np.any(np.abs(w2) <= tiny):
            return MARGINAL, w2
        return STABLE, w2

    def spectrum(self, X: np.ndarray) -> np.ndarray:
        """The float64 spectrum at the rows of X (as `precise_stability` gives it)."""
        M, C, K = self.matrices(X)
        n = self.n
        if not self.gyroscopic:
            return np.array([np.sort(_generalized_eigvalsh(K[i], M[i])) for i in range(len(M))])
        out = []
        for i in range(len(M)):
            A = np.zeros((2 * n, 2 * n))
            A[:n, n:] = np.eye(n)
            A[n:, :n] = -np.linalg.solve(M[i], K[i])
            A[n:, n:] = -np.linalg.solve(M[i], C[i])
            out.append(np.linalg.eigvals(A))
        return np.array(out)


def _spread(mag: np.ndarray) -> np.ndarray:
    """Per row: largest over smallest nonzero magnitude (1 where none is nonzero)."""
    nonzero = mag > 0
    hi = np.max(np.where(nonzero, mag, 0.0), axis=1)
    lo = np.min(np.where(nonzero, mag, np.inf), axis=1)
    return np.where(nonzero.any(axis=1), hi / np.where(np.isfinite(lo), lo, 1.0), 1.0)


def _generalized_eigvalsh(K: np.ndarray, M: np.ndarray) -> np.ndarray:
    """ω² of one point by the same scaled Cholesky reduction as the stacked path."""
    d = 1.0 / np.sqrt(np.abs(np.diag(M)))
    D = np.outer(d, d)
    L = np.linalg.cholesky((M * D + (M * D).T) / 2)
    Linv = np.linalg.inv(L)
    A = Linv @ (K * D) @ Linv.T
    return np.linalg.eigvalsh((A + A.T) / 2)
