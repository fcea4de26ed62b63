"""The energy of one part of a system along the linearized motion, at many digits.

A book follows energy from one part of a system to another (two pendulums coupled by a
weak spring: the energy of m along the beat). A part's own energy is its kinetic energy and
its potential energy in gravity — the terms the system builder records per particle and
body (mechbook.model.system); a spring's or any other interaction's energy belongs to no
one part and is left out. About an equilibrium it is expanded to second order in the
displacements and velocities and counted from its value there, as the linear motion it is
evaluated along (the small-oscillation approximation).

The motion is the linearized initial-value solution y(t) = V·e^{Λt}·V⁻¹·y0 from the state
matrix's eigen-decomposition in mpmath (`LinearMotion`). For a conservative motion (every
exponent imaginary) the supremum over all later times of a function of the state is its
maximum over the torus of the modes' phases (each distinct frequency a phase of its own):
the motion comes arbitrarily close to every point of that torus when the frequencies are
rationally independent, which they are at random parameter points.
"""

from __future__ import annotations

import mpmath
import numpy as np
import sympy as sp

from mechbook.core.expansion import expand_lagrangian
from mechbook.engine.linear import LinearSystem, mp_matrix, state_matrix
from mechbook.errors import NotFoundError, UnsupportedError
from mechbook.model.system import System

DPS = 40


def part_energy(sys: System, name: str) -> sp.Expr:
    """Kinetic plus gravitational energy of particle or body `name` (NotFoundError, a
    KeyError too, with the names there are)."""
    if name not in sys.part_kinetic:
        known = ", ".join(sorted(sys.part_kinetic)) or "none"
        raise NotFoundError(f"no particle or rigid body {name!r} in system {sys.name!r} "
                       f"(its parts: {known})")
    return sys.part_kinetic[name] + sys.part_potential.get(name, sp.S.Zero)


def quadratic_part_energy(sys: System, name: str, point: dict) -> sp.Expr:
    """The part's energy to second order in (q − q*, q̇) about `point`, counted from its
    value there (the small-oscillation energy of that part)."""
    return expand_lagrangian(part_energy(sys, name), sys.q, sys.qd, point, [], 2)


class LinearMotion:
    """δy(t) = (δq, δq̇) of the linear system from δy(0), by the state matrix's
    eigen-decomposition at `dps` digits (a defective matrix is refused)."""

    def __init__(self, lin: LinearSystem, values: dict, q0, v0, dps: int = DPS):
        if lin.driven:
            raise UnsupportedError("the energy of a part along a driven motion")
        if any(x.has(lin.dyn.sys.t) for A in (lin.M, lin.C, lin.K) for x in A):
            raise UnsupportedError("a motion with time-dependent coefficients")
        self.dps = dps
        self.n = len(lin.q)
        with mpmath.workdps(dps + 10):
            M, C, K = (mp_matrix(X, values, dps + 10) for X in (lin.M, lin.C, lin.K))
            A = state_matrix(M, C, K)
            self.lam, V = mpmath.eig(A)
            y0 = mpmath.matrix([*q0, *v0])
            try:
                c = mpmath.lu_solve(V, y0)
            except ZeroDivisionError:
                raise UnsupportedError("a linear motion at a repeated exponent without a full "
                                       "set of modes (a Jordan block)") from None
            self.terms = [(self.lam[j], [c[j] * V[i, j] for i in range(2 * self.n)])
                          for j in range(2 * self.n)]
            self.scale = max([abs(x) for x in self.lam] + [mpmath.mpf(1)])

    def state(self, t) -> list:
        """δy at time t (real, 2n numbers)."""
        with mpmath.workdps(self.dps + 10):
            y = [mpmath.mpf(0)] * (2 * self.n)
            for lam, w in self.terms:
                e = mpmath.exp(lam * t)
                y = [y[i] + w[i] * e for i in range(2 * self.n)]
            return [mpmath.re(x) for x in y]

    def torus(self):
        """(number of phases, y(phases), W): the motion with each distinct frequency's phase
        free; W (phases × 2n, complex, double precision) the same motion as
        y = 2·Re(Σ_k W_k·exp(i·phase_k)), for scanning many phases at once.
        UnsupportedError for a damped or growing motion, or one that drifts (a zero
        exponent the start excites)."""
        tiny = mpmath.mpf(10) ** (-(self.dps - 10)) * self.scale
        size = max([abs(x) for _, w in self.terms for x in w] + [mpmath.mpf(10) ** -300])
        groups: list[tuple] = []
        for lam, w in self.terms:
            if abs(mpmath.re(lam)) > tiny:
                raise UnsupportedError("the supremum over the motion of a damped (or growing) "
                                       "linear system")
            if abs(lam) <= tiny:
                if max(abs(x) for x in w) > tiny * size:
                    raise UnsupportedError("the supremum over a motion that drifts (a zero "
                                           "frequency the start excites)")
                continue
            if mpmath.im(lam) < 0:
                continue  # the conjugate of a term kept
            for g in groups:
                if abs(g[0] - mpmath.im(lam)) <= tiny:
                    g[1].append(w)
                    break
            else:
                groups.append((mpmath.im(lam), [w]))

        def at(phases) -> list:
            y = [mpmath.mpf(0)] * (2 * self.n)
            for (_, ws), th in zip(groups, phases, strict=True):
                e = mpmath.expj(th)
                for w in ws:
                    y = [y[i] + 2 * mpmath.re(w[i] * e) for i in range(2 * self.n)]
            return y

        W = np.array([[complex(sum((w[i] for w in ws), mpmath.mpc(0)))
                       for i in range(2 * self.n)] for _, ws in groups], dtype=complex)
        return len(groups), at, W.reshape(len(groups), 2 * self.n)
