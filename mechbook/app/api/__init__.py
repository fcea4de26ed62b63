"""The Python API: `mechbook.load(id)` -> a `Problem` whose derived results are SymPy objects,
its numbers at the default parameter values or at `params=` (docs/api.md). Import the API
from here; the modules inside are its parts:

    problem        `load` and `Problem`: one problem file, derived on first use, checked
    system         one system's results and numeric methods (`p.system(name)`)
    loaded         what a system asks of the problem it belongs to (below both)
    params         `params=` read and refused, the read-only defaults
    ode            the ODE function f(t, y, u), its inputs given per call
    linearization  the linearized ż = A·z + B·r about an equilibrium
    results        `CheckResult` and `Simulation` (pandas, xarray when asked for)
    animation      `animate()` and an inline `plot()` for a notebook
    display        results that show as mathematics in a notebook (lists and dicts)
    args           every argument checked with the command line's bounds
    frames         the store as pandas DataFrames: `mechbook.results(path)`

The names below load their module on first use (PEP 562), as `mechbook.load` does: `import
mechbook` and the command line's --help must not load SymPy and the engine.

May import: the stages below mechbook.app, its shared modules, and the packages below it:
running/ (a check), store/ (mechbook.results), report/ (the motion's frames for animate())
and output/ (MathML); of mechbook.app only the command line (`solve`) imports the API.
"""

from __future__ import annotations

import importlib

_HOME = {
    "load": "mechbook.app.api.problem",
    "Problem": "mechbook.app.api.problem",
    "SystemView": "mechbook.app.api.system",
    "CheckResult": "mechbook.app.api.results",
    "Simulation": "mechbook.app.api.results",
    "Parameters": "mechbook.app.api.params",
    "OdeFunction": "mechbook.app.api.ode",
    "Linearization": "mechbook.app.api.linearization",
    "MathDict": "mechbook.app.api.display",
    "MathList": "mechbook.app.api.display",
}
__all__ = sorted(_HOME)  # a test keeps each name found in its module


def __getattr__(name: str) -> object:
    if name not in _HOME:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(_HOME[name]), name)
    globals()[name] = value  # loaded once
    return value
