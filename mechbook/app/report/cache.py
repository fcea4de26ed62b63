"""Which pages of a report are still good: a content hash per page, kept beside the pages.

A page depends on its problem file and answer key, on the check the store holds for it,
on books.yaml, on mechbook itself (the engine's hash, as for the check's own cache), on the
page options, and on the work–precision figures `make bench` left. Their hash is the page's
key; `.pages.json` in the report's directory maps each page to its key and to what the
index needs from it (title, parts, systems), and is rewritten (atomically) after every page,
so an interrupted report keeps the pages it finished and a rerun builds only what changed.

The manifest is a file anyone can replace: it is read only as a regular file of bounded
size, as JSON of bounded depth (mechbook.app.bounded); anything else (a FIFO, a link to
/dev/zero, a gigabyte, JSON nested a hundred thousand deep) is no manifest: every page is
built again, with a warning. It is written as a new file renamed over the old one
(mechbook.app.outputs.replaced: no temporary file of a guessable name that a link could
stand in for).
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import stat
from dataclasses import asdict
from pathlib import Path

from mechbook.app.bounded import Unreadable, json_value, read_regular
from mechbook.app.fingerprint import engine_sha256, file_sha256
from mechbook.app.output.text import json_safe
from mechbook.app.outputs import replaced
from mechbook.errors import MechbookError
from mechbook.model.catalog import answer_path, problem_path

MANIFEST = ".pages.json"
FORMAT = 1
MAX_MANIFEST_BYTES = 64 * 2**20  # the whole book's manifest is well under 1 MB
log = logging.getLogger("mechbook.report")


def page_key(pid: str, base: Path, stored: dict | None, options) -> str:
    """The content hash a page is built from (see the module docstring)."""
    h = hashlib.sha256()
    parts: list[str] = [f"format {FORMAT}", engine_sha256(), json.dumps(asdict(options),
                                                                       sort_keys=True)]
    for path in _inputs(pid, base):
        try:
            parts.append(f"{path.name} {file_sha256(path)}" if path.exists() else "-")
        except (MechbookError, OSError):
            parts.append("unreadable")
    attrs = (stored or {}).get("attrs") or {}
    parts.append(json.dumps({k: str(attrs.get(k, "")) for k in
                             ("date", "duration_s", "problem_sha256", "answers_sha256",
                              "engine_sha256")}, sort_keys=True))
    for fig in sorted((base / "results" / "bench").glob(f"{pid}*.png")):
        st = fig.stat()
        parts.append(f"{fig.name} {st.st_size} {st.st_mtime_ns}")
    for text in parts:
        h.update(text.encode("utf-8", "surrogatepass"))
        h.update(b"\0")
    return h.hexdigest()


def _inputs(pid: str, base: Path) -> list[Path]:
    out = [base / "books.yaml"]
    for where in (problem_path, answer_path):
        try:
            out.append(where(pid, base))
        except MechbookError:
            continue
    return out


def load(out: Path) -> dict[str, dict]:
    """{page id: {"key", "index": ...}} of the pages already written (empty if none or
    unreadable: then every page is built)."""
    path = out / MANIFEST
    if not path.exists() and not path.is_symlink():
        return {}
    try:
        data = json_value(read_regular(path, MAX_MANIFEST_BYTES).decode("utf-8"))
    except (Unreadable, ValueError) as exc:  # UnicodeDecodeError is a ValueError
        log.warning("the report's page list %s is not usable (%s): every page is built "
                    "again", path, str(exc).removeprefix(f"cannot read {path}: "))
        return {}
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        return {}
    pages = data.get("pages")
    if not isinstance(pages, dict):
        return {}
    good = {pid: entry for pid, entry in pages.items() if _sound(entry)}
    if len(good) < len(pages):
        log.warning("the report's page list %s holds %d entries that are not what a report "
                    "writes: their pages are built again", path, len(pages) - len(good))
    return good


def _sound(entry) -> bool:
    """An entry as `build_report` writes it: {"key": str, "index": {"title": str, "parts":
    [{"part": str, "quantity": str, "origin": str, "cite": str}]}, "seconds": number}."""
    if not isinstance(entry, dict) or not isinstance(entry.get("key", ""), str):
        return False
    if not isinstance(entry.get("seconds", 0), int | float):
        return False
    index = entry.get("index", {})
    if not isinstance(index, dict) or not isinstance(index.get("title", ""), str):
        return False
    parts = index.get("parts", [])
    return isinstance(parts, list) and all(
        isinstance(p, dict) and all(isinstance(p.get(k, ""), str)
                                    for k in ("part", "quantity", "origin", "cite"))
        and "part" in p for p in parts)


def save(out: Path, pages: dict[str, dict]) -> None:
    """Write the manifest atomically (a new file renamed over it)."""
    try:
        with replaced(out / MANIFEST) as fh:
            fh.write(json.dumps(json_safe({"format": FORMAT, "pages": pages}),
                                ensure_ascii=False).encode("utf-8"))
    except OSError as exc:  # a directory in its place, a full disk: the pages stay good
        log.warning("the report's page list %s cannot be written (%s): the next report "
                    "builds every page again", out / MANIFEST, exc.strerror or exc)


def still_good(out: Path, pid: str, key: str, pages: dict[str, dict]) -> bool:
    """Whether the page of `pid` on disk was built from `key`: a regular file, no link (a
    link or anything else in a page's place is built again, and the new page renamed over
    it, never written through it)."""
    entry = pages.get(pid)
    if not (isinstance(entry, dict) and entry.get("key") == key):
        return False
    try:
        info = os.lstat(out / "problems" / f"{pid}.html")
    except OSError:
        return False
    return stat.S_ISREG(info.st_mode)
