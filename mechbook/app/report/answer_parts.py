"""The answer parts of a problem page: for each, the book's value next to the engine's and
the numbers at one admissible point (mechbook.app.report.values)."""

from __future__ import annotations

from mechbook.app.report.values import book_math, engine_value, numeric_pair
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
               "numeric": None, "erratum": None, "unsupported": data.get("unsupported")}
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
        row["numeric"] = page.step(f"part {part.name}: values at one point",
                                   lambda ctx=ctx, view=view: numeric_pair(ctx, view, values))
    return rows
