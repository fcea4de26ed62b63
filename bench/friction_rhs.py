"""The stick-slip integrator's right-hand side: CPU time per call, on Symon 11-15's top.

Builds `Phases` for the `sliding` system of symon-11-15 (the sliding top) at the problem's
parameter values, as the event_time check does (mechbook.numerics.measure via the model's
`phases` factory), and times

    rhs        N calls of `Phases.rhs` at the check's start (the contact sliding)
    stop       N calls of the sliding contact's stop event there
    integrate  `Phases.solve_ivp` over --span from that start (DOP853, rtol = atol = 1e-12,
               the measurement's tolerance): RHS calls, CPU time, µs per call, and the end
               state in hex (to compare two trees bit for bit)

with time.process_time (CPU time of this process); with --event also

    event      the check's whole measurement (measure.first_event to theta = theta1/1000,
               the rise of the top, ~23 s of motion): CPU time, RHS calls, the time found
               and the state there in hex

 `--tree DIR` imports mechbook from
another tree (e.g. a `git archive` of the base commit) to measure the before figure with
the same script.

    python bench/friction_rhs.py [-N 20000] [--span 0.05] [--tree DIR]
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    ap.add_argument("-N", type=int, default=20000, help="calls timed (rhs, stop)")
    ap.add_argument("--span", type=float, default=0.05, help="time integrated")
    ap.add_argument("--event", action="store_true", help="time the whole measurement")
    ap.add_argument("--tree", type=Path, default=ROOT, help="the mechbook tree imported")
    args = ap.parse_args(argv)
    sys.path.insert(0, str(args.tree.resolve()))

    import numpy as np

    import mechbook
    from mechbook.engine.analysis import Analysis
    from mechbook.model.catalog import problem_path
    from mechbook.model.problem import load_problem
    from mechbook.numerics.friction import Phases
    from mechbook.numerics.measure import TOLERANCE, first_event, signal_functions
    from mechbook.numerics.rhs import build_model

    print(f"mechbook from {Path(mechbook.__file__).parent.parent}")
    a = Analysis(load_problem(problem_path("symon-11-15", args.tree.resolve())))
    system, dyn = a.system("sliding"), a.dynamics("sliding")
    values = {k: float(v) for k, v in a.problem.values().items()}
    phases = Phases(system, dyn, values)

    # the check's start (answers/symon/11-15.yaml): theta1 = 0.5, omega30 = 400, on the
    # slow precession
    theta1, omega30 = 0.5, 400.0
    g, length, r = (values[_sym(values, k)] for k in ("g", "l", "r"))
    prec = g * length / (r**2 * omega30)
    q0 = {"X": 0.0, "Y": 0.0, "theta": theta1, "phi": 0.0, "psi": 0.0}
    qd0 = {"X": 0.0, "Y": 0.0, "theta": 0.0, "phi": prec,
           "psi": omega30 - g * length * math.cos(theta1) / (r**2 * omega30)}
    names = system.coord_names
    y0 = np.array([q0[c] for c in names] + [qd0[c] for c in names])

    # the eps the integrator would use (set by solve_ivp); one tiny run sets it
    phases.solve_ivp((0.0, 1e-9), y0)
    modes, directions = ["slip"] * len(phases.contacts), [None] * len(phases.contacts)
    stop = phases._switch_events(modes, directions, phases.eps)[0]

    for label, call in (("rhs", lambda: phases.rhs(0.0, y0, modes, directions)),
                        ("stop", lambda: stop(0.0, y0))):
        for _ in range(200):
            call()
        start = time.process_time()
        for _ in range(args.N):
            call()
        cpu = time.process_time() - start
        print(f"{label:10s} {args.N} calls  {1e6 * cpu / args.N:7.2f} µs/call"
              f"  {args.N / cpu:9.0f} calls/s")

    start_nfev, start = phases.nfev, time.process_time()
    res = phases.solve_ivp((0.0, args.span), y0, rtol=TOLERANCE, atol=TOLERANCE)
    cpu = time.process_time() - start
    calls = phases.nfev - start_nfev
    print(f"integrate  {args.span} s: {calls} evaluations, {cpu:.3f} s CPU,"
          f" {1e6 * cpu / calls:7.2f} µs/call, status {res.status}")
    print("end state  " + " ".join(float(x).hex() for x in res.y[:, -1]))

    if args.event:
        model = build_model(system, dyn, values)
        theta = next(q for q in system.q if str(q) == "theta")
        fn = signal_functions(system, dyn, values, theta - theta1 / 1000)
        n = len(names)
        start = time.process_time()
        t, y = first_event(model, fn, y0[:n], y0[n:], 1.0 / (1.0 + float(np.max(np.abs(y0[n:])))))
        cpu = time.process_time() - start
        calls = model.built_phases.nfev
        print(f"event      t = {t!r} ({float(t).hex()}): {calls} evaluations,"
              f" {cpu:.2f} s CPU, {1e6 * cpu / calls:.2f} µs per evaluation")
        print("state      " + " ".join(float(x).hex() for x in y))
    return 0


def _sym(values: dict, name: str):
    return next(k for k in values if str(k) == name)


if __name__ == "__main__":
    raise SystemExit(main())
