"""What `mechbook solve` shows and the store keeps: the results a problem's `compute:` asks for.

Each result is either text (a SymPy expression printed in the parser's own syntax, so it can
be read back) or a NumPy array evaluated at the problem's default parameter values.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from mechbook.engine.analysis import Analysis
from mechbook.engine.existence import existing
from mechbook.engine.growth import growth_rates
from mechbook.errors import MechbookError, UnsupportedError
from mechbook.records import Results

DEFAULT_COMPUTE = ["lagrangian", "eom", "momenta", "cyclic", "energy", "equilibria",
                   "small_oscillations"]


def show(expr, order: str | None = None) -> str:
    """expr (or lists and dicts of them) in the parser's own syntax. `order="none"`: the
    terms in SymPy's internal order, not sorted for a reader (for the store: sorting a
    sum's terms for printing is most of the time a long one takes, and the report reads
    the text back and typesets it in its own order)."""
    if isinstance(expr, (list, tuple)):
        return "[" + ", ".join(show(e, order) for e in expr) + "]"
    if isinstance(expr, dict):
        return "{" + ", ".join(f"{k}: {show(v, order)}" for k, v in expr.items()) + "}"
    return sp.sstr(expr, order=order)


def _stored(expr) -> str:
    return show(expr, "none")


def derive(analysis: Analysis, system: str | None = None,
           compute: list[str] | None = None) -> Results:
    sys = analysis.system(system)
    wanted = compute or sys.spec.get("compute") or DEFAULT_COMPUTE
    res = Results(sys.name)
    dyn = analysis.dynamics(sys.name)
    values = analysis.problem.values()

    def attempt(key, fn):
        try:
            fn()
        except UnsupportedError as exc:
            res.notes[key] = f"unsupported: {exc.capability}"

    if "lagrangian" in wanted:
        res.text["lagrangian"] = show(sp.simplify(sys.lagrangian))
        res.text["kinetic"] = show(sp.simplify(sys.kinetic))
        res.text["potential"] = show(sp.simplify(sys.potential))
    if "eom" in wanted:
        def eom():
            res.text["mass_matrix"] = show(dyn.mass_matrix.tolist())
            res.text["forcing"] = show(list(dyn.forcing))
            res.text["accelerations"] = show({a: s for a, s in dyn.solved.items()})
        attempt("eom", eom)
    if "momenta" in wanted:
        res.text["momenta"] = show(dict(zip(sys.q, dyn.momenta, strict=True)))
    if "cyclic" in wanted:
        res.text["cyclic"] = show(dyn.cyclic)
    if "energy" in wanted:
        res.text["energy_function"] = show(dyn.energy_function)
        res.text["energy_conserved"] = str(dyn.energy_conserved)
    if "hamiltonian" in wanted:
        def ham():
            res.text["hamiltonian"] = show(dyn.hamiltonian)
            qdot, pdot = dyn.hamilton_equations
            res.text["hamilton_qdot"] = show(qdot)
            res.text["hamilton_pdot"] = show(pdot)
        attempt("hamiltonian", ham)
    if "equilibria" in wanted or "small_oscillations" in wanted:
        def equilibria():
            eq = analysis.equilibria(sys.name)
            points, gone = existing(eq.symbolic, sys, values)  # real, inside the domains
            res.text["equilibria"] = show(points)
            if gone:
                res.notes["equilibria_left_out"] = (
                    f"{len(gone)} closed-form solution(s) do not exist at the default "
                    "values: " + "; ".join(gone))
            if not points:
                search = (sys.spec.get("equilibria") or {}).get("search")
                found = eq.numeric(values, _ranges(sys, search))
                res.notes["equilibria"] = "no closed form found; numeric equilibria at the " \
                    "default parameters stored as numeric/equilibria"
                if found:
                    res.arrays["equilibria"] = np.array(found)
                    points = [{q: _snap(x) for q, x in zip(sys.q, f, strict=True)}
                              for f in found]
            for i, point in enumerate(points):
                tag = f"equilibrium_{i}"
                if any(v.has(sp.Float) for v in point.values()):
                    res.notes[tag] = f"{show(point)}: numeric point, not linearized symbolically"
                    continue
                try:
                    lin = analysis.linear(sys.name, point)
                except UnsupportedError as exc:
                    res.notes[tag] = f"{show(point)}: unsupported: {exc.capability}"
                    continue
                res.text[f"{tag}/point"] = show(point)
                try:
                    res.text[f"{tag}/stability"] = lin.numeric_stability(values)
                    if not lin.gyroscopic and not lin.first_order:
                        res.text[f"{tag}/stable_if"] = show(lin.stability_condition)
                except (TypeError, ValueError):
                    res.notes[f"{tag}/stability"] = "does not evaluate at the default values"
                    continue
                if "small_oscillations" in wanted:
                    _oscillations(res, lin, tag, values)
        attempt("equilibria", equilibria)
    return res


def _snap(x: float) -> sp.Expr:
    """A numerically found coordinate: k*pi/12 exactly if it is that to 1e-10, else a Float."""
    k = round(x * 12 / np.pi)
    return k * sp.pi / 12 if abs(x - k * np.pi / 12) < 1e-10 else sp.Float(x)


def _ranges(sys, search: dict | None) -> dict | None:
    if not search:
        return None
    vals = sys.problem.values()
    return {sys.q[sys.coord_names.index(k)]: tuple(float(sys.parse(x, ("equilibria", "search",
            k, i)).subs(vals)) for i, x in enumerate(v)) for k, v in search.items()}


def _oscillations(res: Results, lin, tag: str, values: dict) -> None:
    if lin.first_order:
        _first_order(res, lin, tag, values, show)
        return
    res.text[f"{tag}/M"] = show(lin.M.tolist())
    res.text[f"{tag}/K"] = show(lin.K.tolist())
    if lin.gyroscopic:
        res.text[f"{tag}/C"] = show(lin.C.tolist())
    try:
        res.text[f"{tag}/frequencies"] = show(lin.frequencies)
    except UnsupportedError as exc:
        res.notes[f"{tag}/frequencies"] = f"unsupported: {exc.capability}"
    M, C, K = lin.matrices(values)
    res.arrays[f"{tag}/M"] = M
    res.arrays[f"{tag}/K"] = K
    res.arrays[f"{tag}/frequencies"] = lin.numeric_frequencies(values)
    res.arrays[f"{tag}/growth_rates"] = growth_rates(M, C, K)
    if not lin.gyroscopic:
        w2, modes = lin.numeric_modes(values)
        res.arrays[f"{tag}/modes"] = modes


def _first_order(res: Results, lin, tag: str, values: dict, text) -> None:
    """A first-order linearization (velocity constraints): its states, E and Â of
    E·ż = Â·z as text, and at the default values the state matrix A = E⁻¹Â, the exponents
    and the frequencies."""
    res.text[f"{tag}/states"] = text(lin.states)
    if lin.velocity:
        res.text[f"{tag}/rates"] = text(dict(lin.velocity))
    res.text[f"{tag}/E"] = text(lin.E.tolist())
    res.text[f"{tag}/Ahat"] = text(lin.Ahat.tolist())
    try:
        res.arrays[f"{tag}/A"] = lin.numeric_state_matrix(values)
        lam = lin.exponents(values)
        res.arrays[f"{tag}/exponents_real"] = lam.real
        res.arrays[f"{tag}/exponents_imag"] = lam.imag
        res.arrays[f"{tag}/frequencies"] = lin.numeric_frequencies(values)
    except (TypeError, ValueError, MechbookError, ZeroDivisionError) as exc:
        res.notes[f"{tag}/numeric"] = f"not evaluated at the default values: {exc}"


_DYNAMICS_TEXT = ("mass_matrix", "forcing", "momenta", "cyclic", "energy_function",
                  "hamiltonian")


DECLARED = "_declared"  # the store's name for a problem's declared vectors, tensors, bodies


def declared_results(analysis: Analysis) -> Results | None:
    """A problem's declared vectors and tensors, and each body's mass, centre of mass and
    inertia about it, if a check touched them (None otherwise)."""
    decl = analysis.built.declared_built()
    if decl is None:
        return None
    res = Results(DECLARED)
    values = analysis.problem.values()
    for name in decl.vectors + decl.tensors:
        obj = decl.names[name]
        res.text[name] = show(list(obj) if obj.shape == (3, 1) else obj.tolist())
        res.arrays[name] = _numeric(obj, values)
    for name, body in decl.bodies.items():
        res.text[f"{name}/mass"] = show(body.mass)
        res.text[f"{name}/center_of_mass"] = show(list(body.center_of_mass))
        inertia = body.inertia()
        res.text[f"{name}/inertia"] = show(inertia.tolist())
        res.arrays[f"{name}/inertia"] = _numeric(inertia, values)
    return res


def _numeric(obj, values: dict) -> np.ndarray:
    try:
        return np.array(sp.Matrix(obj).subs(values).evalf(), dtype=complex).real
    except (TypeError, ValueError):
        return np.full(sp.Matrix(obj).shape, np.nan)


def computed(analysis: Analysis) -> list[Results]:
    """What a check run derived on its way, as text and default-value arrays, per system
    (and the problem's declared objects): nothing is derived or simplified here (a check
    run stores what its parts needed)."""
    problem = analysis.problem
    values = problem.values()
    out = []
    extra = declared_results(analysis)
    if extra is not None:
        out.append(extra)
    for derived in analysis.derived():  # the systems built (validation builds them all)
        sys, dyn, eq = derived.system, derived.dynamics, derived.equilibria
        res = Results(sys.name)
        res.text["lagrangian"] = _stored(sys.lagrangian)
        res.text["kinetic"] = _stored(sys.kinetic)  # built with the system: nothing derived
        res.text["potential"] = _stored(sys.potential)
        if dyn is not None:
            for key in _DYNAMICS_TEXT:
                if key in vars(dyn):  # a cached_property that was evaluated
                    val = vars(dyn)[key]
                    if key == "momenta":
                        val = dict(zip(sys.q, val, strict=True))
                    res.text[key] = _stored(val.tolist() if hasattr(val, "tolist") else val)
        if eq is not None and eq.solved is not None:
            res.text["equilibria"] = _stored(eq.solved)
        for i, lin in enumerate(derived.linear):
            tag = f"linear_{i}"
            res.text[f"{tag}/point"] = _stored(lin.point)
            if lin.dyn.sys.reduced:
                res.text[f"{tag}/steady_momenta"] = _stored(lin.dyn.sys.held_momenta)
            if lin.first_order:
                _first_order(res, lin, tag, values, _stored)
                continue
            for m in ("M", "C", "K"):
                res.text[f"{tag}/{m}"] = _stored(getattr(lin, m).tolist())
            try:
                M, C, K = lin.matrices(values)
                res.arrays[f"{tag}/M"], res.arrays[f"{tag}/K"] = M, K
                res.arrays[f"{tag}/frequencies"] = lin.numeric_frequencies(values)
                res.arrays[f"{tag}/growth_rates"] = growth_rates(M, C, K)
            except (TypeError, ValueError, MechbookError, np.linalg.LinAlgError) as exc:
                # a point in an answer's own symbols (an orbit radius r0) has no numbers
                # at the default values: its text is stored all the same
                res.notes[f"{tag}/numeric"] = f"not evaluated at the default values: {exc}"
        out.append(res)
    return out
