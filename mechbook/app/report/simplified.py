"""Simplified forms for reading, kept by content across report runs: simplification is
spent once.

`sympy.simplify` turns the double pendulum's L, sin² + cos² and all, into the form a reader
expects, but takes seconds on a loaded machine: paid on every run, a page's budget runs out
and the page shows raw forms. Here each simplified form is kept under the hash of the
expression it came from (its `srepr`, with SymPy's version: another SymPy may simplify
otherwise), one small file per expression under the report's folder (`.simplified/`), so
the next run of any page that shows the same expression reads it back instead of spending
time. Pages built in parallel write distinct files, each written whole and renamed into
place; a symbolic link in the folder is never written through.

The folder is a file anyone can change, so what is read back is checked, never trusted:
read only as a regular file of bounded size, parsed by the safe parser (never `eval`), in
the original expression's own symbols, and accepted only where it equals the original at
three random points to 1e-9; anything else is no cached form (simplified again).
"""

from __future__ import annotations

import hashlib
import logging
import random
from pathlib import Path

import sympy as sp

from mechbook.app.bounded import Unreadable, read_regular
from mechbook.app.outputs import OutputError, output_file, replaced
from mechbook.app.report.stored import read
from mechbook.core.numeval import NotNumeric, evaluate
from mechbook.errors import MechbookError

DIRECTORY = ".simplified"  # in the report's folder
FORMAT = 1
MAX_BYTES = 64 * 1024  # one simplified form (what the page typesets is far shorter)
CHECKS = 3  # random points at which a form read back must equal the original
RTOL = 1e-9
log = logging.getLogger("mechbook.report")


class SimplifiedCache:
    """The simplified forms under `directory` (None: nothing kept, nothing read)."""

    def __init__(self, directory: Path | None):
        self.directory = Path(directory) if directory is not None else None
        self.hits = 0
        self.stored = 0

    def _path(self, expr: sp.Basic) -> Path:
        key = hashlib.sha256(f"{FORMAT}\0{sp.__version__}\0{sp.srepr(expr)}"
                             .encode()).hexdigest()
        return self.directory / key[:2] / f"{key}.txt"

    def get(self, expr: sp.Expr) -> sp.Expr | None:
        """The kept simplified form of `expr`, checked equal to it; None if there is none."""
        if self.directory is None:
            return None
        path = self._path(expr)
        try:
            text = read_regular(path, MAX_BYTES).decode("utf-8")
            names = {s.name: s for s in expr.free_symbols if isinstance(s, sp.Symbol)}
            form = read(text, names)
        except Unreadable as exc:
            if not exc.missing:  # none kept yet is no form, not a damaged one
                log.warning("%s: not a simplified form mechbook wrote; simplified again", path)
            return None
        except FileNotFoundError:
            return None
        except (OSError, UnicodeDecodeError, MechbookError, ValueError):
            log.warning("%s: not a simplified form mechbook wrote; simplified again", path)
            return None
        if not isinstance(form, sp.Expr) or not _same(expr, form):
            log.warning("%s: not equal to the expression it is kept for; simplified again",
                        path)
            return None
        self.hits += 1
        return form

    def put(self, expr: sp.Expr, form: sp.Expr) -> None:
        """Keep `form` as the simplified `expr` (a failure to write costs only the time)."""
        if self.directory is None or form == expr:
            return
        text = sp.sstr(form)
        if not _readable(text, expr):  # kept, it would be refused on every later read
            return
        path = self._path(expr)
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            if not self._inside(path):  # a link planted in the folder: never written through
                log.warning("%s: a symbolic link in the way; the form is not kept", path)
                return
            with replaced(output_file(path, "simplified form")) as fh:
                fh.write(text.encode("utf-8"))
            self.stored += 1
        except (OSError, OutputError) as exc:
            log.debug("%s: not kept (%s)", path, exc)


    def _inside(self, path: Path) -> bool:
        """Whether `path` is a name inside the folder with no symbolic link on the way (the
        folder, its subfolder, the file)."""
        top = self.directory
        return not any(p.is_symlink() for p in (top, path.parent, path))


def _readable(text: str, expr: sp.Expr) -> bool:
    """Whether `get` can read `text` back (the safe parser refuses, say, an integer of
    more digits than a problem file may hold: such a form is shown, not kept)."""
    names = {s.name: s for s in expr.free_symbols if isinstance(s, sp.Symbol)}
    try:
        read(text, names)
    except (MechbookError, ValueError):
        return False
    return True


def _same(a: sp.Expr, b: sp.Expr) -> bool:
    """Whether two expressions agree at CHECKS random real points (positive values: the
    symbols' assumptions are mostly positive), to RTOL of their size."""
    symbols = sorted(a.free_symbols | b.free_symbols, key=str)
    if b.free_symbols - a.free_symbols:
        return False
    rng = random.Random(sp.srepr(a))
    for _ in range(CHECKS):
        point = {s: sp.Float(rng.uniform(0.3, 1.7), 30) for s in symbols}
        try:
            x, mx = evaluate(a, point)
            y, my = evaluate(b, point)
        except (NotNumeric, TypeError, ValueError, ZeroDivisionError, OverflowError):
            return False
        if abs(x - y) > RTOL * max(mx, my, abs(x), 1e-300):
            return False
    return True
