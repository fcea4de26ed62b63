"""`mechbook sweep`: one result of a problem mapped over a grid of parameter values.

The problem is derived once and its linear system (about `--about`, a steady motion
`--steady`, an answer part's point `--part`, or the stable equilibrium) compiled once with
the parameters as arguments (mechbook.engine.linear_grid); the grid is cut into blocks, evaluated
in this process, on a local process pool (`-j`), or on a Dask cluster (`--scheduler`,
mechbook.app.running.distributed), and put back together in grid order. Quantities:

    frequencies  the normal angular frequencies at every point (ascending; NaN: unstable)
    stability    stable / marginal / unstable / undefined at every point, and the largest
                 growth rate
    drift        how far the frequency measured from the nonlinear motion at a finite
                 amplitude drifts from the small-oscillation one: one axis must be the
                 pseudo-parameter `amplitude` (mechbook.crosscheck.amplitude)

The float64 path is then checked against the 30-digit one at sampled points (random ones
and, for a stability map, ones beside the boundary) and the largest relative difference is
reported; the book's answer at the same point (its stability condition, its frequencies),
evaluated over the same grid, is kept beside the engine's for the plot and for a count of
where they disagree (mechbook.app.sweep.book_answer).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import sympy as sp

from mechbook.app.options import SWEEP_SAMPLES
from mechbook.app.running.batch import kill_pool, pool_context
from mechbook.app.running.distributed import (
    connect,
    dask_distributed,
    limited,
    materialize,
    use_scratch,
)
from mechbook.app.running.serverstart import deferred_interrupt, start_server
from mechbook.app.sweep.book_answer import book_overlay
from mechbook.app.sweep.precision import sample_accuracy
from mechbook.app.sweep.spec import (
    AMPLITUDE,
    SweepSpec,
    check_grid,
)
from mechbook.crosscheck.amplitude import amplitude_response
from mechbook.engine.analysis import Analysis
from mechbook.engine.linear_grid import UNDEFINED, Grid, LinearSweep, condition_mask
from mechbook.engine.state_sweep import StateSweep
from mechbook.errors import InputError, MechbookError, NotFoundError
from mechbook.model.catalog import answer_path, problem_path
from mechbook.model.expr import parse
from mechbook.model.problem import load_problem
from mechbook.verify.answers import load_answers
from mechbook.verify.context import Context

BLOCK_ENTRIES = 4_000_000  # matrix entries evaluated per block (bounds a block's memory)
DRIFT_BLOCK = 4  # points per block of a drift sweep (each point is a simulation per mode)


class Sweeper:
    """A sweep's derived and compiled state, built once per process."""

    def __init__(self, spec: SweepSpec, base: Path):
        self.spec = spec
        self.problem = load_problem(problem_path(spec.pid, base))
        self.analysis = Analysis(self.problem)
        apath = answer_path(spec.pid, base)
        self.key = load_answers(apath) if apath.exists() else None
        fixed = dict(self.problem.values())
        symbols = list(fixed)
        self.context = None
        if spec.part is not None:
            self._linearize_at_part(fixed, symbols)
        else:
            self._linearize_at_point()
        self.steady = dict(self.lin.dyn.sys.held_momenta)  # {} about an equilibrium
        self.amplitude = self._amplitude(symbols)
        try:
            self.grid = Grid(list(spec.axes), symbols, fixed)
        except ValueError as exc:
            raise InputError(str(exc)) from None
        self._check_ranges(symbols)
        self.lin_symbols = [s for s in symbols if s is not self.amplitude]
        sweep = StateSweep if self.lin.first_order else LinearSweep  # velocity constraints
        self.linear = sweep(self.lin, self.lin_symbols, spec.backend)
        # the problem's conditions, and a part's `assume:`: points outside are undefined
        self.conditions = list(self.context.sampler.conditions if self.context
                               else self.problem.conditions)
        loose = sorted({str(x) for c in self.conditions for x in c.free_symbols}
                       - {str(x) for x in self.lin_symbols})
        if loose:
            raise MechbookError(f"the conditions use {', '.join(loose)}, which has no value")
        self._models: dict = {}

    def _linearize_at_part(self, fixed: dict, symbols: list) -> None:
        """--part: the part's system, point and values (its own symbols join the grid's)."""
        self.context = Context(self.analysis, self._part(self.spec.part))
        self.system = self.context.system
        self.lin = self.context.linear()
        fixed.update(self.key.symbol_values)
        symbols += [s for s in self.key.symbol_values if s not in symbols]

    def _linearize_at_point(self) -> None:
        """--about / --steady, or the system's stable equilibrium."""
        spec = self.spec
        try:
            self.system = self.analysis.system(spec.system)
        except NotFoundError as exc:
            raise NotFoundError(f"{exc}; name it with --system") from None
        about, steady = self._point(spec.about, "about"), self._point(spec.steady, "steady")
        if steady:
            self.lin = self.analysis.steady_linear(self.system.name, steady, about)
        elif about:
            self.lin = self.analysis.linear(self.system.name, about)
        else:
            self.lin = self.analysis.linear(self.system.name,
                                            self.analysis.default_point(self.system.name))

    def _point(self, pairs, what: str) -> dict:
        """{coordinate: value} from the option's NAME=EXPR pairs (the safe parser)."""
        names = dict(self.system.names)
        out = {}
        for name, text in pairs:
            if name not in self.system.coord_names:
                raise NotFoundError(f"--{what} {name}=...: {name!r} is not a coordinate "
                                   f"of {self.spec.pid} (coordinates: "
                                   f"{', '.join(self.system.coord_names)})")
            q = self.system.q[self.system.coord_names.index(name)]
            out[q] = parse(text, names)
        return out

    def _amplitude(self, symbols: list):
        """A drift sweep's pseudo-parameter `amplitude`, appended to `symbols` (None for
        the other quantities)."""
        spec = self.spec
        if spec.quantity != "drift":
            return None
        if AMPLITUDE in [str(s) for s in symbols]:
            raise MechbookError(f"{spec.pid} has a parameter named {AMPLITUDE!r}: a drift "
                                "sweep cannot tell it from the amplitude")
        if AMPLITUDE not in [a.name for a in spec.axes]:
            raise MechbookError(f"a drift sweep needs --param {AMPLITUDE}=LO:HI:N (the "
                                "largest coordinate displacement of the start)")
        amplitude = sp.Symbol(AMPLITUDE)
        symbols.append(amplitude)
        return amplitude

    def _check_ranges(self, symbols: list) -> None:
        """SymPy simplified with the parameters' assumptions: a swept range honours them."""
        names = [str(s) for s in symbols]
        for a in self.spec.axes:
            sym = symbols[names.index(a.name)] if a.name in names else self.amplitude
            if (sym.is_positive or sym is self.amplitude) and min(a.lo, a.hi) <= 0:
                raise InputError(f"--param {a.text()}: {a.name} is positive; sweep it over "
                                 "positive values")
            if sym.is_nonzero and min(a.lo, a.hi) <= 0 <= max(a.lo, a.hi):
                raise InputError(f"--param {a.text()}: {a.name} is nonzero; keep 0 out of "
                                 "its range")

    def _part(self, name: str):
        if self.key is None:
            raise NotFoundError(f"--part {name}: {self.spec.pid} has no answer key")
        for p in self.key.parts:
            if p.name == name:
                return p
        raise NotFoundError(f"--part {name}: no such part (parts: "
                            f"{', '.join(p.name for p in self.key.parts)})")

    @property
    def modes(self) -> int:
        return self.linear.n

    def point_text(self) -> str:
        pt = ", ".join(f"{k} = {sp.sstr(v)}" for k, v in self.lin.point.items()) or "origin"
        if self.steady:
            pt += "; steady, momenta " + ", ".join(f"p_{k} = {sp.sstr(v)}"
                                                   for k, v in self.steady.items())
        return pt

    def block_size(self) -> int:
        if self.spec.quantity == "drift":
            return DRIFT_BLOCK
        return max(1, BLOCK_ENTRIES // (3 * self.modes**2 + 2 * self.modes + 1))

    # ---- one block ---------------------------------------------------------------------
    def block(self, start: int, stop: int) -> dict[str, np.ndarray]:
        X = self.grid.block(start, stop)
        if self.spec.quantity == "drift":
            return self._drift(X)
        lin_cols = [j for j, s in enumerate(self.grid.symbols) if s is not self.amplitude]
        got = self.linear.evaluate(X[:, lin_cols], ("frequencies", "stability"))
        outside = ~self.admissible(X[:, lin_cols])
        got.stability[outside] = UNDEFINED
        got.frequencies[outside] = np.nan
        got.growth[outside] = np.nan
        out = {"ill": np.array([got.ill]), "precise": np.array([got.precise]),
               "stability": got.stability, "frequencies": got.frequencies}
        if self.spec.quantity == "stability":
            out["growth"] = got.growth
        return out

    def admissible(self, X: np.ndarray) -> np.ndarray:
        """Where the conditions hold, at rows of X (columns: `lin_symbols`)."""
        return condition_mask(self.conditions, self.lin_symbols, X, self.spec.backend)

    def _drift(self, X: np.ndarray) -> dict[str, np.ndarray]:
        k, n = X.shape[0], self.modes
        linear = np.full((k, n), np.nan)
        measured = np.full((k, n), np.nan)
        a_col = self.grid.symbols.index(self.amplitude)
        ok = self.admissible(X[:, [j for j in range(X.shape[1]) if j != a_col]])
        for i, row in enumerate(X):
            if not ok[i]:
                continue
            values = {s: float(x) for s, x in zip(self.grid.symbols, row, strict=True)
                      if s is not self.amplitude}
            try:
                lin, meas = amplitude_response(self.analysis, self.lin, values, [row[a_col]],
                                               self._models)
            except (MechbookError, ValueError, np.linalg.LinAlgError, ZeroDivisionError):
                continue  # no oscillation to measure there: NaN
            linear[i, : len(lin)], measured[i, : len(lin)] = lin, meas[0]
        with np.errstate(all="ignore"):
            rel = (measured - linear) / linear
        return {"linear": linear, "measured": measured, "relative_error": rel,
                "ill": np.array([0]), "precise": np.array([0])}


# ---- where blocks run ------------------------------------------------------------------------
_SWEEPERS: dict[str, Sweeper] = {}  # per process: one sweeper per sweep (compiled once)


def block_of(spec: SweepSpec, start: int, stop: int) -> dict[str, np.ndarray]:
    """One block on whatever process runs it: derived and compiled on first use there."""
    if spec.key not in _SWEEPERS:
        _SWEEPERS[spec.key] = Sweeper(spec, materialize(dict(spec.files)))
    return _SWEEPERS[spec.key].block(start, stop)


def cluster_block(spec: SweepSpec, start: int, stop: int, timeout: float,
                  memory_mb: float) -> dict[str, np.ndarray]:
    """A block on a Dask worker, inside that worker's limited child process."""
    return limited(block_of, (spec, start, stop), timeout, memory_mb)


@dataclass
class SweepResult:
    spec: SweepSpec
    coords: dict[str, np.ndarray]
    arrays: dict[str, np.ndarray]
    dims: dict[str, tuple[str, ...]]
    attrs: dict = field(default_factory=dict)
    book: dict = field(default_factory=dict)  # mechbook.app.sweep.book_answer.BookOverlay fields


def run_sweep(spec: SweepSpec, base: Path, jobs: int = 1, scheduler: str | None = None,
              timeout: float = 600.0, memory_mb: float = 8000.0, samples: int = SWEEP_SAMPLES,
              progress: Callable[[int, int], None] | None = None) -> SweepResult:
    """Build the sweep here (for the accuracy check and the book), evaluate every block
    where asked, and assemble the result in grid order."""
    t0 = time.perf_counter()
    sweeper = Sweeper(spec, base)
    check_grid(list(spec.axes), memory_mb, sweeper.modes)
    built = time.perf_counter() - t0
    size, step = sweeper.grid.size, sweeper.block_size()
    ranges = [(s, min(s + step, size)) for s in range(0, size, step)]
    progress = progress or (lambda done, total: None)
    t1 = time.perf_counter()
    if scheduler:
        parts = _on_cluster(spec, ranges, scheduler, timeout, memory_mb, progress)
        where = f"Dask cluster at {scheduler}"
    elif jobs > 1 and len(ranges) > 1:
        parts = _on_local_processes(spec, ranges, jobs, progress)
        where = f"{jobs} local processes"
    else:
        parts = {}
        for a, b in ranges:
            parts[a] = sweeper.block(a, b)
            progress(len(parts), len(ranges))
        where = "this process"
    seconds = time.perf_counter() - t1
    arrays, dims = _assemble(sweeper, [parts[a] for a, _ in ranges])

    t2 = time.perf_counter()
    accuracy = sample_accuracy(sweeper, arrays, samples)
    attrs = {
        "problem": spec.pid, "title": sweeper.problem.title, "quantity": spec.quantity,
        "system": sweeper.system.name, "point": sweeper.point_text(),
        "axes": " ".join(a.text() for a in spec.axes), "points": size, "modes": sweeper.modes,
        "gyroscopic": bool(sweeper.linear.gyroscopic), "backend": spec.backend,
        "where": where, "blocks": len(ranges), "build_seconds": built,
        "evaluate_seconds": seconds, "points_per_second": size / max(seconds, 1e-9),
        "accuracy_seconds": time.perf_counter() - t2,
        **_provenance(sweeper, parts, accuracy),
    }
    if spec.part:
        attrs["part"] = spec.part
    result = SweepResult(spec, sweeper.grid.coords(), arrays, dims, attrs)

    result.book = book_overlay(sweeper, result)
    return result


def _on_cluster(spec: SweepSpec, ranges: list[tuple[int, int]], scheduler: str,
                timeout: float, memory_mb: float, progress: Callable[[int, int], None]) -> dict:
    """Every block on the Dask cluster, each under the limits on its worker."""
    as_completed = dask_distributed().as_completed
    parts: dict[int, dict] = {}
    with connect(scheduler) as client:
        futures = {client.submit(cluster_block, spec, a, b, timeout, memory_mb,
                                 pure=False): a for a, b in ranges}
        for fut in as_completed(futures):
            parts[futures[fut]] = fut.result()
            progress(len(parts), len(ranges))
    return parts


def _on_local_processes(spec: SweepSpec, ranges: list[tuple[int, int]], jobs: int,
                        progress: Callable[[int, int], None]) -> dict:
    """Every block on a pool of `jobs` local processes (that die with this one)."""
    from concurrent.futures import ProcessPoolExecutor, as_completed
    from multiprocessing import util

    parts: dict[int, dict] = {}
    context = pool_context()
    start_server()
    with deferred_interrupt():  # its workers are started as the blocks are submitted
        pool = ProcessPoolExecutor(jobs, mp_context=context, initializer=use_scratch,
                                   initargs=(os.getpid(), util.get_temp_dir()))
        try:
            futures = {pool.submit(block_of, spec, a, b): a for a, b in ranges}
        except BaseException:
            kill_pool(pool)
            raise
    try:
        for fut in as_completed(futures):
            parts[futures[fut]] = fut.result()
            progress(len(parts), len(ranges))
    except BaseException:  # Ctrl-C (the workers ignore it) or a block's error: stop now
        kill_pool(pool)
        raise
    pool.shutdown()
    return parts


def _provenance(sweeper: Sweeper, parts: dict, accuracy: dict) -> dict:
    """What the stored sweep says about its numbers: conditioning, the 30-digit check, the
    conditions and fixed values it was computed under, the problem file's hash."""
    spec = sweeper.spec
    return {
        "ill_conditioned": int(sum(int(p["ill"][0]) for p in parts.values())),
        "precise_50_digits": int(sum(int(p["precise"][0]) for p in parts.values())),
        "accuracy_samples": accuracy["samples"],
        "max_rel_diff_float64_vs_30_digits": accuracy["max_rel_diff"],
        "accuracy_disagreements": accuracy["disagree"], "accuracy": accuracy,
        "conditions": [sp.sstr(c) for c in sweeper.conditions],
        "fixed": {str(s): v for s, v in sweeper.grid.fixed.items()
                  if str(s) not in {a.name for a in spec.axes}},
        "problem_sha256": sweeper.problem.sha256,
    }


def _assemble(sweeper: Sweeper, parts: list[dict]) -> tuple[dict, dict]:
    shape = sweeper.grid.shape
    names = tuple(a.name for a in sweeper.grid.axes)
    arrays, dims = {}, {}
    for key in parts[0]:
        if key in ("ill", "precise"):
            continue
        full = np.concatenate([p[key] for p in parts], axis=0)
        if full.ndim == 2:
            arrays[key] = full.reshape(*shape, full.shape[1])
            dims[key] = names + ("mode",)
        else:
            arrays[key] = full.reshape(shape)
            dims[key] = names
    return arrays, dims
