"""Content hashes that decide whether a stored result is still valid (the warm-run cache)."""

from __future__ import annotations

import hashlib
from functools import cache
from pathlib import Path

from mechbook.model.input_limits import read_bytes


@cache
def engine_sha256() -> str:
    """Hash of mechbook's own source and schemas (the whole package, every stage): any
    change invalidates every result."""
    here = Path(__file__).parents[1]
    h = hashlib.sha256()
    for path in sorted([*here.rglob("*.py"), *here.rglob("*.json")]):
        h.update(str(path.relative_to(here)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()


def file_sha256(path: str | Path) -> str:
    """Hash of a problem or answer file, read within the input limits (a FIFO or an
    oversized file raises SpecError instead of hanging or filling memory)."""
    return hashlib.sha256(read_bytes(path)).hexdigest()
