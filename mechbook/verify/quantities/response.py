"""Linear response: `matrices`, `characteristic_polynomial`, `exponents`, `decay_rates`,
`complex_modes`, `steady_amplitude`, `resonances`, `simultaneous_diagonalization`.

The answers of damped, gyroscopic and driven systems: the engine's side comes from
mechbook.engine.response (state-space eigenproblem, harmonic response); every comparison
is numeric at random admissible parameter points. Complex numbers in a book value are
written with sqrt(-1).
"""

from __future__ import annotations

import mpmath
import numpy as np
import sympy as sp

from mechbook.core.words import plural
from mechbook.engine import response
from mechbook.errors import UnsupportedError
from mechbook.verify.compare import Verdict, all_vanish, combine, equal, symbolic_or, value
from mechbook.verify.context import Context
from mechbook.verify.registration import EXPR, Family
from mechbook.verify.response_proof import (
    prove_characteristic_polynomial,
    prove_complex_modes,
    prove_exponents,
    prove_normal_transformation,
    prove_simultaneous_diagonalization,
    prove_steady_amplitude,
)

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

POINTS = 5
RTOL = 1e-8  # eigenvalue problems: relative to the largest exponent


def complex_numbers(exprs, pt) -> list[complex]:
    return [value(e, pt) for e in exprs]


def match_complex(book: list[complex], engine: list[complex], partial: bool,
                  rtol: float = RTOL) -> tuple[bool, str]:
    """Multiset equality (book ⊆ engine if partial) of complex numbers."""
    if any(not np.isfinite(b) for b in book):
        return False, "book value does not evaluate here"
    if not partial and len(book) != len(engine):
        return False, f"book has {len(book)} values, engine {len(engine)}: " \
                      f"{_fmt(book)} vs {_fmt(engine)}"
    scale = max([abs(x) for x in list(book) + list(engine)] + [1e-300])
    free = list(engine)
    for b in book:
        i = min(range(len(free)), key=lambda k: abs(free[k] - b), default=None)
        if i is None or abs(free[i] - b) > rtol * scale:
            return False, f"book value {_c(b)} is not among the engine's {_fmt(engine)}"
        free.pop(i)
    return True, ""


def _c(z: complex) -> str:
    return f"{z.real:.8g}" if abs(z.imag) < 1e-12 * max(1, abs(z)) else f"{z:.8g}"


def _fmt(xs) -> str:
    return "[" + ", ".join(_c(x) for x in xs) + "]"


def _matrix(ctx: Context, rows, sub) -> sp.Matrix:
    n = len(ctx.linear().q)
    rows = ctx.as_list(rows, sub)
    if len(rows) != n or any(not isinstance(r, list) or len(r) != n for r in rows):
        raise ctx.part.error(sub, f"expected a {n}x{n} matrix (rows and columns in the order "
                             "of the problem's coordinates)")
    return sp.Matrix([[ctx.parse(x, sub + (i, j)) for j, x in enumerate(r)]
                      for i, r in enumerate(rows)])


@quantity('matrices',
          book='`{M, K, C or B or G: rows}`',
          how=('each given matrix of the linearized equations M·δq̈ + C·δq̇ + K·δq = F equals '
               "the engine's, entry by entry (rows and columns in the problem's coordinate "
               'order); B is the symmetric (friction) part of C, G its antisymmetric '
               '(gyroscopic) part'),
          crosschecks=("modes",))
def check_matrices(ctx: Context, val) -> Verdict:
    val = ctx.as_map(val, ("book",))
    lin = ctx.linear()
    engine = {"M": lin.M, "K": lin.K, "C": lin.C,
              "B": (lin.C + lin.C.T) / 2, "G": (lin.C - lin.C.T) / 2}
    unknown = set(val) - set(engine)
    if unknown:
        raise ctx.part.error(("book", sorted(unknown)[0]), "matrices are M, K, C, B or G")
    verdicts = []
    for name, rows in val.items():
        book = _matrix(ctx, rows, ("book", name))
        for i in range(book.rows):
            for j in range(book.cols):
                v = equal(book[i, j], engine[name][i, j], ctx.sampler)
                if not v.ok:
                    return Verdict(False, v.method, f"{name}[{i + 1},{j + 1}]: {v.detail}")
                verdicts.append(v)
    return combine(verdicts)


def _exponent_map(ctx: Context):
    """The book's variable and p as a function of it (`variable:`, `exponent:`)."""
    name = ctx.part.data.get("variable", "p")
    if name in ctx.names and not isinstance(ctx.names[name], sp.Symbol):
        raise ctx.part.error(("variable",), f"{name!r} is not a plain symbol")
    var = sp.Symbol(name)
    names = dict(ctx.names)
    names[name] = var
    exponent = ctx.parse(ctx.part.data.get("exponent", name), ("exponent",), names=names)
    return var, names, exponent


@quantity('characteristic_polynomial',
          book='polynomial in `variable:` (default p)',
          how=('its roots, mapped to exponents by `exponent:` (p as a function of the '
               'variable, one to one; default p itself), are the 2n exponents p of e^{pt} '
               'solutions of the linearized equations, with multiplicity (mpmath roots and '
               'eigenvalues at 40 digits, at 5 points); write a secular equation in ω as a '
               'polynomial in ω with `exponent: sqrt(-1)*omega`; with `--prove`, `symbolic` where '
               'the exponent is linear in the variable, p = a·x + b, and lc(P)·D(a·x + b) = '
               'lc(D)·P(x) is proved coefficient by coefficient, D(p) = det(Mp² + Cp + K), '
               'both of degree 2n (the same roots with multiplicity), det M decided nonzero'),
          keys={"variable": {"type": "string", "pattern": "^[A-Za-z][A-Za-z0-9_]*$"},
                "exponent": EXPR},
          names=lambda ctx: _exponent_map(ctx)[1],
          complex_values=True,
          crosschecks=("modes",))
def check_characteristic_polynomial(ctx: Context, val) -> Verdict:
    var, names, exponent = _exponent_map(ctx)
    poly_expr = ctx.parse(val, ("book",), names=names)
    if not poly_expr.has(var):
        raise ctx.part.error(("book",), f"the polynomial does not contain {var}")
    lin = ctx.linear()
    for k in range(POINTS):
        pt = ctx.sampler.draw()
        engine = list(response.exponents(lin, pt, precise=True))
        try:
            coeffs = sp.Poly(sp.expand(poly_expr.subs(pt)), var).all_coeffs()
        except sp.PolynomialError:
            raise ctx.part.error(("book",), f"not a polynomial in {var}") from None
        with mpmath.workdps(40):
            roots = mpmath.polyroots([mpmath.mpmathify(complex(sp.N(c, 40))) for c in coeffs],
                                     maxsteps=400, extraprec=400)
            if not isinstance(roots, list):
                roots = [roots]
            mapped = [value(exponent, {**pt, var: sp.Float(str(mpmath.re(r)), 40)
                                       + sp.I * sp.Float(str(mpmath.im(r)), 40)})
                      for r in roots]
        ok, why = match_complex(mapped, engine, partial=False, rtol=1e-7)
        if not ok:
            return Verdict(False, f"numeric({plural(k + 1, 'point')})", why)
    numeric = Verdict(True, f"numeric({POINTS} points, 40 digits)",
                      power=f"{POINTS} points: its roots are the exponents, to 1e-7, at 40 "
                            "digits")
    if not ctx.policy.prove:
        return numeric
    return symbolic_or(numeric, prove_characteristic_polynomial(lin, poly_expr, var, exponent,
                                                                 ctx.sampler),
                        "proved symbolically: lc(P)·det(Mp² + Cp + K) = lc(D)·P, of degree 2n, "
                        "with p the exponent map (a multiset of roots)")


def _book_list(ctx: Context, val) -> list[sp.Expr]:
    return [ctx.parse(v, ("book", i)) for i, v in enumerate(ctx.as_list(val, ("book",)))]


@quantity('exponents',
          book='list of p (complex: sqrt(-1))',
          how=('multiset equality with the 2n exponents p of e^{pt} solutions (roots of '
               'det(Mp² + Cp + K) = 0) at 5 points, each to 1e-8 of the largest |p| (a small '
               'real part beside a large frequency is resolved only to that); `partial: '
               'true` for a subset; with `--prove`, `symbolic` where det M·∏(p − pᵢ) = '
               'det(Mp² + Cp + K) is proved coefficient by coefficient in p (all 2n: the '
               'same multiset), or each pᵢ a root (`partial`, distinct values), det M '
               'decided nonzero'),
          keys={"partial": {"type": "boolean"}},
          complex_values=True,
          crosschecks=("modes",))
def check_exponents(ctx: Context, val) -> Verdict:
    numeric = _multiset_at_points(ctx, val, lambda lin, pt: list(response.exponents(lin, pt)))
    if not (numeric.ok and ctx.policy.prove):
        return numeric
    partial = bool(ctx.part.data.get("partial"))
    return symbolic_or(numeric, prove_exponents(ctx.linear(), _book_list(ctx, val), partial,
                                                 ctx.sampler),
                        "proved symbolically: " + ("each a root of det(Mp² + Cp + K)" if partial
                                                   else "det M·∏(p − pᵢ) = det(Mp² + Cp + K)"))


@quantity('decay_rates',
          book='list of γ',
          how=('multiset equality with −Re p over the exponents, one per oscillating mode '
               '(conjugate pair) and one per real exponent, at 5 points; `partial: true` '
               'for a subset'),
          keys={"partial": {"type": "boolean"}},
          crosschecks=("modes",))
def check_decay_rates(ctx: Context, val) -> Verdict:
    return _multiset_at_points(
        ctx, val, lambda lin, pt: [complex(x) for x in response.decay_rates(lin, pt)])


def _multiset_at_points(ctx: Context, val, engine) -> Verdict:
    """The book's list against engine(lin, point) as a multiset of complex numbers (a
    subset with `partial: true`) at POINTS random points."""
    book = _book_list(ctx, val)
    lin = ctx.linear()
    partial = bool(ctx.part.data.get("partial"))
    for k in range(POINTS):
        pt = ctx.sampler.draw()
        ok, why = match_complex(complex_numbers(book, pt), engine(lin, pt), partial)
        if not ok:
            return Verdict(False, f"numeric({plural(k + 1, 'point')})", why)
    return Verdict(True, f"numeric({POINTS} points, state-space eigenvalues)",
                   power=f"{POINTS} points: the multiset of exponents, each to 1e-8 of the "
                         "largest")


def _residual(M, C, K, p: complex, u: np.ndarray) -> float:
    """|(Mp² + Cp + K)u| relative to the size of its terms."""
    r = (M * p**2 + C * p + K) @ u
    scale = (np.linalg.norm(M, 2) * abs(p) ** 2 + np.linalg.norm(C, 2) * abs(p)
             + np.linalg.norm(K, 2)) * np.linalg.norm(u)
    return float(np.linalg.norm(r) / max(scale, 1e-300))


@quantity('complex_modes',
          book='list of `{exponent: p, shape: {q: complex amplitude}}`',
          how=('p is an exponent of the linearized system and (Mp² + Cp + K)u = 0 for the '
               "book's shape u (relative residual 1e-8; any vector of a degenerate "
               'eigenspace passes), at 5 points; with `--prove`, `symbolic` where '
               'det(Mp² + Cp + K) = 0 and (Mp² + Cp + K)u = 0 are proved entry by entry (u '
               'nonzero at the points)'),
          complex_values=True,
          equivalent=("direction",),
          crosschecks=("modes",))
def check_complex_modes(ctx: Context, val) -> Verdict:
    lin = ctx.linear()
    modes = []
    for i, mode in enumerate(ctx.as_list(val, ("book",))):
        mode = ctx.as_map(mode, ("book", i))
        modes.append((ctx.parse(mode["exponent"], ("book", i, "exponent")),
                      ctx.mode_shape(mode.get("shape"), ("book", i, "shape"))))
    for k in range(POINTS):
        pt = ctx.sampler.draw()
        M, C, K = lin.matrices(pt)
        engine = list(response.exponents(lin, pt))
        for i, (p, shape) in enumerate(modes):
            pv = value(p, pt)
            ok, why = match_complex([pv], engine, partial=True)
            if not ok:
                return Verdict(False, f"numeric({plural(k + 1, 'point')})", f"mode {i}: {why}")
            u = np.array(complex_numbers(list(shape), pt))
            if not np.any(u) or not np.all(np.isfinite(u)):
                return Verdict(False, "numeric", f"mode {i}: the shape is zero or undefined")
            res = _residual(M, C, K, pv, u)
            if res > 1e-8:
                return Verdict(False, f"numeric({plural(k + 1, 'point')})",
                               f"mode {i}: (Mp² + Cp + K)u relative residual {res:.3g}")
    numeric = Verdict(True, f"numeric({POINTS} points)",
                      power=f"{POINTS} points: p an exponent to 1e-8, (Mp² + Cp + K)u to 1e-8")
    if not ctx.policy.prove:
        return numeric
    return symbolic_or(numeric, prove_complex_modes(lin, [(p, list(u)) for p, u in modes],
                                                     ctx.sampler),
                        "proved symbolically: det(Mp² + Cp + K) = 0 and (Mp² + Cp + K)u = 0; "
                        f"u nonzero at {POINTS} points")


def _linear_forms(ctx: Context, keys: list[str], lin) -> dict[str, list]:
    """Each key (a coordinate or a `define:` name) as the gradient of its linear form in the
    displacements, at the point: a coordinate's own unit row, a defined form's derivatives."""
    define = ctx.part.data.get("define") or {}
    out = {}
    for k in keys:
        names = lin.coord_names
        if k in names:
            out[k] = [sp.S(int(c == k)) for c in names]
        elif k in define:
            form = ctx.names[k]
            out[k] = lin.gradient(form)
        else:
            raise ctx.part.error(("book", k), "neither a coordinate nor a `define:` name")
    return out


def _driving(ctx: Context, pt: dict) -> float:
    if "frequency" not in ctx.part.data:
        raise ctx.part.error((), "give the driving frequency as `frequency:`")
    w = value(ctx.parse(ctx.part.data["frequency"], ("frequency",)), pt)
    if abs(w.imag) > 1e-12 * abs(w) or w.real <= 0:
        raise ctx.part.error(("frequency",), "the driving frequency is not a positive number")
    return w.real


@quantity('steady_amplitude',
          book='`{q: A}` (A complex where the response lags)',
          how=('the steady response to a force harmonic at `frequency:` is (for a '
               'coordinate or a linear `define:` form) δq = Re(A·e^{i(ωt + φ₀)}), φ₀ the '
               'phase of the force (its first nonzero '
               'generalized component as Re(F̂ e^{iωt})): A = X_q e^{−iφ₀} with '
               'X = (K − ω²M + iωC)⁻¹F̂, at 5 points (so a real A is the signed amplitude '
               'in phase with the force); with `--prove`, `symbolic` where every '
               'coordinate is given (or n forms, their determinant decided nonzero), F is '
               'proved harmonic at ω, the phase of its first nonzero component is a proved '
               'sign, and (K − ω²M + iωC)·X = e^{−iφ₀}F̂ is proved entry by entry (the '
               'unique response wherever there is one)'),
          keys={"frequency": EXPR},
          complex_values=True,
          crosschecks=("modes", "response"))
def check_steady_amplitude(ctx: Context, val) -> Verdict:
    val = ctx.as_map(val, ("book",))
    book = {c: ctx.parse(v, ("book", c)) for c, v in val.items()}
    lin = ctx.linear()
    rows = _linear_forms(ctx, list(val), lin)
    if not lin.driven:
        return Verdict(False, "exact", "the linearized system has no driving force")
    for k in range(POINTS):
        pt = ctx.sampler.draw()
        w = _driving(ctx, pt)
        phasor = response.forcing_phasor(lin, pt, w)
        big = np.max(np.abs(phasor))
        ref = next(f for f in phasor if abs(f) > 1e-12 * big)
        X = response.harmonic_response(lin, pt, w) * np.exp(-1j * np.angle(ref))
        scale = float(np.max(np.abs(X)))
        for c, e in book.items():
            got = value(e, pt)
            want = complex(np.array(complex_numbers(rows[c], pt)) @ X)
            if not abs(got - want) <= 1e-9 * max(abs(want), 1e-6 * scale):
                return Verdict(False, f"numeric({plural(k + 1, 'point')})",
                               f"{c}: book {_c(got)}, engine {_c(want)} (ω = {w:.6g})")
    numeric = Verdict(True, f"numeric({POINTS} points, (K - w^2 M + i w C) X = F)",
                      power=f"{POINTS} points: each amplitude to 1e-9")
    if not ctx.policy.prove:
        return numeric
    omega = ctx.parse(ctx.part.data["frequency"], ("frequency",))
    return symbolic_or(numeric, prove_steady_amplitude(lin, book, rows, omega, ctx.sampler),
                        "proved symbolically: F harmonic, (K − ω²M + iωC)·X = e^{−iφ₀}F̂ for the "
                        "book's amplitudes (wherever the steady response is unique)")



@quantity('resonances',
          book='list of driving frequencies',
          how=('set equality with the distinct normal frequencies ω (no damping) whose '
               'eigenspace the force reaches (F̂, evaluated with the driving-frequency '
               'parameter `driving:` set to ω, has a component along a mode of ω in the '
               'mass metric): where the steady amplitude is unbounded'),
          keys={"driving": {"type": "string", "pattern": "^[A-Za-z][A-Za-z0-9_]*$"}},
          crosschecks=("modes",))
def check_resonances(ctx: Context, val) -> Verdict:
    book = _book_list(ctx, val)
    lin = ctx.linear()
    name = ctx.part.data.get("driving")
    sym = ctx.names.get(name)
    if not isinstance(sym, sp.Symbol) or sym not in ctx.sampler.base:
        raise ctx.part.error(("driving",), "name the parameter that is the driving frequency")
    if lin.gyroscopic:
        raise UnsupportedError("resonances of a damped or gyroscopic system (peak frequencies)")
    for k in range(POINTS):
        pt = ctx.sampler.draw()
        w2, U = lin.numeric_modes(pt)  # M-orthonormal columns
        scale = max(1e-300, float(np.max(np.abs(w2))))
        groups: list[list[int]] = []
        for j in np.argsort(w2):
            if w2[j] <= 1e-9 * scale:
                continue
            if groups and abs(w2[j] - w2[groups[-1][0]]) <= 1e-7 * scale:
                groups[-1].append(j)
            else:
                groups.append([j])
        excited = []
        for group in groups:
            w = float(np.sqrt(np.mean(w2[group])))
            at = dict(pt)
            at[sym] = sp.Float(w, 30)
            phasor = response.forcing_phasor(lin, at, w)
            Minv = np.linalg.inv(lin.matrices(at)[0])
            size = np.sqrt(abs(np.conj(phasor) @ Minv @ phasor))  # |F| in the dual metric
            along = np.sqrt(sum(abs(U[:, j] @ phasor) ** 2 for j in group))
            if along > 1e-9 * max(size, 1e-300):
                excited.append(complex(w))
        ok, why = match_complex(complex_numbers(book, pt), excited, partial=False)
        if not ok:
            return Verdict(False, f"numeric({plural(k + 1, 'point')})", why)
    return Verdict(True, f"numeric({POINTS} points)",
                   power=f"{POINTS} points: the set of resonant frequencies to 1e-8")


@quantity('simultaneous_diagonalization',
          book='true or false',
          how=('whether one linear change of coordinates diagonalizes M, C (friction) and K '
               'together: K M⁻¹C = C M⁻¹K (Caughey and O\'Kelly), decided at 6 points '
               '(relative residual below 1e-10 at every one, or above 1e-6 at every one); '
               'with `--prove`, `true` is `symbolic` where C = Cᵀ and K·adj(M)·C = '
               'C·adj(M)·K are proved entry by entry, det M decided nonzero (`false` stays '
               'decided at the points)'))
def check_simultaneous_diagonalization(ctx: Context, val) -> Verdict:
    if not isinstance(val, bool):
        raise ctx.part.error(("book",), "expected true or false")
    lin = ctx.linear()
    residuals = [response.commutator_residual(lin, ctx.sampler.draw()) for _ in range(6)]
    yes = all(r < 1e-10 for r in residuals)
    no = all(r > 1e-6 for r in residuals)
    if not (yes or no):
        return Verdict(False, "numeric(6 points)", "diagonalizable at some parameter points "
                       f"only (residuals {', '.join(f'{r:.1e}' for r in residuals)})")
    ok = yes == val
    numeric = Verdict(ok, "numeric(6 points)",
                      f"K M^-1 C - C M^-1 K relative residual up to {max(residuals):.1e}",
                      power="6 points: the commutator below 1e-10 at every one (or above "
                            "1e-6 at every one)")
    if not (ok and ctx.policy.prove):
        return numeric
    return symbolic_or(numeric, prove_simultaneous_diagonalization(lin, val, ctx.sampler),
                        "proved symbolically: C = Cᵀ and K·adj(M)·C = C·adj(M)·K")



@quantity('normal_transformation',
          book='`{q: linear form in normal coordinates}` (every coordinate)',
          how=('x = A·η (the normal coordinates η are answer symbols): AᵀMA = 1 and AᵀKA '
               'diagonal (T = Σ η̇²/2, V = Σ ω²η²/2), entrywise to 1e-9 at 5 points; '
               '`frequencies: {η: ω}` also checks the diagonal; with `--prove`, `symbolic` '
               'where AᵀMA = 1, the off-diagonal AᵀKA and ω² − (AᵀKA)ⱼⱼ are proved 0 entry '
               'by entry'),
          keys={"frequencies": {"type": "object", "additionalProperties": EXPR}},
          crosschecks=("modes",))
def check_normal_transformation(ctx: Context, val) -> Verdict:
    val = ctx.as_map(val, ("book",))
    names = ctx.linear().coord_names
    if set(val) != set(names):
        raise ctx.part.error(("book",), "give every coordinate as a form in the normal "
                             "coordinates")
    forms = [ctx.parse(val[c], ("book", c)) for c in names]
    etas = sorted(set().union(*(f.free_symbols for f in forms))
                  & set(ctx.part.key.symbols.values()), key=lambda s: s.name)
    if len(etas) != len(names):
        raise ctx.part.error(("book",), f"expected {len(names)} normal coordinates (answer "
                             f"symbols), found {[s.name for s in etas]}")
    A = sp.Matrix([[sp.diff(f, e) for e in etas] for f in forms])
    if any(x.free_symbols & set(etas) for x in A):
        raise ctx.part.error(("book",), "the transformation is not linear")
    lin = ctx.linear()
    zero = {e: 0 for e in etas}  # all normal coordinates at rest: the point itself
    offsets = [f.xreplace(zero) - sp.S(lin.point.get(q, 0)) for f, q in zip(forms, lin.q,
                                                                             strict=True)]
    offset = all_vanish([o for o in offsets if o != 0], ctx.sampler) if any(offsets) else None
    if offset is not None and not offset.ok:
        return Verdict(False, offset.method, "with every normal coordinate zero the forms "
                       f"must give the point itself: {offset.detail}")
    freqs = {}
    for k, v in (ctx.part.data.get("frequencies") or {}).items():
        sym = ctx.part.key.symbols.get(k)
        if sym not in etas:
            raise ctx.part.error(("frequencies", k), "not one of the normal coordinates")
        freqs[etas.index(sym)] = ctx.parse(v, ("frequencies", k))
    for k in range(POINTS):
        pt = ctx.sampler.draw()
        M, C, K = lin.matrices(pt)
        An = np.array([[value(x, pt).real for x in row] for row in A.tolist()])
        T, V = An.T @ M @ An, An.T @ K @ An
        off = V - np.diag(np.diag(V))
        scale = max(1e-300, float(np.max(np.abs(V))))
        if np.max(np.abs(T - np.eye(len(names)))) > 1e-9:
            return Verdict(False, f"numeric({plural(k + 1, 'point')})",
                           f"A^T M A is not the unit matrix: {np.round(T, 6).tolist()}")
        if np.max(np.abs(off)) > 1e-9 * scale:
            return Verdict(False, f"numeric({plural(k + 1, 'point')})",
                           f"A^T K A is not diagonal: {np.round(V / scale, 6).tolist()}")
        for j, w in freqs.items():
            wv = value(w, pt)
            if abs(wv**2 - V[j, j]) > 1e-9 * scale:
                return Verdict(False, f"numeric({plural(k + 1, 'point')})",
                               f"{etas[j]}: omega**2 = {_c(wv**2)}, engine {V[j, j]:.10g}")
    numeric = Verdict(True, f"numeric({POINTS} points)",
                      power=f"{POINTS} points in double precision: AᵀMA = 1 and AᵀKA diagonal "
                            "to 1e-9, the offset exact")
    if not ctx.policy.prove or (offset is not None and offset.method != "symbolic"):
        return numeric if not ctx.policy.prove else Verdict(
            True, numeric.method, numeric.detail, numeric.power,
            unproved=offset.unproved or "the offset is checked numerically")
    return symbolic_or(numeric, prove_normal_transformation(lin, A, freqs, ctx.sampler),
                        "proved symbolically: AᵀMA = 1 and AᵀKA diagonal"
                        + (" with the stated ω²" if freqs else "") + ", entry by entry")

