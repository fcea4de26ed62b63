"""One check of many problems, below the command line: `mechbook check`, `report` and the
Python API call this, and only print or return what it gives back.

    ids ──resolve──▶ files in the tree (one id grammar; a bad file among all is an error run)
        ──cache────▶ outcomes still valid in the store (problem, answers, engine unchanged)
        ──order────▶ the rest, the longest first by their stored durations
        ──batch────▶ the local pool (mechbook.app.running.batch) or a Dask cluster (distributed)
        ──store────▶ each finished problem written at once (mechbook.app.store.unsaved.Saver)
        ──report───▶ the runs in the order of the ids, and what became of the store

A check is two steps, so that a caller can refuse its own bad options between them in the
order the command line always has: `CheckService.resolve` (ids and the store's path, before
any work) and `CheckService.run`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from mechbook.app.output.formats import failures
from mechbook.app.outputs import OutputError, output_file, resolve_path
from mechbook.app.running.batch import Batch, BatchOptions
from mechbook.app.running.distributed import ClusterBatch, scheduler_address
from mechbook.app.running.run import ProblemRun, RunOptions, cached_runs, run_problem
from mechbook.app.selection import select
from mechbook.app.store import durations, write
from mechbook.app.store.unsaved import Saver
from mechbook.errors import MechbookError
from mechbook.model.catalog import DEFAULT_STORE, all_ids, existing_problem_path

if TYPE_CHECKING:
    from mechbook.app.store.unsaved import Saver
    from mechbook.model.problem import Problem

OnDone = Callable[[ProblemRun], None]


def _ignore(run: ProblemRun) -> None:
    pass


@dataclass(frozen=True)
class CheckOptions:
    """How one check runs. `store` is relative to the tree unless absolute; it orders the
    work by its stored durations even when nothing is written (`write=False`)."""

    store: Path = DEFAULT_STORE
    write: bool = True  # read valid outcomes from the store and write the new ones
    fresh: bool = False  # recompute everything (the store is still written)
    batch: BatchOptions = BatchOptions()
    scheduler: str | None = None  # a Dask scheduler's address (else $MECHBOOK_SCHEDULER)
    exitfirst: bool = False  # stop at the first problem that fails (pytest's -x)

    @property
    def run(self) -> RunOptions:
        return self.batch.run


@dataclass
class CheckReport:
    """What one check gave: every run in the order of the ids (answered from the store or
    checked now, the same record either way), and what became of the store."""

    runs: list[ProblemRun]
    store: Path
    saver: Saver | None = None  # None: nothing was to be written
    cached: list[str] = field(default_factory=list)  # ids answered from the store
    stopped: list[str] = field(default_factory=list)  # not checked: -x stopped the run

    @property
    def store_error(self) -> str | None:
        return str(self.saver.error) if self.saver and self.saver.error else None

    @property
    def stored(self) -> bool:
        """Whether the store holds this check's results (some were written or were there
        already, and no write failed)."""
        return (self.saver is not None and self.saver.error is None
                and any(r.record is not None or r.cached for r in self.runs))

    @property
    def written(self) -> int:
        return self.saver.written if self.saver else 0

    def store_lines(self) -> list[str]:
        """Lines that say a write failed and where the results went (empty: none)."""
        return self.saver.report() if self.saver else []


def resolve_ids(ids: Sequence[str], base: Path) -> tuple[list[str], dict[str, ProblemRun]]:
    """The named ids (patterns and books expanded: mechbook.app.selection), or all of the
    tree's, each looked up once (mechbook.model.ids: one grammar). A named id that is
    malformed or has no file is a MechbookError; a file of the tree whose name is no good
    id is returned as an error run of its own (`refused`)."""
    named = select(ids, base)
    out = named or all_ids(base)
    refused: dict[str, ProblemRun] = {}
    for pid in out:
        try:
            existing_problem_path(pid, base)
        except MechbookError as exc:
            if named:
                raise
            refused[pid] = ProblemRun(pid, error=str(exc))
    return out, refused


class CheckService:
    """A check of problems of the tree at `base` (see the module docstring)."""

    def __init__(self, base: Path, options: CheckOptions = CheckOptions()):
        self.base = Path(base)
        self.options = options
        self.store = resolve_path(self.base, options.store)
        self.refused: dict[str, ProblemRun] = {}  # files of the tree with unusable names

    def resolve(self, ids: Sequence[str] = ()) -> list[str]:
        """The ids to check (all of the tree's when none are named; none at all is an
        error), as `resolve_ids` finds them. The store's path is checked here too, before
        any work, when it is to be written."""
        out, self.refused = resolve_ids(ids, self.base)
        if not out:
            raise MechbookError(f"no problems under {self.base / 'problems'}")
        if self.options.write:
            try:
                output_file(self.store, "store")
            except OutputError as exc:
                raise MechbookError(str(exc)) from None
        return out

    def run(self, ids: list[str], on_done: OnDone = _ignore) -> CheckReport:
        """Check `ids` (from `resolve`): answer what the store still holds, run the rest
        the longest first on the pool or the cluster, write each as it finishes; every run,
        cached or new, is handed to `on_done` as it is known."""
        opts = self.options
        good = [pid for pid in ids if pid not in self.refused]
        reuse = opts.write and not opts.fresh
        runs = cached_runs(good, self.base, self.store, opts.run.crosscheck) if reuse else {}
        cached = list(runs)
        runs.update(self.refused)
        for pid in ids:
            if pid in runs:
                on_done(runs[pid])
        saver = Saver(self.store)
        past = durations(self.store)
        todo = sorted((pid for pid in ids if pid not in runs),
                      key=lambda pid: -past.get(pid, float("inf")))
        if opts.exitfirst and failures(list(runs.values())):
            todo = []  # a failure known already: -x checks nothing more
        batch = self._batch(todo, lambda run: None)

        def finished(run: ProblemRun) -> None:
            on_done(run)
            if run.record is not None and opts.write:
                saver.save(run.record)  # never raises: a failure keeps the record aside
            if opts.exitfirst and failures([run]):
                batch.stop()

        batch.on_done = finished
        try:
            for run in batch.run(todo):
                runs[run.pid] = run
        finally:
            if opts.write:
                saver.finish()  # the store written anew once, with what it holds
        return CheckReport([runs[pid] for pid in ids if pid in runs], self.store,
                           saver if opts.write else None, cached,
                           [pid for pid in ids if pid not in runs])

    def _batch(self, todo: list[str], finished: OnDone):
        """The cluster when a scheduler is named and there is work, else the local pool
        (the pool runs in this process with `serial`)."""
        address = None if self.options.batch.serial else \
            scheduler_address(self.options.scheduler)
        if address and todo:
            return ClusterBatch(address, self.base, self.options.batch, on_done=finished)
        return Batch(self.base, self.options.batch, on_done=finished)


def check_loaded(problem: Problem, base: Path, options: RunOptions | None = None,
                 store: str | Path | None = None) -> ProblemRun:
    """Check a problem already loaded (the Python API's), in this process, and write the
    run to `store` if given (StoreError if it cannot be: the caller asked for it)."""
    run = run_problem(problem.id, Path(base), options or RunOptions(), problem=problem)
    if store is not None and run.record is not None:
        write([run.record], store)
    return run


def check(ids: Sequence[str], base: Path, options: CheckOptions = CheckOptions(),
          on_done: OnDone = _ignore) -> CheckReport:
    """`resolve` then `run`, for callers with nothing to do between them."""
    service = CheckService(base, options)
    return service.run(service.resolve(ids), on_done)

