"""Problem files: load, validate, and turn declarations into SymPy symbols and expressions.

A problem holds shared parameters and one or more systems (a problem whose parts use
different physical set-ups, say a free and a driven chain, declares `systems:`), or none: a
problem about tensors and bodies declares only those (mechbook/model/declared.py).
Everything a system says is parsed with the safe parser; an error names the file and line.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field
from pathlib import Path

import sympy as sp

from mechbook.errors import ExpressionError
from mechbook.model.books import file_id_error
from mechbook.model.continuum import field_of
from mechbook.model.expr import CONSTANTS, DECLARABLE, FUNCTIONS, Operator, parse
from mechbook.model.functional import functional_of
from mechbook.model.input_limits import check_problem_counts, decode, read_bytes
from mechbook.model.schema import validate
from mechbook.model.yamlio import Document, loads

T = sp.Symbol("t", real=True)
RESERVED = {"t"} | set(CONSTANTS) | (set(FUNCTIONS) - DECLARABLE)
SYSTEM_KEYS = ("coordinates", "driven", "particles", "rigid_bodies", "gravity", "springs",
               "kinetic", "potential", "lagrangian", "velocity_potential", "constraints",
               "velocity_constraints", "rolling",
               "forces", "torques", "friction", "attractors", "dissipation", "string", "average",
               "approximation", "equilibria", "initial", "compute", "doc")
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
    """A problem file's declarations, as data: nothing built from it is kept here (its
    systems and declared objects are kept by model.built.Built, which an Analysis owns)."""

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
    functions: dict = field(default_factory=dict)  # name -> Operator (arbitrary functions)

    @property
    def book(self) -> str:
        return self.id.split("-")[0]

    def names(self) -> dict[str, sp.Basic]:
        names: dict[str, sp.Basic] = {n: p.symbol for n, p in self.parameters.items()}
        names.update(self.functions)
        return names

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


def _function(doc: Document, name: str, spec: dict, params: dict) -> Operator:
    """An arbitrary smooth function of one argument, as the book keeps it (a field B_z(r)).

    It is realized as a polynomial c0 + c1*x + ... + cd*x**d whose coefficients are
    parameters `<name>_c<k>` (real, any sign), sampled like every other parameter: an
    identity between expressions in the function's values and derivatives at a point holds
    for every smooth function exactly when it holds for every such polynomial of degree at
    least the highest derivative used, so random coefficients test it as random parameter
    values test any other identity. `degree` (default 6) bounds the derivatives a check may
    use; `values` gives the coefficients' defaults (default 1/(k+1)!, a gentle function)."""
    if name in params or name in RESERVED:
        raise doc.error(("functions", name), f"{name!r} is already a name")
    degree = spec.get("degree", 6)
    defaults = spec.get("values") or [1.0 / math.factorial(k + 1) for k in range(degree + 1)]
    if len(defaults) != degree + 1:
        raise doc.error(("functions", name, "values"), f"give {degree + 1} coefficients")
    coeffs = []
    for k in range(degree + 1):
        cname = f"{name}_c{k}"
        if cname in params:
            raise doc.error(("functions", name), f"{cname!r} is already a parameter")
        params[cname] = Parameter(cname, sp.Symbol(cname, real=True), float(defaults[k]),
                                  f"coefficient of x**{k} in the function {name}")
        coeffs.append(params[cname].symbol)

    def realize(x):
        return sum((c * x**k for k, c in enumerate(coeffs)), sp.S.Zero)

    return Operator(name, realize, (1, 1))


def load_problem(path: str | Path) -> Problem:
    """Load and validate a problem file; raise SpecError naming file and line on any fault."""
    raw = read_bytes(path)
    doc = loads(decode(raw, str(path)), str(path))
    validate(doc, "problem")
    check_problem_counts(doc)
    data = doc.data
    params = {n: _parameter(doc, n, s) for n, s in data["parameters"].items()}
    functions = {}
    for name, spec in (data.get("functions") or {}).items():
        functions[name] = _function(doc, name, spec or {}, params)
    if "systems" in data:
        inline = [k for k in SYSTEM_KEYS if k in data]
        if inline:
            raise doc.error((inline[0],), "with 'systems:' every system key goes inside a system")
        systems = {n: SystemSpec(n, s, ("systems", n)) for n, s in data["systems"].items()}
    elif "coordinates" in data:
        systems = {"main": SystemSpec("main", {k: data[k] for k in SYSTEM_KEYS if k in data}, ())}
    else:  # no system: declared vectors, tensors and bodies, or a functional, only
        stray = [k for k in SYSTEM_KEYS if k in data and k != "doc"]
        if stray:
            raise doc.error((stray[0],), "'coordinates' is required (or a 'systems' mapping) "
                            f"for a system; {stray[0]!r} belongs to one")
        systems = {}
    why = file_id_error(data["id"], path)
    if why:
        raise doc.error(("id",), why)
    sha = hashlib.sha256(raw).hexdigest()
    problem = Problem(data["id"], data["title"], data["source"], str(path), doc, params, systems,
                      sha, data.get("description", ""), functions=functions)
    problem.conditions = [problem.parse(c, ("conditions", i), relation=True)
                          for i, c in enumerate(data.get("conditions", []))]
    if not all(bool(c.subs(problem.values())) for c in problem.conditions):
        raise doc.error(("conditions",), "the default parameter values violate the conditions")
    functional_of(doc, problem.names())  # refused now, at its line (model.built keeps one)
    if "field" in data:  # checked now (file and line), built again by model.built.Built
        field_of(doc, problem.names())
    return problem
