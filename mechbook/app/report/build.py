"""Writing the report: the index (every problem's outcome per part, errata, unsupported parts,
filters by book and status) and one page per problem, under one directory that works
offline (`results/report/index.html` by default).

It is built like `mechbook check`: the pages run on the batch machinery's worker processes
(mechbook.app.running.batch: a time limit and a memory bound per page, a dead worker replaced), the
slowest first; each worker writes its page the moment it is done, and `.pages.json` records
the content hash each page was built from (mechbook.app.report.cache), so an interrupted
report keeps what it finished and a rerun rebuilds only the pages whose problem, answer key,
stored check, books.yaml or mechbook changed. Progress is a bar with ETA on a terminal, a
line per page otherwise. The index is written last, from the store and the pages' entries.
"""

from __future__ import annotations

import sys
import time
from collections import Counter
from dataclasses import dataclass, field
from datetime import UTC, datetime
from importlib import resources
from pathlib import Path

from mechbook.app.output.text import unicode_safe
from mechbook.app.outputs import replaced
from mechbook.app.report import cache
from mechbook.app.report.page import PageOptions, build_page
from mechbook.app.report.progress import Progress
from mechbook.app.report.simplified import DIRECTORY as SIMPLIFIED
from mechbook.app.running.batch import Batch, BatchOptions
from mechbook.app.running.quiet import warnings_as_notes
from mechbook.app.store import StoreError, problems, read, vet
from mechbook.core.words import duration, plural
from mechbook.errors import MechbookError, describe
from mechbook.model.books import books, split_id
from mechbook.model.catalog import all_ids
from mechbook.records import STATUSES, Status
from mechbook.version import __version__

NOT_CHECKED = "not checked"


@dataclass(frozen=True)
class ReportOptions:
    jobs: int = 0  # worker processes (0: one per core)
    serial: bool = False  # pages in this process (tests, debugging)
    page: PageOptions = field(default_factory=PageOptions)
    page_timeout: float = 600.0  # seconds for one page, all steps together
    memory_mb: float = 4000.0  # resident memory of one page's worker


@dataclass(frozen=True)
class _Task:
    """What a worker needs to build and write a page (plain data: it crosses processes)."""

    out: Path
    store: Path
    page: PageOptions


def build_report(base: Path, store: Path, out: Path, ids: list[str] | None = None,
                 options: ReportOptions = ReportOptions(), log=None) -> Path:
    """Write the report for `ids` (every problem by default) to `out`; returns index.html."""
    log = log or (lambda text: print(text, file=sys.stderr))
    base, out, store = Path(base), Path(out), Path(store)
    ids = list(ids or all_ids(base))
    stored, damaged = _stored(ids, store, log)
    (out / "problems").mkdir(parents=True, exist_ok=True)
    _copy_assets(out / "assets")
    pages = cache.load(out)
    keys = {pid: cache.page_key(pid, base, stored.get(pid), options.page) for pid in ids}
    todo = [pid for pid in ids if pid in damaged
            or not cache.still_good(out, pid, keys[pid], pages)]
    if todo:
        _build_pages(base, store, out, todo, keys, pages, stored, options, log)
    else:
        log(f"all {plural(len(ids), 'page')} are up to date")
    declared = books(base)
    rows, problems_index = [], []
    for pid in ids:
        entry = index_entry(pid, (pages.get(pid) or {}).get("index") or {}, stored.get(pid),
                             declared)
        problems_index.append(entry)
        rows.extend(entry["rows"])
    counts = Counter(r["status"] for r in rows)
    book_list = [{"id": b, "label": (declared[b].label if b in declared else b),
                  "book": declared.get(b)}
                 for b in sorted({e["book"] for e in problems_index})]
    index = out / "index.html"
    render("index.html", index, tree=base, problems=problems_index, rows=rows,
           books=book_list, statuses=[*STATUSES, NOT_CHECKED], counts=counts,
           version=__version__, store=shown_path(store, base),
           date=datetime.now(UTC).isoformat(timespec="seconds"),
           errata=[r for r in rows if r["status"] == Status.ERRATUM],
           unsupported=[r for r in rows if r["status"] == Status.UNSUPPORTED])
    return index


def _build_pages(base, store, out, todo, keys, pages, stored, options: ReportOptions,
                 log) -> None:
    order = sorted(todo, key=lambda pid: -_expected(pid, pages, stored))
    progress = Progress(len(order), log)

    def finished(result: dict) -> None:
        pid = result["pid"]
        if result.get("failed"):
            _write_failed(base, out, pid, stored.get(pid), result["failed"])
        pages[pid] = {"key": keys[pid] if not result.get("failed") else "",
                      "index": result.get("index") or {}, "seconds": result["seconds"]}
        cache.save(out, pages)
        progress.done(pid, result["seconds"], result.get("failed"))

    batch = Batch(base, BatchOptions(options.jobs, options.page_timeout, options.memory_mb,
                                     max_tasks=25, run=_Task(out, store, options.page),
                                     serial=options.serial),
                  on_done=finished, task=page_task, failed=_page_failed)
    try:
        batch.run(order)
    finally:
        progress.close()


def _expected(pid: str, pages: dict, stored: dict) -> float:
    """A page's expected time: its last build's, else its check's (the slowest first)."""
    last = (pages.get(pid) or {}).get("seconds")
    if isinstance(last, int | float):
        return float(last)
    return float(((stored.get(pid) or {}).get("attrs") or {}).get("duration_s") or 1e6)


def page_task(pid: str, base: Path, task: _Task, stage) -> dict:
    """Build one page and write it (in a worker); its entry for the index comes back."""
    start = time.monotonic()
    stored, why = _read_one(pid, task.store)
    notes: list[str] = []
    try:
        with warnings_as_notes(notes):
            stage("building the page")
            page = build_page(pid, base, stored, task.page, task.out / SIMPLIFIED)
    except MechbookError as exc:  # a problem file that does not load: said on its page
        return {"pid": pid, "failed": str(exc), "seconds": time.monotonic() - start}
    except Exception as exc:  # noqa: BLE001 - one page must not end the report
        describe(exc)  # the traceback to the debug log; the page says it in words
        return {"pid": pid, "failed": "the engine could not build it (`mechbook check -v "
                f"{pid}` shows the fault)", "seconds": time.monotonic() - start}
    if why:
        page["page_notes"].append(f"its stored outcomes are not shown: {why}")
    page["page_notes"] += [f"note: {n}" for n in notes]
    stage("writing the page")
    declared = books(base)
    for system in page.get("systems", []):
        system["bench_figure"] = _bench_figure(base, task.out, pid, system["name"],
                                               len(page["systems"]))
    checks = {c["part"]: c for c in (stored or {}).get("checks", [])}
    for part in page.get("parts", []):
        part["check"] = checks.get(part["part"])
    index = {"title": page.get("title", ""),
             "parts": [{"part": p["part"], "quantity": p.get("quantity", ""),
                        "origin": p.get("origin", ""), "cite": p.get("cite", "")}
                       for p in page.get("parts", [])]}
    entry = index_entry(pid, index, stored, declared)
    render("problem.html", task.out / "problems" / f"{pid}.html", tree=base, page=page,
           stored=stored, entry=entry, version=__version__)
    return {"pid": pid, "index": index, "seconds": time.monotonic() - start}


def _page_failed(pid: str, why: str, seconds: float, stage: str) -> dict:
    return {"pid": pid, "failed": why, "seconds": seconds, "index": {}}


def _write_failed(base: Path, out: Path, pid: str, stored: dict | None, why: str) -> None:
    """A page that says it could not be built, and why (in words)."""
    page = {"id": pid, "title": ((stored or {}).get("attrs") or {}).get("title", ""),
            "source": "", "description": "", "notes_text": "", "parameters": [],
            "conditions": [], "defaults": "", "systems": [], "parts": [],
            "crosscheck_figures": {},
            "page_notes": [f"this page could not be built: {why}"]}
    entry = index_entry(pid, {"title": page["title"]}, stored, books(base))
    render("problem.html", out / "problems" / f"{pid}.html", tree=base, page=page,
           stored=stored, entry=entry, version=__version__)


def _read_one(pid: str, store: Path) -> tuple[dict | None, str | None]:
    if not store.exists():
        return None, None
    try:
        return read(pid, store), None
    except KeyError:
        return None, None
    except (StoreError, OSError) as exc:
        return None, str(exc)


def _stored(ids: list[str], store: Path, log) -> tuple[dict[str, dict], dict[str, str]]:
    """The stored records of `ids`, and {id: why} for those the store has but cannot give
    back (damaged): the report says so and shows them as not checked."""
    if not store.exists():
        return {}, {}
    vet(store)  # once for the whole file, not a child per record
    try:
        in_store = set(problems(store))
    except StoreError as exc:
        log(f"warning: {exc}; every problem is shown as not checked")
        return {}, {pid: str(exc) for pid in ids}
    stored, damaged = {}, {}
    for pid in ids:
        if pid not in in_store:
            continue
        try:
            stored[pid] = read(pid, store)
        except StoreError as exc:
            log(f"warning: {exc}")
            damaged[pid] = str(exc)
    return stored, damaged


def index_entry(pid: str, index: dict, stored: dict | None, declared: dict) -> dict:
    book = split_id(pid)[0]
    attrs = (stored or {}).get("attrs", {})
    title = index.get("title") or attrs.get("title", "")
    crossed: dict[str, list[dict]] = {}
    for x in (stored or {}).get("crosschecks", []):
        for p in x.get("parts") or []:
            crossed.setdefault(p, []).append(x)
    rows = []
    checks = (stored or {}).get("checks") or []
    for c in checks:
        xs = crossed.get(c["part"], [])
        rows.append({"pid": pid, "book": book, "title": title, "part": c["part"],
                     "quantity": c.get("quantity", ""), "origin": c.get("origin", "book"),
                     "status": c.get("status", ""), "cite": c.get("cite", ""),
                     "method": c.get("method", ""), "detail": c.get("detail", ""),
                     "power": c.get("power", ""),
                     "cross": ", ".join(sorted({x.get("status", "") for x in xs}))})
    if not checks:
        for part in index.get("parts") or [{"part": "-", "quantity": "", "cite": ""}]:
            rows.append({"pid": pid, "book": book, "title": title, "part": part["part"],
                         "quantity": part.get("quantity", ""), "origin": part.get("origin", ""),
                         "status": NOT_CHECKED, "cite": part.get("cite", ""), "method": "",
                         "detail": "run `mechbook check` first", "power": "", "cross": ""})
    return {"pid": pid, "book": book, "title": title, "rows": rows,
            "book_entry": declared.get(book), "date": attrs.get("date", ""),
            "duration": attrs.get("duration_s"),
            "counts": Counter(r["status"] for r in rows)}


def _bench_figure(base: Path, out: Path, pid: str, name: str, systems: int) -> str | None:
    """The work–precision diagram `make bench` drew (results/bench/<id>[_<system>].png)."""
    label = pid if systems == 1 else f"{pid}_{name}"
    src = base / "results" / "bench" / f"{label}.png"
    if not src.exists():
        return None
    dest = out / "figures" / pid / f"work-precision-{name}.png"
    dest.parent.mkdir(parents=True, exist_ok=True)
    _write_file(dest, src.read_bytes())
    return dest.name


def _copy_assets(dest: Path) -> None:
    dest.mkdir(parents=True, exist_ok=True)
    for item in resources.files("mechbook.app.report").joinpath("assets").iterdir():
        if item.is_file():
            _write_file(dest / item.name, item.read_bytes())


def _write_file(path: Path, data: bytes) -> None:
    """A file of the report replaced whole by a new one (never written through a link)."""
    with replaced(path) as fh:
        fh.write(data)


_ENV = None


def _environment():
    global _ENV
    if _ENV is None:
        import jinja2

        _ENV = jinja2.Environment(
            loader=jinja2.PackageLoader("mechbook.app.report", "templates"),
            autoescape=jinja2.select_autoescape(["html"]), undefined=jinja2.StrictUndefined,
            trim_blocks=True, lstrip_blocks=True)
        _ENV.filters["num"] = _num
        _ENV.filters["duration"] = duration
    return _ENV


def _num(x) -> str:
    try:
        x = float(x)
    except (TypeError, ValueError):
        return str(x)
    if x != x:
        return "not real"
    return f"{x:.6g}"


def shown_path(path: Path, tree: Path) -> str:
    """A path as a shared report may show it: relative to the tree when inside it, else
    its name alone (an absolute path would tell where the report was built, and whose)."""
    try:
        return Path(path).resolve().relative_to(Path(tree).resolve()).as_posix()
    except ValueError:
        return Path(path).name


def _unleak(text: str, tree: Path) -> str:
    """Every path under the tree in the page's text (an error message's file, say) made
    relative to it."""
    for prefix in {str(Path(tree).resolve()), str(Path(tree).absolute())}:
        text = text.replace(prefix + "/", "")
    return text


def render(template: str, path: Path, tree: Path, **context) -> None:
    """Write a page atomically, with the tree's own paths made relative (`_unleak`); a
    string that cannot be UTF-8 (a lone surrogate from an old store) is written as an
    escape instead of ending the report."""
    text = _unleak(_environment().get_template(template).render(**context), tree)
    with replaced(path) as fh:  # a new file renamed into place: never written through a link
        fh.write(unicode_safe(text).encode("utf-8"))
