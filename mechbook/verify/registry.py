"""Every answer quantity, registered in one place: name → check, schema fragment, doc line.

A quantity is one function `check(ctx, value) -> Verdict` in a module of
mechbook.verify.quantities, registered with `@quantity(name, book=..., how=..., keys=...)`
(mechbook.verify.registration; this module imports every quantity module, so it sits above them):
`book` says what the part's `book:` value holds, `how` how it is checked (both become the
row of the table in docs/answers.md, which a test keeps equal to this registry), and `keys`
maps the part keys this quantity reads, beyond the common ones, to their JSON-Schema
fragments. The answer-key schema is assembled from the bundled base schema and these
registrations, so a key that does not apply to a part's quantity is an error with its line.
Adding a quantity is one new function (or module) and its registration.
"""

from __future__ import annotations

import copy
from functools import cache

import mechbook.verify.quantities  # noqa: F401 - every quantity module registers its checks
from mechbook.model.schema import bundled
from mechbook.verify.registration import QUANTITIES, Quantity

# part keys every quantity accepts (their schemas are in the bundled answers.json)
COMMON_KEYS = ("part", "cite", "quantity", "system", "book", "about", "steady", "reduce",
               "assume", "restrict", "define", "note", "verdict", "erratum", "unsupported",
               "origin")


def quantities() -> dict[str, Quantity]:
    """All registered quantities (this module imports the modules that register them)."""
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
    print(markdown_table())
