"""SciPy's solve_ivp methods (RK45, DOP853, Radau, LSODA: adaptive; rtol, atol, max_step)
behind the Integrator interface; DOP853 and RK45 run in the compiled loops (loops.c) when
nothing asks for what only solve_ivp has (events, a dense output)."""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from mechbook.numerics import c_stepping as loops
from mechbook.numerics.integrator_base import Integrator, Trajectory


class SciPyMethod(Integrator):
    """solve_ivp with one of its methods; options rtol, atol, max_step, first_step,
    dense_output."""

    adaptive = True

    def solve(self, model, t_span, q0, qd0, t_eval=None, events=None) -> Trajectory:
        opts = {"rtol": 1e-8, "atol": 1e-10}
        opts.update({k: v for k, v in self.options.items() if v is not None})
        compiled = opts.pop("compiled", True)
        y0 = np.concatenate((q0, qd0)).astype(float)
        n = model.n
        settings = {"method": self.name, **{k: v for k, v in opts.items()
                                             if isinstance(v, (int, float, bool, str))}}
        nat = model.native if compiled and self.name in ("DOP853", "RK45") else None
        if nat is not None and not events and not opts.get("dense_output") \
                and not opts.get("vectorized"):
            run = loops.adaptive(
                nat, model.stats, self.name, t_span, y0, opts["rtol"], opts["atol"],
                opts.get("max_step", math.inf), opts.get("first_step"), t_eval)
            model.stats["rhs_calls"] += run.evaluations
            return Trajectory(run.t, run.y[:n], run.y[n:], self.name,
                              {**settings, "compiled": True}, run.evaluations,
                              run.status == 0, run.message)
        sol = solve_ivp(model.rhs, t_span, y0, method=self.name, t_eval=t_eval,
                        events=events, **opts)
        return Trajectory(sol.t, sol.y[:n], sol.y[n:], self.name, settings, int(sol.nfev),
                          bool(sol.success), str(sol.message), sol.sol,
                          list(sol.t_events or []), list(sol.y_events or []))

