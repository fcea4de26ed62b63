"""A first-order linearization over a grid of parameter values (a rolling coin's stability
map), compiled once and batched as mechbook.engine.linear_grid does for M, C, K.

E(p) and Â(p) of E·ż = Â·z (mechbook.engine.state_space) are compiled with the parameters as
arguments (the compile layer's batch entry); at each block of points A = E⁻¹Â is solved in
stacked NumPy calls and the eigenvalues of its core (the states left once the structural
zero exponents are taken out) give the stability (a real part beyond GROWTH_TOL of the
largest, outside the zero cluster, grows) and the frequencies (|Im p| of each oscillating
pair, NaN for a growing real exponent; the rest NaN-padded). A point whose exponents double
precision cannot place (a small one: a Jordan block's split zero, a slow mode) is counted ill
and recomputed at 50 digits while there are few (PRECISE_LIMIT).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import sympy as sp

from mechbook.core.compile import DEFAULT_BACKEND, compile_batch
from mechbook.core.words import plural
from mechbook.engine.linear import ZERO_CLUSTER
from mechbook.engine.linear_grid import (
    GROWTH_TOL,
    PRECISE_LIMIT,
    STABLE,
    UNDEFINED,
    UNSTABLE,
    Block,
    sweepable,
)
from mechbook.engine.state_space import (
    StateSpaceSystem,
    ambiguous_exponents,
    frequencies_of_exponents,
)


class StateSweep:
    """E(p), Â(p) of one first-order linearization compiled for stacked evaluation."""

    gyroscopic = True  # decided from exponents, as a gyroscopic system's are

    def __init__(self, lin: StateSpaceSystem, symbols: Sequence[sp.Symbol],
                 backend: str = DEFAULT_BACKEND):
        self.lin = lin
        self.symbols = list(symbols)
        self.size = lin.Ahat.rows
        self.core = list(lin.core)
        self.n = max(1, len(self.core) // 2)  # frequency slots: one per exponent pair
        free = set().union(*(x.free_symbols for x in list(lin.E) + list(lin.Ahat)))
        sweepable(free, self.symbols, lin.dyn.sys.t)
        self._fn = compile_batch(self.symbols, list(lin.E) + list(lin.Ahat), backend)

    def state_matrices(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(the cores of A = E⁻¹Â, shape (k, c, c); the points where they evaluate)."""
        N = self.size
        raw = self._fn(np.asarray(X, dtype=float))
        E = raw[:, : N * N].reshape(-1, N, N)
        Ahat = raw[:, N * N:].reshape(-1, N, N)
        ok = np.all(np.isfinite(raw), axis=1)
        with np.errstate(all="ignore"):
            cond = np.linalg.cond(np.where(ok[:, None, None], E, np.eye(N)))
        ok &= np.isfinite(cond) & (cond < 1e15)
        A = np.full(E.shape, np.nan)
        if ok.any():
            A[ok] = np.linalg.solve(E[ok], Ahat[ok])
        idx = np.array(self.core, dtype=int)
        return A[:, idx][:, :, idx], ok

    def evaluate(self, X: np.ndarray, want: Sequence[str] = ("frequencies", "stability"),
                 precise: bool = True) -> Block:
        """Frequencies and/or stability at the rows of X (see the module docstring)."""
        core, ok = self.state_matrices(X)
        k = core.shape[0]
        freq = np.full((k, self.n), np.nan)
        stab = np.full(k, UNDEFINED, dtype=np.int8)
        growth = np.full(k, np.nan)
        ill = np.zeros(k, dtype=bool)
        idx = np.flatnonzero(ok)
        lam = np.linalg.eigvals(core[idx]) if len(idx) and core.shape[1] else \
            np.zeros((len(idx), 0), complex)
        for row, i in enumerate(idx):
            self._one(lam[row], i, freq, stab, growth)
            ill[i] = ambiguous_exponents(lam[row])
        block = Block()
        block.ill = int(ill.sum())
        if precise and 0 < block.ill <= PRECISE_LIMIT:
            for i in np.flatnonzero(ill):
                values = {s: sp.Float(float(x), 30) for s, x in zip(self.symbols, X[i],
                                                                    strict=True)}
                exact = np.array([complex(x) for x in self.lin.precise_exponents(values)
                                  [: len(self.core)]])
                self._one(exact, i, freq, stab, growth)
                block.precise += 1
        elif block.ill:
            block.notes.append(f"{plural(block.ill, 'point')} with exponents double precision "
                               f"cannot "
                               f"place kept at float64 (more than {PRECISE_LIMIT} in a block)")
        return block.keep(want, freq, stab, growth)

    def _one(self, lam: np.ndarray, i: int, freq, stab, growth) -> None:
        """One point's frequencies, stability code and growth rate from its exponents."""
        w = frequencies_of_exponents(lam)[: self.n]
        freq[i, : len(w)] = w
        scale = max(1.0, float(np.max(np.abs(lam)))) if len(lam) else 1.0
        live = lam[np.abs(lam) > ZERO_CLUSTER * scale]
        re = float(live.real.max()) if len(live) else 0.0
        unstable = re > GROWTH_TOL * scale
        stab[i] = UNSTABLE if unstable else STABLE
        growth[i] = re if unstable else 0.0

    def precise_frequencies(self, values: dict, dps: int = 30) -> np.ndarray:
        """Frequencies at one point at `dps` digits (the slots as `evaluate` fills them)."""
        out = np.full(self.n, np.nan)
        w = [float(x) for x in self.lin.precise_frequencies(_floats(values, dps), dps)]
        out[: min(len(w), self.n)] = w[: self.n]
        return out

    def precise_stability(self, values: dict, dps: int = 30) -> tuple[int, np.ndarray]:
        """(stability code, the core's exponents) at one point at `dps` digits."""
        at = _floats(values, dps)
        lam = np.array([complex(x) for x in self.lin.precise_exponents(at, dps)
                        [: len(self.core)]])
        code = UNSTABLE if self.lin.precise_stability(at, dps) == "unstable" else STABLE
        return code, lam

    def spectrum(self, X: np.ndarray) -> np.ndarray:
        """The float64 exponents of the core at the rows of X."""
        core, _ = self.state_matrices(X)
        return np.array([np.linalg.eigvals(c) for c in core])


def _floats(values: dict, dps: int) -> dict:
    return {k: sp.Float(float(v), dps) for k, v in values.items()}
