"""With `--prove`, a stability verdict (`stable`, `unstable`) proved from the linearization
M·δq̈ + C·δq̇ + K·δq = 0 by signs that hold at every admissible point (proof.prove_sign):
no eigenvalue is computed.

    unstable  det M > 0 and det K < 0: the characteristic polynomial
              p(λ) = det(λ²M + λC + K) has p(0) = det K < 0 and leading coefficient
              det M > 0, so a real root λ > 0 (any C: damping, gyroscopic terms); or, with
              C = 0 and M, K symmetric, M positive definite and some K_ii < 0 (then
              eᵢᵀK eᵢ < 0: an ω² < 0).
    stable    M, K symmetric, C antisymmetric (gyroscopic or none), M and K positive
              definite (every leading principal minor > 0): the energy ½δq̇ᵀMδq̇ + ½δqᵀKδq
              is conserved and definite, and every exponent is imaginary and simple; or,
              with p(λ) even in λ (its odd coefficients 0 exactly) as P(s), s = λ², P of
              degree ≤ 3 after the factor s^j of a symmetry's zero exponents (neutral, as
              in the numeric verdict; none allowed without velocity terms, where a zero
              ω² is marginal), with every coefficient > 0 and, for degree 2 or 3, the
              discriminant > 0: the roots s are real (discriminant), distinct and negative
              (positive coefficients), so the exponents ±i√(−s) are simple and imaginary
              (gyroscopic stabilization: the least axis of a free body, a spinning top).

A verdict outside these cases (marginal; damping with a stable claim; more coordinates
under gyroscopic terms) is left unproved with the reason.
"""

from __future__ import annotations

import time

import sympy as sp

from mechbook.core.identity import decide_zero
from mechbook.core.timeout import Timeout, time_limit
from mechbook.engine.linear import LinearSystem, secular_determinant
from mechbook.errors import MechbookError
from mechbook.verify.proof import BUDGET, NO_PATH, NO_SIGN, Proof, prove_sign

MAX_COORDINATES = 4  # Berkowitz's determinant of λ²M + λC + K beyond: no attempt
MAX_ENTRY = 2000  # characters of a matrix entry: larger (a root's closed form) is not tried
# (SymEngine's expansion of the determinant cannot be interrupted)
# the proof's share of the part's budget: the six Symon verdicts it proves took at most
# 0.34 s of CPU each; Symon 12-28 (b-inside, b-outside), not proved, spent 1.4 s and 3.3 s
# (signs of 3105 and 11 394 operations): 1.5 s keeps every proof, with four times its time
SHARE = 0.15
NOT_SYMMETRIC = "M or K not shown symmetric (circulatory terms?)"
TOO_LARGE = "the linearization's entries are too large for a sign's proof"
FIRST_ORDER = "a first-order linearization (velocity constraints): no M, C, K to sign"


def prove_stability(lin: LinearSystem, claim: str, sampler) -> Proof:
    """Is the linearization `claim` ('stable' or 'unstable') at every admissible point,
    proved exactly? Proof(False, why) where not.

    Example: M = [[m]], C = [[0]], K = [[-k]] with m, k > 0: 'unstable' is proved."""
    try:
        M, C, K = lin.M, lin.C, lin.K
    except MechbookError:  # a first-order linearization (velocity constraints): no M, C, K
        return Proof(False, FIRST_ORDER)
    if M.rows > MAX_COORDINATES or claim not in ("stable", "unstable"):
        return Proof(False, NO_PATH)
    if any(len(str(x)) > MAX_ENTRY for A in (M, C, K) for x in A):
        return Proof(False, TOO_LARGE)
    budget = sampler.proof_budget()
    seconds = min(budget.left(), SHARE * sampler.policy.seconds)
    if seconds <= 0:
        return Proof(False, BUDGET)
    before, start = budget.spent, time.process_time()
    try:
        with time_limit(seconds):
            return _prove(M, C, K, claim, sampler)
    except Timeout:
        return Proof(False, BUDGET)
    except Exception:  # noqa: BLE001 - SymPy's odd failures: the numeric verdict stands
        return Proof(False, NO_SIGN)
    finally:  # all of it charged once (the signs' own charges included in it)
        budget.spent = before + time.process_time() - start


def _prove(M, C, K, claim: str, sampler) -> Proof:
    if not (_zero(M - M.T) and _zero(K - K.T)):
        return Proof(False, NOT_SYMMETRIC)
    velocity = not _zero(C)
    if claim == "unstable":
        return _unstable(M, C, K, velocity, sampler)
    if not _zero(C + C.T):
        return Proof(False, NO_PATH + " (damping: no stable claim is proved)")
    if _definite(M, sampler) and _definite(K, sampler):
        return Proof(True)
    if not velocity:  # K not shown definite and nothing gyroscopic to stabilize it
        return Proof(False, NO_SIGN)
    return _gyroscopic(M, C, K, sampler)


def _zero(A: sp.Matrix) -> bool:
    return all(x == 0 or decide_zero(x).zero is True for x in A)


def _definite(A: sp.Matrix, sampler) -> bool:
    """Every leading principal minor proved > 0 (Sylvester's criterion)."""
    return all(prove_sign(secular_determinant(A[:k, :k]), sampler)
               for k in range(1, A.rows + 1))


def _unstable(M, C, K, velocity: bool, sampler) -> Proof:
    if prove_sign(secular_determinant(M), sampler) and \
            prove_sign(secular_determinant(K), sampler, -1):
        return Proof(True)
    if not velocity and _definite(M, sampler) and \
            any(prove_sign(K[i, i], sampler, -1) for i in range(K.rows)):
        return Proof(True)
    return Proof(False, NO_SIGN)


def _gyroscopic(M, C, K, sampler) -> Proof:
    lam = sp.Dummy("lambda")
    p = sp.Poly(secular_determinant(lam**2 * M + lam * C + K), lam, domain=sp.EX)
    coeffs = p.all_coeffs()[::-1]  # c_0, c_1, ...
    if not all(c == 0 or decide_zero(c).zero is True for c in coeffs[1::2]):
        return Proof(False, NO_PATH + " (the characteristic polynomial is not even)")
    even = list(coeffs[0::2])  # P(s) = Σ even[k]·s^k
    while even and (even[0] == 0 or decide_zero(even[0]).zero is True):
        even.pop(0)  # the zero exponents of a symmetry
    if not 2 <= len(even) <= 4:
        return Proof(False, NO_PATH + " (too many coordinates under gyroscopic terms)")
    if not all(prove_sign(c, sampler) for c in even):
        return Proof(False, NO_SIGN)
    s = sp.Dummy("s")
    if len(even) > 2 and not prove_sign(sp.discriminant(sp.Poly(even[::-1], s)), sampler):
        return Proof(False, NO_SIGN)
    return Proof(True)
