"""Work–precision of every integrator on every problem that can be simulated.

For each system of each problem that `mechbook simulate` can start (initial conditions from
the problem's `initial:`, or its fallback: at rest 0.1 from the first stable equilibrium;
the others are listed with the reason they were skipped), over BENCH_PERIODS periods of
the slowest linear mode (rates from the Jacobian at the start, `simulate/stiffness.py`):

* a reference solution, DOP853 at rtol 1e-13, atol 1e-15; on a few small problems that
  reference is itself checked against mpmath's Taylor-series `odefun` at 20 digits, and on
  the linear autonomous ones against the closed form exp(At)·y0 at 30 digits;
* each adaptive SciPy method (RK45, DOP853, Radau, LSODA) at rtol = atol = 1e-3 … 1e-12,
  and each fixed-step method that applies (RK4; leapfrog and yoshida4 for separable
  Hamiltonians; implicit midpoint for canonical ones, up to 512) at 8, 16, … 2048 steps per
  period of the fastest linear mode: the error at the end time (`accuracy.state_error`: the largest
  componentwise error relative to the component's scale), the wall time (median of 3 runs;
  one run when the first takes over 0.25 s, whose timing varies by a few per cent only),
  and the number of right-hand-side evaluations.
  A run is cut at 300,000 evaluations (recorded as over budget).

Then: the cheapest method and setting meeting 1e-3, 1e-6, 1e-9 and 1e-12 per problem (the
summary table, printed and saved as CSV), the accuracy rule of `mechbook simulate
--accuracy` derived from the data (printed, saved as results/bench/accuracy_rule.py) and
the committed rule re-checked against it; energy drift over 10⁴ periods of a pendulum
(lim-2030 released at 1 rad) for the symplectic methods, RK4 and RK45/DOP853 at modest
tolerances; a stiffness sweep (lim-2033, two pendulums coupled by a spring 1 … 10⁶ times
stiffer than gravity, started in and out of phase) with what `simulate` detects and
chooses; and cold against warm `mechbook check` times (results cached by content hash).

Writes results/bench.h5 (one group per table, one dataset per column; written to a
temporary file and renamed), results/bench/*.csv and a work–precision diagram per problem,
results/bench/<problem>.png (error against wall time, log–log, one line per method).
Timings depend on the machine and never gate anything.

    python bench/work_precision.py [--problems ID ...] [--quick] [--out FILE] [--figdir DIR]
                                   [--no-long] [--no-stiff] [--no-check]
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mechbook.core.timeout import Timeout, hard_time_limit  # noqa: E402
from mechbook.engine.analysis import Analysis  # noqa: E402
from mechbook.errors import MechbookError, UnsupportedError  # noqa: E402
from mechbook.model.catalog import all_ids, problem_path  # noqa: E402
from mechbook.model.problem import load_problem  # noqa: E402
from mechbook.numerics import accuracy  # noqa: E402
from mechbook.numerics.integrators import IntegratorError, integrate, make_integrator  # noqa: E402
from mechbook.numerics.monitors import conserved_quantities, drifts  # noqa: E402
from mechbook.numerics.rhs import build_model  # noqa: E402
from mechbook.numerics.simulate import initial_state  # noqa: E402
from mechbook.numerics.stiffness import IMPLICIT, assess, linear_rates  # noqa: E402

SCIPY = ("RK45", "DOP853", "Radau", "LSODA")
ADAPTIVE = (*SCIPY, "taylor")
FIXED = ("RK4", "leapfrog", "yoshida4", "midpoint")
TOLS = tuple(10.0 ** -k for k in range(3, 13))
TAYLOR_TOLS = tuple(10.0 ** -k for k in range(6, 17))  # heyoka: 1e-6 ... 1e-16
QUICK_TAYLOR_TOLS = (1e-6, 1e-10, 1e-13, 1e-16)
QUICK_TOLS = (1e-3, 1e-6, 1e-9, 1e-12)
STEPS = tuple(2 ** k for k in range(3, 12))  # steps per period of the fastest mode
QUICK_STEPS = (8, 32, 128, 512)
MIDPOINT_MAX = 512  # its Newton iteration makes finer rungs too slow for the budget
TARGETS = (1e-3, 1e-6, 1e-9, 1e-12, 1e-14)
RULE_TARGETS = tuple(10.0 ** -k for k in range(3, 15))
EXTENDED_TOL = 1e-30  # the float128 Taylor reference's tolerance
PERIODS = accuracy.BENCH_PERIODS
REFERENCE = {"rtol": 1e-13, "atol": 1e-15}
BUDGET = 300_000  # RHS evaluations per run
REPEAT, SLOW = 3, 0.25  # median of REPEAT runs; a single run once the first exceeds SLOW s
LADDER_STOP = 1.0  # a fixed-step ladder stops after a run this long (s)
SEARCH_LIMIT = 5.0  # seconds for finding a start (the stable-equilibrium search)
FLOOR = 1e-13  # errors below this are at the reference's own level: stop refining
MP_CHECK = ("lim-2030", "lim-2065", "symon-09-10")  # small problems checked with mpmath
LONG = {"pid": "lim-2030", "system": "main", "init": {"theta": "1"}, "periods": 10_000}
STIFF = {"pid": "lim-2033", "system": "main", "param": "k",
         "ratios": (1.0, 1e2, 1e3, 1e4, 1e5, 1e6), "excited_up_to": 1e4}
CHECK_PIDS = ("lim-2030", "lim-2031", "lim-2036")


class OverBudget(Exception):
    pass


class Budget(dict):
    """`Model.stats` that raises OverBudget once the evaluation count passes `limit`."""

    limit = math.inf

    def __setitem__(self, key, value):
        super().__setitem__(key, value)
        if key == "rhs_calls" and value > self.limit:
            raise OverBudget


@dataclass
class Case:
    label: str
    pid: str
    system: str
    model: object
    q0: np.ndarray
    qd0: np.ndarray
    source: str
    omega_min: float | None
    omega_max: float
    t_end: float
    applicable: dict = field(default_factory=dict)  # fixed method -> "" or why not
    scale: np.ndarray | None = None
    y_ref: np.ndarray | None = None
    ref_seconds: float = 0.0
    ref_evals: int = 0
    y_ref_dop853: np.ndarray | None = None  # DOP853 at 1e-13 (the reference without heyoka)
    reference: str = "DOP853 rtol 1e-13 atol 1e-15"


@dataclass
class Run:
    method: str
    setting: str
    tol: float
    steps_per_period: int
    error: float
    seconds: float
    evals: int
    repeats: int
    ok: bool
    message: str = ""
    compile_seconds: float = 0.0  # the Taylor integrator's first build at this tolerance


# ---- finding what can be simulated ---------------------------------------------------------
def discover(pids: list[str]) -> tuple[list[Case], list[dict]]:
    cases, skipped = [], []
    for pid in pids:
        try:
            problem = load_problem(problem_path(pid, ROOT))
        except MechbookError as exc:
            skipped.append({"problem": pid, "system": "", "reason": f"does not load: {exc}"})
            continue
        analysis = Analysis(problem)
        for name in problem.systems:
            label = f"{pid}/{name}" if len(problem.systems) > 1 else pid
            reason = ""
            started = time.perf_counter()
            try:
                system, dyn = analysis.system(name), analysis.dynamics(name)
                values = problem.values()
                if system.free_driven:
                    raise UnsupportedError("an arbitrary driven coordinate (no function of t)")
                with hard_time_limit(SEARCH_LIMIT):
                    q0, qd0, source = initial_state(analysis, name, {}, values)
                model = build_model(system, dyn, values, conserved_quantities(system, dyn))
            except Timeout:
                reason = (f"no `initial:` and no stable equilibrium found within "
                          f"{SEARCH_LIMIT:g} s")
            except UnsupportedError as exc:
                reason = f"unsupported: {exc.capability}"
            except (MechbookError, KeyError, ValueError, TypeError) as exc:
                reason = str(exc).replace(f"{pid}: ", "")
                if "no stable equilibrium" in reason:
                    reason = "no `initial:` and no stable equilibrium to start near"
                    if time.perf_counter() - started > SEARCH_LIMIT - 0.5:
                        reason += f" found within {SEARCH_LIMIT:g} s"
            if reason:
                skipped.append({"problem": pid, "system": name, "reason": reason})
                print(f"{label}: skipped ({reason})", file=sys.stderr)
                continue
            rates = linear_rates(model, 0.0, q0, qd0)
            if rates is None or not rates.omega_max:
                skipped.append({"problem": pid, "system": name,
                                "reason": "the linearized equations do not evaluate at the "
                                          "start (no time scale)"})
                continue
            period = rates.period or 2 * math.pi / rates.omega_max
            case = Case(label, pid, name, model, q0, qd0, source, rates.omega_min,
                        rates.omega_max, PERIODS * period)
            for m in FIXED:
                try:
                    make_integrator(m).check(model, 0.0, q0, qd0)
                    case.applicable[m] = ""
                except IntegratorError as exc:
                    case.applicable[m] = str(exc)
            cases.append(case)
    return cases, skipped


# ---- running -------------------------------------------------------------------------------
def end_state(traj) -> np.ndarray:
    return np.concatenate((traj.q[:, -1], traj.qd[:, -1]))


def run_once(case: Case, method: str, opts: dict, t_end: float | None = None):
    """(end state or None, seconds, evaluations, message)."""
    model = case.model
    t_end = case.t_end if t_end is None else t_end
    if not isinstance(model.stats, Budget):
        model.stats = Budget(model.stats)
    model.stats.limit = model.stats["rhs_calls"] + BUDGET
    calls = model.stats["rhs_calls"]
    t_eval = [t_end] if method in FIXED or method == "taylor" else None
    start = time.process_time()  # CPU time: the 2 cores are shared with other work
    y, message, steps = None, "", 0
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            traj = integrate(model, (0.0, t_end), case.q0, case.qd0, method, t_eval=t_eval,
                             **opts)
        if traj.success and len(traj.t) and abs(traj.t[-1] - t_end) <= 1e-9 * max(1, t_end):
            y = end_state(traj)
        else:
            message = traj.message or "stopped early"
        steps = int(traj.settings.get("steps", 0)) if method == "taylor" else 0
    except OverBudget:
        message = f"over budget ({BUDGET} evaluations)"
    except (IntegratorError, np.linalg.LinAlgError, ValueError, UnsupportedError) as exc:
        message = str(exc)
    seconds = time.process_time() - start
    model.stats.limit = math.inf
    # the Taylor method counts steps (each a Taylor expansion of order ~ -log tol / 2)
    return y, seconds, steps or model.stats["rhs_calls"] - calls, message


def measure(case: Case, method: str, opts: dict, setting: str, tol: float = math.nan,
            per_period: int = 0, repeat: int = REPEAT) -> Run:
    y, seconds, evals, message = run_once(case, method, opts)
    times = [seconds]
    if y is not None and seconds < SLOW:
        times += [run_once(case, method, opts)[1] for _ in range(repeat - 1)]
    error = accuracy.state_error(y, case.y_ref, case.scale) if y is not None else math.inf
    return Run(method, setting, tol, per_period, error, statistics.median(times), evals,
               len(times), y is not None and math.isfinite(error), message)


def reference(case: Case) -> str:
    """Fill in the reference solution; '' or why it failed."""
    samples = np.linspace(0.0, case.t_end, 201)
    start = time.perf_counter()
    calls = case.model.stats["rhs_calls"]
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        traj = integrate(case.model, (0.0, case.t_end), case.q0, case.qd0, "DOP853",
                         t_eval=samples, **REFERENCE)
    case.ref_seconds = time.perf_counter() - start
    case.ref_evals = case.model.stats["rhs_calls"] - calls
    if not traj.success or len(traj.t) != len(samples) or not np.all(np.isfinite(traj.y)):
        return f"the reference run failed: {traj.message}"
    case.y_ref = case.y_ref_dop853 = end_state(traj)
    case.scale = accuracy.scales(traj.y)
    extended = extended_reference(case)
    if extended is not None:
        case.y_ref = extended
        case.reference = f"heyoka Taylor, float128, tol {EXTENDED_TOL:.0e}"
    return ""


def extended_reference(case: Case) -> np.ndarray | None:
    """The end state by heyoka's Taylor method in quadruple precision (float128, ~34
    digits) on the same double-precision equations, or None where heyoka or its float128
    is missing or the system does not translate."""
    from mechbook.numerics import taylor

    if not taylor.available():
        return None
    import heyoka as hy

    if not hasattr(hy, "real128"):
        return None
    try:
        start = time.perf_counter()
        ta = taylor.integrator(case.model, EXTENDED_TOL, key="extended", fp_type=hy.real128)
        y0 = np.concatenate((case.q0, case.qd0))
        taylor.reset(ta, 0.0, np.array([hy.real128(float(v)) for v in y0], dtype=hy.real128))
        out = ta.propagate_until(hy.real128(case.t_end))
        if out[0] != hy.taylor_outcome.time_limit:
            return None
        case.ref_seconds += time.perf_counter() - start
        return np.array([float(v) for v in ta.state])
    except (UnsupportedError, ValueError, RuntimeError) as exc:
        print(f"{case.label}: no float128 reference ({exc})", file=sys.stderr)
        return None


def ladder(case: Case, quick: bool) -> list[Run]:
    runs: list[Run] = []
    repeat = 1 if quick else REPEAT
    for method in SCIPY:
        for tol in QUICK_TOLS if quick else TOLS:
            r = measure(case, method, {"rtol": tol, "atol": tol}, f"tol={tol:.0e}", tol,
                        repeat=repeat)
            runs.append(r)
            if r.message.startswith("over budget"):
                break  # tighter tolerances cost more still
    runs += taylor_ladder(case, quick, repeat)
    fast_period = 2 * math.pi / case.omega_max
    for method in FIXED:
        if case.applicable[method]:
            continue
        for n in QUICK_STEPS if quick else STEPS:
            if method == "midpoint" and n > MIDPOINT_MAX:
                break
            steps = max(1, math.ceil(case.t_end / (fast_period / n) - 1e-9))
            step = case.t_end / steps
            r = measure(case, method, {"step": step}, f"{n}/period (h={step:.3g})",
                        per_period=n, repeat=repeat)
            runs.append(r)
            if r.ok and (r.error < FLOOR or r.seconds > LADDER_STOP):
                break
            if r.message.startswith("over budget"):
                break
    return runs


def taylor_ladder(case: Case, quick: bool, repeat: int) -> list[Run]:
    """The Taylor method at tol 1e-6 ... 1e-16; the compile of each tolerance's integrator
    (a new order, new code) timed on its own before the timed runs."""
    from mechbook.numerics import taylor

    if not taylor.available():
        return []
    runs = []
    for tol in QUICK_TAYLOR_TOLS if quick else TAYLOR_TOLS:
        start = time.process_time()
        try:
            taylor.integrator(case.model, tol, key="plain")
        except (UnsupportedError, ValueError, RuntimeError) as exc:
            return [Run("taylor", "unsupported", tol, 0, math.inf, math.nan, 0, 0, False,
                        str(exc))]
        compile_s = time.process_time() - start
        r = measure(case, "taylor", {"tol": tol}, f"tol={tol:.0e}", tol, repeat=repeat)
        r.compile_seconds = compile_s
        runs.append(r)
    return runs


# ---- checking the reference ----------------------------------------------------------------
def mp_rhs(case: Case, dps: int):
    """y' = F(t, y) in mpmath arithmetic from the engine's M q̈ = f, parameters exact."""
    import mpmath as mp
    import sympy as sp

    problem = load_problem(problem_path(case.pid, ROOT))
    analysis = Analysis(problem)
    system, dyn = analysis.system(case.system), analysis.dynamics(case.system)
    exact = {k: sp.Rational(float(v)) for k, v in problem.values().items()}
    res = [e.xreplace(exact) for e in dyn.residuals]
    zero = {a: 0 for a in dyn.qdd}
    n = len(dyn.q)
    M = sp.Matrix(n, n, lambda i, j: sp.diff(res[i], dyn.qdd[j]))
    f = sp.Matrix([-e.xreplace(zero) for e in res])
    args = [system.t, *dyn.q, *dyn.qd]
    Mf = sp.lambdify(args, M, "mpmath")
    ff = sp.lambdify(args, f, "mpmath")
    mp.mp.dps = dps

    def F(t, y):
        a = mp.lu_solve(mp.matrix(Mf(t, *y)), mp.matrix(ff(t, *y)))
        return [*y[n:], *(a[i] for i in range(n))]

    return F, M, f, args, system, dyn


def linear_closed_form(case: Case) -> np.ndarray | None:
    """exp(A t)·y0 at 30 digits if the equations are linear, autonomous, homogeneous."""
    import mpmath as mp
    import sympy as sp

    F, M, f, args, system, dyn = mp_rhs(case, 30)
    y = [*dyn.q, *dyn.qd]
    if (M.free_symbols - {system.t}) or system.t in f.free_symbols:
        return None
    try:
        if any(sp.Poly(e, *y).total_degree() > 1 for e in f if e != 0):
            return None
    except sp.PolynomialError:
        return None
    if any(e.subs({v: 0 for v in y}) != 0 for e in f):
        return None
    n = len(dyn.q)
    Mi = M.inv()
    acc = Mi * f
    A = sp.zeros(2 * n, 2 * n)
    for i in range(n):
        A[i, n + i] = 1
        for j, v in enumerate(y):
            A[n + i, j] = sp.diff(acc[i], v)
    mp.mp.dps = 30
    Am = mp.matrix([[mp.mpf(sp.Rational(A[i, j])) if A[i, j].is_Rational
                     else mp.mpf(str(sp.N(A[i, j], 40))) for j in range(2 * n)]
                    for i in range(2 * n)])
    y0 = mp.matrix([mp.mpf(float(v)) for v in np.concatenate((case.q0, case.qd0))])
    out = mp.expm(Am * mp.mpf(case.t_end)) * y0
    return np.array([float(out[i]) for i in range(2 * n)])


def check_references(cases: list[Case]) -> list[dict]:
    import mpmath as mp

    rows = []
    for case in cases:
        if case.y_ref is None:
            continue
        how, exact = "", None
        start = time.perf_counter()
        try:
            exact = linear_closed_form(case)
            if exact is not None:
                how = "closed form exp(At)y0, 30 digits"
            elif case.pid in MP_CHECK:
                F = mp_rhs(case, 20)[0]
                sol = mp.odefun(F, 0, [mp.mpf(float(v)) for v in
                                       np.concatenate((case.q0, case.qd0))])
                exact = np.array([float(v) for v in sol(mp.mpf(case.t_end))])
                how = "mpmath odefun (Taylor series), 20 digits"
        except (MechbookError, ValueError, TypeError, ZeroDivisionError) as exc:
            how = f"failed: {exc}"
        finally:
            mp.mp.dps = 15
        if exact is None:
            continue
        rows.append({"problem": case.label, "how": how, "t_end": case.t_end,
                     "reference": case.reference,
                     "reference_error": accuracy.state_error(case.y_ref, exact, case.scale),
                     "dop853_reference_error": accuracy.state_error(case.y_ref_dop853, exact,
                                                                    case.scale),
                     "seconds": time.perf_counter() - start})
        print(f"{case.label}: reference vs {how}: {rows[-1]['reference_error']:.1e}",
              file=sys.stderr)
    return rows


# ---- tables --------------------------------------------------------------------------------
def summary(runs: pd.DataFrame) -> pd.DataFrame:
    rows = []
    for label, group in runs.groupby("problem", sort=False):
        row = {"problem": label}
        for target in TARGETS:
            ok = group[group.ok & (group.error <= target)]
            key = f"{target:.0e}"
            if ok.empty:
                row[key] = "none reached it"
                continue
            best = ok.loc[ok.seconds.idxmin()]
            row[key] = (f"{best.method} {best.setting.split(' ')[0]}: {best.seconds * 1e3:.3g} ms, "
                        f"{best.evals} ev, err {best.error:.0e}")
        rows.append(row)
    return pd.DataFrame(rows)


def derive_rule(runs: pd.DataFrame, labels: list[str]) -> dict:
    """TABLE of mechbook/simulate/accuracy.py from the adaptive runs (see its docstring)."""
    rule: dict[float, dict[str, tuple]] = {}
    adaptive = runs[runs.method.isin(ADAPTIVE)]
    for target in RULE_TARGETS:
        row = {}
        for method in ADAPTIVE:
            best = None
            for tol in sorted(adaptive.tol.unique(), reverse=True):
                sel = adaptive[(adaptive.method == method) & (adaptive.tol == tol)]
                if set(sel.problem) != set(labels) or not sel.ok.all():
                    continue
                worst = float(sel.error.max())
                if worst <= target:  # cost: runs plus the Taylor compiles, over the systems
                    cost = sel.seconds.sum() + sel.compile_seconds.fillna(0).sum()
                    best = (float(tol), worst, float(cost))
                    break
            if best is not None:
                row[method] = best
        if row:
            rule[target] = row
    return rule


def rule_source(rule: dict, n_systems: int) -> str:
    lines = [f"BENCH_SYSTEMS = {n_systems}", "TABLE: dict[float, dict[str, tuple[float, float, "
             "float]]] = {"]
    for target, row in rule.items():
        lines.append(f"    {target:.0e}: {{")
        for method, (tol, worst, secs) in row.items():
            lines.append(f"        {method!r}: ({tol:.0e}, {worst:.1e}, {secs:.3g}),")
        lines.append("    },")
    lines.append("}")
    return "\n".join(lines) + "\n"


def recheck_rule(runs: pd.DataFrame, labels: list[str]) -> list[dict]:
    """Does the committed TABLE's non-stiff choice still meet each target on this data?"""
    rows = []
    for target in sorted(accuracy.TABLE, reverse=True):
        try:
            choice = accuracy.choose(target)
        except MechbookError:
            continue
        sel = runs[(runs.method == choice.method)
                   & np.isclose(runs.tol, choice.rtol, rtol=1e-6, atol=0)
                   & runs.problem.isin(labels)]
        worst = float(sel.error.max()) if len(sel) == len(labels) else math.inf
        rows.append({"target": target, "method": choice.method, "tol": choice.rtol,
                     "committed_expected": choice.expected, "worst_now": worst,
                     "holds": bool(worst <= target)})
    return rows


# ---- long runs -----------------------------------------------------------------------------
def long_run(quick: bool) -> list[dict]:
    problem = load_problem(problem_path(LONG["pid"], ROOT))
    analysis = Analysis(problem)
    name = LONG["system"]
    system, dyn = analysis.system(name), analysis.dynamics(name)
    values = problem.values()
    model = build_model(system, dyn, values, conserved_quantities(system, dyn))
    q0, qd0, _ = initial_state(analysis, name, LONG["init"], values)
    rates = linear_rates(model, 0.0, np.zeros(model.n), np.zeros(model.n))
    period = rates.period
    periods = LONG["periods"] // (10 if quick else 1)
    t_end = periods * period
    t_eval = np.arange(periods + 1) * period
    t_eval[-1] = t_end
    rows = []
    settings = [("taylor", {"tol": 2.0 ** -52}, "tol = 2.2e-16"),
                ("leapfrog", {"step": period / 20}, "h = T/20"),
                ("yoshida4", {"step": period / 20}, "h = T/20"),
                ("RK4", {"step": period / 20}, "h = T/20"),
                ("RK45", {"rtol": 1e-6, "atol": 1e-6}, "rtol = atol = 1e-6"),
                ("DOP853", {"rtol": 1e-6, "atol": 1e-6}, "rtol = atol = 1e-6")]
    for method, opts, label in settings:
        calls = model.stats["rhs_calls"]
        start = time.process_time()
        traj = integrate(model, (0.0, t_end), q0, qd0, method, t_eval=t_eval, **opts)
        seconds = time.process_time() - start
        d = next(x for x in drifts(model, traj) if x.name == "energy_function")
        dev = np.abs(d.values - d.initial) / d.scale
        tenth = max(1, len(dev) // 10)
        rows.append({"method": method, "setting": label, "periods": periods,
                     "evals": model.stats["rhs_calls"] - calls, "seconds": seconds,
                     "max_rel_energy_error_first_tenth": float(dev[:tenth].max()),
                     "max_rel_energy_error_last_tenth": float(dev[-tenth:].max()),
                     "final_rel_energy_error": float(dev[-1]),
                     "drift_rate_per_period": d.rate * period})
        print(f"long run {method}: {rows[-1]}", file=sys.stderr)
    return rows


# ---- stiffness -----------------------------------------------------------------------------
def pendulum_closed_form(theta0: float, omega0: float, t: float) -> tuple[float, float]:
    """θ(t), θ̇(t) of a simple pendulum released at rest from θ0 (Jacobi elliptic
    functions, mpmath at 30 digits): θ = 2 asin(k sn(K − ω0 t | k²)), θ̇ = −2 k ω0 cn(…)."""
    import mpmath as mp

    with mp.workdps(30):
        k = mp.sin(mp.mpf(theta0) / 2)
        u = mp.ellipk(k ** 2) - mp.mpf(omega0) * mp.mpf(t)
        sn, cn = mp.ellipfun("sn", u, m=k ** 2), mp.ellipfun("cn", u, m=k ** 2)
        return float(2 * mp.asin(k * sn)), float(-2 * k * omega0 * cn)


def stiffness_sweep(quick: bool) -> list[dict]:
    """lim-2033 with the spring k·l² = ratio × m·g·l, over 3 periods of the slow (in-phase)
    mode, from two starts: in phase (θ1 = θ2 = 0.1: the spring never stretches, each bob
    swings as a simple pendulum, and the reference is that closed form) and with the fast
    mode excited (θ2 = 0.1 − 0.1/√ratio: the same energy in the spring at every ratio; the
    reference is DOP853 at rtol 1e-12, for ratios up to 1e4 — beyond, it costs millions of
    evaluations — and only at tol 1e-6, to keep the bench short)."""
    problem = load_problem(problem_path(STIFF["pid"], ROOT))
    analysis = Analysis(problem)
    name = STIFF["system"]
    system, dyn = analysis.system(name), analysis.dynamics(name)
    base = problem.values()
    by_name = {s.name: s for s in base}
    m, g, length = (base[by_name[x]] for x in ("m", "g", "l"))
    omega0 = math.sqrt(g / length)
    rows = []
    ratios = STIFF["ratios"][::5] if quick else STIFF["ratios"]
    for ratio in ratios:
        values = dict(base)
        values[by_name[STIFF["param"]]] = ratio * m * g / length  # k l² / (m g l)
        model = build_model(system, dyn, values)
        at_rest = linear_rates(model, 0.0, np.zeros(model.n), np.zeros(model.n))
        t_end = PERIODS * at_rest.period
        starts = {"in phase": {"theta1": "0.1", "theta2": "0.1"}}
        if ratio <= STIFF["excited_up_to"]:
            starts["fast mode excited"] = {"theta1": "0.1",
                                           "theta2": repr(0.1 - 0.1 / math.sqrt(ratio))}
        for start_name, init in starts.items():
            q0, qd0, _ = initial_state(analysis, name, init, values)
            case = Case(f"{STIFF['pid']} k×{ratio:.0e}", STIFF["pid"], name, model, q0, qd0,
                        start_name, at_rest.omega_min, at_rest.omega_max, t_end)
            samples = np.linspace(0, t_end, 201)
            if start_name == "in phase":
                th = np.array([pendulum_closed_form(float(q0[0]), omega0, t) for t in samples])
                ref_y = np.vstack((th[:, 0], th[:, 0], th[:, 1], th[:, 1]))
                how = "closed form (simple pendulum)"
            else:
                with warnings.catch_warnings(), np.errstate(all="ignore"):
                    warnings.simplefilter("ignore")
                    ref = integrate(model, (0.0, t_end), q0, qd0, "DOP853", rtol=1e-12,
                                    atol=1e-14, t_eval=samples)
                if not ref.success:
                    continue
                ref_y, how = ref.y, "DOP853 rtol 1e-12"
            case.y_ref, case.scale = ref_y[:, -1], accuracy.scales(ref_y)
            for tol in (1e-6, 1e-9) if start_name == "in phase" else (1e-6,):
                st = assess(model, (0.0, t_end), q0, qd0, rtol=tol)  # what `simulate` sees
                for method in SCIPY:
                    r = measure(case, method, {"rtol": tol, "atol": tol}, f"tol={tol:.0e}",
                                tol, repeat=1 if quick else REPEAT)
                    rows.append({"stiffness_ratio": ratio, "start": start_name,
                                 "omega_slow": at_rest.omega_min, "omega_fast": at_rest.omega_max,
                                 "t_end": t_end, "start_rate_ratio": st.rates.ratio,
                                 "radians_fastest": st.radians,
                                 "fast_excitation": st.excitation,
                                 "detected_stiff": st.stiff,
                                 "auto_method": IMPLICIT if st.stiff else "DOP853",
                                 "reference": how, "method": method, "tol": tol,
                                 "error": r.error, "seconds": r.seconds, "evals": r.evals,
                                 "ok": r.ok, "message": r.message})
                print(f"stiffness {ratio:.0e} {start_name} tol {tol:.0e}: rates ratio "
                      f"{st.rates.ratio:.3g}, excitation {st.excitation:.1e}, stiff {st.stiff}",
                      file=sys.stderr)
    return rows


# ---- cold and warm checks ------------------------------------------------------------------
def mechbook_command() -> list[str]:
    exe = Path(sys.executable).parent / "mechbook"
    if exe.exists():
        return [str(exe)]
    return [sys.executable, "-c", "from mechbook.app.cli import main; main()"]


def check_times(pids: list[str], quick: bool) -> list[dict]:
    rows = []
    repeat = 1 if quick else REPEAT
    tmp = Path(tempfile.mkdtemp(prefix="mechbook-checkbench-"))
    try:
        for pid in pids:
            store = tmp / f"{pid}.h5"

            def once(pid=pid, store=store):
                start = time.perf_counter()
                out = subprocess.run([*mechbook_command(), "--root", str(ROOT), "check", pid,
                                      "--store", str(store)], capture_output=True, text=True)
                wall = time.perf_counter() - start
                found = re.search(r"\(([\d.]+) s\)", out.stderr)
                return wall, float(found.group(1)) if found else math.nan, out.returncode

            cold, warm = [], []
            for _ in range(repeat):
                store.unlink(missing_ok=True)
                cold.append(once())
            for _ in range(repeat):
                warm.append(once())
            cw, ci = statistics.median(x[0] for x in cold), statistics.median(x[1] for x in cold)
            ww, wi = statistics.median(x[0] for x in warm), statistics.median(x[1] for x in warm)
            rows.append({"problem": pid, "cold_wall_s": cw, "warm_wall_s": ww,
                         "ratio_wall": cw / ww, "cold_in_process_s": ci,
                         "warm_in_process_s": wi, "exit_codes": ",".join(
                             str(x[2]) for x in cold + warm)})
            print(f"check {pid}: cold {cw:.2f} s, warm {ww:.2f} s", file=sys.stderr)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return rows


# ---- output --------------------------------------------------------------------------------
def write_h5(path: Path, tables: dict[str, pd.DataFrame], attrs: dict) -> None:
    """Every table as a group of column datasets; temporary file, then os.replace."""
    import h5py

    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        with h5py.File(tmp, "w") as f:
            f.attrs.update({k: v for k, v in attrs.items() if v is not None})
            for name, df in tables.items():
                g = f.create_group(name)
                g.attrs["columns"] = list(df.columns)
                for col in df.columns:
                    values = df[col].to_numpy()
                    if values.dtype.kind in "biuf":
                        g.create_dataset(col, data=values)
                    else:
                        g.create_dataset(col, data=[str(v) for v in values],
                                         dtype=h5py.string_dtype("utf-8"))
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def plot(case: Case, runs: list[Run], figdir: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5))
    for method in (*ADAPTIVE, *FIXED):
        pts = [(r.seconds, max(r.error, 1e-17)) for r in runs if r.method == method and r.ok]
        if pts:
            x, y = zip(*pts, strict=True)
            ax.loglog(x, y, "o-" if method in ADAPTIVE else "s--", ms=4, label=method)
    ax.set_xlabel("wall time per run (s; median of 3, one run above 0.25 s)")
    ax.set_ylabel("relative error of the state at the end")
    ax.set_title(f"{case.label}: {PERIODS} periods, t = {case.t_end:.3g}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    out = figdir / (case.label.replace("/", "_") + ".png")
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    plt.close(fig)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--problems", nargs="*", default=None, metavar="ID")
    ap.add_argument("--quick", action="store_true",
                    help="4 tolerances, 4 step sizes, single runs, shorter long run")
    ap.add_argument("--out", type=Path, default=ROOT / "results" / "bench.h5")
    ap.add_argument("--figdir", type=Path, default=ROOT / "results" / "bench")
    ap.add_argument("--no-long", action="store_true")
    ap.add_argument("--no-stiff", action="store_true")
    ap.add_argument("--no-check", action="store_true")
    opts = ap.parse_args()
    began = time.perf_counter()
    opts.figdir.mkdir(parents=True, exist_ok=True)
    pids = opts.problems or all_ids(ROOT)
    phases: dict[str, float] = {}
    cases, skipped = discover(pids)
    phases["discovery"] = time.perf_counter() - began
    all_runs, info = [], []
    for case in cases:
        why = reference(case)
        if why:
            skipped.append({"problem": case.pid, "system": case.system, "reason": why})
            print(f"{case.label}: skipped ({why})", file=sys.stderr)
            continue
        start = time.perf_counter()
        runs = ladder(case, opts.quick)
        for r in runs:
            all_runs.append({"problem": case.label, **r.__dict__})
        plot(case, runs, opts.figdir)
        info.append({"problem": case.label, "dof": case.model.n, "start": case.source,
                     "omega_min": case.omega_min or math.nan, "omega_max": case.omega_max,
                     "t_end": case.t_end, "reference_evals": case.ref_evals,
                     "reference_s": case.ref_seconds,
                     **{f"{m}_applies": not case.applicable[m] for m in FIXED},
                     "seconds": time.perf_counter() - start})
        print(f"{case.label}: {len(runs)} runs in {info[-1]['seconds']:.1f} s",
              file=sys.stderr)
        sys.stderr.flush()
    phases["ladders"] = time.perf_counter() - began - sum(phases.values())
    good = [c for c in cases if c.y_ref is not None]
    runs = pd.DataFrame(all_runs)
    labels = [c.label for c in good]
    tables = {"runs": runs, "systems": pd.DataFrame(info), "skipped": pd.DataFrame(skipped)}
    tables["reference_checks"] = pd.DataFrame(check_references(good))
    phases["reference_checks"] = time.perf_counter() - began - sum(phases.values())
    tables["summary"] = summary(runs)
    rule = derive_rule(runs, labels)
    rule_text = rule_source(rule, len(labels))
    (opts.figdir / "accuracy_rule.py").write_text(rule_text)
    tables["rule"] = pd.DataFrame([{"target": t, "method": m, "tol": v[0], "worst_error": v[1],
                                    "seconds_sum": v[2]} for t, row in rule.items()
                                   for m, v in row.items()])
    tables["rule_recheck"] = pd.DataFrame(recheck_rule(runs, labels))
    for key, flag, fn in (("long_run", opts.no_long, long_run),
                          ("stiffness", opts.no_stiff, stiffness_sweep)):
        if flag:
            continue
        try:
            tables[key] = pd.DataFrame(fn(opts.quick))
        except (MechbookError, KeyError, ValueError) as exc:  # the problem file changed
            print(f"{key}: not run ({exc})", file=sys.stderr)
        phases[key] = time.perf_counter() - began - sum(phases.values())
    if not opts.no_check:
        tables["check_cache"] = pd.DataFrame(check_times(
            [p for p in CHECK_PIDS if p in pids], opts.quick))
        phases["check_cache"] = time.perf_counter() - began - sum(phases.values())
    elapsed = time.perf_counter() - began
    tables["phases"] = pd.DataFrame([{"phase": k, "seconds": v} for k, v in phases.items()])
    attrs = {"date": datetime.now(UTC).isoformat(timespec="seconds"),
             "machine": f"{platform.machine()}, {os.cpu_count()} cores, {platform.system()}",
             "python": platform.python_version(), "numpy": np.__version__,
             "quick": bool(opts.quick), "seconds": elapsed, "periods": PERIODS,
             "reference": ", ".join(sorted({c.reference for c in good})),
             "timing": "process CPU time", "budget_evaluations": BUDGET}
    write_h5(opts.out, tables, attrs)
    for name, df in tables.items():
        df.to_csv(opts.figdir / f"{name}.csv", index=False)
    with pd.option_context("display.width", 250, "display.max_columns", 30,
                           "display.max_colwidth", 60, "display.max_rows", 500):
        print(f"\n== skipped ({len(skipped)})")
        print(tables["skipped"].to_string(index=False))
        print("\n== reference checks")
        print(tables["reference_checks"].to_string(index=False, float_format="{:.2e}".format))
        print("\n== cheapest method meeting each accuracy (median wall time of 3 runs)")
        print(tables["summary"].to_string(index=False))
        print("\n== accuracy rule (paste into mechbook/simulate/accuracy.py)")
        print(rule_text)
        print("== committed rule re-checked")
        print(tables["rule_recheck"].to_string(index=False))
        for name in ("long_run", "stiffness", "check_cache", "phases"):
            if name in tables:
                print(f"\n== {name}")
                print(tables[name].to_string(index=False, float_format="{:.3g}".format))
    print(f"\n{len(labels)} systems, {len(runs)} runs, {elapsed:.0f} s; written to {opts.out}, "
          f"{opts.figdir}/")


if __name__ == "__main__":
    main()
