"""Progress of a report on stderr: a bar with ETA on a terminal, otherwise a line per page
with the count and the time left at the pace so far (`[12/158] lim-2031 (1.8 s), about 4
min left`)."""

from __future__ import annotations

import sys
import time
from collections.abc import Callable

import click


class Progress:
    def __init__(self, total: int, log: Callable[[str], None]):
        self.total, self.count, self.log = total, 0, log
        self.start = time.monotonic()
        self.bar = None
        if sys.stderr.isatty() and total > 1:
            self.bar = click.progressbar(length=total, label="report pages", file=sys.stderr,
                                         show_eta=True, show_pos=True,
                                         item_show_func=lambda pid: pid or "")
            self.bar.__enter__()

    def done(self, pid: str, seconds: float, failed: str | None = None) -> None:
        self.count += 1
        if self.bar is not None:
            self.bar.update(1, pid)
            if failed:
                click.echo(f"\n{pid}: the page could not be built: {failed}", err=True)
            return
        elapsed = time.monotonic() - self.start
        left = elapsed / self.count * (self.total - self.count)
        eta = f", about {_duration(left)} left" if self.count < self.total else ""
        what = f": could not be built: {failed}" if failed else ""
        self.log(f"[{self.count}/{self.total}] {pid} ({seconds:.1f} s){what}{eta}")

    def close(self) -> None:
        if self.bar is not None:
            self.bar.__exit__(None, None, None)
            self.bar = None


def _duration(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    return f"{seconds / 60:.0f} min"
