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
interrupted run leaves the previous file whole and readable. Rewriting a problem's checks
keeps its stored simulations; storing a simulation replaces only that simulation.
"""

from __future__ import annotations

import fcntl
import json
import os
import shutil
import tempfile
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import UTC, datetime
from importlib.metadata import version
from pathlib import Path
from typing import TYPE_CHECKING

import h5py
import numpy as np

from mechbook import __version__
from mechbook.app.fingerprint import engine_sha256
from mechbook.model.catalog import DEFAULT_STORE
from mechbook.records import CrossCheck, Outcome, Results

if TYPE_CHECKING:
    from mechbook.model.problem import Problem

DEFAULT_PATH = DEFAULT_STORE
FORMAT = 1
_STR = h5py.string_dtype("utf-8")
_SCALE_ATTRS = {"CLASS", "NAME", "DIMENSION_LIST", "REFERENCE_LIST", "DIMENSION_LABELS"}


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
    """Add or replace the given problems in the store, atomically."""
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
    """An open copy of the store (or a new file) that replaces `path` only on success."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with _locked(path.parent):
        with _edited_copy(path) as f:
            yield f


@contextmanager
def _edited_copy(path: Path) -> Iterator[h5py.File]:
    fd, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".tmp", dir=path.parent)
    os.close(fd)
    # mkstemp makes the file 0600; keep the old file's mode, or follow the umask
    if path.exists():
        mode = path.stat().st_mode & 0o777
    else:
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask
    os.chmod(tmp, mode)
    try:
        if path.exists():
            shutil.copyfile(path, tmp)
            mode = "a"
        else:
            mode = "w"
        with h5py.File(tmp, mode) as f:
            f.attrs["format"] = FORMAT
            yield f
        with open(tmp, "rb") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


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
        "title": rec.title, "source": rec.source,
        "problem_sha256": rec.problem_sha256, "answers_sha256": rec.answers_sha256,
        "engine_sha256": engine_sha256(), "mechbook": __version__,
        "sympy": version("sympy"), "numpy": np.__version__, "h5py": h5py.__version__,
        "date": datetime.now(UTC).isoformat(timespec="seconds"),
        "duration_s": float(rec.duration),
    })
    for res in rec.results:
        s = g.require_group("systems").create_group(res.system, track_order=True)
        for key, text in res.text.items():
            s.create_dataset(f"symbolic/{key}", data=text, dtype=_STR)
        for key, arr in res.arrays.items():
            s.create_dataset(f"numeric/{key}", data=np.asarray(arr, dtype=float))
        for key, text in res.notes.items():
            s.create_dataset(f"notes/{key}", data=text, dtype=_STR)
    checks = g.create_group("checks")
    for i, o in enumerate(rec.outcomes):
        c = checks.create_group(o.part)
        c.attrs.update({"index": i, "origin": o.origin, "quantity": o.quantity,
                        "cite": o.cite, "status": o.status, "method": o.method,
                        "detail": o.detail, "seconds": float(o.seconds), "power": o.power})
    if rec.crosschecks:
        cross = g.create_group("crosschecks", track_order=True)
        for i, x in enumerate(rec.crosschecks):
            c = cross.create_group(str(i))
            c.attrs.update({k: (json.dumps(v) if isinstance(v, (list, dict)) else v)
                            for k, v in x.items()})


def read(pid: str, path: str | Path = DEFAULT_PATH) -> dict:
    """One problem's record as plain Python data (raises KeyError if absent)."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"no store at {path}; run `mechbook check` first")
    with h5py.File(path, "r") as f:
        if "problems" not in f or pid not in f["problems"]:
            raise KeyError(f"{pid} is not in {path}; run `mechbook check {pid}`")
        g = f["problems"][pid]
        out = {"attrs": {k: _plain(v) for k, v in g.attrs.items()}, "systems": {}, "checks": []}
        for sname, s in g.get("systems", {}).items():
            entry = {"symbolic": {}, "numeric": {}, "notes": {}}
            for kind in entry:
                if kind in s:
                    s[kind].visititems(lambda name, obj, kind=kind, entry=entry:
                                       _collect(entry[kind], name, obj))
            out["systems"][sname] = entry
        for part, c in g.get("checks", {}).items():
            out["checks"].append({"part": part, **{k: _plain(v) for k, v in c.attrs.items()}})
        out["checks"].sort(key=lambda c: c.get("index", 0))
        out["crosschecks"] = _crosschecks(g)
        out["simulations"] = sorted(g.get("simulations", {}).keys())
    return out


def _crosschecks(g: h5py.Group) -> list[dict]:
    out = []
    for key, c in g.get("crosschecks", {}).items():
        entry = {k: _plain(v) for k, v in c.attrs.items()}
        for k in ("parts", "modes"):
            if isinstance(entry.get(k), str):
                entry[k] = json.loads(entry[k])
        out.append((int(key), entry))
    return [e for _, e in sorted(out, key=lambda x: x[0])]


def write_simulation(pid: str, name: str, arrays: dict[str, np.ndarray], attrs: dict,
                     array_attrs: dict[str, dict] | None = None,
                     path: str | Path = DEFAULT_PATH) -> Path:
    """Store one simulation at /problems/<pid>/simulations/<name>, replacing only it,
    atomically (the rest of the file, checks included, is kept as it was)."""
    if not name or "/" in name or name.startswith("."):
        raise ValueError(f"invalid simulation name {name!r}")
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
    with h5py.File(path, "r") as f:
        s = f["problems"][pid]["simulations"][name]
        out = {"attrs": {k: _plain(v) for k, v in s.attrs.items()}, "arrays": {},
               "array_attrs": {}}

        def visit(key, obj):
            if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f":
                out["arrays"][key] = np.array(obj[()])
                out["array_attrs"][key] = {k: _plain(v) for k, v in obj.attrs.items()
                                           if k not in _SCALE_ATTRS}

        s.visititems(visit)
    return out


def _attr(v):
    if v is None:
        return ""
    if isinstance(v, (bool, int, float, str, np.generic)):
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
    stored (and, with `crosschecks`, that were cross-checked). One read of the file."""
    path = Path(path)
    out: dict[str, Cached] = {}
    if not path.exists():
        return out
    engine = engine_sha256()
    try:
        with h5py.File(path, "r") as f:
            root = f.get("problems", {})
            for pid, shas in wanted.items():
                if pid not in root:
                    continue
                g = root[pid]
                a = {k: _plain(v) for k, v in g.attrs.items()}
                if (a.get("problem_sha256"), a.get("answers_sha256"),
                        a.get("engine_sha256")) != (*shas, engine):
                    continue
                crossed = [CrossCheck.from_dict(d) for d in _crosschecks(g)]
                if crosschecks and not crossed:
                    continue
                out[pid] = Cached(_outcomes(pid, g), crossed if crosschecks else [],
                                  float(a.get("duration_s", 0.0)))
    except OSError:
        return {}
    return out


def durations(path: str | Path = DEFAULT_PATH) -> dict[str, float]:
    """Each stored problem's last cold duration (seconds): a batch starts the longest first."""
    path = Path(path)
    if not path.exists():
        return {}
    try:
        with h5py.File(path, "r") as f:
            return {pid: float(g.attrs.get("duration_s", 0.0))
                    for pid, g in f.get("problems", {}).items()}
    except OSError:
        return {}


def _outcomes(pid: str, g: h5py.Group) -> list[Outcome]:
    fields = ("quantity", "cite", "status", "method", "detail", "seconds", "origin", "power")
    rows = []
    for part, c in g.get("checks", {}).items():
        a = {k: _plain(v) for k, v in c.attrs.items()}
        rows.append((a.get("index", 0), Outcome(pid, part, **{k: a[k] for k in fields
                                                              if k in a})))
    return [o for _, o in sorted(rows, key=lambda r: r[0])]


def problems(path: str | Path = DEFAULT_PATH) -> list[str]:
    with h5py.File(path, "r") as f:
        return sorted(f.get("problems", {}).keys())


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
