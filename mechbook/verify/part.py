"""An answer key and its parts, as records: a module of its own so that the checks' context
imports them without the key loader (mechbook.verify.answers, which builds the schema from
the table of quantities)."""

from __future__ import annotations

import re
from dataclasses import dataclass

import sympy as sp

from mechbook.errors import ExpressionError
from mechbook.model.expr import parse, parse_equation
from mechbook.model.tensorexpr import parse_tensor
from mechbook.model.yamlio import Document
from mechbook.verify.registration import QuantityTable


class AnswerKey:
    """An answer key: its document, its own symbols (`symbols:`, e.g. integration constants,
    with the values they are sampled at), its parts, and the table of quantities it was read
    against (its parts are checked with that table unless a caller gives another)."""

    def __init__(self, doc: Document, quantities: QuantityTable):
        self.doc = doc
        self.file = doc.file
        self.quantities = quantities
        data = doc.data
        self.problem_id: str = data["problem"]
        self.symbols: dict[str, sp.Symbol] = {}
        self.symbol_values: dict[sp.Symbol, float] = {}
        for name, spec in (data.get("symbols") or {}).items():
            spec = spec or {}
            positive = spec.get("positive", True)
            sym = sp.Symbol(name, positive=True) if positive else sp.Symbol(name, real=True)
            self.symbols[name] = sym
            self.symbol_values[sym] = float(spec.get("value", 1.0))
        self.parts = [Part(self, i, p) for i, p in enumerate(data["parts"])]
        seen = set()
        for p in self.parts:
            if p.name in seen:
                raise p.error(("part",), f"part {p.name!r} appears twice")
            seen.add(p.name)


@dataclass(frozen=True)
class Part:
    """One part of an answer key: its data, names and parsing (a record: what a check learns
    about it, such as the names available to it, stays with the check's context)."""

    key: AnswerKey
    index: int
    data: dict

    @property
    def name(self) -> str:
        return self.data["part"]

    @property
    def quantity(self) -> str:
        return self.data["quantity"]

    @property
    def system(self) -> str | None:
        return self.data.get("system")

    @property
    def path(self) -> tuple:
        return ("parts", self.index)

    def error(self, sub: tuple, message: str):
        return self.key.doc.error(self.path + sub, message)

    def names(self, base: dict, tensor: bool = False,
              bodies: dict | None = None) -> tuple[dict[str, sp.Basic], dict[str, str]]:
        """The names this part may use: `base` (a system's, or the problem's declared
        ones), the key's symbols and its abbreviations (tensor expressions, which may name
        the problem's `bodies`, if `tensor`); and {abbreviation: why it does not parse here}
        for those left out (`parse` says why when a part uses one)."""
        names = dict(base)
        unavailable: dict[str, str] = {}
        for sym in self.key.symbols:
            if sym in names:
                raise self.key.doc.error(("symbols", sym), f"{sym!r} is already a name of the "
                                         "problem (a parameter, coordinate or rate)")
        names.update(self.key.symbols)
        for abbr, text in (self.key.doc.data.get("abbreviations") or {}).items():
            if abbr in names:
                raise self.key.doc.error(("abbreviations", abbr), f"{abbr!r} is already a name")
            try:
                names[abbr] = parse_tensor(text, names, bodies or {}) if tensor \
                    else parse(text, names)
            except ExpressionError as exc:
                # An abbreviation may belong to another of the problem's systems (it names
                # that system's coordinates): it is simply not available in this one, and a
                # part that uses it here is told why (the first abbreviation of a chain that
                # failed, with its own reason).
                used = re.search(r"unknown name '(\w+)'", str(exc))
                unavailable[abbr] = unavailable.get(used.group(1) if used else "", str(exc))
        return names, unavailable

    def parse(self, text, sub: tuple, names: dict, equation: bool = False,
              relation: bool = False, complex_ok: bool = False,
              unavailable: dict[str, str] | None = None) -> sp.Basic:
        """`text` parsed with `names` (an equation, or a relation, if asked); SpecError at
        `sub` if it does not parse, saying why an abbreviation it uses is `unavailable`.
        `complex_ok`: complex constants allowed (a quantity whose values are complex)."""
        try:
            if equation:
                return parse_equation(text, names, complex_ok)
            return parse(text, names, relation, complex_ok)
        except ExpressionError as exc:
            message = str(exc)
            for abbr, why in (unavailable or {}).items():
                if f"unknown name {abbr!r}" in message:
                    message += f" (abbreviation {abbr!r} does not parse here: {why})"
            raise self.error(sub, message) from None
