"""Integrators behind one interface, in the manner of `scipy.integrate.solve_ivp`.

`integrate(model, t_span, q0, qd0, method=..., **options)` returns a `Trajectory` of
(t, q, q̇) whatever the method. The methods:

    RK45, DOP853, Radau, LSODA   SciPy's solve_ivp (adaptive; rtol, atol, max_step)
    RK4                          classical fixed-step Runge–Kutta (explicit, not symplectic):
                                 the baseline against which symplectic methods are judged
    leapfrog (verlet)            Störmer–Verlet, kick-drift-kick: 2nd order, symplectic,
                                 time-reversible; needs a separable H = p·M⁻¹p/2 + V(q)
    yoshida4 (forest-ruth)       Yoshida's / Forest–Ruth's triple-jump composition of
                                 leapfrog: 4th order, symplectic; separable H only
    midpoint                     implicit midpoint rule on canonical (q, p), p = ∂L/∂q̇:
                                 2nd order, symplectic for any H(q, p) (non-separable,
                                 gyroscopic); solved by simplified Newton iteration

Fixed-step methods take `step` (default: the span over 10,000 steps). A symplectic method
keeps the energy error bounded (oscillating, no secular growth) over very long runs, which
an explicit Runge–Kutta method does not; they apply only to conservative systems, and the
separable ones only when the model is separable (`rhs.structure` decides). An option a
method does not take (`rtol` for a fixed-step method, `step` for an adaptive one) would have
no effect, so it is refused (IntegratorError, saying why), never dropped.

Each name is one entry of mechbook.numerics.methods.METHODS (the options it takes, the
class that runs it); the classes are one module per family: scipy_methods, fixed_step,
taylor (TaylorMethod), on the interface of integrator_base.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Sequence

import numpy as np

from mechbook.numerics.integrator_base import (  # noqa: F401 - re-exported
    Integrator,
    IntegratorError,
    Trajectory,
)
from mechbook.numerics.methods import (  # noqa: F401 - the names, re-exported
    ALIASES,
    FIXED_METHODS,
    METHODS,
    OPTIONS,
    SCIPY_METHODS,
    TAYLOR,
    kind,
    why_not,
)
from mechbook.numerics.rhs import Model


def make_integrator(method: str, **options) -> Integrator:
    """The integrator named `method` (see the module docstring) with its options.
    IntegratorError for an unknown method, and for an option given (not None) that the
    method does not take: it would have no effect, so it is refused, saying why."""
    entry = METHODS.get(method)
    if entry is None:
        raise IntegratorError(f"unknown method {method!r}; known: {', '.join(METHODS)}")
    applicable = _applicable(method, OPTIONS[entry.family], options)
    # the method's module, imported when it is used (numerics.methods names it)
    cls = getattr(importlib.import_module(entry.module), entry.cls)
    return cls(entry.alias_of or method, **applicable)


def _applicable(method: str, allowed: tuple[str, ...], options: dict) -> dict:
    """The options `method` takes; IntegratorError naming one given that it does not."""
    for name, value in options.items():
        if value is not None and name not in allowed:
            raise IntegratorError(f"option {name!r} does not apply to method {method!r} "
                                  f"({why_not(name, method)}); it takes: "
                                  f"{', '.join(sorted(allowed))}")
    return {k: v for k, v in options.items() if k in allowed}


def integrate(model: Model, t_span: tuple[float, float], q0: Sequence[float],
              qd0: Sequence[float], method: str = "DOP853",
              t_eval: Sequence[float] | None = None, events: Sequence[Callable] | None = None,
              **options) -> Trajectory:
    """Integrate the model from (q0, q̇0) over t_span with `method` (solve_ivp-like)."""
    integ = make_integrator(method, **options)
    q0 = np.asarray(q0, float)
    qd0 = np.asarray(qd0, float)
    integ.check(model, float(t_span[0]), q0, qd0)
    return integ.solve(model, t_span, q0, qd0, t_eval=t_eval, events=events)
