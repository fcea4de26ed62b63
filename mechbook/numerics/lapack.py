"""Small linear solves for right-hand sides: LAPACK's dgesv called directly.

Shared by the model's right-hand side (numerics/model) and the stick-slip integrator
(numerics/friction), which call it on every evaluation an integrator asks for."""

from __future__ import annotations

import numpy as np
from scipy.linalg.lapack import dgesv as _DGESV


def solve_small(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """np.linalg.solve(a, b) for one small system: the same LAPACK routine (dgesv, the same
    result to the bit), called without NumPy's generalized-ufunc set-up, which costs twice
    the solve itself at n = 2 or 3, on every right-hand side an integrator asks for."""
    _, _, x, info = _DGESV(a, b)
    if info:
        raise np.linalg.LinAlgError("Singular matrix")
    return x
