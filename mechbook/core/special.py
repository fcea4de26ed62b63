"""Special functions SymPy lacks or evaluates outside their real domain, with their mpmath
evaluators: Jacobi's elliptic functions sn, cn, dn, the positive zeros of Bessel's J_ν and
Y_ν, and real-domain guards for the incomplete elliptic integrals and Bessel's functions.

Why a module of its own: the safe parser (mechbook.model.expr) offers these names to problem
text, the 30- and 50-digit evaluator (core.numeval) and the double-precision constant check
(model.constants) evaluate them, and the compile layer (core.compile) vectorizes them; all
four must agree on one convention and one domain. The convention is SymPy's and mpmath's
parameter m = k² throughout: sn(u, m) = sin φ where u = F(φ, m) = ∫₀^φ dθ/sqrt(1 − m sin²θ).
A value outside the real domain (a zero's index that is not a positive integer, a negative
order of a zero, F(φ, m) with m·sin²φ > 1, Y_ν(x) at x ≤ 0) raises DomainError (a ValueError) with
the reason: the parser's constant check turns it into an error at the expression's column,
and a checked point where it happens is a singular point, as a division by zero is.
"""

from __future__ import annotations

import mpmath
import sympy as sp
from sympy.core.function import ArgumentIndexError


class DomainError(ValueError):
    """A special function called outside its (real) domain; the message says why."""


def _is_real(*args) -> bool:
    return all(mpmath.im(a) == 0 for a in args)


def _real(value, args, why: str):
    """`value` if it is real (or the arguments are not), else DomainError(why): a complex
    value of real arguments is outside the function's real domain. An imaginary part at
    rounding level (mpmath's transformations leave 1e-20 of it) is dropped."""
    if not _is_real(*args):
        return value
    im, re = abs(mpmath.im(value)), abs(mpmath.re(value))
    if im == 0 or im <= mpmath.mpf(2) ** (8 - mpmath.mp.prec) * max(re, 1):
        return mpmath.mpf(mpmath.re(value))
    raise DomainError(why)


def ellipf(phi, m):
    """F(φ, m), the incomplete elliptic integral of the first kind (m = k²); real for
    m·sin²φ ≤ 1 (DomainError otherwise). ellipf(pi/2, m) is K(m)."""
    return _real(mpmath.ellipf(phi, m), (phi, m),
                 "F(φ, m) has no real value where m·sin²φ > 1")


def ellipe(*args):
    """E(m) or E(φ, m), the complete or incomplete integral of the second kind (m = k²)."""
    return _real(mpmath.ellipe(*args), args,
                 "E(m) has no finite real value for m > 1, nor E(φ, m) where m·sin²φ > 1")


def ellippi(*args):
    """Π(n, m) or Π(n, φ, m), the integral of the third kind ∫₀^φ dθ/((1 − n sin²θ)·
    sqrt(1 − m sin²θ)) (SymPy's and mpmath's argument order); real where 1 − m sin²θ > 0
    on the path and the principal value exists."""
    return _real(mpmath.ellippi(*args), args,
                 "Π(n, φ, m) has no real value here (m·sin²φ > 1, or n > 1 in the complete "
                 "Π(n, m))")


def _jacobi(kind: str, u, m):
    """sn, cn or dn of (u, m) at the working precision; for m > 1 by the reciprocal-
    parameter transformation (sn(u, m) = sn(√m·u, 1/m)/√m, cn(u, m) = dn(√m·u, 1/m),
    dn(u, m) = cn(√m·u, 1/m)), which keeps real values real."""
    if _is_real(u, m) and m > 1:
        r = mpmath.sqrt(m)
        if kind == "sn":
            return mpmath.ellipfun("sn", r * u, m=1 / m) / r
        return mpmath.ellipfun({"cn": "dn", "dn": "cn"}[kind], r * u, m=1 / m)
    return _real(mpmath.ellipfun(kind, u, m=m), (u, m), "not real")


def sn(u, m):
    """Jacobi's sn(u, m) (m = k²): sin of the amplitude φ with u = F(φ, m)."""
    return _jacobi("sn", u, m)


def cn(u, m):
    """Jacobi's cn(u, m) = cos φ, u = F(φ, m)."""
    return _jacobi("cn", u, m)


def dn(u, m):
    """Jacobi's dn(u, m) = sqrt(1 − m sin²φ), u = F(φ, m)."""
    return _jacobi("dn", u, m)


def besselj(nu, x):
    """J_ν(x); real for x ≥ 0, or any x where ν is an integer."""
    return _real(mpmath.besselj(nu, x), (nu, x),
                 "J_ν(x) has no real value for x < 0 unless ν is an integer")


def bessely(nu, x):
    """Y_ν(x); real for x > 0 only."""
    if _is_real(nu, x) and x <= 0:
        raise DomainError("Y_ν(x) is defined (real and finite) for x > 0 only")
    return _real(mpmath.bessely(nu, x), (nu, x), "Y_ν(x) has no real value here")


def _zero_args(nu, n) -> int:
    """The zero's order and index checked: ν real ≥ 0, n a positive integer."""
    if not _is_real(nu, n):
        raise DomainError("a zero's order ν and index n are real")
    if nu < 0:
        raise DomainError(f"a zero's order ν must be ≥ 0 (it is {mpmath.nstr(nu, 6)})")
    k = int(mpmath.nint(n))
    if k != n or k < 1:
        raise DomainError(f"a zero's index n must be a positive integer "
                         f"(it is {mpmath.nstr(n, 6)})")
    return k


def besseljzero(nu, n):
    """j_ν,n: the n-th positive zero of J_ν (n = 1, 2, ...; ν ≥ 0)."""
    return mpmath.besseljzero(nu, _zero_args(nu, n))


def besselyzero(nu, n):
    """y_ν,n: the n-th positive zero of Y_ν (n = 1, 2, ...; ν ≥ 0)."""
    return mpmath.besselyzero(nu, _zero_args(nu, n))


def _number_args(args, prec: int) -> list | None:
    """The arguments as mpmath numbers of `prec` bits if all are numbers, else None."""
    if not all(a.is_number for a in args):
        return None
    try:
        return [a._to_mpmath(prec) for a in args]
    except (TypeError, ValueError, AttributeError):
        return None


class _Special(sp.Function):
    """A function of this module: its numeric value from `_mp` (at SymPy's requested
    precision). Its domain is checked where it is evaluated: the parser's constant check
    (model.constants) refuses a call of numbers outside it with the reason."""

    _mp = staticmethod(lambda *a: None)

    def _eval_evalf(self, prec):
        with mpmath.workprec(prec):
            nums = _number_args(self.args, prec + 10)
            if nums is None:
                return None
            v = self._mp(*nums)
            if _is_real(v):
                return sp.Float(v, precision=prec)
            z = complex(v)  # as before: the complex value to double precision
            return sp.Float(z.real) + sp.I * sp.Float(z.imag)

    def _eval_is_real(self):
        return None


class jacobi_sn(_Special):  # noqa: N801 - the name a problem writes
    """sn(u, m), Jacobi's elliptic sine (parameter m = k²)."""

    nargs = 2
    _mp = staticmethod(sn)

    @classmethod
    def eval(cls, u, m):
        if u.is_zero:
            return sp.S.Zero
        if m.is_zero:
            return sp.sin(u)
        return None

    def fdiff(self, argindex=1):
        if argindex == 1:
            return jacobi_cn(*self.args) * jacobi_dn(*self.args)
        raise ArgumentIndexError(self, argindex)


class jacobi_cn(_Special):  # noqa: N801
    """cn(u, m), Jacobi's elliptic cosine."""

    nargs = 2
    _mp = staticmethod(cn)

    @classmethod
    def eval(cls, u, m):
        if u.is_zero:
            return sp.S.One
        if m.is_zero:
            return sp.cos(u)
        return None

    def fdiff(self, argindex=1):
        if argindex == 1:
            return -jacobi_sn(*self.args) * jacobi_dn(*self.args)
        raise ArgumentIndexError(self, argindex)


class jacobi_dn(_Special):  # noqa: N801
    """dn(u, m), Jacobi's delta amplitude."""

    nargs = 2
    _mp = staticmethod(dn)

    @classmethod
    def eval(cls, u, m):
        if u.is_zero or m.is_zero:
            return sp.S.One
        return None

    def fdiff(self, argindex=1):
        u, m = self.args
        if argindex == 1:
            return -m * jacobi_sn(u, m) * jacobi_cn(u, m)
        raise ArgumentIndexError(self, argindex)


class bessel_j_zero(_Special):  # noqa: N801
    """j_ν,n, the n-th positive zero of J_ν: a constant for numeric ν and n."""

    nargs = 2
    _mp = staticmethod(besseljzero)

    def fdiff(self, argindex=1):
        raise ArgumentIndexError(self, argindex)


class bessel_y_zero(_Special):  # noqa: N801
    """y_ν,n, the n-th positive zero of Y_ν."""

    nargs = 2
    _mp = staticmethod(besselyzero)

    def fdiff(self, argindex=1):
        raise ArgumentIndexError(self, argindex)


# the names a problem writes -> (what builds the SymPy object, its arity)
PARSER_FUNCTIONS = {
    "elliptic_f": (sp.elliptic_f, (2, 2)),
    "elliptic_e": (sp.elliptic_e, (1, 2)),
    "elliptic_pi": (sp.elliptic_pi, (2, 3)),
    "jacobi_sn": (jacobi_sn, (2, 2)),
    "jacobi_cn": (jacobi_cn, (2, 2)),
    "jacobi_dn": (jacobi_dn, (2, 2)),
    "besselj": (sp.besselj, (2, 2)),
    "bessely": (sp.bessely, (2, 2)),
    "bessel_j_zero": (bessel_j_zero, (2, 2)),
    "bessel_y_zero": (bessel_y_zero, (2, 2)),
}

# SymPy's function classes -> their mpmath evaluators with the real-domain guard
MPMATH = {
    sp.elliptic_f: ellipf, sp.elliptic_e: ellipe, sp.elliptic_pi: ellippi,
    jacobi_sn: sn, jacobi_cn: cn, jacobi_dn: dn,
    sp.besselj: besselj, sp.bessely: bessely,
    bessel_j_zero: besseljzero, bessel_y_zero: besselyzero,
}
