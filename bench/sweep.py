"""Sweep speed and accuracy: 10⁶-point frequency sweeps, float64 against 30 digits.

    python bench/sweep.py [--points 1000000] [--samples 200] [--csv FILE]

For each case (a 2-degree-of-freedom problem without velocity terms, the 3-degree-of-freedom
gyroscopic one, the one-degree lim-2031 stability map) the grid is the square of
sqrt(POINTS) values per axis; `run_sweep` is timed as the command runs it (derive and
compile once, stacked eigensolvers in this process, then the 30-digit check at SAMPLES
points). Each backend of the compile layer is timed on the 2-degree case as well.
Prints one table (points per second of the evaluation, and the whole run's seconds).
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mechbook.app.sweep import make_spec, run_sweep  # noqa: E402
from mechbook.engine.linear_grid import parse_axis  # noqa: E402

CASES = [
    # (label, problem, quantity, axes (lo, hi per name), --about, backend)
    ("2 dof (double pendulum)", "lim-2036", "frequencies",
     {"l1": (0.5, 2.0), "l2": (0.5, 2.0)}, None, "llvm"),
    ("2 dof, symengine backend", "lim-2036", "frequencies",
     {"l1": (0.5, 2.0), "l2": (0.5, 2.0)}, None, "symengine"),
    ("2 dof, sympy backend", "lim-2036", "frequencies",
     {"l1": (0.5, 2.0), "l2": (0.5, 2.0)}, None, "sympy"),
    ("3 dof gyroscopic (crossed fields)", "lim-2037", "frequencies",
     {"B": (0.1, 6.0), "omega0": (0.5, 3.0)}, None, "llvm"),
    ("1 dof stability map (bead on hoop)", "lim-2031", "stability",
     {"omega": (0.5, 10.0), "b": (0.1, 1.0)}, {"theta": "pi"}, "llvm"),
]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--samples", type=int, default=200)
    ap.add_argument("--csv", type=Path, default=None)
    args = ap.parse_args()
    side = int(round(args.points ** 0.5))
    rows = []
    for label, pid, quantity, axes, about, backend in CASES:
        spec = make_spec(pid, ROOT, quantity,
                         [parse_axis(f"{k}={lo}:{hi}:{side}") for k, (lo, hi) in axes.items()],
                         about=about, backend=backend)
        t = time.perf_counter()
        result = run_sweep(spec, ROOT, samples=args.samples)
        total = time.perf_counter() - t
        a = result.attrs
        rows.append({"case": label, "problem": pid, "quantity": quantity, "backend": backend,
                     "points": a["points"], "modes": a["modes"],
                     "build_s": round(a["build_seconds"], 2),
                     "evaluate_s": round(a["evaluate_seconds"], 2),
                     "points_per_s": round(a["points_per_second"]),
                     "accuracy_samples": a["accuracy_samples"],
                     "max_rel_diff_30_digits": f"{a['max_rel_diff_float64_vs_30_digits']:.2e}",
                     "disagree": a["accuracy_disagreements"],
                     "ill_conditioned": a["ill_conditioned"],
                     "book": result.book.get("lines", [""])[0][:60],
                     "total_s": round(total, 2)})
        print(rows[-1], flush=True)
    cols = list(rows[0])
    print(" | ".join(cols))
    for r in rows:
        print(" | ".join(str(r[c]) for c in cols))
    if args.csv:
        with open(args.csv, "w", newline="") as fh:
            w = csv.DictWriter(fh, cols)
            w.writeheader()
            w.writerows(rows)


if __name__ == "__main__":
    main()
