"""Numeric right-hand sides generated once from the engine's symbolic equations of motion.

The equations are taken as the engine states them, M(q, t)·q̈ = f(q, q̇, t) (plus Aᵀλ with
constraints, holonomic ones kept as g̈ = 0, velocity ones as ċ = 0), from
`Dynamics.residuals` — never re-derived — with the parameter values substituted. M and f
are compiled together (common subexpressions eliminated, by the compile layer
`mechbook.core.compile`) and the accelerations come from a numeric linear solve at each
call, which is cheaper to generate and more robust than SymPy's symbolic inverse of M. The
backend that compiled them is recorded on the model.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import sympy as sp

from mechbook.core.compile import (
    BACKENDS,
    DEFAULT_BACKEND,
    Compiled,
    as_expr,
    compile_batch,
    compile_exprs,
)
from mechbook.core.secalc import either, same
from mechbook.errors import UnsupportedError
from mechbook.numerics import c_library
from mechbook.numerics.friction import Phases
from mechbook.numerics.lapack import solve_small as _gesv


@dataclass
class EquationSource:
    """M q̈ = f (+ A q̈ + b = 0) with the parameters as symbols and their values: what a
    backend that compiles once per system (the Taylor backend) starts from."""

    t: sp.Symbol
    q: list
    qd: list
    M: list  # n×n, row-major
    f: list
    A: list  # m×n, row-major
    b: list
    values: dict  # parameter symbol -> float


@dataclass
class Model:
    """The numeric equations of motion of one system at fixed parameter values.

    State: y = (q, q̇), 2n floats. `rhs(t, y)` is what `solve_ivp` wants; `accelerations`
    solves M q̈ = f (with constraint multipliers when the system has constraints).
    The canonical pieces (momenta, ∂L/∂q, the mass matrix of L) serve the symplectic
    integrators, and `monitors` evaluates every conserved quantity the engine found."""

    names: list[str]
    n: int
    backend: str
    generation_seconds: float
    _mf: Compiled
    _canonical: Callable[[], Compiled]
    _monitor_fn: Callable[[np.ndarray], np.ndarray] | None  # batch entry
    monitor_names: list[str]
    constraints: int = 0
    nonconservative: bool = False
    stats: dict = field(default_factory=lambda: {"rhs_calls": 0})
    # () -> EquationSource: the same equations with the parameters still symbols (Taylor)
    _source: Callable[[], EquationSource] | None = None
    cache: dict = field(default_factory=dict)  # compiled artefacts of other backends (Taylor)
    _momenta_fn: Callable[[np.ndarray], np.ndarray] | None = None  # batch: (N, 1+2n) -> (N, n)

    def __post_init__(self) -> None:
        self._buf = np.zeros(1 + 2 * self.n)

    # ---- equations of motion -----------------------------------------------------------
    def mass_and_forcing(self, t: float, q: np.ndarray, qd: np.ndarray):
        """M (n×n), f (n), and with constraints A (m×n), b (m) where A q̈ + b = 0."""
        out = self._mf(np.concatenate(([t], q, qd)))
        n, m = self.n, self.constraints
        M = out[: n * n].reshape(n, n)
        f = out[n * n: n * n + n]
        if not m:
            return M, f, None, None
        A = out[n * n + n: n * n + n + m * n].reshape(m, n)
        b = out[n * n + n + m * n:]
        return M, f, A, b

    @cached_property
    def source(self) -> EquationSource:
        if self._source is None:
            raise UnsupportedError("this model keeps no symbolic equations")
        return self._source()

    @cached_property
    def native(self):
        """The compiled loops' view of this model (`c_library.NativeModel`), or None where the
        loop library or the LLVM kernel is unavailable (then the Python paths run)."""
        kernel = c_library.kernel_pointer(self._mf)
        lib = c_library.library() if kernel else None
        if lib is None:
            return None
        return c_library.NativeModel(lib, kernel, self.n, self.constraints, keep=(self._mf,))

    @cached_property
    def native_canonical(self):
        """Like `native`, with the canonical kernel too (the implicit midpoint loop)."""
        kernel, canon = c_library.kernel_pointer(self._mf), c_library.kernel_pointer(self.canonical)
        lib = c_library.library() if kernel and canon else None
        if lib is None:
            return None
        return c_library.NativeModel(lib, kernel, self.n, self.constraints, canonical=canon,
                                  keep=(self._mf, self.canonical))

    def accelerations(self, t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        nat = self.native
        if nat is not None:
            self.stats["rhs_calls"] += 1
            return nat.accelerations(t, q, qd)
        return self.accelerations_python(t, q, qd)

    def accelerations_python(self, t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """The reference: kernel through its Python wrapper, NumPy solve."""
        self._buf[0] = t
        self._buf[1:self.n + 1] = q
        self._buf[self.n + 1:] = qd
        return self._solve(self._mf(self._buf))

    def _solve(self, out: np.ndarray) -> np.ndarray:
        self.stats["rhs_calls"] += 1
        n, m = self.n, self.constraints
        if not m:
            if n == 1:
                return out[1:2] / out[0]
            return _gesv(out[: n * n].reshape(n, n), out[n * n: n * n + n])
        M = out[: n * n].reshape(n, n)
        A = out[n * n + n: n * n + n + m * n].reshape(m, n)
        big = np.zeros((n + m, n + m))
        big[:n, :n], big[:n, n:], big[n:, :n] = M, -A.T, A
        rhs = np.concatenate((out[n * n: n * n + n], -out[n * n + n + m * n:]))
        return np.linalg.solve(big, rhs)[:n]

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        """dy/dt for y = (q, q̇) (the function `solve_ivp` integrates): one call into the
        compiled kernel and solve where they exist, no allocation but the result."""
        nat = self.native
        if nat is not None:
            self.stats["rhs_calls"] += 1
            return nat.rhs(t, y)
        return self.rhs_python(t, y)

    def rhs_python(self, t: float, y: np.ndarray) -> np.ndarray:
        """The reference right-hand side: kernel through its Python wrapper, NumPy solve."""
        buf = self._buf
        buf[0] = t
        buf[1:] = y
        return np.concatenate((y[self.n:], self._solve(self._mf(buf))))

    # ---- canonical form (symplectic integrators) ---------------------------------------
    @cached_property
    def canonical(self) -> Compiled:
        """(t, q, q̇) -> [M_L (n×n), b (n), ∂L/∂q + Q (n)] with p = M_L q̇ + b."""
        return self._canonical()

    def canonical_parts(self, t: float, q: np.ndarray, qd: np.ndarray):
        n = self.n
        out = self.canonical(np.concatenate(([t], q, qd)))
        return out[: n * n].reshape(n, n), out[n * n: n * n + n], out[n * n + n:]

    def momenta(self, t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        M, b, _ = self.canonical_parts(t, q, qd)
        return M @ qd + b

    def velocities(self, t: float, q: np.ndarray, p: np.ndarray) -> np.ndarray:
        """q̇ from p = M_L(q, t) q̇ + b(q, t) (L quadratic in the velocities)."""
        M, b, _ = self.canonical_parts(t, q, np.zeros(self.n))
        return np.linalg.solve(M, p - b)

    def hamilton(self, t: float, q: np.ndarray, p: np.ndarray) -> np.ndarray:
        """(q̇, ṗ) at canonical (q, p): ṗ = ∂L/∂q + Q at q̇(q, p)."""
        qd = self.velocities(t, q, p)
        self.stats["rhs_calls"] += 1
        _, _, pdot = self.canonical_parts(t, q, qd)
        return np.concatenate((qd, pdot))

    # ---- monitors ----------------------------------------------------------------------
    def monitors(self, t: np.ndarray, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """Conserved quantities along a trajectory: shape (len(monitor_names), len(t)), in
        one vectorized call of the batch entry (a Python loop over 2·10⁵ samples cost ~2 s)."""
        if self._monitor_fn is None:
            return np.zeros((0, len(t)))
        return self._monitor_fn(_points(t, q, qd)).T

    def momenta_along(self, t: np.ndarray, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """p = ∂L/∂q̇ at every sample, (n, len(t)), in one vectorized call."""
        if self._momenta_fn is None:
            return np.array([self.momenta(tk, q[:, k], qd[:, k])
                             for k, tk in enumerate(t)]).T.reshape(self.n, len(t))
        return self._momenta_fn(_points(t, q, qd)).T


@dataclass
class Structure:
    """What the symplectic integrators need to know, decided at random points."""

    separable: bool  # H = p·M⁻¹p/2 + V(q), M constant: leapfrog / Yoshida apply
    canonical: bool  # L quadratic in q̇, no constraints, no non-conservative force
    reason: str = ""


def _points(t: np.ndarray, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """Samples as the rows (t, q, q̇) of the batch entry's input."""
    return np.column_stack((np.asarray(t, float), np.asarray(q, float).T,
                            np.asarray(qd, float).T))


def _numeric_values(values: dict) -> dict:
    return {k: sp.Float(float(v), 17) for k, v in values.items()}


def build_model(system, dyn, values: dict, conserved: dict[str, sp.Expr] | None = None,
                backend: str = DEFAULT_BACKEND) -> Model:
    """Compile the equations of motion of `system` (its `Dynamics` `dyn`) at `values`.

    `conserved` maps a monitor name to a quantity (in q, q̇, t) to evaluate along the motion.
    """
    if system.free_driven:
        raise UnsupportedError("simulating a system with an arbitrary driven coordinate "
                               "(give it as a function of t)")
    start = time.perf_counter()
    sub = _numeric_values(values)
    t = system.t
    q, qd, qdd = list(dyn.q), list(dyn.qd), list(dyn.qdd)
    n = len(q)
    zero_acc = {a: 0 for a in qdd}
    m = dyn.velocity_jacobian.rows  # holonomic constraints (as g̈) and velocity ones

    def equations(conv) -> list:  # M, f (and A, b) in either algebra (core.secalc.either)
        at = {conv(k): conv(v) for k, v in sub.items()}
        res = [conv(e).xreplace(at) for e in dyn.residuals]
        rest = {conv(a): conv(0) for a in qdd}
        exprs = [e.diff(conv(a)) for e in res for a in qdd] + [-e.xreplace(rest) for e in res]
        if m:  # A q̈ + bias = 0: the constraints differentiated to the accelerations
            exprs += [conv(x).xreplace(at) for x in dyn.velocity_jacobian]
            exprs += [conv(x).xreplace(at) for x in dyn.constraint_bias]
        return [as_expr(e) if conv is same else e for e in exprs]  # d(plain 0) is an int

    exprs = either(equations)  # SymEngine's objects go to the compile layer as they are
    bad = {str(x) for e in exprs for x in e.free_symbols} - {str(x) for x in [t] + q + qd}
    if bad:
        raise UnsupportedError("simulation: symbols without a value: "
                               + ", ".join(sorted(bad)))
    args = [t] + q + qd
    mf, used = compile_exprs(args, exprs, backend)

    def canonical() -> Compiled:
        def parts(conv) -> list:  # ∂²L/∂q̇∂q̇, ∂L/∂q̇ at q̇ = 0, ∂L/∂q + Q
            at = {conv(k): conv(v) for k, v in sub.items()}
            L = conv(system.lagrangian).xreplace(at)
            v = [conv(x) for x in qd]
            rest = {x: conv(0) for x in v}
            ML = [L.diff(a).diff(b) for a in v for b in v]
            bvec = [L.diff(a).xreplace(rest) for a in v]
            dLdq = [L.diff(conv(x)) + conv(F).xreplace(at)
                    for x, F in zip(q, system.forces, strict=True)]
            return ML + bvec + dLdq

        fn, _ = compile_exprs(args, either(parts), used)
        return fn

    monitor_fn = momenta_fn = None
    names = list(conserved or {})
    if names:  # evaluated on whole trajectories only: the batch entry
        monitor_fn = compile_batch(args, [conserved[k].xreplace(sub) for k in names], used)
        L = system.lagrangian.xreplace(sub)
        momenta_fn = compile_batch(args, [sp.diff(L, v) for v in qd], used)
    def source() -> EquationSource:
        res = list(dyn.residuals)
        Ms = [as_expr(sp.diff(e, a)) for e in res for a in qdd]
        fs = [as_expr(-e.xreplace(zero_acc)) for e in res]
        As, bs = [], []
        if m:
            As = [as_expr(x) for x in dyn.velocity_jacobian]
            bs = [as_expr(x) for x in dyn.constraint_bias]
        return EquationSource(t, q, qd, Ms, fs, As, bs,
                              {k: float(v) for k, v in values.items()})

    nonconservative = any(F != 0 for F in system.forces)
    model = Model(list(system.coord_names), n, used, 0.0, mf, canonical, monitor_fn, names,
                  constraints=m, nonconservative=nonconservative, _source=source,
                  _momenta_fn=momenta_fn)
    model.generation_seconds = time.perf_counter() - start
    if system.contacts:  # stick and slip: an integrator of phases, built when first asked
        from functools import partial

        model.phases = partial(Phases, system, dyn, values, model)
    return model


def structure(model: Model, state: tuple | None = None, samples: int = 5,
              seed: int = 1) -> Structure:
    """Decide numerically whether the system is separable (H = T(p) + V(q)) or at least
    canonical (L quadratic in q̇), at random states near `state` = (t, q, q̇).

    Separable means M_L constant, b = 0 and ∂L/∂q free of q̇ and t. Random-point tests
    avoid simplifying large expressions; a function that is not constant differs at random
    points far beyond the 1e-12 tolerance used."""
    if model.constraints:
        return Structure(False, False, "the system has multiplier constraints")
    if model.nonconservative:
        return Structure(False, False, "the system has non-conservative generalized forces")
    rng = np.random.default_rng(seed)
    n = model.n
    t0, q0, v0 = state if state is not None else (0.0, np.zeros(n), np.zeros(n))
    q0, v0 = np.asarray(q0, float), np.asarray(v0, float)
    qs = 0.1 * np.maximum(1e-3, np.abs(q0)) + 0.05
    pts = [(t0 + rng.uniform(-1, 1), q0 + qs * rng.uniform(-1, 1, n),
            v0 + rng.uniform(-1, 1, n)) for _ in range(samples)]
    with np.errstate(all="ignore"):
        parts = [model.canonical_parts(t, q, v) for t, q, v in pts]
        moved = [model.canonical_parts(t + 0.37, q, rng.uniform(-1, 1, n)) for t, q, _ in pts]
    if not all(np.all(np.isfinite(np.concatenate([x.ravel() for x in p])))
               for p in parts + moved):
        return Structure(False, False, "the equations do not evaluate near the initial state")
    try:
        for M, _, _ in parts:
            np.linalg.cholesky((M + M.T) / 2)
    except np.linalg.LinAlgError:
        return Structure(False, False, "the kinetic energy is not positive definite")
    M0 = parts[0][0]
    scale = max(1e-300, float(np.abs(M0).max()))

    def same(a, b, ref):
        return np.allclose(a, b, rtol=1e-12, atol=1e-13 * max(1e-300, float(np.abs(ref).max())))

    # L quadratic in q̇ (p = M_L q̇ + b exactly) iff M_L = ∂²L/∂q̇² does not depend on q̇;
    # `moved` also shifts t, so a mass matrix that varies in t fails here and below
    quadratic = all(same(M, M2, M) for (M, _, _), (M2, _, _) in zip(parts, moved, strict=True))
    const_M = all(same(M, M0, M0) for M, _, _ in parts + moved)
    if not quadratic and const_M:
        quadratic = True
    if not quadratic:
        return Structure(False, False, "the Lagrangian is not quadratic in the velocities")
    zero_b = all(np.allclose(b, 0, atol=1e-14 * scale) for _, b, _ in parts + moved)
    free_dq = all(same(d1, d2, d1) for (_, _, d1), (_, _, d2) in zip(parts, moved, strict=True))
    if const_M and zero_b and free_dq:
        return Structure(True, True)
    why = []
    if not const_M:
        why.append("the mass matrix depends on q or t")
    if not zero_b:
        why.append("L has terms linear in the velocities")
    if not free_dq:
        why.append("∂L/∂q depends on q̇ or t")
    return Structure(False, True, "; ".join(why))


def timed_calls(fn: Callable[[], object], seconds: float = 0.2) -> float:
    """Mean seconds per call of fn() over about `seconds` (for the benchmarks)."""
    calls, start = 0, time.perf_counter()
    while True:
        for _ in range(50):
            fn()
        calls += 50
        elapsed = time.perf_counter() - start
        if elapsed > seconds:
            return elapsed / calls


__all__ = ["BACKENDS", "DEFAULT_BACKEND", "EquationSource", "Model", "Structure", "build_model",
           "compile_exprs", "structure", "timed_calls"]
