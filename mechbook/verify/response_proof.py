"""With `--prove`, the linear-response answers proved from the linearization
M·δq̈ + C·δq̇ + K·δq = 0 without solving it: through the characteristic polynomial
D(p) = det(Mp² + Cp + K) (Berkowitz, division-free) and exact identities in its
coefficients (proof.prove_zero on each).

    exponents            all 2n: det M·∏(p − pᵢ) − D(p) ≡ 0 in p, coefficient by
                         coefficient (the monic polynomials equal: the multisets of roots
                         equal), det M not identically 0; `partial`: each D(pᵢ) = 0.
    complex_modes        each (Mp² + Cp + K)u = 0 entry by entry and D(p) = 0.
    characteristic_polynomial
                         the book's P(x) with p = a·x + b (a linear `exponent:`): the
                         polynomials lc(P)·D(a·x + b) and lc(D)·P(x) equal in x, of the same
                         degree 2n, so their roots agree with multiplicity where the leading
                         coefficients do not vanish (checked at the sampled points).
    simultaneous_diagonalization (true)
                         C − Cᵀ = 0 and K·adj(M)·C − C·adj(M)·K = 0 entry by entry
                         (adj M = det M·M⁻¹: Caughey and O'Kelly's condition without a
                         division), det M not identically 0.

Each refuses (Proof(False, why), the numeric verdict standing) where an identity is not
established exactly, where the system is too large for the determinant, or where the
statement has no such form (a `false` verdict: non-commuting matrices are shown so only at
points).
"""

from __future__ import annotations

import sympy as sp

from mechbook.core.identity import decide_zero, nonzero_determinant
from mechbook.engine.linear import secular_determinant
from mechbook.verify.compare import value
from mechbook.verify.proof import NO_PATH, OPEN, Proof, prove_sign, prove_zero

MAX_COORDINATES = 6  # Berkowitz's determinant of Mp² + Cp + K beyond: no attempt
MAX_ENTRY = 2000  # characters of a matrix entry: larger (a root's closed form) is not tried
MAX_EXPAND = 20000  # characters of a claim SymPy's expand is run on first
TOO_LARGE = "the linearization is too large for an exact characteristic polynomial"
SINGULAR = "the mass matrix is not shown invertible"
NOT_LINEAR = "the exponent is not a linear function of the variable"
FALSE_CLAIM = "a `false` verdict is decided at points only (no identity to prove)"


def proved_all(exprs, sampler) -> Proof:
    """Every expression proved 0: the canonical forms of all first, then simplify for the
    ones left open (the part's budget); the first failure's reason otherwise.

    Example: proved_all([x - x, sin(x)**2 + cos(x)**2 - 1], sampler) == Proof(True)."""
    # SymPy's expansion first: it joins √x·√x and √x/√x, which the canonical forms would
    # otherwise meet as independent roots after merging √a·√b (Symon 12-30's shapes)
    exprs = [sp.expand(e) if len(str(e)) < MAX_EXPAND else sp.S(e) for e in exprs]
    first = [prove_zero(e, sampler, canonical_only=True) for e in exprs]
    for p in first:
        if not p.ok and p.why != OPEN:
            return p
    for e, p in zip(exprs, first, strict=True):
        if not p.ok:
            q = prove_zero(e, sampler)
            if not q.ok:
                return q
    return Proof(True)


def _refusal(lin) -> str:
    """Why no characteristic polynomial is formed exactly ('' where one is)."""
    if getattr(lin, "first_order", False):
        return NO_PATH + " (a first-order linearization)"
    M, C, K = lin.M, lin.C, lin.K
    if M.rows > MAX_COORDINATES:
        return TOO_LARGE
    if any(len(str(x)) > MAX_ENTRY for A in (M, C, K) for x in A):
        return TOO_LARGE
    if not _nonsingular(M):
        return SINGULAR
    return ""


def _nonsingular(A: sp.Matrix) -> bool:
    """det A not identically 0, decided exactly: at a rational point, or (irrational
    entries, such as √2 in a rotated form) its canonical form nonzero at an exact point."""
    return nonzero_determinant(A) or decide_zero(secular_determinant(A)).zero is False


def _distinct(values: list[sp.Expr], sampler) -> bool:
    """The values pairwise apart at a sampled point (a double root written two ways would
    otherwise be proved a root once, not twice)."""
    pt = sampler.draw()
    nums = [value(v, pt) for v in values]
    return all(abs(a - b) > 1e-12 * max(1.0, abs(a), abs(b))
               for i, a in enumerate(nums) for b in nums[i + 1:])


def _char_poly(lin, p: sp.Symbol) -> sp.Expr:
    return secular_determinant(p**2 * lin.M + p * lin.C + lin.K)


def _coefficients(expr: sp.Expr, x: sp.Symbol) -> list[sp.Expr]:
    return sp.Poly(sp.expand(expr), x, domain=sp.EX).all_coeffs()


def prove_exponents(lin, book: list[sp.Expr], partial: bool, sampler) -> Proof:
    """Are the book's exponents (all 2n, or a subset of distinct ones with `partial`) the
    roots of det(Mp² + Cp + K), proved exactly?

    Example: M = [[m]], C = [[b]], K = [[k]]: [−b/(2m) ± √(b² − 4mk)/(2m)] is proved."""
    why = _refusal(lin)
    if why:
        return Proof(False, why)
    p = sp.Dummy("p")
    D = _char_poly(lin, p)
    if partial:
        if not _distinct(book, sampler):  # a repeated root would need D'(p) = 0 as well
            return Proof(False, NO_PATH + " (a repeated value in a partial list)")
        return proved_all([D.subs(p, b) for b in book], sampler)
    if len(book) != 2 * lin.M.rows:
        return Proof(False, NO_PATH + " (not all 2n exponents)")
    monic = secular_determinant(lin.M) * sp.Mul(*[p - b for b in book])
    return proved_all(_coefficients(monic - D, p), sampler)


def prove_complex_modes(lin, modes: list[tuple[sp.Expr, list[sp.Expr]]], sampler) -> Proof:
    """Is each (p, u) an exponent with (Mp² + Cp + K)u = 0, proved exactly?

    Example: M = [[1]], C = [[0]], K = [[w**2]]: (i·w, [1]) is proved."""
    why = _refusal(lin)
    if why:
        return Proof(False, why)
    s = sp.Dummy("p")
    D = _char_poly(lin, s)
    claims = []
    for p, shape in modes:
        A = p**2 * lin.M + p * lin.C + lin.K
        claims += list(A * sp.Matrix(shape)) + [D.subs(s, p)]
    return proved_all(claims, sampler)


def prove_characteristic_polynomial(lin, poly: sp.Expr, var: sp.Symbol, exponent: sp.Expr,
                                    sampler) -> Proof:
    """Is the book's polynomial in `var`, with p = exponent(var), proportional to
    det(Mp² + Cp + K), proved exactly (same degree 2n, coefficients in proportion)?

    Example: M = [[1]], K = [[w**2]], p = sqrt(-1)*x: w**2 − x**2 is proved."""
    why = _refusal(lin)
    if why:
        return Proof(False, why)
    a, b = sp.diff(exponent, var), exponent.subs(var, 0)
    if a.has(var) or sp.expand(exponent - a * var - b) != 0 or a == 0:
        return Proof(False, NOT_LINEAR)
    p = sp.Dummy("p")
    D = sp.expand(_char_poly(lin, p).subs(p, a * var + b))
    try:
        book, engine = _coefficients(poly, var), _coefficients(D, var)
    except sp.PolynomialError:
        return Proof(False, NO_PATH + " (not a polynomial in the variable)")
    if len(book) != len(engine) or len(engine) != 2 * lin.M.rows + 1:
        return Proof(False, NO_PATH + " (the degrees are not both 2n)")
    lb, le = book[0], engine[0]
    return proved_all([lb * e - le * c for c, e in zip(book, engine, strict=True)], sampler)


def prove_simultaneous_diagonalization(lin, claim: bool, sampler) -> Proof:
    """Is `true` (one congruence diagonalizes M, C and K) proved exactly: C symmetric and
    K·adj(M)·C = C·adj(M)·K?

    Example: C = b·M: K adj(M) (bM) = b·det M·K = (bM) adj(M) K, proved."""
    if not claim:
        return Proof(False, FALSE_CLAIM)
    why = _refusal(lin)
    if why:
        return Proof(False, why)
    M, C, K = lin.M, lin.C, lin.K
    adj = M.adjugate(method="berkowitz")
    claims = list(C - C.T) + list(K * adj * C - C * adj * K)
    return proved_all([c for c in claims if c != 0], sampler)


def prove_steady_amplitude(lin, book: dict, rows: dict, omega: sp.Expr, sampler) -> Proof:
    """Are the book's steady amplitudes (every coordinate, or n independent linear forms of
    them) the harmonic response, proved exactly? The force F(t) proved harmonic,
    F(t) = F(0)cos ωt + F(π/2ω) sin ωt (so F̂ = F(0) − i·F(π/2ω)); the phase factor
    e^{−iφ₀} of its first nonzero component a proved sign (a real or an imaginary
    component); then with R the forms' rows (det R ≠ 0 exactly) and the book's values A,
    (K − ω²M + iωC)·adj(R)·A = det R·e^{−iφ₀}·F̂, entry by entry: the book's response
    solves the steady equations wherever they have one solution.

    Example: M = [[m]], K = [[k]], F = F0 cos ωt: {x: F0/(k − mω²)} is proved."""
    why = _refusal(lin)
    if why:
        return Proof(False, why)
    n = lin.M.rows
    if len(book) != n:
        return Proof(False, NO_PATH + " (not every coordinate's amplitude: the rest of the "
                     "response is not stated)")
    R = sp.Matrix([rows[c] for c in book])
    if not _nonsingular(R):
        return Proof(False, NO_PATH + " (the forms are not shown independent)")
    t = lin.dyn.sys.t
    F = [sp.S(f) for f in lin.F]
    at0 = [f.subs(t, 0) for f in F]
    at4 = [f.subs(t, sp.pi / (2 * omega)) for f in F]
    harmonic = proved_all([f - a * sp.cos(omega * t) - b * sp.sin(omega * t)
                           for f, a, b in zip(F, at0, at4, strict=True)], sampler)
    if not harmonic.ok:
        return Proof(False, "the force is not proved harmonic at the driving frequency ("
                     + harmonic.why + ")")
    phase = _phase(at0, at4, sampler)
    if phase is None:
        return Proof(False, NO_SIGN_PHASE)
    Fh = sp.Matrix([a - sp.I * b for a, b in zip(at0, at4, strict=True)])
    H = lin.K - omega**2 * lin.M + sp.I * omega * lin.C
    A = sp.Matrix(list(book.values()))
    residual = H * R.adjugate(method="berkowitz") * A - R.det(method="berkowitz") * phase * Fh
    return proved_all(list(residual), sampler)


NO_SIGN_PHASE = "the force's phase is not a proved sign (its first component's sign)"


def _phase(at0: list, at4: list, sampler) -> sp.Expr | None:
    """e^{−iφ₀} for the first component of F̂ = F(0) − i·F(π/2ω) not identically 0: ±1
    where it is real (F(π/2ω) = 0 there) of a proved sign, ±i where it is imaginary;
    None otherwise."""
    def vanishes(e) -> bool:
        return e == 0 or decide_zero(e).zero is True

    for a, b in zip(at0, at4, strict=True):
        if vanishes(a) and vanishes(b):
            continue
        if vanishes(b):  # F̂ = a real: e^{−iφ₀} = sign a
            part, unit = a, sp.S.One
        elif vanishes(a):  # F̂ = −i·b: e^{−iφ₀} = i·sign b
            part, unit = b, sp.I
        else:
            return None
        if prove_sign(part, sampler):
            return unit
        if prove_sign(part, sampler, -1):
            return -unit
        return None
    return None


def prove_normal_transformation(lin, A: sp.Matrix, frequencies: dict, sampler) -> Proof:
    """x = A·η: AᵀMA = 1 and AᵀKA diagonal (with `frequencies: {j: ω}` its diagonal
    ω²), proved exactly entry by entry? `lin` must have no velocity terms (C = 0).

    Example: M = [[m]], K = [[k]], A = [[1/√m]], {0: √(k/m)} is proved."""
    if getattr(lin, "first_order", False):
        return Proof(False, NO_PATH + " (a first-order linearization)")
    M, K = lin.M, lin.K
    if any(len(str(x)) > MAX_ENTRY for B in (M, K, A) for x in B):
        return Proof(False, TOO_LARGE)
    T, V = A.T * M * A, A.T * K * A
    n = A.cols
    claims = [T[i, j] - (1 if i == j else 0) for i in range(n) for j in range(n) if i <= j]
    claims += [V[i, j] for i in range(n) for j in range(n) if i < j]
    claims += [w**2 - V[j, j] for j, w in frequencies.items()]
    return proved_all(claims, sampler)


def prove_proportional(book: sp.Expr, engine: sp.Expr, x: sp.Symbol, sampler) -> Proof:
    """Are two polynomials in x proportional by a factor free of x, proved exactly (the
    same degree, lc(B)·E = lc(E)·B coefficient by coefficient)? Then they have the same
    roots with multiplicity wherever their leading coefficients do not vanish (a steady
    motion's equation in its rate and the engine's condition, which may differ by a
    factor such as sin θ0).

    Example: prove_proportional(2*x**2 - 2, sin(t)*(x**2 - 1), x, sampler).ok."""
    try:
        b, e = _coefficients(book, x), _coefficients(engine, x)
    except sp.PolynomialError:
        return Proof(False, NO_PATH + " (not a polynomial in the rate)")
    if len(b) != len(e) or len(b) < 2:
        return Proof(False, NO_PATH + " (the degrees differ)")
    return proved_all([b[0] * ce - e[0] * cb for cb, ce in zip(b, e, strict=True)], sampler)
