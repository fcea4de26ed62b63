"""How fast a small disturbance grows about an unstable equilibrium: the rate λ of e^(λt).

The numeric normal frequencies mark an unstable mode with NaN (ω² < 0 has no real root),
which told a reader nothing. Where ω² < 0 the mode grows like e^(λt) with λ = √(−ω²); with
gyroscopic or friction terms the rates are the positive real parts of the exponents of the
first-order system. Both are given at the default parameter values, beside the
frequencies, and printed as such (`describe`).
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg


def growth_rates(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> np.ndarray:
    """One rate per mode, in the order of LinearSystem.numeric_frequencies: √(−ω²) for a
    mode with ω² < 0 and 0 for the others; with C ≠ 0, the n largest real parts of the
    exponents (0 where not positive)."""
    n = M.shape[0]
    with np.errstate(all="ignore"):
        if not np.any(C):
            w2 = scipy.linalg.eigh(K, M, eigvals_only=True)
            scale = max(1e-300, float(np.max(np.abs(w2)))) if len(w2) else 1.0
            return np.where(w2 < -1e-12 * scale, np.sqrt(np.abs(w2)), 0.0)
        A = np.block([[np.zeros((n, n)), np.eye(n)],
                      [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
        real = np.sort(np.linalg.eigvals(A).real)[::-1][:n]
        scale = max(1e-300, float(np.max(np.abs(real)))) if len(real) else 1.0
        return np.where(real > 1e-9 * scale, real, 0.0)


def describe(frequencies, rates) -> str:
    """'[2.1, unstable: grows like e^(3.4 t)]': each mode's ω, or its growth rate, to the
    stored value's full precision (`show` reads results back; it must not round them)."""
    out = []
    for i, w in enumerate(frequencies):
        rate = float(rates[i]) if rates is not None and i < len(rates) else 0.0
        if rate > 0 or not math.isfinite(float(w)):
            out.append(f"unstable: grows like e^({rate!r} t)" if rate > 0 else "unstable")
        else:
            out.append(repr(float(w)))
    return "[" + ", ".join(out) + "]"
