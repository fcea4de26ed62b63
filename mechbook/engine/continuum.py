"""A field's equation and normal frequencies from its Lagrangian density (`field:`).

The field equation is Euler–Lagrange's for fields, Σ_α (−D)^α ∂ℒ/∂u_α = 0 over the jet
(higher derivatives for a beam), of ℒ·r in polar coordinates (divided by r after). The
normal frequencies come by separation: on a segment, the determinant of the boundary
conditions on the transfer matrix exp(A(λ)·L) of the mode's ODE (constant coefficients;
λ = ω², a point mass making a condition depend on λ) vanishes, each root polished at 30
digits with mpmath's findroot from a bracket the spectral discretization (engine.spectral)
gives; a rectangle's are sums of the two segments' eigenvalues; a disk's and an
annulus's come from Bessel functions (zeros of J_n or J_n′ at 30 digits, the annulus's
cross products of J_n and Y_n), each n ≥ 1 twice (cos nθ and sin nθ).
"""

from __future__ import annotations

from weakref import WeakKeyDictionary

import mpmath as mp
import sympy as sp

from mechbook.engine.spectral import segment_eigenvalues
from mechbook.errors import UnsupportedError
from mechbook.model.continuum import FieldModel, T

DIGITS = 30
_EQUATIONS: WeakKeyDictionary = WeakKeyDictionary()  # a model's field equation, derived once
_SQUARES: WeakKeyDictionary = WeakKeyDictionary()  # a model's ω² by (point, count), once


def _to_function(model: FieldModel) -> tuple:
    variables = (T, *model.coords)
    U = sp.Function(model.name)(*variables)
    sub = {}
    for orders, sym in model.jets.items():
        spec = [(v, k) for v, k in zip(variables, orders, strict=True) if k]
        sub[sym] = sp.Derivative(U, *spec) if spec else U
    return U, variables, sub


def _to_jets(model: FieldModel, expr: sp.Expr, U, variables) -> sp.Expr:
    back = {}
    for d in expr.atoms(sp.Derivative):
        counts = dict(d.variable_count)
        back[d] = model.jet(tuple(int(counts.get(v, 0)) for v in variables))
    return expr.xreplace(back).xreplace({U: model.jet((0,) * len(variables))})


def total_derivative(model: FieldModel, expr: sp.Expr, axis: int) -> sp.Expr:
    """D_axis of a jet expression (axis 0 is t, then the space coordinates)."""
    U, variables, sub = _to_function(model)
    return _to_jets(model, sp.diff(expr.xreplace(sub), variables[axis]), U, variables)


def field_equation(model: FieldModel) -> sp.Expr:
    """The Euler–Lagrange expression E (E = 0 is the field equation) in the jet's symbols.

    >>> # ℒ = ρu_t²/2 − τu_x²/2 gives −ρ·u_tt + τ·u_xx
    """
    if model in _EQUATIONS:
        return _EQUATIONS[model]
    U, variables, sub = _to_function(model)
    weight = model.coords[0] if model.polar else sp.S.One
    lag = model.density * weight
    out = sp.S.Zero
    for orders, sym in list(model.jets.items()):
        d = sp.diff(lag, sym)
        if d == 0:
            continue
        term = d.xreplace(sub)
        for v, k in zip(variables, orders, strict=True):
            if k:
                term = sp.diff(term, v, k)
        out += (-1) ** sum(orders) * term
    eq = sp.expand(_to_jets(model, out, U, variables) / weight)
    _EQUATIONS[model] = eq
    return eq


def linear_coefficients(model: FieldModel, expr: sp.Expr) -> dict:
    """{jet orders: coefficient} of an expression linear and homogeneous in the jet."""
    syms = {s: o for o, s in model.jets.items()}
    present = [s for s in expr.free_symbols if s in syms]
    coeffs = {syms[s]: sp.expand(expr).coeff(s) for s in present}
    rest = sp.expand(expr - sum(c * s for s, c in zip(present, coeffs.values(), strict=True)))
    if rest != 0 or any(c.free_symbols & set(syms) for c in coeffs.values()):
        raise UnsupportedError("normal modes of a nonlinear field equation")
    return coeffs


def edge_conditions(model: FieldModel, edge) -> list[sp.Expr]:
    """The edge's conditions as jet expressions that vanish there (before x is put in)."""
    ax = edge.axis + 1
    dims = len(model.coords)

    def unit(k):
        return tuple([0] + [k if i + 1 == ax else 0 for i in range(dims)])

    lag = model.density
    q = sp.diff(lag, model.jet(unit(2)))  # the moment: the coefficient of δu_n
    p = sp.diff(lag, model.jet(unit(1))) - total_derivative(model, q, ax)  # of δu
    u, un = model.jet(unit(0)), model.jet(unit(1))
    natural = [edge.sign * p] + ([q] if model.space_order() == 2 else [])
    if edge.kind == "fixed":
        return [u]
    if edge.kind == "clamped":
        return [u, un]
    if edge.kind == "hinged":
        return [u, q]
    if edge.kind == "free":
        return natural
    utt = model.jet(tuple([2] + [0] * dims))
    return [natural[0] - edge.spring * u - edge.mass * utt] + natural[1:]


def modal_coefficients(model: FieldModel, eq: sp.Expr) -> tuple:
    """(−c_tt, the space coefficients) of the field equation; UnsupportedError where the
    modes do not separate so."""
    coeffs = linear_coefficients(model, eq)
    dims = len(model.coords)
    tt = tuple([2] + [0] * dims)
    if tt not in coeffs:
        raise UnsupportedError("normal modes of a field equation without u_tt")
    if any(o[0] == 1 for o in coeffs):
        raise UnsupportedError("normal modes of a damped field (terms in u_t)")
    weight = -coeffs.pop(tt)
    if any(o[0] for o in coeffs):
        raise UnsupportedError("normal modes of a field equation with mixed t derivatives")
    return weight, coeffs


def as_number(expr, point) -> mp.mpf:
    v = sp.N(sp.S(expr).xreplace(point), DIGITS + 5)
    if not v.is_number:
        raise UnsupportedError(f"separation with coefficients that vary in space ({expr})")
    return mp.mpf(str(v))


def _bc_rows(model: FieldModel, edge, axis_orders: int, point: dict) -> list:
    """Each condition as (row of ∂^k u coefficients, coefficient of λ·u) at the edge."""
    rows = []
    dims = len(model.coords)
    for cond in edge_conditions(model, edge):
        coeffs = linear_coefficients(model, cond)
        row = [mp.mpf(0)] * axis_orders
        lam = mp.mpf(0)
        for o, c in coeffs.items():
            c = as_number(c.xreplace({model.coords[edge.axis]: edge.at}), point)
            space = o[1:]
            if o[0] == 2 and not any(space):
                lam += c  # u_tt = −λ·u: K·u = λ·(c)·u
                continue
            if o[0] or any(space[i] for i in range(dims) if i != edge.axis):
                raise UnsupportedError("an edge condition that does not separate")
            row[space[edge.axis]] += c
        rows.append((row, lam))
    return rows


def transfer_matrix(A, length) -> mp.matrix:
    """exp(A·L), the transfer matrix of a mode ODE's first-order form A (an mpmath matrix)
    over the length L. For a 2×2 A (a second-order ODE) in closed form: with t = tr A/2 and
    s² = t² − det A, (A − tI)² = s²I gives exp(AL) = e^{tL}[cosh(sL)·I + (sinh(sL)/s)·
    (A − tI)] (cos and sin where s² < 0): exact, and a twentieth of the time
    of mpmath's Taylor series with squarings, which a root's polish calls ten times; other
    sizes by mpmath's expm (a Vandermonde diagonalization of a beam's 4×4 companion matrix
    was tried: its roots at twice the digits cost as much as the series), but for a mode
    ODE with only its highest and lowest derivatives (a uniform beam's φ⁗ = μφ): its
    companion matrix has Aⁿ = μI, and exp(AL) in closed form (`_cyclic_transfer`).

    >>> transfer_matrix(mp.matrix([[0, 1], [-1, 0]]), mp.pi / 2)[0, 1]  # sin(π/2)
    mpf('1.0')
    """
    if A.rows != 2:
        cyclic = _cyclic_transfer(A, length)
        return mp.expm(A * length) if cyclic is None else cyclic
    t = (A[0, 0] + A[1, 1]) / 2
    s2 = t * t - (A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0])
    if s2 > 0:
        s = mp.sqrt(s2)
        ch, sh = mp.cosh(s * length), mp.sinh(s * length) / s
    elif s2 < 0:
        s = mp.sqrt(-s2)
        ch, sh = mp.cos(s * length), mp.sin(s * length) / s
    else:
        ch, sh = mp.mpf(1), length
    e = mp.exp(t * length)
    return mp.matrix([[e * (ch + sh * (A[0, 0] - t)), e * sh * A[0, 1]],
                      [e * sh * A[1, 0], e * (ch + sh * (A[1, 1] - t))]])


def _cyclic_transfer(A, length) -> mp.matrix | None:
    """exp(A·L) of an n×n companion matrix whose only last-row entry is μ = A[n−1, 0] ≠ 0
    (A shifts e_j to e_{j−1}, e_0 to μ·e_{n−1}: Aⁿ = μI), else None. On A's eigenvector of
    eigenvalue s (one of the n roots of sⁿ = μ), Σ_k f_k A^k = e^{sL} for f_k =
    (1/n)·Σ_j s_j^(−k)·e^{s_j L}, as the roots' ratios are the n-th roots of unity; and
    (A^k)_{ij} is 1 at j = i + k, μ at j = i + k − n, 0 elsewhere: exp(AL)_{ij} = f_{j−i},
    or μ·f_{j−i+n} below the diagonal. n exponentials instead of the series' squarings;
    None where |s|L < 1e-3 (the f_k cancel there: the series is as cheap)."""
    n = A.rows
    mu = A[n - 1, 0]
    if n < 3 or mu == 0 or any(A[n - 1, k] != 0 for k in range(1, n)) or \
            any(A[i, k] != (1 if k == i + 1 else 0) for i in range(n - 1) for k in range(n)):
        return None
    size = abs(mu) ** (mp.mpf(1) / n)
    if size * abs(length) < mp.mpf("1e-3"):
        return None
    extra = 5 + int(n * max(0.0, float(-mp.log10(size * abs(length)))))
    with mp.workdps(mp.mp.dps + extra):  # f_{n−1} ~ (sL)^(n−1)/(n−1)!: digits cancel below 1
        roots = [mp.root(mp.mpc(mu), n, k) for k in range(n)]
        exps = [mp.exp(r * length) for r in roots]
        f = [mp.re(mp.fsum(e / r ** k for r, e in zip(roots, exps, strict=True))) / n
             for k in range(n)]
    out = mp.matrix(n, n)
    for i in range(n):
        for j in range(n):
            out[i, j] = +f[j - i] if j >= i else mu * f[j - i + n]
    return out


def _boundary_matrix(ode: list, weight, length, left: list, right: list, lam):
    """The boundary conditions on φ's initial data (φ, φ′, …) at x = 0 for
    Σ a_k φ^(k) + λ·w·φ = 0 on [0, L] at λ: singular exactly at an eigenvalue."""
    n = len(ode) - 1
    with mp.workdps(DIGITS + 10):
        a = [mp.mpf(c) for c in ode]
        a[0] += lam * weight
        A = mp.zeros(n, n)
        for i in range(n - 1):
            A[i, i + 1] = 1
        for k in range(n):
            A[n - 1, k] = -a[k] / a[n]
        phi = transfer_matrix(A, length)
        M = mp.zeros(n, n)
        for i, (row, mass) in enumerate(left):
            for k in range(n):
                M[i, k] = row[k] + (-lam * mass if k == 0 else 0)
        for j, (row, mass) in enumerate(right):
            r = [row[k] + (-lam * mass if k == 0 else 0) for k in range(n)]
            for k in range(n):
                M[len(left) + j, k] = mp.fsum(r[m] * phi[m, k] for m in range(n))
        return M


def segment_problem(model: FieldModel, coeffs: dict, weight, axis: int, edges: tuple,
                    point: dict, with_constant: bool) -> tuple:
    """The 1-D eigenproblem along `axis`: (ODE coefficients a_0..a_n, w, L, left rows,
    right rows) at the parameter point."""
    dims = len(model.coords)
    n = 0
    ode = [mp.mpf(0)] * 5
    for o, c in coeffs.items():
        space = o[1:]
        if not any(space):
            if with_constant:
                ode[0] += as_number(c, point)
            continue
        if any(space[i] for i in range(dims) if i != axis):
            continue
        ode[space[axis]] += as_number(c, point)
        n = max(n, space[axis])
    lo, hi = (e for e in edges if e.axis == axis)
    length = as_number(hi.at - lo.at, point)
    rows = [_bc_rows(model, e, n, point) for e in (lo, hi)]
    return ode[:n + 1], as_number(weight, point), length, rows[0], rows[1]


def _rigid_modes(problem: tuple) -> int:
    """How many independent modes have λ = 0 (a free end's translation and rotation): the
    nullity of the boundary matrix at λ = 0, by its singular values at 40 digits."""
    ode, w, length, left, right = problem
    with mp.workdps(DIGITS + 10):
        m = _boundary_matrix(ode, w, length, left, right, mp.mpf(0))
        sv = mp.svd_r(m, compute_uv=False)
        top = max(abs(x) for x in sv)
        return sum(1 for x in sv if abs(x) <= mp.mpf(10) ** (-DIGITS + 5) * top)


def _polish(problem: tuple, guesses: list) -> list:
    """Each spectral eigenvalue polished to a root of the boundary determinant (the rigid
    modes' λ = 0 counted exactly)."""
    ode, w, length, left, right = problem
    guesses = sorted(guesses)
    scale = max(abs(g) for g in guesses) if guesses else 1.0
    rigid = _rigid_modes(problem)
    near = [g for g in guesses if abs(g) <= 1e-6 * scale]
    if len(near) < rigid:
        raise UnsupportedError(f"{rigid} rigid modes, but the discretization has "
                               f"{len(near)} eigenvalues near 0")
    out = [mp.mpf(0)] * rigid
    guesses = [g for g in guesses if abs(g) > 1e-6 * scale] if rigid else guesses
    for i, g in enumerate(guesses):
        gaps = [abs(g - h) for j, h in enumerate(guesses) if j != i] + [abs(g) or 1.0]
        delta = 0.3 * max(min(gaps), 1e-9 * scale)
        with mp.workdps(DIGITS + 10):
            def f(lam):
                return mp.det(_boundary_matrix(ode, w, length, left, right, lam))
            lo, hi = mp.mpf(g) - delta, mp.mpf(g) + delta
            try:  # the secant from the collocation's value (it is close), else the bracket
                root = mp.findroot(f, (mp.mpf(g), mp.mpf(g) + delta * mp.mpf("1e-4")),
                                   solver="secant")
                if abs(root - g) > delta:
                    raise ValueError("left the bracket")
            except (ValueError, ZeroDivisionError):
                try:
                    root = mp.findroot(f, (lo, hi), solver="anderson")
                except (ValueError, ZeroDivisionError):
                    raise UnsupportedError("no root of the boundary determinant near the "
                                           f"discretization's eigenvalue {g:.8g}") from None
            if abs(root - g) > delta:
                raise UnsupportedError("the boundary determinant's root left the bracket of "
                                       f"the discretization's eigenvalue {g:.8g}")
            out.append(root)
    return out


def _segment_lambdas(model, coeffs, weight, axis, point, count, with_constant) -> list:
    problem = segment_problem(model, coeffs, weight, axis, model.edges, point, with_constant)
    ode, w, length, left, right = problem
    guesses = segment_eigenvalues([float(c) for c in ode], float(w), float(length),
                                  [([float(x) for x in r], float(m)) for r, m in left],
                                  [([float(x) for x in r], float(m)) for r, m in right],
                                  count)
    return _polish(problem, guesses)


def squared_frequencies(model: FieldModel, point: dict, count: int) -> list:
    """The lowest `count` values of ω² (degenerate ones repeated), at 30 digits, at the
    parameter point {symbol: value}; computed once per model, point and count (a part's
    default point is its spectral cross-check's)."""
    key = (tuple(sorted((str(k), str(v)) for k, v in point.items())), count)
    known = _SQUARES.setdefault(model, {})
    if key not in known:
        with mp.workdps(DIGITS):  # the parameters read at 30 digits whoever asks
            known[key] = _squared_frequencies(model, point, count)
    return list(known[key])


def _squared_frequencies(model: FieldModel, point: dict, count: int) -> list:
    eq = field_equation(model)
    weight, coeffs = modal_coefficients(model, eq)
    if model.domain == "segment":
        return _segment_lambdas(model, coeffs, weight, 0, point, count, True)[:count]
    if model.domain == "rectangle":
        if any(o[1] and o[2] for o in coeffs):
            raise UnsupportedError("separation with a mixed derivative u_xy")
        xs = _segment_lambdas(model, coeffs, weight, 0, point, count, True)
        ys = _segment_lambdas(model, coeffs, weight, 1, point, count, False)
        return sorted(a + b for a in xs[:count] for b in ys[:count])[:count]
    return bessel_lambdas(model, weight, coeffs, point, count)


def isotropic_membrane(model: FieldModel, weight, coeffs: dict, point: dict) -> tuple:
    r = model.coords[0]
    rr, r1, th, c0 = (coeffs.pop(o, sp.S.Zero) for o in ((0, 2, 0), (0, 1, 0), (0, 0, 2),
                                                         (0, 0, 0)))
    if coeffs or sp.simplify(r1 - rr / r) != 0 or sp.simplify(th - rr / r**2) != 0 \
            or rr.has(r) or c0.has(r):
        raise UnsupportedError("separation on a disk or annulus of a density that is not "
                               "an isotropic membrane's (τ∇²u with constant τ)")
    return as_number(rr, point), as_number(c0, point), as_number(weight, point)


def _cross(n, k, a, b, da, db):
    return (mp.besselj(n, k * a, da) * mp.bessely(n, k * b, db)
            - mp.besselj(n, k * b, db) * mp.bessely(n, k * a, da))


def _annulus_roots(n: int, sizes: list, deriv: list, count: int, kmax=None) -> list:
    """The lowest `count` positive roots k of the annulus's cross product: sign changes on
    a grid of 1/16 of the spacing π/(b − a) at double precision, each polished at 35
    digits (none beyond kmax)."""
    a, b = sizes
    out = []

    def f(z):
        return _cross(n, z, a, b, deriv[0], deriv[1])

    with mp.workdps(15):
        step = mp.pi / (b - a) / 16
        k, prev = step / 4, f(step / 4)
        brackets = []
        while len(brackets) < count and (kmax is None or k < kmax):
            cur = f(k + step)
            if mp.sign(cur) != mp.sign(prev):
                brackets.append((k, k + step))
            k, prev = k + step, cur
    for lo, hi in brackets:
        out.append(mp.findroot(f, (mp.mpf(lo), mp.mpf(hi)), solver="anderson"))
    return out


def bessel_lambdas(model: FieldModel, weight, coeffs: dict, point: dict, count: int) -> list:
    """ω² of an isotropic membrane on a disk or an annulus: (τk² − c0)/w over the radial
    wave numbers k of each n (zeros of J_n or J_n′; cross products of J_n and Y_n)."""
    tau, c0, w = isotropic_membrane(model, weight, dict(coeffs), point)
    deriv = [0 if e.kind == "fixed" else 1 for e in model.edges]
    sizes = [as_number(e.at, point) for e in model.edges]
    out = []
    with mp.workdps(DIGITS + 5):
        for n in range(0, count + 2):
            ks = []
            if all(deriv) and n == 0:
                ks.append(mp.mpf(0))  # a free edge all round: the rigid (uniform) mode
            if model.domain == "disk":
                need = count - len(ks)
                ks += [mp.besseljzero(n, s, derivative=deriv[0]) / sizes[0]
                       for s in range(1, need + 1 + (1 if n == 0 and deriv[0] else 0))
                       if not (n == 0 and deriv[0] and s == 1)][:need]
            else:
                top = sorted(out)[count - 1] if len(out) >= count else None
                kmax = None if top is None else mp.sqrt((top * w + c0) / tau)
                ks += _annulus_roots(n, sizes, deriv, count - len(ks), kmax)
            lams = [(tau * kk**2 - c0) / w for kk in ks]
            if n and len(out) >= count and (not lams or min(lams) > sorted(out)[count - 1]):
                break
            out += lams * (2 if n else 1)
    return sorted(out)[:count]
