"""The compile layer: SymPy expressions turned into fast numeric functions, once.

Every numeric evaluation of engine expressions at many points goes through here: the
simulation's right-hand side (mechbook.numerics.rhs), the phase-space flow, the numeric
equilibrium search, the cross-checks and region checks. Two entries:

    compile_exprs(args, exprs)  f(x) for one point x (a flat vector of the args' values)
                                -> a flat array of the expressions' values
    compile_batch(args, exprs)  f(X) for N points at once, X of shape (N, len(args))
                                -> an array of shape (N, len(exprs)) (NaN where undefined)

Backends (docs/numerics.md has the measurements that chose the default):
    llvm      SymEngine's Lambdify, LLVM-compiled, with cse (the default)
    symengine SymEngine's Lambdify, interpreted ("lambda" backend), with cse
    sympy     SymPy's lambdify(cse=True) printing to `math` (one point) or NumPy and SciPy's
              special functions (batches, and a point `math` cannot take)
A backend that cannot translate an expression hands over to the next. Nothing here parses
text: the inputs are SymPy objects built by the safe parser or the engine, or SymEngine
objects the engine built from those (`as_expr` refuses anything else).
"""

from __future__ import annotations

import numbers
from collections.abc import Callable, Sequence

import numpy as np
import sympy as sp

from mechbook.core import special
from mechbook.core.backends import BACKENDS, DEFAULT_BACKEND  # the names' owner
from mechbook.errors import UnsupportedError

Compiled = Callable[[np.ndarray], np.ndarray]


def numpy_modules() -> list:
    """lambdify's namespaces for NumPy: SciPy's special functions (Γ, Bessel's J_ν, Y_ν) and
    the elliptic integrals K(m), E(m), F(φ, m), E(φ, m) (scipy.special.ellipk, ellipe,
    ellipkinc, ellipeinc: the same parameter m = k² as SymPy's), which neither SymEngine nor
    SymPy's printers translate; Π, Jacobi's sn, cn, dn and the Bessel zeros, which SciPy has
    not for every argument, element by element from mechbook.core.special at double
    precision (NaN outside their domain). SciPy is imported here, when an expression needs
    this fallback, not when mechbook starts."""
    import scipy.special

    def elliptic_e(*args):
        return scipy.special.ellipe(*args) if len(args) == 1 else \
            scipy.special.ellipeinc(*args)

    names = {"elliptic_k": scipy.special.ellipk, "elliptic_e": elliptic_e,
             "elliptic_f": scipy.special.ellipkinc}
    for fn, mp in special.MPMATH.items():
        names.setdefault(fn.__name__, _elementwise(mp))
    return [names, "numpy", "scipy"]


def _elementwise(mp) -> Callable:
    """An mpmath evaluator as a NumPy function of arrays, at double precision: NaN where it
    refuses the point (outside its domain)."""
    import mpmath

    def one(*args) -> float:
        try:
            with mpmath.workprec(53):
                v = mp(*(mpmath.mpf(float(a)) for a in args))
            return float(v) if mpmath.im(v) == 0 else float("nan")
        except (ValueError, ZeroDivisionError, OverflowError):
            return float("nan")

    vectorized = np.vectorize(one, otypes=[float])
    return lambda *args: vectorized(*args)[()]


def as_expr(e) -> sp.Basic:
    """An engine result as a SymPy object: plain numbers are wrapped, anything else (text
    above all) is refused; nothing here is ever parsed."""
    if isinstance(e, sp.Basic):
        return e
    if isinstance(e, numbers.Integral) and not isinstance(e, bool):  # NumPy's too
        return sp.Integer(int(e))
    if isinstance(e, numbers.Real):
        return sp.Float(float(e))
    if isinstance(e, numbers.Complex):
        return sp.Float(e.real) + sp.I * sp.Float(e.imag)
    raise TypeError(f"not an engine expression: {type(e).__name__}")


def _checked(e):
    """`as_expr`, but a SymEngine expression (the engine's fast algebra) passes as it is."""
    import symengine as se

    return e if isinstance(e, se.Basic) else as_expr(e)


def _sympy(e) -> sp.Basic:
    """A SymPy object for the SymPy backend (SymEngine's converted)."""
    return e if isinstance(e, sp.Basic) else e._sympy_()


def compile_exprs(args: Sequence[sp.Symbol], exprs: Sequence[sp.Expr],
                  backend: str = DEFAULT_BACKEND) -> tuple[Compiled, str]:
    """Compile `exprs` (a flat list) in `args` into f(vector) -> array, with cse.

    Returns the function and the backend that actually compiled it (a backend that cannot
    translate an expression hands over to the next in BACKENDS)."""
    if backend not in BACKENDS:
        raise ValueError(f"unknown backend {backend!r}; known: {', '.join(BACKENDS)}")
    exprs = [_checked(e) for e in exprs]
    order = list(BACKENDS[BACKENDS.index(backend):])
    last: Exception | None = None
    for name in order:
        try:
            return _COMPILERS[name](list(args), exprs), name
        except Exception as exc:  # noqa: BLE001 - any failure hands over to the next backend
            last = exc
    raise UnsupportedError(f"compiling the equations of motion numerically ({last})")


def _compile_symengine(args, exprs, backend: str) -> Compiled:
    import symengine as se

    # SymPy objects converted to SymEngine ones (_checked has refused anything but those)
    se_args = [se.sympify(_checked(a)) for a in args]
    se_exprs = [se.sympify(e) for e in exprs]
    if not exprs:
        return lambda x: np.zeros(0)
    fn = se.Lambdify(se_args, se_exprs, real=True, cse=True, backend=backend)
    probe = fn(np.full(len(args), 0.3))  # surface translation errors now, not mid-run
    if np.asarray(probe).shape[-1:] != (len(exprs),) and len(exprs) != 1:
        raise ValueError("unexpected output shape from Lambdify")

    nargs, width = len(args), len(exprs)

    def call(x: np.ndarray) -> np.ndarray:
        # one point as float64 in one block: the machine code's own entry, without
        # Lambdify's checks and broadcasting (0.5 µs against 2.9 µs a call; the same code,
        # so the same values); anything else (a batch, a list) through Lambdify
        if type(x) is np.ndarray and x.dtype == np.float64 and x.shape == (nargs,) \
                and x.flags.c_contiguous and x.flags.writeable:
            out = np.empty(width)
            fn.unsafe_real(x, out)
            return out
        return np.asarray(fn(x), dtype=float).reshape(-1)

    # the LLVM object itself: mechbook.numerics.c_library calls its machine code directly
    call.lambdify = fn  # type: ignore[attr-defined]
    return call


def _compile_sympy(args, exprs) -> Compiled:
    if not exprs:
        return lambda x: np.zeros(0)
    args, exprs = [_sympy(a) for a in args], [_sympy(e) for e in exprs]
    try:
        fn = sp.lambdify(args, exprs, modules="math", cse=True)
        fn(*([0.3] * len(args)))
    except (NameError, TypeError, ValueError, AttributeError, ZeroDivisionError):
        fn = sp.lambdify(args, exprs, modules=numpy_modules(), cse=True)
        _untranslated(fn, len(args))

    nan = np.full(len(exprs), np.nan)

    def call(x: np.ndarray) -> np.ndarray:
        try:
            return np.array(fn(*x), dtype=float).reshape(-1)
        except (ValueError, ZeroDivisionError, OverflowError):  # math's domain errors
            return nan.copy()

    return call


def _untranslated(fn, nargs: int) -> None:
    """Refuse now a function lambdify could not translate (it would raise NameError at the
    first evaluation, mid-run): DiracDelta, from differentiating sign or Heaviside, is the
    usual one."""
    try:
        with np.errstate(all="ignore"):
            fn(*([0.3] * nargs))
    except NameError as exc:
        name = getattr(exc, "name", None) or str(exc)
        hint = " (the derivative of sign or Heaviside)" if "DiracDelta" in str(exc) else ""
        raise ValueError(f"{name}{hint} has no numeric form") from None
    except Exception:  # noqa: BLE001, S110 - a value error at the probe point only
        pass


_COMPILERS: dict[str, Callable[[list, list], Compiled]] = {
    "llvm": lambda a, e: _compile_symengine(a, e, "llvm"),
    "symengine": lambda a, e: _compile_symengine(a, e, "lambda"),
    "sympy": _compile_sympy,
}




def compile_batch(args: Sequence[sp.Symbol], exprs: Sequence[sp.Expr],
                  backend: str = DEFAULT_BACKEND) -> Callable[[np.ndarray], np.ndarray]:
    """Compile `exprs` in `args` into F(X) -> (N, len(exprs)) for X of shape (N, len(args)).

    Points where an expression is undefined come out NaN (never an exception), so a batch
    of sample points can be filtered afterwards."""
    if backend not in BACKENDS:
        raise ValueError(f"unknown backend {backend!r}; known: {', '.join(BACKENDS)}")
    exprs = [_checked(e) for e in exprs]
    width = len(exprs)
    if not width:
        return lambda X: np.zeros((np.asarray(X).shape[0], 0))
    last: Exception | None = None
    for name in BACKENDS[BACKENDS.index(backend):]:
        try:
            if name == "sympy":
                fn = sp.lambdify([_sympy(a) for a in args], [_sympy(e) for e in exprs],
                                 modules=numpy_modules(), cse=True)
                _untranslated(fn, len(args))

                def batch(X, fn=fn):
                    X = np.asarray(X, dtype=float)
                    with np.errstate(all="ignore"):
                        cols = fn(*X.T)
                    return np.column_stack([np.broadcast_to(np.asarray(c, dtype=float),
                                                            (X.shape[0],)) for c in cols])
            else:
                import symengine as se

                fn = se.Lambdify([se.sympify(_checked(a)) for a in args],
                                 [se.sympify(e) for e in exprs], real=True, cse=True,
                                 backend="llvm" if name == "llvm" else "lambda")
                fn(np.full((2, len(args)), 0.3))  # translation errors now, not mid-run

                def batch(X, fn=fn):
                    X = np.asarray(X, dtype=float)
                    with np.errstate(all="ignore"):
                        return np.asarray(fn(X), dtype=float).reshape(X.shape[0], width)
            return batch
        except Exception as exc:  # noqa: BLE001 - any failure hands over to the next backend
            last = exc
    raise UnsupportedError(f"compiling expressions numerically ({last})")
