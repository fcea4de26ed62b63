"""A sweep's definition as plain data (it travels to cluster workers), and the grid's size
checked before anything is allocated. Imports no NumPy or SymPy: the command line reads
the quantities from here for its choices."""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from mechbook.core.backends import DEFAULT_BACKEND
from mechbook.errors import MechbookError
from mechbook.model.catalog import existing_problem_path

if TYPE_CHECKING:
    from mechbook.engine.linear_grid import Axis

QUANTITIES = ("frequencies", "stability", "drift")
AMPLITUDE = "amplitude"
MAX_POINTS = 10_000_000  # points of one grid: its arrays are held in this process
BYTES_PER_VALUE = 8 * 3  # float64, the blocks and their concatenation, the book's overlay


def check_grid(axes: list[Axis], memory_mb: float = 0.0, modes: int = 1) -> int:
    """The grid's size, refused (MechbookError) before anything is allocated when it has
    more than MAX_POINTS points or its arrays would need more than `memory_mb` MB (0: no
    bound): a sweep is bounded in memory like a check."""
    points = math.prod(a.n for a in axes)
    if points > MAX_POINTS:
        raise MechbookError(f"the grid has {points:,} points; at most {MAX_POINTS:,} (use "
                            "fewer points per axis)")
    need = points * (2 * modes + 4) * BYTES_PER_VALUE / 2**20
    if memory_mb and need > memory_mb:
        raise MechbookError(f"the grid's {points:,} points x {modes} mode(s) would need about "
                            f"{need:,.0f} MB, more than the memory bound of {memory_mb:g} MB "
                            "(--memory): use fewer points or raise the bound")
    return points


@dataclass(frozen=True)
class SweepSpec:
    """Everything that defines a sweep, as plain data (it travels to cluster workers)."""

    pid: str
    files: tuple[tuple[str, bytes], ...]  # the problem's and answer key's files
    quantity: str
    axes: tuple[Axis, ...]
    system: str | None = None
    about: tuple[tuple[str, str], ...] = ()
    steady: tuple[tuple[str, str], ...] = ()
    part: str | None = None
    backend: str = DEFAULT_BACKEND

    @property
    def key(self) -> str:
        h = hashlib.sha256(repr((self.pid, self.quantity, self.axes, self.system, self.about,
                                 self.steady, self.part, self.backend)).encode())
        for name, data in self.files:
            h.update(name.encode() + b"\0" + data)
        return h.hexdigest()


def make_spec(pid: str, base: Path, quantity: str, axes: list[Axis], *,
              system: str | None = None, about: dict | None = None,
              steady: dict | None = None, part: str | None = None,
              backend: str = DEFAULT_BACKEND) -> SweepSpec:
    # at call time: the command line reads this module at start-up (distributed: NumPy)
    from mechbook.app.running.distributed import tree_files

    if quantity not in QUANTITIES:
        raise MechbookError(f"unknown quantity {quantity!r}; known: {', '.join(QUANTITIES)}")
    check_grid(axes)
    existing_problem_path(pid, base)  # no such problem: the one message (and status)
    files = tree_files(pid, base)
    return SweepSpec(pid, tuple(sorted(files.items())), quantity, tuple(axes), system,
                     tuple((about or {}).items()), tuple((steady or {}).items()), part,
                     backend)
