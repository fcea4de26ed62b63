"""Numeric command-line options that refuse NaN and infinities and have an upper bound.

click's FloatRange lets NaN through (every comparison with NaN is false), so `--timeout nan`
removed the time limit; an option without a maximum let `--points 10**20` reach NumPy. Every
numeric option of the command line is one of these, with the bounds below: far above any
real use, low enough that a run stays bounded (each run also has its time limit and memory
bound), and a batch's default limits. Importing this module loads only click.
"""

from __future__ import annotations

import math

import click

# a batch's default limits (here, so that --help shows them without loading the batch
# machinery, h5py and NumPy)
DEFAULT_TIMEOUT = 600.0  # seconds per problem; the slowest takes well under a minute
DEFAULT_MEMORY_MB = 8000  # resident memory per worker

MAX_SECONDS = 1e6  # wall-clock limits: about 11.6 days
MAX_MEMORY_MB = 1e7  # 10 TB: more than any machine this runs on
MAX_STEP_SECONDS = 3600.0  # one derivation step, one proof attempt
MAX_JOBS = 1024
MAX_POINTS = 1_000_000  # samples of one simulation
MAX_SAMPLES = 10_000  # accuracy samples of a sweep
SWEEP_SAMPLES = 24  # points of a sweep's 30-digit accuracy check, by default
MAX_TIME = 1e9  # simulated time, step sizes


class Finite(click.FloatRange):
    """A float in [min, max] (open ends where asked): finite, NaN and infinities refused."""

    name = "number"

    def convert(self, value, param, ctx):
        x = click.FLOAT.convert(value, param, ctx)
        if not math.isfinite(x):
            self.fail(f"{value!r} is not a finite number", param, ctx)
        return super().convert(x, param, ctx)


def seconds(max_: float = MAX_SECONDS) -> Finite:
    """A time limit: positive, finite, at most `max_`."""
    return Finite(min=0, min_open=True, max=max_)


def memory() -> Finite:
    """A memory bound in MB (0: none), finite, at most MAX_MEMORY_MB."""
    return Finite(min=0, max=MAX_MEMORY_MB)


def jobs(min_: int = 0) -> click.IntRange:
    return click.IntRange(min=min_, max=MAX_JOBS)
