"""A linearization as the Python API hands it out: ż = A·z + B·r, and M, C, K where it is
second order.

sympy.physics.mechanics' `Linearizer` returns the state matrix A and the input matrix B of
a system linearized about an operating point, holonomic or not; users reach for them to
design a controller or to read the exponents. Here they come from the engine's
linearization (mechbook.engine.linear.LinearSystem, or mechbook.engine.state_space for a
system whose velocity constraints leave fewer speeds than coordinates): the state z is the
independent coordinates' displacements and then their rates (or the independent speeds),
the inputs r the small parameters and the free driven coordinates the forcing holds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as sp

from mechbook.engine.response import exponents
from mechbook.errors import NotFoundError
from mechbook.model.manifold import Freedoms, manifold_of


@dataclass
class Linearization:
    """ż = A·z + B·r about `point` (and the uniform motion `rates`).

    Attributes
    ----------
    states : list of sympy.Symbol
        z: δ of each independent coordinate, then of each independent rate (or speed).
    A, B : sympy.Matrix
        The state matrix, and the input matrix over `inputs` (empty without inputs).
    M, C, K : sympy.Matrix or None
        M·δq̈ + C·δq̇ + K·δq = F over the independent coordinates; None for a first-order
        linearization (velocity constraints).
    freedoms : Freedoms
        Degrees of freedom at the point: of the configuration and of the velocity.

    Examples
    --------
    >>> lin = mechbook.load("lim-2031").linearize(about={"theta": 0})
    >>> lin.A, lin.exponents()          # doctest: +SKIP
    """

    states: list
    A: sp.Matrix
    B: sp.Matrix
    inputs: list
    M: sp.Matrix | None
    C: sp.Matrix | None
    K: sp.Matrix | None
    freedoms: Freedoms
    point: dict
    rates: dict
    engine: object  # the engine's own linear system (LinearSystem or StateSpaceSystem)
    values: dict  # the default parameter values

    def exponents(self, params: dict | None = None) -> np.ndarray:
        """The exponents p of e^{pt} solutions: the eigenvalues of A.

        Parameters
        ----------
        params : dict, optional
            Parameter values instead of the defaults, {name or symbol: number}.

        Returns
        -------
        numpy.ndarray
            The complex exponents.

        Examples
        --------
        >>> lin.exponents(params={"W": 3})        # doctest: +SKIP
        """
        return exponents(self.engine, self._at(params))

    def frequencies(self, params: dict | None = None) -> np.ndarray:
        """The oscillation frequencies.

        Parameters
        ----------
        params : dict, optional
            Parameter values instead of the defaults, {name or symbol: number}.

        Returns
        -------
        numpy.ndarray
            One angular frequency per oscillating mode; NaN marks a growing mode.

        Examples
        --------
        >>> lin.frequencies(params={"W": 3})      # doctest: +SKIP
        """
        return np.asarray(self.engine.numeric_frequencies(self._at(params)))

    def stability(self, params: dict | None = None) -> str:
        """Whether small motions about the point stay small.

        Parameters
        ----------
        params : dict, optional
            Parameter values instead of the defaults, {name or symbol: number}.

        Returns
        -------
        str
            'stable', 'unstable' or 'marginal'.

        Examples
        --------
        >>> lin.stability(params={"W": 0.5})      # doctest: +SKIP
        'unstable'
        """
        return self.engine.numeric_stability(self._at(params))

    def _at(self, params: dict | None) -> dict:
        out = dict(self.values)
        by_name = {str(k): k for k in out}
        for k, v in (params or {}).items():
            if str(k) not in by_name:  # a value nothing reads would change nothing
                raise NotFoundError(f"{str(k)!r} is not a parameter here (parameters: "
                                    f"{', '.join(sorted(by_name))})")
            out[by_name[str(k)]] = v
        return {k: sp.Float(float(v), 30) for k, v in out.items()}


def linearization(lin, values: dict) -> Linearization:
    """The API's view of the engine's linear system `lin`."""
    dyn = lin.dyn
    sys = dyn.sys
    point = dict(lin.point)
    rates = dict(getattr(lin, "velocity", {}) or {})
    inputs = list(sys.small_params) + [s for trio in getattr(sys, "free_driven", [])
                                       for s in trio]
    if lin.first_order:
        A = lin.state_matrix()
        n = len(lin.coords)
        low = lin.E[n:, n:].LUsolve(lin.f[n:, :])
        forcing = sp.Matrix.vstack(lin.f[:n, :], low)
        states = [sp.Symbol(s) for s in lin.states]
        M = C = K = None
    else:
        n = len(lin.q)
        MK = lin.M.LUsolve(lin.K)
        MC = lin.M.LUsolve(lin.C)
        A = sp.Matrix.vstack(sp.Matrix.hstack(sp.zeros(n, n), sp.eye(n)),
                             sp.Matrix.hstack(-MK, -MC)).applyfunc(sp.cancel)
        forcing = sp.Matrix.vstack(sp.zeros(n, 1), lin.M.LUsolve(lin.F))
        states = ([sp.Symbol(f"delta_{q}") for q in lin.q]
                  + [sp.Symbol(f"delta_{v}") for v in lin.qd])
        M, C, K = lin.M, lin.C, lin.K
    used = [r for r in inputs if any(x.has(r) for x in forcing)]
    B = (sp.Matrix([[sp.cancel(sp.diff(x, r)) for r in used] for x in forcing])
         if used else sp.zeros(A.rows, 0))
    return Linearization(states, A, B, used, M, C, K, _freedoms(sys, point, rates, values),
                         point, rates, lin, dict(values))


def _freedoms(sys, point: dict, rates: dict, values: dict) -> Freedoms:
    n = len(sys.q)
    manifold = manifold_of(sys)
    if manifold is None:
        return Freedoms(n, n)
    at = {k: sp.Float(float(v), 30) for k, v in values.items()}
    state = {q: sp.S(point.get(q, 0)).subs(values) for q in sys.q}
    state.update({v: sp.S(rates.get(q, 0)).subs(values) for q, v in zip(sys.q, sys.qd,
                                                                       strict=True)})
    return manifold.freedoms({**at, **state, sys.t: sp.S.Zero})
