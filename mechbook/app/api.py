"""The Python API: a problem loaded by id, its derived results as SymPy objects.

    >>> import mechbook
    >>> p = mechbook.load("lim-2031")
    >>> p.lagrangian                         # a SymPy expression
    >>> p.eom                                # Lagrange's equations, M·q̈ = f, as sp.Eq
    >>> p.frequencies(about={"theta": "pi"}) # normal frequencies about an equilibrium
    >>> p.check()                            # the book's answers, part by part
    >>> p.simulate(t_end=5)                  # the full nonlinear motion, with energy drift

A problem with several systems answers for each through `p.system("name")`; the shortcuts
on `p` itself need a problem with one system. Text given to the API (an `about:` point) goes
through the same safe parser as problem files. Results are simplified for reading
(`simplify=True`, as `mechbook solve`; each simplification has a time limit); checks and
simulations use the unsimplified engine, as `mechbook check` does. Objects show themselves
in a notebook (`_repr_latex_`, `_repr_html_`).
"""

from __future__ import annotations

import html
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import sympy as sp

from mechbook.app.display import MathDict, MathList
from mechbook.app.linearization import Linearization, linearization
from mechbook.app.mathml import math
from mechbook.core.compile import as_expr
from mechbook.engine.analysis import Analysis
from mechbook.errors import NotFoundError
from mechbook.model.books import Book, book_of
from mechbook.model.catalog import problem_path, root
from mechbook.model.problem import Problem as Model
from mechbook.model.problem import load_problem
from mechbook.records import FAILING, CrossCheck, Outcome


def load(problem_id: str, root_dir: str | Path | None = None,
         simplify: bool = True) -> Problem:
    """The problem `problem_id` of the tree at `root_dir` (default: $MECHBOOK_ROOT or the
    nearest parent holding problems/)."""
    base = Path(root_dir) if root_dir is not None else root()
    return Problem(load_problem(problem_path(problem_id, base)), base, simplify)


class SystemView:
    """One system's derived results as SymPy objects (computed on first use, cached)."""

    def __init__(self, problem: Problem, name: str):
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
        return list(self._sys.q)

    @property
    def lagrangian(self) -> sp.Expr:
        return self._readable(self._sys.lagrangian)

    @property
    def kinetic(self) -> sp.Expr:
        return self._readable(self._sys.kinetic)

    @property
    def potential(self) -> sp.Expr:
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
        return MathDict(self._dyn.solved)

    @property
    def momenta(self) -> dict[sp.Symbol, sp.Expr]:
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
        return bool(self._dyn.energy_conserved)

    @property
    def hamiltonian(self) -> sp.Expr:
        return self._dyn.hamiltonian

    @property
    def equilibria(self) -> list[dict]:
        """The equilibria SymPy finds in closed form that exist at the default values (real,
        inside the coordinates' domains: mechbook.engine.domains)."""
        from mechbook.engine.domains import existing

        points, _ = existing(self._an.equilibria(self.name).symbolic, self._sys,
                             self.problem.model.values())
        return MathList(MathDict(p) for p in points)

    def point(self, about: dict | None = None) -> dict:
        """An equilibrium as {coordinate symbol: value}: `about` ({name: text or number}),
        or the system's one stable equilibrium when `about` is None."""
        if about is None:
            return self._an.default_point(self.name)
        sys = self._sys
        out = {}
        for name, val in about.items():
            key = str(name)
            if key not in sys.coord_names:
                raise NotFoundError(f"{key!r} is not a coordinate of {self.problem.id} "
                               f"({', '.join(sys.coord_names)})")
            if isinstance(val, str):
                val = self.problem.model.parse(val, (), dict(sys.names))
            out[sys.q[sys.coord_names.index(key)]] = as_expr(val)
        return out

    def linear(self, about: dict | None = None):
        """The linearized system M·δq̈ + C·δq̇ + K·δq = F about an equilibrium."""
        return self._an.linear(self.name, self.point(about))

    def linearize(self, about: dict | None = None, steady: dict | None = None,
                  reduce: bool | None = None) -> Linearization:
        """The linearization (ż = A·z + B·r as sympy's Linearizer gives it; M, C, K where
        second order; the degrees of freedom) about `about` ({coordinate: value}; default
        the one stable equilibrium), or about the steady motion with `steady` rates (those a
        constraint fixes are solved for; `reduce`: Routh's reduction, default unless the
        system has constraints). mechbook.app.linearization.Linearization says more.

        >>> lin = p.linearize(about={"theta": "pi/2"}, steady={"psi": "W"})  # doctest: +SKIP
        >>> lin.A, lin.freedoms, lin.exponents({"W": 3})                     # doctest: +SKIP
        """
        point = self.point(about) if (about is not None or not steady) else {}
        model = self.problem.model
        if steady:
            rates = self.point(steady)
            sys = self._sys
            if reduce is None:
                reduce = not (sys.constraints or sys.velocity_constraints)
            lin = self._an.steady_linear(self.name, rates, point, reduce)
        else:
            lin = self._an.linear(self.name, point)
        return linearization(lin, model.values())

    def frequencies(self, about: dict | None = None, numeric: bool = False) -> list:
        """Normal angular frequencies about an equilibrium: SymPy expressions, or floats at
        the default parameter values with `numeric=True`."""
        lin = self.linear(about)
        if numeric:
            return [float(w) for w in lin.numeric_frequencies(self.problem.model.values())]
        return MathList(self._readable(w) for w in lin.frequencies)

    def modes(self, about: dict | None = None) -> tuple[Any, Any]:
        """(ω, mode shapes as columns) at the default parameter values."""
        import numpy as np

        w2, shapes = self.linear(about).numeric_modes(self.problem.model.values())
        return np.sqrt(np.clip(w2, 0, None)), shapes

    def simulate(self, t_end: float = 10.0, **options) -> Simulation:
        """Integrate the full nonlinear equations (see mechbook.numerics.simulate.simulate
        for the options: method, accuracy, init, parameters, rtol, atol, points, ...)."""
        from mechbook.numerics.simulate import simulate

        run = simulate(self.problem.fast, self.name, t_span=(0.0, float(t_end)), **options)
        return Simulation(run)

    def _readable(self, expr):
        if not self.problem.simplify:
            return expr
        from mechbook.core.timeout import try_simplify

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


class Problem:
    """A loaded problem: its data (`model`), and derived results through `system(name)` or,
    for a problem with one system, directly (`p.lagrangian`, `p.eom`, ...)."""

    simplify_seconds = 5.0

    def __init__(self, model: Model, base: Path, simplify: bool = True):
        self.model, self.base, self.simplify = model, Path(base), simplify
        self.analysis = Analysis(model, simplify=simplify)
        self.fast = Analysis(model) if simplify else self.analysis  # checks, simulations
        self._views: dict[str, SystemView] = {}

    id = property(lambda self: self.model.id)
    title = property(lambda self: self.model.title)
    source = property(lambda self: self.model.source)
    description = property(lambda self: self.model.description.strip())

    @property
    def book(self) -> Book | None:
        return book_of(self.id, self.base)

    @property
    def parameters(self) -> dict[str, float]:
        """Default parameter values by name."""
        return {n: p.value for n, p in self.model.parameters.items()}

    @property
    def systems(self) -> list[str]:
        return list(self.model.systems)

    def system(self, name: str | None = None) -> SystemView:
        if name is None:
            if len(self.model.systems) == 1:
                name = self.systems[0]
            elif "main" in self.model.systems:
                name = "main"  # of several systems, the one named main is the default
            else:
                raise NotFoundError(f"{self.id} has several systems ({', '.join(self.systems)}): "
                               "choose one with p.system(name)")
        if name not in self.model.systems:
            raise NotFoundError(f"{self.id} has no system {name!r} ({', '.join(self.systems)})")
        if name not in self._views:
            self._views[name] = SystemView(self, name)
        return self._views[name]

    # the only system's results, for the common case
    lagrangian = property(lambda self: self.system().lagrangian)
    kinetic = property(lambda self: self.system().kinetic)
    potential = property(lambda self: self.system().potential)
    eom = property(lambda self: self.system().eom)
    accelerations = property(lambda self: self.system().accelerations)
    momenta = property(lambda self: self.system().momenta)
    cyclic = property(lambda self: self.system().cyclic)
    energy = property(lambda self: self.system().energy)
    hamiltonian = property(lambda self: self.system().hamiltonian)
    equilibria = property(lambda self: self.system().equilibria)

    def frequencies(self, about: dict | None = None, numeric: bool = False) -> list:
        return self.system().frequencies(about, numeric)

    def linearize(self, about: dict | None = None, steady: dict | None = None,
                  reduce: bool | None = None) -> Linearization:
        """The only system's linearization (SystemView.linearize)."""
        return self.system().linearize(about, steady, reduce)

    def modes(self, about: dict | None = None):
        return self.system().modes(about)

    def simulate(self, t_end: float = 10.0, system: str | None = None,
                 **options) -> Simulation:
        return self.system(system).simulate(t_end, **options)

    def check(self, crosscheck: bool = True, store: str | Path | None = None) -> CheckResult:
        """Check the problem as loaded against its answer key in this process (and
        cross-check it); `store` also writes the run to that HDF5 file."""
        from mechbook.app.run import RunOptions
        from mechbook.app.service import check_loaded

        run = check_loaded(self.model, self.base, RunOptions(crosscheck=crosscheck), store)
        return CheckResult(self.id, run.outcomes, run.crosschecks, run.error, run.seconds)

    def _repr_latex_(self) -> str:
        if len(self.systems) != 1:
            return f"$\\text{{{self.id}: systems {', '.join(self.systems)}}}$"
        return self.system()._repr_latex_()

    def _repr_html_(self) -> str:
        head = (f"<h3>{html.escape(self.id)}: {html.escape(self.title)}</h3>"
                f"<p><i>{html.escape(self.source)}</i></p>"
                f"<p>{html.escape(self.description)}</p>")
        if len(self.systems) != 1:
            return head + f"<p>systems: {html.escape(', '.join(self.systems))}</p>"
        return head + f"<p>L =</p>{math(self.lagrangian)}"

    def __repr__(self) -> str:
        return f"<mechbook problem {self.id}: {self.title}>"


@dataclass
class CheckResult:
    """The outcome of checking one problem: one Outcome per answer part, the cross-checks."""

    problem: str
    outcomes: list[Outcome]
    crosschecks: list[CrossCheck] = field(default_factory=list)
    error: str | None = None
    seconds: float = 0.0

    @property
    def ok(self) -> bool:
        """No part failed or errored, no cross-check failed, and the problem ran."""
        return (self.error is None and all(o.status not in FAILING
                                           for o in self.outcomes)
                and not any(x.failed for x in self.crosschecks))

    def to_frame(self):
        """The outcomes as a pandas DataFrame (needs pandas: pip install mechbook[data])."""
        from mechbook.core.optional import require

        pd = require("pandas", "data", "CheckResult.to_frame()")
        return pd.DataFrame([o.as_dict() for o in self.outcomes])

    def __repr__(self) -> str:
        rows = [f"{o.part:<16} {o.quantity:<20} {o.status:<12} {o.method}"
                for o in self.outcomes]
        head = f"{self.problem}: " + (self.error or ("ok" if self.ok else "FAILED"))
        return "\n".join([head, *rows])

    def _repr_html_(self) -> str:
        rows = "".join(f"<tr><td>{html.escape(o.part)}</td><td>{html.escape(o.quantity)}</td>"
                       f"<td>{html.escape(o.status)}</td><td>{html.escape(o.method)}</td>"
                       f"<td>{html.escape(o.detail)}</td></tr>" for o in self.outcomes)
        return (f"<p>{html.escape(self.problem)}: {html.escape(self.error or '')}</p>"
                "<table><tr><th>part</th><th>quantity</th><th>outcome</th><th>method</th>"
                f"<th>detail</th></tr>{rows}</table>")


class Simulation:
    """A finished simulation: the trajectory, the drift of every conserved quantity."""

    def __init__(self, run):
        self.run = run

    t = property(lambda self: self.run.trajectory.t)
    q = property(lambda self: self.run.trajectory.q)
    qdot = property(lambda self: self.run.trajectory.qd)
    coordinates = property(lambda self: list(self.run.model.names))

    @property
    def drifts(self) -> dict[str, float]:
        """Largest relative drift of each conserved quantity the engine found."""
        return {d.name: float(d.relative) for d in self.run.drifts}

    def plot(self, path: str | Path) -> Path:
        from mechbook.numerics.plot import plot_simulation

        return plot_simulation(self.run, path)

    def store(self, path: str | Path, name: str | None = None) -> str:
        """Write the run into an HDF5 store; returns its group's path there."""
        from mechbook.app.store import write_simulation

        run = self.run
        name = name or f"{run.system}-{run.trajectory.method}"
        write_simulation(run.problem_id, name, run.arrays(), run.settings(),
                         {f"monitors/{d.name}": d.attrs() for d in run.drifts}, path)
        return f"/problems/{run.problem_id}/simulations/{name}"

    def _repr_html_(self) -> str:
        rows = "".join(f"<tr><td>{html.escape(k)}</td><td>{v:.2e}</td></tr>"
                       for k, v in self.drifts.items())
        traj = self.run.trajectory
        return (f"<p>{html.escape(self.run.problem_id)} [{html.escape(self.run.system)}]: "
                f"{html.escape(traj.method)}, {len(traj.t)} samples to t = "
                f"{traj.t[-1]:.4g}</p><table><tr><th>conserved quantity</th>"
                f"<th>relative drift</th></tr>{rows}</table>")

    def __repr__(self) -> str:
        return (f"<simulation of {self.run.problem_id} [{self.run.system}], "
                f"{self.run.trajectory.method}, drifts {self.drifts}>")
