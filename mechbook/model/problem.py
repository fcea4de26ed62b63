"""Problem files: load, validate, and turn declarations into SymPy symbols and expressions.

A problem holds shared parameters and one or more systems (a problem whose parts use
different physical set-ups, say a free and a driven chain, declares `systems:`). Everything
a system says is parsed with the safe parser; an error names the file and line.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from pathlib import Path

import sympy as sp

from mechbook.errors import ExpressionError
from mechbook.model.expr import CONSTANTS, FUNCTIONS, parse
from mechbook.model.schema import validate
from mechbook.model.yamlio import Document, load

T = sp.Symbol("t", real=True)
RESERVED = {"t"} | set(CONSTANTS) | set(FUNCTIONS)
SYSTEM_KEYS = ("coordinates", "driven", "particles", "rigid_bodies", "gravity", "springs",
               "kinetic", "potential", "lagrangian", "velocity_potential", "constraints",
               "forces", "dissipation", "approximation", "equilibria", "initial", "compute", "doc")
DEFAULT_VALUES = {"g": 9.81}  # documented default for the gravitational acceleration
DEFAULT_VALUE = 1.0


@dataclass
class Parameter:
    name: str
    symbol: sp.Symbol
    value: float
    doc: str = ""
    small: bool = False

    @property
    def positive(self) -> bool:
        return bool(self.symbol.is_positive)


@dataclass
class SystemSpec:
    """One system's declarations, still as data, with a path for error lines."""

    name: str
    data: dict
    path: tuple


@dataclass
class Problem:
    id: str
    title: str
    source: str
    file: str
    doc: Document
    parameters: dict[str, Parameter]
    systems: dict[str, SystemSpec]
    sha256: str
    description: str = ""
    conditions: list = field(default_factory=list)
    _cache: dict = field(default_factory=dict, repr=False)

    @property
    def book(self) -> str:
        return self.id.split("-")[0]

    def names(self) -> dict[str, sp.Basic]:
        return {n: p.symbol for n, p in self.parameters.items()}

    def values(self) -> dict[sp.Symbol, float]:
        return {p.symbol: p.value for p in self.parameters.values()}

    def parse(self, text, path: tuple, names: dict | None = None, relation: bool = False):
        """Parse text at `path` of this file; an ExpressionError becomes a SpecError."""
        try:
            return parse(text, names if names is not None else self.names(), relation)
        except ExpressionError as exc:
            raise self.doc.error(path, str(exc)) from None


def _parameter(doc: Document, name: str, spec: dict | None) -> Parameter:
    spec = spec or {}
    if name in RESERVED or name.startswith("_"):
        raise doc.error(("parameters", name), f"{name!r} is reserved and cannot be a parameter")
    positive = spec.get("positive", True)
    real = spec.get("real", True)
    assumptions = {"real": real} if real else {}
    if positive:
        assumptions["positive"] = True
    elif spec.get("nonzero"):
        assumptions["nonzero"] = True
    value = float(spec.get("value", DEFAULT_VALUES.get(name, DEFAULT_VALUE)))
    if positive and value <= 0:
        raise doc.error(("parameters", name, "value"), f"{name} is positive but value is {value}")
    return Parameter(name, sp.Symbol(name, **assumptions), value, spec.get("doc", ""),
                     bool(spec.get("small", False)))


def load_problem(path: str | Path) -> Problem:
    """Load and validate a problem file; raise SpecError naming file and line on any fault."""
    doc = load(path)
    validate(doc, "problem")
    data = doc.data
    params = {n: _parameter(doc, n, s) for n, s in data["parameters"].items()}
    if "systems" in data:
        inline = [k for k in SYSTEM_KEYS if k in data]
        if inline:
            raise doc.error((inline[0],), "with 'systems:' every system key goes inside a system")
        systems = {n: SystemSpec(n, s, ("systems", n)) for n, s in data["systems"].items()}
    else:
        if "coordinates" not in data:
            raise doc.error((), "'coordinates' is required (or a 'systems' mapping)")
        systems = {"main": SystemSpec("main", {k: data[k] for k in SYSTEM_KEYS if k in data}, ())}
    expected = Path(path).stem
    if not data["id"].endswith(expected):
        raise doc.error(("id",), f"id {data['id']!r} does not match the file name {expected!r}")
    sha = hashlib.sha256(Path(path).read_bytes()).hexdigest()
    problem = Problem(data["id"], data["title"], data["source"], str(path), doc, params, systems,
                      sha, data.get("description", ""))
    problem.conditions = [problem.parse(c, ("conditions", i), relation=True)
                          for i, c in enumerate(data.get("conditions", []))]
    if not all(bool(c.subs(problem.values())) for c in problem.conditions):
        raise doc.error(("conditions",), "the default parameter values violate the conditions")
    return problem
