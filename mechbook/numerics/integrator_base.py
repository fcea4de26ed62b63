"""What every integration method shares: the `Integrator` interface (one method, its options,
`check` that it applies to a model, `solve`), the `Trajectory` it returns and
`IntegratorError`. The methods themselves are one module per family (scipy_methods,
fixed_step, taylor), named in mechbook.numerics.methods.METHODS."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from mechbook.errors import MechbookError
from mechbook.numerics.rhs import Model, structure


class IntegratorError(MechbookError):
    """The method does not apply to this system, or its iteration failed."""


@dataclass
class Trajectory:
    """The result of any integrator: samples of (t, q, q̇), plus how they were made."""

    t: np.ndarray
    q: np.ndarray  # (n, N)
    qd: np.ndarray  # (n, N)
    method: str
    settings: dict
    nfev: int = 0
    success: bool = True
    message: str = ""
    sol: Callable | None = None  # dense output (SciPy methods with dense_output=True)
    t_events: list = field(default_factory=list)
    y_events: list = field(default_factory=list)

    @property
    def y(self) -> np.ndarray:
        return np.vstack((self.q, self.qd))


class Integrator:
    """One integration method; a subclass implements `solve` (and says whether it is
    symplectic or adaptive, and what structure of model it requires). Constructed as
    `cls(name, **options)` by numerics.integrators.make_integrator, from its entry in
    numerics.methods.METHODS, with the options that entry's family takes."""

    symplectic: ClassVar[bool] = False
    adaptive: ClassVar[bool] = False
    requires: ClassVar[str] = ""  # "", "separable" or "canonical"

    def __init__(self, name: str, **options):
        self.name = name  # the method's name, as its results carry it
        self.options = options

    def check(self, model: Model, t0: float, q0: np.ndarray, qd0: np.ndarray) -> None:
        """Raise IntegratorError if the method does not apply to `model`."""
        if not self.requires:
            return
        st = structure(model, (t0, q0, qd0))
        if self.requires == "separable" and not st.separable:
            hint = " (use method 'midpoint')" if st.canonical else ""
            raise IntegratorError(f"{self.name} needs a separable Hamiltonian "
                                  f"H = p·M⁻¹p/2 + V(q): {st.reason}{hint}")
        if self.requires == "canonical" and not st.canonical:
            raise IntegratorError(f"{self.name} needs a conservative Lagrangian system "
                                  f"quadratic in the velocities: {st.reason}")

    def solve(self, model: Model, t_span: tuple[float, float], q0: np.ndarray,
              qd0: np.ndarray, t_eval: Sequence[float] | None = None,
              events: Sequence[Callable] | None = None) -> Trajectory:
        raise NotImplementedError

