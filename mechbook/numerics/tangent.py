"""The tangent flow: a motion and k tangent vectors carried along it, from the engine's own
equations differentiated (the variational equations).

The engine states the motion as residuals R(t, q, q̇, q̈) = 0 (`Dynamics.residuals`). A
displacement δq of the motion satisfies their differential,

    ∂R/∂q̈ · δq̈ + ∂R/∂q̇ · δq̇ + ∂R/∂q · δq = 0,

which is again linear in the accelerations. So the motion and k displacements together are
one system of n·(1 + k) coordinates in the same form M·q̈ = f — a block lower-triangular
mass matrix — and it is compiled and integrated by the project's own model and loops
(mechbook.numerics.rhs, DOP853 in loops.c): no finite differences and no second code path
for the derivative. Holonomic or velocity constraints and frictional contacts are refused
(their tangent space is not the whole state space).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

from mechbook.errors import UnsupportedError
from mechbook.numerics.integrators import integrate
from mechbook.numerics.rhs import Model, build_model

RTOL = 1e-12  # the flow's tolerance (relative and absolute), as the measurements' DOP853
ANGLE_STATES = 4  # random states at which a coordinate is tested for being an angle


@dataclass
class _System:
    """What `build_model` reads of a system, for the augmented one (no Lagrangian: the
    canonical form, which only the symplectic integrators ask for, does not exist)."""

    t: sp.Symbol
    q: list
    qd: list
    coord_names: list
    forces: list
    lagrangian: sp.Expr | None = None
    contacts: tuple = ()
    free_driven: bool = False


@dataclass
class _Dynamics:
    q: list
    qd: list
    qdd: list
    residuals: list
    velocity_jacobian: sp.Matrix = field(default_factory=lambda: sp.zeros(0, 1))
    constraint_bias: list = field(default_factory=list)


class TangentFlow:
    """The motion of `system` at the parameter `values`, with `copies` tangent vectors.

    `flow(t0, t1, y, V)` carries the state y (2n: q, q̇) and the tangent vectors, the
    columns of V (2n × copies), from t0 to t1. `free` names a parameter kept as a constant
    coordinate of the compiled model (p̈ = 0, never displaced), so that `value` may be moved
    without compiling again (a bifurcation's bisection). Example: the monodromy of a driven
    system, `TangentFlow(sys, dyn, values, 2 * n).flow(0, T, y0, np.eye(2 * n))[1]`."""

    def __init__(self, system, dyn, values: dict, copies: int, free: sp.Symbol | None = None):
        if system.constraints or system.velocity_constraints or system.contacts:
            raise UnsupportedError("the tangent flow of a system with constraints or "
                                   "contacts (its tangent space is not the whole state)")
        self.n, self.copies, self.free = len(dyn.q), copies, free
        self.value = float(values[free]) if free is not None else 0.0
        fixed = {k: v for k, v in values.items() if k != free}
        self.model = _augmented(system, dyn, fixed, copies, free)
        self.offset = self.n + (free is not None)  # where the first displacement starts
        self.evaluations = 0

    def pack(self, y: np.ndarray, V: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The compiled model's (q, q̇) for the state y and the tangent vectors V."""
        n, k = self.n, self.copies
        extra = [[self.value], [0.0]] if self.free is not None else [[], []]
        q0 = np.concatenate([y[:n], extra[0]] + [V[:n, j] for j in range(k)])
        qd0 = np.concatenate([y[n:], extra[1]] + [V[n:, j] for j in range(k)])
        return q0, qd0

    def unpack(self, q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(y, V) from the compiled model's (q, q̇)."""
        n, k, o = self.n, self.copies, self.offset
        V = np.empty((2 * n, k))
        for j in range(k):
            V[:n, j] = q[o + n * j: o + n * (j + 1)]
            V[n:, j] = qd[o + n * j: o + n * (j + 1)]
        return np.concatenate((q[:n], qd[:n])), V

    def flow(self, t0: float, t1: float, y: np.ndarray, V: np.ndarray,
             rtol: float = RTOL, max_step: float = math.inf) -> tuple[np.ndarray, np.ndarray]:
        """(y(t1), V(t1)); UnsupportedError if the integration fails. `max_step` bounds the
        steps: a drive that acts in short pulses needs it below the pulse's width, or an
        adaptive step may pass over the pulse without seeing it."""
        q0, qd0 = self.pack(y, V)
        run = integrate(self.model, (t0, t1), q0, qd0, method="DOP853", rtol=rtol, atol=rtol,
                        max_step=max_step, t_eval=[t1])
        self.evaluations += run.nfev
        if not run.success or run.q.shape[1] == 0:
            raise UnsupportedError(f"the tangent flow's integration failed: {run.message}")
        return self.unpack(run.q[:, -1], run.qd[:, -1])

    def reach(self, t0: float, t1: float, y: np.ndarray) -> tuple[float, np.ndarray]:
        """How far the motion alone gets from y toward t1 (where an integration failed:
        whether the state ran away, or the steps did), as (t, state)."""
        with np.errstate(all="ignore"):
            sol = solve_ivp(self.rate, (t0, t1), np.asarray(y, float), method="DOP853",
                            rtol=RTOL, atol=RTOL)
        return float(sol.t[-1]), sol.y[:, -1]

    def rate(self, t: float, y: np.ndarray) -> np.ndarray:
        """dy/dt of the motion itself (2n)."""
        q, qd = self.pack(y, np.zeros((2 * self.n, self.copies)))
        z = self.model.rhs(t, np.concatenate((q, qd)))
        N, n = self.model.n, self.n
        return np.concatenate((z[:n], z[N:N + n]))

    def padding(self) -> np.ndarray:
        """The compiled model's coordinates after the motion's at rest: the free parameter at
        its value, the displacements zero."""
        rest = np.zeros(self.model.n - self.n)
        if self.free is not None:
            rest[0] = self.value
        return rest


def _augmented(system, dyn, values: dict, copies: int, free: sp.Symbol | None) -> Model:
    """The motion and `copies` displacements as one model of n·(1 + copies) coordinates
    (and the `free` parameter as one more, with p̈ = 0, after the motion's)."""
    q, qd, qdd = list(dyn.q), list(dyn.qd), list(dyn.qdd)
    res = list(dyn.residuals)
    grads = [[(sp.diff(e, a), sp.diff(e, b), sp.diff(e, c)) for a, b, c in zip(q, qd, qdd,
                                                                            strict=True)]
             for e in res]
    names, Q, QD, QDD, R = list(system.coord_names), list(q), list(qd), list(qdd), list(res)
    if free is not None:
        pdd = sp.Symbol(f"_{free}_ddot", real=True)
        names.append(f"_{free}")
        Q, QD, QDD = Q + [free], QD + [sp.Symbol(f"_{free}_dot", real=True)], QDD + [pdd]
        R.append(pdd)
    for j in range(copies):
        dq = [sp.Symbol(f"_d{j}_{c}", real=True) for c in system.coord_names]
        dqd = [sp.Symbol(f"_d{j}_{c}_dot", real=True) for c in system.coord_names]
        dqdd = [sp.Symbol(f"_d{j}_{c}_ddot", real=True) for c in system.coord_names]
        for row in grads:
            R.append(sum((gq * x + gv * v + ga * a for (gq, gv, ga), x, v, a
                          in zip(row, dq, dqd, dqdd, strict=True)), sp.S.Zero))
        names += [f"_d{j}_{c}" for c in system.coord_names]
        Q, QD, QDD = Q + dq, QD + dqd, QDD + dqdd
    aug = _System(system.t, Q, QD, names, [sp.S.Zero] * len(Q))
    return build_model(aug, _Dynamics(Q, QD, QDD, R), values)


def angle_coordinates(model: Model, n: int, rest: np.ndarray | None = None,
                      seed: int = 7) -> list[bool]:
    """Which of the first n coordinates of `model` are angles of the equations: the
    accelerations unchanged when the coordinate alone is moved by 2π, at ANGLE_STATES random
    states (to 1e-9; the model's other coordinates at `rest`, default zero, their velocities
    zero). An angle's value is then meaningful only modulo 2π (a pendulum that turns over is
    still bounded)."""
    rng = np.random.default_rng(seed)
    rest = np.zeros(model.n - n) if rest is None else rest
    still = np.zeros(model.n - n)
    out = []
    for i in range(n):
        same = True
        for _ in range(ANGLE_STATES):
            t = rng.uniform(0, 1)
            q = np.concatenate((rng.uniform(-1, 1, n), rest))
            v = np.concatenate((rng.uniform(-1, 1, n), still))
            shifted = q.copy()
            shifted[i] += 2 * np.pi
            with np.errstate(all="ignore"):
                a = model.accelerations(t, q, v)[:n]
                b = model.accelerations(t, shifted, v)[:n]
            if not (np.all(np.isfinite(a)) and np.allclose(a, b, rtol=1e-9, atol=1e-9)):
                same = False
                break
        out.append(same)
    return out


__all__ = ["RTOL", "TangentFlow", "angle_coordinates"]
