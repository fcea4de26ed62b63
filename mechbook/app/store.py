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

A run copies the current file, edits the copy and renames it over the original, so an
interrupted run leaves the previous file whole and readable (mechbook.app.outputs: the copy
is an anonymous file until an instant before the rename, so a killed run leaves no temporary
file). Rewriting a problem's checks keeps its stored simulations; storing a simulation
replaces only that simulation.

Nothing fails quietly. A write that cannot be made (a read-only or full file system, a
directory or device at the path) raises StoreError with the path and the reason; the command
line then keeps the results in a side file (mechbook.app.unsaved) and exits non-zero. A
damaged store (truncated, bytes flipped, not HDF5 at all) is detected before it is edited:
it is moved aside to `<name>.damaged-<time>`, rebuilt from every problem, simulation and
sweep that can still be read whole, and a warning says what was kept and what was lost.
Readers (`show`, `report`) raise StoreError naming what is damaged.
"""

from __future__ import annotations

import fcntl
import json
import logging
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
from mechbook.app.outputs import OutputError, output_file, remove_stale, replaced
from mechbook.app.text import storable
from mechbook.errors import MechbookError
from mechbook.model.catalog import DEFAULT_STORE
from mechbook.records import CrossCheck, Outcome, Results
from mechbook.version import __version__

if TYPE_CHECKING:
    from mechbook.model.problem import Problem

DEFAULT_PATH = DEFAULT_STORE
FORMAT = 1
_STR = h5py.string_dtype("utf-8")
_SCALE_ATTRS = {"CLASS", "NAME", "DIMENSION_LIST", "REFERENCE_LIST", "DIMENSION_LABELS"}
log = logging.getLogger("mechbook.store")
DAMAGED = ".damaged-"  # a damaged store is moved aside to <name>.damaged-<UTC time>
_RUN_NAME = re.compile(r"[A-Za-z0-9_+-][A-Za-z0-9._+-]{0,99}")


class StoreError(MechbookError):
    """The store cannot be written or read; names the file and the reason."""

    def __init__(self, path: str | Path, reason: str, action: str = "write"):
        self.path, self.reason = Path(path), reason
        super().__init__(f"cannot {action} the store {path}: {reason}")


def _reason(exc: BaseException) -> str:
    """What went wrong, in one line (OSError's text without its errno prefix)."""
    if isinstance(exc, OSError) and exc.strerror and not exc.filename:
        return exc.strerror
    if isinstance(exc, OSError) and exc.strerror:
        return f"{exc.strerror} ({exc.filename})"
    return (str(exc).strip().splitlines() or [type(exc).__name__])[0]


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


def write(records: Iterable[ProblemRecord], path: str | Path = DEFAULT_PATH) -> Path:
    """Add or replace the given problems in the store, atomically; StoreError (path and
    reason) if that cannot be done, and then the store is as it was."""
    records = list(records)
    with _atomic_edit(path) as f:
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


@contextmanager
def _atomic_edit(path: str | Path) -> Iterator[h5py.File]:
    """An open copy of the store (or a new file) that replaces `path` only on success.
    Every failure, whatever raised it (the file system, HDF5), is a StoreError."""
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
                _ensure_sound(real, shown)
            with replaced(real, copy=True) as fh:
                with h5py.File(fh, "r+" if real.exists() else "w") as f:
                    f.attrs["format"] = FORMAT
                    entered = True
                    yield f
            _SOUND[str(real)] = _signature(real)
    except StoreError:
        raise
    except Exception as exc:  # noqa: BLE001 - every way a write fails is reported as one
        if entered and not isinstance(exc, OSError | RuntimeError | ValueError | TypeError):
            raise  # the caller's own fault, raised inside the edit: not the store's
        raise StoreError(shown, _reason(exc)) from exc


# ---- a damaged store: detected before an edit, moved aside, rebuilt --------------------------
_SOUND: dict[str, tuple] = {}  # path -> signature of the file last found (or made) sound


def _signature(path: Path) -> tuple:
    st = os.stat(path)
    return st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns


def damage(path: str | Path) -> str | None:
    """What is wrong with the store at `path` (None: every object and attribute reads, and
    every string is UTF-8). Reads the whole file once."""
    try:
        with h5py.File(path, "r") as f:
            _read_all(f)
    except Exception as exc:  # noqa: BLE001 - any failure to read is damage, described
        return _reason(exc)
    return None


def _member(group: h5py.Group, name: str):
    """group[name], {} if there is none; an entry that is listed but cannot be opened (h5py's
    `get` gives None for it, which reads as absent) raises: it is damage, not absence."""
    return group[name] if name in group else {}


def _walk(group: h5py.Group, prefix: str = "") -> Iterator[tuple[str, object]]:
    """(relative name, object) of everything under `group`, parents first. By the groups'
    own listings, as `read` finds things (HDF5's visititems walks the metadata another way
    and fails on damage that leaves every member readable)."""
    for name in group:
        obj = group[name]  # raises if listed but unreadable
        yield prefix + name, obj
        if isinstance(obj, h5py.Group):
            yield from _walk(obj, f"{prefix}{name}/")


def _read_all(group: h5py.Group) -> None:
    """Read every attribute, dataset and string under `group` (raises on damage)."""
    _attrs(group)
    for _, obj in _walk(group):
        _attrs(obj)
        if isinstance(obj, h5py.Dataset):
            _decoded(obj[()])


def _attrs(obj) -> dict:
    return {k: _decoded(obj.attrs[k]) for k in obj.attrs if k not in _SCALE_ATTRS}


def _decoded(v):
    """A value read from HDF5 with its strings decoded (UnicodeDecodeError if damaged)."""
    if isinstance(v, bytes):
        return v.decode("utf-8")
    if isinstance(v, np.ndarray) and v.dtype.kind == "O":
        return [_decoded(x) for x in v.ravel()]
    return v


def _ensure_sound(path: Path, shown: Path) -> None:
    """Before an edit: a damaged store is moved aside and rebuilt from what still reads."""
    if _SOUND.get(str(path)) == _signature(path):
        return
    why = damage(path)
    if why is None:
        _SOUND[str(path)] = _signature(path)
        return
    stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%S.%fZ")
    aside = path.with_name(f"{path.name}{DAMAGED}{stamp}")
    kept, lost = [], []
    with replaced(path) as fh:  # the rebuilt store
        with h5py.File(fh, "w") as out:
            out.attrs["format"] = FORMAT
            kept, lost = _salvage(path, out)
        os.link(path, aside)  # the damaged file stays whole beside the new one
    _SOUND[str(path)] = _signature(path)
    lost_text = f"; could not read (lost here, kept in the damaged file): {', '.join(lost)}" \
        if lost else ""
    log.warning("the store %s was damaged (%s): moved aside to %s and rebuilt with the %d "
                "entries that could still be read%s", shown, why, aside, len(kept), lost_text)


def _salvage(path: Path, out: h5py.File) -> tuple[list[str], list[str]]:
    """Copy every problem, sweep and top-level entry of the damaged file at `path` that
    reads whole into `out`; ([kept], [lost]) by name."""
    kept: list[str] = []
    lost: list[str] = []
    try:
        src = h5py.File(path, "r")
    except Exception:  # noqa: BLE001 - nothing readable at all: an empty store
        return kept, ["the whole file"]
    with src:
        try:
            tops = list(src.keys())
        except Exception:  # noqa: BLE001
            return kept, ["the whole file"]
        for top in tops:
            try:
                children = list(src[top].keys()) if isinstance(src[top], h5py.Group) else None
            except Exception:  # noqa: BLE001
                lost.append(f"/{top}")
                continue
            for name in (children if children is not None else [None]):
                where = f"/{top}/{name}" if name is not None else f"/{top}"
                try:
                    obj = src[where]
                    if isinstance(obj, h5py.Group):
                        _read_all(obj)
                        _copy_group(obj, out.require_group(top).create_group(
                            name, track_order=True) if name is not None
                            else out.create_group(top, track_order=True))
                    else:
                        _copy_dataset(obj, out.require_group(top) if name else out,
                                      name or top)
                    kept.append(where)
                except Exception:  # noqa: BLE001 - that entry is damaged: left out
                    if where in out:
                        del out[where]
                    lost.append(where)
    return kept, lost


def _copy_group(src: h5py.Group, dst: h5py.Group) -> None:
    """Copy a subtree between files as plain data (object references, which dimension
    scales are made of, do not survive a copy between files: the scales are re-attached by
    their paths inside the subtree)."""
    dst.attrs.update(_raw_attrs(src))
    scales, links = [], []
    for name, obj in _walk(src):
        if isinstance(obj, h5py.Group):
            dst.create_group(name, track_order=True).attrs.update(_raw_attrs(obj))
            continue
        _copy_dataset(obj, dst, name)
        if obj.is_scale:
            scales.append((name, obj.attrs.get("NAME", b"")))
        for i, dim in enumerate(obj.dims):
            for scale in dim.values():
                links.append((name, i, scale.name[len(src.name):].lstrip("/")))
    for name, label in scales:
        dst[name].make_scale(_decoded(label) or name.rsplit("/", 1)[-1])
    for name, i, scale in links:
        if scale in dst:
            dst[name].dims[i].attach_scale(dst[scale])


def _copy_dataset(obj: h5py.Dataset, dst: h5py.Group, name: str) -> None:
    d = dst.create_dataset(name, data=obj[()], dtype=obj.dtype,
                           compression=obj.compression)
    d.attrs.update(_raw_attrs(obj))


def _raw_attrs(obj) -> dict:
    return {k: obj.attrs[k] for k in obj.attrs if k not in _SCALE_ATTRS}


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
        "title": storable(rec.title), "source": storable(rec.source),
        "problem_sha256": rec.problem_sha256, "answers_sha256": rec.answers_sha256,
        "engine_sha256": engine_sha256(), "mechbook": __version__,
        "sympy": version("sympy"), "numpy": np.__version__, "h5py": h5py.__version__,
        "date": datetime.now(UTC).isoformat(timespec="seconds"),
        "duration_s": float(rec.duration),
    })
    for res in rec.results:
        s = g.require_group("systems").create_group(res.system, track_order=True)
        for key, text in res.text.items():
            s.create_dataset(f"symbolic/{key}", data=storable(text), dtype=_STR)
        for key, arr in res.arrays.items():
            s.create_dataset(f"numeric/{key}", data=np.asarray(arr, dtype=float))
        for key, text in res.notes.items():
            s.create_dataset(f"notes/{key}", data=storable(text), dtype=_STR)
    checks = g.create_group("checks")
    for i, o in enumerate(rec.outcomes):
        c = checks.create_group(o.part)
        c.attrs.update({"index": i, "origin": o.origin, "quantity": o.quantity,
                        "cite": storable(o.cite), "status": str(o.status),
                        "method": storable(o.method), "detail": storable(o.detail),
                        "seconds": float(o.seconds), "power": storable(o.power)})
    if rec.crosschecks:
        cross = g.create_group("crosschecks", track_order=True)
        for i, x in enumerate(rec.crosschecks):
            c = cross.create_group(str(i))
            c.attrs.update({k: _attr(v) for k, v in x.items()})


@contextmanager
def _opened(path: str | Path) -> Iterator[h5py.File]:
    """The store opened for reading; StoreError (what is wrong, how to recover) if it cannot
    be; FileNotFoundError if there is none."""
    if not os.path.lexists(path):
        raise FileNotFoundError(f"no store at {path}; run `mechbook check` first")
    if not Path(path).is_file():  # a FIFO would block the open; a directory, a dead link
        raise StoreError(path, "it is not a regular file (a directory, a FIFO, a device or "
                         "a broken link): give the path of a store", "read")
    try:
        f = h5py.File(path, "r")
    except Exception as exc:  # noqa: BLE001 - truncated, not HDF5, a directory, unreadable
        raise StoreError(path, f"{_reason(exc)}: the file is damaged or not a mechbook store "
                         "(the next `mechbook check` into it moves it aside and rebuilds it "
                         "from what can still be read)", "read") from None
    with f:
        yield f


def _damaged(path: str | Path, what: str, exc: BaseException) -> StoreError:
    return StoreError(path, f"{what} is damaged ({_reason(exc)}); the next `mechbook check` "
                      "into this store moves it aside and rebuilds it", "read")


def read(pid: str, path: str | Path = DEFAULT_PATH) -> dict:
    """One problem's record as plain Python data (KeyError if absent, FileNotFoundError if
    there is no store, StoreError naming what is damaged)."""
    path = Path(path)
    with _opened(path) as f:
        try:
            present = "problems" in f and pid in f["problems"]
        except Exception as exc:  # noqa: BLE001
            raise _damaged(path, "the list of problems", exc) from None
        if not present:
            raise KeyError(f"{pid} is not in {path}; run `mechbook check {pid}`")
        try:
            return _read_problem(f["problems"][pid])
        except Exception as exc:  # noqa: BLE001 - damage inside the record, described
            raise _damaged(path, f"the stored record of {pid}", exc) from None


def _read_problem(g: h5py.Group) -> dict:
    out = {"attrs": {k: _plain(v) for k, v in g.attrs.items()}, "systems": {}, "checks": []}
    for sname in _member(g, "systems"):
        s = g["systems"][sname]
        entry = {"symbolic": {}, "numeric": {}, "notes": {}}
        for kind in entry:
            if kind in s:
                for name, obj in _walk(s[kind]):
                    _collect(entry[kind], name, obj)
        out["systems"][sname] = entry
    for part in _member(g, "checks"):
        c = g["checks"][part]
        out["checks"].append({"part": part, **{k: _plain(v) for k, v in c.attrs.items()}})
    out["checks"].sort(key=lambda c: c.get("index", 0))
    out["crosschecks"] = _crosschecks(g)
    out["simulations"] = sorted(_member(g, "simulations").keys())
    return out


def _crosschecks(g: h5py.Group) -> list[dict]:
    out = []
    group = _member(g, "crosschecks")
    for key in group:
        entry = {k: _plain(v) for k, v in group[key].attrs.items()}
        for k in ("parts", "modes"):
            if isinstance(entry.get(k), str):
                entry[k] = json.loads(entry[k])
        out.append((int(key), entry))
    return [e for _, e in sorted(out, key=lambda x: x[0])]


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
    with _atomic_edit(path) as f:
        sims = f.require_group("problems").require_group(pid).require_group("simulations")
        if name in sims:
            del sims[name]
        s = sims.create_group(name, track_order=True)
        s.attrs.update({k: _attr(v) for k, v in attrs.items()})
        for key, arr in arrays.items():
            d = s.create_dataset(key, data=np.asarray(arr, dtype=float), compression="gzip")
            for k, v in ((array_attrs or {}).get(key) or {}).items():
                d.attrs[k] = _attr(v)
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


def read_simulation(pid: str, name: str, path: str | Path = DEFAULT_PATH) -> dict:
    """{"attrs": {...}, "arrays": {key: array}, "array_attrs": {key: {...}}} of one run."""
    with _opened(path) as f:
        try:
            s = f["problems"][pid]["simulations"][name]
        except KeyError:
            raise KeyError(f"no simulation {name!r} of {pid} in {path}") from None
        try:
            out = {"attrs": {k: _plain(v) for k, v in s.attrs.items()}, "arrays": {},
                   "array_attrs": {}}

            def visit(key, obj):
                if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f":
                    out["arrays"][key] = np.array(obj[()])
                    out["array_attrs"][key] = {k: _plain(v) for k, v in obj.attrs.items()
                                               if k not in _SCALE_ATTRS}

            s.visititems(visit)
        except Exception as exc:  # noqa: BLE001
            raise _damaged(path, f"the simulation {name} of {pid}", exc) from None
    return out


def _attr(v):
    """An attribute value HDF5 can hold (strings made storable, lists and dicts as JSON)."""
    if v is None:
        return ""
    if isinstance(v, str):
        return storable(v)
    if isinstance(v, (bool, int, float, np.generic)):
        return v
    return json.dumps(v)


@dataclass
class Cached:
    """A problem's stored outcomes and cross-checks, still valid for this run."""

    outcomes: list[Outcome]
    crosschecks: list[CrossCheck]
    duration: float


def cached(wanted: dict[str, tuple[str, str]], path: str | Path = DEFAULT_PATH,
           crosschecks: bool = True) -> dict[str, Cached]:
    """The stored results of the problems in `wanted` ({id: (problem sha256, answers
    sha256)}) whose problem file, answer key and engine are unchanged since they were
    stored (and, with `crosschecks`, that were cross-checked). One read of the file. A
    record that cannot be read is not a hit (the problem is checked again); a store that
    cannot be read gives no hits (its first write moves it aside and rebuilds it)."""
    path = Path(path)
    out: dict[str, Cached] = {}
    if not path.is_file():
        return out
    engine = engine_sha256()
    try:
        with h5py.File(path, "r") as f:
            root = _member(f, "problems")
            for pid, shas in wanted.items():
                try:
                    hit = _cached_one(root, pid, shas, engine, crosschecks)
                except Exception as exc:  # noqa: BLE001 - damaged: check it again
                    log.debug("stored record of %s in %s unreadable: %s", pid, path,
                              _reason(exc))
                    continue
                if hit is not None:
                    out[pid] = hit
    except Exception as exc:  # noqa: BLE001 - a damaged store: no hits
        log.debug("store %s unreadable: %s", path, _reason(exc))
        return {}
    return out


def _cached_one(root, pid: str, shas: tuple[str, str], engine: str,
                crosschecks: bool) -> Cached | None:
    if pid not in root:
        return None
    g = root[pid]
    a = {k: _plain(v) for k, v in g.attrs.items()}
    if (a.get("problem_sha256"), a.get("answers_sha256"), a.get("engine_sha256")) != \
            (*shas, engine):
        return None
    crossed = [CrossCheck.from_dict(d) for d in _crosschecks(g)]
    if crosschecks and not crossed:
        return None
    return Cached(_outcomes(pid, g), crossed if crosschecks else [],
                  float(a.get("duration_s", 0.0)))


def durations(path: str | Path = DEFAULT_PATH) -> dict[str, float]:
    """Each stored problem's last cold duration (seconds): a batch starts the longest first
    (an unreadable store or record just gives no duration)."""
    path = Path(path)
    if not path.is_file():
        return {}
    out = {}
    try:
        with h5py.File(path, "r") as f:
            root = _member(f, "problems")
            for pid in root:
                try:
                    out[pid] = float(root[pid].attrs.get("duration_s", 0.0))
                except Exception:  # noqa: BLE001 - damaged: no duration known
                    continue
    except Exception:  # noqa: BLE001 - damaged store: no durations
        return out
    return out


def _outcomes(pid: str, g: h5py.Group) -> list[Outcome]:
    fields = ("quantity", "cite", "status", "method", "detail", "seconds", "origin", "power")
    rows = []
    checks = _member(g, "checks")
    for part in checks:
        a = {k: _plain(v) for k, v in checks[part].attrs.items()}
        rows.append((a.get("index", 0), Outcome(pid, part, **{k: a[k] for k in fields
                                                              if k in a})))
    return [o for _, o in sorted(rows, key=lambda r: r[0])]


def problems(path: str | Path = DEFAULT_PATH) -> list[str]:
    """The ids stored (StoreError if the store cannot be read)."""
    with _opened(path) as f:
        try:
            return sorted(_member(f, "problems").keys())
        except Exception as exc:  # noqa: BLE001
            raise _damaged(path, "the list of problems", exc) from None


def _collect(target: dict, name: str, obj) -> None:
    if isinstance(obj, h5py.Dataset):
        data = obj[()]
        target[name] = data.decode() if isinstance(data, bytes) else (
            np.array(data) if obj.dtype.kind == "f" else _plain(data))


def _plain(v):
    if isinstance(v, bytes):
        return v.decode()
    if isinstance(v, np.generic):
        return v.item()
    return v
