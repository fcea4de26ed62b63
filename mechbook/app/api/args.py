"""The Python API's arguments checked before any work, with the bounds of the command line.

A notebook passes what it likes: `t_end=float("inf")` ran until killed, `points=10**12`
asked NumPy for 7 TiB, `params=[...]` raised AttributeError, `params={"m": 10**400}`
OverflowError. Every public function of the API checks its arguments here first: a bad one
is an `InputError` (mechbook's own, also a ValueError) naming the argument, what was given
and what is accepted; the bounds are those of the command line's options
(mechbook.app.options), so the API refuses what `mechbook simulate` refuses.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from numbers import Integral, Real
from pathlib import Path

from mechbook.app import options as opt
from mechbook.errors import InputError

SHOWN = 60  # characters of a bad value shown in the message


def _shown(value: object) -> str:
    try:
        text = repr(value)
    except Exception:  # noqa: BLE001 - an object whose repr fails still gets a message
        text = f"<{type(value).__name__}>"
    return text if len(text) <= SHOWN else text[:SHOWN] + "..."


def number(name: str, value: object, low: float, high: float, low_open: bool = False,
           high_open: bool = False) -> float:
    """`value` as a finite float in [low, high] (open ends where asked); InputError naming
    `name` otherwise (a bool, a huge integer, NaN and infinities included).

    Example: ``number("t_end", 5, 0, 1e9, low_open=True)`` is 5.0."""
    if isinstance(value, bool) or not isinstance(value, Real):
        raise InputError(f"{name}: {_shown(value)} is not a number")
    try:
        x = float(value)
    except (OverflowError, ValueError, TypeError):
        raise InputError(f"{name}: {_shown(value)} is too large for a float") from None
    if not math.isfinite(x):
        raise InputError(f"{name}: {_shown(value)} is not a finite number")
    if x < low or (low_open and x == low) or x > high or (high_open and x == high):
        raise InputError(f"{name}: {_shown(value)} is outside {'(' if low_open else '['}"
                         f"{low:g}, {high:g}{')' if high_open else ']'}")
    return x


def integer(name: str, value: object, low: int, high: int) -> int:
    """`value` as an int in [low, high]; InputError naming `name` otherwise."""
    if isinstance(value, bool) or not isinstance(value, Integral):
        raise InputError(f"{name}: {_shown(value)} is not an integer")
    if not low <= int(value) <= high:
        raise InputError(f"{name}: {value} is outside [{low}, {high}]")
    return int(value)


def mapping(name: str, value: object) -> Mapping:
    """`value` if it is a mapping (None: empty); InputError naming `name` otherwise."""
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise InputError(f"{name}: {_shown(value)} is not a mapping; give a dict such as "
                         f"{name}={{'m': 2}}")
    return value


def text(name: str, value: object, optional: bool = True) -> str | None:
    """`value` if it is a string (None where `optional`); InputError naming `name`."""
    if value is None and optional:
        return None
    if not isinstance(value, str):
        raise InputError(f"{name}: {_shown(value)} is not a string")
    return value


def path(name: str, value: object) -> Path:
    """`value` as a Path (a str or os.PathLike); InputError naming `name` otherwise."""
    if isinstance(value, Path):
        return value
    if not isinstance(value, str) or not value or "\0" in value:
        raise InputError(f"{name}: {_shown(value)} is not a path")
    return Path(value)


def simulate_options(t_end: object, options: dict) -> float:
    """The arguments of `simulate` checked as `mechbook simulate` checks its options
    (options are changed in place to plain numbers); the end time."""
    t = number("t_end", t_end, 0, opt.MAX_TIME, low_open=True)
    bounds = {"accuracy": (0, 1, True, True), "rtol": (0, 1, True, True),
              "atol": (0, 1e6, False, False), "max_step": (0, opt.MAX_TIME, True, False),
              "step": (0, opt.MAX_TIME, True, False)}
    for key, (low, high, low_open, high_open) in bounds.items():
        if options.get(key) is not None:
            options[key] = number(key, options[key], low, high, low_open, high_open)
    if options.get("points") is not None:
        options["points"] = integer("points", options["points"], 2, opt.MAX_POINTS)
    for key in ("method", "backend"):
        text(key, options.get(key))
    for key in ("init", "params"):
        mapping(key, options.get(key))
    return t
