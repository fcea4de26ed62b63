"""A simulated motion stays inside the coordinates' domains (mechbook.model.domains).

Polar coordinates are singular at r = 0: a run that reaches it is no longer the problem's
motion, and past it the integrator follows equations that describe nothing. A start outside
a domain is refused; a run is cut at its last sample inside, with a note saying which
coordinate left its domain and when.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from mechbook.errors import MechbookError


def check_start(sys, q0: np.ndarray, values: dict) -> None:
    """MechbookError when the initial coordinates `q0` lie outside a domain."""
    for q, x in zip(sys.q, q0, strict=True):
        dom = sys.domains.get(q)
        if dom is not None and not dom.contains(float(x), values):
            raise MechbookError(f"the initial value {q} = {float(x):.6g} is outside the "
                                f"coordinate's domain {dom.text}")


def within_domains(sys, traj, values: dict):
    """(the trajectory up to its last sample inside every domain, a note or None)."""
    domains = sys.domains
    if not domains or not len(traj.t):
        return traj, None
    bad = np.zeros(len(traj.t), dtype=bool)
    left = {}
    for i, q in enumerate(sys.q):
        dom = domains.get(q)
        if dom is None:
            continue
        out = np.array([not dom.contains(float(x), values) for x in traj.q[i]])
        if out.any():
            left[int(np.argmax(out))] = dom
        bad |= out
    if not bad.any():
        return traj, None
    first = int(np.argmax(bad))
    dom = left[min(left)]
    keep = max(first, 1)
    cut = replace(traj, t=traj.t[:keep], q=traj.q[:, :keep], qd=traj.qd[:, :keep],
                  success=False, message=f"{dom.text} no longer holds")
    return cut, (f"the motion left the domain {dom.text} at t = {float(traj.t[first]):.4g}: "
                 "the run stops there (the problem's coordinates describe nothing past it)")
