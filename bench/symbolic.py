"""Symbolic cost per problem: mechbook's derivation against sympy.physics.mechanics.

For every system of every problem: the time to derive the equations of motion (mass matrix
and forcing) with and without simplification, the same derivation by
`sympy.physics.mechanics.LagrangesMethod` from the same Lagrangian (as a ratio), the size of
the results (operation count), and the time to linearize about the default equilibrium and
find the normal frequencies. Both derivations are checked to agree numerically, so the
ratio compares equal work. Prints a table; `--csv FILE` saves it. Never used to gate CI.

    python bench/symbolic.py [ID ...] [--repeat N] [--csv FILE]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import sympy as sp
from sympy.core.cache import clear_cache
from sympy.physics.mechanics import LagrangesMethod, dynamicsymbols, msubs

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mechbook.engine.analysis import Analysis  # noqa: E402
from mechbook.engine.lagrange import Dynamics  # noqa: E402
from mechbook.errors import MechbookError, UnsupportedError  # noqa: E402
from mechbook.model.catalog import all_ids, problem_path  # noqa: E402
from mechbook.model.problem import load_problem  # noqa: E402
from mechbook.model.system import system_of  # noqa: E402


def timed(fn, repeat: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeat):
        clear_cache()  # SymPy memoizes; every timing starts cold so the ratio is fair
        start = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times), out


def ours(system, simplify: bool):
    dyn = Dynamics(system, simplify)
    return dyn.mass_matrix, dyn.forcing


def theirs(system):
    """LagrangesMethod on the same L, with q(t) dynamic symbols."""
    funcs = [dynamicsymbols(q.name) for q in system.q]
    sub = {}
    for q, qd, f in zip(system.q, system.qd, funcs, strict=True):
        sub[qd] = f.diff(dynamicsymbols._t)
        sub[q] = f
    lag = system.lagrangian.subs(sub, simultaneous=True).subs(sp.Symbol("t", real=True),
                                                               dynamicsymbols._t)
    lm = LagrangesMethod(lag, funcs)  # systems with generalized forces are skipped
    lm.form_lagranges_equations()
    return lm.mass_matrix, lm.forcing, funcs


def agree(system, ours_mf, theirs_mf) -> float:
    """Largest relative difference of M⁻¹f between the two derivations at a random state."""
    (M1, f1), (M2, f2, funcs) = ours_mf, theirs_mf
    rng = np.random.default_rng(1)
    values = dict(system.problem.values())
    state = {}
    for q, qd, f in zip(system.q, system.qd, funcs, strict=True):
        a, b = rng.uniform(-0.5, 0.5, 2)
        values[q], values[qd] = a, b
        state[f.diff(dynamicsymbols._t)] = b
        state[f] = a
    t = rng.uniform(0, 1)
    values[system.t] = t
    def num(A, sub):
        return np.array(msubs(A, sub).evalf().tolist(), dtype=float)

    a1 = np.linalg.solve(num(M1, values), num(f1, values))
    sub2 = {**{k: v for k, v in values.items() if k not in system.q + system.qd}, **state}
    sub2[dynamicsymbols._t] = t
    a2 = np.linalg.solve(num(M2, sub2), num(f2, sub2))
    return float(np.max(np.abs(a1 - a2)) / max(1e-300, float(np.max(np.abs(a1)))))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("ids", nargs="*")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--csv", type=Path)
    args = parser.parse_args()
    rows = []
    for pid in args.ids or all_ids(ROOT):
        try:
            problem = load_problem(problem_path(pid, ROOT))
        except MechbookError as exc:
            print(f"{pid}: skipped ({exc})", file=sys.stderr)
            continue
        for name in problem.systems:
            system = system_of(problem, name)
            if system.constraints or system.free_driven or any(f != 0 for f in system.forces):
                continue  # LagrangesMethod comparison needs the plain Lagrangian form
            t_raw, mf_raw = timed(lambda s=system: ours(s, False), args.repeat)
            t_simp, mf_simp = timed(lambda s=system: ours(s, True), args.repeat)
            t_lm, mf_lm = timed(lambda s=system: theirs(s), args.repeat)
            analysis = Analysis(problem)
            clear_cache()
            start = time.perf_counter()
            try:
                point = analysis.default_point(name)
                lin = analysis.linear(name, point)
                lin.numeric_frequencies(problem.values())
                t_lin = time.perf_counter() - start
            except (UnsupportedError, ValueError, TypeError):
                t_lin = float("nan")
            rows.append({
                "problem": pid, "system": name, "dof": len(system.q),
                "eom_s": t_raw, "eom_simplified_s": t_simp, "lagranges_method_s": t_lm,
                "ratio_ours_to_LM": t_raw / t_lm,
                "ops_raw": int(sp.count_ops(mf_raw[1])), "ops_simplified":
                    int(sp.count_ops(mf_simp[1])), "ops_LM": int(sp.count_ops(mf_lm[1])),
                "small_oscillations_s": t_lin,
                "max_rel_diff_vs_LM": agree(system, mf_raw, mf_lm),
            })
    table = pd.DataFrame(rows)
    with pd.option_context("display.width", 200, "display.max_columns", 20):
        print(table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    if args.csv:
        table.to_csv(args.csv, index=False)


if __name__ == "__main__":
    main()
