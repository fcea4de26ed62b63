"""mechbook: textbook mechanics problems as declarative Lagrangian systems, checked.

    import mechbook
    p = mechbook.load("lim-2031")            # a problem; p.lagrangian, p.eom, p.check(), ...
    frames = mechbook.results("results/mechbook.h5")   # the store as pandas DataFrames

`load`, `Problem` and `results` are imported on first use (PEP 562), so `import mechbook`
(and the command line's --help) does not load SymPy, NumPy or the engine.
"""

from mechbook.version import __version__

__all__ = ["Problem", "load", "results", "__version__"]

_LAZY = {"load": "mechbook.app.api.problem", "Problem": "mechbook.app.api.problem",
         "results": "mechbook.app.api.frames"}


def __getattr__(name: str):
    if name in _LAZY:
        if _LAZY[name] == "mechbook.app.api.problem":
            # on first use (PEP 562): `import mechbook` stays light
            from mechbook.app.api import problem as module
        else:
            # on first use (PEP 562): `import mechbook` stays light
            from mechbook.app.api import frames as module
        return getattr(module, name)
    raise AttributeError(f"module 'mechbook' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
