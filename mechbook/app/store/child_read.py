"""Reading a store that HDF5 may never come back from, in a child process under a CPU limit.

libhdf5 does not end on some damaged files: one flipped byte in the length of a string in
a global heap collection (fuzz case 3064 of seed 1) makes it spin at 100 % CPU inside
`H5Aread` (HDFGroup/hdf5#1707; h5py#2088, closed as the library's fault). A loop in C is
not ended by Python's signal handlers, so the in-process time limits cannot stop it; the
kernel's RLIMIT_CPU can. A store whose current version this process has not found sound
(`damage` read all of it, or this process wrote it) is therefore read in a forked child
whose CPU time is bounded; the child sends back the result, or the exception, and a child
that the limit ends is `StoreHang`, a StoreError the callers already handle. A file found
sound is read in this process: the cost of a sound store is one fork per read until then
(tens of milliseconds).
"""

from __future__ import annotations

import functools
import inspect
import os
import pickle
import resource
import select
import signal
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

GUARD_CPU_SECONDS = 10.0  # and 2 s more per MB: a full store (4 MB, 3,900 objects) reads
GUARD_CPU_PER_MB = 2.0    # whole in about 3 s; a file that loops takes this long to say so
_SOUND: dict[str, tuple] = {}  # path -> signature of the version last found (or made) sound
_ENDED: dict[str, tuple] = {}  # path -> signature of a version a child did not come back from
F = TypeVar("F", bound=Callable[..., Any])
R = TypeVar("R")


class ChildEnded(Exception):
    """The child reading `path` was ended (by the CPU limit) before it answered."""

    def __init__(self, path: str | Path, seconds: float):
        super().__init__(path, seconds)
        self.path, self.seconds = Path(path), seconds


def signature(path: str | Path) -> tuple | None:
    """What identifies one version of the file (None: there is none)."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns


def mark_sound(path: str | Path) -> None:
    """The file's current version is sound (read whole, or written by this process)."""
    sig = signature(path)
    if sig is not None:
        _SOUND[str(path)] = sig


def is_sound(path: str | Path) -> bool:
    sig = signature(path)
    return sig is not None and _SOUND.get(str(path)) == sig


def cpu_limit(path: str | Path) -> float:
    """The CPU seconds a child may take to read the file at `path`, by its size."""
    sig = signature(path)
    return GUARD_CPU_SECONDS + GUARD_CPU_PER_MB * (sig[2] if sig else 0) / 2**20


def in_child(path: str | Path, fn: Callable[..., R], *args, **kwargs) -> R:
    """fn(*args, **kwargs) computed in a forked child whose CPU time is bounded
    (`cpu_limit`); its result, or the exception it raised; ChildEnded when the limit ended
    it, or at once when a child already did not come back from this version of the file."""
    sig = signature(path)
    seconds = cpu_limit(path)
    if sig is not None and _ENDED.get(str(path)) == sig:
        raise ChildEnded(path, seconds)
    rd, wr = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: compute, send, leave without running the parent's cleanup
        code = 0
        try:
            os.close(rd)
            signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent answers Ctrl-C
            limit = int(seconds) + 1  # CPU time starts at 0 in a child
            resource.setrlimit(resource.RLIMIT_CPU, (limit, limit + 1))
            try:
                out = ("value", fn(*args, **kwargs))
            except BaseException as exc:  # noqa: BLE001 - sent to the parent as it is
                out = ("raise", _portable(exc, path))
            data = pickle.dumps(out)
            view = memoryview(data)
            while view:
                view = view[os.write(wr, view):]
        except BaseException:  # noqa: BLE001 - nothing sent: the parent reports it
            code = 1
        finally:
            os._exit(code)
    os.close(wr)
    chunks = []
    deadline = time.monotonic() + 4 * seconds + 30  # a child stuck without using CPU too
    try:
        while True:
            ready, _, _ = select.select([rd], [], [], max(0.0, deadline - time.monotonic()))
            if not ready:
                os.kill(pid, signal.SIGKILL)
                chunks = []
                break
            chunk = os.read(rd, 1 << 20)
            if not chunk:
                break
            chunks.append(chunk)
    except BaseException:  # Ctrl-C here: the child is not left to finish
        os.kill(pid, signal.SIGKILL)
        raise
    finally:
        os.close(rd)
        _, status = os.waitpid(pid, 0)
    if os.WIFSIGNALED(status) or not chunks:
        if sig is not None:
            _ENDED[str(path)] = sig
        raise ChildEnded(path, seconds)
    kind, value = pickle.loads(b"".join(chunks))
    if kind == "raise":
        raise value
    return value


def _portable(exc: BaseException, path: str | Path) -> BaseException:
    """`exc` if it survives pickling whole, else a RuntimeError that says what it was."""
    try:
        back = pickle.loads(pickle.dumps(exc))
        if type(back) is type(exc) and str(back) == str(exc):
            return exc
    except Exception:  # noqa: BLE001
        pass
    return RuntimeError(f"{type(exc).__name__}: {exc}")


def sheltered(on_hang: Callable[[Path, float], BaseException]) -> Callable[[F], F]:
    """A decorator: the store named by the function's `path` argument is read in a child
    (`in_child`) unless its current version is known to be sound; a child the limit ended
    raises on_hang(path, seconds)."""
    def decorate(fn: F) -> F:
        params = inspect.signature(fn)

        @functools.wraps(fn)
        def wrapper(*args, **kwargs):
            bound = params.bind(*args, **kwargs)
            bound.apply_defaults()
            path = bound.arguments["path"]
            if is_sound(path) or signature(path) is None:
                return fn(*args, **kwargs)
            try:
                return in_child(path, fn, *args, **kwargs)
            except ChildEnded as end:
                raise on_hang(end.path, end.seconds) from None

        return wrapper  # type: ignore[return-value]

    return decorate
