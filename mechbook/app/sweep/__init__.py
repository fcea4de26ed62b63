"""`mechbook sweep`'s work: one result of a problem over a grid of parameter values (the
command itself: mechbook.app.cli.sweep). Import it from here; the modules inside are its
parts:

    spec          a sweep's definition as plain data, the grid's size checked (no NumPy)
    runner        the problem derived and compiled once, the grid evaluated in blocks
    precision     the float64 results against the 30-digit path at sampled points
    book_answer   the book's answer over the same grid
    storage       a sweep's result in the HDF5 store or a netCDF-4 file
    figures       its plots (matplotlib)
    text_summary  what the command prints

The names below load their module on first use (PEP 562): the command line reads `spec`'s
QUANTITIES for its option choices at start-up, and importing this package must not load
NumPy and SymPy for that.

May import: the stages below mechbook.app, its shared modules, store/ and running/ (a
pool of workers, a cluster); spec, read at start-up, nothing that loads NumPy or SymPy.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # what the names are, for a reader and a type checker
    from mechbook.app.sweep.figures import plot_sweep
    from mechbook.app.sweep.runner import BLOCK_ENTRIES, Sweeper, SweepResult, block_of, run_sweep
    from mechbook.app.sweep.spec import (
        AMPLITUDE,
        MAX_POINTS,
        QUANTITIES,
        SweepSpec,
        check_grid,
        make_spec,
    )
    from mechbook.app.sweep.storage import (
        STORE_POINTS,
        read_netcdf,
        read_store,
        stored_sweeps,
        write_netcdf,
        write_store,
    )
    from mechbook.app.sweep.text_summary import summary

_HOME = {
    **dict.fromkeys(("AMPLITUDE", "MAX_POINTS", "QUANTITIES", "SweepSpec", "check_grid",
                     "make_spec"), "mechbook.app.sweep.spec"),
    **dict.fromkeys(("BLOCK_ENTRIES", "Sweeper", "SweepResult", "block_of", "run_sweep"),
                    "mechbook.app.sweep.runner"),
    **dict.fromkeys(("STORE_POINTS", "read_netcdf", "read_store", "stored_sweeps",
                     "write_netcdf", "write_store"), "mechbook.app.sweep.storage"),
    "plot_sweep": "mechbook.app.sweep.figures",
    "summary": "mechbook.app.sweep.text_summary",
}
__all__ = [  # the same names as _HOME (a test keeps them equal)
    "AMPLITUDE", "BLOCK_ENTRIES", "MAX_POINTS", "QUANTITIES", "STORE_POINTS", "SweepResult",
    "SweepSpec", "Sweeper", "block_of", "check_grid", "make_spec", "plot_sweep", "read_netcdf",
    "read_store", "run_sweep", "stored_sweeps", "summary", "write_netcdf", "write_store",
]


def __getattr__(name: str) -> object:
    if name not in _HOME:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(_HOME[name]), name)
    globals()[name] = value  # loaded once
    return value
