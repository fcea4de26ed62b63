"""One problem's derived results, computed lazily and cached per system and per point.

The checker and the CLI both ask this object for what they need; nothing is derived that is
not asked for ("the engine computes only what the problem asks for"). It keeps everything
derived from its problem: the systems and declared objects (through its model.built.Built),
their dynamics, equilibria and linearizations, and what `reuse` was asked to keep; what a
check derived is what its Analysis holds (`derived`, which engine.derive stores).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TypeVar

import sympy as sp

from mechbook.core.numeval import is_zero
from mechbook.engine.equilibria import Equilibria
from mechbook.engine.lagrange import Dynamics
from mechbook.engine.linear import LinearSystem
from mechbook.engine.routh import ReducedSystem
from mechbook.engine.screen import screen
from mechbook.errors import UnsupportedError
from mechbook.model.built import Built
from mechbook.model.declared import Declared
from mechbook.model.functional import Functional
from mechbook.model.problem import Problem
from mechbook.model.system import System

T = TypeVar("T")


@dataclass(frozen=True)
class Derived:
    """What an analysis derived for one system so far (engine.derive stores it)."""

    system: System
    dynamics: Dynamics | None
    equilibria: Equilibria | None
    linear: list[LinearSystem]  # in the order they were asked for


class Analysis:
    def __init__(self, problem: Problem, simplify: bool = False, built: Built | None = None):
        """`built`: the systems and declared objects to start from (another analysis's
        `built`, shared: the API's simplified and plain analyses build each system once);
        by default, a new one."""
        self.problem = problem
        self.simplify = simplify
        self.built = built if built is not None else Built(problem)
        self._dyn: dict[str, Dynamics] = {}
        self._eq: dict[str, Equilibria] = {}
        self._lin: dict[tuple, LinearSystem] = {}
        self._reused: dict[tuple, object] = {}

    def system(self, name: str | None = None) -> System:
        return self.built.system(name)

    def declared(self) -> Declared:
        """The problem's declared vectors, tensors and bodies (built once)."""
        return self.built.declared()

    def functional(self) -> Functional | None:
        """The problem's declared functional, or None (built once)."""
        return self.built.functional()

    def derived(self) -> list[Derived]:
        """For each system built so far (in the problem's order), what was derived for it."""
        return [Derived(sys, self._dyn.get(sys.name), self._eq.get(sys.name),
                        [lin for key, lin in self._lin.items() if key[0] == sys.name])
                for sys in self.built.systems_built()]

    def dynamics(self, name: str | None = None) -> Dynamics:
        sys = self.system(name)
        if sys.name not in self._dyn:
            self._dyn[sys.name] = Dynamics(sys, self.simplify)
        return self._dyn[sys.name]

    def reuse(self, key: tuple, compute: Callable[[], T]) -> T:
        """compute() once per analysis for `key` (which must name everything the result
        depends on): two parts that ask the same question of the same motion (its event
        time, and how far a coordinate has moved by then) share one integration."""
        if key not in self._reused:
            self._reused[key] = compute()
        return self._reused[key]  # type: ignore[return-value]

    def equilibria(self, name: str | None = None) -> Equilibria:
        sys = self.system(name)
        if sys.name not in self._eq:
            self._eq[sys.name] = Equilibria(self.dynamics(name))
        return self._eq[sys.name]

    def linear(self, name: str | None, point: dict, given: dict | None = None) -> LinearSystem:
        """The linear system about the equilibrium `point` (an equilibrium where the
        parameters satisfy `given`, {parameter: expression}, when that is not empty)."""
        sys = self.system(name)
        key = (sys.name, tuple(sorted((str(k), sp.srepr(v)) for k, v in point.items())),
               _key(given))
        if key not in self._lin:
            self._lin[key] = self.equilibria(name).linearize(point, given=given)
        return self._lin[key]

    def steady_linear(self, name: str | None, rates: dict, point: dict,
                      reduce: bool = True, given: dict | None = None) -> LinearSystem:
        """Linearization about a steady motion: coordinates turning at `rates`, the others
        at `point`. By Routh's reduction (momenta of the cyclic coordinates fixed) unless
        `reduce` is false: then every coordinate is kept, the turning ones as deviations
        from the uniform turn (their zero roots stay in the secular equation)."""
        sys = self.system(name)
        key = (sys.name, "steady" if reduce else "steady-full",
               tuple(sorted((str(k), sp.srepr(v)) for k, v in rates.items())),
               tuple(sorted((str(k), sp.srepr(v)) for k, v in point.items())), _key(given))
        if key not in self._lin:
            if reduce:
                reduced = ReducedSystem(sys, rates, point, self.simplify)
                dyn = Dynamics(reduced, self.simplify)
                self._lin[key] = Equilibria(dyn).linearize(point, given=given)
            else:
                self._lin[key] = self.equilibria(name).linearize(point, rates, given)
        return self._lin[key]

    def stable_equilibria(self, name: str | None = None,
                          budget: float | None = None) -> list[dict]:
        """Closed-form equilibria that are stable at the default parameter values (the
        search given up after `budget` seconds when no part asked for it)."""
        eq = self.equilibria(name)
        values = self.problem.values()
        out = []
        for point in eq.within(budget):
            try:
                ok = self.linear(name, point).numeric_stability(values) == "stable"
            except (UnsupportedError, TypeError, ValueError):
                continue
            if ok:
                out.append(point)
        return out

    DEFAULT_POINT_BUDGET = 5.0  # seconds to look for closed-form equilibria

    def default_point(self, name: str | None = None) -> dict:
        """The equilibrium to expand about when a question names none: the stable one
        (among the closed-form equilibria SymPy finds within DEFAULT_POINT_BUDGET s), or
        the origin when the system is already linear with no static equilibrium issue.
        Numeric first: when a root finder sees one stable equilibrium at the default values
        and it is the origin, the origin it is, without a closed-form search."""
        origin = self._stable_origin(name)
        if origin is not None:
            return origin
        try:
            stable = self.stable_equilibria(name, self.DEFAULT_POINT_BUDGET)
        except UnsupportedError:
            stable = []
        distinct = []
        values = self.problem.values()
        for pt in stable:
            num = tuple(complex(sp.N(v.subs(values))) for v in pt.values())
            if not any(max(abs(a - b) for a, b in zip(num, d, strict=True)) < 1e-9
                       for d in distinct):
                distinct.append(num)
        if len(distinct) == 1:
            return stable[0]
        sys = self.system(name)
        origin = {q: sp.S.Zero for q in sys.q}
        if len(distinct) == 0:
            # a system with a zero-frequency mode (a free translation) has no isolated
            # equilibrium; the origin is one if the conditions vanish there
            if all(is_zero(c.subs(origin)) for c in self.equilibria(name).conditions):
                return origin
        raise UnsupportedError("choosing the equilibrium: the answer must name `about:` "
                               f"({len(distinct)} stable equilibria found)")


    def _stable_origin(self, name: str | None) -> dict | None:
        """The origin, if it is an equilibrium and the only stable one a root finder sees
        at the default values (every other equilibrium found is unstable); else None."""

        sys = self.system(name)
        eq = self.equilibria(name)
        try:
            found = screen(eq, self.problem.values()).found
            origin = {q: sp.S.Zero for q in sys.q}
            if not all(is_zero(c.subs(origin)) for c in eq.conditions):
                return None
        except UnsupportedError:
            return None
        maybe = [f for f in found if f.stability != "unstable"]
        if len(maybe) == 1 and maybe[0].isolated and maybe[0].stability == "stable" \
                and max(abs(float(x)) for x in maybe[0].point) < 1e-9:
            return origin
        return None


def _key(given: dict | None) -> tuple:
    return tuple(sorted((str(k), sp.srepr(v)) for k, v in (given or {}).items()))
