"""The Python API: a problem loaded by id, its derived results as SymPy objects.

    >>> import mechbook
    >>> p = mechbook.load("lim-2031")
    >>> p.lagrangian                         # a SymPy expression
    >>> p.eom                                # Lagrange's equations, M·q̈ = f, as sp.Eq
    >>> p.equilibria[0]["theta"]             # by the coordinate's name or its symbol
    >>> p.frequencies(about={"theta": "pi"}) # normal frequencies about an equilibrium
    >>> p.frequencies(numeric=True, params={"omega": 8})   # at other parameter values
    >>> p.check()                            # the book's answers, part by part
    >>> p.simulate(t_end=5).to_xarray()      # the full nonlinear motion, with energy drift
    >>> f = p.ode_function()                 # dy/dt = f(t, y) for solve_ivp

A problem with several systems answers for each through `p.system("name")`; the shortcuts
on `p` itself need a problem with one system (or take `system=`). Text given to the API
(an `about:` point, `params=`, `init=`) goes through the same safe parser as problem files.
Results are simplified for reading (`simplify=True`, as `mechbook solve`; each
simplification has a time limit); checks and simulations use the unsimplified engine, as
`mechbook check` does. Objects show themselves in a notebook (`_repr_latex_`,
`_repr_html_`). The system's methods live in mechbook.app.api.system, parameter values in
params (`params=`) and ode (the ODE function), the results in results.
"""

from __future__ import annotations

import functools
import html
from pathlib import Path

from mechbook.app.api import args
from mechbook.app.api.params import Parameters
from mechbook.app.api.results import CheckResult, Simulation
from mechbook.app.api.system import SystemView
from mechbook.app.output.mathml import math
from mechbook.app.running.run import RunOptions
from mechbook.app.running.service import check_loaded
from mechbook.engine.analysis import Analysis
from mechbook.errors import InputError, NotFoundError
from mechbook.model.books import Book, book_of
from mechbook.model.catalog import existing_problem_path, root
from mechbook.model.problem import Problem as Model
from mechbook.model.problem import load_problem

__all__ = ["CheckResult", "Problem", "Simulation", "SystemView", "load"]


def load(problem_id: str, root_dir: str | Path | None = None,
         simplify: bool = True) -> Problem:
    """Load a problem of a tree by its id.

    Parameters
    ----------
    problem_id : str
        ``<book>-<number>``, e.g. ``"lim-2031"``.
    root_dir : str or pathlib.Path, optional
        The tree holding problems/ and answers/ (default: $MECHBOOK_ROOT, else the
        nearest parent of the working directory that holds problems/).
    simplify : bool, default True
        Simplify derived results for reading (each within a time limit).

    Returns
    -------
    Problem
        The problem, its results derived on first use.

    Examples
    --------
    >>> p = mechbook.load("lim-2031")
    >>> p.title
    'Bead on a hoop spinning about a vertical diameter'
    """
    args.text("problem_id", problem_id, optional=False)
    base = args.path("root_dir", root_dir) if root_dir is not None else root()
    return Problem(load_problem(existing_problem_path(problem_id, base)), base, simplify)


def _on_the_system(name: str):
    """A method of the problem's only system (or of `system=`), documented there."""
    method = getattr(SystemView, name)

    @functools.wraps(method)
    def call(self, *args, system: str | None = None, **kwargs):
        return getattr(self.system(system), name)(*args, **kwargs)

    return call


def _of_the_system(result: property) -> property:
    """A result of the problem's only system (p.system().NAME), with its docstring."""
    name, doc = result.fget.__name__, result.__doc__
    return property(lambda self: getattr(self.system(), name),
                    doc=f"{doc}\n\n(Of the problem's only system, or the one named main: "
                        "``p.system(name)`` for another.)")


class Problem:
    """A loaded problem: its data (`model`), and derived results through `system(name)` or,
    for a problem with one system, directly (`p.lagrangian`, `p.eom`, ...; the numeric
    methods take `system=` to name one of several)."""

    simplify_seconds = 5.0

    def __init__(self, model: Model, base: Path, simplify: bool = True):
        self.model, self.base, self.simplify = model, Path(base), simplify
        self.analysis = Analysis(model, simplify=simplify)
        # checks, simulations: unsimplified, on the same systems (each built once)
        self.fast = Analysis(model, built=self.analysis.built) if simplify else self.analysis
        self._views: dict[str, SystemView] = {}

    id = property(lambda self: self.model.id, doc="The problem id, ``<book>-<number>``.")
    title = property(lambda self: self.model.title, doc="The problem's title, our own words.")
    source = property(lambda self: self.model.source,
                      doc="The book and the problem's number in it.")
    description = property(lambda self: self.model.description.strip(),
                           doc="The problem file's own short description of the system.")

    @property
    def book(self) -> Book | None:
        """The book of books.yaml the problem belongs to (None if it declares none)."""
        return book_of(self.id, self.base)

    @property
    def parameters(self) -> Parameters:
        """The default parameter values by name (read-only: the numeric methods take
        `params=` for other values)."""
        return Parameters({n: p.value for n, p in self.model.parameters.items()}, self.id)

    @property
    def systems(self) -> list[str]:
        """The names of the problem's systems (``main`` for a problem with one)."""
        return list(self.model.systems)

    def system(self, name: str | None = None) -> SystemView:
        """One system of the problem.

        Parameters
        ----------
        name : str, optional
            The system's name; default the only one (or the one named ``main``).

        Returns
        -------
        SystemView
            Its derived results and numeric methods.

        Examples
        --------
        >>> mechbook.load("lim-2043").system("main").lagrangian   # doctest: +SKIP
        """
        args.text("name", name)
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
    lagrangian = _of_the_system(SystemView.lagrangian)
    kinetic = _of_the_system(SystemView.kinetic)
    potential = _of_the_system(SystemView.potential)
    eom = _of_the_system(SystemView.eom)
    accelerations = _of_the_system(SystemView.accelerations)
    momenta = _of_the_system(SystemView.momenta)
    cyclic = _of_the_system(SystemView.cyclic)
    energy = _of_the_system(SystemView.energy)
    hamiltonian = _of_the_system(SystemView.hamiltonian)
    equilibria = _of_the_system(SystemView.equilibria)
    frequencies = _on_the_system("frequencies")
    modes = _on_the_system("modes")
    linearize = _on_the_system("linearize")
    simulate = _on_the_system("simulate")
    ode_function = _on_the_system("ode_function")

    def check(self, crosscheck: bool = True, store: str | Path | None = None) -> CheckResult:
        """Check the problem as loaded against its answer key, in this process.

        Parameters
        ----------
        crosscheck : bool, default True
            Also run the independent cross-checks.
        store : str or pathlib.Path, optional
            Also write the run to this HDF5 store.

        Returns
        -------
        CheckResult
            One outcome per answer part, the cross-checks; `ok`, `to_frame()`.

        Examples
        --------
        >>> mechbook.load("lim-2031").check().ok       # doctest: +SKIP
        True
        """
        if not isinstance(crosscheck, bool):
            raise InputError(f"crosscheck: {crosscheck!r:.60} is not True or False")
        store = args.path("store", store) if store is not None else None
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
