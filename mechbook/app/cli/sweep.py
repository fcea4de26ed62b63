"""`mechbook sweep`: one result of a problem over a grid of parameter values (the work is
mechbook.app.sweep's; here: the options checked before any work, the outputs written)."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import click

from mechbook.app import options as opt
from mechbook.app.cli.common import (
    backend_option,
    checked_output,
    given,
    in_tree,
    jobs_option,
    memory_option,
    name_option,
    no_store_option,
    plot_option,
    problem_id_argument,
    resolve_root,
    say,
    scheduler_option,
    store_option,
    system_option,
    timeout_option,
)
from mechbook.app.cli.statuses import failure
from mechbook.app.sweep.spec import QUANTITIES
from mechbook.core.backends import DEFAULT_BACKEND
from mechbook.errors import MechbookError, message


@click.command("sweep")
@problem_id_argument()
@click.option("--param", "params", multiple=True, required=True, metavar="NAME=LO:HI:N[:log]",
              help="A swept parameter: N values from LO to HI (evenly; ':log' evenly in log). "
                   "Repeat for a plane or more; the others stay at their values (N=1 fixes "
                   "one: k=2:2:1). For --quantity drift one must be 'amplitude'.")
@click.option("--quantity", type=click.Choice(list(QUANTITIES)),
              default="frequencies", show_default=True,
              help="frequencies: the normal frequencies; stability: stable / marginal / "
                   "unstable and the growth rate; drift: the frequency measured from the "
                   "nonlinear motion at each amplitude against the linear one.")
@system_option()
@click.option("--about", multiple=True, metavar="COORD=EXPR",
              help="The equilibrium to linearize about (theta=pi); default: the stable one.")
@click.option("--steady", multiple=True, metavar="COORD=RATE",
              help="A steady motion: a cyclic coordinate turning at RATE (with --about for "
                   "the others), reduced by Routh's procedure.")
@click.option("--part", default=None,
              help="Take the point (and the book's answer drawn over) from this answer part.")
@backend_option("How M(p), C(p), K(p) are compiled.", DEFAULT_BACKEND)
@jobs_option("Local worker processes for the blocks (1: this process).", least=1)
@scheduler_option("Evaluate the blocks on the Dask cluster at ADDRESS (default "
                  "$MECHBOOK_SCHEDULER, else locally).")
@timeout_option("Wall-clock seconds allowed per block on a cluster worker.")
@memory_option("Resident memory (MB) allowed per cluster worker's block, and for the "
               "sweep's arrays here (a grid whose arrays would need more is refused "
               "before anything is computed; 0: no bound).")
@click.option("--samples", type=click.IntRange(min=0, max=opt.MAX_SAMPLES),
              default=opt.SWEEP_SAMPLES, show_default=True,
              help="Points where the float64 result is checked against 30 digits.")
@name_option("Name of the stored sweep (default QUANTITY-AXES).")
@store_option("HDF5 store to add the sweep to.")
@no_store_option("Do not store the sweep.")
@click.option("--out", "out_path", type=click.Path(dir_okay=False, path_type=Path),
              default=None, help="Write the sweep to this netCDF-4 file (named dimensions); a "
                                 "sweep too large for the store goes to results/sweeps/ anyway.")
@plot_option("Write the figure here (PNG, SVG, PDF by suffix).")
@click.pass_context
def command(ctx: click.Context, problem_id: str, params: tuple[str, ...], quantity: str,
            system: str | None, about: tuple[str, ...], steady: tuple[str, ...],
            part: str | None, backend: str, jobs: int, scheduler: str | None, timeout: float,
            memory_mb: float, samples: int, name: str | None, store_path: Path,
            no_store: bool, out_path: Path | None, plot_path: Path | None) -> None:
    """Map a problem's frequencies, stability or frequency drift over a grid of parameter
    values: derived once, M(p), C(p), K(p) compiled once, every point's eigenproblem solved
    in stacked batches; the float64 result is checked against 30 digits at sampled points
    and the book's answer at the same point is drawn over (and compared)."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.running.distributed import scheduler_address
    from mechbook.app.sweep import make_spec, run_sweep

    base = resolve_root(ctx)
    path = in_tree(ctx, store_path)
    axes = _axes(params, memory_mb, name)
    if not no_store:
        checked_output(path, "store")
    checked_output(out_path, "netCDF file")
    checked_output(plot_path, "plot")
    if (about or steady) and part:
        raise click.UsageError("--part takes the point from the answer key: drop --about/"
                               "--steady, or --part")
    address = scheduler_address(scheduler)
    _refuse_what_does_not_apply(ctx, address)
    try:
        spec = make_spec(problem_id, base, quantity, axes, system=system,
                         about=_pairs(about, "--about"), steady=_pairs(steady, "--steady"),
                         part=part, backend=backend)
        with _BlockProgress() as progress:
            result = run_sweep(spec, base, jobs=jobs, scheduler=address, timeout=timeout,
                               memory_mb=memory_mb, samples=samples, progress=progress)
    except (MechbookError, KeyError) as exc:
        out = failure(exc)  # no such problem: its own status (statuses.TABLE)
        out.message = message(exc)
        raise out from None
    run_name = name or "-".join([quantity] + [a.name for a in axes])
    failed = not _write(result, base, path, run_name, out_path, stored=not no_store)
    if plot_path is not None:
        # at call time, not at the top: `mechbook --help` and `list` start without it
        from mechbook.app.sweep.figures import plot_sweep

        say(f"plot written to {plot_sweep(result, plot_path)}")
    if failed:
        sys.exit(1)


class _BlockProgress:
    """The blocks evaluated so far, on stderr: a bar on a terminal, otherwise a line per
    block (`[7/14] blocks evaluated (2.1 s)`), for a CI log; nothing for a single block."""

    def __enter__(self) -> _BlockProgress:
        self.start, self.bar = time.monotonic(), None
        return self

    def __call__(self, done: int, total: int) -> None:
        if total < 2:
            return
        if not sys.stderr.isatty():
            click.echo(f"[{done}/{total}] blocks evaluated "
                       f"({time.monotonic() - self.start:.1f} s)", err=True)
            return
        if self.bar is None:
            self.bar = click.progressbar(length=total, label="blocks", file=sys.stderr,
                                         show_eta=True, show_pos=True)
            self.bar.__enter__()
        self.bar.update(1)

    def __exit__(self, *exc) -> None:
        if self.bar is not None:
            self.bar.__exit__(None, None, None)


def _axes(params: tuple[str, ...], memory_mb: float, name: str | None) -> list:
    """The swept axes, the grid's size and the run's name checked before any work."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.store import check_run_name
    from mechbook.app.sweep import check_grid
    from mechbook.engine.linear_grid import parse_axis

    try:
        axes = [parse_axis(p) for p in params]
        check_grid(axes, memory_mb)
    except (ValueError, MechbookError) as exc:
        raise click.BadParameter(str(exc), param_hint="--param") from None
    try:
        if name is not None:
            check_run_name(name, "sweep")
    except MechbookError as exc:
        raise click.BadParameter(str(exc), param_hint="--name") from None
    return axes


def _refuse_what_does_not_apply(ctx: click.Context, address: str | None) -> None:
    """--timeout bounds a block on a cluster worker and -j counts local processes: each
    given where the other kind of run happens would be dropped silently."""
    if address is None and given(ctx, "timeout"):
        raise click.UsageError("--timeout limits a block on a cluster worker: without "
                               "--scheduler (or $MECHBOOK_SCHEDULER) it has no effect")
    if address is not None and given(ctx, "jobs"):
        raise click.UsageError("-j counts local processes: on a cluster (--scheduler or "
                               "$MECHBOOK_SCHEDULER) it has no effect")


def _pairs(items: tuple[str, ...], what: str) -> dict[str, str]:
    out = {}
    for item in items:
        key, sep, val = item.partition("=")
        if not sep or not key.strip() or not val.strip():
            raise click.BadParameter(f"{item!r}: expected NAME=EXPR", param_hint=what)
        out[key.strip()] = val.strip()
    return out


def _write(result, base: Path, store: Path, run_name: str, out_path: Path | None,
           stored: bool) -> bool:
    """The summary printed, the sweep written to the netCDF file and (`stored`) the store;
    a sweep too large for the store goes to results/sweeps/ anyway. False if a write
    failed (the sweep is then kept where it can be)."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.store import StoreError
    from mechbook.app.sweep.storage import STORE_POINTS, write_netcdf, write_store
    from mechbook.app.sweep.text_summary import summary

    for line in summary(result):
        say(line)
    pid = result.spec.pid
    big = result.attrs["points"] > STORE_POINTS
    if out_path is None and big and stored:
        out_path = base / "results" / "sweeps" / f"{pid}-{run_name}.nc"
    try:
        if out_path is not None:
            result.attrs["file"] = str(write_netcdf(result, out_path))
            say(f"written to {out_path} (netCDF-4, dimensions {', '.join(result.coords)})")
        if stored:
            write_store(result, run_name, store)
            where = "its attributes and the file's path" if big else "stored"
            say(f"{where} as /sweeps/{pid}/{run_name} in {store}")
    except (StoreError, MechbookError) as exc:
        say(f"error: {exc}", err=True)
        say(_keep_sweep(result, store, f"{pid}-{run_name}"), err=True)
        return False
    return True


def _keep_sweep(result, store: Path, label: str) -> str:
    """A sweep that could not be written where asked, kept as a netCDF file in the first
    place that takes it (beside the store, the temporary directory, home)."""
    import tempfile

    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.sweep.storage import write_netcdf

    tried = []
    for place in (store.parent, Path(tempfile.gettempdir()), Path.home()):
        try:
            side = write_netcdf(result, place / f"{label}.unsaved.nc")
            return f"error: the sweep is kept in {side} (netCDF-4; xarray opens it)"
        except (OSError, MechbookError, RuntimeError, ValueError) as exc:
            tried.append(f"{place}: {exc}")
    return "error: the sweep could not be kept anywhere (" + "; ".join(tried) + ")"
