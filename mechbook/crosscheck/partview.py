"""What the cross-checks read of an answer part: the one door into mechbook.verify.

A cross-check vouches for a part at the part's own point, as the part's check reads it:
its system, the linear system about its `about:` (or `steady:`) point, its default
parameter values (with `assume:` and the key's own symbols), its parser (names from
`define:` included), and, for steady motions and trajectories, the family of steady rates
or the level set its quantity derives (for scattering, the orbit from infinity). Only this
module opens verify's `Context` and those quantity families; the rest of crosscheck/ asks a
`PartView` and never sees their insides.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import sympy as sp

from mechbook.engine.analysis import Analysis
from mechbook.verify.answers import Part
from mechbook.verify.compare import value
from mechbook.verify.context import Context
from mechbook.verify.context import split_named as _split_named
from mechbook.verify.quantities.brackets import bracket_claim
from mechbook.verify.quantities.canonical import hamiltonian_claim
from mechbook.verify.quantities.scattering import Beam
from mechbook.verify.quantities.steady import family
from mechbook.verify.quantities.trajectory import Motion

if TYPE_CHECKING:
    from mechbook.engine.lagrange import Dynamics
    from mechbook.engine.linear import LinearSystem
    from mechbook.engine.steady import SteadyFamily
    from mechbook.model.protocol import SystemLike


class PartView:
    """An answer part as a cross-check sees it (errors in the part: SpecError, raised here
    as its own check raises them)."""

    def __init__(self, analysis: Analysis, part: Part):
        self._ctx = Context(analysis, part)
        self.part = part

    @property
    def system(self) -> SystemLike:
        return self._ctx.system

    @property
    def dyn(self) -> Dynamics:
        return self._ctx.dyn

    @property
    def names(self) -> dict[str, sp.Basic]:
        return self._ctx.names

    def linear(self) -> LinearSystem:
        """The linear system about the part's point (UnsupportedError: none)."""
        return self._ctx.linear()

    def values(self) -> dict:
        """The parameter values the part is checked at by default."""
        return self._ctx.sampler.default()

    def parse(self, text: object, sub: tuple) -> sp.Expr:
        """An expression of the part at `sub` of its key (`text`: a value of the key as YAML
        read it), through the safe parser; SpecError if it is none."""
        return self._ctx.parse(text, sub)

    def number(self, key: str, values: dict) -> float:
        """The real value of the part's `key:` (a driving frequency) at `values`."""
        return value(self.parse(self.part.data[key], (key,)), values).real

    def steady_family(self) -> SteadyFamily:
        """The steady motions a `steady_rates`/`steady_exists` part derives
        (mechbook.verify.quantities.steady: `real_rates(values)`, `point`, `rates`, `x`)."""
        return family(self._ctx)

    def bracket(self) -> tuple | None:
        """A bracket part's (f, g, h, H): its functions and value in (q, p_q, t), H the
        symbol standing for the engine's Hamiltonian (mechbook.verify.quantities.brackets);
        None where the part names its own variables or Hamiltonian."""
        return bracket_claim(self._ctx)

    def new_hamiltonian(self) -> tuple | None:
        """A canonical map's new pairs, its values in (q, p_q, t) and the book's K (None
        where the part states no K or names its own variables)."""
        return hamiltonian_claim(self._ctx)

    def motion(self) -> Motion:
        """The trajectory a trajectory part derives (mechbook.verify.quantities.trajectory:
        `level`, `orbit(values)`, `measured(values)`)."""
        return Motion(self._ctx)

    def beam(self) -> Beam:
        """The orbit from infinity a scattering part names (mechbook.verify.quantities.
        scattering: `engine` (the reduction), `at(values)` (b, E), `value(...)`)."""
        return Beam(self._ctx)


def split_named(text: object) -> tuple[str | None, object]:
    """(name, value) of a first integral written `name = value` (verify's reading)."""
    return _split_named(text)
