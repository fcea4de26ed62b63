"""Which way of turning the symbolic equations of motion into a numeric RHS is fastest?

For every system of every problem (and synthetic chains of N pendulums, whose expressions
grow quickly with N), the same expressions — mass matrix and forcing, M q̈ = f, at the
default parameter values — are compiled by each backend:

    sympy-math   SymPy lambdify(cse=True), `math` module (scalar calls)
    sympy-numpy  SymPy lambdify(cse=True), `numpy` module
    symengine    SymEngine Lambdify(cse=True), interpreted ("lambda") backend
    llvm         SymEngine Lambdify(cse=True), LLVM JIT-compiled
    gcc          sympy.cse + ccode, compiled by gcc -O2 into a shared library, ctypes call

and timed: generation (cold SymPy cache, median of --repeat), one raw call of the compiled
function, and a whole DOP853 integration (rtol 1e-10, 5 time units, from q = 0.1, at most
100,000 evaluations: a run into a singularity is cut and shown as NaN) through mechbook's
Model wrapper — what `mechbook simulate` and the cross-check pay. Every backend must give
the same accelerations (checked to 1e-9: column `agrees`); `solved` is False where the run
from q = 0.1 reaches a singular configuration (then backends part ways only there).
Prints a table; `--csv FILE` saves it. Timings are machine-dependent and never gate CI.

    python bench/rhs_backends.py [ID ...] [--chains 2,4,6] [--repeat N] [--csv FILE]
"""

from __future__ import annotations

import argparse
import ctypes
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
import sympy as sp
from scipy.integrate import solve_ivp
from sympy.core.cache import clear_cache

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mechbook.core import compile as rhsmod  # noqa: E402
from mechbook.engine.analysis import Analysis  # noqa: E402
from mechbook.errors import MechbookError  # noqa: E402
from mechbook.model.catalog import all_ids, problem_path  # noqa: E402
from mechbook.model.problem import load_problem  # noqa: E402
from mechbook.numerics.rhs import Model, timed_calls  # noqa: E402

BACKENDS = ("sympy-math", "sympy-numpy", "symengine", "llvm", "gcc")
SPAN = 5.0  # time units integrated
BUDGET = 100_000  # RHS evaluations before a run (a trajectory into a singularity) is cut


class _Budget(Exception):
    pass


def _budget(f):
    calls = [0]

    def wrapped(t, y):
        calls[0] += 1
        if calls[0] > BUDGET:
            raise _Budget
        return f(t, y)

    return wrapped


def compile_gcc(args, exprs):
    """C via sympy.cse + ccode, gcc -O2 -shared, called through ctypes on fixed buffers."""
    names = [sp.Symbol(f"a{i}", real=True) for i in range(len(args))]
    exprs = [e.xreplace(dict(zip(args, names, strict=True))) for e in exprs]
    reps, reduced = sp.cse(exprs)
    lines = ["#include <math.h>", "void rhs(const double *x, double *out) {"]
    lines += [f"  const double {a} = x[{i}];" for i, a in enumerate(names)]
    lines += [f"  const double {s} = {sp.ccode(v)};" for s, v in reps]
    lines += [f"  out[{i}] = {sp.ccode(e)};" for i, e in enumerate(reduced)]
    lines.append("}")
    tmp = Path(tempfile.mkdtemp(prefix="mechbook-bench-"))
    src, lib = tmp / "rhs.c", tmp / "rhs.so"
    src.write_text("\n".join(lines) + "\n")
    subprocess.run(["gcc", "-O2", "-shared", "-fPIC", "-o", str(lib), str(src), "-lm"],
                   check=True)
    so = ctypes.CDLL(str(lib))
    so.rhs.restype = None
    out = np.zeros(len(exprs))
    pout = out.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
    fn = so.rhs

    def call(x: np.ndarray) -> np.ndarray:
        x = np.ascontiguousarray(x, dtype=float)
        fn(x.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), pout)
        return out.copy()

    return call


def compile_with(name: str, args, exprs):
    if name == "sympy-math":
        return rhsmod._compile_sympy(args, exprs)
    if name == "sympy-numpy":
        fn = sp.lambdify(args, exprs, modules="numpy", cse=True)
        return lambda x: np.array(fn(*x), dtype=float)
    if name == "symengine":
        return rhsmod._compile_symengine(args, exprs, "lambda")
    if name == "llvm":
        return rhsmod._compile_symengine(args, exprs, "llvm")
    return compile_gcc(args, exprs)


def equations(system, dyn, values):
    """The flat list [M..., f...] of `build_model`, and its arguments."""
    sub = {k: sp.Float(float(v), 17) for k, v in values.items()}
    residuals = [e.xreplace(sub) for e in dyn.residuals]
    zero = {a: 0 for a in dyn.qdd}
    M = [sp.diff(e, a) for e in residuals for a in dyn.qdd]
    f = [-e.xreplace(zero) for e in residuals]
    return [system.t] + list(dyn.q) + list(dyn.qd), M + f


def chain_problem(n: int, tmp: Path) -> Path:
    """A planar chain of n equal pendulums (lim-9NNN), written to a temporary tree."""
    xs, ys, parts = [], [], []
    for i in range(1, n + 1):
        xs.append(f"l*sin(th{i})")
        ys.append(f"l*cos(th{i})")
        parts.append(f"  b{i}: {{mass: m, position: [{' + '.join(xs)}, -({' + '.join(ys)})]}}")
    coords = "\n".join(f"  th{i}: {{}}" for i in range(1, n + 1))
    text = (f"id: lim-{9000 + n}\nsource: bench\ntitle: chain of {n} pendulums\n"
            "parameters:\n  m: {value: 0.3}\n  l: {value: 0.5}\n  g: {}\n"
            f"coordinates:\n{coords}\nparticles:\n" + "\n".join(parts) + "\ngravity: {}\n")
    d = tmp / "problems" / "lim"
    d.mkdir(parents=True, exist_ok=True)
    path = d / f"{9000 + n}.yaml"
    path.write_text(text)
    return path


def bench_system(label: str, system, dyn, values, repeat: int) -> list[dict]:
    args, exprs = equations(system, dyn, values)
    n = len(dyn.q)
    x = np.concatenate(([0.1], np.full(n, 0.2), np.full(n, 0.1)))
    ops = int(sp.count_ops(exprs))
    rows, reference = [], None
    for name in BACKENDS:
        gen = []
        for _ in range(repeat):
            clear_cache()
            start = time.perf_counter()
            fn = compile_with(name, args, exprs)
            gen.append(time.perf_counter() - start)
        call = timed_calls(lambda fn=fn: fn(x))
        model = Model(list(system.coord_names), n, name, 0.0, fn, lambda: None, None, [])
        acc = model.accelerations(0.1, x[1:n + 1], x[n + 1:])
        if reference is None:
            reference = acc
        agree = bool(np.allclose(acc, reference, rtol=1e-9, atol=1e-12))
        y0 = np.concatenate((np.full(n, 0.1), np.zeros(n)))
        start = time.perf_counter()
        try:
            sol = solve_ivp(_budget(model.rhs), (0, SPAN), y0, method="DOP853", rtol=1e-10,
                            atol=1e-12)
        except _Budget:
            rows.append({"system": label, "n": n, "ops": ops, "backend": name,
                         "generate_ms": 1e3 * statistics.median(gen), "call_us": 1e6 * call,
                         "nfev": BUDGET, "solve_ms": float("nan"), "total_ms": float("nan"),
                         "agrees": agree, "solved": False})
            continue
        solve_s = time.perf_counter() - start
        rows.append({"system": label, "n": n, "ops": ops, "backend": name,
                     "generate_ms": 1e3 * statistics.median(gen), "call_us": 1e6 * call,
                     "nfev": sol.nfev, "solve_ms": 1e3 * solve_s,
                     "total_ms": 1e3 * (statistics.median(gen) + solve_s),
                     "agrees": agree, "solved": bool(sol.success)})
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("ids", nargs="*")
    ap.add_argument("--chains", default="2,4,6", help="pendulum chains to add ('' for none)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--csv", default=None)
    opts = ap.parse_args()
    os.environ.setdefault("SYMENGINE_LAMBDIFY_BACKEND", "llvm")
    rows: list[dict] = []
    jobs = []
    for pid in opts.ids or all_ids(ROOT):
        try:
            problem = load_problem(problem_path(pid, ROOT))
        except MechbookError as exc:
            print(f"{pid}: skipped ({exc})", file=sys.stderr)
            continue
        jobs += [(f"{pid}/{s}" if len(problem.systems) > 1 else pid, problem, s)
                 for s in problem.systems]
    tmp = Path(tempfile.mkdtemp(prefix="mechbook-chains-"))
    for k in [int(c) for c in opts.chains.split(",") if c]:
        problem = load_problem(chain_problem(k, tmp))
        jobs.append((f"chain-{k}", problem, "main"))
    for label, problem, sname in jobs:
        analysis = Analysis(problem, simplify=False)
        try:
            system = analysis.system(sname)
            if system.free_driven or system.constraints:
                continue
            dyn = analysis.dynamics(sname)
            rows += bench_system(label, system, dyn, problem.values(), opts.repeat)
        except (MechbookError, ValueError, np.linalg.LinAlgError) as exc:
            print(f"{label}: skipped ({exc})", file=sys.stderr)
            continue
        print(f"{label}: done", file=sys.stderr)
        sys.stderr.flush()
    df = pd.DataFrame(rows)
    pd.set_option("display.width", 200)
    pd.set_option("display.max_rows", 500)
    print(df.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    summary = df.groupby("backend")[["generate_ms", "call_us", "solve_ms", "total_ms"]]
    print("\nmedian over systems:")
    print(summary.median().round(3).to_string())
    print("\nsum over systems:")
    print(summary.sum().round(1).to_string())
    if not df["agrees"].all():
        print("\nDISAGREEMENT:", df[~df["agrees"]][["system", "backend"]].to_string())
    if opts.csv:
        df.to_csv(opts.csv, index=False)


if __name__ == "__main__":
    main()
