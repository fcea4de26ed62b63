"""Integrating through stick and slip: the non-smooth part of Coulomb friction.

A contact (mechbook.model.friction) slides while its tangential velocity v_t is not zero:
the force −μN·v_t/|v_t| is part of the equations of motion. When v_t reaches zero the
contact may stick: the tangential force λ that keeps v_t = 0 (a velocity constraint,
J·q̈ + bias = 0 along the surface) is computed with the accelerations, and the contact
sticks if |λ| ≤ μN; otherwise it slides on, in the direction −λ̂ it is pushed. A stuck
contact slips again when |λ| reaches μN. The integration runs in phases of fixed modes
(DOP853), each ended by the event that changes a mode:

    sliding   |v_t| falls to ε (1e-9 of the velocity scale): then the switch is decided
    sticking  μN − |λ| falls to 0

and a caller's own events (their `terminal` and `direction` honoured) are passed through
every phase. `Phases.solve_ivp` answers like scipy's solve_ivp (t, y, t_events, y_events,
status, nfev, message), so the trajectory measurements use it unchanged
(mechbook.numerics.measure).
"""

from __future__ import annotations

import ctypes
import math
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp as scipy_solve_ivp

from mechbook.core.compile import as_expr, compile_exprs
from mechbook.errors import UnsupportedError
from mechbook.numerics.c_library import kernel_pointer
from mechbook.numerics.events import ROWS, solve_with_events
from mechbook.numerics.lapack import solve_small as _gesv

EPS = 1e-9  # a sliding speed this small (relative to the velocity scale) is a stop


@dataclass
class Result:
    t: np.ndarray
    y: np.ndarray
    t_events: list
    y_events: list
    status: int = 0
    nfev: int = 0
    message: str = ""
    # (t, contact, 'stick', 'slip', or 'through': stopped and slid on the way it is pushed)
    switches: list = field(default_factory=list)

    @property
    def success(self) -> bool:
        return self.status >= 0


def _norm(v: np.ndarray) -> float:
    """np.linalg.norm of a vector, to the bit (it is sqrt(v·v) there too), without its
    checks and dispatch: a few hundred ns instead of a microsecond."""
    return math.sqrt(v.dot(v))


def _same(a: float, b: float) -> bool:
    """a and b the same float to the bit (0.0 and -0.0 told apart; NaN never the same)."""
    return a == b and (a != 0.0 or math.copysign(1.0, a) == math.copysign(1.0, b))


def _kernel(fn, x: np.ndarray, out: np.ndarray):
    """fn(x) into `out`, as a function of nothing: the LLVM machine code behind a SymEngine
    Lambdify (mechbook.numerics.c_library.kernel_pointer) called through ctypes with the two
    buffers' addresses (~0.3 µs against ~2 µs through Lambdify's own wrapper: the same
    code, the same numbers), else Lambdify writing into `out`; None for a backend that can
    do neither (then `fn`'s result is copied)."""
    raw = getattr(fn, "lambdify", None)
    if raw is None:
        return None
    pointer = kernel_pointer(fn)
    if pointer is not None:
        address, user = pointer
        call = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p)(address)
        xa, oa = x.ctypes.data, out.ctypes.data
        keep = (raw, x, out)  # the machine code's owner and the buffers live as long

        def kernel(call=call, keep=keep):
            call(oa, xa, user)

        return kernel
    try:  # not the LLVM backend: Lambdify's own call
        raw(x, out=out)
    except TypeError:
        return None
    return lambda: raw(x, out=out)


def _tangent_basis(n: np.ndarray) -> np.ndarray:
    """Rows: an orthonormal basis of the plane (or line) perpendicular to n."""
    d = len(n)
    basis = []
    for e in np.eye(d):
        v = e - (e @ n) * n
        for b in basis:
            v = v - (v @ b) * b
        if np.linalg.norm(v) > 1e-8:
            basis.append(v / np.linalg.norm(v))
        if len(basis) == d - 1:
            break
    return np.array(basis)


class Phases:
    """A system with frictional contacts at fixed parameter values, integrated in phases.

    `smooth`, the system's own compiled model (mechbook.numerics.rhs.build_model: every
    contact sliding, −μN·v_t/|v_t| in its forces), lets a phase in which every contact
    slides run in the compiled DOP853 loop (`_sliding`); the other phases, and the step in
    which an event happens, run in SciPy's DOP853 on this class's right-hand side."""

    def __init__(self, system, dyn, values: dict, smooth=None):
        self._smooth = smooth
        if not system.contacts:
            raise UnsupportedError("no frictional contact")
        if system.constraints or system.velocity_constraints:
            raise UnsupportedError("stick and slip with multiplier constraints")
        sub = {k: sp.Float(float(v), 17) for k, v in values.items()}
        q, qd, qdd = list(dyn.q), list(dyn.qd), list(dyn.qdd)
        self.n = len(q)
        L = dyn.L
        zero = {a: 0 for a in qdd}
        res = [system.dt(sp.diff(L, v)) - sp.diff(L, x) - F
               for x, v, F in zip(q, qd, system.forces_without_friction, strict=True)]
        res = [sp.expand(e).xreplace(sub) for e in res]
        M = [sp.diff(e, a) for e in res for a in qdd]
        f0 = [-e.xreplace(zero) for e in res]
        exprs = M + f0
        self.contacts = []
        for c in system.contacts:
            d = c.tangential.rows
            normal = np.array([float(x) for x in c.normal.xreplace(sub)])
            start = len(exprs)
            exprs += list(c.tangential) + list(c.jacobian) + list(c.bias) + [c.mu, c.normal_force]
            self.contacts.append((c.name, d, start, _tangent_basis(normal)))
        exprs = [as_expr(sp.S(e).xreplace(sub)) for e in exprs]
        bad = set().union(*(e.free_symbols for e in exprs)) - set([system.t] + q + qd)
        if bad:
            raise UnsupportedError("friction: symbols without a value: "
                                   + ", ".join(sorted(map(str, bad))))
        self._fn, _ = compile_exprs([system.t] + q + qd, exprs)
        self.nfev = 0
        self.eps = [0.0] * len(self.contacts)
        # the compiled function writes into one buffer, of which M, f0 and every contact's
        # v_t, J, Jᵀ and bias are views made once here (no slicing or reshaping per call);
        # `_x` holds the (t, y) of the values in `_out` while `_fresh` is true. The kernel
        # holds the two buffers' addresses: a Phases is built where it is used, never
        # copied or pickled
        n = self.n
        self._x = np.zeros(1 + 2 * n)
        self._out = out = np.zeros(len(exprs))
        self._fresh = False
        self._kernel = _kernel(self._fn, self._x, out)
        self._M = out[: n * n].reshape(n, n)
        self._f0 = out[n * n: n * n + n]
        self._views = []
        for _, d, k, T in self.contacts:
            J = out[k + d: k + d + d * n].reshape(d, n)
            self._views.append((out[k: k + d], J, J.T, out[k + d + d * n: k + 2 * d + d * n],
                                k + 2 * d + d * n, T))

    # ---- pieces at a state ----------------------------------------------------------------
    def _evaluate(self, t: float, y: np.ndarray, reuse: bool = False) -> None:
        """The compiled expressions at (t, y), into the buffer `_out` (its views M, f0, ...
        valid until the next call). With `reuse`, a (t, y) the last evaluation had to the
        bit (an event at the state the integrator has just evaluated the right-hand side
        at) keeps the values there, without a second compiled call: the same numbers, since
        the function is deterministic."""
        self.nfev += 1
        x = self._x
        if reuse and self._fresh and _same(t, float(x[0])) \
                and np.asarray(y, float).tobytes() == x[1:].tobytes():
            return
        self._fresh = False
        x[0] = t
        x[1:] = y
        if self._kernel is not None:
            self._kernel()
        else:
            self._out[:] = self._fn(x)
        self._fresh = True

    def _contacts(self) -> list:
        """Per contact (v_t, J, bias, μ, N, T) of the last evaluation (views of the buffer)."""
        out = self._out
        return [(vt, J, bias, float(out[k]), float(out[k + 1]), T)
                for vt, J, _, bias, k, T in self._views]

    def _parts(self, t: float, y: np.ndarray, reuse: bool = False):
        """M, f0 and the contacts' parts (`_contacts`) at (t, y): views of the buffer, valid
        until the next evaluation (no caller keeps them longer)."""
        self._evaluate(t, y, reuse)
        return self._M, self._f0, self._contacts()

    def _accelerations(self, t, y, modes: list, directions: list, reuse: bool = False):
        """(q̈, the stuck contacts' tangential forces λ (Cartesian)); the parts at (t, y)
        are left in the buffer (`_contacts`)."""
        self._evaluate(t, y, reuse)
        out, n = self._out, self.n
        f = self._f0
        rows, rhs, stuck = [], [], []
        for i, ((vt, J, JT, bias, k, T), mode) in enumerate(zip(self._views, modes,
                                                                 strict=True)):
            if mode == "slip":
                speed = _norm(vt)
                # just released, or through a stop: the way it is pushed, until it moves
                if directions[i] is not None and speed <= 10 * self.eps[i]:
                    u = directions[i]
                else:
                    u = vt / speed if speed > 0 else np.zeros_like(vt)
                f = f - out[k] * out[k + 1] * (JT @ u)  # new: the buffer's f0 is kept
            else:
                rows.append(T @ J)
                rhs.append(-(T @ bias))
                stuck.append(i)
        if not rows:
            return _gesv(self._M, f), {}
        A = np.vstack(rows)
        m = A.shape[0]
        big = np.zeros((n + m, n + m))
        big[:n, :n], big[:n, n:], big[n:, :n] = self._M, -A.T, A
        sol = _gesv(big, np.concatenate((f, np.concatenate(rhs))))
        lam, forces, k = sol[n:], {}, 0
        for i in stuck:
            T = self._views[i][5]
            forces[i] = T.T @ lam[k: k + T.shape[0]]
            k += T.shape[0]
        return sol[:n], forces

    def rhs(self, t, y, modes, directions):
        return np.concatenate((y[self.n:], self._accelerations(t, y, modes, directions)[0]))

    # ---- modes ----------------------------------------------------------------------------
    def _decide(self, t, y, modes: list, eps: list) -> tuple[list, list]:
        """Modes after a stop or a release: contacts at rest (|v_t| ≤ ε) stick if the force
        that keeps them stuck is within μN, else slide the way they are pushed."""
        modes = list(modes)
        directions = [None] * len(modes)
        _, _, contacts = self._parts(t, y)
        for i, (vt, *_rest) in enumerate(contacts):
            if modes[i] == "slip" and np.linalg.norm(vt) <= 2 * eps[i]:  # the root's slack
                modes[i] = "stick"
        for _ in range(len(modes) + 1):
            _, forces = self._accelerations(t, y, modes, directions)
            contacts = self._contacts()
            # at the limit within the release event's root (1e-9 of μN) it lets go
            over = [(np.linalg.norm(F) / max(contacts[i][3] * contacts[i][4], 1e-300), i)
                    for i, F in forces.items()
                    if np.linalg.norm(F) >= contacts[i][3] * contacts[i][4] * (1 - 1e-9)]
            if not over:
                return modes, directions
            _, i = max(over)
            F = forces[i]
            modes[i] = "slip"
            directions[i] = -F / np.linalg.norm(F)  # it slides the way it is pushed
        return modes, directions

    def _stuck_velocities(self, t, y, modes: list, before: list) -> np.ndarray:
        """The velocities with every newly stuck contact's sliding (at most ε) removed: the
        least change in the kinetic metric, q̇ − M⁻¹Aᵀ(AM⁻¹Aᵀ)⁻¹A q̇ (the impulse of
        sticking)."""
        fresh = [i for i, (m, b) in enumerate(zip(modes, before, strict=True))
                 if m == "stick" and b == "slip"]
        if not fresh:
            return y
        M, _, contacts = self._parts(t, y)
        A = np.vstack([contacts[i][5] @ contacts[i][1] for i in fresh])
        v = y[self.n:]
        Minv_At = np.linalg.solve(M, A.T)
        v = v - Minv_At @ np.linalg.solve(A @ Minv_At, A @ v)
        return np.concatenate((y[: self.n], v))

    def _switch_events(self, modes, directions, eps):
        events = []
        for i, mode in enumerate(modes):
            if mode == "slip":
                def stop(t, y, i=i):
                    self._evaluate(t, y, reuse=True)
                    return _norm(self._views[i][0]) - eps[i]

                stop.terminal, stop.direction = True, -1
                events.append(stop)
            else:
                def release(t, y, i=i):
                    _, forces = self._accelerations(t, y, modes, directions, reuse=True)
                    _, _, _, _, k, _ = self._views[i]
                    return float(self._out[k]) * float(self._out[k + 1]) - _norm(forces[i])

                release.terminal, release.direction = True, -1
                events.append(release)
        return events

    def solve_ivp(self, t_span, y0, events=(), rtol: float = 1e-10, atol: float = 1e-10,
                  method: str = "DOP853", max_phases: int = 10000) -> Result:
        """Integrate over t_span from y0 through every switch (module docstring)."""
        t, t_end = float(t_span[0]), float(t_span[1])
        y = np.asarray(y0, float)
        _, _, contacts = self._parts(t, y)
        scale = max([np.linalg.norm(c[1]) * np.linalg.norm(y[self.n:]) for c in contacts]
                    + [np.linalg.norm(c[0]) for c in contacts] + [1e-12])
        eps = [EPS * scale] * len(contacts)
        self.eps = eps
        modes, directions = self._decide(t, y, ["slip"] * len(contacts), eps)
        user = list(events)
        t_events = [[] for _ in user]
        y_events = [[] for _ in user]
        switches = []
        start_nfev = self.nfev
        for _ in range(max_phases):
            switch = self._switch_events(modes, directions, eps)
            native = self._native() if method == "DOP853" else None
            if native is not None and all(m == "slip" for m in modes) \
                    and all(d is None for d in directions):
                sol = self._sliding(native, (t, t_end), y, user + switch, modes, directions,
                                    rtol, atol)
            else:
                sol = scipy_solve_ivp(lambda tt, yy, m=modes, d=directions:
                                      self.rhs(tt, yy, m, d), (t, t_end), y, method=method,
                                      rtol=rtol, atol=atol, events=user + switch)
            if sol.status < 0:
                return Result(np.array([t]), y[:, None], t_events, y_events, -1,
                              self.nfev - start_nfev, sol.message, switches)
            for k in range(len(user)):
                for te, ye in zip(sol.t_events[k], sol.y_events[k], strict=True):
                    if not t_events[k] or te > t_events[k][-1] + 1e-14 * max(1, abs(te)):
                        t_events[k].append(te)
                        y_events[k].append(ye)
            t, y = float(sol.t[-1]), sol.y[:, -1]
            fired_user = sol.status == 1 and any(
                getattr(user[k], "terminal", False) and len(sol.t_events[k])
                and abs(sol.t_events[k][-1] - t) <= 1e-12 * max(1, abs(t))
                for k in range(len(user)))
            if fired_user or sol.status == 0:
                return Result(np.array([t]), y[:, None],
                              [np.array(x) for x in t_events],
                              [np.array(x).reshape(len(x), len(y)) for x in y_events],
                              1 if fired_user else 0, self.nfev - start_nfev, sol.message,
                              switches)
            before = list(modes)
            _, _, now = self._parts(t, y)
            stopped = [i for i, c in enumerate(now)
                       if before[i] == "slip" and np.linalg.norm(c[0]) <= 2 * eps[i]]
            modes, directions = self._decide(t, y, modes, eps)
            y = self._stuck_velocities(t, y, modes, before)
            switches += [(t, self.contacts[i][0], m) for i, m in enumerate(modes)
                         if m != before[i]]
            switches += [(t, self.contacts[i][0], "through") for i in stopped
                         if modes[i] == "slip"]  # stopped, and pushed on the other way
        raise UnsupportedError(f"friction: more than {max_phases} stick-slip phases")

    # ---- every contact sliding: the compiled loop ------------------------------------------
    def _native(self):
        """The smooth model's compiled loops (native.NativeModel), or None (no model given,
        no C compiler, another backend): then every phase runs in SciPy."""
        if self._smooth is None or self._smooth.constraints:
            return None
        return self._smooth.native

    def _sliding(self, native, span, y0, events, modes, directions, rtol, atol,
                 rows: int = ROWS) -> SimpleNamespace:
        """A phase with every contact sliding, answered like solve_ivp (t, y, t_events,
        y_events, status, message): the compiled DOP853 loop on the smooth model, the steps
        in which an event changes sign taken again by SciPy on this class's right-hand side
        (mechbook.numerics.events.solve_with_events)."""

        def fun(tt, yy, m=modes, d=directions):
            return self.rhs(tt, yy, m, d)

        return solve_with_events(native, fun, span, y0, rtol=rtol, atol=atol, events=events,
                                 rows=rows, stats=self._smooth.stats)
