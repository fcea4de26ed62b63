"""Fuzzing the surfaces issue 33 attacked (the kinds of tests/fuzz.py named restore, init,
watch, pagelist, hdf5 and regex): what mechbook reads back of its own (a side file, the
report's page list, a store), what it writes into a folder it is given (init), what it polls
(watch), and the regular expressions a user writes (books.yaml).

Each generator returns the JSON-able spec of a case; each runner takes the case's folder and
its spec and returns (status, message). A case's tree is `<case>/tree`; `<case>/outside`
holds files that must never change, and the case's parent folder must gain nothing but other
cases. Besides ok, refused (a MechbookError with a message) and crash (anything else), a
runner reports:
    outside  a file written, changed or removed outside the tree
    lost     a result a restore said it stored that its store does not give back
    leak     a marker kept outside the store or the tree shows up in what was read
    unsafe   a refusal that does not name what it refused, a foreign file changed
The batch that runs the cases (tests/fuzz.py) reports hang (its time limit) and bomb (its
memory bound): a read without bound shows there.
"""

from __future__ import annotations

import hashlib
import json
import os
import random
from pathlib import Path

MARKER = "OUTSIDE-THE-TREE-52b1"


# ---- what must not change ----------------------------------------------------------------
def _snapshot(top: Path) -> dict[str, str]:
    """Every entry under `top` (links not followed, special files by kind), with a hash of
    each regular file's bytes."""
    out = {}
    if not top.exists():
        return out
    for dirpath, dirnames, filenames in os.walk(top):
        for name in dirnames + filenames:
            path = Path(dirpath) / name
            try:
                st = path.lstat()
            except OSError:
                continue
            rel = str(path.relative_to(top))
            if path.is_symlink():
                out[rel] = "link " + os.readlink(path)
            elif path.is_file() and st.st_size <= 1 << 22:
                out[rel] = hashlib.sha256(path.read_bytes()).hexdigest()
            else:
                out[rel] = f"mode {st.st_mode:o} size {st.st_size}"
    return out


class Guard:
    """The outside of a case: its `outside` folder, its own folder but the tree, and the
    chunk's folder (which only other cases may add to)."""

    def __init__(self, where: Path):
        self.where = where
        self.outside = where / "outside"
        self.outside.mkdir(exist_ok=True)
        (self.outside / "kept.txt").write_text(MARKER)
        self.before = self._state()

    def _state(self) -> tuple:
        own = {k: v for k, v in _snapshot(self.where).items()
               if not k.startswith("tree/") and k != "tree"}
        chunk = sorted(n for n in os.listdir(self.where.parent) if not n.startswith("case-"))
        return own, chunk

    def changed(self) -> str | None:
        own, chunk = self._state()
        if chunk != self.before[1]:
            return f"the chunk's folder gained {sorted(set(chunk) - set(self.before[1]))}"
        if own != self.before[0]:
            diff = sorted(set(own.items()) ^ set(self.before[0].items()))
            return f"outside the tree: {diff[:3]}"
        return None


def _tree(where: Path, pids=("lim-2101",)) -> Path:
    """A small tree: pendulum problems and keys (tests/hostile.py), books.yaml."""
    from hostile import pendulum_tree

    return pendulum_tree(where / "tree", nums=tuple(p.split("-", 1)[1] for p in pids))


def _special(path: Path, kind: str, guard: Guard) -> None:
    """Put `kind` at `path` (replacing what is there)."""
    import shutil

    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    elif os.path.lexists(path):
        path.unlink()
    path.parent.mkdir(parents=True, exist_ok=True)
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "devzero":
        path.symlink_to("/dev/zero")
    elif kind == "directory":
        path.mkdir()
    elif kind == "dangling":
        path.symlink_to(guard.outside / "nothing-here")
    elif kind == "loop":
        path.symlink_to(path)
    elif kind == "outside-link":
        path.symlink_to(guard.outside / "kept.txt")
    elif kind == "sparse":
        with open(path, "wb") as fh:
            fh.truncate(3 * 2**30)
    elif kind == "empty":
        path.write_bytes(b"")


def _message(exc: BaseException) -> str:
    return str(exc)


def _refused(exc: BaseException, names: str | None = None) -> tuple[str, str]:
    message = _message(exc)
    if not message.strip():
        return "crash", f"{type(exc).__name__} with an empty message"
    if names is not None and names not in message:
        return "unsafe", f"a refusal that does not name {names}: {message[:300]}"
    return "refused", message


def _crash(exc: BaseException) -> tuple[str, str]:
    import traceback

    return "crash", f"{type(exc).__name__}: {exc}\n{traceback.format_exc()}"


# ---- restore -----------------------------------------------------------------------------
SIDE_SPECIALS = ["fifo", "devzero", "directory", "dangling", "loop", "sparse", "empty"]
STORE_PLACES = ["tree", "tree-relative", "absolute-outside", "relative-outside", "../../up",
                "linked-outside", "books.yaml", "directory", "fifo", "problem-file", "", None,
                7, "nul\x00byte"]
HOSTILE_IDS = ["../../x", "a/b", "lim-2031\x00x", "lim-2031/../../y", "", None, 7, ".", "..",
               "lim-" + "9" * 200, "LIM-2031", "lim-2031 ", "lim--2031", "lim-20\u00b31"]


def restore_spec(rng: random.Random) -> dict:
    return {"lines": rng.randint(1, 6), "seed": rng.randrange(2**31),
            "special": rng.choice(SIDE_SPECIALS) if rng.random() < 0.15 else None,
            "store": rng.choice(STORE_PLACES) if rng.random() < 0.5 else "tree",
            "mutate": rng.choice(["none", "id", "field", "value", "deep", "json", "format",
                                  "kind", "huge", "simulation"])}


def _place(where: Path, tree: Path, guard: Guard, how) -> object:
    """The `store` a side file's line names."""
    if how == "tree":
        return str(tree / "results" / "mechbook.h5")
    if how == "tree-relative":
        return "results/restored.h5"
    if how == "absolute-outside":
        return str(guard.outside / "absolute.h5")
    if how == "relative-outside":
        return "../outside/relative.h5"
    if how == "../../up":
        return "../../escaped.h5"
    if how == "linked-outside":
        link = tree / "results" / "linked.h5"
        link.parent.mkdir(parents=True, exist_ok=True)
        if not os.path.lexists(link):
            link.symlink_to(guard.outside / "through-link.h5")
        return "results/linked.h5"
    if how == "books.yaml":
        return "books.yaml"
    if how == "directory":
        (tree / "results" / "adir.h5").mkdir(parents=True, exist_ok=True)
        return "results/adir.h5"
    if how == "fifo":
        path = tree / "results" / "fifo.h5"
        path.parent.mkdir(parents=True, exist_ok=True)
        if not os.path.lexists(path):
            os.mkfifo(path)
        return "results/fifo.h5"
    if how == "problem-file":
        return "problems/lim/2101.yaml"
    return how


def _side_line(rng: random.Random, pid: str, store: object, spec: dict) -> str:
    from dataclasses import asdict

    import fuzz
    from fuzz_faults import HOSTILE_STRINGS, _record

    from mechbook.app.output.text import json_safe
    from mechbook.app.store.unsaved import json_default

    record = json.loads(json.dumps(json_safe(asdict(_record(pid, rng.sample(HOSTILE_STRINGS,
                                                                            4), rng))),
                                   default=json_default))
    entry = {"format": 1, "kind": "problem", "store": store, "record": record}
    mutate = spec["mutate"] if rng.random() < 0.6 else "none"
    if mutate == "id":
        record["problem_id"] = rng.choice(HOSTILE_IDS)
    elif mutate == "field":
        target = rng.choice([record, record["outcomes"][0], record["results"][0],
                             record["crosschecks"][0], entry])
        key = rng.choice(list(target))
        if rng.random() < 0.3:
            del target[key]
        else:
            target[key] = fuzz._random_value(rng, ["x", "lim-2101"])
    elif mutate == "value":
        record[rng.choice(["title", "source", "duration", "outcomes", "results"])] = \
            rng.choice(fuzz.HOSTILE_VALUES)
    elif mutate == "deep":
        n = rng.choice([40, 1000, 100_000])
        return json.dumps(entry)[:-1] + ', "deep": ' + "[" * n + "]" * n + "}\n"
    elif mutate == "json":
        text = json.dumps(entry)
        i = rng.randrange(len(text))
        return text[:i] + rng.choice(["{", "]", '"', "\\", "\x00", "NaN", ",,"]) + text[i:] + "\n"
    elif mutate == "format":
        entry["format"] = rng.choice([0, 2, 99, "1", None, 1.5])
    elif mutate == "kind":
        entry["kind"] = rng.choice(["sweep", "", None, 3, "PROBLEM"])
    elif mutate == "huge":
        record["title"] = "x" * rng.choice([70_000, 2_000_000])
    elif mutate == "simulation":
        entry = {"format": 1, "kind": "simulation", "store": store,
                 "problem_id": rng.choice([pid, *HOSTILE_IDS]),
                 "name": rng.choice(["main-RK4", "../x", "", ".hidden", "a/b", "ok+1"]),
                 "arrays": rng.choice([{"t": [0.0, 1.0], "q": [[0.0, 1.0]]},
                                       {"t": [[1], [2, 3]]}, {"../t": [1.0]}, {"t": "x"}]),
                 "attrs": rng.choice([{"method": "RK4"}, {"": 1}, {"a/b": 2}, []]),
                 "array_attrs": rng.choice([{}, {"t": {"x": 1}}, {"nope": {}}])}
    return json.dumps(entry, allow_nan=True) + "\n"


def run_restore(where: Path, spec: dict) -> tuple[str, str]:
    """Write a side file (good and hostile lines), restore it as `mechbook restore` does
    from inside the tree; nothing outside may change; what it says it stored reads back."""
    from mechbook.app.store.reader import read
    from mechbook.app.store.restore import restore
    from mechbook.errors import MechbookError

    rng = random.Random(spec["seed"])
    tree = _tree(where)
    guard = Guard(where)
    side = tree / "results" / "kept.jsonl"
    side.parent.mkdir(parents=True, exist_ok=True)
    lines, wanted = [], []
    for i in range(spec["lines"]):
        pid = f"lim-{2101 + i}"
        store = _place(where, tree, guard, spec["store"] if i == 0 or rng.random() < 0.3
                       else "tree")
        lines.append(_side_line(rng, pid, store, spec))
        wanted.append(pid)
    side.write_text("".join(lines), encoding="utf-8", errors="surrogatepass")
    if spec["special"]:
        _special(side, spec["special"], guard)
    try:
        problems, simulations = restore(side, None, tree)
    except MechbookError as exc:
        status, message = _refused(exc, str(side))
    except Exception as exc:  # noqa: BLE001 - what the fuzzer looks for
        return _crash(exc)
    else:
        status, message = "ok", f"{problems} problem(s), {simulations} simulation(s)"
        for line in lines:
            entry = json.loads(line)
            if entry.get("kind") != "problem":
                continue
            named = Path(entry["store"])
            path = named if named.is_absolute() else tree / named
            try:
                read(entry["record"]["problem_id"], path)
            except Exception as exc:  # noqa: BLE001
                return "lost", f"restored, but {path} does not give it back: {exc}"
    moved = guard.changed()
    if moved:
        return "outside", moved
    return status, message


# ---- init --------------------------------------------------------------------------------
PLANTS = ["none", "dangling-file", "linked-folder", "linked-subfolder", "file-for-folder",
          "fifo-file", "existing-file", "deep-dangling", "dir-is-link", "dir-is-dangling",
          "dir-is-fifo"]


def init_spec(rng: random.Random) -> dict:
    return {"plant": rng.choice(PLANTS), "seed": rng.randrange(2**31),
            "name": rng.choice(["tree", "tree", "a/b/c", "", " ", "x" * 300, "y/" + "z" * 256,
                                "-dash", "name with spaces", "é", "a\nb", "t" * 255])}


def run_init(where: Path, spec: dict) -> tuple[str, str]:
    """`mechbook init NAME` (its command, in this process) with something planted under
    NAME first: nothing may be written outside NAME, and what it writes is regular files."""
    from click.testing import CliRunner

    from mechbook.app.authoring.init import FILES
    from mechbook.app.cli import main

    guard = Guard(where)
    root = where / "tree"
    root.mkdir()
    rng = random.Random(spec["seed"])
    name = spec["name"]
    target = root / name if name.strip() else root
    plant = spec["plant"]
    dest = rng.choice(list(FILES.values()))
    if not name.strip() and plant.startswith("dir-is"):
        plant = "none"  # '' names the current folder, which exists: nothing to plant there
    try:
        if plant == "dir-is-link":
            (root / "real").mkdir()
            Path(target).parent.mkdir(parents=True, exist_ok=True)
            target.symlink_to(root / "real")
        elif plant == "dir-is-dangling":
            target.parent.mkdir(parents=True, exist_ok=True)
            target.symlink_to(guard.outside / "no-dir")
        elif plant == "dir-is-fifo":
            target.parent.mkdir(parents=True, exist_ok=True)
            os.mkfifo(target)
        elif plant != "none":
            path = target / dest
            if plant in ("linked-folder", "linked-subfolder", "file-for-folder"):
                parts = Path(dest).parts
                folder = target / (parts[0] if plant != "linked-subfolder" or len(parts) < 3
                                   else Path(parts[0]) / parts[1])
                folder.parent.mkdir(parents=True, exist_ok=True)
                if plant == "file-for-folder":
                    folder.write_text("a file where a folder goes")
                else:
                    folder.symlink_to(guard.outside, target_is_directory=True)
            else:
                path.parent.mkdir(parents=True, exist_ok=True)
                if plant in ("dangling-file", "deep-dangling"):
                    path.symlink_to(guard.outside / "planted" / "deeper" if plant ==
                                    "deep-dangling" else guard.outside / "planted")
                elif plant == "fifo-file":
                    os.mkfifo(path)
                else:
                    path.write_text("mine")
    except OSError as exc:  # the name itself cannot be made here (too long): init decides
        if not name.strip() or len(name) < 200:
            raise
        _ = exc
    cwd = os.getcwd()
    os.chdir(root)
    try:
        res = CliRunner().invoke(main, ["init", "--", name])  # a name may start with "-"
    finally:
        os.chdir(cwd)
    moved = guard.changed()
    if moved:
        return "outside", moved
    if res.exception is not None and not isinstance(res.exception, SystemExit):
        import traceback

        return "crash", "".join(traceback.format_exception(res.exception))[-2000:]
    if res.exit_code != 0:
        message = res.output.strip()
        return ("refused", message) if message.startswith("Error: ") else \
            ("crash", f"exit {res.exit_code} without a message: {message[:300]}")
    real = Path(os.path.realpath(target))
    for rel in FILES.values():
        path = real / rel
        if path.is_symlink() or not path.is_file():
            return "unsafe", f"init reported success but {path} is not a regular file"
    return "ok", f"initialized {name!r}"


# ---- watch -------------------------------------------------------------------------------
WATCHED = ["problem", "answers", "books"]
WATCH_KINDS = ["fifo", "devzero", "directory", "dangling", "loop", "outside-link", "sparse",
               "empty", "large", "bytes", "good"]


def watch_spec(rng: random.Random) -> dict:
    return {"which": rng.choice(WATCHED), "kind": rng.choice(WATCH_KINDS),
            "seed": rng.randrange(2**31)}


def run_watch(where: Path, spec: dict) -> tuple[str, str]:
    """What `watch` does on a save: poll its three files (their signature) and check the
    problem (the task its worker runs), with one of them replaced by what an editor or a
    user can leave behind. Neither may block, read without bound, or end in a traceback."""
    from mechbook.app.authoring.watch import check_in_worker, files_signature, report_lines
    from mechbook.app.running.run import RunOptions

    tree = _tree(where)
    guard = Guard(where)
    paths = {"problem": tree / "problems" / "lim" / "2101.yaml",
             "answers": tree / "answers" / "lim" / "2101.yaml", "books": tree / "books.yaml"}
    path = paths[spec["which"]]
    rng = random.Random(spec["seed"])
    kind = spec["kind"]
    if kind == "large":
        path.write_text("# " + "x" * rng.choice([140_000, 2_000_000]) + "\n")
    elif kind == "bytes":
        path.write_bytes(bytes(rng.randrange(256) for _ in range(rng.randint(1, 3000))))
    elif kind != "good":
        _special(path, kind, guard)
    before = files_signature(list(paths.values()))
    try:
        run, cpu = check_in_worker("lim-2101", tree, RunOptions(crosscheck=False),
                                   lambda text: None)
        lines = report_lines(run, run.seconds, cpu)
    except Exception as exc:  # noqa: BLE001 - the worker reports a task that raises as its
        return _crash(exc)  # failure; the fuzzer wants to see it
    after = files_signature(list(paths.values()))
    text = "\n".join(lines)
    if "Traceback" in text or any("Traceback" in d for d in run.debug):
        return "crash", text[:2000] + "\n".join(run.debug)[:2000]
    if MARKER in text:
        return "leak", text[:500]
    moved = guard.changed()
    if moved:
        return "outside", moved
    if before != after:
        return "unsafe", "checking changed what watch polls"
    return ("refused", run.error) if run.error else ("ok", lines[0])


# ---- the report's page list --------------------------------------------------------------
PAGELISTS = ["fifo", "devzero", "directory", "dangling", "loop", "outside-link", "sparse",
             "empty", "nested", "random", "shapes", "bytes", "good", "tmp-link"]


def pagelist_spec(rng: random.Random) -> dict:
    return {"kind": rng.choice(PAGELISTS), "seed": rng.randrange(2**31)}


def run_pagelist(where: Path, spec: dict) -> tuple[str, str]:
    """The report's reading and writing of its page list, with a hostile one in place: load
    it, build the index's entries from it, save it again."""
    import fuzz

    from mechbook.app.report import cache
    from mechbook.app.report.build import index_entry

    rng = random.Random(spec["seed"])
    tree = _tree(where)
    guard = Guard(where)
    out = tree / "results" / "report"
    out.mkdir(parents=True)
    path = out / cache.MANIFEST
    kind = spec["kind"]
    good = {"format": 1, "pages": {"lim-2101": {"key": "0" * 64, "index": {
        "title": "a pendulum", "parts": [{"part": "a", "quantity": "eom", "origin": "book",
                                          "cite": "test"}]}, "seconds": 1.0}}}
    if kind == "nested":
        n = rng.choice([33, 1000, 200_000])
        path.write_text("[" * n + "]" * n)
    elif kind == "random":
        path.write_text(json.dumps({"format": 1, "pages": fuzz._random_value(rng, ["lim-2101"])},
                                   allow_nan=True))
    elif kind == "shapes":
        entry = good["pages"]["lim-2101"]
        target = rng.choice([entry, entry["index"], entry["index"]["parts"][0]])
        target[rng.choice(list(target))] = rng.choice(fuzz.HOSTILE_VALUES)
        path.write_text(json.dumps(good, allow_nan=True))
    elif kind == "bytes":
        path.write_bytes(bytes(rng.randrange(256) for _ in range(rng.randint(1, 5000))))
    elif kind == "good":
        path.write_text(json.dumps(good))
    elif kind == "tmp-link":  # the old writer's guessable temporary name, planted
        for pid in range(1, 65536, 4096):
            (out / f"{cache.MANIFEST}.{pid}.tmp").symlink_to(guard.outside / "kept.txt")
        (out / f"{cache.MANIFEST}.{os.getpid()}.tmp").symlink_to(guard.outside / "kept.txt")
    else:
        _special(path, kind, guard)
    try:
        pages = cache.load(out)
        for pid in pages:
            index_entry(pid, (pages.get(pid) or {}).get("index") or {}, None, {})
        pages["lim-2101"] = {"key": "1" * 64, "index": {"title": "t", "parts": []},
                             "seconds": 0.5}
        cache.save(out, pages)
    except Exception as exc:  # noqa: BLE001
        return _crash(exc)
    moved = guard.changed()
    if moved:
        return "outside", moved
    if MARKER in json.dumps(pages, default=str):
        return "leak", "a file outside the tree was read as the page list"
    return "ok", f"{kind}: {len(pages)} page(s) kept"


# ---- hostile stores ------------------------------------------------------------------------
HDF5_FAULTS = ["bomb-gzip", "bomb-lzf", "unallocated", "big-numeric-attr", "big-text-attr",
               "foreign", "format", "soft-loop", "external", "hard-cycle", "many-strings",
               "compound", "deep-groups", "many-groups", "missing-attr", "attr-type",
               "bad-status", "bad-json", "deep-json", "problems-dataset", "record-dataset",
               "reference", "external-storage", "virtual", "sweep-bomb", "simulation-bomb"]


def hdf5_spec(rng: random.Random) -> dict:
    return {"fault": rng.choice(HDF5_FAULTS), "records": rng.randint(1, 3),
            "seed": rng.randrange(2**31)}


def _hostile_hdf5(path: Path, fault: str, rng: random.Random, guard: Guard) -> None:
    import h5py
    import numpy as np

    outside = guard.outside / "outside.h5"
    with h5py.File(outside, "w") as f:
        f.attrs["format"] = 1
        f.create_dataset("secret", data=MARKER, dtype=h5py.string_dtype())
        f.create_dataset("data", data=np.full(100, 7.0))
    if fault == "foreign":
        path.unlink()
        with h5py.File(path, "w") as f:
            f.create_dataset("measurements", data=np.arange(rng.randint(1, 1000), dtype=float))
            f.attrs["instrument"] = "spectrometer"
        return
    with h5py.File(path, "a") as f:
        rec = f["problems"][sorted(f["problems"])[0]]
        if fault in ("bomb-gzip", "bomb-lzf", "unallocated", "simulation-bomb"):
            n = rng.choice([10**8, 4 * 10**8, 10**10])
            where = rec.require_group("simulations/main-RK4") if fault == "simulation-bomb" \
                else rec.require_group("systems/main/numeric")
            d = where.create_dataset("bomb", shape=(n,), dtype="f8", chunks=(1 << 18,),
                                     compression=None if fault == "unallocated" else
                                     ("gzip" if fault == "bomb-gzip" else "lzf"),
                                     fillvalue=rng.choice([0.0, 1.5]))
            if fault != "unallocated":
                d[: 1 << 18] = 0.0
        elif fault == "sweep-bomb":
            g = f.require_group("sweeps").require_group(rec.name.rsplit("/", 1)[-1])
            s = g.create_group("map")
            d = s.create_dataset("frequencies", shape=(10**9,), dtype="f8", chunks=(1 << 18,),
                                 compression="gzip")
            d[: 1 << 18] = 1.0
        elif fault == "big-numeric-attr":
            rec.attrs.create("blob", np.zeros(rng.choice([200_000, 2_000_000])))
        elif fault == "big-text-attr":
            rec.attrs.create(rng.choice(["title", "notes"]),
                             "x" * rng.choice([2_000_000, 20_000_000]),
                             dtype=h5py.string_dtype())
        elif fault == "format":
            f.attrs["format"] = rng.choice([2, 99, -1, 0, "1", 1.5, np.arange(3), True])
        elif fault == "soft-loop":
            rec["systems/main/symbolic/loop"] = h5py.SoftLink(rng.choice(["/", rec.name]))
        elif fault == "external":
            rec["systems/main/symbolic/ext"] = h5py.ExternalLink(str(outside),
                                                                 rng.choice(["/", "/secret"]))
        elif fault == "hard-cycle":
            rec["systems/main/symbolic/cycle"] = rec["systems"]
        elif fault == "many-strings":
            rec["systems/main"].create_dataset("symbolic/many", data=np.array(
                ["x" * 10] * rng.choice([5000, 100_000]), dtype=object),
                dtype=h5py.string_dtype())
        elif fault == "compound":
            rec["systems/main"].create_dataset("numeric/compound", data=np.zeros(
                3, dtype=[("a", "f8"), ("b", "i4")]))
        elif fault == "deep-groups":
            g = rec["systems/main"]
            for i in range(rng.choice([30, 200])):
                g = g.create_group(f"d{i}")
        elif fault == "many-groups":
            g = rec["systems/main/notes"] if "notes" in rec["systems/main"] else \
                rec["systems/main"].create_group("notes")
            for i in range(rng.choice([2000, 20_000])):
                g.create_group(f"g{i}")
        elif fault == "missing-attr":
            del rec.attrs[rng.choice(["title", "source", "problem_sha256", "date",
                                      "mechbook", "duration_s"])]
        elif fault == "attr-type":
            rec.attrs[rng.choice(["title", "duration_s", "date"])] = \
                rng.choice([np.arange(4), 5, "text", 1.5])
        elif fault == "bad-status":
            c = rec["checks"][sorted(rec["checks"])[0]]
            c.attrs["status"] = rng.choice(["great", "", "PASS", "1"])
        elif fault == "bad-json":
            rec["crosschecks/0"].attrs[rng.choice(["parts", "modes"])] = \
                rng.choice(["[1, {", '{"a": 1}', "7", '[{"a": [}]', '["a", 3]', "[[[]]]"])
        elif fault == "deep-json":
            n = rng.choice([40, 5000, 200_000])
            rec["crosschecks/0"].attrs["modes"] = "[" * n + "]" * n
        elif fault == "problems-dataset":
            del f["problems"]
            f.create_dataset("problems", data=np.arange(10.0))
        elif fault == "record-dataset":
            name = rec.name
            del f[name]
            f.create_dataset(name, data=np.arange(10.0))
        elif fault == "reference":
            rec["systems/main"].create_dataset("numeric/ref", data=rec.ref,
                                               dtype=h5py.ref_dtype)
        elif fault == "external-storage":
            raw = guard.outside / "raw.bin"
            raw.write_bytes(np.full(1000, 3.0).tobytes())
            rec["systems/main"].create_dataset("numeric/ext", shape=(1000,), dtype="f8",
                                               external=[(str(raw), 0, 8000)])
        elif fault == "virtual":
            layout = h5py.VirtualLayout(shape=(100,), dtype="f8")
            layout[:] = h5py.VirtualSource(str(outside), "data", shape=(100,))
            rec["systems/main"].create_virtual_dataset("numeric/virtual", layout)


def run_hdf5(where: Path, spec: dict) -> tuple[str, str]:
    """A store of real-looking records made hostile one way; every reader tried (show's,
    the report's, the check's cache and durations, sweeps, simulations), then one record
    saved the way `check` saves it. Readers may refuse (StoreError naming the store) but
    never crash, read outside the file, or take memory past the batch's bound; the save must
    lose nothing readable, and never change a file that is not a mechbook store."""
    from fuzz_faults import HOSTILE_STRINGS, _readable, _record

    import mechbook.app.store as store
    from mechbook.app.store.unsaved import Saver
    from mechbook.app.sweep.storage import stored_sweeps
    from mechbook.errors import MechbookError

    rng = random.Random(spec["seed"])
    tree = _tree(where)
    guard = Guard(where)
    path = tree / "results" / "mechbook.h5"
    records = [_record(f"fuzz-{i}", rng.sample(HOSTILE_STRINGS, 4), rng)
               for i in range(spec["records"])]
    store.write(records, path)
    store.write_simulation("fuzz-0", "main-DOP853", {"t": [0.0, 0.5, 1.0]}, {"rtol": 1e-8},
                           None, path)
    fault = spec["fault"]
    _hostile_hdf5(path, fault, rng, guard)
    guard.before = guard._state()  # the outside file was made above: from here on, frozen
    shown: list[str] = []
    foreign_bytes = path.read_bytes() if fault in ("foreign", "format") else None
    try:
        for reader in (lambda: store.problems(path),
                       lambda: [store.read(p, path) for p in (r.problem_id for r in records)],
                       lambda: store.read_simulation("fuzz-0", "main-DOP853", path),
                       lambda: stored_sweeps("fuzz-0", path),
                       lambda: store.cached({r.problem_id: (r.problem_sha256,
                                                            r.answers_sha256)
                                             for r in records}, path),
                       lambda: store.durations(path), lambda: store.damage(path)):
            try:
                shown.append(repr(reader()))
            except (MechbookError, FileNotFoundError) as exc:
                if not str(exc).strip():
                    return "crash", f"{type(exc).__name__} with an empty message"
                shown.append(str(exc))
        before = _readable(path)
        saver = Saver(path)
        saver.save(_record("fuzz-new", rng.sample(HOSTILE_STRINGS, 4), rng))
    except Exception as exc:  # noqa: BLE001
        return _crash(exc)
    if any(MARKER in s for s in shown):
        return "leak", "data outside the store was read through it"
    moved = guard.changed()
    if moved:
        return "outside", moved
    if foreign_bytes is not None and saver.error is not None and \
            path.read_bytes() != foreign_bytes:
        return "unsafe", "a file that is not a store of this mechbook was changed"
    if saver.error is None:
        after = _readable(path)
        gone = [pid for pid in before if pid not in after]
        if gone or "fuzz-new" not in after:
            return "lost", f"after the save: gone {gone}, new record kept: {'fuzz-new' in after}"
        return "ok", f"{fault}: written"
    if saver.side.path is None:
        return "lost", f"not stored and not kept: {saver.error}"
    if str(path) not in str(saver.error):
        return "unsafe", f"a store error that does not name the store: {saver.error}"
    return "refused", f"{fault}: {saver.error}"


# ---- user regular expressions ----------------------------------------------------------------
PATTERNS = ["(a+)+b", "(a|a)*b", "(a*)*b", "((a+)+)+c", "(x+x+)+y", "(a|aa)+b", "(.*a){20}",
            "(a?){30}a{30}", "([a-z]+)*[0-9]", "(\\w+\\s?)*$", "^(([a-z])+.)+[A-Z]([a-z])+$",
            "(a)\\1", "(?=a)a", "(?<=a)b", "(?!x)a", "a{0,1000}", "a{1000}", "(a{100}){100}",
            "[", "(", "*a", "a**", "\\", "(?P<x>a)(?P=x)", "\\p{L}+", "[0-9]+(\\.[0-9]+)?",
            "[0-9]{4}", "(" * 500 + "a" + ")" * 500, "|".join(f"a{i}" for i in range(3000)),
            "a" * 60_000, "[^\\x00-\\x7f]+", "(?i)LIM", "\\d+", ""]


def regex_spec(rng: random.Random) -> dict:
    pattern = rng.choice(PATTERNS)
    if rng.random() < 0.3:  # a random pattern over the usual characters
        alphabet = list("ab()[]{}*+?|.\\^$0-9,") + ["(?:", "{2,}", "\\d", "\\w"]
        pattern = "".join(rng.choice(alphabet) for _ in range(rng.randint(1, 40)))
    n = rng.choice([10, 36, 60, 79])
    return {"pattern": pattern, "example": rng.choice(["ab", "a" * 30 + "b", "2031", "x", ""]),
            "numbers": ["a" * n, "a" * n + "c", "x" * n + "y", "2031", "a-b-c", "1.1"]}


def run_regex(where: Path, spec: dict) -> tuple[str, str]:
    """books.yaml with the user's pattern: read it, then list and resolve problems whose
    numbers could make a backtracking matcher run for ever; the batch's time limit is the
    judge of a hang."""
    from mechbook.errors import MechbookError
    from mechbook.model.books import load_books
    from mechbook.model.catalog import all_ids, problem_path

    tree = where / "tree"
    (tree / "problems" / "lim").mkdir(parents=True)
    quoted = json.dumps(spec["pattern"])  # a JSON string is a YAML double-quoted scalar
    (tree / "books.yaml").write_text(
        "books:\n  - id: lim\n    title: A book\n    author: An author\n"
        f"    numbers: {quoted}\n    example: {json.dumps(spec['example'])}\n", "utf-8")
    for number in spec["numbers"]:
        (tree / "problems" / "lim" / f"{number}.yaml").write_text("id: x\n")
    try:
        books = load_books(tree / "books.yaml")
    except MechbookError as exc:
        return _refused(exc, "books.yaml")
    except Exception as exc:  # noqa: BLE001
        return _crash(exc)
    matched = 0
    try:
        for pid in all_ids(tree):
            try:
                problem_path(pid, tree)
                matched += 1
            except MechbookError:
                continue
    except MechbookError as exc:
        return _refused(exc)
    except Exception as exc:  # noqa: BLE001
        return _crash(exc)
    return "ok", f"{len(books)} book(s), {matched} of {len(spec['numbers'])} numbers match"


GENERATORS = {"restore": restore_spec, "init": init_spec, "watch": watch_spec,
              "pagelist": pagelist_spec, "hdf5": hdf5_spec, "regex": regex_spec}
RUNNERS = {"restore": run_restore, "init": run_init, "watch": run_watch,
           "pagelist": run_pagelist, "hdf5": run_hdf5, "regex": run_regex}
