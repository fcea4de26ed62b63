"""Every answer quantity, registered in one place: name → check, schema fragment, doc line.

A quantity is one function `check(ctx, value) -> Verdict` in a module of
mechbook.verify.quantities, registered with `@quantity(name, book=..., how=..., keys=...)`:
`book` says what the part's `book:` value holds, `how` how it is checked (both become the
row of the table in docs/answers.md, which a test keeps equal to this registry), and `keys`
maps the part keys this quantity reads, beyond the common ones, to their JSON-Schema
fragments. The answer-key schema is assembled from the bundled base schema and these
registrations, so a key that does not apply to a part's quantity is an error with its line.
Adding a quantity is one new function (or module) and its registration.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cache

from mechbook.model.schema import bundled

# part keys every quantity accepts (their schemas are in the bundled answers.json)
COMMON_KEYS = ("part", "cite", "quantity", "system", "book", "about", "steady", "reduce",
               "assume", "restrict", "define", "note", "verdict", "erratum", "unsupported",
               "origin")


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
    # imports neither): the independent checks that vouch for it (mechbook.crosscheck's
    # CROSSCHECKS), how the report shows the engine's value (mechbook.app.report.values'
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


def quantities() -> dict[str, Quantity]:
    """All registered quantities (importing the modules that register them)."""
    import mechbook.verify.quantities  # noqa: F401 - registers every quantity

    return QUANTITIES


@cache
def answers_schema() -> dict:
    """The answer-key schema: the bundled base, with the quantity names, their extra keys'
    schemas, and for each quantity the keys a part of it may carry."""
    schema = copy.deepcopy(bundled("answers"))
    part = schema["$defs"]["part"]
    table = quantities()
    part["properties"]["quantity"] = {"enum": sorted(table)}
    rules = []
    for q in table.values():
        for key, fragment in q.keys.items():
            known = part["properties"].get(key)
            if known is not None and known != fragment:
                raise ValueError(f"key {key!r} of quantity {q.name!r} has a schema that "
                                 "differs from another quantity's")
            part["properties"][key] = fragment
        rules.append({"if": {"properties": {"quantity": {"const": q.name}},
                             "required": ["quantity"]},
                      "then": {"propertyNames": {"enum": list(COMMON_KEYS) + list(q.keys)}}})
    part["allOf"] = rules
    return schema


def markdown_table() -> str:
    """The table of quantities in docs/answers.md."""
    rows = ["| quantity | `book` | check |", "| --- | --- | --- |"]
    for name in sorted(quantities()):
        q = QUANTITIES[name]
        keys = ", ".join(f"`{k}`" for k in q.keys)
        extra = f" (keys: {keys})" if keys else ""
        rows.append(f"| `{name}`{extra} | {q.book} | {q.how} |")
    return "\n".join(rows)


if __name__ == "__main__":  # python -m mechbook.verify.registry: the table for the docs
    # run as __main__, this module is a second copy: the quantities register in the one
    # imported by name, so the table comes from there (this copy's registry stays empty)
    from mechbook.verify.registry import markdown_table as _table

    print(_table())
