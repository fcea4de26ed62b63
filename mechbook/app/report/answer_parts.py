"""The answer parts of a problem page: for each, the book's value next to the engine's and
the numbers at one admissible point (mechbook.app.report.values)."""

from __future__ import annotations

import sympy as sp

from mechbook.app.report.values import (
    book_math,
    display_of,
    engine_value,
    numeric_pair,
    stability_boundary,
)
from mechbook.verify.context import Context


def parts(page, analysis, key, views: dict) -> list[dict]:
    values = analysis.problem.values()
    default = next(iter(analysis.problem.systems), None)
    rows = []
    for part in key.parts:
        data = part.data
        row = {"part": part.name, "cite": data.get("cite", ""), "quantity": part.quantity,
               "origin": data.get("origin", "book"), "system": part.system,
               "note": str(data.get("note", "")).strip(), "book": "", "engine": None,
               "numeric": None, "erratum": None, "unsupported": data.get("unsupported"),
               "boundary": None}
        rows.append(row)
        ctx = page.step(f"part {part.name}", lambda part=part: Context(analysis, part))
        row["book"] = book_math(ctx, data.get("book"))
        if "erratum" in data:
            err = data["erratum"]
            row["erratum"] = {"corrected": book_math(ctx, err.get("corrected"),
                                                     ("erratum", "corrected")),
                              "derivation": str(err.get("derivation", "")).strip()}
        if row["unsupported"] or ctx is None:
            continue
        view = views.get(part.system or default)
        value = page.step(f"part {part.name}: the engine's value",
                          lambda ctx=ctx, view=view: engine_value(ctx, view, values))
        if value is not None:
            row["engine"] = page.show(value)
        if display_of(part.quantity) == "sylvester_criterion":
            found = page.step(f"part {part.name}: the engine's boundary",
                              lambda ctx=ctx, view=view: stability_boundary(ctx, view, values))
            if found:
                row["boundary"] = page.show([sp.Eq(s, r, evaluate=False)
                                             for s, roots in found.items() for r in roots])
        row["numeric"] = page.step(f"part {part.name}: values at one point",
                                   lambda ctx=ctx, view=view: numeric_pair(ctx, view, values))
    return rows
