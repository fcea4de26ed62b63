"""Simulation against a reference compiled loop on the same equations, in one run.

Every figure is a ratio measured in the same process, runs interleaved (A, B, A, B, ...),
process CPU time, median of --repeat rounds:

* the reference: C generated from the same M(q) and f(q, q̇) the engine gives (sympy.cse +
  ccode), the solve and the stepping loop written around it by hand and compiled with
  gcc -O2 as one file (everything inlined): the fastest loop these equations allow;
* one right-hand-side call (chains of 1 to 8 pendulums): mechbook's compiled kernel and
  solve called in a compiled loop (`mb_rhs_repeat`), the reference's, and mechbook's
  `Model.rhs` from Python (compiled, and the Python reference path it replaced);
* fixed steps (lim-2030, released at 1 rad, 10⁴ periods at h = T/20): leapfrog, yoshida4,
  RK4 through `integrate` (compiled loops) against the reference's loops; the Python loops
  (compiled=False) on a tenth of the span;
* DOP853 at rtol = atol = 1e-6 over 10³ periods: mechbook's compiled DOP853 against
  Fortran's dop853 (scipy.integrate.ode) calling the reference's compiled right-hand side,
  and solve_ivp with the compiled and the Python right-hand side;
* the Taylor method (heyoka, tol = machine epsilon) over 10⁴ periods: integration time,
  compile time (separately), energy error;
* the long-run table: every method over 10⁴ periods, ns per step, evaluations, energy error
  in the first and last tenth, seconds, compile seconds.

    python bench/compiled_steps.py [--repeat 3] [--csv DIR] [--quick]
"""

from __future__ import annotations

import argparse
import ctypes
import math
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import sympy as sp

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from rhs_backends import chain_problem, equations  # noqa: E402

from mechbook.engine.analysis import Analysis  # noqa: E402
from mechbook.model.catalog import problem_path  # noqa: E402
from mechbook.model.problem import load_problem  # noqa: E402
from mechbook.numerics import c_library  # noqa: E402
from mechbook.numerics.integrators import integrate  # noqa: E402
from mechbook.numerics.monitors import conserved_quantities, drifts  # noqa: E402
from mechbook.numerics.rhs import build_model  # noqa: E402
from mechbook.numerics.simulate import initial_state  # noqa: E402
from mechbook.numerics.stiffness import linear_rates  # noqa: E402

YOSHIDA_W1 = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))

REFERENCE_C = Path(__file__).with_name("reference_loop.c")


class Reference:
    """The reference compiled loop for one system (see the module docstring)."""

    def __init__(self, system, dyn, values):
        args, exprs = equations(system, dyn, values)
        n = len(dyn.q)
        names = [sp.Symbol(f"a{i}", real=True) for i in range(len(args))]
        exprs = [e.xreplace(dict(zip(args, names, strict=True))) for e in exprs]
        start = time.perf_counter()
        reps, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("c"))
        body = [f"    const double {a} = x[{i}];" for i, a in enumerate(names)]
        body += [f"    const double {s} = {sp.ccode(v)};" for s, v in reps]
        body += [f"    out[{i}] = {sp.ccode(e)};" for i, e in enumerate(reduced)]
        self.ops = int(sum(sp.count_ops(e) for e in reduced) + sum(sp.count_ops(v)
                                                                     for _, v in reps))
        tmp = Path(tempfile.mkdtemp(prefix="mechbook-ref-"))
        src, lib = tmp / "ref.c", tmp / "ref.so"
        src.write_text(REFERENCE_C.read_text().replace("@N@", str(n))
                       .replace("@BODY@", "\n".join(body)))
        subprocess.run(["gcc", "-O2", "-shared", "-fPIC", "-o", str(lib), str(src), "-lm"],
                       check=True)
        self.compile_seconds = time.perf_counter() - start
        so = ctypes.CDLL(str(lib))
        P, D, L, I = ctypes.c_void_p, ctypes.c_double, ctypes.c_long, ctypes.c_int  # noqa: E741
        so.ref_rhs.argtypes = [D, P, P]
        so.ref_rhs_repeat.argtypes = [D, P, P, L]
        so.ref_leapfrog.argtypes = [D, D, L, P, I, P, P]
        so.ref_rk4.argtypes = [D, D, L, P]
        for f in (so.ref_rhs, so.ref_rhs_repeat, so.ref_leapfrog, so.ref_rk4):
            f.restype = None
        self.so, self.n = so, n
        self._y, self._dy = np.zeros(2 * n), np.zeros(2 * n)

    def rhs(self, t, y):
        """The compiled right-hand side as a Python callable (for Fortran's dop853)."""
        self._y[:] = y
        self.so.ref_rhs(t, c_library.address(self._y), c_library.address(self._dy))
        return self._dy.copy()


def cpu(fn) -> float:
    start = time.process_time()
    fn()
    return time.process_time() - start


def interleaved(fns: dict, repeat: int) -> dict:
    """Median process time of each callable, run A, B, C, A, B, C, ..."""
    times = {k: [] for k in fns}
    for _ in range(repeat):
        for k, fn in fns.items():
            times[k].append(cpu(fn))
    return {k: statistics.median(v) for k, v in times.items()}


def load(pid: str, name: str | None = None, root: Path = ROOT):
    problem = load_problem(problem_path(pid, root))
    an = Analysis(problem)
    name = name or next(iter(problem.systems))
    return an, an.system(name), an.dynamics(name), problem.values()


# ---- one right-hand-side call --------------------------------------------------------------
def rhs_calls(repeat: int, sizes=(1, 2, 4, 8)) -> list[dict]:
    rows = []
    tmp = Path(tempfile.mkdtemp(prefix="mechbook-chains-"))
    for k in sizes:
        problem = load_problem(chain_problem(k, tmp))
        an = Analysis(problem)
        sys_, dyn = an.system(None), an.dynamics(None)
        values = problem.values()
        model = build_model(sys_, dyn, values)
        ref = Reference(sys_, dyn, values)
        nat = model.native
        y = np.full(2 * k, 0.1)
        ya, dya = y.copy(), np.zeros(2 * k)
        yb, dyb = y.copy(), np.zeros(2 * k)
        reps = 200_000 if k <= 4 else 50_000
        calls_py = 20_000

        def ours_loop(nat=nat, ya=ya, dya=dya, reps=reps):
            nat.lib.mb_rhs_repeat(nat.ptr, 0.0, c_library.address(ya), c_library.address(dya), reps)

        def ref_loop(ref=ref, yb=yb, dyb=dyb, reps=reps):
            ref.so.ref_rhs_repeat(0.0, c_library.address(yb), c_library.address(dyb), reps)

        def ours_python(model=model, y=y, calls=calls_py):
            for _ in range(calls):
                model.rhs(0.0, y)

        def before_python(model=model, y=y, calls=calls_py):
            for _ in range(calls):
                model.rhs_python(0.0, y)

        t = interleaved({"ours_loop": ours_loop, "ref_loop": ref_loop,
                         "ours_python": ours_python, "before_python": before_python}, repeat)
        row = {"dof": k, "operations": ref.ops,
               "compiled_call_us": t["ours_loop"] / reps * 1e6,
               "reference_call_us": t["ref_loop"] / reps * 1e6,
               "python_call_us": t["ours_python"] / calls_py * 1e6,
               "before_python_call_us": t["before_python"] / calls_py * 1e6}
        row["ratio_compiled"] = row["compiled_call_us"] / row["reference_call_us"]
        row["ratio_python"] = row["python_call_us"] / row["reference_call_us"]
        rows.append(row)
        print(f"rhs {k} dof: {row}", file=sys.stderr)
    return rows


# ---- the long run --------------------------------------------------------------------------
def energy_errors(model, traj) -> tuple[float, float, float]:
    d = next(x for x in drifts(model, traj) if x.name == "energy_function")
    dev = np.abs(d.values - d.initial) / d.scale
    tenth = max(1, len(dev) // 10)
    return float(dev[:tenth].max()), float(dev[-tenth:].max()), float(dev[-1])


def long_runs(repeat: int, quick: bool) -> tuple[list[dict], dict]:
    an, sys_, dyn, values = load("lim-2030", "main")
    model = build_model(sys_, dyn, values, conserved_quantities(sys_, dyn))
    q0, qd0, _ = initial_state(an, "main", {"theta": "1"}, values)
    rates = linear_rates(model, 0.0, np.zeros(1), np.zeros(1))
    T = rates.period
    periods = 1000 if quick else 10_000
    t_end = periods * T
    grid = np.arange(periods + 1) * T
    grid[-1] = t_end
    ref = Reference(sys_, dyn, values)
    h = T / 20
    steps = int(round(t_end / h))
    rows = []
    info = {"period": T, "periods": periods, "reference_compile_s": ref.compile_seconds,
            "loops_build_s": c_library.build_seconds()}

    def run(method, **opts):
        return integrate(model, (0.0, t_end), q0, qd0, method, t_eval=grid, **opts)

    # fixed steps: compiled loop vs the reference loop vs the Python loop (a tenth)
    for method, weights in (("leapfrog", (1.0,)),
                            ("yoshida4", (YOSHIDA_W1, 1 - 2 * YOSHIDA_W1, YOSHIDA_W1)),
                            ("RK4", None)):
        w = np.array(weights or [1.0])
        short = max(1, steps // 10)

        def ref_run(w=w, method=method):
            q, v = q0.copy(), qd0.copy()
            if method == "RK4":
                y = np.concatenate((q, v))
                ref.so.ref_rk4(0.0, h, steps, c_library.address(y))
            else:
                ref.so.ref_leapfrog(0.0, h, steps, c_library.address(w), len(w),
                                    c_library.address(q), c_library.address(v))

        def python_run(method=method, short=short):
            integrate(model, (0.0, short * h), q0, qd0, method, step=h, compiled=False,
                      t_eval=[short * h])

        t = interleaved({"ours": lambda method=method: run(method, step=h), "ref": ref_run,
                         "python": python_run}, repeat)
        traj = run(method, step=h)
        first, last, final = energy_errors(model, traj)
        rows.append({"method": method, "setting": "h = T/20", "steps": steps,
                     "evals": traj.nfev, "seconds": t["ours"],
                     "ns_per_step": t["ours"] / steps * 1e9,
                     "reference_ns_per_step": t["ref"] / steps * 1e9,
                     "ratio_to_reference": t["ours"] / t["ref"],
                     "python_ns_per_step": t["python"] / short * 1e9,
                     "energy_first_tenth": first, "energy_last_tenth": last,
                     "energy_final": final, "compile_s": 0.0})
        print(f"long {method}: {rows[-1]}", file=sys.stderr)

    # the implicit midpoint rule: compiled against the Python loop (no reference loop)
    short = max(1, steps // 20)
    t = interleaved({"ours": lambda: run("midpoint", step=h),
                     "python": lambda: integrate(model, (0.0, short * h), q0, qd0, "midpoint",
                                                 step=h, compiled=False, t_eval=[short * h])},
                    repeat)
    traj = run("midpoint", step=h)
    first, last, final = energy_errors(model, traj)
    rows.append({"method": "midpoint", "setting": "h = T/20", "steps": steps,
                 "evals": traj.nfev, "seconds": t["ours"], "ns_per_step": t["ours"] / steps * 1e9,
                 "reference_ns_per_step": math.nan, "ratio_to_reference": math.nan,
                 "python_ns_per_step": t["python"] / short * 1e9,
                 "energy_first_tenth": first, "energy_last_tenth": last,
                 "energy_final": final, "compile_s": 0.0})
    print(f"long midpoint: {rows[-1]}", file=sys.stderr)

    # DOP853 at 1e-6: compiled loop vs Fortran dop853 with the reference's compiled RHS
    from scipy.integrate import ode, solve_ivp

    span = (1000 if not quick else 100) * T
    y0 = np.concatenate((q0, qd0))
    counter = {"n": 0}

    def fortran():
        counter["n"] = 0

        def f(t, y):
            counter["n"] += 1
            return ref.rhs(t, y)

        r = ode(f).set_integrator("dop853", rtol=1e-6, atol=1e-6, nsteps=10**9)
        r.set_initial_value(y0, 0.0)
        r.integrate(span)

    def ours_dop():
        integrate(model, (0.0, span), q0, qd0, "DOP853", rtol=1e-6, atol=1e-6,
                  t_eval=[span])

    def ivp_compiled_rhs():
        solve_ivp(model.rhs, (0.0, span), y0, method="DOP853", rtol=1e-6, atol=1e-6,
                  t_eval=[span])

    def ivp_python_rhs():
        solve_ivp(model.rhs_python, (0.0, span / 10), y0, method="DOP853", rtol=1e-6,
                  atol=1e-6, t_eval=[span / 10])

    t = interleaved({"ours": ours_dop, "fortran": fortran, "ivp": ivp_compiled_rhs,
                     "ivp_before": ivp_python_rhs}, repeat)
    fortran()
    nf = counter["n"]
    ev_ours = integrate(model, (0.0, span), q0, qd0, "DOP853", rtol=1e-6, atol=1e-6,
                        t_eval=[span]).nfev
    ev_ivp = solve_ivp(model.rhs, (0.0, span), y0, method="DOP853", rtol=1e-6,
                       atol=1e-6, t_eval=[span]).nfev
    ev_before = solve_ivp(model.rhs_python, (0.0, span / 10), y0, method="DOP853",
                          rtol=1e-6, atol=1e-6, t_eval=[span / 10]).nfev
    info["dop853"] = {"periods": span / T, "ours_us_per_eval": t["ours"] / ev_ours * 1e6,
                      "fortran_us_per_eval": t["fortran"] / nf * 1e6,
                      "ratio": (t["ours"] / ev_ours) / (t["fortran"] / nf),
                      "solve_ivp_compiled_rhs_us_per_eval": t["ivp"] / ev_ivp * 1e6,
                      "solve_ivp_python_rhs_us_per_eval": t["ivp_before"] / ev_before * 1e6,
                      "evals_ours": ev_ours, "evals_fortran": nf}
    print(f"dop853: {info['dop853']}", file=sys.stderr)

    # adaptive methods over the long run (compiled DOP853/RK45), and Taylor
    for method, opts, label in (("RK45", {"rtol": 1e-6, "atol": 1e-6}, "rtol = atol = 1e-6"),
                                ("DOP853", {"rtol": 1e-6, "atol": 1e-6}, "rtol = atol = 1e-6"),
                                ("DOP853", {"rtol": 1e-12, "atol": 1e-12},
                                 "rtol = atol = 1e-12")):
        t = interleaved({"ours": lambda method=method, opts=opts: run(method, **opts)},
                        repeat)
        traj = run(method, **opts)
        first, last, final = energy_errors(model, traj)
        rows.append({"method": method, "setting": label, "steps": math.nan,
                     "evals": traj.nfev, "seconds": t["ours"],
                     "ns_per_step": math.nan, "reference_ns_per_step": math.nan,
                     "ratio_to_reference": math.nan, "python_ns_per_step": math.nan,
                     "energy_first_tenth": first, "energy_last_tenth": last,
                     "energy_final": final, "compile_s": 0.0})
        print(f"long {method}: {rows[-1]}", file=sys.stderr)
    try:
        from mechbook.numerics import taylor
    except ImportError:
        return rows, info
    if taylor.available():
        fresh = build_model(sys_, dyn, values, conserved_quantities(sys_, dyn))
        start = time.process_time()
        taylor.integrator(fresh, taylor.DEFAULT_TOL, key="plain")
        compile_s = time.process_time() - start
        t = interleaved({"ours": lambda: integrate(fresh, (0.0, t_end), q0, qd0, "taylor",
                                                   t_eval=grid)}, repeat)
        traj = integrate(fresh, (0.0, t_end), q0, qd0, "taylor", t_eval=grid)
        first, last, final = energy_errors(fresh, traj)
        steps_t = traj.settings["steps"]
        rows.append({"method": "taylor", "setting": "tol = 2.2e-16 (order "
                     f"{taylor.integrator(fresh, taylor.DEFAULT_TOL, key='plain').order})",
                     "steps": steps_t, "evals": math.nan, "seconds": t["ours"],
                     "ns_per_step": t["ours"] / steps_t * 1e9, "reference_ns_per_step": math.nan,
                     "ratio_to_reference": math.nan, "python_ns_per_step": math.nan,
                     "energy_first_tenth": first, "energy_last_tenth": last,
                     "energy_final": final, "compile_s": compile_s})
        print(f"long taylor: {rows[-1]}", file=sys.stderr)
    return rows, info


# ---- a sweep of a trajectory quantity: frequency against amplitude -------------------------
def amplitude_sweep(repeat: int, count: int = 64) -> dict:
    """lim-2030's frequency at `count` amplitudes (0.01 to 2.5 rad): DOP853 one amplitude
    at a time (crosscheck.amplitude) against one Taylor batch run, and their agreement."""
    from mechbook.crosscheck.amplitude import amplitude_response
    from mechbook.numerics import taylor

    an, sys_, dyn, values = load("lim-2030", "main")
    lin = an.linear("main", {sys_.q[0]: 0})
    amps = np.linspace(0.01, 2.5, count)
    models: dict = {}
    amplitude_response(an, lin, values, amps[:1], models)  # the model, compiled once
    if not taylor.available():
        return {}
    start = time.process_time()
    amplitude_response(an, lin, values, amps[:1], models, method="taylor")
    first = time.process_time() - start  # heyoka import and the batch integrator's compile
    out = {}

    def dop():
        out["dop"] = amplitude_response(an, lin, values, amps, models)[1]

    def tay():
        out["taylor"] = amplitude_response(an, lin, values, amps, models, method="taylor")[1]

    t = interleaved({"dop": dop, "taylor": tay}, repeat)
    return {"amplitudes": count, "dop853_s": t["dop"], "taylor_batch_s": t["taylor"],
            "ratio": t["dop"] / t["taylor"], "taylor_first_call_s": first,
            "max_relative_difference": float(np.nanmax(np.abs(out["dop"] / out["taylor"] - 1)))}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="10³ periods, two chain sizes")
    ap.add_argument("--csv", type=Path, default=None, help="directory for the CSV tables")
    opts = ap.parse_args()
    import pandas as pd

    if c_library.library() is None:
        sys.exit(f"no compiled loops: {c_library.why()}")
    began = time.perf_counter()
    calls = pd.DataFrame(rhs_calls(opts.repeat, (1, 4) if opts.quick else (1, 2, 4, 8)))
    rows, info = long_runs(opts.repeat, opts.quick)
    sweep = amplitude_sweep(opts.repeat, 16 if opts.quick else 64)
    runs = pd.DataFrame(rows)
    print(f"# {platform.machine()}, {os.cpu_count()} cores, Python "
          f"{platform.python_version()}, process CPU time, median of {opts.repeat} "
          f"interleaved rounds, {time.perf_counter() - began:.0f} s")
    with pd.option_context("display.width", 250, "display.max_columns", 30):
        print("\n== one right-hand-side call (µs)")
        print(calls.to_string(index=False, float_format="{:.3g}".format))
        print(f"\n== long runs: lim-2030 from 1 rad, {info['periods']} periods of "
              f"T = {info['period']:.4g}")
        print(runs.to_string(index=False, float_format="{:.3g}".format))
        print("\n== DOP853 at rtol = atol = 1e-6")
        for k, v in info["dop853"].items():
            print(f"  {k}: {v:.4g}")
        print("\n== frequency against amplitude (a sweep of a trajectory quantity)")
        for k, v in sweep.items():
            print(f"  {k}: {v:.4g}")
        print(f"\nreference compile (sympy cse + gcc): {info['reference_compile_s']:.3f} s; "
              f"loops.c build this process: {info['loops_build_s']:.3f} s (0: cached)")
    if opts.csv:
        opts.csv.mkdir(parents=True, exist_ok=True)
        calls.to_csv(opts.csv / "rhs_calls.csv", index=False)
        runs.to_csv(opts.csv / "long_runs.csv", index=False)
        pd.DataFrame([info["dop853"]]).to_csv(opts.csv / "dop853.csv", index=False)


if __name__ == "__main__":
    main()
