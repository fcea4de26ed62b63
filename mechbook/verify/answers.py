"""Answer keys: the book's answers, part by part, kept apart from the problem files.

An answer key names, for each part, the quantity it checks and the book's value, in the
problem's own symbols plus any symbols of its own (`symbols:`, e.g. integration constants or
the names of normal coordinates) and abbreviations (`abbreviations: {omega0: sqrt(g/l)}`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import sympy as sp

from mechbook.errors import ExpressionError
from mechbook.model.expr import parse, parse_equation
from mechbook.model.limits import check_answer_counts
from mechbook.model.schema import validate
from mechbook.model.tensorexpr import parse_tensor
from mechbook.model.yamlio import Document, load


@dataclass
class Part:
    key: AnswerKey
    index: int
    data: dict
    _unavailable: dict = field(default_factory=dict, repr=False)  # abbreviation -> why

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
              bodies: dict | None = None) -> dict[str, sp.Basic]:
        """The names this part may use: `base` (a system's, or the problem's declared
        ones), the key's symbols and its abbreviations (tensor expressions, which may name
        the problem's `bodies`, if `tensor`)."""
        names = dict(base)
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
                self._unavailable[abbr] = self._unavailable.get(used.group(1) if used else "",
                                                                str(exc))
        return names

    def parse(self, text, sub: tuple, names: dict, equation: bool = False,
              relation: bool = False) -> sp.Basic:
        from mechbook.verify.registry import quantities

        known = quantities().get(self.quantity)
        complex_ok = bool(known and known.complex_values)  # exponents, complex modes
        try:
            if equation:
                return parse_equation(text, names, complex_ok)
            return parse(text, names, relation, complex_ok)
        except ExpressionError as exc:
            message = str(exc)
            for abbr, why in self._unavailable.items():
                if f"unknown name {abbr!r}" in message:
                    message += f" (abbreviation {abbr!r} does not parse here: {why})"
            raise self.error(sub, message) from None


class AnswerKey:
    def __init__(self, doc: Document):
        self.doc = doc
        self.file = doc.file
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


def load_answers(path: str | Path) -> AnswerKey:
    from mechbook.verify.registry import answers_schema  # the quantities register on import

    doc = load(path)
    validate(doc, answers_schema())
    check_answer_counts(doc)
    return AnswerKey(doc)
