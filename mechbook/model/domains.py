"""Where a coordinate may be: `positive`, `nonnegative` or a `range: [lo, hi]`.

A radius is positive, a polar angle lies in [0, pi]: a coordinate's domain says where the
problem's description holds. `positive` and `nonnegative` become the symbol's assumptions
(SymPy's solve then drops r = 0 and r < 0 itself, and a random state is drawn positive); a
range is kept beside it. The engine's equilibria, the samplers and the simulations ask
this module whether a value is inside (`Domain.contains`), and draw inside it (`sample`).
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass

import sympy as sp


@dataclass(frozen=True)
class Domain:
    """An interval of a coordinate's values; bounds are expressions in the parameters."""

    name: str
    lo: sp.Expr | None = None  # None: unbounded
    hi: sp.Expr | None = None
    lo_open: bool = False
    hi_open: bool = False

    @property
    def text(self) -> str:
        """How the domain reads: 'r > 0', '0 <= theta <= pi'."""
        lo = None if self.lo is None else sp.sstr(self.lo)
        hi = None if self.hi is None else sp.sstr(self.hi)
        left = "" if lo is None else f"{lo} {'<' if self.lo_open else '<='} "
        right = "" if hi is None else f" {'<' if self.hi_open else '<='} {hi}"
        if hi is None and lo is not None:
            return f"{self.name} {'>' if self.lo_open else '>='} {lo}"
        return f"{left}{self.name}{right}"

    def bounds(self, values: dict) -> tuple[float, float]:
        """(lo, hi) as floats at `values` (infinite where unbounded)."""
        lo = -math.inf if self.lo is None else float(self.lo.subs(values))
        hi = math.inf if self.hi is None else float(self.hi.subs(values))
        return lo, hi

    def contains(self, x: float, values: dict, tol: float = 1e-12) -> bool:
        """Whether the value `x` lies in the domain at the parameter values `values`."""
        lo, hi = self.bounds(values)
        scale = tol * max(1.0, abs(lo) if math.isfinite(lo) else 0.0,
                          abs(hi) if math.isfinite(hi) else 0.0)
        above = x > lo + scale if self.lo_open else x >= lo - scale
        below = x < hi - scale if self.hi_open else x <= hi + scale
        return above and below

    def clip(self, lo: float, hi: float, values: dict) -> tuple[float, float]:
        """A search interval [lo, hi] narrowed to the domain (open ends moved inside)."""
        dlo, dhi = self.bounds(values)
        width = hi - lo
        if math.isfinite(dlo):
            lo = max(lo, dlo + (1e-3 * width if self.lo_open else 0.0))
        if math.isfinite(dhi):
            hi = min(hi, dhi - (1e-3 * width if self.hi_open else 0.0))
        return lo, hi

    def sample(self, rng: random.Random, values: dict) -> float:
        """A random value inside the domain (for random states)."""
        lo, hi = self.bounds(values)
        if math.isfinite(lo) and math.isfinite(hi):
            return rng.uniform(lo, hi) if hi > lo else lo
        if math.isfinite(lo):
            return lo + rng.uniform(0.1, 1.0) * max(1.0, abs(lo))
        if math.isfinite(hi):
            return hi - rng.uniform(0.1, 1.0) * max(1.0, abs(hi))
        return rng.uniform(-1.0, 1.0)


def assumptions(spec: dict | None) -> dict:
    """SymPy assumptions of a coordinate's symbol from its declaration."""
    spec = spec or {}
    if spec.get("positive"):
        return {"positive": True}
    if spec.get("nonnegative"):
        return {"nonnegative": True, "real": True}
    return {"real": True}


def domain_of(name: str, spec: dict | None, parse) -> Domain | None:
    """The declared domain of coordinate `name` (None: the whole real line). `parse(text,
    sub)` reads a range's bounds (the problem's parser, so an error names the line)."""
    spec = spec or {}
    if spec.get("positive"):
        return Domain(name, sp.S.Zero, None, lo_open=True)
    if spec.get("nonnegative"):
        return Domain(name, sp.S.Zero, None)
    if "range" in spec:
        lo, hi = (parse(x, ("range", i)) for i, x in enumerate(spec["range"]))
        return Domain(name, lo, hi)
    return None


def outside(point: dict, domains: dict, values: dict) -> str | None:
    """Why `point` ({coordinate symbol: value}) is outside a coordinate's domain at the
    parameter values `values`, or None where it is inside (or cannot be evaluated)."""
    for sym, dom in domains.items():
        if sym not in point:
            continue
        value = point[sym]
        try:
            z = complex(sp.N(value.subs(values), 20)) if isinstance(value, sp.Basic) \
                else complex(value)
        except (TypeError, ValueError, ZeroDivisionError, OverflowError):
            continue
        if abs(z.imag) > 1e-9 * max(1.0, abs(z.real)):
            continue  # not real: another question (mechbook.engine.existence)
        if not dom.contains(z.real, values):
            return f"{sym} = {sp.sstr(point[sym])} is outside {dom.text}"
    return None
