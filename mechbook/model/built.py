"""What is built from one problem, each thing once: its systems, its declared vectors,
tensors and bodies, and its functional.

The builder keeps what it built, not the Problem (plain data that anyone may hold): an
engine Analysis owns one Built, so what a check built is what its Built holds, and a new
Analysis starts from nothing. `mechbook validate` uses one without the engine.
"""

from __future__ import annotations

from mechbook.model.continuum import FieldModel, field_of
from mechbook.model.declared import Declared, declared
from mechbook.model.functional import Functional, functional_of
from mechbook.model.problem import Problem
from mechbook.model.system import System, system_name, system_of


class Built:
    """One problem's systems and declared objects, each built on first use and kept."""

    def __init__(self, problem: Problem) -> None:
        self.problem = problem
        self._systems: dict[str, System] = {}
        self._declared: Declared | None = None
        self._functional: list[Functional | None] = []
        self._field: FieldModel | None = None

    def system(self, name: str | None = None) -> System:
        """The system `name` (or the only one, or `main`), built once. NotFoundError (a
        KeyError too) names the systems there are."""
        name = system_name(self.problem, name)
        if name not in self._systems:
            self._systems[name] = system_of(self.problem, name, self.declared)
        return self._systems[name]

    def declared(self) -> Declared:
        """The problem's declared vectors, tensors and bodies, built once."""
        if self._declared is None:
            self._declared = declared(self.problem)
        return self._declared

    def functional(self) -> Functional | None:
        """The problem's declared functional (None if it has none), built once."""
        if not self._functional:
            self._functional.append(functional_of(self.problem.doc, self.problem.names()))
        return self._functional[0]

    def field(self) -> FieldModel | None:
        """The problem's continuous field (`field:`), built once, or None if it has none."""
        if self._field is None and "field" in self.problem.doc.data:
            self._field = field_of(self.problem.doc, self.problem.names())
        return self._field

    def systems_built(self) -> list[System]:
        """The systems built so far, in the problem's order."""
        return [self._systems[n] for n in self.problem.systems if n in self._systems]

    def declared_built(self) -> Declared | None:
        """The declared objects if something asked for them, else None."""
        return self._declared
