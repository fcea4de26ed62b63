"""Whether an answer key is well formed, before any part is checked: every name a part uses
resolved against its problem (mechbook.verify.keynames) and every expression parsed in the
part's context; nothing is derived beyond building the systems, nothing judged.

`mechbook validate` refuses a key at its first fault; `mechbook check` refuses a key with
any fault whole, each malformed part saying where (mechbook.app orchestrates both, with
their time limits).
"""

from __future__ import annotations

from mechbook.engine.analysis import Analysis
from mechbook.errors import SpecError
from mechbook.verify.context import Context, strip_const
from mechbook.verify.keynames import check_part_names
from mechbook.verify.part import AnswerKey, Part
from mechbook.verify.registration import QuantityTable

# the part keys that hold expressions (beyond a quantity's own, which its check parses)
EXPRESSION_KEYS = ("book", "about", "initial", "released", "region", "time", "hold", "signal",
                   "event", "period")


def validate_key(analysis: Analysis, key: AnswerKey,
                 quantities: QuantityTable | None = None) -> dict[str, SpecError]:
    """{part name: its fault (file:line)} for every malformed part, in the key's order; empty
    for a well-formed key. `quantities`: the table to check with (default: the key's)."""
    faults = {}
    for part in key.parts:
        try:
            validate_part(analysis, part, quantities)
        except SpecError as exc:
            faults[part.name] = exc
    return faults


def validate_part(analysis: Analysis, part: Part,
                  quantities: QuantityTable | None = None) -> None:
    """Every name the part uses resolved and every expression of it parsed in its context;
    SpecError (file:line) on the first fault."""
    check_part_names(part, analysis.problem)
    ctx = Context(analysis, part, validate_only=True, quantities=quantities)
    q = ctx.quantity
    if ctx.tensor_mode:  # vectors, tensors, bodies: the statement built once, nothing judged
        q.check(ctx, part.data.get("book"))
        if "erratum" in part.data:
            q.check(ctx, part.data["erratum"]["corrected"])
        return
    names = q.names(ctx) if q.names else ctx.names  # a book value's extra names
    for field in EXPRESSION_KEYS:
        if field == "book" and part.data.get("book") in q.literals:
            continue  # a word such as "stable", not an expression
        if field in part.data:
            _parse_all(ctx, part.data[field], (field,), names if field == "book" else ctx.names)
    if "erratum" in part.data:
        _parse_all(ctx, part.data["erratum"]["corrected"], ("erratum", "corrected"), names)
    if q.validate is not None and "unsupported" not in part.data:
        q.validate(ctx)  # the quantity's own refusal (a scattering part on a bound orbit)


def _parse_all(ctx: Context, value, sub: tuple, names: dict) -> None:
    """Parse every string inside `value` (nested mappings and lists), at its own path."""
    if isinstance(value, dict):
        for k, v in value.items():
            _parse_all(ctx, v, sub + (k,), names)
    elif isinstance(value, list):
        for i, v in enumerate(value):
            _parse_all(ctx, v, sub + (i,), names)
    elif isinstance(value, str):
        value = strip_const(value)  # a first integral may be written "... = constant"
        if "<" in value or ">" in value:
            ctx.parse(value, sub, relation=True, names=names)
        else:
            ctx.parse(value, sub, equation=True, names=names)
