"""One problem's page of the report, built from what the check stored, in a worker process.

The check already derived, for the parts it judged, the Lagrangian and Lagrange's
equations, the equilibria SymPy found, and every linearization with its M, C, K and
frequencies (mechbook.engine.derive.computed): the page reads them back from the store
(mechbook.app.report.derivation) instead of deriving them again. Nothing is solved,
linearized or proved here; stability, frequencies, growth rates and mode shapes are numbers
from the stored matrices at the default values. What the check did not need and costs
little — the kinetic and potential energies (built with the system), momenta, the energy
function — is derived under a short limit; a short simulation of the full equations gives
the page its charts and the animation of the bodies. Only what is shown is simplified for
reading, each expression within `simplify_seconds` and all within `simplify_budget`; an
expression left as derived says so, and why, above it.

A step that fails or runs out leaves one line under "Not shown", with the reason in
words: never an exception's text. The outcomes themselves come from the store: this module
decides nothing.
"""

from __future__ import annotations

import html
import logging
import time
from dataclasses import dataclass, field
from pathlib import Path

import sympy as sp

from mechbook.app.output.mathml import math
from mechbook.app.report import svg
from mechbook.app.report.answer_parts import parts
from mechbook.app.report.derivation import StoredSystem
from mechbook.app.report.simplified import SimplifiedCache
from mechbook.app.report.systems import system_section
from mechbook.app.report.values import point_math
from mechbook.core.timeout import Timeout, hard_time_limit, time_limit
from mechbook.engine.analysis import Analysis
from mechbook.errors import MechbookError, UnsupportedError, describe
from mechbook.model.catalog import answer_path, problem_path
from mechbook.model.problem import load_problem
from mechbook.verify.answers import load_answers

LONGEST = 6000  # characters of SymPy text beyond which an expression is not typeset
MAX_POINTS = 8  # equilibria shown per system
SMALL = 30  # operations: an expression simplified even when the page's budget is spent
log = logging.getLogger("mechbook.faults")


@dataclass(frozen=True)
class PageOptions:
    seconds: float = 10.0  # limit of each step that computes
    # limit of each expression's simplification, and of all of one page's: spent once, as
    # the forms are kept (mechbook.app.report.simplified); the double pendulum's L takes
    # 1-3 s on a loaded machine
    simplify_seconds: float = 3.0
    simplify_budget: float = 15.0
    simulate: bool = True
    t_end: float = 10.0
    simulate_seconds: float = 10.0


@dataclass
class Page:
    """The page being built: its notes ("Not shown") and its time budgets."""

    options: PageOptions
    notes: list[str] = field(default_factory=list)
    budget: float = 0.0
    timings: list[tuple[str, float]] = field(default_factory=list)  # the slow steps
    simplifying: float = 0.0
    raw: set = field(default_factory=set)  # why expressions were left as derived
    kept: SimplifiedCache = field(default_factory=lambda: SimplifiedCache(None))

    def step(self, label: str, fn, seconds: float | None = None):
        """fn() within the step limit; None (and a line under "Not shown") if it cannot."""
        seconds = seconds or self.options.seconds
        start = time.monotonic()
        try:
            with hard_time_limit(seconds):
                return fn()
        except Timeout:
            self.notes.append(f"{label}: not shown (it takes longer than {seconds:g} s)")
        except UnsupportedError as exc:
            self.notes.append(f"{label}: not shown (the engine cannot do this yet: "
                              f"{exc.capability})")
        except MechbookError as exc:
            self.notes.append(f"{label}: not shown ({_short(str(exc))})")
        except Exception as exc:  # noqa: BLE001 - one step must not take down the page
            describe(exc)  # the traceback goes to the debug log
            self.notes.append(f"{label}: not shown (the engine could not evaluate it)")
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
        if isinstance(obj, sp.Equality):
            return sp.Eq(self.readable(obj.lhs), self.readable(obj.rhs), evaluate=False)
        if not isinstance(obj, sp.Expr) or obj.is_Atom:
            return obj
        if self.options.simplify_seconds > 0:
            kept = self.kept.get(obj)  # simplified on an earlier run: nothing to spend
            if kept is not None:
                return kept
        seconds = min(self.options.simplify_seconds, self.budget)
        if seconds <= 0 < self.options.simplify_seconds and sp.count_ops(obj) <= SMALL:
            seconds = self.options.simplify_seconds  # past the budget, but costs little
        if seconds <= 0:
            self.raw.add(UNSIMPLIFIED["off" if self.options.simplify_seconds <= 0
                                      else "budget"].format(o=self.options))
            return obj
        start = time.monotonic()
        try:
            with time_limit(seconds):
                out = sp.simplify(obj)
            self.kept.put(obj, out)
        except Timeout:  # too long (or the alarm arrived just after simplify returned)
            out = obj
            why = "slow" if seconds >= self.options.simplify_seconds else "budget"
            self.raw.add(UNSIMPLIFIED[why].format(o=self.options))
        spent = time.monotonic() - start
        self.budget -= spent
        self.simplifying += spent
        return out

    def show(self, obj, simplify: bool = True) -> str:
        """MathML of a result (simplified for reading) — with a note saying so when it is
        shown as derived, unsimplified, and why — or a note when it is too long."""
        self.raw = set()
        if simplify:
            obj = self.readable(obj)
        if len(sp.sstr(obj)) > LONGEST:
            return ('<p class="note">too long to typeset here (`mechbook solve` prints '
                    "it)</p>")
        if not simplify and _compound(obj):
            self.raw.add("shown as derived")
        note = "".join(f'<p class="note unsimplified">not simplified: {html.escape(why)}</p>'
                       for why in sorted(self.raw))
        return note + math(obj)


UNSIMPLIFIED = {  # why an expression is shown as the engine derived it
    "slow": "simplifying it takes longer than {o.simplify_seconds:g} s "
            "(mechbook report --simplify-seconds)",
    "budget": "the page's {o.simplify_budget:g} s for simplifying were spent "
              "(mechbook report --simplify-seconds raises both)",
    "off": "simplification is off (--simplify-seconds 0)",
}


def _compound(obj) -> bool:
    """Something a simplification could change (not a lone number or symbol)."""
    if isinstance(obj, list | tuple):
        return any(_compound(o) for o in obj)
    if isinstance(obj, dict):
        return any(_compound(v) for v in obj.values())
    if isinstance(obj, sp.MatrixBase | sp.Equality):
        return any(_compound(a) for a in (obj if isinstance(obj, sp.MatrixBase)
                                         else obj.args))
    return isinstance(obj, sp.Expr) and not obj.is_Atom


def _short(text: str) -> str:
    """A message's first line, without a file path prefix."""
    first = (text.strip().splitlines() or [""])[0]
    return first if len(first) <= 300 else first[:297] + "..."


def build_page(pid: str, base: Path, stored: dict | None,
               options: PageOptions = PageOptions(), kept: Path | None = None) -> dict:
    """Everything the problem's page shows, as plain data (HTML fragments, numbers); the
    simplified forms kept under `kept` are reused and new ones added
    (mechbook.app.report.simplified)."""
    start = time.monotonic()
    page = Page(options, budget=options.simplify_budget, kept=SimplifiedCache(kept))
    problem = load_problem(problem_path(pid, base))
    analysis = Analysis(problem)
    out = {"id": pid, "title": problem.title, "source": problem.source,
           "description": problem.description.strip(),
           "notes_text": str(problem.doc.data.get("notes", "")).strip(),
           "parameters": [(n, p.value, p.doc) for n, p in problem.parameters.items()
                          if not _coefficient(problem, n)],
           "conditions": [math(c, display=False) for c in problem.conditions],
           "defaults": page.step("the default values", lambda: point_math(problem.values(),
                                                                          problem)) or "",
           "systems": [], "parts": [], "crosscheck_figures": {}}
    apath = answer_path(pid, base)
    key = page.step("the answer key", lambda: _answers(apath)) if apath.exists() else None
    stored_systems = (stored or {}).get("systems") or {}
    views: dict[str, StoredSystem] = {}
    for name in problem.systems:
        section, view = system_section(page, analysis, name, stored_systems.get(name), key)
        out["systems"].append(section)
        if view is not None:
            views[name] = view
    if key is not None:
        out["parts"] = parts(page, analysis, key, views)
    for i, x in enumerate((stored or {}).get("crosschecks", [])):
        if x.get("kind") == "frequencies" and x.get("modes"):
            chart = page.step(f"cross-check chart {x['name']}", lambda x=x: (
                svg.frequencies_chart(x["modes"], f"{pid}: {x['name']}")))
            if chart is not None:
                out["crosscheck_figures"][i] = chart
    out["page_notes"] = page.notes
    out["timings"] = page.timings + [("simplifying for display", page.simplifying)]
    out["seconds"] = time.monotonic() - start
    return out


def _coefficient(problem, name: str) -> bool:
    """A parameter that is a coefficient of an arbitrary function (shown with it)."""
    return any(name.startswith(f + "_c") for f in problem.functions)


def _answers(path: Path):
    return load_answers(path)
