"""The warm-run cache: which stored outcomes are still valid (problem file, answer key and
engine unchanged), and each problem's last duration (a batch starts the longest first).
Both read the store once and never fail: an unreadable record or store is no hit.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path

import h5py

from mechbook.app.fingerprint import engine_sha256
from mechbook.app.store.bounds import attribute, attributes, member
from mechbook.app.store.entries import plain_value, read_crosschecks, reason_of, refusal, subgroup
from mechbook.app.store.reader import DEFAULT_PATH, StoreError, guarded
from mechbook.records import CrossCheck, Outcome

log = logging.getLogger("mechbook.store")


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
    stored (and, with `crosschecks`, that were cross-checked). One read of the file (in a
    child while the file is not known sound: mechbook.app.store.child_read). A record that
    cannot be read is not a hit (the problem is checked again); a store that cannot be
    read gives no hits (its first write moves it aside and rebuilds it)."""
    try:
        return _cached(wanted, Path(path), crosschecks, engine_sha256())
    except StoreError as exc:  # HDF5 did not come back: no hits
        log.debug("store %s unreadable: %s", path, exc)
        return {}


@guarded
def _cached(wanted: dict[str, tuple[str, str]], path: Path, crosschecks: bool,
            engine: str) -> dict[str, Cached]:
    out: dict[str, Cached] = {}
    if not path.is_file():
        return out
    try:
        with h5py.File(path, "r") as f:
            if refusal(f) is not None:  # not a store of ours: no hits (its write is refused)
                return {}
            root = subgroup(f, "problems")
            for pid, shas in wanted.items():
                try:
                    hit = _cached_one(root, pid, shas, engine, crosschecks)
                except Exception as exc:  # noqa: BLE001 - damaged: check it again
                    log.debug("stored record of %s in %s unreadable: %s", pid, path,
                              reason_of(exc))
                    continue
                if hit is not None:
                    out[pid] = hit
    except Exception as exc:  # noqa: BLE001 - a damaged store: no hits
        log.debug("store %s unreadable: %s", path, reason_of(exc))
        return {}
    return out


def _cached_one(root, pid: str, shas: tuple[str, str], engine: str,
                crosschecks: bool) -> Cached | None:
    if pid not in root:
        return None
    g = member(root, pid)
    a = {k: plain_value(v) for k, v in attributes(g).items()}
    if (a.get("problem_sha256"), a.get("answers_sha256"), a.get("engine_sha256")) != \
            (*shas, engine):
        return None
    crossed = [CrossCheck.from_dict(d) for d in read_crosschecks(g)]
    if crosschecks and not crossed:
        return None
    return Cached(_outcomes(pid, g), crossed if crosschecks else [],
                  float(a.get("duration_s", 0.0)))


def durations(path: str | Path = DEFAULT_PATH) -> dict[str, float]:
    """Each stored problem's last cold duration (seconds): a batch starts the longest first
    (an unreadable store or record just gives no duration)."""
    try:
        return _durations(Path(path))
    except StoreError:  # HDF5 did not come back: no durations
        return {}


@guarded
def _durations(path: Path) -> dict[str, float]:
    if not path.is_file():
        return {}
    out = {}
    try:
        with h5py.File(path, "r") as f:
            if refusal(f) is not None:
                return out
            root = subgroup(f, "problems")
            for pid in root:
                try:
                    g = member(root, pid)
                    out[pid] = float(attribute(g, "duration_s")) if "duration_s" in g.attrs \
                        else 0.0
                except Exception:  # noqa: BLE001 - damaged: no duration known
                    continue
    except Exception:  # noqa: BLE001 - damaged store: no durations
        return out
    return out


def _outcomes(pid: str, g: h5py.Group) -> list[Outcome]:
    fields = ("quantity", "cite", "status", "method", "detail", "seconds", "origin", "power")
    rows = []
    checks = subgroup(g, "checks")
    for part in checks:
        a = {k: plain_value(v) for k, v in attributes(member(checks, part)).items()}
        rows.append((a.get("index", 0), Outcome(pid, part, **{k: a[k] for k in fields
                                                              if k in a})))
    return [o for _, o in sorted(rows, key=lambda r: r[0])]
