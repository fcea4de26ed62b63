"""A system's section of a problem page: the derivation, the equilibria and a simulation.

The Lagrangian, T and V come with the system as it is built from its declarations;
Lagrange's equations, the momenta and the energy function are the stored ones where the
check derived them, else derived here under the step limit (they are cheap). The
equilibria are those the check found or linearized about (mechbook.app.report.equilibria_table);
the simulation starts from the problem's `initial:` or near a stable one of them.
"""

from __future__ import annotations

import json

import numpy as np
import sympy as sp

from mechbook.app.report import svg
from mechbook.app.report.animation import frames
from mechbook.app.report.derivation import StoredSystem
from mechbook.app.report.equilibria_table import equilibria_rows
from mechbook.app.report.stored import names_for
from mechbook.model.manifold import manifold_of
from mechbook.numerics.simulate import FALLBACK_OFFSET, simulate


def system_section(page, analysis, name: str, entry: dict | None, key) -> tuple:
    """(the section's data, the stored results as a StoredSystem or None)."""
    res = {"name": name, "doc": "", "coordinates": [], "blocks": [], "equilibria": [],
           "left_out": [], "simulation": None}
    sys_ = page.step(f"system {name}", lambda: analysis.system(name))
    if sys_ is None:
        return res, None
    res["doc"] = str(sys_.spec.get("doc", ""))
    coords = sys_.spec.get("coordinates") or {}
    res["coordinates"] = [(c, str((coords.get(c) or {}).get("doc", "")),
                           sys_.domains[q].text if q in sys_.domains else "")
                          for c, q in zip(sys_.coord_names, sys_.q, strict=True)]
    names = dict(sys_.names)
    if key is not None:
        names.update(key.symbols)
    names.update({f"p_{c}": sp.Symbol(f"p_{c}", real=True) for c in sys_.coord_names})
    view = StoredSystem(entry, names_for(names))
    blocks = res["blocks"]

    def block(title: str, fn, simplify: bool = True) -> None:
        value = page.step(f"{title} ({name})", fn)
        if value is not None:
            blocks.append({"title": title, "math": page.show(value, simplify)})

    block("Lagrangian L = T − V", lambda: sys_.lagrangian)
    block("Kinetic energy T", lambda: sys_.kinetic)
    block("Potential energy V", lambda: sys_.potential)
    dyn = analysis.dynamics(name)
    block("Equations of motion (Lagrange)", lambda: _eom(view, dyn, sys_))
    block("Generalized momenta", lambda: _momenta(view, dyn, sys_))
    cyclic = page.step(f"cyclic coordinates ({name})", lambda: _cyclic(view, dyn))
    if cyclic:
        block("Cyclic coordinates: conserved momenta", lambda: cyclic)
    conserved = page.step(f"energy ({name})", lambda: bool(dyn.energy_conserved))
    block("Energy function h = Σ q̇ ∂L/∂q̇ − L" + (" (conserved)" if conserved else
                                                    " (not conserved)"),
          lambda: view.get("energy_function") or dyn.energy_function)
    values = analysis.problem.values()
    rows, left_out = equilibria_rows(page, sys_, view, values)
    res["equilibria"], res["left_out"] = rows, left_out
    if page.options.simulate:
        res["simulation"] = _simulation(page, analysis, name, sys_, rows)
    for row in rows:
        row.pop("values", None)  # SymPy objects stay in the worker
    return res, view


def _eom(view: StoredSystem, dyn, sys_) -> list:
    M, f = view.get("mass_matrix"), view.get("forcing")
    M = sp.Matrix(M) if M is not None else dyn.mass_matrix
    f = sp.Matrix(f) if f is not None else dyn.forcing
    f = sp.Matrix(f).reshape(M.rows, 1)
    lhs = M * sp.Matrix(dyn.qdd)
    rhs = f
    if dyn.constrained:
        rhs = rhs + dyn.velocity_jacobian.T * sp.Matrix(dyn.multipliers)
    return [sp.Eq(a, b, evaluate=False) for a, b in zip(lhs, rhs, strict=True)]


def _momenta(view: StoredSystem, dyn, sys_) -> dict:
    stored = view.get("momenta")
    if isinstance(stored, dict):
        return {sp.Symbol(f"p_{k}"): v for k, v in stored.items()}
    return dict(zip([sp.Symbol(f"p_{c}") for c in sys_.coord_names], dyn.momenta,
                    strict=True))


def _cyclic(view: StoredSystem, dyn) -> dict:
    stored = view.get("cyclic")
    found = stored if isinstance(stored, dict) else dyn.cyclic
    return {sp.Symbol(f"p_{q}"): p for q, p in found.items()}


def _simulation(page, analysis, name: str, sys_, rows: list[dict]) -> dict | None:
    """A run from the system's `initial:`, or else at rest a little away from the first
    stable equilibrium of the table; the page says which (or why there is none)."""
    opts = page.options
    init, source, seconds = None, "the problem's initial conditions", opts.simulate_seconds
    if not sys_.spec.get("initial"):
        stable = [r for r in rows if r["stability"] == "stable" and r.get("values")]
        known = [r for r in rows if r.get("values")]
        if stable:
            start, near = stable[0]["values"], "the first stable equilibrium above"
        elif known:
            start, near = known[0]["values"], (f"equilibrium 1 above ({known[0]['stability']})"
                                               if known[0]["stability"] else
                                               "equilibrium 1 above")
        else:
            start = [_inside(sys_, q, analysis.problem.values()) for q in sys_.q]
            near, seconds = "q = 0 (no equilibrium known to the check)", min(seconds, 4.0)
        # unequal offsets, so that a uniform translation is not all that moves
        q0 = [float(x) + FALLBACK_OFFSET * (1.0 if i == 0 else 0.5)
              for i, x in enumerate(start)]
        source = (f"at rest, {FALLBACK_OFFSET:g} ({FALLBACK_OFFSET / 2:g} in the other "
                  f"coordinates) from {near}")
        init, projected = _on_constraints(sys_, analysis.problem.values(), q0)
        if projected:
            source += ", moved onto the constraints as the checks move their states"

    def run():
        with np.errstate(all="ignore"):
            return simulate(analysis, name, init=init, t_span=(0.0, opts.t_end), points=601)

    sim = page.step(f"simulation ({name})", run, seconds)
    if sim is None:
        return None
    traj = sim.trajectory
    if not len(traj.t):
        page.notes.append(f"simulation ({name}): not shown (no samples: {traj.message})")
        return None
    names = list(sys_.coord_names)
    charts = [svg.chart([(c, traj.t, traj.q[i]) for i, c in enumerate(names)],
                        "coordinates against time", "t", "q"),
              svg.chart([(c, traj.q[i], traj.qd[i]) for i, c in enumerate(names)],
                        "phase portrait", "q", "dq/dt")]
    if sim.drifts:
        charts.append(svg.chart([(d.name, traj.t, (d.values - d.initial) / d.scale)
                                 for d in sim.drifts], "drift of the conserved quantities",
                                "t", "(Q − Q₀) / scale"))
    motion = page.step(f"animation ({name})",
                       lambda: frames(sys_, traj, analysis.problem.values()))
    return {"charts": charts,
            "motion": json.dumps(motion).replace("</", "<\\/") if motion else None,
            "drifts": [(d.name, float(d.relative)) for d in sim.drifts],
            "method": settings_text(traj.settings),
            "initial": ", ".join(f"{k} = {v:.4g}" for k, v in sim.initial.items()),
            "initial_source": source, "t_end": float(traj.t[-1]),
            "samples": len(traj.t), "notes": list(sim.notes)}


def _on_constraints(sys_, values: dict, q0: list[float]) -> tuple[dict, bool]:
    """The start {coordinate or rate: text} for the simulation: `q0` at rest, or, for a
    system with constraints, the nearest state on its constraint manifold (coordinates and
    rates, as the checks settle their sampled states: mechbook.model.manifold), and
    whether it was moved there."""
    names = list(sys_.coord_names)
    manifold = manifold_of(sys_)
    if manifold is None:
        return {c: repr(x) for c, x in zip(names, q0, strict=True)}, False
    settled = manifold.settle(values, np.array(q0), np.zeros(len(q0)))
    if settled is None:  # the simulation says why it cannot start there
        return {c: repr(x) for c, x in zip(names, q0, strict=True)}, False
    q1, qd1 = settled
    init = {c: repr(float(x)) for c, x in zip(names, q1, strict=True)}
    init.update({f"{c}dot": repr(float(v)) for c, v in zip(names, qd1, strict=True)})
    return init, True


def settings_text(settings: dict) -> str:
    """An integrator's settings for a reader: `DOP853, rtol 1e-08, atol 1e-10, compiled`
    (a flag by its name, never a Python True or False)."""
    out = []
    for key, value in settings.items():
        if key == "method":
            out.insert(0, str(value))
        elif isinstance(value, bool):
            out.append(key if value else f"not {key}")
        elif value is not None:
            out.append(f"{key} {value:.3g}" if isinstance(value, float) else f"{key} {value}")
    return ", ".join(out)


def _inside(sys_, q, values: dict) -> float:
    """0, or the nearest value well inside the coordinate's domain (a radius: 1)."""
    dom = sys_.domains.get(q)
    if dom is None or dom.contains(0.0, values) and not dom.lo_open:
        return 0.0
    lo, hi = dom.bounds(values)
    if np.isfinite(lo) and np.isfinite(hi):
        return (lo + hi) / 2
    return lo + 1.0 if np.isfinite(lo) else hi - 1.0
