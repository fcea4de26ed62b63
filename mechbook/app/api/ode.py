"""The API's ODE function: dy/dt = f(t, y, u) of one system, its inputs u given per call.

A controller or an integrator of one's own needs the equations of motion as a function, and
a controller changes its inputs at every step: PyDy's `generate_ode_function` takes the
"specified" quantities (forces, torques, prescribed motions) per call for that reason. Here
the inputs are the parameters one names (`inputs=["F"]`: a force, a torque, a stiffness
one wants to drive) and, always, every driven coordinate the problem leaves free
(`driven: {y: {free: true}}`: y, ydot, yddot, the motion of a support). Without inputs the
function is `mechbook simulate`'s own compiled right-hand side; with them the same
equations are compiled with the inputs as arguments.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import sympy as sp

from mechbook.app.api.params import texts
from mechbook.core.backends import DEFAULT_BACKEND
from mechbook.core.compile import compile_exprs
from mechbook.errors import InputError, NotFoundError
from mechbook.numerics.rhs import build_model
from mechbook.numerics.simulate import initial_state


def input_symbols(sys, values: Mapping, names: Sequence[str]) -> list[sp.Symbol]:
    """The inputs u: the free driven coordinates' (y, ẏ, ÿ), then the parameters `names`
    (in their order); a name that is no parameter is a NotFoundError naming those there are."""
    out = [s for trio in sys.free_driven for s in trio]
    by_name = {str(k): k for k in values}
    for name in names:
        if str(name) not in by_name:
            raise NotFoundError(f"inputs: {str(name)!r} is not a parameter (parameters: "
                                f"{', '.join(sorted(by_name))})")
        sym = by_name[str(name)]
        if sym in out:
            raise InputError(f"inputs: {str(name)!r} named twice")
        out.append(sym)
    return out


class _WithInputs:
    """M q̈ = f (+ A q̈ + b = 0) compiled in (t, q, q̇, u), solved for q̈ per call."""

    def __init__(self, sys, dyn, values: dict, inputs: list[sp.Symbol]):
        fixed = {k: sp.Float(float(v), 17) for k, v in values.items() if k not in inputs}
        qdd = list(dyn.qdd)
        rest = {a: 0 for a in qdd}
        res = [e.xreplace(fixed) for e in dyn.residuals]  # SymPy already
        exprs = [sp.diff(e, a) for e in res for a in qdd] + [-e.xreplace(rest) for e in res]
        self.m = dyn.velocity_jacobian.rows
        if self.m:  # A q̈ + bias = 0: the constraints differentiated to the accelerations
            exprs += [x.xreplace(fixed) for x in dyn.velocity_jacobian]
            exprs += [x.xreplace(fixed) for x in dyn.constraint_bias]
        args = [sys.t, *dyn.q, *dyn.qd, *inputs]
        self.n = len(qdd)
        self.fn, _ = compile_exprs(args, exprs, DEFAULT_BACKEND)

    def rhs(self, t: float, y: np.ndarray, u: np.ndarray) -> np.ndarray:
        out = np.asarray(self.fn(np.concatenate(([t], y, u))), dtype=float).ravel()
        n, m = self.n, self.m
        M = out[: n * n].reshape(n, n)
        f = out[n * n: n * n + n]
        if m:
            A = out[n * n + n: n * n + n + m * n].reshape(m, n)
            big = np.zeros((n + m, n + m))
            big[:n, :n], big[:n, n:], big[n:, :n] = M, -A.T, A
            acc = np.linalg.solve(big, np.concatenate((f, -out[n * n + n + m * n:])))[:n]
        else:
            acc = np.linalg.solve(M, f)
        return np.concatenate((y[n:], acc))


class OdeFunction:
    """dy/dt = f(t, y, u) of one system's full nonlinear equations of motion, for
    `scipy.integrate.solve_ivp`, a controller, or an integrator of one's own.

    The state is y = (q, q̇): the coordinates, then their rates, in the order of `states`.
    The inputs u are given per call, in the order of `inputs` (none: f(t, y)). Without
    inputs it is the compiled right-hand side `mechbook simulate` integrates.

    Attributes
    ----------
    states : list of str
        The names of y's components (``theta``, then ``thetadot``).
    inputs : list of str
        The names of u's components: free driven coordinates (``y``, ``ydot``,
        ``yddot``), then the parameters named by ``inputs=``.
    parameters : dict of str to float
        The values the other parameters were compiled at.

    Examples
    --------
    >>> f = mechbook.load("lim-2029").ode_function(system="general")   # doctest: +SKIP
    >>> f.inputs                                                        # doctest: +SKIP
    ['y', 'ydot', 'yddot']
    >>> f(0.0, [0.1, 0.0], [0.0, 0.0, 1.0])                             # doctest: +SKIP
    """

    def __init__(self, analysis, system: str, values: dict[sp.Symbol, float],
                 inputs: Sequence[str] = ()):
        sys, dyn = analysis.system(system), analysis.dynamics(system)
        self._analysis, self._system, self._values = analysis, sys.name, values
        symbols = input_symbols(sys, values, inputs)
        self.inputs = [str(s) for s in symbols]
        if symbols:
            self._with = _WithInputs(sys, dyn, values, symbols)
            self._model = None
            names = list(sys.coord_names)
        else:
            self._model = build_model(sys, dyn, values)
            names = list(self._model.names)
        self.states = [*names, *(f"{c}dot" for c in names)]
        self.parameters = {str(k): float(v) for k, v in values.items() if k not in symbols}

    def __call__(self, t: float, y, u=None) -> np.ndarray:
        """dy/dt at time `t`, state `y` and inputs `u` (a sequence in the order of
        `inputs`, or a mapping {name: value}; omitted when there are no inputs)."""
        y = np.asarray(y, dtype=float)
        if self._model is not None:
            if u is not None and len(np.atleast_1d(u)):
                raise InputError("this function has no inputs (name parameters with "
                                 "ode_function(inputs=[...]))")
            return self._model.rhs(float(t), y)
        return self._with.rhs(float(t), y, self._inputs(u))

    def _inputs(self, u) -> np.ndarray:
        if isinstance(u, Mapping):
            missing = [k for k in self.inputs if k not in u]
            extra = [str(k) for k in u if str(k) not in self.inputs]
            if missing or extra:
                raise InputError(f"inputs: give {', '.join(self.inputs)}"
                                 + (f" (missing: {', '.join(missing)})" if missing else "")
                                 + (f" (not inputs: {', '.join(extra)})" if extra else ""))
            u = [u[k] for k in self.inputs]
        arr = np.asarray([] if u is None else u, dtype=float).ravel()
        if arr.size != len(self.inputs):
            raise InputError(f"inputs: {len(self.inputs)} values wanted "
                             f"({', '.join(self.inputs)}), {arr.size} given")
        return arr

    def initial(self, init: Mapping | None = None) -> np.ndarray:
        """The state `simulate` starts from with the same `init` ({coordinate or
        coordinate + 'dot': number or text}; the problem's `initial:` and then zeros for
        what it leaves out)."""
        q0, qd0, _ = initial_state(self._analysis, self._system, texts(init, "init"),
                                   self._values)
        return np.concatenate((q0, qd0))

    def __repr__(self) -> str:
        u = f", u = ({', '.join(self.inputs)})" if self.inputs else ""
        return f"<ode function of {self._system}: y = ({', '.join(self.states)}){u}>"
