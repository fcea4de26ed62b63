"""How a quantity is declared: its entry, the families that collect a module's entries, the
table a check uses, and shared key schemas (a leaf the quantity modules import;
mechbook.verify.registry, above them, builds the default table from the modules it names)."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Mapping
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
    # function), "direction" (a mode shape's length), "open" (a claim true of every value
    # near the book's, such as a map that is not canonical); stated in docs/answers.md
    equivalent: tuple | Callable = ()
    # how other stages use the quantity, as plain names they map to their own code (verify
    # imports neither): the independent checks that vouch for it (mechbook.crosscheck.
    # problem.CROSSCHECKS), how the report shows the engine's value (mechbook.app.report.values'
    # DISPLAYS), the `mechbook sweep --quantity` whose grid its book value is drawn on
    crosschecks: tuple[str, ...] = ()
    display: str | None = None
    sweeps: tuple[str, ...] = ()
    # ctx -> None: the quantity's own validation of a part before anything is judged (a
    # scattering part's orbit is unbound), SpecError at the part's line otherwise
    validate: Callable | None = None


class Family:
    """The quantities one module defines, in order: `@family.quantity(...)` makes the decorated
    function the check of a quantity and records its entry here (nothing global: the table a
    check uses is built from families by `QuantityTable.of`)."""

    def __init__(self) -> None:
        self._entries: dict[str, Quantity] = {}

    @property
    def entries(self) -> tuple[Quantity, ...]:
        return tuple(self._entries.values())

    def quantity(self, name: str, *, book: str, how: str, keys: dict | None = None,
                 names: Callable | None = None, literals: tuple = (),
                 needs_system: bool = True, complex_values: bool = False,
                 equivalent: tuple | Callable = (), crosschecks: tuple[str, ...] = (),
                 display: str | None = None, sweeps: tuple[str, ...] = (),
                 validate: Callable | None = None) -> Callable[[Callable], Callable]:
        """Make the decorated function the check of quantity `name` (`names`: a function of
        the part's context giving the names its book value may use beyond the usual ones,
        e.g. a polynomial's variable; `mechbook validate` parses with them; `literals`:
        words the book value may be instead, e.g. "stable"; `needs_system`: False for
        quantities of declared tensors and bodies, which a problem without a system can
        have; `complex_values`: its values are complex on purpose, so its expressions may
        hold constants such as sqrt(-1), which are refused elsewhere; `crosschecks`,
        `display`, `sweeps`: names of the cross-checks that vouch for it, of how the report
        shows the engine's value, of the sweeps that draw its book value — see
        `Quantity`; `validate`: a function of the part's context that refuses a part whose
        keys cannot describe what the quantity needs, SpecError at its line, run by
        `mechbook validate` and before a check)."""
        def declare(fn: Callable) -> Callable:
            if name in self._entries:
                raise ValueError(f"quantity {name!r} declared twice")
            self._entries[name] = Quantity(
                name, fn, book, how, dict(keys or {}), names, tuple(literals), needs_system,
                complex_values, equivalent if callable(equivalent) else tuple(equivalent),
                tuple(crosschecks), display, tuple(sweeps), validate)
            return fn

        return declare


class QuantityTable(Mapping[str, Quantity]):
    """The quantities a check knows, name -> entry: what an answer key may name (its schema
    is built from the table) and how each part is checked. Immutable; compared and hashed
    by identity, so that what is derived from a table (its schema) is cached per table."""

    def __init__(self, entries: Iterable[Quantity]) -> None:
        table: dict[str, Quantity] = {}
        for q in entries:
            if q.name in table and table[q.name] is not q:
                raise ValueError(f"quantity {q.name!r} is in the table twice")
            table[q.name] = q
        self._table = table

    @classmethod
    def of(cls, *families: Family) -> QuantityTable:
        """The table of the quantities of `families` (a name in two of them is an error)."""
        return cls(q for family in families for q in family.entries)

    def __getitem__(self, name: str) -> Quantity:
        return self._table[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._table)

    def __len__(self) -> int:
        return len(self._table)

    __eq__ = object.__eq__
    __hash__ = object.__hash__

    def __repr__(self) -> str:
        return f"QuantityTable({len(self)} quantities)"
