"""How a quantity registers: its entry, the decorator and shared key schemas (a leaf the
quantity modules import; mechbook.verify.registry, above them, holds the whole table)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

# schema fragments shared by several quantities' keys
EXPR = {"$ref": "#/$defs/expr"}
POINT = {"$ref": "#/$defs/point"}
NAME = {"type": "string", "pattern": "^[A-Za-z][A-Za-z0-9_]*$"}  # a coordinate or symbol
LIMIT = {"type": "object", "required": ["parameter", "to"], "additionalProperties": False,
         "properties": {"parameter": {"type": "string"}, "to": {"enum": ["0", "oo", 0]},
                        "order": {"type": "integer", "minimum": 0, "maximum": 3}}}
ESTIMATE = {"type": "object", "required": ["rtol"], "additionalProperties": False,
            "properties": {"values": {"type": "object",
                                      "additionalProperties": {"$ref": "#/$defs/expr"}},
                           "rtol": {"type": "number", "exclusiveMinimum": 0, "maximum": 0.5}}}
REGION = {"type": "object", "minProperties": 1,
          "additionalProperties": {"type": "array", "minItems": 2, "maxItems": 2,
                                   "items": EXPR}}


@dataclass(frozen=True)
class Quantity:
    name: str
    check: Callable
    book: str  # what `book:` holds
    how: str  # how it is checked
    keys: dict = field(default_factory=dict)  # extra part keys -> JSON-Schema fragments
    names: Callable | None = None  # ctx -> the names its `book:` may use beyond ctx.names
    literals: tuple = ()  # words a `book:` value may be instead of an expression
    needs_system: bool = True  # False: tensors and bodies, checked without a system
    complex_values: bool = False  # its expressions may hold complex constants (sqrt(-1))
    # changes of one value the check does not see by definition (mechbook.verify.power):
    # "shift" (a constant added), "scale" (a factor), "function" (a conserved quantity's
    # function), "direction" (a mode shape's length); stated in docs/answers.md
    equivalent: tuple | Callable = ()
    # how other stages use the quantity, as plain names they map to their own code (verify
    # imports neither): the independent checks that vouch for it (mechbook.crosscheck.
    # problem.CROSSCHECKS), how the report shows the engine's value (mechbook.app.report.values'
    # DISPLAYS), the `mechbook sweep --quantity` whose grid its book value is drawn on
    crosschecks: tuple[str, ...] = ()
    display: str | None = None
    sweeps: tuple[str, ...] = ()


QUANTITIES: dict[str, Quantity] = {}


def quantity(name: str, *, book: str, how: str, keys: dict | None = None,
             names: Callable | None = None, literals: tuple = (), needs_system: bool = True,
             complex_values: bool = False, equivalent: tuple | Callable = (),
             crosschecks: tuple[str, ...] = (), display: str | None = None,
             sweeps: tuple[str, ...] = ()) -> Callable[[Callable], Callable]:
    """Register the decorated function as the check of quantity `name` (`names`: a function
    of the part's context giving the names its book value may use beyond the usual ones,
    e.g. a polynomial's variable; `mechbook validate` parses with them; `literals`: words
    the book value may be instead, e.g. "stable"; `needs_system`: False for quantities of
    declared tensors and bodies, which a problem without a system can have;
    `complex_values`: its values are complex on purpose, so its expressions may hold
    constants such as sqrt(-1), which are refused elsewhere; `crosschecks`, `display`,
    `sweeps`: names of the cross-checks that vouch for it, of how the report shows the
    engine's value, of the sweeps that draw its book value — see `Quantity`)."""
    def register(fn):
        if name in QUANTITIES and QUANTITIES[name].check is not fn:
            raise ValueError(f"quantity {name!r} registered twice")
        QUANTITIES[name] = Quantity(name, fn, book, how, dict(keys or {}), names,
                                    tuple(literals), needs_system, complex_values,
                                    equivalent if callable(equivalent) else tuple(equivalent),
                                    tuple(crosschecks), display, tuple(sweeps))
        return fn

    return register


def registered(name: str) -> Quantity:
    """The entry of a registered quantity (all are registered once mechbook.verify.registry,
    which imports every quantity module, is imported: answers.py imports it)."""
    return QUANTITIES[name]
