"""What a check run prints: progress on stderr (a bar with ETA on a terminal, one line per
problem otherwise) and the table of outcomes per part with its cross-check column."""

from __future__ import annotations

import sys
from collections import Counter

import click

from mechbook.core.words import plural
from mechbook.records import FAILING, Status

# the order a summary counts outcomes in: of the parts, and of the cross-checks
STATUS_ORDER = (Status.PASS, Status.ERRATUM, Status.UNSUPPORTED, Status.FAIL, Status.ERROR)
CROSS_ORDER = (Status.PASS, Status.NA, Status.FAIL, Status.ERROR)


class Progress:
    """Progress of a batch on stderr: a bar with ETA on a terminal, a plain line per
    finished problem otherwise (CI logs)."""

    def __init__(self, total: int, cached: int):
        self.total, self.done = total, cached
        self.bar = None
        if sys.stderr.isatty() and total > cached:
            self.bar = click.progressbar(length=total - cached, label="checking",
                                         file=sys.stderr, show_eta=True, show_pos=True,
                                         item_show_func=lambda pid: pid or "")
            self.bar.__enter__()

    def finished(self, run) -> None:
        self.done += 1
        if self.bar is not None:
            self.bar.update(1, run.pid)
            if run.error or any(o.status in FAILING for o in run.outcomes):
                click.echo(f"\n{run.pid}: {_summary(run)}", err=True)
        else:
            click.echo(f"[{self.done}/{self.total}] {run.pid} ({run.seconds:.1f} s): "
                       f"{_summary(run)}", err=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.__exit__(None, None, None)


def _summary(run) -> str:
    counts = Counter(o.status for o in run.outcomes)
    summary = run.error or ", ".join(f"{counts[s]} {s}" for s in STATUS_ORDER if counts[s])
    if run.cached:
        summary += " (cached: problem, answers and engine unchanged)"
    return summary


def print_table(runs: list, verbose: bool) -> None:
    total: Counter = Counter()
    crossed: Counter = Counter()
    click.echo(f"{'problem':<16} {'part':<16} {'quantity':<20} {'outcome':<12} "
               f"{'cross-check':<12} method / detail")
    click.echo("-" * 112)
    for run in runs:
        if run.error:
            click.echo(f"{run.pid:<16} {'-':<16} {'-':<20} {'ERROR':<12} {'-':<12} {run.error}")
            total[Status.ERROR] += 1
            continue
        by_part: dict[str, list] = {}
        for x in run.crosschecks:
            crossed[x.status] += 1
            for p in x.parts:
                by_part.setdefault(p, []).append(x)
        for o in run.outcomes:
            total[o.status] += 1
            info = o.method
            if o.status != Status.PASS or verbose:
                info = f"{o.method} {o.detail}".strip()
            if verbose and o.power:
                info = f"[{o.power}] {info}"
            label = o.part if o.origin == "book" else f"{o.part} (derived)"
            cell = ",".join(x.cell() for x in by_part.get(o.part, [])) or "-"
            click.echo(f"{run.pid:<16} {label:<16} {o.quantity:<20} {o.status:<12} {cell:<12} "
                       f"{info[:160] if not verbose else info}")
    click.echo("-" * 112)
    parts = sum(total.values())
    click.echo(f"{plural(len(runs), 'problem')}, {plural(parts, 'part')}: " +
               ", ".join(f"{total[s]} {s}" for s in STATUS_ORDER if total[s]))
    if crossed:
        click.echo(f"cross-checks: {sum(crossed.values())}: " +
                   ", ".join(f"{crossed[s]} {s}" for s in CROSS_ORDER if crossed[s]))
    loose = [(r.pid, x) for r in runs for x in r.crosschecks if not x.parts]
    if loose:  # the engine's own equilibria, systems no answer part refers to
        click.echo("\ncross-checks no answer part refers to:")
        for pid, x in loose:
            info = f"{x.name}: {x.detail}"
            click.echo(f"  {pid:<16} {x.cell():<12} {info[:160] if not verbose else info}")
    notes = [(r.pid, n) for r in runs for n in r.notes] if verbose else []
    if notes:  # warnings turned into notes, derived results not stored ...
        click.echo("\nnotes:")
        for pid, note in notes:
            click.echo(f"  {pid:<16} {note}")
    shown = [(r.pid, x) for r in runs for x in r.crosschecks if verbose or x.failed]
    if shown:
        click.echo("\ncross-check details:" if verbose else "\nfailed cross-checks:")
        for pid, x in shown:
            click.echo(f"  {pid:<16} {x.name} [{x.cell()}; {x.seconds:.2f} s] {x.detail}")
