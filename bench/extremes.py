"""Numerical stability of the normal frequencies at extreme parameter ratios.

For every problem with a small-oscillation result about its default equilibrium, each
parameter is scaled by 10^k (k = -8 … 8) in turn, and the engine's numeric frequencies
(`LinearSystem.numeric_frequencies`, the path `mechbook check` uses) are compared with the
closed-form frequencies evaluated with 50-digit mpmath arithmetic (their size: a closed form
such as sqrt(k/m) - omega changes sign as a parameter grows). Reports the worst
relative error per system (and where it occurs), and every ratio where the engine reports
a zero frequency that is not zero, or a nonzero one that is. A system whose linear system
has no normal frequencies at its default point (a mass matrix that is not positive
definite: a chart's singular point) is listed as not applicable, with the reason. Progress
goes to stderr, a line per problem. Never used to gate CI.

    python bench/extremes.py [ID ...] [--decades 8] [--quick] [--csv FILE]

--quick: the ratios 10^k for k = -8, -4, 0, 4, 8 only, and a system whose default point,
linear system and closed-form frequencies take more than QUICK_SECONDS of CPU to derive
(an 8-coordinate secular determinant spends its whole 30 s limit) is skipped and listed
as such: a few minutes instead of a quarter of an hour.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import mpmath
import numpy as np
import pandas as pd
import sympy as sp

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mechbook.core.timeout import Timeout, cpu_time, hard_time_limit  # noqa: E402
from mechbook.engine.analysis import Analysis  # noqa: E402
from mechbook.errors import MechbookError, UnsupportedError  # noqa: E402
from mechbook.model.catalog import all_ids, problem_path  # noqa: E402
from mechbook.model.problem import load_problem  # noqa: E402

DIGITS = 50
QUICK_SECONDS = 5.0  # --quick: CPU for a system's default point and closed forms
AGREE = mpmath.mpf(10) ** -25  # two evaluations of a closed form agreeing this well: exact
TOLERANCE = 1e-10  # the aim: every system within this at every ratio


def closed_forms(freqs: list[sp.Expr], symbols: list[sp.Symbol]):
    """The closed forms as one mpmath function of the parameters (SymPy's lambdify to
    mpmath: evaluated at the working precision, independently of the engine's numeval)."""
    return sp.lambdify(symbols, freqs, modules="mpmath")


def reference(fn, symbols: list[sp.Symbol], values: dict) -> np.ndarray:
    """The closed forms' sizes at `values` (a parameter's float value taken exactly); NaN
    where one is not real (an unstable ratio). Evaluated at 50 digits, then at twice the
    digits until two evaluations agree to AGREE: a closed form can cancel most of them
    (symon-09-29 at kφ × 1e-8: a frequency 1e-15 from terms of 1e14 keeps 5 of 50 digits),
    which evalf's adaptive precision did for the bench before."""
    last = None
    for digits in (DIGITS, 2 * DIGITS, 4 * DIGITS, 8 * DIGITS):
        with mpmath.workdps(digits):
            got = [mpmath.mpc(z) for z in fn(*(mpmath.mpf(float(values[s])) for s in symbols))]
            if last is not None and all(
                    abs(a - b) <= AGREE * max(abs(a), mpmath.mpf(10) ** (-digits))
                    for a, b in zip(got, last, strict=True)):
                break
            last = got
    out = []
    for z in got:
        real = abs(z.imag) <= mpmath.mpf(10) ** -30 * max(1, abs(z))
        out.append(float(abs(z.real)) if real else np.nan)
    return np.sort(np.array(out))


def ratios(decades: int, quick: bool) -> list[int]:
    return [k for k in range(-decades, decades + 1) if not quick or k % 4 == 0]


def sweep(pid: str, decades: int, quick: bool = False) -> list[dict]:
    problem = load_problem(problem_path(pid, ROOT))
    rows = []
    for name in problem.systems:
        analysis = Analysis(problem)
        row = {"problem": pid, "system": name, "dof": 0, "worst_relative_error": 0.0,
               "at": "", "false_zeros": 0, "false_nonzeros": 0, "note": ""}
        skipped = dict(row, worst_relative_error=np.nan,
                       note=f"skipped (--quick): its closed forms take more than "
                            f"{QUICK_SECONDS:g} s to derive")
        start = cpu_time()
        try:
            with hard_time_limit(QUICK_SECONDS if quick else 0):  # 0: no limit
                point = analysis.default_point(name)
                lin = analysis.linear(name, point)
                freqs = list(lin.frequencies)
        except (UnsupportedError, MechbookError, ValueError, TypeError):
            # the engine turns a time limit it meets into "unsupported": ours, if it ran out
            if quick and cpu_time() - start >= 0.95 * QUICK_SECONDS:
                rows.append(skipped)
            continue
        except Timeout:
            rows.append(skipped)
            continue
        base = problem.values()
        row["dof"] = len(lin.q)
        try:
            lin.numeric_frequencies(base)
        except MechbookError as exc:  # no normal frequencies at this point at all
            rows.append(dict(row, worst_relative_error=np.nan, note=f"n.a.: {exc}"))
            continue
        symbols = sorted(set().union(*(f.free_symbols for f in freqs)) | set(base),
                         key=lambda s: s.name)
        fn = closed_forms(freqs, symbols)
        for sym in base:
            for k in ratios(decades, quick):
                values = dict(base)
                values[sym] = base[sym] * 10.0**k
                ref = reference(fn, symbols, values)
                if np.any(~np.isfinite(ref)):
                    continue  # the point is unstable at this ratio: no real frequencies
                try:
                    got = np.sort(lin.numeric_frequencies(values))
                except (np.linalg.LinAlgError, ValueError, MechbookError):
                    got = np.full_like(ref, np.nan)
                scale = max(float(np.max(np.abs(ref))), 1e-300)
                err = np.abs(got - ref) / np.maximum(np.abs(ref), 1e-300)
                err = np.where(ref == 0, np.abs(got) / scale, err)
                row["false_zeros"] += int(np.sum((got == 0) & (ref != 0)))
                row["false_nonzeros"] += int(np.sum((got != 0) & (ref == 0)))
                e = float(np.nanmax(err)) if np.all(np.isfinite(got)) else np.inf
                if e > row["worst_relative_error"]:
                    row["worst_relative_error"], row["at"] = e, f"{sym}x1e{k}"
        rows.append(row)
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("ids", nargs="*")
    parser.add_argument("--decades", type=int, default=8)
    parser.add_argument("--quick", action="store_true",
                        help="ratios 10^k for k a multiple of 4 only")
    parser.add_argument("--csv", type=Path)
    args = parser.parse_args()
    rows = []
    ids = args.ids or all_ids(ROOT)
    start = time.perf_counter()
    for i, pid in enumerate(ids, 1):
        t = time.perf_counter()
        got = sweep(pid, args.decades, args.quick)
        rows += got
        worst = max((r["worst_relative_error"] for r in got if not r["note"]), default=None)
        false = sum(r["false_zeros"] + r["false_nonzeros"] for r in got)
        shown = ("no frequencies about a default point" if worst is None and not got else
                 f"worst {worst:.1e}" if worst is not None else "") + \
            (f", {false} false zero/nonzero" if false else "") + \
            "".join(f"; {r['system']} {r['note']}" for r in got if r["note"])
        print(f"[{i}/{len(ids)}] {pid} ({time.perf_counter() - t:.1f} s, "
              f"{time.perf_counter() - start:.0f} s in all): {shown}", file=sys.stderr,
              flush=True)
    table = pd.DataFrame(rows, columns=["problem", "system", "dof", "worst_relative_error",
                                        "at", "false_zeros", "false_nonzeros", "note"])
    print(table.to_string(index=False, float_format=lambda v: f"{v:.2e}"))
    done = table[table["note"] == ""]
    skipped = int(table["note"].str.startswith("skipped").sum())
    bad = done[(done["worst_relative_error"] > TOLERANCE) | (done["false_zeros"] > 0)
               | (done["false_nonzeros"] > 0)]
    names = ", ".join(bad["problem"] + ":" + bad["system"]) or "-"
    print(f"\n{len(done)} systems checked, {len(table) - len(done) - skipped} not "
          f"applicable, {skipped} skipped; "
          f"{len(done) - len(bad)} within {TOLERANCE:g} at every ratio with no false zero "
          f"or nonzero frequency; {len(bad)} not: {names}")
    if args.csv:
        table.to_csv(args.csv, index=False)


if __name__ == "__main__":
    main()
