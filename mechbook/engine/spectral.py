"""The normal modes of a segment, a rectangle and a Bessel radial problem by Chebyshev
collocation: a discretization independent of
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
    if len(ode) == 5:
        return _fourth_order(ode, weight, d, left, right, count)
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
    return _pencil_eigenvalues(K, B, count)


def _fourth_order(ode: list, weight: float, d: np.ndarray, left: list, right: list,
                  count: int) -> list[float]:
    """A fourth-order ODE as two second-order ones, φ″ = ψ and Σ a_k φ^(k) + λwφ = 0 with
    φ‴, φ⁗ written ψ′, ψ″: the collocation matrices' condition grows as N⁴, not N⁸ (a
    beam's lowest λ to ~1e-13 instead of ~1e-9 at best)."""
    n = d.shape[0]
    eye, zero = np.eye(n), np.zeros((n, n))
    d2 = d @ d
    a0, a1, a2, a3, a4 = ode
    K = -np.block([[d2, -eye], [a0 * eye + a1 * d, a2 * eye + a3 * d + a4 * d2]])
    B = np.block([[zero, zero], [weight * eye, zero]])

    def row(coeffs: list, end: int) -> np.ndarray:
        b = list(coeffs) + [0.0] * (4 - len(coeffs))
        return np.hstack([b[0] * eye[end] + b[1] * d[end], b[2] * eye[end] + b[3] * d[end]])

    for end, conds in ((0, left), (n - 1, right)):
        for block, (coeffs, mass) in enumerate(conds):
            i = block * n + end
            K[i] = row(coeffs, end)
            B[i] = 0.0
            B[i, end] = mass
    return _pencil_eigenvalues(K, B, count)


def _pencil_eigenvalues(K: np.ndarray, B: np.ndarray, count: int) -> list[float]:
    vals = scipy.linalg.eig(K, B, right=False)
    finite = vals[np.isfinite(vals)]
    finite = finite[np.abs(finite.imag) <= 1e-6 * np.maximum(1.0, np.abs(finite.real))]
    return sorted(float(v) for v in finite.real)[:count]


def rectangle_eigenvalues(ops: dict, weight: float, sides: tuple, edges: dict, count: int,
                          points: int = 20) -> list[float]:
    """The lowest λ of Σ ops[(b, c)]·∂_x^b ∂_y^c φ + λ·w·φ = 0 on [0, a]×[0, b] by 2-D
    Chebyshev collocation (no separation), a tensor grid of (points + 1)²; `edges`
    {x0, x1, y0, y1: coefficients of the normal derivatives φ, φ_n} (second order only).

    >>> rectangle_eigenvalues({(2, 0): 1, (0, 2): 1}, 1, (np.pi, np.pi),
    ...     {e: [1, 0] for e in ("x0", "x1", "y0", "y1")}, 1)
    [2.0...]
    """
    _, dx = chebyshev_matrix(points, float(sides[0]))
    _, dy = chebyshev_matrix(points, float(sides[1]))
    n = points + 1
    eye = np.eye(n)
    px = [eye, dx, dx @ dx]
    py = [eye, dy, dy @ dy]
    K = -sum(a * np.kron(px[b], py[c]) for (b, c), a in ops.items())
    B = weight * np.eye(n * n)
    rows = {}
    for i in range(n):  # index i*n + j is (x_i, y_j); y edges first, x edges win corners
        for j, name in ((0, "y0"), (points, "y1")):
            c = edges[name]
            rows[i * n + j] = c[0] * np.kron(eye[i], eye[j]) + c[1] * np.kron(eye[i], dy[j])
        for k, name in ((0, "x0"), (points, "x1")):
            c = edges[name]
            rows[k * n + i] = c[0] * np.kron(eye[k], eye[i]) + c[1] * np.kron(dx[k], eye[i])
    for idx, row in rows.items():
        K[idx] = row
        B[idx] = 0.0
    return _pencil_eigenvalues(K, B, count)


def radial_eigenvalues(order: int, inner: float, outer: float, kinds: tuple, count: int,
                       points: int = POINTS) -> list[float]:
    """The lowest k² of r²φ″ + rφ′ − n²φ + k²r²φ = 0 (Bessel's equation of order n) on
    [inner, outer] by Chebyshev collocation; `kinds` (inner, outer): 0 for φ = 0, 1 for
    φ′ = 0; a disk (inner = 0) is regular at the centre (φ = 0 there for n ≥ 1, φ′ = 0
    for n = 0).

    >>> radial_eigenvalues(0, 0.0, 1.0, (None, 0), 1)  # j_01 = 2.4048...
    [5.78...]
    """
    r, d = chebyshev_matrix(points, outer - inner)
    r = r + inner
    size = points + 1
    R = np.diag(r)
    K = -(R @ R @ d @ d + R @ d - order**2 * np.eye(size))
    B = R @ R
    for idx, kind in ((0, kinds[0]), (points, kinds[1])):
        if kind is None:  # the centre of a disk
            kind = 1 if order == 0 else 0
        K[idx] = np.eye(size)[idx] if kind == 0 else d[idx]
        B[idx] = 0.0
    return _pencil_eigenvalues(K, B, count)
