"""One system of a loaded problem, as the Python API hands it out (`p.system(name)`, or `p`
itself for a problem with one system): derived results as SymPy objects, numbers at the
default parameter values or at `params=` (mechbook.app.api.params)."""

from __future__ import annotations

import html
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import sympy as sp

from mechbook.app.api import args
from mechbook.app.api.display import MathDict, MathList
from mechbook.app.api.linearization import Linearization, linearization
from mechbook.app.api.loaded import LoadedProblem
from mechbook.app.api.ode import OdeFunction
from mechbook.app.api.params import parameter_values, refuse_unknown, texts
from mechbook.app.api.results import Simulation
from mechbook.app.output.mathml import math
from mechbook.core.compile import as_expr
from mechbook.core.timeout import try_simplify
from mechbook.engine.existence import existing
from mechbook.errors import InputError, NotFoundError, SpecError
from mechbook.numerics.simulate import simulate

if TYPE_CHECKING:
    import numpy as np

SIMULATE_OPTIONS = ("init", "params", "method", "accuracy", "rtol", "atol", "max_step",
                    "step", "points", "backend")


class SystemView:
    """One system's derived results as SymPy objects (computed on first use, cached)."""

    def __init__(self, problem: LoadedProblem, name: str):
        self.problem, self.name = problem, name
        self._an = problem.analysis

    @property
    def _sys(self):
        return self._an.system(self.name)

    @property
    def _dyn(self):
        return self._an.dynamics(self.name)

    @property
    def coordinates(self) -> list[sp.Symbol]:
        """The generalized coordinates q, as SymPy symbols, in the problem file's order."""
        return list(self._sys.q)

    @property
    def lagrangian(self) -> sp.Expr:
        """The Lagrangian L = T − V in q and q̇ (simplified for reading unless the problem
        was loaded with ``simplify=False``)."""
        return self._readable(self._sys.lagrangian)

    @property
    def kinetic(self) -> sp.Expr:
        """The kinetic energy T in q and q̇ (of every particle and rigid body)."""
        return self._readable(self._sys.kinetic)

    @property
    def potential(self) -> sp.Expr:
        """The potential energy V in q (gravity, springs, declared potentials)."""
        return self._readable(self._sys.potential)

    @property
    def eom(self) -> list[sp.Eq]:
        """Lagrange's equations M·q̈ = f (+ Aᵀλ with constraint multipliers λ: A the
        constraints at the velocity level, holonomic ones as ġ, then velocity constraints)."""
        dyn = self._dyn
        lhs = dyn.mass_matrix * sp.Matrix(dyn.qdd)
        rhs = dyn.forcing
        if dyn.constrained:
            rhs = rhs + dyn.velocity_jacobian.T * sp.Matrix(dyn.multipliers)
        return MathList(sp.Eq(a, b, evaluate=False) for a, b in zip(lhs, rhs, strict=True))

    @property
    def accelerations(self) -> dict[sp.Symbol, sp.Expr]:
        """The equations of motion solved for the accelerations, {q̈: expression}."""
        return MathDict(self._dyn.solved)

    @property
    def momenta(self) -> dict[sp.Symbol, sp.Expr]:
        """The generalized momenta p = ∂L/∂q̇, {q: p} (shown as p_q)."""
        return MathDict(zip(self._sys.q, self._dyn.momenta, strict=True), label=_momentum)

    @property
    def cyclic(self) -> dict[sp.Symbol, sp.Expr]:
        """Ignorable coordinates and their (conserved) momenta."""
        return MathDict(self._dyn.cyclic, label=_momentum)

    @property
    def energy(self) -> sp.Expr:
        """The energy function h = Σ q̇ ∂L/∂q̇ − L (conserved when `energy_conserved`)."""
        return self._dyn.energy_function

    @property
    def energy_conserved(self) -> bool:
        """Whether the energy function is conserved (L has no explicit t, no
        nonconservative forces)."""
        return bool(self._dyn.energy_conserved)

    @property
    def hamiltonian(self) -> sp.Expr:
        """The Hamiltonian H(q, p) = Σ p q̇ − L, q̇ eliminated for the momenta p_q."""
        return self._dyn.hamiltonian

    @property
    def equilibria(self) -> list[dict]:
        """The equilibria SymPy finds in closed form that exist at the default values (real,
        inside the coordinates' domains: mechbook.engine.existence), each a dict from
        coordinate to value; index it by the coordinate's symbol or its name."""
        points, _ = existing(self._an.equilibria(self.name).symbolic, self._sys,
                             self.problem.model.values())
        return MathList(MathDict(p) for p in points)

    def point(self, about: Mapping | None = None, what: str = "about") -> dict:
        """An equilibrium as {coordinate symbol: value}: `about` ({name or symbol: text or
        number}), or the system's one stable equilibrium when `about` is None. Text that
        does not parse is the fault of the argument `what` (about= or steady=), never of a
        line of the problem file."""
        if about is None:
            return self._an.default_point(self.name)
        sys = self._sys
        out = {}
        for name, val in args.mapping("about", about).items():
            key = str(name)
            if key not in sys.coord_names:
                raise NotFoundError(f"{key!r} is not a coordinate of {self.problem.id} "
                                    f"({', '.join(sys.coord_names)})")
            if isinstance(val, str):
                try:
                    val = self.problem.model.parse(val, (), dict(sys.names))
                except SpecError as exc:
                    raise InputError(f"{what}={{{key!r}: {val!r}}}: {exc.bare}") from None
            elif not isinstance(val, sp.Basic):
                val = args.number(f"about[{key!r}]", val, -1e100, 1e100)
            out[sys.q[sys.coord_names.index(key)]] = as_expr(val)
        return out

    def linear(self, about: Mapping | None = None):
        """The engine's linearized system M·δq̈ + C·δq̇ + K·δq = F about an equilibrium."""
        return self._an.linear(self.name, self.point(about))

    def linearize(self, about: Mapping | None = None, steady: Mapping | None = None,
                  reduce: bool | None = None) -> Linearization:
        """The linearization ż = A·z + B·r, as sympy's Linearizer gives it.

        Parameters
        ----------
        about : dict, optional
            The point, {coordinate: value} (names or symbols; numbers or text). Default:
            the system's one stable equilibrium.
        steady : dict, optional
            A steady motion's rates, {coordinate: rate}; the rates a constraint fixes are
            solved for.
        reduce : bool, optional
            Routh's reduction of the cyclic coordinates (default: unless the system has
            constraints).

        Returns
        -------
        Linearization
            A, B, the states and inputs; M, C, K where the linearization is second order;
            the degrees of freedom; `exponents`, `frequencies`, `stability` at `params=`.

        Examples
        --------
        >>> lin = p.linearize(about={"theta": "pi/2"}, steady={"psi": "W"})  # doctest: +SKIP
        >>> lin.A, lin.freedoms, lin.exponents(params={"W": 3})             # doctest: +SKIP
        """
        point = self.point(about) if (about is not None or not steady) else {}
        if steady:
            rates = self.point(steady, "steady")
            sys = self._sys
            if reduce is None:
                reduce = not (sys.constraints or sys.velocity_constraints)
            lin = self._an.steady_linear(self.name, rates, point, reduce)
        else:
            lin = self._an.linear(self.name, point)
        return linearization(lin, self.problem.model.values())

    def frequencies(self, about: Mapping | None = None, numeric: bool = False,
                    params: Mapping | None = None) -> list:
        """The normal angular frequencies of small oscillations about an equilibrium.

        Parameters
        ----------
        about : dict, optional
            The equilibrium, {coordinate: value} (names or symbols; numbers or text such as
            ``"acos(-g/(b*omega**2))"``). Default: the system's one stable equilibrium.
        numeric : bool, default False
            Floats instead of SymPy expressions.
        params : dict, optional
            Parameter values instead of the defaults, {name: number or text}: the numbers
            are computed there; the expressions have those values put in.

        Returns
        -------
        list
            SymPy expressions, or floats with ``numeric=True`` (NaN marks an unstable,
            imaginary frequency).

        Examples
        --------
        >>> p = mechbook.load("lim-2031")
        >>> p.frequencies(about={"theta": "acos(-g/(b*omega**2))"}, numeric=True)
        [5.0306...]
        >>> p.frequencies(about={"theta": "acos(-g/(b*omega**2))"}, numeric=True,
        ...               params={"omega": 8})                     # doctest: +SKIP
        """
        values = parameter_values(self.problem.model, params)  # refused before any work
        lin = self.linear(about)
        if numeric:
            return [float(w) for w in lin.numeric_frequencies(values)]
        out = [self._readable(w) for w in lin.frequencies]
        if params:
            chosen = {self.problem.model.parameters[str(k)].symbol for k in params}
            out = [w.subs({s: values[s] for s in chosen}) for w in out]
        return MathList(out)

    def modes(self, about: Mapping | None = None,
              params: Mapping | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The normal modes of small oscillations about an equilibrium, numerically.

        Parameters
        ----------
        about : dict, optional
            The equilibrium, as for `frequencies`.
        params : dict, optional
            Parameter values instead of the defaults, {name: number or text}.

        Returns
        -------
        omegas : numpy.ndarray
            The angular frequencies, shape (n,), ascending (0 for an unstable mode).
        shapes : numpy.ndarray
            The mode shapes as columns, shape (n, n), M-normalized.

        Examples
        --------
        >>> omegas, shapes = mechbook.load("lim-2031").modes(about={"theta": "pi"},
        ...                                                   params={"omega": 2})  # doctest: +SKIP
        """
        import numpy as np

        values = parameter_values(self.problem.model, params)
        w2, shapes = self.linear(about).numeric_modes(values)
        return np.sqrt(np.clip(w2, 0, None)), shapes

    def simulate(self, t_end: float = 10.0, **options) -> Simulation:
        """Integrate the full nonlinear equations of motion (as `mechbook simulate`).

        Parameters
        ----------
        t_end : float, default 10
            The end of the run (it starts at t = 0).
        init : dict, optional
            The initial state, {coordinate or coordinate + 'dot': number or text}; what it
            leaves out comes from the problem's `initial:`, else 0 (with neither, the run
            starts at rest 0.1 from the first stable equilibrium, and says so).
        params : dict, optional
            Parameter values instead of the defaults, {name: number or text}.
        method : str, optional
            DOP853 (default; Radau when the run is stiff), RK45, Radau, LSODA, RK4,
            leapfrog, yoshida4, midpoint, or taylor (heyoka).
        accuracy : float, optional
            The accuracy wanted: the method and the tolerance are chosen from it.
        rtol, atol, max_step, step : float, optional
            Tolerances (adaptive methods) or the step (fixed-step methods).
        points : int, default 2001
            Samples recorded (adaptive methods).
        backend : str, optional
            How the equations are compiled (docs/numerics.md).

        Returns
        -------
        Simulation
            The trajectory (`t`, `q`, `qdot`), the drift of each conserved quantity,
            `to_xarray()`, `plot()`, `store()`.

        Examples
        --------
        >>> run = mechbook.load("lim-2031").simulate(t_end=5, init={"theta": 1.0},
        ...                                          params={"omega": 8})   # doctest: +SKIP
        >>> run.drifts                                                       # doctest: +SKIP
        {'energy_function': 1.2e-10}
        """
        refuse_unknown("simulate", options, SIMULATE_OPTIONS)
        t_end = args.simulate_options(t_end, options)
        options["init"] = texts(options.get("init"), "init")
        options["parameters"] = texts(options.pop("params", None))
        if options.get("backend") is None:
            options.pop("backend", None)
        run = simulate(self.problem.fast, self.name, t_span=(0.0, float(t_end)), **options)
        return Simulation(run, self.problem.fast.system(self.name))

    def ode_function(self, params: Mapping | None = None,
                     inputs: Sequence[str] = ()) -> OdeFunction:
        """The equations of motion as a fast function dy/dt = f(t, y, u), y = (q, q̇), for
        `scipy.integrate.solve_ivp` or one's own integrator or controller (what PyDy's
        `generate_ode_function` gives, its "specifieds" given per call).

        Parameters
        ----------
        params : dict, optional
            Parameter values instead of the defaults, {name: number or text}; they are
            compiled in.
        inputs : list of str, optional
            Parameters given per call instead (a force, a torque: what a controller sets
            at each step). A driven coordinate the problem leaves free (`{free: true}`) is
            always an input: its value, rate and acceleration.

        Returns
        -------
        OdeFunction
            Callable as f(t, y, u) (f(t, y) without inputs); `states` names y's
            components, `inputs` u's; `initial(init)` is the state `simulate(init=...)`
            starts from.

        Examples
        --------
        >>> from scipy.integrate import solve_ivp
        >>> f = mechbook.load("lim-2031").ode_function(inputs=["omega"])     # doctest: +SKIP
        >>> sol = solve_ivp(f, (0, 5), f.initial({"theta": 1.0}), args=([6.0],))  # doctest: +SKIP
        """
        values = parameter_values(self.problem.model, params)
        return OdeFunction(self.problem.fast, self.name, values, inputs)

    def _readable(self, expr):
        if not self.problem.simplify:
            return expr

        return try_simplify(expr, self.problem.simplify_seconds)

    def _repr_latex_(self) -> str:
        return "$\\displaystyle " + r" \\ ".join(
            [f"L = {sp.latex(self.lagrangian)}"] + [sp.latex(e) for e in self.eom]) + "$"

    def _repr_html_(self) -> str:
        return (f"<p>system <b>{html.escape(self.name)}</b> of {html.escape(self.problem.id)}"
                f"</p><p>L =</p>{math(self.lagrangian)}<p>equations of motion</p>"
                f"{math(self.eom)}")


def _momentum(q: sp.Symbol) -> sp.Symbol:
    return sp.Symbol(f"p_{q}")
