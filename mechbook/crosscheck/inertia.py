"""Cross-check: each declared body's mass, centre of mass and inertia tensor, the engine's
(tabulated shapes, Rodrigues' rotations, the parallel-axis theorem) against an assembly by
integration over the shapes (mechbook/crosscheck/assembly.py), at random parameter points.

It vouches for the answer parts whose expressions name the body. A problem without a system
has no Newton or frequency check; its other parts get an `n.a.` cross-check saying so.
"""

from __future__ import annotations

import re

import numpy as np

from mechbook.crosscheck.assembly import composite_inertia
from mechbook.crosscheck.guard import guarded
from mechbook.engine.analysis import Analysis
from mechbook.records import CrossCheck, Status
from mechbook.verify.answers import AnswerKey
from mechbook.verify.compare import Sampler, value

TOL = 1e-20  # relative, in 30-digit arithmetic
POINTS = 6


def _mentions(part, body: str) -> bool:
    """Does the part's object or statement name the body (directly or through one of the
    key's abbreviations)?"""
    text = " ".join(str(v) for k, v in part.data.items()
                    if k in ("tensor", "book", "define", "equations"))
    for abbr, meaning in (part.key.doc.data.get("abbreviations") or {}).items():
        if re.search(rf"\b{re.escape(abbr)}\b", text):
            text += " " + str(meaning)
    return re.search(rf"\b{re.escape(body)}\b", text) is not None


def inertia_crosschecks(analysis: Analysis, key: AnswerKey | None) -> list[CrossCheck]:
    """One check per declared body, and an n.a. for the parts of a problem without a system
    that no body check covers."""
    problem = analysis.problem
    names = list(problem.doc.data.get("bodies") or {})
    parts = key.parts if key else []
    out = []
    covered: set[str] = set()
    for name in names:
        x = CrossCheck(f"inertia:{name}", "inertia", "",
                       parts=[p.name for p in parts if _mentions(p, name)])
        covered |= set(x.parts)
        with guarded(x, unsupported=Status.ERROR):  # a declared body's inertia always applies
            _compare(analysis, name, x)
        out.append(x)
    if not problem.systems:
        rest = [p.name for p in parts if p.name not in covered]
        if rest:
            out.append(CrossCheck("none", "none", "", Status.NA, parts=rest,
                                  detail="no system (tensors and bodies only): no Newton or "
                                  "frequency check applies"))
    return out


def _compare(analysis: Analysis, name: str, x: CrossCheck) -> None:
    problem = analysis.problem
    body = analysis.declared().bodies[name]
    engine = [body.mass, *body.center_of_mass, *body.inertia()]
    m, com, inertia = composite_inertia(problem, name)
    own = [m, *com, *inertia]
    sampler = Sampler(problem.values(), problem.conditions, seed=20261124)
    worst = 0.0
    used = 0
    for _ in range(POINTS * 3):
        if used >= POINTS:
            break
        point = sampler.draw()
        a = np.array([value(e, point) for e in engine])
        b = np.array([value(e, point) for e in own])
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
            continue
        used += 1
        scale = max(float(np.max(np.abs(a))), float(np.max(np.abs(b))), 1e-300)
        worst = max(worst, float(np.max(np.abs(a - b))) / scale)
    if used == 0:
        x.status, x.detail = Status.ERROR, "the body's inertia does not evaluate"
        return
    x.error = worst
    x.status = Status.PASS if worst < TOL else Status.FAIL
    x.detail = (f"mass, centre of mass and inertia about it: table + parallel axes vs "
                f"integration over {len(body.pieces)} part(s), {used} random points, max "
                f"relative difference {worst:.1e}")
