"""What a system offers the engine, the numerics, verification and the cross-checks.

Two kinds of object keep this contract: a `System` built from a problem file
(mechbook.model.system), and the system Routh's reduction leaves when the momenta of some
cyclic coordinates are held fixed (mechbook.engine.routh.ReducedSystem). Code that takes
either asks the contract, never `hasattr`: `reduced` says which kind it is, `full` is the
system built from the file (itself, or the one that was reduced), `held_momenta` the fixed
momenta of the cyclic coordinates taken out and `held` the symbols standing for them in
the reduced Lagrangian (both empty for a `System`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    import sympy as sp

    from mechbook.model.data import Data
    from mechbook.model.domains import Domain
    from mechbook.model.problem import Problem


class SystemLike(Protocol):
    """A system of coordinates q with a Lagrangian, as the engine derives from it."""

    problem: Problem
    name: str  # the system's name in its problem file (a reduced one keeps it)
    spec: dict[str, Data]  # the file's declarations of the system
    t: sp.Symbol
    q: list[sp.Symbol]  # coordinates, with their rates qd and accelerations qdd
    qd: list[sp.Symbol]
    qdd: list[sp.Symbol]
    coord_names: list[str]
    names: dict[str, sp.Basic]  # every name an expression of the system may use
    lagrangian: sp.Expr
    forces: list[sp.Expr]  # generalized forces not derived from a potential, per coordinate
    constraints: list[tuple[str, sp.Expr]]  # (name, g(q)) held by multipliers
    # (name, c(q, q̇, t)) linear in q̇, held by multipliers: velocity constraints, rolling
    velocity_constraints: list[tuple[str, sp.Expr]]
    small_params: list[sp.Symbol]  # parameters switched off at an equilibrium
    free_driven: list[tuple[sp.Symbol, sp.Symbol, sp.Symbol]]  # (y, ẏ, ÿ) driven freely
    domains: dict[sp.Symbol, Domain]  # coordinates' declared domains, where they are checked

    @property
    def reduced(self) -> bool:
        """Routh-reduced: some cyclic coordinates taken out at fixed momenta."""
        ...

    @property
    def full(self) -> SystemLike:
        """The system built from the file (a `System`, whose `reduced` is False): this one, or
        the one that was reduced."""
        ...

    @property
    def held_momenta(self) -> dict[sp.Symbol, sp.Expr]:
        """{cyclic coordinate taken out: its fixed momentum} ({} for a full system)."""
        ...

    @property
    def held(self) -> dict[sp.Symbol, sp.Expr]:
        """{symbol standing for a held momentum in the Lagrangian: its value} ({} for a
        full system)."""
        ...

    def dt(self, expr: sp.Expr) -> sp.Expr:
        """The total time derivative along the motion."""
        ...

    def numeric_values(self) -> dict[sp.Symbol, float]:
        """The parameters' default values."""
        ...
