"""The built-in answer quantities: the table built from the modules listed here, the answer
key schema of a table, and the table of quantities in docs/answers.md.

A quantity is one function `check(ctx, value) -> Verdict` in a module of
mechbook.verify.quantities, declared with `@quantity(name, book=..., how=..., keys=...)`, the
decorator of that module's `FAMILY` (mechbook.verify.registration): `book` says what the
part's `book:` value holds, `how` how it is checked (both become the row of the table in
docs/answers.md, which a test keeps equal to this table), and `keys` maps the part keys this
quantity reads, beyond the common ones, to their JSON-Schema fragments. The answer-key schema
is assembled from the bundled base schema and a table's entries, so a key that does not
apply to a part's quantity is an error with its line. Adding a quantity is one new function
in a family's module; a new family is a new module and its line in `MODULES`. A caller may
check with a table of its own (`QuantityTable.of(...)`, passed to `load_answers`).
"""

from __future__ import annotations

import copy
from functools import cache

from mechbook.model.schema import bundled
from mechbook.verify.quantities import (
    access,
    action,
    adiabatic,
    brackets,
    canonical,
    chaos,
    continuum,
    equations,
    equilibria,
    expressions,
    extremum,
    functional,
    hamilton_jacobi,
    motion,
    oscillations,
    parts,
    perturbation,
    phase,
    response,
    rotation,
    scattering,
    stability,
    steady,
    tensors,
    trajectory,
    words,
)
from mechbook.verify.registration import QuantityTable

# the modules whose families make up the built-in table, one per family of quantities
MODULES = (access, action, adiabatic, brackets, canonical, chaos, continuum, equations,
           equilibria, expressions, extremum, functional, hamilton_jacobi, motion,
           oscillations, parts, perturbation, phase, response, rotation, scattering,
           stability, steady, tensors, trajectory, words)

# part keys every quantity accepts (their schemas are in the bundled answers.json)
COMMON_KEYS = ("part", "cite", "quantity", "system", "book", "about", "steady", "reduce",
               "assume", "restrict", "define", "note", "verdict", "erratum", "unsupported",
               "origin")


@cache
def default_quantities() -> QuantityTable:
    """The built-in table: every quantity of the modules in `MODULES`."""
    return QuantityTable.of(*(module.FAMILY for module in MODULES))


def answers_schema(table: QuantityTable | None = None) -> dict:
    """The answer-key schema for `table` (default: the built-in one): the bundled base, with
    the quantity names, their extra keys' schemas, and for each quantity the keys a part of
    it may carry."""
    return _schema(default_quantities() if table is None else table)


@cache
def _schema(table: QuantityTable) -> dict:
    schema = copy.deepcopy(bundled("answers"))
    part = schema["$defs"]["part"]
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


def markdown_table(table: QuantityTable | None = None) -> str:
    """The table of quantities in docs/answers.md (of the built-in table by default)."""
    table = default_quantities() if table is None else table
    rows = ["| quantity | `book` | check |", "| --- | --- | --- |"]
    for name in sorted(table):
        q = table[name]
        keys = ", ".join(f"`{k}`" for k in q.keys)
        extra = f" (keys: {keys})" if keys else ""
        rows.append(f"| `{name}`{extra} | {q.book} | {q.how} |")
    return "\n".join(rows)


if __name__ == "__main__":  # python -m mechbook.verify.registry: the table for the docs
    print(markdown_table())
