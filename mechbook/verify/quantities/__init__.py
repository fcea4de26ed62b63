"""The answer quantities, one module per family; importing this package registers them all
(mechbook.verify.registry). A new family is a new module here and a line below."""

from mechbook.verify.quantities import (  # noqa: F401 - each module registers its checks
    access,
    adiabatic,
    equations,
    equilibria,
    expressions,
    extremum,
    motion,
    oscillations,
    parts,
    perturbation,
    phase,
    response,
    rotation,
    stability,
    steady,
    tensors,
    trajectory,
    words,
)
