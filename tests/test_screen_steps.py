"""The equilibrium screen's Newton steps (engine.screen._newton_steps): the pseudo-inverse
step pinv(J)·F, by LU solves where J is well conditioned and by the SVD elsewhere."""

from __future__ import annotations

import numpy as np

from mechbook.engine.screen import _newton_steps


def test_regular_jacobians_take_the_inverse_step():
    rng = np.random.default_rng(7)
    for n in (1, 2, 3, 4):
        J = rng.normal(size=(200, n, n)) + 3 * np.eye(n)
        F = rng.normal(size=(200, n))
        expected = np.array([np.linalg.inv(j) @ f for j, f in zip(J, F, strict=True)])
        assert np.allclose(_newton_steps(J, F), expected, rtol=1e-12, atol=1e-12)


def test_singular_jacobians_take_the_least_norm_step():
    """diag(a, 0): the step moves the first coordinate by F₀/a and leaves the flat one;
    a zero Jacobian takes no step; a rank-one J = u vᵀ moves along v by (u·F)/(|u|²|v|²)."""
    J = np.array([[[2.0, 0.0], [0.0, 0.0]],
                  [[0.0, 0.0], [0.0, 0.0]],
                  [[1.0, 2.0], [2.0, 4.0]],
                  [[4.0, 1.0], [1.0, 3.0]]])  # and a regular one in the same batch
    F = np.array([[3.0, 5.0], [1.0, 1.0], [1.0, 1.0], [1.0, 2.0]])
    got = _newton_steps(J, F)
    u = v = np.array([1.0, 2.0])
    rank_one = v * (u @ F[2]) / ((u @ u) * (v @ v))
    regular = np.array([[3.0, -1.0], [-1.0, 4.0]]) @ F[3] / 11.0
    assert np.allclose(got, [[1.5, 0.0], [0.0, 0.0], rank_one, regular], rtol=1e-14, atol=1e-14)


def test_nearly_singular_jacobians_are_not_inverted():
    """cond J = 1e12: the pseudo-inverse keeps the tiny singular value (above 1e-15 of the
    largest) as the inverse does; the ill-conditioned rows go through the SVD."""
    J = np.array([[[1.0, 0.0], [0.0, 1e-12]]])
    F = np.array([[1.0, 1e-12]])
    assert np.allclose(_newton_steps(J, F), [[1.0, 1.0]], rtol=1e-9)
