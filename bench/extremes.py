"""Numerical stability of the normal frequencies at extreme parameter ratios.

For every problem with a small-oscillation result about its default equilibrium, each
parameter is scaled by 10^k (k = -8 … 8) in turn, and the engine's numeric frequencies
(`LinearSystem.numeric_frequencies`, the path `mechbook check` uses) are compared with the
closed-form frequencies evaluated with 50-digit mpmath arithmetic (their size: a closed form
such as sqrt(k/m) - omega changes sign as a parameter grows). Reports the worst
relative error per problem (and where it occurs). Never used to gate CI.

    python bench/extremes.py [ID ...] [--decades 8] [--csv FILE]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import sympy as sp

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mechbook.engine.analysis import Analysis  # noqa: E402
from mechbook.errors import MechbookError, UnsupportedError  # noqa: E402
from mechbook.model.catalog import all_ids, problem_path  # noqa: E402
from mechbook.model.problem import load_problem  # noqa: E402


def reference(freqs: list[sp.Expr], values: dict) -> np.ndarray:
    exact = {k: sp.Rational(v) for k, v in values.items()}  # no 15-digit Floats inside
    out = []
    for f in freqs:
        z = complex(sp.N(f.subs(exact), 50))
        # a closed form may be signed (sqrt(k/m) - omega in a rotating frame): the
        # frequency is its size, as numeric_frequencies returns it
        out.append(abs(z.real) if abs(z.imag) <= 1e-30 * max(1, abs(z)) else np.nan)
    return np.sort(np.array(out))


def sweep(pid: str, decades: int) -> list[dict]:
    problem = load_problem(problem_path(pid, ROOT))
    rows = []
    for name in problem.systems:
        analysis = Analysis(problem)
        try:
            point = analysis.default_point(name)
            lin = analysis.linear(name, point)
            freqs = list(lin.frequencies)
        except (UnsupportedError, MechbookError, ValueError, TypeError):
            continue
        base = problem.values()
        worst, where = 0.0, ""
        for sym in base:
            for k in range(-decades, decades + 1):
                values = dict(base)
                values[sym] = base[sym] * 10.0**k
                ref = reference(freqs, values)
                if np.any(~np.isfinite(ref)):
                    continue  # the point is unstable at this ratio: no real frequencies
                try:
                    got = np.sort(lin.numeric_frequencies(values))
                except (np.linalg.LinAlgError, ValueError):
                    got = np.full_like(ref, np.nan)
                scale = max(float(np.max(np.abs(ref))), 1e-300)
                err = np.abs(got - ref) / np.maximum(np.abs(ref), 1e-300)
                err = np.where(ref == 0, np.abs(got) / scale, err)
                e = float(np.nanmax(err)) if np.all(np.isfinite(got)) else np.inf
                if e > worst:
                    worst, where = e, f"{sym}x1e{k}"
        rows.append({"problem": pid, "system": name, "dof": len(lin.q),
                     "worst_relative_error": worst, "at": where})
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("ids", nargs="*")
    parser.add_argument("--decades", type=int, default=8)
    parser.add_argument("--csv", type=Path)
    args = parser.parse_args()
    rows = []
    for pid in args.ids or all_ids(ROOT):
        rows += sweep(pid, args.decades)
    table = pd.DataFrame(rows)
    print(table.to_string(index=False, float_format=lambda v: f"{v:.2e}"))
    if args.csv:
        table.to_csv(args.csv, index=False)


if __name__ == "__main__":
    main()
