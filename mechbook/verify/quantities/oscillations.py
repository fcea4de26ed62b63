"""Small oscillations: `frequencies`, `period`, `normal_modes`, `normal_coordinates`,
`mode_count`, `mode_node`, and the asymptotic (`limit:`) form of the first and third.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from mechbook.core.identity import nonzero_determinant
from mechbook.core.numeval import NotNumeric, evaluate_mp
from mechbook.core.words import plural
from mechbook.engine import perturbation
from mechbook.engine.linear import LinearSystem, secular_determinant
from mechbook.errors import MechbookError, UnsupportedError, WrongAnswerError
from mechbook.model.manifold import Freedoms
from mechbook.verify.asymptotic import asymptotic
from mechbook.verify.compare import Verdict, all_vanish, at_point, match_multiset, vanishes
from mechbook.verify.context import Context, numbers
from mechbook.verify.registration import EXPR, LIMIT, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity


def _book_frequencies(ctx: Context, val) -> list[sp.Expr]:
    return [ctx.parse(v, ("book", i)) for i, v in enumerate(ctx.as_list(val, ("book",)))]


@quantity('frequencies',
          book='list of ω',
          how=("multiset equality with the engine's normal frequencies at random points "
               '(numeric `eigh`, or state-space eigenvalues with gyroscopic terms), '
               'symbolic with `--prove` where each book ω² is proved a root of '
               'det(K − ω²M) of the multiplicity the book gives it (det M decided nonzero: '
               "no closed-form roots needed), or, with gyroscopic terms, equal to the "
               "engine's closed-form root; `partial: true` for a "
               'subset; `limit: {parameter, to: 0 or oo, order}` for asymptotic formulas'),
          keys={"partial": {"type": "boolean"},
                "limit": LIMIT},
          crosschecks=("modes",), display="frequency_list", sweeps=("frequencies",))
def check_frequencies(ctx: Context, val) -> Verdict:
    """Multiset of normal angular frequencies (numeric eigh at random points; symbolic where
    SymPy can); `partial: true` allows the book to list a subset; `limit:` compares an
    asymptotic formula."""
    book = _book_frequencies(ctx, val)
    lin = ctx.linear()
    partial = bool(ctx.part.data.get("partial"))
    if "limit" in ctx.part.data:
        return _check_limit(ctx, book, lin)
    n = 0
    for _ in range(6):
        pt = ctx.sampler.draw()
        ok, why = match_multiset(numbers(book, pt), list(lin.numeric_frequencies(pt)), partial)
        n += 1
        if not ok:
            return Verdict(False, f"numeric({plural(n, 'point')})", why + at_point(pt))
    precise = _precise_frequencies(ctx, book, lin, partial)
    if precise and not precise.ok:
        return precise
    how = f"numeric({plural(n, 'point')}, eigensolver" + (", 1 at 50 digits)" if precise else ")")
    power = f"{plural(n, 'point')} to 1e-8" + (f", 1 at 50 digits to {PRECISE_RTOL:g}"
                                                if precise else "")
    if partial:
        power += f"; partial: {len(book)} of {len(lin.q)} frequencies (the rest unchecked)"
    proved, why = _symbolic_frequencies(ctx, book, lin, partial)
    return Verdict(True, "symbolic" if proved else how, precise.detail if precise else "",
                   power=power, unproved=why)


PRECISE_RTOL = 1e-20  # book against engine frequencies, both at 50 digits


def _precise_frequencies(ctx: Context, book, lin: LinearSystem, partial: bool):
    """The double-precision pass resolves 1e-8; at one more point both sides are taken at
    50 digits (mpmath eigenvalues) and must agree to 1e-20, so an answer wrong by less than
    the eigensolver's rounding still fails. None where 50 digits mean nothing: numbers of
    double precision in the equations (a numeric equilibrium) or in the book, or an
    estimate."""
    entries = (list(lin.E) + list(lin.Ahat) if lin.first_order else
               list(lin.M) + list(lin.K) + list(lin.C))
    if ctx.sampler.rtol > 1e-10 or any(_has_doubles(x) for x in list(book) + entries):
        return None
    pt = ctx.sampler.draw()
    try:
        engine = [float("nan") if w != w else w for w in perturbation.precise_frequencies(lin, pt)]
    except (UnsupportedError, ZeroDivisionError, ValueError):
        return None
    import mpmath

    with mpmath.workdps(perturbation.DPS):
        values = []
        for b in book:
            try:
                v = evaluate_mp(b, pt, perturbation.DPS)
            except (NotNumeric, ZeroDivisionError, ValueError, TypeError):
                return None
            if abs(mpmath.im(v)) > PRECISE_RTOL * max(1, abs(v)):
                return None  # not real here: the double-precision pass has judged that
            values.append(mpmath.re(v))
        free = [e for e in engine if mpmath.isfinite(e)]
        worst = mpmath.mpf(0)
        for v in sorted(values):
            if not free:
                return Verdict(False, "numeric(50 digits)", "more book values than engine "
                               "frequencies" + at_point(pt))
            j = min(range(len(free)), key=lambda i: abs(free[i] - v))
            rel = abs(free[j] - v) / max(abs(v), mpmath.mpf(10) ** -30)
            worst = max(worst, rel)
            if rel > PRECISE_RTOL:
                return Verdict(False, "numeric(50 digits)",
                               f"book value {mpmath.nstr(v, 25)} differs from the engine's "
                               f"{mpmath.nstr(free[j], 25)} by a relative {float(rel):.2g} at "
                               f"50 digits (below double precision's reach)" + at_point(pt))
            free.pop(j)
        if free and not partial:
            return Verdict(False, "numeric(50 digits)",
                           "the engine has more frequencies" + at_point(pt))
    return Verdict(True, "numeric(50 digits)", f"at 50 digits within {float(worst):.1g}",
                   power=f"at 50 digits to {PRECISE_RTOL:g}")



def _has_doubles(x) -> bool:
    return isinstance(x, sp.Basic) and any(f._prec < 90 for f in x.atoms(sp.Float))


def _symbolic_frequencies(ctx, book, lin, partial) -> tuple[bool, str]:
    """(proved, why not): with `--prove`, do the engine's closed-form frequencies match the
    book's exactly? The numeric multiset comparison has already decided."""
    if not ctx.policy.prove:
        return False, ""
    if not (lin.first_order or lin.gyroscopic):
        try:
            return _secular_roots(ctx, book, lin)
        except (MechbookError, ValueError, TypeError, ZeroDivisionError) as exc:
            return False, f"the secular polynomial could not be formed ({type(exc).__name__})"
    if not hasattr(lin, "frequencies_at"):  # a first-order linearization (rolling, velocity
        # constraints): its frequencies are eigenvalues of the state matrix, numbers only
        return False, "no symbolic proof path for a first-order linearization's frequencies"
    pt = ctx.sampler.draw()
    try:
        engine = list(lin.frequencies_at(pt))  # the key's symbols (a steady rate) valued too
    except UnsupportedError:
        return False, "the engine's frequencies have no closed form here"
    eng_vals = numbers(engine, pt)
    used = set()
    for b in book:
        bv = numbers([b], pt)[0]
        idx = [i for i in range(len(engine)) if i not in used
               and abs(eng_vals[i] - bv) <= 1e-8 * max(1, abs(bv))]
        if not idx:
            return False, "no closed-form engine frequency to pair with"
        v = vanishes(b**2 - engine[idx[0]] ** 2, ctx.sampler)
        if v.method != "symbolic":
            return False, v.unproved
        used.add(idx[0])
    return True, ""


def _secular_roots(ctx: Context, book, lin: LinearSystem) -> tuple[bool, str]:
    """(proved, why not) without solving the secular equation: each book ω² is a root of
    P(w) = det(K − wM) of the multiplicity the book gives it (P and its first k − 1
    derivatives vanish there identically), values the book repeats are proved equal, and
    det M is decided nonzero, so P has degree n: n book values are then all its roots (the
    numeric pass has matched them as a multiset, which also tells the distinct ones
    apart)."""
    w = sp.Dummy("w")
    if not nonzero_determinant(lin.M):
        return False, "the mass matrix is not shown invertible"
    P = secular_determinant(lin.K - w * lin.M)
    pt = ctx.sampler.draw()
    squares = [b**2 for b in book]
    values = numbers(squares, pt)
    groups: list[list[int]] = []
    for i, v in enumerate(values):
        for grp in groups:
            if abs(values[grp[0]] - v) <= 1e-12 * max(1.0, abs(v)):
                grp.append(i)
                break
        else:
            groups.append([i])
    for grp in groups:
        first = squares[grp[0]]
        claims = [squares[i] - first for i in grp[1:]]
        claims += [sp.diff(P, w, j).subs(w, first) for j in range(len(grp))]
        v = all_vanish(claims, ctx.sampler)
        if not v.ok or v.method != "symbolic":
            return False, v.unproved or "a book value is not a root of det(K − ω²M)"
    return True, ""


def _check_limit(ctx: Context, book, lin: LinearSystem) -> Verdict:
    def error(pt) -> float:
        """The worst relative difference, book against engine, both at 50 digits (the walk
        toward the limit goes where the difference is far below double precision)."""
        import mpmath

        with mpmath.workdps(perturbation.DPS):
            eng = list(perturbation.precise_frequencies(lin, pt))
            worst = mpmath.mpf(0)
            for b in book:  # one-to-one: each engine frequency matches once
                try:
                    v = evaluate_mp(b, pt, perturbation.DPS)
                except (NotNumeric, ZeroDivisionError, ValueError, TypeError):
                    return float("inf")
                if abs(mpmath.im(v)) > mpmath.mpf(10) ** -40 * max(1, abs(v)):
                    return float("inf")  # a book value that is not real here fails
                v = mpmath.re(v)
                if not eng:
                    return float("inf")
                nearest = min(range(len(eng)), key=lambda i, v=v: abs(eng[i] - v))
                worst = max(worst, abs(eng.pop(nearest) - v) / max(abs(v), mpmath.mpf(10) ** -300))
            return float(worst)

    return asymptotic(ctx, error, floor=1e-40)


@quantity('period',
          book='expression',
          how="2π/ω for one of the engine's nonzero frequencies",
          crosschecks=("modes",), display="period_list")
def check_period(ctx: Context, val) -> Verdict:
    """2π/ω for one of the engine's nonzero frequencies."""
    period = ctx.parse(val, ("book",))
    lin = ctx.linear()
    for _ in range(6):
        pt = ctx.sampler.draw()
        p = numbers([period], pt)[0]
        freqs = [w for w in lin.numeric_frequencies(pt) if w > 0]
        if not any(abs(2 * np.pi / w - p) <= 1e-8 * p for w in freqs):
            return Verdict(False, "numeric", f"period {p:.10g} vs engine "
                           f"{[2 * np.pi / w for w in freqs]}" + at_point(pt))
    why = ""
    try:
        if ctx.policy.prove:
            tries = [vanishes(period - 2 * sp.pi / w, ctx.sampler)
                     for w in lin.frequencies if w != 0]
            if any(v.method == "symbolic" for v in tries):
                return Verdict(True, "symbolic", power="proved symbolically")
            why = "; ".join(dict.fromkeys(v.unproved for v in tries if v.unproved))
    except UnsupportedError:
        why = "the engine's frequencies have no closed form here"
    return Verdict(True, "numeric(6 points)",
                   power="6 points: 2π/ω matches one of the engine's frequencies to 1e-8",
                   unproved=why)


def _mode_residual(lin: LinearSystem, freq: sp.Expr, shape: sp.Matrix, pt: dict) -> float:
    M, C, K = lin.matrices(pt)
    w = numbers([freq], pt)[0]
    u = np.array(numbers(list(shape), pt))
    return _eig_residual(K, M, w**2, u) if np.any(u) else np.inf


def _eig_residual(K: np.ndarray, M: np.ndarray, w2: float, u: np.ndarray) -> float:
    """|(K − ω²M)u| relative to the size of its terms (norm-wise, robust to zero entries)."""
    r = (K - w2 * M) @ u
    scale = (np.linalg.norm(K, 2) + abs(w2) * np.linalg.norm(M, 2)) * np.linalg.norm(u)
    return float(np.linalg.norm(r) / max(scale, 1e-300))


@quantity('normal_modes',
          book='list of `{frequency, shape: {q: amplitude}}`',
          how=('(K − ω²M)u = 0: shapes compared up to scale and sign; any vector of a '
               'degenerate eigenspace passes; with `limit:`, each book mode must '
               'approach an engine mode (frequency and the angle between shapes) as the '
               'parameter goes to its limit; with `--prove`, `symbolic` where each '
               '(K − ω²M)u is proved 0 entry by entry (no velocity terms)'),
          keys={"limit": LIMIT},
          equivalent=("direction",),
          crosschecks=("modes",))
def check_normal_modes(ctx: Context, val) -> Verdict:
    """Each (frequency, shape) satisfies (K − ω²M)·u = 0: shape up to scale and sign, and any
    vector of a degenerate eigenspace is accepted."""
    lin = ctx.linear()
    modes = ctx.as_list(val, ("book",))
    if "limit" in ctx.part.data:
        return _modes_limit(ctx, modes, lin)
    for _ in range(5):
        pt = ctx.sampler.draw()
        for i, mode in enumerate(modes):
            mode = ctx.as_map(mode, ("book", i))
            freq = ctx.parse(mode["frequency"], ("book", i, "frequency"))
            shape = ctx.mode_shape(mode.get("shape"), ("book", i, "shape"))
            if abs(numbers([freq], pt)[0]) not in _near(lin.numeric_frequencies(pt),
                                                         numbers([freq], pt)[0]):
                return Verdict(False, "numeric", f"mode {i}: frequency not an engine "
                               "frequency" + at_point(pt))
            res = _mode_residual(lin, freq, shape, pt)
            if res > 1e-8:
                return Verdict(False, "numeric", f"mode {i}: (K - w^2 M) u relative residual "
                               f"{res:.3g}" + at_point(pt))
    return _proved_modes(ctx, modes, lin) if ctx.policy.prove else _numeric_modes()


def _numeric_modes() -> Verdict:
    return Verdict(True, "numeric(5 points)",
                   power="5 points: each (ω, shape) satisfies (K − ω²M)u = 0 to 1e-8 of its "
                   "scale (a shape up to its length)")


def _proved_modes(ctx: Context, modes: list, lin: LinearSystem) -> Verdict:
    """With `--prove`, after the numeric pass: each (K − ω²M)u proved 0 entry by entry
    (u is nonzero at the points drawn, so ω² is an eigenvalue and u its eigenvector)."""
    numeric = _numeric_modes()
    if lin.first_order or lin.gyroscopic:
        numeric.unproved = "gyroscopic or first-order modes: compared numerically"
        return numeric
    residuals = []
    for i, mode in enumerate(modes):
        mode = ctx.as_map(mode, ("book", i))
        freq = ctx.parse(mode["frequency"], ("book", i, "frequency"))
        shape = ctx.mode_shape(mode.get("shape"), ("book", i, "shape"))
        residuals += list((lin.K - freq**2 * lin.M) * shape)
    proof = all_vanish(residuals, ctx.sampler)
    if proof.ok and proof.method == "symbolic":
        return Verdict(True, "symbolic", power="proved symbolically: (K − ω²M)u = 0 for "
                       "each mode (a shape up to its length)")
    numeric.unproved = proof.unproved
    return numeric


def _modes_limit(ctx: Context, modes: list, lin: LinearSystem) -> Verdict:
    """Modes in a limit of the parameters: each book mode must approach one engine mode, in
    frequency (relative error) and in shape (the sine of the angle between the shapes)."""
    parsed = []
    for i, mode in enumerate(modes):
        mode = ctx.as_map(mode, ("book", i))
        parsed.append((ctx.parse(mode["frequency"], ("book", i, "frequency")),
                       ctx.mode_shape(mode.get("shape"), ("book", i, "shape"))))

    def error(pt) -> float:
        """The worst of each book mode's frequency error and the sine of its angle to the
        nearest engine mode, all at 50 digits (the walk toward the limit goes where they
        are far below double precision)."""
        import mpmath

        with mpmath.workdps(perturbation.DPS):
            w2, modes = perturbation.precise_modes(lin, pt)
            n = modes.rows
            vecs = []
            for j in range(modes.cols):
                v = [modes[i, j] for i in range(n)]
                norm = mpmath.sqrt(mpmath.fsum(x * x for x in v))
                vecs.append([x / norm for x in v])
            free = list(range(len(w2)))
            worst = mpmath.mpf(0)
            for freq, shape in parsed:
                try:
                    w = evaluate_mp(freq, pt, perturbation.DPS)
                    u = [evaluate_mp(x, pt, perturbation.DPS) for x in shape]
                except (NotNumeric, ZeroDivisionError, ValueError, TypeError):
                    return float("inf")
                if any(abs(mpmath.im(x)) > mpmath.mpf(10) ** -40 * max(1, abs(x))
                       for x in [w, *u]):
                    return float("inf")
                w, u = mpmath.re(w), [mpmath.re(x) for x in u]
                size = mpmath.sqrt(mpmath.fsum(x * x for x in u))
                if not free or size == 0:
                    return float("inf")
                best, pick = None, None
                for j in free:
                    v = vecs[j]
                    dot = mpmath.fsum(a * b for a, b in zip(u, v, strict=True))
                    # the sine of the angle, from the part of u off v (no cancellation)
                    off = mpmath.sqrt(mpmath.fsum((a - dot * b) ** 2
                                                  for a, b in zip(u, v, strict=True)))
                    dw = abs(mpmath.sqrt(abs(w2[j])) - w) / max(abs(w), mpmath.mpf(10) ** -300)
                    best_j = max(off / size, dw)
                    if best is None or best_j < best:
                        best, pick = best_j, j
                free.remove(pick)
                worst = max(worst, best)
            return float(worst)

    return asymptotic(ctx, error, floor=1e-40)



def _near(values, x, rtol=1e-8):
    return [x] if any(abs(v - x) <= rtol * max(1, abs(x)) for v in values) else []


@quantity('normal_coordinates',
          book='list of `{coordinate: linear form, frequency?}`',
          how=('c·q is a normal coordinate iff M⁻¹c is a mode (with velocity terms C, also '
               'an eigenvector of M⁻¹C: then C does not couple it); with `--prove`, '
               '`symbolic` where K·adj(M)·c is proved parallel to c (= ω²·det(M)·c with a '
               "frequency) and, with every coordinate given, the forms' determinant "
               'decided nonzero'),
          equivalent=("scale", "shift"),
          crosschecks=("modes",))
def check_normal_coordinates(ctx: Context, val) -> Verdict:
    """A linear form c·q is a normal coordinate iff u = M⁻¹c is a mode: (K − ω²M)u = 0."""
    lin = ctx.linear()
    items = ctx.as_list(val, ("book",))
    rows = []
    for _ in range(5):
        pt = ctx.sampler.draw()
        M, C, K = lin.matrices(pt)
        rows = []
        for i, item in enumerate(items):
            item = ctx.as_map(item, ("book", i))
            form = ctx.parse(item["coordinate"], ("book", i, "coordinate"))
            c = sp.Matrix([sp.diff(form, q) for q in ctx.system.q])
            if any(s in ctx.system.q for x in c for s in x.free_symbols):
                raise ctx.part.error(("book", i, "coordinate"), "a normal coordinate is linear "
                                     "in the coordinates")
            cv = np.array(numbers(list(c), pt))
            rows.append(cv)
            u = np.linalg.solve(M, cv)
            w2 = float(u @ K @ u / (u @ M @ u))
            if _eig_residual(K, M, w2, u) > 1e-8:
                return Verdict(False, "numeric", f"{item['coordinate']} is not a normal "
                               "coordinate (M^-1 c is not a mode)")
            if np.any(C) and _eig_residual(C, M, float(u @ C @ u / (u @ M @ u)), u) > 1e-8:
                return Verdict(False, "numeric", f"{item['coordinate']} is not a normal "
                               "coordinate: the velocity terms C couple it to the others")
            if "frequency" in item:
                w = numbers([ctx.parse(item["frequency"], ("book", i, "frequency"))], pt)[0]
                engine = lin.mode_frequency(c, pt)
                if abs(engine - w) > 1e-8 * max(1, w):
                    return Verdict(False, "numeric", f"{item['coordinate']}: frequency "
                                   f"{w:.10g}, engine {engine:.10g}")
        if len(rows) == len(ctx.system.q) and np.linalg.matrix_rank(np.array(rows)) < len(rows):
            return Verdict(False, "numeric", "the normal coordinates are not independent")
    numeric = Verdict(True, "numeric(5 points)",
                      power="5 points: M⁻¹c an eigenvector to 1e-8 (a form up to a factor), "
                      "ω to 1e-8")
    return _proved_normal_coordinates(ctx, items, lin, numeric) if ctx.policy.prove else numeric


def _proved_normal_coordinates(ctx: Context, items: list, lin: LinearSystem,
                               numeric: Verdict) -> Verdict:
    """With `--prove`, after the numeric pass: for each form c·q, v = K·adj(M)·c is
    parallel to c (v_i c_j = v_j c_i), or v = ω²·det(M)·c where the book gives ω; det M
    and, with every coordinate given, the forms' determinant decided nonzero. Then M⁻¹c
    is a mode, exactly."""
    if lin.first_order or lin.gyroscopic or not nonzero_determinant(lin.M):
        numeric.unproved = "velocity terms, or a mass matrix not shown invertible"
        return numeric
    adj, det = lin.M.adjugate(method="berkowitz"), lin.M.det(method="berkowitz")
    claims, rows = [], []
    for i, item in enumerate(items):
        item = ctx.as_map(item, ("book", i))
        form = ctx.parse(item["coordinate"], ("book", i, "coordinate"))
        c = sp.Matrix([sp.diff(form, q) for q in ctx.system.q])
        rows.append(list(c))
        v = lin.K * adj * c
        if "frequency" in item:
            w = ctx.parse(item["frequency"], ("book", i, "frequency"))
            claims += list(v - w**2 * det * c)
        else:
            n = len(c)
            claims += [v[a] * c[b] - v[b] * c[a] for a in range(n) for b in range(a + 1, n)]
    if len(rows) == len(ctx.system.q) and not nonzero_determinant(sp.Matrix(rows)):
        numeric.unproved = "the forms' independence is checked numerically only"
        return numeric
    proof = all_vanish(claims, ctx.sampler)
    if proof.method == "symbolic":
        return Verdict(True, "symbolic", power="proved symbolically: M⁻¹c is a mode of each "
                       "form (a form up to a factor)")
    numeric.unproved = proof.unproved
    return numeric


@quantity('mode_count',
          book='integer, or `{configuration: k, velocity: d}`',
          how=('the degrees of freedom: the coordinates less the rank of the constraints\' '
               'Jacobian, at the part\'s point (`about:`) or at 6 random states on the '
               'constraint manifold (40 digits). An integer is the number of independent '
               'velocities (virtual displacements: velocity constraints such as rolling count); '
               '`configuration:` and `velocity:` state the freedoms of the configuration '
               '(holonomic constraints only) and of the velocity apart'))
def check_mode_count(ctx: Context, val) -> Verdict:
    """Coordinates less the rank of the constraint Jacobian (holonomic, and with the
    velocity constraints), where the system moves (mechbook.model.manifold)."""
    want = _freedom_claim(ctx, val)
    found = _freedoms(ctx)
    got = {"configuration": found.configuration, "velocity": found.velocity}
    wrong = [k for k, v in want.items() if got[k] != v]
    bare = isinstance(val, int)  # the one count: the independent velocities
    said = str(val) if bare else ", ".join(f"{k} {v}" for k, v in want.items())
    engine = str(got["velocity"]) if bare else ", ".join(f"{k} {got[k]}" for k in want)
    if wrong:
        return Verdict(False, "exact", f"book {said}, engine {engine} degrees of freedom "
                       f"({len(ctx.system.q)} coordinates)")
    return Verdict(True, "exact", f"{engine} degrees of freedom ({len(ctx.system.q)} "
                   "coordinates)", power="exact: an integer")


def _freedom_claim(ctx: Context, val) -> dict[str, int]:
    if isinstance(val, bool):
        raise ctx.part.error(("book",), "expected an integer (or {configuration, velocity})")
    if isinstance(val, int):
        return {"velocity": val}
    val = ctx.as_map(val, ("book",))
    out = {}
    for k, v in val.items():
        if k not in ("configuration", "velocity"):
            raise ctx.part.error(("book", k), "the freedoms are `configuration` and `velocity`")
        if not isinstance(v, int) or isinstance(v, bool):
            raise ctx.part.error(("book", k), "expected an integer")
        out[k] = v
    if not out:
        raise ctx.part.error(("book",), "give `configuration`, `velocity` or both")
    return out


def _freedoms(ctx: Context) -> Freedoms:
    """The freedoms at the part's point, or the most frequent over random states (a rank
    drops only on a thin set: where the constraints are singular)."""
    manifold = ctx.sampler.manifold
    n = len(ctx.system.q)
    if manifold is None:
        return Freedoms(n, n)
    state = list(ctx.system.q) + list(ctx.system.qd)
    if "about" in ctx.part.data:
        pt = ctx.sampler.draw()
        at = {q: v.subs(pt) for q, v in ctx.point().items()}
        at.update({v: sp.S.Zero for v in ctx.system.qd})
        projected = manifold.project({**pt, **at, ctx.system.t: sp.S.Zero})
        if projected is None or any(abs(float(projected[q] - sp.N(at[q], 30))) > 1e-12
                                    for q in at if q in ctx.system.q):
            raise WrongAnswerError("the part's point does not satisfy the constraints")
        return manifold.freedoms(projected)
    seen: dict[Freedoms, int] = {}
    for _ in range(6):
        f = manifold.freedoms(ctx.sampler.draw(state))
        seen[f] = seen.get(f, 0) + 1
    return max(seen, key=lambda f: seen[f])


@quantity('mode_node',
          book='`{symbol: value}`',
          how=('the point (`position:`, linear in the displacements) does not move in '
               'the mode of `frequency:`'),
          keys={"position": EXPR,
                "frequency": EXPR},
          crosschecks=("modes",))
def check_mode_node(ctx: Context, val) -> Verdict:
    """A point whose position (linear in the small displacements) stays put in the mode of a
    given frequency: ∇position · u = 0. The book's value fixes the point's parameter."""
    book = ctx.as_map(val, ("book",))
    lin = ctx.linear()
    subs = {ctx.names[k]: ctx.parse(v, ("book", k)) for k, v in book.items()}
    position = ctx.parse(ctx.part.data["position"], ("position",)).subs(subs)
    freq = ctx.parse(ctx.part.data["frequency"], ("frequency",))
    point = lin.point
    grad = [sp.diff(position, q).subs(point) for q in ctx.system.q]
    for _ in range(5):
        pt = ctx.sampler.draw()
        _, vecs = lin.numeric_modes(pt)
        w = numbers([freq], pt)[0]
        # the engine's frequencies, ascending as the modes are: a zero mode's ω² decided at
        # 50 digits (in double its root is rounding of ~1e-8), an unstable mode's NaN
        freqs = lin.numeric_frequencies(pt)
        idx = [i for i, f in enumerate(freqs) if abs(f - w) <= 1e-8 * max(1, w)]
        if not idx:
            return Verdict(False, "numeric", "frequency is not an engine frequency")
        g = np.array(numbers(grad, pt))
        for i in idx:
            u = vecs[:, i]
            if abs(g @ u) > 1e-9 * (np.abs(g) @ np.abs(u)):
                return Verdict(False, "numeric", f"the point moves in that mode ({g @ u:.3g})")
    return Verdict(True, "numeric(5 points)",
                   power="5 points: the book's node does not move in the mode, to 1e-9")
