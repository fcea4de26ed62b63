"""Writing the report: the index (every problem's outcome per part, errata, unsupported parts,
filters by book and status) and one page per problem, under one directory that works
offline (`results/report/index.html` by default).

The outcomes are read from the store that `mechbook check` wrote; a problem not in the store
is listed as "not checked". Problem pages are computed on worker processes (each page's
steps have their own limits, and a page that outlasts `page_timeout` is replaced by a page
that says so); work–precision diagrams that `make bench` left in results/bench/ are copied
beside the pages that concern them.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import shutil
import sys
from collections import Counter
from dataclasses import dataclass, field
from datetime import UTC, datetime
from importlib import resources
from pathlib import Path

from mechbook import __version__
from mechbook.app.report.page import PageOptions
from mechbook.model.books import books, split_id
from mechbook.model.catalog import all_ids
from mechbook.records import STATUSES

NOT_CHECKED = "not checked"


@dataclass(frozen=True)
class ReportOptions:
    jobs: int = 0  # worker processes (0: one per core)
    serial: bool = False  # pages in this process (tests, debugging)
    page: PageOptions = field(default_factory=PageOptions)
    page_timeout: float = 600.0  # seconds for one page, all steps together


def build_report(base: Path, store: Path, out: Path, ids: list[str] | None = None,
                 options: ReportOptions = ReportOptions(), log=None) -> Path:
    """Write the report for `ids` (every problem by default) to `out`; returns index.html."""
    log = log or (lambda text: print(text, file=sys.stderr))
    base, out = Path(base), Path(out)
    ids = list(ids or all_ids(base))
    stored, damaged = _stored(ids, Path(store), log)
    (out / "problems").mkdir(parents=True, exist_ok=True)
    _copy_assets(out / "assets")
    pages = _pages(ids, base, out, stored, options, log)
    for pid, why in damaged.items():
        pages[pid].setdefault("page_notes", []).append(f"its stored outcomes are not shown: "
                                                       f"{why}")
    declared = books(base)
    rows, problems_index = [], []
    for pid in ids:
        page = pages[pid]
        bench = _bench_figures(base, out, pid, [s["name"] for s in page.get("systems", [])])
        for system in page.get("systems", []):
            system["bench_figure"] = bench.get(system["name"])
        checks = {c["part"]: c for c in (stored.get(pid) or {}).get("checks", [])}
        for part in page.get("parts", []):
            part["check"] = checks.get(part["part"])
        entry = _index_entry(pid, page, stored.get(pid), declared)
        problems_index.append(entry)
        rows.extend(entry["rows"])
        _render("problem.html", out / "problems" / f"{pid}.html", page=page,
                stored=stored.get(pid), entry=entry, version=__version__)
    counts = Counter(r["status"] for r in rows)
    book_list = [{"id": b, "label": (declared[b].label if b in declared else b),
                  "book": declared.get(b)}
                 for b in sorted({e["book"] for e in problems_index})]
    index = out / "index.html"
    _render("index.html", index, problems=problems_index, rows=rows, books=book_list,
            statuses=[*STATUSES, NOT_CHECKED], counts=counts, version=__version__,
            store=str(store), date=datetime.now(UTC).isoformat(timespec="seconds"),
            errata=[r for r in rows if r["status"] == "erratum"],
            unsupported=[r for r in rows if r["status"] == "unsupported"])
    return index


def _stored(ids: list[str], store: Path, log) -> tuple[dict[str, dict], dict[str, str]]:
    """The stored records of `ids`, and {id: why} for those the store has but cannot give
    back (damaged): the report says so and shows them as not checked."""
    from mechbook.app.store import StoreError, problems, read

    if not store.exists():
        return {}, {}
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


def _pages(ids, base, out, stored, options: ReportOptions, log) -> dict[str, dict]:
    from mechbook.app.lifeline import die_with
    from mechbook.app.report.page import build_page

    args = {pid: (pid, base, out / "figures" / pid, stored.get(pid), options.page)
            for pid in ids}
    pages: dict[str, dict] = {}
    if options.serial:
        for pid in ids:
            pages[pid] = _guarded(build_page, *args[pid])
            log(f"page {pid} ({pages[pid].get('seconds', 0):.1f} s)")
        return pages
    jobs = options.jobs or (mp.cpu_count() or 1)
    ctx = mp.get_context("forkserver")
    ctx.set_forkserver_preload(["mechbook.app.report.page"])
    pool = ctx.Pool(jobs, maxtasksperchild=10, initializer=die_with, initargs=(os.getpid(),))
    try:
        pending = {pid: pool.apply_async(_guarded, (build_page, *args[pid])) for pid in ids}
        for pid, job in pending.items():
            try:
                pages[pid] = job.get(options.page_timeout)
            except mp.TimeoutError:
                pages[pid] = _failed(pid, f"the page took longer than "
                                          f"{options.page_timeout:g} s")
            log(f"page {pid} ({pages[pid].get('seconds', 0):.1f} s)")
    finally:
        pool.terminate()
        pool.join()
    return pages


def _guarded(fn, pid, *args) -> dict:
    try:
        return fn(pid, *args)
    except Exception as exc:  # noqa: BLE001 - one problem's page must not end the report
        return _failed(pid, f"{type(exc).__name__}: {exc}")


def _failed(pid: str, why: str) -> dict:
    return {"id": pid, "title": "", "source": "", "description": "", "notes_text": "",
            "parameters": [], "conditions": [], "systems": [], "parts": [],
            "crosscheck_figures": {}, "page_notes": [f"this page could not be built: {why}"],
            "seconds": 0.0}


def _index_entry(pid: str, page: dict, stored: dict | None, declared: dict) -> dict:
    book = split_id(pid)[0]
    attrs = (stored or {}).get("attrs", {})
    title = page.get("title") or attrs.get("title", "")
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
        for part in page.get("parts") or [{"part": "-", "quantity": "", "cite": ""}]:
            rows.append({"pid": pid, "book": book, "title": title, "part": part["part"],
                         "quantity": part.get("quantity", ""), "origin": part.get("origin", ""),
                         "status": NOT_CHECKED, "cite": part.get("cite", ""), "method": "",
                         "detail": "run `mechbook check` first", "power": "", "cross": ""})
    return {"pid": pid, "book": book, "title": title, "rows": rows,
            "book_entry": declared.get(book), "date": attrs.get("date", ""),
            "duration": attrs.get("duration_s"),
            "counts": Counter(r["status"] for r in rows)}


def _bench_figures(base: Path, out: Path, pid: str, systems: list[str]) -> dict[str, str]:
    """Work–precision diagrams of `make bench` (results/bench/<id>[_<system>].png)."""
    found = {}
    for name in systems:
        label = pid if len(systems) == 1 else f"{pid}_{name}"
        src = base / "results" / "bench" / f"{label}.png"
        if src.exists():
            dest = out / "figures" / pid / f"work-precision-{name}.png"
            dest.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(src, dest)
            found[name] = dest.name
    return found


def _copy_assets(dest: Path) -> None:
    dest.mkdir(parents=True, exist_ok=True)
    for item in resources.files("mechbook.app.report").joinpath("assets").iterdir():
        if item.is_file():
            (dest / item.name).write_bytes(item.read_bytes())


def _environment():
    import jinja2

    env = jinja2.Environment(loader=jinja2.PackageLoader("mechbook.app.report", "templates"),
                             autoescape=jinja2.select_autoescape(["html"]),
                             undefined=jinja2.StrictUndefined, trim_blocks=True,
                             lstrip_blocks=True)
    env.filters["num"] = _num
    return env


def _num(x) -> str:
    try:
        x = float(x)
    except (TypeError, ValueError):
        return str(x)
    if x != x:
        return "not real"
    return f"{x:.6g}"


def _render(template: str, path: Path, **context) -> None:
    """Write a page; a string that cannot be UTF-8 (a lone surrogate from an old store) is
    written as an escape instead of ending the report."""
    from mechbook.app.text import unicode_safe

    text = _environment().get_template(template).render(**context)
    path.write_text(unicode_safe(text), encoding="utf-8")
