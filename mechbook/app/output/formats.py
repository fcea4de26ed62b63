"""Machine-readable results of `mechbook check`: JSON (--format json, its JSON Schema in
mechbook/app/schemas/check-result.json) and JUnit XML (--junit-xml) for CI dashboards.

JUnit XML is written with the standard library's ElementTree: the format is a handful of
elements (testsuites > testsuite per problem > testcase per answer part and per
cross-check), and the maintained JUnit packages add nothing a CI reader needs.
Mapping: pass and erratum (the book's error is recorded and the corrected value passes) are
passing cases, fail a <failure>, error an <error>, unsupported a <skipped> with the missing
capability; a problem that could not be checked is one <error> case.
"""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET
from collections import Counter
from importlib import resources
from pathlib import Path

from mechbook.app.output.text import for_xml
from mechbook.app.outputs import OutputError, output_file, replaced
from mechbook.records import CROSSCHECK_STATUSES, FAILING, STATUSES, Status
from mechbook.version import __version__


def schema() -> dict:
    """The JSON Schema of `mechbook check --format json`."""
    text = resources.files("mechbook.app").joinpath("schemas", "check-result.json") \
        .read_text("utf-8")
    return json.loads(text)


def _number(x) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


def failures(runs: list) -> int:
    """What makes `mechbook check` exit 1: problems not checked, parts that failed or
    errored, cross-checks that failed."""
    return (sum(1 for r in runs if r.error)
            + sum(1 for r in runs for o in r.outcomes if o.status in FAILING)
            + sum(1 for r in runs for x in r.crosschecks if x.failed))


def to_json(runs: list, root: Path, store: Path | None, store_error: str | None = None) -> dict:
    """The JSON document of a check run (plain data; `json.dumps` it). `store` is where the
    results were written (None: nowhere); `store_error` why they could not be."""
    problems, parts, crossed = [], Counter(), Counter()
    for run in runs:
        vouch: dict[str, list[str]] = {}
        for x in run.crosschecks:
            crossed[x.status] += 1
            for p in x.parts:
                vouch.setdefault(p, []).append(x.name)
        rows = []
        for o in run.outcomes:
            parts[o.status] += 1
            rows.append({"part": o.part, "quantity": o.quantity, "cite": o.cite,
                         "origin": o.origin, "status": o.status, "method": o.method,
                         "detail": o.detail, "power": o.power, "seconds": float(o.seconds),
                         "crosschecks": vouch.get(o.part, [])})
        problems.append({
            "id": run.pid, "book": run.pid.split("-", 1)[0], "error": run.error,
            "seconds": float(run.seconds), "cached": bool(run.cached), "parts": rows,
            "crosschecks": [{"name": x.name, "kind": x.kind, "system": x.system,
                             "status": x.status, "error": _number(x.error),
                             "detail": x.detail, "parts": list(x.parts),
                             "seconds": float(x.seconds)} for x in run.crosschecks],
            "notes": list(run.notes)})
    bad = failures(runs)
    summary = {"problems": len(runs), "parts": sum(parts.values()),
               **{s: parts[s] for s in STATUSES},
               "problem_errors": sum(1 for r in runs if r.error),
               "crosschecks": {s: crossed[s] for s in CROSSCHECK_STATUSES},
               "failures": bad, "ok": bad == 0}
    if store_error:
        summary["ok"] = False
    return {"format": 1, "mechbook": __version__, "root": str(root),
            "store": str(store) if store is not None else None, "store_error": store_error,
            "problems": problems, "summary": summary}


def junit_xml(runs: list) -> ET.ElementTree:
    """A JUnit XML tree of a check run: one testsuite per problem."""
    top = ET.Element("testsuites", name="mechbook check")
    totals = Counter()
    for run in runs:
        suite = ET.SubElement(top, "testsuite", name=run.pid)
        counts = Counter()
        if run.error:
            case = ET.SubElement(suite, "testcase", classname=run.pid, name="load and check",
                                 time=f"{run.seconds:.3f}")
            ET.SubElement(case, "error", message=run.error[:500]).text = run.error
            counts.update(tests=1, errors=1)
        for o in run.outcomes:
            case = ET.SubElement(suite, "testcase", classname=run.pid,
                                 name=f"{o.part} [{o.quantity}]", time=f"{o.seconds:.3f}")
            counts["tests"] += 1
            text = f"{o.cite}\n{o.method} {o.detail}".strip()
            if o.power:
                ET.SubElement(case, "properties").append(
                    ET.Element("property", name="power", value=o.power))
            if o.status == Status.FAIL:
                ET.SubElement(case, "failure", message=o.detail[:500] or "fail").text = text
                counts["failures"] += 1
            elif o.status == Status.ERROR:
                ET.SubElement(case, "error", message=o.detail[:500] or "error").text = text
                counts["errors"] += 1
            elif o.status == Status.UNSUPPORTED:
                ET.SubElement(case, "skipped", message=f"unsupported: {o.detail}"[:500])
                counts["skipped"] += 1
            elif o.status == Status.ERRATUM:
                ET.SubElement(case, "system-out").text = f"erratum: {o.detail}"
        for x in run.crosschecks:
            case = ET.SubElement(suite, "testcase", classname=run.pid,
                                 name=f"cross-check {x.name}", time=f"{x.seconds:.3f}")
            counts["tests"] += 1
            if x.status == Status.FAIL:
                ET.SubElement(case, "failure", message=x.detail[:500] or "fail").text = x.detail
                counts["failures"] += 1
            elif x.status == Status.ERROR:
                ET.SubElement(case, "error", message=x.detail[:500] or "error").text = x.detail
                counts["errors"] += 1
            elif x.status == Status.NA:
                ET.SubElement(case, "skipped", message=f"n.a.: {x.detail}"[:500])
                counts["skipped"] += 1
        suite.set("time", f"{run.seconds:.3f}")
        for key in ("tests", "failures", "errors", "skipped"):
            suite.set(key, str(counts[key]))
        totals.update(counts)
    for key in ("tests", "failures", "errors", "skipped"):
        top.set(key, str(totals[key]))
    _xml_safe(top)
    ET.indent(top)
    return ET.ElementTree(top)


def write_junit(runs: list, path: Path) -> Path:
    """Write the JUnit XML, replacing a regular file (or nothing) at `path` whole
    (mechbook.app.outputs); OutputError with the path and the reason if it cannot be."""
    path = Path(path)
    real = output_file(path, "JUnit XML file")
    tree = junit_xml(runs)
    try:
        real.parent.mkdir(parents=True, exist_ok=True)
        with replaced(real) as fh:
            tree.write(fh, encoding="utf-8", xml_declaration=True)
    except OSError as exc:
        raise OutputError(path, exc.strerror or str(exc), "JUnit XML file") from exc
    return path


def _xml_safe(top: ET.Element) -> None:
    """Every attribute and text of the tree made legal XML 1.0 (a control character in a
    detail or a cite would make the document malformed)."""
    for el in top.iter():
        el.attrib.update({k: for_xml(v) for k, v in el.attrib.items()})
        if el.text:
            el.text = for_xml(el.text)
