"""What one system of the API (mechbook.app.api.system) asks of the problem it belongs to.

A module below both the problem (mechbook.app.api.problem, which hands out its systems) and
the system, so that the system names the problem's type without importing it back: the
`Problem` class keeps this contract (tests/test_api_controller.py checks it does)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol, runtime_checkable

if TYPE_CHECKING:
    from mechbook.engine.analysis import Analysis
    from mechbook.model.problem import Problem as Model


@runtime_checkable
class LoadedProblem(Protocol):
    """A loaded problem as its systems see it."""

    model: Model  # the problem file, read
    analysis: Analysis  # derived, simplified for reading when `simplify` is set
    fast: Analysis  # derived, unsimplified (for numbers: simulations, ODE functions)
    simplify: bool
    simplify_seconds: float

    @property
    def id(self) -> str:
        """The problem id, ``<book>-<number>``."""
        ...
