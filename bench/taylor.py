"""Issue 42's Taylor row: `mechbook simulate --method taylor` against heyoka's own
`propagate_grid` on the same equation, in one run.

The problem: classic-finite-pendulum (θ̈ = −(g/l) sin θ, l = 1.3, g = 9.81), released at
rest from θ0 = 1 rad, 10⁴ periods of that amplitude (4 √(l/g) K(sin²(θ0/2)) each), tol
1e-15, 2001 samples. The reference is heyoka used directly: θ̈ = −(g/l)·sin θ built once
with `taylor_adaptive`, its state reset and `propagate_grid` called on the same grid.
Timed, interleaved (A, B, C, A, B, C, ...), median of --repeat rounds, process CPU time
(wall time beside it):

* `heyoka grid`: the reference's propagate_grid alone;
* `mechbook integrate`: `integrate(model, ..., "taylor", t_eval=grid, tol=1e-15)` on a
  built model — the Taylor path alone (state reset, grid, output arrays);
* `mechbook simulate`: `numerics.simulate.simulate(analysis, ...)`, what the CLI's
  worker runs after deriving: parameters, initial state, model, stiffness assessment,
  integrator (heyoka's in-memory cache), integration, energy monitor;
* compile, separately, heyoka's in-memory LLVM cache emptied before each: the reference's
  `taylor_adaptive`; mechbook's `taylor.system_of` + `taylor.integrator` on a new model
  (`taylor_form`, translation, compile), and the model's own build (`build_model`: the
  SymEngine right-hand side that the stiffness check uses, the monitors); and together
  (a first run against compile + grid);
* the CLI's core function in process (`app.running.simrun.simulate_task`: load, validate,
  derive, simulate, the report's arrays) and the CLI itself (`mechbook simulate ...
  --serial`), wall time in a fresh process including imports, with `--no-store` and with
  the HDF5 write.

Accuracy: the largest |θ| difference between the two trajectories, and of each against the
closed form θ = 2 asin(k sn(K − ω0 t | k²)) at 30 digits (mpmath); with --float128 also
against the project's float128 reference (heyoka in quadruple precision at tol 1e-30 on
mechbook's equations, as bench/work_precision.py; about a minute).

    python bench/taylor.py [--repeat 7] [--cli 3] [--float128] [--profile]
"""

from __future__ import annotations

import argparse
import cProfile
import io
import math
import os
import pstats
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import mpmath as mp
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mechbook.engine.analysis import Analysis  # noqa: E402
from mechbook.model.catalog import problem_path  # noqa: E402
from mechbook.model.problem import load_problem  # noqa: E402
from mechbook.numerics.integrators import integrate  # noqa: E402
from mechbook.numerics.monitors import conserved_quantities  # noqa: E402
from mechbook.numerics.rhs import build_model  # noqa: E402
from mechbook.numerics.simulate import simulate  # noqa: E402

PROBLEM = "classic-finite-pendulum"
THETA0 = 1.0
PERIODS = 10_000
TOL = 1e-15
POINTS = 2001


def timed(fn) -> tuple[float, float, object]:
    """(CPU seconds, wall seconds, result) of one call."""
    c, w = time.process_time(), time.perf_counter()
    out = fn()
    return time.process_time() - c, time.perf_counter() - w, out


def interleaved(fns: dict, repeat: int) -> dict:
    """{name: (median CPU, median wall)}, the callables run A, B, C, A, B, C, ..."""
    cpu = {k: [] for k in fns}
    wall = {k: [] for k in fns}
    for _ in range(repeat):
        for k, fn in fns.items():
            c, w, _ = timed(fn)
            cpu[k].append(c)
            wall[k].append(w)
    return {k: (statistics.median(cpu[k]), statistics.median(wall[k])) for k in fns}


def closed_form(g: float, length: float, t: np.ndarray) -> np.ndarray:
    """θ(t) released at rest from THETA0, at 30 digits (the parameters' doubles exactly)."""
    with mp.workdps(30):
        w0 = mp.sqrt(mp.mpf(g) / mp.mpf(length))
        k = mp.sin(mp.mpf(THETA0) / 2)
        m = k * k
        K = mp.ellipk(m)
        return np.array([float(2 * mp.asin(k * mp.ellipfun("sn", K - w0 * mp.mpf(x), m=m)))
                         for x in t])


def float128_reference(model, grid: np.ndarray) -> np.ndarray | None:
    """θ on `grid` by heyoka in quadruple precision on mechbook's equations (the reference
    of bench/work_precision.py), or None without heyoka's real128."""
    import heyoka as hy

    from mechbook.numerics import taylor

    if not hasattr(hy, "real128"):
        return None
    ta = taylor.integrator(model, 1e-30, key="extended", fp_type=hy.real128)
    taylor.reset(ta, 0.0, np.array([hy.real128(THETA0), hy.real128(0.0)], dtype=hy.real128))
    res = ta.propagate_grid(np.array([hy.real128(float(x)) for x in grid], dtype=hy.real128))
    return np.array([float(row[0]) for row in np.asarray(res[5])])


def cli_wall(args: list[str], rounds: int) -> float:
    """Median wall seconds of `mechbook ARGS` in a fresh process (imports included)."""
    exe = Path(sys.executable).with_name("mechbook")
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "mechbook"]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    walls = []
    for _ in range(rounds):
        start = time.perf_counter()
        subprocess.run(cmd + args, cwd=ROOT, env=env, check=True, capture_output=True)
        walls.append(time.perf_counter() - start)
    return statistics.median(walls)


def import_wall(module: str, rounds: int) -> float:
    walls = []
    for _ in range(rounds):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-c", f"import {module}"], check=True,
                       env={**os.environ, "PYTHONPATH": str(ROOT)})
        walls.append(time.perf_counter() - start)
    return statistics.median(walls)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--cli", type=int, default=3, help="rounds of the CLI's wall time (0: none)")
    ap.add_argument("--float128", action="store_true",
                    help="also compare against the float128 reference (about a minute)")
    ap.add_argument("--profile", action="store_true", help="cProfile of one simulate()")
    args = ap.parse_args(argv)

    import heyoka as hy

    from mechbook.app.running.simrun import SimRequest, simulate_task
    from mechbook.numerics import taylor

    problem = load_problem(problem_path(PROBLEM, ROOT))
    values = {s.name: float(v) for s, v in problem.values().items()}
    g, length = values["g"], values["l"]
    T = 4 * math.sqrt(length / g) * float(mp.ellipk(math.sin(THETA0 / 2) ** 2))
    t_end = PERIODS * T
    grid = np.linspace(0.0, t_end, POINTS)
    print(f"{PROBLEM}: θ0 = {THETA0} rad, {PERIODS} periods (T = {T:.12g}, t_end = "
          f"{t_end:.12g}), tol {TOL:g}, {POINTS} samples; load average "
          f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}")

    # the reference: heyoka directly on θ̈ = −(g/l) sin θ
    th, v = hy.make_vars("th", "v")
    ode = [(th, v), (v, -(g / length) * hy.sin(th))]

    def hy_compile():
        hy.llvm_state.clear_memcache()
        return hy.taylor_adaptive(ode, [THETA0, 0.0], tol=TOL)

    ta = hy_compile()

    def hy_grid():
        ta.time = 0.0
        ta.state[:] = [THETA0, 0.0]
        return np.asarray(ta.propagate_grid(grid)[5])

    # mechbook: the derived analysis kept (as in one process), everything after it timed
    analysis = Analysis(problem)
    sysm, dyn = analysis.system(None), analysis.dynamics(None)

    def new_model():
        return build_model(sysm, dyn, problem.values(), conserved_quantities(sysm, dyn))

    model = new_model()

    def mb_integrate():
        return integrate(model, (0.0, t_end), [THETA0], [0.0], "taylor", t_eval=grid,
                         tol=TOL)

    def mb_simulate():
        return simulate(analysis, None, init={"theta": repr(THETA0)}, t_span=(0.0, t_end),
                        method="taylor", points=POINTS, rtol=TOL)

    fresh = []  # models built outside the timings, one per round of mb_taylor_compile

    def mb_model():
        fresh.append(new_model())

    def mb_taylor_compile():
        hy.llvm_state.clear_memcache()
        taylor.integrator(fresh.pop(), TOL, key="plain")  # taylor_form, translation, compile

    request = SimRequest(PROBLEM, method="taylor", rtol=TOL, t_end=t_end, points=POINTS,
                         init=(f"theta={THETA0!r}",))

    def cli_core():
        report = simulate_task(request, ROOT, None, lambda stage: None)
        if report.error:
            raise SystemExit(report.error)
        return report

    for fn in (hy_grid, mb_integrate, mb_simulate, cli_core):  # warm every path once
        fn()
    if args.profile:
        prof = cProfile.Profile()
        prof.enable()
        mb_simulate()
        prof.disable()
        out = io.StringIO()
        pstats.Stats(prof, stream=out).sort_stats("cumulative").print_stats(18)
        print(out.getvalue())

    t = interleaved({"heyoka grid": hy_grid, "mechbook integrate": mb_integrate,
                     "mechbook simulate": mb_simulate, "heyoka compile": hy_compile,
                     "mechbook model build": mb_model,
                     "mechbook taylor compile": mb_taylor_compile,
                     "cli core (in process)": cli_core},
                    args.repeat)
    width = max(map(len, t))
    for k, (c, w) in t.items():
        print(f"  {k:<{width}}  {c:8.4f} s CPU  {w:8.4f} s wall")
    ref = t["heyoka grid"][0]
    print(f"ratio, integration alone (mechbook integrate / heyoka grid): "
          f"{t['mechbook integrate'][0] / ref:.3f}")
    print(f"ratio, simulate (mechbook simulate / heyoka grid): "
          f"{t['mechbook simulate'][0] / ref:.3f}   <- the row of issue 42 (goal <= 1.3)")
    hc, mc = t["heyoka compile"][0], t["mechbook taylor compile"][0]
    build = t["mechbook model build"][0]
    print(f"ratio, compile (mechbook taylor compile / heyoka compile): {mc / hc:.3f}")
    print(f"ratio, a first run (model build + taylor compile + simulate / heyoka compile + "
          f"grid): {(build + mc + t['mechbook simulate'][0]) / (hc + ref):.3f}")
    print(f"ratio, the CLI's work in process (cli core / heyoka compile + grid): "
          f"{t['cli core (in process)'][0] / (hc + ref):.3f}")

    # accuracy: the two trajectories, the closed form, the float128 reference
    ours = mb_simulate().trajectory.q[0]
    theirs = hy_grid()[:, 0]
    exact = closed_form(g, length, grid)
    print(f"max |θ mechbook − θ heyoka| = {np.max(np.abs(ours - theirs)):.3e}")
    print(f"max |θ − closed form|: mechbook {np.max(np.abs(ours - exact)):.3e}, heyoka "
          f"{np.max(np.abs(theirs - exact)):.3e}")
    if args.float128:
        quad = float128_reference(model, grid)
        if quad is not None:
            print(f"max |θ − float128 reference|: mechbook {np.max(np.abs(ours - quad)):.3e}, "
                  f"heyoka {np.max(np.abs(theirs - quad)):.3e}; reference − closed form "
                  f"{np.max(np.abs(quad - exact)):.3e}")

    if args.cli:
        cli = ["simulate", PROBLEM, "--method", "taylor", "--rtol", repr(TOL), "--init",
               f"theta={THETA0!r}", "--t-end", repr(t_end), "--points", str(POINTS),
               "--serial"]
        with tempfile.TemporaryDirectory() as tmp:
            stored = cli_wall(cli + ["--store", str(Path(tmp) / "runs.h5")], args.cli)
        print(f"CLI wall (fresh process, imports included), median of {args.cli}: "
              f"--no-store {cli_wall(cli + ['--no-store'], args.cli):.3f} s, with the HDF5 "
              f"write {stored:.3f} s; `import heyoka` alone "
              f"{import_wall('heyoka', args.cli):.3f} s, `import mechbook.numerics.simulate` "
              f"{import_wall('mechbook.numerics.simulate', args.cli):.3f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
