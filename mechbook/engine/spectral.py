"""The normal modes of a segment by Chebyshev collocation: a discretization independent of
separation, which converges to its eigenvalues spectrally (docs/answers.md gives figures).

Σ a_k φ^(k) + λ·w·φ = 0 on [0, L] is collocated at the N + 1 Chebyshev–Lobatto points; the
rows of the points next to each end are replaced by that end's boundary conditions
(m conditions: the m outermost rows), and a condition Σ b_k φ^(k) = λ·b_tt·φ (a point mass)
puts its λ term in the right-hand matrix. The finite eigenvalues of the pencil, real parts,
ascending, are the discretization's λ = ω².
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

POINTS = 64  # collocation points: the lowest modes converge to ~1e-12 well before this


def chebyshev_matrix(n: int, length: float) -> tuple[np.ndarray, np.ndarray]:
    """(points on [0, L], the first-derivative matrix) of n + 1 Chebyshev–Lobatto points
    (Trefethen, Spectral Methods in MATLAB, cheb.m, mapped from [1, -1] to [0, L])."""
    x = np.cos(np.pi * np.arange(n + 1) / n)
    c = np.hstack([2.0, np.ones(n - 1), 2.0]) * (-1.0) ** np.arange(n + 1)
    dx = x[:, None] - x[None, :]
    d = np.outer(c, 1.0 / c) / (dx + np.eye(n + 1))
    d -= np.diag(d.sum(axis=1))
    # x in [1, -1] -> s = L(1 - x)/2 in [0, L]: d/ds = -(2/L) d/dx
    return length * (1 - x) / 2, -(2.0 / length) * d


def segment_eigenvalues(ode: list, weight: float, length: float, left: list, right: list,
                        count: int, points: int = POINTS) -> list[float]:
    """The lowest `count` eigenvalues λ of Σ ode[k]·φ^(k) + λ·weight·φ = 0 on [0, length]
    with the ends' conditions [(coefficients of φ^(k), coefficient of λφ), ...].

    >>> segment_eigenvalues([0, 0, 1.0], 1.0, np.pi, [([1, 0], 0)], [([1, 0], 0)], 2)
    [1.0..., 4.0...]
    """
    _, d = chebyshev_matrix(points, length)
    size = points + 1
    powers = [np.eye(size)]
    for _ in range(len(ode)):
        powers.append(d @ powers[-1])
    K = -sum(a * powers[k] for k, a in enumerate(ode))
    B = weight * np.eye(size)
    # point 0 is s = 0 (left), point N is s = L (right)
    rows = [(i, cond) for i, cond in enumerate(left)]
    rows += [(points - j, cond) for j, cond in enumerate(right)]
    for i, (coeffs, mass) in rows:
        end = 0 if i < size // 2 else points
        K[i] = sum(b * powers[k][end] for k, b in enumerate(coeffs))
        B[i] = 0.0
        B[i, end] = mass
    vals = scipy.linalg.eig(K, B, right=False)
    finite = vals[np.isfinite(vals)]
    finite = finite[np.abs(finite.imag) <= 1e-6 * np.maximum(1.0, np.abs(finite.real))]
    return sorted(float(v) for v in finite.real)[:count]
