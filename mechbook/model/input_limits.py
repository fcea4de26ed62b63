"""Input limits, applied while a file is read, before anything is built from it.

A problem or answer file comes from a contributor and may be careless or hostile. Every
limit here refuses the input quickly with file:line and what is wrong, before any work that
could grow without bound: a "billion laughs" document (nested YAML aliases, exponential when
expanded), a huge or endless file (a FIFO, /dev/zero), absurd nesting, a number that does
not fit, or a system with thousands of coordinates. The limits are far above what any book
problem needs (the committed files' largest counts are in docs/reliability.md).

YAML anchors, aliases and explicit tags are refused outright rather than capped: no problem
needs them, and refusing them is the only rule a reader can check by eye.
"""

from __future__ import annotations

import math
import os
import re
import stat
from collections.abc import Callable
from pathlib import Path

from mechbook.errors import SpecError

# ruamel.yaml reads ~20,000 nodes a second (pure Python): the caps keep the worst file to a
# fraction of a second.
MAX_FILE_BYTES = 128 * 1024  # the largest committed file is ~7 KB
MAX_YAML_DEPTH = 32  # nesting of mappings and sequences (the committed files use <= 7)
MAX_YAML_NODES = 5_000  # scalars, mappings and sequences in one file (committed: <= 273)
MAX_NUMBER_CHARS = 100  # an unquoted number literal longer than this is refused
MAX_MAGNITUDE = 1e100  # |number| in the data (as for literals in expressions): room for
# physical constants in SI units (the sun's mass 2e30 kg, Planck's constant 6.6e-34 J s)
MIN_MAGNITUDE = 1e-100  # smallest nonzero |number|

# Counts per problem (per system where it says so) and per answer key: the committed
# files' largest are 6 coordinates, 4 particles, 4 springs, 3 constraints, 8 parameters,
# 3 systems, 10 parts, 5 abbreviations, 6 symbols.
PROBLEM_COUNTS = {
    "parameters": 64, "systems": 8, "conditions": 32,
}
SYSTEM_COUNTS = {
    "coordinates": 16, "driven": 16, "particles": 32, "rigid_bodies": 32, "springs": 64,
    "constraints": 16, "velocity_constraints": 16, "rolling": 8, "forces": 16, "initial": 64,
}
FUNCTIONAL_COUNTS = {"functions": 6, "constraints": 8}  # a functional's (mechbook.model.functional)
ANSWER_COUNTS = {"parts": 64, "abbreviations": 64, "symbols": 64}
PART_COUNTS = {"assume": 32, "define": 32}

# what YAML may read as a number (decimal, with '_', '.', an exponent; hexadecimal, octal,
# binary; YAML 1.1's base 60); an expression such as 2*(m*l**2) is text and may be long
_NUMBERISH = re.compile(r"[-+]?(?:[0-9_]*\.?[0-9_]*(?:[eE][-+]?[0-9_]+)?|0[xX][0-9a-fA-F_]+"
                        r"|0[oO]?[0-7_]+|0[bB][01_]+|[0-9][0-9_]*(?::[0-5]?[0-9])+(?:\.[0-9_]*)?)")
# characters text may not hold: C0 and C1 controls but tab and newline, DEL, lone surrogates
# (no character at all: they cannot be written as UTF-8) and the noncharacters U+FFFE, U+FFFF
_BAD_TEXT = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f\ud800-\udfff\ufffe\uffff]")
_CHAR_NAMES = {"\x00": "NUL", "\x1b": "escape", "\r": "carriage return", "\x7f": "delete"}


def read_text(path: str | Path) -> str:
    """The text of a regular file of at most MAX_FILE_BYTES, decoded as UTF-8."""
    return decode(read_bytes(path), str(path))


def read_bytes(path: str | Path) -> bytes:
    """The bytes of a regular file of at most MAX_FILE_BYTES.

    A FIFO, a device or a directory is refused before it is opened for reading (reading
    /dev/zero never ends); the size is checked on the open file and again on what is read,
    so a file that grows meanwhile cannot slip past."""
    path = Path(path)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise SpecError(f"cannot read file: {exc.strerror}", str(path)) from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise SpecError("not a regular file", str(path))
        if info.st_size > MAX_FILE_BYTES:
            raise SpecError(f"file too large ({info.st_size} bytes; at most "
                            f"{MAX_FILE_BYTES})", str(path))
        with os.fdopen(fd, "rb", closefd=False) as fh:
            data = fh.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise SpecError(f"cannot read file: {exc.strerror}", str(path)) from None
    finally:
        os.close(fd)
    if len(data) > MAX_FILE_BYTES:
        raise SpecError(f"file too large (more than {MAX_FILE_BYTES} bytes)", str(path))
    return data


def decode(data: bytes, file: str) -> str:
    """UTF-8 text, or a SpecError naming the line of the first undecodable byte."""
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise SpecError(f"not UTF-8 text (byte 0x{data[exc.start]:02x} at offset "
                        f"{exc.start})", file, line) from None


def check_events(events, file: str) -> None:
    """Refuse anchors, aliases, explicit tags, deep nesting, too many nodes and overlong
    number literals, from the parser's event stream (nothing is built or expanded yet)."""
    depth = nodes = 0
    for ev in events:
        kind = type(ev).__name__
        if kind in ("StreamStartEvent", "StreamEndEvent", "DocumentStartEvent",
                    "DocumentEndEvent"):
            continue
        line = ev.start_mark.line + 1 if ev.start_mark is not None else None
        if kind == "AliasEvent":
            raise SpecError(f"YAML alias *{ev.anchor} is not allowed (anchors and aliases "
                            "are refused: write the value out)", file, line)
        if kind.endswith("EndEvent"):
            depth -= 1
            continue
        nodes += 1
        if nodes > MAX_YAML_NODES:
            raise SpecError(f"too many YAML nodes (more than {MAX_YAML_NODES})", file, line)
        if getattr(ev, "anchor", None):
            raise SpecError(f"YAML anchor &{ev.anchor} is not allowed (anchors and aliases "
                            "are refused: write the value out)", file, line)
        tag = getattr(ev, "tag", None)
        if tag is not None and str(tag) not in ("!", ""):
            raise SpecError(f"YAML tag {tag} is not allowed (write plain values)", file, line)
        if kind in ("MappingStartEvent", "SequenceStartEvent"):
            depth += 1
            if depth > MAX_YAML_DEPTH:
                raise SpecError(f"YAML nested too deeply (more than {MAX_YAML_DEPTH} levels)",
                                file, line)
        elif kind == "ScalarEvent" and ev.style is None and len(ev.value) > MAX_NUMBER_CHARS \
                and _NUMBERISH.fullmatch(ev.value):
            raise SpecError(f"unquoted value of {len(ev.value)} characters starting "
                            f"{ev.value[:20]!r} (a number that long is refused; quote text)",
                            file, line)


def check_text(value: str, where: Callable[[], tuple[str, int | None]]) -> str:
    """Text as every output can hold it (HDF5, JSON, XML, a terminal): no NUL, no lone
    surrogate, no control character but tab and newline; SpecError naming the character
    and where it is otherwise."""
    bad = _BAD_TEXT.search(value)
    if bad:
        ch = bad.group()
        code = f"U+{ord(ch):04X}"
        if "\ud800" <= ch <= "\udfff":
            what = f"a lone surrogate {code} (not a character)"
        elif ch in ("\ufffe", "\uffff"):
            what = f"the noncharacter {code}"
        else:
            name = _CHAR_NAMES.get(ch)
            what = f"the control character {code}" + (f" ({name})" if name else "")
        raise SpecError(f"text holds {what} at character {bad.start() + 1}: text may hold "
                        "tabs and line breaks but no other control characters; remove it",
                        *where())
    return value


def check_scalar(value, where: Callable[[], tuple[str, int | None]]):
    """A plain scalar of a loaded file (valid text, bool, None, or a finite number of sane
    size); anything else YAML can make (dates, binary, sets) is refused."""
    if value is None or isinstance(value, bool):
        return value
    if isinstance(value, str):
        return check_text(value, where)
    if isinstance(value, int | float):
        if isinstance(value, float) and not math.isfinite(value):
            raise SpecError(f"number {value} is not finite", *where())
        if value != 0 and not MIN_MAGNITUDE <= abs(value) <= MAX_MAGNITUDE:
            shown = f"{value:g}" if isinstance(value, float) else \
                f"of about {value.bit_length() * math.log10(2):.0f} digits"  # no float: huge
            raise SpecError(f"number {shown} out of range (|x| from {MIN_MAGNITUDE:g} to "
                            f"{MAX_MAGNITUDE:g}, or 0)", *where())
        return value
    raise SpecError(f"a value of type {type(value).__name__} is not allowed here (quote it "
                    "if it is text)", *where())


def check_counts(doc, data: dict, limits: dict[str, int], prefix: tuple = ()) -> None:
    """Refuse a mapping or list in `data` with more entries than its limit."""
    for key, most in limits.items():
        value = data.get(key)
        if isinstance(value, dict | list) and len(value) > most:
            raise doc.error(prefix + (key,), f"too many entries ({len(value)}; at most "
                            f"{most})")


def check_problem_counts(doc) -> None:
    data = doc.data
    check_counts(doc, data, PROBLEM_COUNTS)
    if isinstance(data.get("functional"), dict):
        check_counts(doc, data["functional"], FUNCTIONAL_COUNTS, ("functional",))
    check_counts(doc, data, SYSTEM_COUNTS)
    for name, system in (data.get("systems") or {}).items():
        if isinstance(system, dict):
            check_counts(doc, system, SYSTEM_COUNTS, ("systems", name))


def check_answer_counts(doc) -> None:
    data = doc.data
    check_counts(doc, data, ANSWER_COUNTS)
    for i, part in enumerate(data.get("parts") or []):
        if isinstance(part, dict):
            check_counts(doc, part, PART_COUNTS, ("parts", i))
