"""The HDF5 store: every run's results, checks and provenance, written atomically.

Layout (one group per problem, replaced whole on each run of that problem):
    /problems/<id>                 attrs: title, source, problem_sha256, answers_sha256,
                                          engine_sha256 (the warm-run cache key), mechbook, sympy,
                                          numpy, h5py, date, duration_s
    /problems/<id>/systems/<s>/symbolic/<key>   UTF-8 string datasets
    /problems/<id>/systems/<s>/numeric/<key>    float arrays (default parameter values)
    /problems/<id>/systems/<s>/notes/<key>      why a result is missing
    /problems/<id>/systems/_declared/...        the problem's declared vectors, tensors and
                                                bodies (mass, centre of mass, inertia), if
                                                a part used them
    /problems/<id>/checks/<part>   attrs: quantity, cite, status, method, detail, seconds
    /problems/<id>/crosschecks/<n> attrs: name, kind, system, status, error, detail, parts,
                                          seconds, modes (JSON); see mechbook/crosscheck.py
    /problems/<id>/simulations/<name>   attrs: the method's settings, initial conditions,
                                        parameters, RHS backend, drift of each monitor;
                                        datasets t, coordinate (names), q (n×N), qdot (n×N),
                                        monitors/<quantity> (with attrs initial,
                                        max_abs_drift, relative_drift, final_drift,
                                        drift_rate); t and coordinate are HDF5 dimension
                                        scales, so xarray (h5netcdf) opens the group

A write edits a copy of the current file and renames it over the original, so an
interrupted run leaves the previous file whole and readable (mechbook.app.outputs: the new
file is anonymous until an instant before the rename, so a killed run leaves no temporary
file). A single write edits the copy in memory and writes it anew with only what it holds
(mechbook.app.store.compaction: HDF5 keeps the space of a replaced group); a check writes each
problem as it finishes without that and compacts once at its end, so a store's size depends
on its contents, not on how many runs wrote it. Rewriting a problem's checks keeps its
stored simulations; storing a simulation replaces only that simulation.

Nothing fails quietly. A write that cannot be made (a read-only or full file system, a
directory or device at the path) raises StoreError with the path and the reason; the command
line then keeps the results in a side file (mechbook.app.store.unsaved) and exits non-zero. A
damaged store (truncated, bytes flipped, not HDF5 at all) is detected before it is edited:
it is moved aside to `<name>.damaged-<time>`, rebuilt from every problem, simulation and
sweep that can still be read whole, and a warning says what was kept and what was lost.
Readers (`show`, `report`) raise StoreError naming what is damaged.

The modules beside this one: reader (reading, StoreError), entries (records read whole and
checked, `damage`), bounds (every read bounded), warm_cache (the warm-run cache and
durations), repair (a damaged store moved aside and rebuilt), compaction (a store written
anew), child_read (a store not yet found sound read in a child). The package's __init__
exposes their public names.
"""

from __future__ import annotations

import fcntl
import io
import json
import os
import re
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import UTC, datetime
from importlib.metadata import version
from pathlib import Path
from typing import TYPE_CHECKING

import h5py
import numpy as np

from mechbook.app.fingerprint import engine_sha256
from mechbook.app.output.text import storable
from mechbook.app.outputs import OutputError, output_file, remove_stale, replaced
from mechbook.app.store.bounds import MAX_ATTRIBUTE_BYTES, MAX_TEXT_BYTES
from mechbook.app.store.child_read import mark_sound
from mechbook.app.store.compaction import compact
from mechbook.app.store.entries import FORMAT, reason_of
from mechbook.app.store.reader import DEFAULT_PATH, StoreError
from mechbook.app.store.repair import ensure_sound
from mechbook.errors import MechbookError
from mechbook.records import Outcome, Results
from mechbook.version import __version__

if TYPE_CHECKING:
    from mechbook.model.problem import Problem

_STR = h5py.string_dtype("utf-8")
_RUN_NAME = re.compile(r"[A-Za-z0-9_+-][A-Za-z0-9._+-]{0,99}")


@dataclass
class ProblemRecord:
    """Everything one run learned about one problem, as plain data (it crosses process
    boundaries: a batch's workers send records to the parent, the store's only writer)."""

    problem_id: str
    title: str
    source: str
    problem_sha256: str
    results: list[Results] = field(default_factory=list)
    outcomes: list[Outcome] = field(default_factory=list)
    duration: float = 0.0
    answers_sha256: str = ""
    crosschecks: list[dict] = field(default_factory=list)  # CrossCheck.as_dict()

    @classmethod
    def of(cls, problem: Problem, results: Iterable[Results], outcomes: Iterable[Outcome],
           duration: float, answers_sha256: str = "",
           crosschecks: Iterable[dict] = ()) -> ProblemRecord:
        return cls(problem.id, problem.title, problem.source, problem.sha256, list(results),
                   list(outcomes), duration, answers_sha256, list(crosschecks))


def write(records: Iterable[ProblemRecord], path: str | Path = DEFAULT_PATH,
          compacted: bool = True) -> Path:
    """Add or replace the given problems in the store, atomically; StoreError (path and
    reason) if that cannot be done, and then the store is as it was. `compacted=False`
    leaves the space of what was replaced in the file (a run writing problem after problem
    compacts once, at its end: `compact_store`)."""
    records = list(records)
    with atomic_edit(path, compacted) as f:
        root = f.require_group("problems")
        for rec in records:
            _write_problem(root, rec)
    return Path(path)


@contextmanager
def _locked(directory: Path) -> Iterator[None]:
    """An exclusive lock on the store's directory for one read-modify-write: two processes
    writing the same store (two `mechbook check` runs) take turns, so neither starts from a
    copy the other is about to replace. Readers need no lock: the file is only ever
    replaced by a rename, so they see the old file or the new one, never a torn one."""
    fd = os.open(directory, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # closing releases the lock


def compact_store(path: str | Path = DEFAULT_PATH) -> None:
    """Write the store anew with only what it holds (mechbook.app.store.compaction), atomically;
    StoreError as for `write`."""
    if Path(path).exists():
        with atomic_edit(path):
            pass


@contextmanager
def atomic_edit(path: str | Path, compacted: bool = True) -> Iterator[h5py.File]:
    """An open copy of the store (or a new file) that replaces `path` only on success,
    written anew with only what it holds when `compacted`. Every failure, whatever raised
    it (the file system, HDF5), is a StoreError."""
    shown = Path(path)
    try:
        real = output_file(shown, "store")
    except OutputError as exc:
        raise StoreError(shown, exc.reason) from None
    entered = False
    try:
        real.parent.mkdir(parents=True, exist_ok=True)
        with _locked(real.parent):
            remove_stale(real)  # what a writer killed mid-write left (we hold the lock)
            if real.exists():
                ensure_sound(real, shown)
            with replaced(real, copy=not compacted) as fh:
                image = fh if not compacted else \
                    io.BytesIO(real.read_bytes() if real.exists() else b"")
                with h5py.File(image, "r+" if real.exists() else "w") as f:
                    f.attrs["format"] = FORMAT
                    entered = True
                    yield f
                if compacted:
                    compact(image, fh)  # the edit's freed space left behind
            mark_sound(real)  # written by this process: its readers need no child
    except StoreError:
        raise
    except Exception as exc:  # noqa: BLE001 - every way a write fails is reported as one
        if entered and not isinstance(exc, OSError | RuntimeError | ValueError | TypeError):
            raise  # the caller's own fault, raised inside the edit: not the store's
        raise StoreError(shown, reason_of(exc)) from exc


def _write_problem(root: h5py.Group, rec: ProblemRecord) -> None:
    pid = rec.problem_id
    kept = f"_simulations_of_{pid}"
    if pid in root:
        if "simulations" in root[pid]:  # a check run keeps the problem's simulations
            root.move(f"{pid}/simulations", kept)
        del root[pid]
    g = root.create_group(pid, track_order=True)
    if kept in root:
        root.move(kept, f"{pid}/simulations")
    g.attrs.update({
        "title": bounded_text(rec.title), "source": bounded_text(rec.source),
        "problem_sha256": rec.problem_sha256, "answers_sha256": rec.answers_sha256,
        "engine_sha256": engine_sha256(), "mechbook": __version__,
        "sympy": version("sympy"), "numpy": np.__version__, "h5py": h5py.__version__,
        "date": datetime.now(UTC).isoformat(timespec="seconds"),
        "duration_s": float(rec.duration),
    })
    for res in rec.results:
        s = g.require_group("systems").create_group(res.system, track_order=True)
        for key, text in res.text.items():
            s.create_dataset(f"symbolic/{key}", data=bounded_text(text, MAX_TEXT_BYTES), dtype=_STR)
        for key, arr in res.arrays.items():
            s.create_dataset(f"numeric/{key}", data=np.asarray(arr, dtype=float))
        for key, text in res.notes.items():
            s.create_dataset(f"notes/{key}", data=bounded_text(text, MAX_TEXT_BYTES), dtype=_STR)
    checks = g.create_group("checks")
    for i, o in enumerate(rec.outcomes):
        c = checks.create_group(o.part)
        c.attrs.update({"index": i, "origin": o.origin, "quantity": o.quantity,
                        "cite": bounded_text(o.cite), "status": str(o.status),
                        "method": bounded_text(o.method), "detail": bounded_text(o.detail),
                        "seconds": float(o.seconds), "power": bounded_text(o.power)})
    if rec.crosschecks:
        cross = g.create_group("crosschecks", track_order=True)
        for i, x in enumerate(rec.crosschecks):
            c = cross.create_group(str(i))
            c.attrs.update({k: attribute_value(v) for k, v in x.items()})


def check_run_name(name: object, what: str = "run") -> str:
    """A stored run's name (a simulation's, a sweep's): one HDF5 path component of letters,
    digits, '.', '_', '-' and '+' that does not start with '.'; MechbookError otherwise.
    Checked before the run, so a bad name never costs a computation."""
    if not isinstance(name, str) or not _RUN_NAME.fullmatch(name):
        raise MechbookError(f"invalid {what} name {name!r}: letters, digits, '.', '_', '-' "
                            "and '+' only, not starting with '.', at most 100 characters")
    return name


def write_simulation(pid: str, name: str, arrays: dict[str, np.ndarray], attrs: dict,
                     array_attrs: dict[str, dict] | None = None,
                     path: str | Path = DEFAULT_PATH) -> Path:
    """Store one simulation at /problems/<pid>/simulations/<name>, replacing only it,
    atomically (the rest of the file, checks included, is kept as it was)."""
    check_run_name(name, "simulation")
    with atomic_edit(path) as f:
        sims = f.require_group("problems").require_group(pid).require_group("simulations")
        if name in sims:
            del sims[name]
        s = sims.create_group(name, track_order=True)
        s.attrs.update({k: attribute_value(v) for k, v in attrs.items()})
        for key, arr in arrays.items():
            d = s.create_dataset(key, data=np.asarray(arr, dtype=float), compression="gzip")
            for k, v in ((array_attrs or {}).get(key) or {}).items():
                d.attrs[k] = attribute_value(v)
        _dimension_scales(s, str(attrs.get("coordinates") or ""))
    return Path(path)


def _dimension_scales(s: h5py.Group, coordinates: str) -> None:
    """Label the axes of a stored trajectory with HDF5 dimension scales: `t` (the sample
    times) and `coordinate` (the coordinates' names), so that netCDF readers (xarray with
    h5netcdf) open the group as a dataset with q(coordinate, t), qdot(coordinate, t) and
    each monitor(t)."""
    if "t" not in s or s["t"].ndim != 1:
        return
    t = s["t"]
    t.make_scale("t")
    n = len(t)
    names = [c for c in coordinates.split(",") if c]
    coord = None
    if names and all(s[k].shape == (len(names), n) for k in ("q", "qdot") if k in s):
        coord = s.create_dataset("coordinate", data=np.array(names, dtype=object), dtype=_STR)
        coord.make_scale("coordinate")

    def attach(key: str, obj) -> None:
        if not isinstance(obj, h5py.Dataset) or obj.name in (t.name, getattr(coord, "name", "")):
            return
        if obj.ndim == 1 and obj.shape[0] == n:
            obj.dims[0].attach_scale(t)
        elif obj.ndim == 2 and coord is not None and obj.shape == (len(names), n):
            obj.dims[0].attach_scale(coord)
            obj.dims[1].attach_scale(t)

    s.visititems(attach)


def attribute_value(v: object) -> object:
    """An attribute value HDF5 can hold (strings made storable, lists and dicts as JSON,
    NumPy numbers inside them as floats); the store's records and a sweep's entries."""
    if v is None:
        return ""
    if isinstance(v, str):
        return bounded_text(v)
    if isinstance(v, (bool, int, float, np.generic)):
        return v
    return bounded_text(json.dumps(v, default=float), cut=False)


def bounded_text(text: str, limit: int = MAX_ATTRIBUTE_BYTES, cut: bool = True) -> str:
    """`text` as the store holds it (mechbook.app.output.text.storable) and as its readers will
    read it back: no longer than their bound (mechbook.app.store.bounds), cut with a note
    if it is longer (a title or an error's detail of megabytes), or, for JSON that cutting
    would break (`cut` False), a ValueError."""
    text = storable(str(text))
    if len(text) * 4 <= limit or len(text.encode("utf-8")) <= limit:
        return text
    if not cut:  # a ValueError inside an edit: the write's StoreError, naming the store
        raise ValueError(f"a value of {len(text)} characters is more than the store reads "
                         f"back ({limit} bytes)")
    keep = limit // 4 - 100
    return f"{text[:keep]} [... {len(text) - keep} more characters not stored]"


