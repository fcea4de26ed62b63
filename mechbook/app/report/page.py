"""One problem's page of the report, computed in a worker process: the derivation as
mathematics, the book's value next to the engine's for every part, and the figures.

Everything is derived unsimplified (as a check does) and each step has a wall-clock limit
(`hard_time_limit`, which keeps firing until the step is left, so the engine's own searches
cannot outlast it); a step that runs out or fails leaves a note on the page instead of its
result. Only what is shown is simplified, one expression at a time, each within
`simplify_seconds` and all within `simplify_budget` per page, outside the step limits so
that SymPy's own limit applies. The outcomes themselves come from the store: this module
decides nothing.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import sympy as sp

from mechbook.app.mathml import math
from mechbook.app.report import figures
from mechbook.app.report.values import book_math, engine_value, numeric_pair
from mechbook.core.timeout import Timeout, hard_time_limit, try_simplify
from mechbook.engine.analysis import Analysis
from mechbook.errors import MechbookError, UnsupportedError
from mechbook.model.catalog import answer_path, problem_path
from mechbook.model.problem import load_problem

LONGEST = 12000  # characters of SymPy text beyond which an expression is not typeset
MAX_POINTS = 6  # equilibria shown per system


@dataclass(frozen=True)
class PageOptions:
    seconds: float = 15.0  # limit of each derivation step
    simplify_seconds: float = 2.0  # limit of each expression's simplification
    simplify_budget: float = 15.0  # all simplification of one page
    simulate: bool = True
    t_end: float = 10.0
    simulate_seconds: float = 20.0


@dataclass
class _Page:
    options: PageOptions
    notes: list[str] = field(default_factory=list)
    budget: float = 0.0
    timings: list[tuple[str, float]] = field(default_factory=list)  # the slow steps
    simplifying: float = 0.0

    def step(self, label: str, fn, seconds: float | None = None, hard: bool = True):
        """fn() within the step limit; None (and a note on the page) if it cannot finish.
        `hard=False` sets no limit of its own, for a call that keeps its own limits (an
        outer alarm would switch those off)."""
        seconds = seconds or self.options.seconds
        start = time.monotonic()
        try:
            if not hard:
                return fn()
            with hard_time_limit(seconds):
                return fn()
        except Timeout:
            self.notes.append(f"{label}: not shown (gave up after {seconds:g} s)")
        except UnsupportedError as exc:
            self.notes.append(f"{label}: unsupported: {exc.capability}")
        except (MechbookError, KeyError) as exc:
            self.notes.append(f"{label}: {exc}")
        except Exception as exc:  # noqa: BLE001 - one step must not take down the page
            self.notes.append(f"{label}: {type(exc).__name__}: {exc}")
        finally:
            if time.monotonic() - start > 1.0:
                self.timings.append((label, time.monotonic() - start))
        return None

    def readable(self, obj):
        """`obj` simplified for reading, within the per-expression and per-page limits."""
        if isinstance(obj, list | tuple):
            return [self.readable(o) for o in obj]
        if isinstance(obj, dict):
            return {k: self.readable(v) for k, v in obj.items()}
        if isinstance(obj, sp.MatrixBase):
            return obj.applyfunc(self.readable)
        if isinstance(obj, sp.Eq):
            return sp.Eq(self.readable(obj.lhs), self.readable(obj.rhs), evaluate=False)
        if not isinstance(obj, sp.Expr) or obj.is_Atom or self.budget <= 0:
            return obj
        start = time.monotonic()
        try:
            out = try_simplify(obj, min(self.options.simplify_seconds, self.budget))
        except Timeout:  # the alarm arrived just after simplify returned
            out = obj
        spent = time.monotonic() - start
        self.budget -= spent
        self.simplifying += spent
        return out

    def show(self, obj) -> str:
        """MathML of a derived result (simplified), or a note when it is too long."""
        obj = self.readable(obj)
        if len(sp.sstr(obj)) > LONGEST:
            return '<p class="note">too long to typeset here (see `mechbook solve`)</p>'
        return math(obj)


def build_page(pid: str, base: Path, figdir: Path, stored: dict | None,
               options: PageOptions = PageOptions()) -> dict:
    """Everything the problem's page shows, as plain data (HTML fragments, numbers, the
    figures written under `figdir`, named relative to it)."""
    start = time.monotonic()
    page = _Page(options, budget=options.simplify_budget)
    problem = load_problem(problem_path(pid, base))
    analysis = Analysis(problem)
    out = {"id": pid, "title": problem.title, "source": problem.source,
           "description": problem.description.strip(),
           "notes_text": str(problem.doc.data.get("notes", "")).strip(),
           "parameters": [(n, p.value, p.doc) for n, p in problem.parameters.items()],
           "conditions": [math(c, display=False) for c in problem.conditions],
           "systems": [], "parts": [], "crosscheck_figures": {}}
    apath = answer_path(pid, base)
    key = page.step("answer key", lambda: _answers(apath)) if apath.exists() else None
    for name in problem.systems:
        out["systems"].append(_system(page, analysis, name, figdir, _asked(page, analysis,
                                                                           key, name)))
    if key is not None:
        out["parts"] = _parts(page, analysis, key)
    for i, x in enumerate((stored or {}).get("crosschecks", [])):
        if x.get("kind") == "frequencies" and x.get("modes"):
            fig = page.step(f"cross-check figure {x['name']}", lambda x=x, i=i: (
                figures.crosscheck_frequencies(x["modes"], f"{pid}: {x['name']}",
                                               figdir / f"crosscheck-{i}.png")))
            if fig is not None:
                out["crosscheck_figures"][i] = fig.name
    out["page_notes"] = page.notes
    out["timings"] = page.timings + [("simplifying for display", page.simplifying)]
    out["seconds"] = time.monotonic() - start
    return out


def _answers(path: Path):
    from mechbook.verify.answers import load_answers

    return load_answers(path)


def _asked(page: _Page, analysis: Analysis, key, name: str) -> list[dict]:
    """The equilibria the answer parts name (`about:`) in system `name`."""
    from mechbook.verify.context import Context

    out = []
    for part in (key.parts if key else []):
        if "about" not in part.data or "steady" in part.data:
            continue
        if (part.system or next(iter(analysis.problem.systems))) != name:
            continue
        point = page.step(f"part {part.name}: its point",
                          lambda part=part: Context(analysis, part).point())
        if point is not None:
            out.append(point)
    return out


def _system(page: _Page, analysis: Analysis, name: str, figdir: Path,
            asked: list[dict]) -> dict:
    sys_ = page.step(f"system {name}", lambda: analysis.system(name))
    res = {"name": name, "doc": "", "coordinates": [], "blocks": [], "equilibria": [],
           "simulation": None}
    if sys_ is None:
        return res
    res["doc"] = str(sys_.spec.get("doc", ""))
    coords = sys_.spec.get("coordinates") or {}
    res["coordinates"] = [(c, str((coords.get(c) or {}).get("doc", "")))
                          for c in sys_.coord_names]
    blocks = res["blocks"]

    def block(title: str, label: str, fn) -> None:
        value = page.step(f"{title} ({name})", fn)
        if value is not None:
            blocks.append({"title": title, "math": page.show(value), "label": label})

    block("Lagrangian", "L", lambda: sys_.lagrangian)
    block("Kinetic energy", "T", lambda: sys_.kinetic)
    block("Potential energy", "V", lambda: sys_.potential)
    dyn = analysis.dynamics(name)

    def eom():
        lhs = dyn.mass_matrix * sp.Matrix(dyn.qdd)
        rhs = dyn.forcing
        if sys_.constraints:
            rhs = rhs + dyn.constraint_jacobian.T * sp.Matrix(dyn.multipliers)
        return [sp.Eq(a, b, evaluate=False) for a, b in zip(lhs, rhs, strict=True)]

    block("Equations of motion (Lagrange)", "eom", eom)
    block("Generalized momenta", "p", lambda: dict(zip(
        [sp.Symbol(f"p_{c}") for c in sys_.coord_names], dyn.momenta, strict=True)))
    cyclic = page.step(f"cyclic coordinates ({name})", lambda: dyn.cyclic)
    if cyclic:
        block("Cyclic coordinates: conserved momenta", "cyclic",
              lambda: {sp.Symbol(f"p_{q}"): p for q, p in cyclic.items()})
    conserved = page.step(f"energy ({name})", lambda: bool(dyn.energy_conserved))
    block("Energy function h = Σ q̇ ∂L/∂q̇ − L" + (" (conserved)" if conserved else
                                                    " (not conserved)"),
          "h", lambda: dyn.energy_function)
    if "hamiltonian" in (sys_.spec.get("compute") or []):
        block("Hamiltonian", "H", lambda: dyn.hamiltonian)
    res["equilibria"] = _equilibria(page, analysis, name, sys_, figdir, asked)
    if page.options.simulate:
        stable = [e["values"] for e in res["equilibria"] if e["stability"] == "stable"]
        res["simulation"] = _simulation(page, analysis, name, figdir, stable)
    for e in res["equilibria"]:
        del e["values"]  # SymPy objects stay in the worker
    return res


def _equilibria(page: _Page, analysis: Analysis, name: str, sys_, figdir: Path,
                asked: list[dict]) -> list[dict]:
    """The closed-form equilibria SymPy finds within the step's time (the engine's own
    limits), and the points the answer parts name."""
    found = page.step(f"equilibria ({name})",
                      lambda: analysis.equilibria(name).within(page.options.seconds / 2),
                      hard=False) or []
    if not found:
        page.notes.append(f"equilibria ({name}): none found in closed form within "
                          f"{page.options.seconds / 2:g} s; showing the points the answers name")
    points, seen = [], set()
    for point in [*found, *asked]:
        key = sp.srepr(sorted(point.items(), key=lambda kv: str(kv[0])))
        if key not in seen:
            seen.add(key)
            points.append(point)
    values = analysis.problem.values()
    out = []
    for i, point in enumerate(points[:MAX_POINTS]):
        entry = {"point": page.show(point), "stability": "", "frequencies": "",
                 "numeric": [], "modes": "", "figure": None, "values": point}
        out.append(entry)
        if any(v.has(sp.Float) for v in point.values()):
            continue
        lin = page.step(f"linearization about equilibrium {i + 1} ({name})",
                        lambda point=point: analysis.linear(name, point))
        if lin is None:
            continue
        entry["stability"] = page.step(f"stability {i + 1} ({name})",
                                       lambda lin=lin: lin.numeric_stability(values)) or ""
        freqs = page.step(f"frequencies about equilibrium {i + 1} ({name})",
                          lambda lin=lin: list(lin.frequencies))
        if freqs is not None:
            entry["frequencies"] = page.show(freqs)
        num = page.step(f"numeric frequencies {i + 1} ({name})",
                        lambda lin=lin: [float(w) for w in lin.numeric_frequencies(values)])
        entry["numeric"] = num or []
        if entry["stability"] in ("stable", "marginal") and not lin.gyroscopic:
            modes = page.step(f"normal modes {i + 1} ({name})",
                              lambda lin=lin: lin.numeric_modes(values))
            if modes is None:
                continue
            omegas = np.sqrt(np.clip(modes[0], 0, None))
            shapes = np.real(modes[1])
            shapes = shapes / np.where(np.abs(shapes).max(axis=0) > 0,
                                       shapes[np.abs(shapes).argmax(axis=0),
                                              range(shapes.shape[1])], 1.0)
            entry["modes"] = math(sp.Matrix(shapes.shape[0], shapes.shape[1],
                                            [sp.Float(x, 4) for x in shapes.flatten()]))
            fig = page.step(f"mode shapes {i + 1} ({name})", lambda omegas=omegas,
                            shapes=shapes, i=i: figures.mode_shapes(
                                omegas, shapes, list(sys_.coord_names),
                                f"{analysis.problem.id} [{name}]: normal modes about "
                                f"equilibrium {i + 1}", figdir / f"modes-{name}-{i + 1}.png"))
            entry["figure"] = fig.name if fig is not None else None
    return out


def _simulation(page: _Page, analysis: Analysis, name: str, figdir: Path,
                stable: list[dict]) -> dict | None:
    """A run from the system's `initial:`, or else at rest 0.1 away (in every coordinate)
    from the first stable equilibrium found above, or from an equilibrium found numerically
    at the default values, or from q = 0; the page says which."""
    from mechbook.numerics.plot import plot_simulation
    from mechbook.numerics.simulate import FALLBACK_OFFSET, simulate

    opts = page.options
    sys_ = analysis.system(name)
    init, source = None, ""
    if not sys_.spec.get("initial"):
        values = analysis.problem.values()
        if stable:
            start = [float(sp.N(stable[0].get(q, 0).subs(values))) for q in sys_.q]
            source = "the first stable equilibrium above"
        else:
            found = page.step(f"numeric equilibria ({name})",
                              lambda: analysis.equilibria(name).numeric(values))
            start = [float(x) for x in found[0]] if found else [0.0] * len(sys_.q)
            source = ("an equilibrium found numerically at the default values (its "
                      "stability not decided)" if found else "q = 0 (no equilibrium found)")
        # unequal offsets, so that a uniform translation is not all that moves
        init = {c: repr(x + FALLBACK_OFFSET * (1.0 if i == 0 else 0.5))
                for i, (c, x) in enumerate(zip(sys_.coord_names, start, strict=True))}
    def run():
        with warnings.catch_warnings():  # a run that blows up says so in its notes
            warnings.simplefilter("ignore", RuntimeWarning)
            return simulate(analysis, name, init=init, t_span=(0.0, opts.t_end), points=1001)

    sim = page.step(f"simulation ({name})", run, opts.simulate_seconds)
    if sim is None:
        return None
    traj = sim.trajectory
    if not len(traj.t):
        page.notes.append(f"simulation ({name}): no samples ({traj.message})")
        return None
    fig = page.step(f"simulation figure ({name})",
                    lambda: plot_simulation(sim, figdir / f"simulation-{name}.png"))
    return {"figure": fig.name if fig is not None else None,
            "drifts": [(d.name, float(d.relative)) for d in sim.drifts],
            "method": ", ".join(f"{k}={v}" for k, v in traj.settings.items()),
            "initial": ", ".join(f"{k} = {v:.4g}" for k, v in sim.initial.items()),
            "initial_source": (sim.initial_source if init is None else
                               f"at rest, {FALLBACK_OFFSET:g} ({FALLBACK_OFFSET / 2:g} in "
                               f"the other coordinates) from {source}"),
            "t_end": float(traj.t[-1]),
            "samples": len(traj.t), "notes": list(sim.notes)}


def _parts(page: _Page, analysis: Analysis, key) -> list[dict]:
    from mechbook.verify.context import Context

    rows = []
    for part in key.parts:
        data = part.data
        row = {"part": part.name, "cite": data.get("cite", ""), "quantity": part.quantity,
               "origin": data.get("origin", "book"), "system": part.system,
               "note": str(data.get("note", "")).strip(), "book": "", "engine": None,
               "numeric": None, "erratum": None, "unsupported": data.get("unsupported")}
        rows.append(row)
        ctx = page.step(f"part {part.name}", lambda part=part: Context(analysis, part))
        if ctx is None:
            continue
        row["book"] = page.step(f"part {part.name}: the book's value",
                                lambda ctx=ctx, data=data: book_math(ctx, data.get("book"))) or ""
        if "erratum" in data:
            err = data["erratum"]
            row["erratum"] = {
                "corrected": page.step(f"part {part.name}: corrected value",
                                       lambda ctx=ctx, err=err: book_math(
                                           ctx, err.get("corrected"), ("erratum",))) or "",
                "derivation": str(err.get("derivation", "")).strip()}
        if row["unsupported"]:
            continue
        value = page.step(f"part {part.name}: the engine's value",
                          lambda ctx=ctx: engine_value(ctx))
        if value is not None:
            row["engine"] = page.show(value)
        row["numeric"] = page.step(f"part {part.name}: values at one point",
                                   lambda ctx=ctx: numeric_pair(ctx))
    return rows
