"""Parameter values and initial states, for the Python API.

One way to evaluate at other parameter values: `params={name: value}` on every numeric
method (`frequencies`, `modes`, `simulate`, `ode_function`, and a linearization's
`exponents`, `frequencies`, `stability`). `p.parameters` shows the defaults and cannot be
changed: an assignment would silently change nothing, so it is refused, naming `params=`.
Keys are names or SymPy symbols; values are numbers or text (read by the safe parser, and
may use the other parameters' defaults), as `mechbook simulate --param` reads them.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from numbers import Real

import numpy as np
import sympy as sp

from mechbook.app.api import args
from mechbook.errors import InputError, NotFoundError
from mechbook.model.hints import did_you_mean

# keyword arguments people reach for, and what mechbook calls them
ALIASES = {"initial": "init", "initial_conditions": "init", "initial_state": "init",
           "ics": "init", "y0": "init", "x0": "init", "parameters": "params",
           "param": "params", "p": "params", "constants": "params", "t_span": "t_end",
           "tf": "t_end", "t_final": "t_end", "duration": "t_end", "tol": "rtol",
           "n_points": "points", "npoints": "points", "num": "points"}


class Parameters(Mapping):
    """The default parameter values by name: read-only (use `params=` to evaluate
    elsewhere)."""

    def __init__(self, values: dict[str, float], problem_id: str):
        self._values, self._id = dict(values), problem_id

    def __getitem__(self, name: str) -> float:
        return self._values[str(name)]

    def __iter__(self) -> Iterator[str]:
        return iter(self._values)

    def __len__(self) -> int:
        return len(self._values)

    def __setitem__(self, name, value) -> None:
        raise TypeError(f"the parameters of {self._id} are its defaults and are not changed "
                        f"here (a change would affect nothing): evaluate at other values "
                        f"with params=, e.g. p.frequencies(numeric=True, params={{{str(name)!r}"
                        f": {value!r}}}) or p.simulate(params=...)")

    def __delitem__(self, name) -> None:
        raise TypeError(f"the parameters of {self._id} are its defaults and are not removed "
                        "here: evaluate at other values with params=")

    def __repr__(self) -> str:
        return f"Parameters({self._values!r})"


def parameter_values(model, params: Mapping | None) -> dict[sp.Symbol, float]:
    """The default values with `params` ({name or symbol: number or text}) applied."""
    values = dict(model.values())
    for key, given in args.mapping("params", params).items():
        name = str(key)
        if name not in model.parameters:
            hint = did_you_mean(name, model.parameters)
            raise NotFoundError(f"{name!r} is not a parameter of {model.id} (parameters: "
                                f"{', '.join(model.parameters)})" + (f"; {hint}" if hint
                                                                       else ""))
        param = model.parameters[name]
        value = _number(model, name, given)
        if param.positive and not value > 0:
            raise InputError(f"parameter {name} of {model.id} is positive, got {value}")
        values[param.symbol] = value
    return values


def _number(model, name: str, given) -> float:
    if isinstance(given, Real) and not isinstance(given, bool):
        value = args.number(f"params[{name!r}]", given, -math.inf, math.inf)
    elif isinstance(given, str | sp.Basic):
        expr = model.parse(given, ()) if isinstance(given, str) else given  # a SymPy object
        try:
            value = float(expr.subs(model.values()))
        except (TypeError, ValueError):
            raise InputError(f"parameter {name}: {given!r} is not a number") from None
    else:
        raise InputError(f"parameter {name}: {given!r} is not a number (a number, or text "
                         "such as '2*pi')")
    if not np.isfinite(value):
        raise InputError(f"parameter {name}: {given!r} is not finite")
    return value


def texts(params: Mapping | None, what: str = "params") -> dict[str, str]:
    """{name or symbol: number or text} as {name: text}, for the simulation's reader
    (InputError naming `what` for anything else: a list, a number too large for a float,
    NaN, infinities)."""
    out = {}
    for k, v in args.mapping(what, params).items():
        if isinstance(v, Real) and not isinstance(v, bool):
            out[str(k)] = repr(args.number(f"{what}[{str(k)!r}]", v, -math.inf, math.inf))
        elif isinstance(v, str | sp.Basic):
            out[str(k)] = str(v)
        else:
            raise InputError(f"{what}[{str(k)!r}]: {v!r:.60} is not a number (a number, or "
                             "text such as '2*pi')")
    return out


def refuse_unknown(method: str, given: Mapping, known: tuple[str, ...]) -> None:
    """A TypeError naming the keyword `method` takes instead of an unknown one."""
    for name in given:
        if name in known:
            continue
        meant = ALIASES.get(name)
        hint = (f"did you mean {meant!r}?" if meant in known else
                did_you_mean(name, known) or f"it takes: {', '.join(known)}")
        raise TypeError(f"{method}() got an unexpected keyword argument {name!r}; {hint}")
