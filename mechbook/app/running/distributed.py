"""Checks and sweeps on a running Dask cluster (`--scheduler ADDRESS` or $MECHBOOK_SCHEDULER).

Why Dask distributed and not Ray (bench/schedulers.py measured both on this 2-core machine;
docs/performance.md has the table): a local Dask cluster of 2 workers is ready in about 2 s
against Ray's 5-10 s, uses about a third of the memory (Ray starts its GCS, raylet and
object store with it) and a tenth of the installed size, and is pure Python on PyPI. Ray's
lower per-task overhead (about 1 ms against 2-5 ms) does not count for tasks of seconds,
and what Ray offers beyond Dask (killing a running task) does not spare us our own limits:
a check must be stopped with the stage it was in, and the memory bound read from /proc,
exactly as the local pool does. So the limits stay ours on every scheduler: each task runs
its work in a child process of the Dask worker (the local pool's code, `mechbook.app.running.batch`,
for a check; `Sidecar` below for a sweep block), killed and replaced when it passes the
time or memory bound.

What travels: problem and answer files go with each task as text (the workers need no copy
of the tree and no shared file system), results come back as plain data (`ProblemRun`,
NumPy arrays); compiled functions never travel: each worker derives and compiles once per
sweep and keeps it (`mechbook.app.sweep.block_of`).

Dask's worker processes are daemons by default and a daemon may not start children: start
workers with DASK_DISTRIBUTED__WORKER__DAEMON=False (README), as `local_cluster` does.
"""

from __future__ import annotations

import atexit
import hashlib
import multiprocessing as mp
import os
import shutil
import tempfile
import time
from collections.abc import Callable
from dataclasses import replace
from multiprocessing.connection import Connection, wait
from pathlib import Path

from mechbook.app.running.batch import POLL, Batch, BatchOptions, pool_context, rss_mb
from mechbook.app.running.lifeline import die_with
from mechbook.app.running.run import ProblemRun
from mechbook.app.running.serverstart import start_server
from mechbook.core.optional import require
from mechbook.errors import MechbookError
from mechbook.model.catalog import answer_path, problem_path

ENV = "MECHBOOK_SCHEDULER"
DAEMON_ENV = "DASK_DISTRIBUTED__WORKER__DAEMON"


def scheduler_address(option: str | None) -> str | None:
    """The scheduler to use: the option, else $MECHBOOK_SCHEDULER, else None (local)."""
    return option or os.environ.get(ENV) or None


def tree_files(pid: str, base: Path) -> dict[str, bytes]:
    """A problem's files, relative path -> bytes (what a worker needs to check it)."""
    out = {}
    for path in (problem_path(pid, base), answer_path(pid, base)):
        if path.exists():
            out[str(path.relative_to(base))] = path.read_bytes()
    return out


_TREES: dict[str, Path] = {}  # per worker process: content hash -> scratch tree
# where the scratch trees go: the temporary directory on a Dask worker; in a local pool's
# worker, the run's own multiprocessing folder (set by `use_scratch`), which goes with the
# run even when it is killed (mechbook.app.running.lifeline): a pool's workers end by os._exit,
# and their atexit never runs
SCRATCH: str | None = None


def use_scratch(run_pid: int, folder: str) -> None:
    """A local pool worker's initializer: die with the run, keep scratch trees in `folder`."""
    global SCRATCH
    die_with(run_pid)
    SCRATCH = folder


def materialize(files: dict[str, bytes]) -> Path:
    """The files written to a scratch tree on this worker (once per content)."""
    digest = hashlib.sha256()
    for name in sorted(files):
        digest.update(name.encode() + b"\0" + files[name] + b"\0")
    key = digest.hexdigest()
    if key not in _TREES or not _TREES[key].exists():
        base = Path(tempfile.mkdtemp(prefix="mechbook-tree-", dir=SCRATCH))
        atexit.register(shutil.rmtree, base, True)  # removed when the worker exits
        (base / "problems").mkdir()
        for name, data in files.items():
            target = base / name
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(data)
        _TREES[key] = base
    return _TREES[key]


def _can_fork() -> None:
    if mp.current_process().daemon:
        raise MechbookError("this Dask worker is a daemon process and cannot start the "
                            "child process that enforces the time and memory limits; start "
                            f"the workers with {DAEMON_ENV}=False")


def check_task(pid: str, files: dict[str, bytes], options: BatchOptions,
               client_base: str) -> ProblemRun:
    """On a worker: check one problem in a one-worker local batch (its limits act from
    outside, as in `mechbook check`), paths in messages shown as the client's."""
    _can_fork()
    base = materialize(files)
    run = Batch(base, replace(options, jobs=1, serial=False)).run([pid])[0]
    return _relocated(run, str(base), client_base)


def _relocated(run: ProblemRun, here: str, there: str) -> ProblemRun:
    """File names in messages as the client knows them."""
    if run.error:
        run.error = run.error.replace(here, there)
    for o in run.outcomes:
        o.detail = o.detail.replace(here, there)
    return run


def dask_distributed():
    """dask.distributed, or MissingDependencyError with the install line (before anything
    else of a run on the cluster imports it)."""
    return require("dask.distributed", "cluster", "--scheduler (a Dask cluster)")


def connect(address: str):
    """A Dask client of the scheduler at `address` (a clear error if none answers)."""
    client = dask_distributed().Client
    try:
        return client(address, timeout="10s")
    except (OSError, TimeoutError) as exc:
        raise MechbookError(f"no Dask scheduler answers at {address}: {exc}") from None


class ClusterBatch:
    """`mechbook check` on a Dask cluster: one task per problem, results handed to
    `on_done` as they arrive (the client stays the store's only writer)."""

    def __init__(self, address: str, base: Path, options: BatchOptions | None = None,
                 on_done: Callable[[ProblemRun], None] | None = None):
        self.address = address
        self.base = base
        self.options = options or BatchOptions()
        self.on_done = on_done or (lambda run: None)
        self.stopped = False

    def stop(self) -> None:
        """Submit no more and cancel what is queued or running (`check -x`)."""
        self.stopped = True

    def run(self, ids: list[str]) -> list[ProblemRun]:
        as_completed = dask_distributed().as_completed
        done: dict[str, ProblemRun] = {}
        with connect(self.address) as client:
            # in the order given (the longest first), as the local pool does
            futures = {client.submit(check_task, pid, tree_files(pid, self.base),
                                     self.options, str(self.base), pure=False,
                                     priority=len(ids) - i,
                                     key=f"mechbook-check-{pid}-{os.getpid()}-{time.time_ns()}"):
                       pid for i, pid in enumerate(ids)}
            for fut in as_completed(futures):
                pid = futures[fut]
                try:
                    run = fut.result()
                except Exception as exc:  # noqa: BLE001 - a lost worker must not end the batch
                    run = ProblemRun(pid, error=f"on the cluster: {type(exc).__name__}: {exc}")
                done[pid] = run
                self.on_done(run)
                if self.stopped:
                    client.cancel([f for f in futures if not f.done()])
                    break
        return [done[pid] for pid in ids if pid in done]


# ---- a child process with limits, for work that is not a whole check ------------------------
def _sidecar_loop(conn: Connection) -> None:
    while True:
        try:
            job = conn.recv()
        except (EOFError, KeyboardInterrupt):
            return
        if job is None:
            return
        fn, args = job
        try:
            conn.send(("ok", fn(*args)))
        except Exception as exc:  # noqa: BLE001 - reported to the caller, who raises it
            conn.send(("error", f"{type(exc).__name__}: {exc}"))


class Sidecar:
    """One persistent child process that runs functions with a wall-clock and memory bound;
    a call past either kills it (a fresh one serves the next call) and raises. It keeps
    its state between calls, so what a function caches there (a compiled sweep) is reused."""

    def __init__(self):
        self._proc = None
        self._conn: Connection | None = None

    def _start(self) -> None:
        ctx = pool_context()
        start_server()
        parent, child = ctx.Pipe()
        self._proc = ctx.Process(target=_sidecar_loop, args=(child,), daemon=True)
        self._proc.start()
        child.close()
        self._conn = parent

    def stop(self) -> None:
        if self._proc is not None:
            self._proc.kill()
            self._proc.join()
            self._conn.close()
        self._proc = self._conn = None

    def call(self, fn, args: tuple, timeout: float, memory_mb: float):
        if self._proc is None or not self._proc.is_alive():
            self._start()
        start = time.monotonic()
        self._conn.send((fn, args))
        while True:
            ready = wait([self._conn, self._proc.sentinel], POLL)
            if self._conn in ready:
                try:
                    kind, payload = self._conn.recv()
                except (EOFError, OSError):
                    kind, payload = "error", "the child process died"
                if kind == "ok":
                    return payload
                if not self._proc.is_alive():
                    self.stop()
                raise MechbookError(payload)
            why = None
            if self._proc.sentinel in ready or not self._proc.is_alive():
                why = f"the child process died (exit code {self._proc.exitcode})"
            elif time.monotonic() - start > timeout:
                why = f"exceeded the time limit of {timeout:g} s"
            elif memory_mb and rss_mb(self._proc.pid) > memory_mb:
                why = f"exceeded the memory bound of {memory_mb:g} MB"
            if why:
                self.stop()
                raise MechbookError(why)


_SIDECAR = Sidecar()


def limited(fn, args: tuple, timeout: float, memory_mb: float):
    """`fn(*args)` in this process's sidecar, with the limits (see `Sidecar`)."""
    _can_fork()
    return _SIDECAR.call(fn, args, timeout, memory_mb)


def local_cluster(workers: int = 2):
    """A Dask cluster on this machine (tests, and trying `--scheduler` out): `workers`
    processes of one thread each, allowed to start the children that enforce limits, and
    handed one task at a time (worker-saturation 1.0: Dask's default 1.1 queues a second
    task on a one-thread worker, which then waits behind a long problem while another
    worker idles)."""
    import dask
    from dask.distributed import LocalCluster

    with dask.config.set({"distributed.worker.daemon": False,
                          "distributed.scheduler.worker-saturation": 1.0}):
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                            dashboard_address=None, host="127.0.0.1")
