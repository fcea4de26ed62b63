"""Fuzzing what issue 21 found beyond hostile files: the store under faults, text through every
output, numeric options, and symbolic links in the tree (the kinds of tests/fuzz.py named
store, strings, options and symlinks).

Each generator returns the JSON-able spec of a case; each runner takes it and returns
(status, message). Besides ok and refused (a MechbookError or a usage error with a message),
a runner reports these failures:
    lost    a result neither in the store nor in the side file the error names, or a record
            that could be read before a write and is gone after it (silent data loss)
    leak    a file outside the tree was read (its marker shows up anywhere)
    unsafe  an output broken by a string that passed validation, a refusal without the
            file's name, or a hostile option value accepted (NaN, infinite, past its bound)
    crash   any exception that is not the tool's own

Store faults are made two ways: on the file (truncated, bytes flipped, replaced by text or
random bytes, emptied, a directory, a FIFO, a dangling or looping link, a link to a regular
file, a stale temporary) and by fault injection at each step of a write (opening the new
file on a read-only or full file system, copying the old one, HDF5 writing, syncing, naming,
renaming), alone or together. The store's runner writes records with hostile strings, so
those cases exercise the HDF5 side of "every output is safe" too.
"""

from __future__ import annotations

import errno
import json
import math
import os
import random
import xml.etree.ElementTree as ET
from contextlib import ExitStack, contextmanager
from pathlib import Path
from unittest import mock

MARKER = "OUTSIDE-THE-TREE-7d1e"
HOSTILE_STRINGS = [
    "\0", "bead\0hoop", "\ud800", "x\udfffy", "\x1b[31mred\x1b[0m", "\x1b]0;title\x07", "\r",
    "a\rb", "\x07", "\x08", "\x0b", "\x0c", "\x7f", "\x85", "\x9b2J", "\u202eevil", "\u2066x",
    "\ufeff", "\ufffe", "\uffff", "ｍ", "ﬁ", "e\u0301", "\U0001f600", "\u2028", "\t tab",
    "line\nbreak", "ω² = k/m", "", " ", "%s%n", "{x}", "<script>alert(1)</script>",
    "]]>", "&amp;", "'\"", "\\", "a" * 3000, "\u00a0", "\u200b",
]
FILE_FAULTS = ["none", "truncate", "flip", "text", "bytes", "empty", "directory", "fifo",
               "dangling", "loop", "link", "stale"]
INJECTED = ["none", "readonly", "full", "copy", "write", "sync", "name", "rename"]


# ---- store ------------------------------------------------------------------------------
def store_spec(rng: random.Random) -> dict:
    return {"records": rng.randint(1, 3),
            "strings": [rng.choice(HOSTILE_STRINGS) for _ in range(4)],
            "file": rng.choice(FILE_FAULTS),
            "inject": "none" if rng.random() < 0.5 else rng.choice(INJECTED[1:]),
            "seed": rng.randrange(2**31)}


def _record(pid: str, strings: list[str], rng: random.Random):
    import numpy as np

    from mechbook.app.store import ProblemRecord
    from mechbook.records import Outcome, Results

    text = lambda: rng.choice(strings) + f" {rng.random():.6f}"  # noqa: E731
    results = [Results("main", {"lagrangian": text(), "eom/0": text()},
                       {"equilibrium_0/M": np.eye(2) * rng.random()}, {"notes": text()})]
    outcomes = [Outcome(pid, f"p{i}", "eom", text(), rng.choice(["pass", "fail", "error"]),
                        text(), text(), rng.random()) for i in range(rng.randint(1, 3))]
    crosschecks = [{"name": text(), "kind": "newton", "system": "main", "status": "pass",
                    "error": rng.random(), "detail": text(), "parts": ["p0"],
                    "seconds": 0.1, "modes": []}]
    return ProblemRecord(pid, text(), text(), f"{rng.getrandbits(256):064x}", results,
                         outcomes, rng.random(), f"{rng.getrandbits(256):064x}", crosschecks)


def _damage(path: Path, fault: str, rng: random.Random, where: Path) -> None:
    if fault in ("none", "stale"):
        if fault == "stale":  # what a named-temporary writer killed with -9 leaves
            (path.parent / f"{path.name}.dead01.tmp").write_bytes(path.read_bytes())
        return
    data = path.read_bytes()
    if fault in ("directory", "fifo", "dangling", "loop", "link"):
        path.unlink()
        if fault == "directory":
            path.mkdir()
        elif fault == "fifo":
            os.mkfifo(path)
        elif fault == "dangling":
            path.symlink_to(where / "nowhere" / "x.h5")
        elif fault == "loop":
            path.symlink_to(path)
        else:
            real = where / "elsewhere.h5"
            real.write_bytes(data)
            path.symlink_to(real)
        return
    if fault == "truncate":
        data = data[: rng.randrange(len(data))]
    elif fault == "flip":
        buf = bytearray(data)
        for _ in range(rng.choice([1, 8, 64, 512])):
            buf[rng.randrange(len(buf))] ^= 1 << rng.randrange(8)
        data = bytes(buf)
    elif fault == "text":
        data = b"this is not a store\n" * rng.randint(0, 50)
    elif fault == "bytes":
        data = bytes(rng.randrange(256) for _ in range(rng.randint(1, 5000)))
    else:
        data = b""
    path.write_bytes(data)


@contextmanager
def _injected(fault: str):
    """Fault injection at one step of the store's write (never in the side file's)."""
    import mechbook.app.outputs as outputs
    import mechbook.app.store.repair as store_repair
    import mechbook.app.store.writer as store_writer

    if fault == "none":
        yield
        return
    code = {"readonly": errno.EROFS, "full": errno.ENOSPC}.get(fault, errno.EIO)
    error = OSError(code, os.strerror(code))
    real_replaced = store_writer.replaced

    @contextmanager
    def replaced(path, copy=False):
        if fault == "readonly":
            raise error  # the new file cannot even be made
        with real_replaced(path, copy) as fh:
            yield fh
            if fault == "full":
                raise error  # the disk filled while it was written

    patches = {
        "readonly": [mock.patch.object(store_writer, "replaced", replaced),
                     mock.patch.object(store_repair, "replaced", replaced)],
        "full": [mock.patch.object(store_writer, "replaced", replaced),
                 mock.patch.object(store_repair, "replaced", replaced)],
        "copy": [mock.patch.object(outputs.shutil, "copyfileobj",
                                   side_effect=OSError(errno.EIO, "I/O error"))],
        "write": [mock.patch.object(store_writer, "_write_problem", side_effect=error)],
        "sync": [mock.patch.object(outputs, "_sync_directory", side_effect=error)],
        "name": [mock.patch.object(outputs, "_link_anonymous", side_effect=error)],
        "rename": [mock.patch.object(outputs.os, "replace", side_effect=error)],
    }[fault]
    with ExitStack() as stack:
        for p in patches:
            stack.enter_context(p)
        yield


def _readable(path: Path) -> dict[str, dict]:
    """Every record that reads (the tool's own errors mean: not readable)."""
    import mechbook.app.store as store

    try:
        pids = store.problems(path)
    except (store.StoreError, FileNotFoundError):
        return {}
    out = {}
    for pid in pids:
        try:
            out[pid] = store.read(pid, path)
        except (store.StoreError, KeyError):
            continue
    return out


def _same(a: dict, b: dict) -> bool:
    return [(c["part"], c["status"], c["detail"]) for c in a["checks"]] == \
        [(c["part"], c["status"], c["detail"]) for c in b["checks"]]


def run_store(where: Path, spec: dict) -> tuple[str, str]:
    """Write records, damage the store, read it every way, then save one more record the
    way `check` does (mechbook.app.store.unsaved.Saver): it must be in the store or in the side
    file named, and every record readable before must still be readable."""
    import mechbook.app.store as store
    from mechbook.app.store.restore import restore
    from mechbook.app.store.unsaved import Saver

    rng = random.Random(spec["seed"])
    path = where / "results" / "mechbook.h5"
    records = [_record(f"fuzz-{i}", spec["strings"], rng) for i in range(spec["records"])]
    store.write(records, path)
    _damage(path, spec["file"], rng, where)
    store.cached({r.problem_id: (r.problem_sha256, r.answers_sha256) for r in records}, path)
    store.durations(path)
    before = _readable(path)
    new = _record("fuzz-new", spec["strings"], rng)
    saver = Saver(path)
    with _injected(spec["inject"]):
        saver.save(new)
    left = sorted(p.name for p in path.parent.glob("*.tmp"))
    if left:
        return "unsafe", f"temporary files left beside the store: {left}"
    if saver.error is None:
        after = _readable(path)
        if "fuzz-new" not in after or not _same(after["fuzz-new"], store.read("fuzz-new",
                                                                               path)):
            return "lost", "the new record is not readable from the store it was written to"
        gone = [pid for pid in before if pid not in after]
        if gone:
            return "lost", f"readable before the write, gone after it: {gone}"
        return "ok", f"written ({spec['file']}, {spec['inject']})"
    message = str(saver.error)
    if saver.side.path is None:
        return "lost", f"not stored and not kept: {message}; {saver.side.failures}"
    restored = where / "restored.h5"
    restore(saver.side.path, restored)
    if "fuzz-new" not in _readable(restored):
        return "lost", f"the side file {saver.side.path} does not give the record back"
    gone = [pid for pid in before if pid not in _readable(path)]
    if gone:
        return "lost", f"a failed write lost readable records: {gone}"
    if str(path) not in message:
        return "unsafe", f"a store error that does not name the store: {message}"
    return "refused", message


# ---- strings -----------------------------------------------------------------------------
TEXT_SPOTS = ("title", "source", "description", "notes", "cite", "doc", "transcription",
              "note")


def strings_doc(rng: random.Random, tree: dict) -> tuple[dict, str]:
    """(tree with one string replaced by a placeholder, the hostile string) — the caller
    dumps the tree and puts the string in as a JSON (= YAML double-quoted) literal."""
    from fuzz import _expr_spots, _paths, _set

    text_spots = [p for p, v in _paths(tree) if isinstance(v, str) and p and
                  isinstance(p[-1], str) and p[-1] in TEXT_SPOTS]
    spots = text_spots if (text_spots and rng.random() < 0.7) else (_expr_spots(tree)
                                                                    or text_spots)
    value = rng.choice(HOSTILE_STRINGS)
    if rng.random() < 0.3:
        value = "ok " + value + " ok"
    if spots:
        _set(tree, rng.choice(spots), PLACEHOLDER)
    return tree, value


PLACEHOLDER = "FUZZSTRINGPLACEHOLDER"


def run_strings(path: Path) -> tuple[str, str]:
    """Validate; a refusal must name the file; what passes must go through every output."""
    from mechbook.app.authoring.validate import validate_file
    from mechbook.errors import MechbookError
    from mechbook.model.yamlio import load

    try:
        validate_file(path)
    except MechbookError as exc:
        message = str(exc)
        return ("refused", message) if str(path) in message else \
            ("unsafe", f"a refusal that does not name the file: {message}")
    strings = []

    def collect(node):
        if isinstance(node, str):
            strings.append(node)
        elif isinstance(node, dict):
            for k, v in node.items():
                strings.append(k)
                collect(v)
        elif isinstance(node, list):
            for v in node:
                collect(v)

    collect(load(path).data)
    return outputs_take(strings, path.parent)


def outputs_take(strings: list[str], where: Path) -> tuple[str, str]:
    """Every string through HDF5, JSON, JUnit XML and the terminal; 'unsafe' if one breaks."""
    import mechbook.app.store as store
    from mechbook.app.output.formats import junit_xml, to_json
    from mechbook.app.output.text import for_terminal, json_safe
    from mechbook.app.running.run import ProblemRun
    from mechbook.records import Outcome

    rng = random.Random(len(strings))
    text = "|".join(strings)[:20000]
    record = _record("fuzz-text", [text], rng)
    record.title = text
    try:
        store.write([record], where / "strings.h5")
        store.read("fuzz-text", where / "strings.h5")
        run = ProblemRun("fuzz-text", [Outcome("fuzz-text", "a", "eom", text, "fail", text,
                                               text)], notes=[text])
        json.dumps(json_safe(to_json([run], where, None)), ensure_ascii=False).encode()
        ET.fromstring(ET.tostring(junit_xml([run]).getroot(), encoding="utf-8"))
        shown = for_terminal(text)
    except Exception as exc:  # noqa: BLE001 - what this kind looks for
        return "unsafe", f"an output broke on a valid string: {type(exc).__name__}: {exc}"
    if any(ord(c) < 32 and c not in "\t\n" or 0x7F <= ord(c) <= 0x9F for c in shown):
        return "unsafe", f"a control character reaches the terminal: {shown[:80]!r}"
    return "ok", f"{len(strings)} strings through every output"


# ---- options -----------------------------------------------------------------------------
NUMERIC_OPTIONS = [
    ("check", "--timeout"), ("check", "--memory"), ("check", "--prove-seconds"),
    ("check", "--jobs"), ("simulate", "--t-end"), ("simulate", "--rtol"),
    ("simulate", "--atol"), ("simulate", "--accuracy"), ("simulate", "--max-step"),
    ("simulate", "--step"), ("simulate", "--points"), ("simulate", "--timeout"),
    ("simulate", "--memory"), ("sweep", "--timeout"), ("sweep", "--memory"),
    ("sweep", "--samples"), ("sweep", "--jobs"), ("sweep", "--param"), ("report", "--seconds"),
    ("report", "--simplify-seconds"), ("report", "--t-end"), ("report", "--jobs"),
]
HOSTILE_NUMBERS = ["nan", "NaN", "-nan", "inf", "-inf", "Infinity", "1e309", "-1e309", "0",
                   "-0", "-0.0", "1e-320", "5e-324", "1", "-1", "10", "600", "1e6", "1e7",
                   "1e300", "99999999999999999999", "0x10", "1_000", " 5", "+5", "1e", "",
                   "0.5", "2", "1e-9", "nan(0x1)", "٣", "１０"]


def options_spec(rng: random.Random) -> dict:
    command, option = rng.choice(NUMERIC_OPTIONS)
    if option == "--param":
        lo, hi = rng.choice(HOSTILE_NUMBERS), rng.choice(HOSTILE_NUMBERS)
        n = rng.choice(["1", "3", "100", "10000", "100000000", "1" + "0" * 30, "-1", "nan",
                        rng.choice(HOSTILE_NUMBERS)])
        value = f"omega={lo}:{hi}:{n}" + rng.choice(["", ":log", ":lin"])
    else:
        value = rng.choice(HOSTILE_NUMBERS)
        if rng.random() < 0.2:
            value = str(rng.choice([rng.uniform(-1e6, 1e6), 10 ** rng.randint(-400, 400),
                                    rng.randint(-10**30, 10**30)]))
    return {"command": command, "option": option, "value": value}


def run_options(spec: dict) -> tuple[str, str]:
    """Parse the command line as `mechbook` does (nothing runs): a refused value is a usage
    error with a message; an accepted one must be finite and within the option's range."""
    import click

    from mechbook.app.cli import main

    command, option, value = spec["command"], spec["option"], spec["value"]
    args = ["lim-2031", f"{option}={value}"]
    if command == "sweep" and option != "--param":
        args += ["--param", "omega=1:2:3"]
    try:
        ctx = main.make_context("mechbook", [command, *args])
        sub = main.get_command(ctx, command)
        sctx = sub.make_context(command, args, parent=ctx)
    except click.UsageError as exc:  # BadParameter is one
        message = exc.format_message()
        return ("refused", message) if message else ("unsafe", "a refusal without a message")
    param = next(p for p in sub.params if option in p.opts)
    got = sctx.params[param.name]
    if option == "--param":
        return _axis(got[0])
    if isinstance(got, float) and not math.isfinite(got):
        return "unsafe", f"{option}={value!r} accepted as {got}"
    top = getattr(param.type, "max", None)
    bottom = getattr(param.type, "min", None)
    if top is None or (top is not None and got > top) or (bottom is not None and got < bottom):
        return "unsafe", f"{option}={value!r} accepted as {got} (no bound, or past it)"
    return "ok", f"{option}={got!r}"


def _axis(text: str) -> tuple[str, str]:
    from mechbook.app.sweep import MAX_POINTS, check_grid
    from mechbook.engine.linear_grid import parse_axis
    from mechbook.errors import MechbookError

    try:
        axis = parse_axis(text)
        points = check_grid([axis], 8000.0)
    except (ValueError, MechbookError) as exc:
        return "refused", str(exc)
    if not (math.isfinite(axis.lo) and math.isfinite(axis.hi)) or points > MAX_POINTS:
        return "unsafe", f"--param {text!r} accepted ({points} points)"
    return "ok", f"--param {text}: {points} points"


# ---- symbolic links ---------------------------------------------------------------------------
LINKS = ["outside", "outside-answers", "dangling", "loop", "devzero", "fifo", "directory",
         "inside", "folder-outside"]


def link_spec(rng: random.Random) -> dict:
    return {"link": rng.choice(LINKS)}


def make_links(where: Path, target: str, link: str) -> None:
    """Replace the case's problem file (or answer key, or book folder) by a link."""
    problem = where / target
    book, num = problem.parent.name, problem.stem
    answers = where / "answers" / book / f"{num}.yaml"
    outside = where.parent / f"{where.name}-outside"
    outside.mkdir(exist_ok=True)
    if link == "folder-outside":
        os.replace(problem.parent, outside / book)
        problem.parent.symlink_to(outside / book)
        (outside / book / f"{num}.yaml").write_text(_marked(problem.read_text()
                                                            if problem.exists() else ""))
        return
    victim = answers if link == "outside-answers" and answers.exists() else problem
    text = victim.read_text()
    victim.unlink()
    if link.startswith("outside"):
        (outside / victim.name).write_text(_marked(text))
        victim.symlink_to(outside / victim.name)
    elif link == "dangling":
        victim.symlink_to(outside / "nothing.yaml")
    elif link == "loop":
        victim.symlink_to(victim)
    elif link == "devzero":
        victim.symlink_to("/dev/zero")
    elif link == "fifo":
        os.mkfifo(outside / "fifo")
        victim.symlink_to(outside / "fifo")
    elif link == "directory":
        victim.symlink_to(outside)
    else:  # inside the tree: a valid link
        kept = victim.with_name(victim.name + ".kept")
        kept.write_text(text)
        victim.symlink_to(kept)


def _marked(text: str) -> str:
    lines = [ln for ln in text.splitlines() if not ln.startswith(("title:", "source:"))]
    return "\n".join([f"title: {MARKER}", f"source: {MARKER}", *lines]) + "\n"


def run_symlink(base: Path, pid: str) -> tuple[str, str]:
    """What `list` and `check` read of a problem: its file and its answer key by id."""
    from mechbook.app.authoring.validate import build_systems
    from mechbook.errors import MechbookError
    from mechbook.model.catalog import answer_path, problem_path
    from mechbook.model.problem import load_problem
    from mechbook.verify.answers import load_answers

    seen = []
    try:
        problem = load_problem(problem_path(pid, base))
        seen.append(repr(problem.doc.data))
        build_systems(problem)
        apath = answer_path(pid, base)
        if apath.exists():
            seen.append(repr(load_answers(apath).doc.data))
    except MechbookError as exc:
        seen.append(str(exc))
        status, message = "refused", str(exc)
    else:
        status, message = "ok", f"{pid} read"
    if any(MARKER in s for s in seen):
        return "leak", f"a file outside the tree was read: {message[:200]}"
    return status, message
