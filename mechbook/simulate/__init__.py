"""Numerical integration of the full nonlinear equations of motion.

    rhs          the equations compiled once per problem (SymEngine/LLVM with cse by default)
    integrators  SciPy's solve_ivp methods and fixed-step RK4 / symplectic methods, one
                 interface
    monitors     drift of the conserved quantities the engine found
    stiffness    time scales from the linearized equations; is a run stiff?
    accuracy     method and tolerance for a requested accuracy (a rule measured by
                 bench/work_precision.py)
    core         initial conditions and `simulate`, the entry point of `mechbook simulate`
    plot         coordinates against time and the phase portrait (matplotlib, Agg)
"""

from .core import Simulation, simulate
from .integrators import METHODS, Trajectory, integrate
from .rhs import DEFAULT_BACKEND, Model, build_model

__all__ = ["DEFAULT_BACKEND", "METHODS", "Model", "Simulation", "Trajectory", "build_model",
           "integrate", "simulate"]
