"""The documentation pages (docs/*.md), wherever mechbook is installed.

In a checkout they are docs/ beside the package; a wheel carries them inside it, as
mechbook/docs/ (setup.py copies them when the package is built), since a wheel's user has
no checkout while `--help`, the starter files and error messages point to them.
`mechbook docs` lists and prints them.
"""

from __future__ import annotations

import re
from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path

from mechbook.errors import NotFoundError
from mechbook.model.hints import did_you_mean


def location() -> Traversable:
    """The directory of the pages: the package's own (a wheel), else the checkout's."""
    shipped = resources.files("mechbook").joinpath("docs")
    if shipped.is_dir():
        return shipped
    return Path(__file__).resolve().parents[2] / "docs"


def pages() -> dict[str, Traversable]:
    """Every page by name (`schema` for schema.md), in alphabetical order."""
    where = location()
    if not where.is_dir():
        return {}
    found = [p for p in where.iterdir() if p.name.endswith(".md")]
    return {p.name[:-3]: p for p in sorted(found, key=lambda p: p.name)}


def title(page: Traversable) -> str:
    """A page's first heading."""
    for line in page.read_text("utf-8").splitlines():
        m = re.match(r"#+\s+(.*)", line)
        if m:
            return m.group(1).strip()
    return ""


def page_text(name: str) -> str:
    """The page `name` (with or without .md); NotFoundError naming those there are."""
    name = name.removesuffix(".md").removeprefix("docs/")
    found = pages()
    if name not in found:
        hint = did_you_mean(name, found)
        raise NotFoundError(f"no page {name!r} in the docs (pages: {', '.join(found)})"
                            + (f"; {hint}" if hint else ""))
    return found[name].read_text("utf-8")
