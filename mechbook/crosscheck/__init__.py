"""Independent cross-checks of the engine, run beside the answer key's checks.

None of them looks at the book's answers. Which of them vouch for a part is declared by its
quantity's registration (`crosschecks=`, names in vouch.py):
    frequencies  normal frequencies measured from a simulation of the nonlinear equations
    newton       the engine's equations against Newton's and Euler's laws, with kinematics
                 computed here independently (kinematics.py)
    conserved    the book's first integrals constant along a simulated trajectory
    response     a steady-state amplitude measured from the driven nonlinear motion
                 (frequencies.py also measures damped modes' decay rates)
    amplitude    the frequency measured at a finite amplitude (for `mechbook sweep
                 --quantity drift`: where the linear answer stops being good)
    motion       steady motions kept by a simulation; trajectory quantities of the level
                 set measured by integration
    inertia      each declared body's inertia: the engine's table and parallel axes against
                 integration over its parts (assembly.py)

May import: mechbook.verify (how an answer part names its point: `about:`, `steady:`,
`assume:`), mechbook.numerics, mechbook.engine (the results under test), mechbook.core,
mechbook.model — but never the engine's kinematics `mechbook.model.bodies` (a test
enforces it). Outcomes: pass · fail · n.a. (does not apply, with the reason) · error (the
check itself could not run: counts as a fail).
"""

from __future__ import annotations

import time

import sympy as sp

from mechbook.crosscheck.frequencies import frequency_crosscheck
from mechbook.crosscheck.inertia import inertia_crosschecks
from mechbook.crosscheck.motion import steady_crosscheck, trajectory_crosscheck
from mechbook.crosscheck.newton import newton_crosscheck
from mechbook.crosscheck.vouch import crosschecks_of
from mechbook.engine.analysis import Analysis
from mechbook.errors import UnsupportedError, describe
from mechbook.records import CrossCheck
from mechbook.verify.answers import AnswerKey
from mechbook.verify.context import Context  # how a part names its point


# ---- one problem -------------------------------------------------------------------------------
def _numeric_key(lin, values: dict, params: set) -> tuple:
    """What makes two cross-checks the same: system, steady or not, the point and the
    parameter values, numerically (so `pi - acos(x)` and `acos(-x)` coincide)."""
    sys_lin = lin.dyn.sys
    steady = tuple(sorted(map(str, sys_lin.momenta))) if hasattr(sys_lin, "base") else ()
    point = []
    for q in lin.q:
        try:
            point.append(round(float(sp.N(sp.S(lin.point.get(q, 0)).subs(values))), 9))
        except (TypeError, ValueError):
            point.append(str(lin.point.get(q, 0)))
    pv = tuple(sorted((str(k), round(float(v), 12)) for k, v in values.items() if k in params))
    return (steady, tuple(point), pv)


def _point_label(lin) -> str:
    sys_lin = lin.dyn.sys
    pt = ", ".join(f"{q}: {sp.sstr(lin.point.get(q, 0))}" for q in lin.q)
    if hasattr(sys_lin, "base"):
        cyc = ", ".join(f"p_{c}" for c in sys_lin.momenta)
        return f"{{{pt}}} steady ({cyc} fixed)"
    return "{" + pt + "}"


def crosscheck_problem(analysis: Analysis, key: AnswerKey | None = None,
                       stage=lambda text: None) -> list[CrossCheck]:
    """Every cross-check of a problem: Newton per system, frequencies per linear system the
    answer key refers to and per stable equilibrium the engine derives. `stage` is told
    which check is running (a batch reports it if the problem runs out of time)."""
    problem = analysis.problem
    out: list[CrossCheck] = []
    newton: dict[str, CrossCheck] = {}
    for name in problem.systems:
        stage(f"cross-check newton:{name}")
        try:
            newton[name] = newton_crosscheck(analysis, name)
        except Exception as exc:  # a fault here must not hide the other checks
            newton[name] = CrossCheck(f"newton:{name}", "newton", name, "error",
                                      detail=_fault(exc))
    only = next(iter(problem.systems)) if len(problem.systems) == 1 else None
    freq: dict[tuple, CrossCheck] = {}
    models: dict = {}
    measured: dict = {}
    params = set(problem.values())
    for part in (key.parts if key else []):
        if "unsupported" in part.data:
            continue
        sname = part.system or only
        vouch = crosschecks_of(part.quantity)  # the names its registration declares
        if "newton" in vouch and sname in newton:
            newton[sname].parts.append(part.name)
        if "first_integrals" in vouch or "energy_integral" in vouch:
            stage(f"cross-check conserved:{part.name}")
            x = _guarded_conserved(analysis, part, models)
            if x is not None:
                out.append(x)
        if "steady" in vouch:
            tag = (sname, "steady", repr(part.data.get("about")), part.data.get("unknown"),
                   repr(part.data.get("hold")), repr(part.data.get("assume")),
                   repr(part.data.get("estimate")))
            if tag in measured:
                measured[tag].parts.append(part.name)
            else:
                stage(f"cross-check steady:{part.name}")
                measured[tag] = steady_crosscheck(analysis, part)
                out.append(measured[tag])
        if "trajectory" in vouch:
            tag = (sname, part.quantity, repr(part.data.get("initial")),
                   part.data.get("coordinate"), part.data.get("rate"))
            if tag in measured:
                measured[tag].parts.append(part.name)
            else:
                stage(f"cross-check measured:{part.name}")
                measured[tag] = trajectory_crosscheck(analysis, part)
                out.append(measured[tag])
        if "modes" not in vouch:
            continue
        try:
            ctx = Context(analysis, part)
            lin = ctx.linear()
            values = ctx.sampler.default()
        except UnsupportedError as exc:
            tag = (sname, "n.a.", part.name)
            freq[tag] = CrossCheck(f"modes:{sname}", "frequencies", sname or "", "n.a.",
                                   detail=f"no linear system: {exc.capability}")
            freq[tag].parts.append(part.name)
            continue
        except Exception as exc:  # noqa: BLE001 - the part's own check reports it too
            tag = (sname, "error", part.name)
            freq[tag] = CrossCheck(f"modes:{sname}", "frequencies", sname or "", "error",
                                   detail=_fault(exc))
            freq[tag].parts.append(part.name)
            continue
        if "response" in vouch:
            stage(f"cross-check response:{part.name}")
            out.append(_guarded_response(analysis, ctx, lin, values, part, models))
        label = _point_label(lin)
        tag = (sname, *_numeric_key(lin, values, params))
        if tag not in freq:
            stage(f"cross-check modes:{sname}@{label}")
            freq[tag] = _guarded_frequency(analysis, lin, values, f"modes:{sname}@{label}",
                                           models)
        freq[tag].parts.append(part.name)
    for name in problem.systems:  # the engine's own stable equilibria
        stage(f"cross-check: the engine's own equilibria of {name}")
        try:
            engine_systems = _engine_linear_systems(analysis, name, freq)
        except Exception as exc:  # noqa: BLE001 - reported, never hidden
            freq[(name, "engine-error")] = CrossCheck(f"modes:{name}", "frequencies", name,
                                                      "error", detail=_fault(exc))
            continue
        for lin, label in engine_systems:
            values = dict(problem.values())
            tag = (name, *_numeric_key(lin, values, params))
            if tag not in freq:
                stage(f"cross-check modes:{name}@{label}")
                freq[tag] = _guarded_frequency(analysis, lin, values, f"modes:{name}@{label}",
                                               models)
    out += list(newton.values()) + list(freq.values())
    stage("cross-check: declared bodies")
    out += inertia_crosschecks(analysis, key)
    return out


def _guarded_conserved(analysis: Analysis, part, models: dict) -> CrossCheck | None:
    """The simulation cross-check of a part's first integral (None: the part states none)."""
    from mechbook.crosscheck.conserved import book_integrals, conserved_crosscheck
    from mechbook.verify.context import Context

    start = time.perf_counter()
    x = CrossCheck(f"conserved:{part.name}", "conserved", part.system or "", "error",
                   parts=[part.name])
    try:
        ctx = Context(analysis, part)
        exprs = book_integrals(ctx)
        if not exprs:
            return None
        x.status, x.error, x.detail = conserved_crosscheck(analysis, ctx, exprs, models)
    except UnsupportedError as exc:
        x.status, x.detail = "n.a.", exc.capability
    except Exception as exc:  # noqa: BLE001 - reported, never hidden
        x.detail = _fault(exc)
    x.seconds = time.perf_counter() - start
    return x


def _guarded_response(analysis, ctx, lin, values, part, models) -> CrossCheck:
    """The driven simulation of a steady-amplitude part (crosscheck.response)."""
    from mechbook.crosscheck.response import response_crosscheck
    from mechbook.verify.compare import value

    try:
        omega = value(ctx.parse(part.data["frequency"], ("frequency",)), values).real
        x = response_crosscheck(analysis, lin, values, omega, f"response:{part.name}", models)
    except Exception as exc:  # noqa: BLE001 - reported, never hidden
        x = CrossCheck(f"response:{part.name}", "response", part.system or "", "error",
                       detail=_fault(exc))
    x.parts.append(part.name)
    return x


def _fault(exc: BaseException) -> str:
    """A message (the tool's own errors say what is wrong; the traceback of anything else
    goes to the debug log, `mechbook check -v`)."""
    return describe(exc)


def _guarded_frequency(analysis, lin, values, name, models) -> CrossCheck:
    try:
        return frequency_crosscheck(analysis, lin, values, name, models)
    except Exception as exc:  # a fault here must not hide the other checks
        return CrossCheck(name, "frequencies", "", "error", detail=_fault(exc))


def _engine_linear_systems(analysis: Analysis, name: str, checked: dict) -> list[tuple]:
    """Linear systems about the stable equilibria of `name` at the default values (when the
    system asks for small oscillations) that no check in `checked` (tags as
    `_numeric_key` makes them) has linearized yet. Found numerically (mechbook.engine.screen):
    no part asks for a closed form here, and SymPy's search would mostly spend its time
    limit on transcendental conditions and find nothing."""
    from mechbook.engine.screen import screen, snap

    sys = analysis.system(name)
    compute = sys.spec.get("compute")
    if compute is not None and "small_oscillations" not in compute:
        return []
    values = analysis.problem.values()
    try:
        found = screen(analysis.equilibria(name), values)
    except UnsupportedError:
        return []
    pv = tuple(sorted((str(k), round(float(v), 12)) for k, v in values.items()))
    done = [tag[2] for tag in checked if len(tag) == 4 and tag[0] == name and tag[1] == ()
            and tag[3] == pv and all(isinstance(x, float) for x in tag[2])]
    out = []
    for f in found.found:
        if not (f.isolated and f.stability == "stable"):
            continue
        if any(found.same(f.point, d) for d in done):
            continue
        point = {q: snap(x) for q, x in zip(sys.q, f.point, strict=True)}
        try:
            lin = analysis.linear(name, point)
            if lin.numeric_stability(values) != "stable" and not _marginal_ok(lin, values):
                continue
        except (UnsupportedError, TypeError, ValueError):
            continue
        done.append(tuple(f.point))
        out.append((lin, _point_label(lin)))
    return out


def _marginal_ok(lin, values) -> bool:
    """A marginal point (zero modes, e.g. a free translation) with the rest oscillating."""
    try:
        return lin.numeric_stability(values) == "marginal"
    except (TypeError, ValueError):
        return False

