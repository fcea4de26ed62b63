"""Compiled stepping: the C loops of `loops.c` driving the equations' LLVM kernels.

Why: a step of a fixed-step method, or a right-hand-side call from SciPy, cost ~20 µs in
Python (wrapping, a NumPy solve, concatenation, a finiteness check) against ~0.05 µs of
arithmetic. Here the whole loop runs in C and calls the machine code SymEngine's LLVM
backend already made for M and f (`Lambdify.as_ctypes`: no second compile per system); the
small mass-matrix solve is in C too. `loops.c` is generic (n, m at run time), so it is
compiled once per machine with the system's C compiler (`cc`, or $CC) and cached by the
hash of its source under $MECHBOOK_CACHE (default ~/.cache/mechbook). Without a compiler,
or with MECHBOOK_NATIVE=0, everything falls back to the Python reference loops in
`fixed_step.py` (and scipy's solve_ivp), which compute the same numbers.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import shutil
import subprocess
import tempfile
import time
import weakref
from pathlib import Path

import numpy as np

SOURCE = Path(__file__).with_name("loops.c")
FLAGS = ("-O2", "-ffp-contract=off", "-fPIC", "-shared")  # no FMA: rounding as in NumPy

_P = ctypes.c_void_p
_D = ctypes.c_double
_L = ctypes.c_long
_I = ctypes.c_int
_SIGNATURES = {
    "mb_model_new": (_P, [_P, _P, _P, _P, _I, _I]),
    "mb_model_free": (None, [_P]),
    "mb_nfev": (_L, [_P]),
    "mb_rhs": (_I, [_P, _D, _P, _P]),
    "mb_accel": (_I, [_P, _D, _P, _P, _P]),
    "mb_rk4": (_L, [_P, _D, _D, _L, _P, _P, _L, _P, _P, _L]),
    "mb_leapfrog": (_L, [_P, _D, _D, _L, _P, _I, _P, _P, _P, _L, _P, _P, _L]),
    "mb_midpoint": (_L, [_P, _D, _D, _L, _P, _D, _I, _P, _L, _P, _P, _L]),
    "mb_rhs_repeat": (None, [_P, _D, _P, _P, _L]),
    "mb_rk_adaptive": (_L, [_P, _I, _D, _D, _P, _D, _P, _D, _D, _P, _P, _P, _P, _P, _P, _P,
                            _L, _P, _P, _P, _P, _L]),
}

_state: dict = {"lib": None, "tried": False, "build_seconds": 0.0, "why": ""}


def cache_dir() -> Path:
    base = os.environ.get("MECHBOOK_CACHE")
    if base:
        return Path(base)
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "mechbook"


def _compiler() -> str | None:
    return shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc")


def library() -> ctypes.CDLL | None:
    """The loaded loop library, built on first use; None where it cannot be (then
    `why()` says why and the Python loops run)."""
    if _state["tried"]:
        return _state["lib"]
    _state["tried"] = True
    if os.environ.get("MECHBOOK_NATIVE", "1") == "0":
        _state["why"] = "MECHBOOK_NATIVE=0"
        return None
    cc = _compiler()
    if cc is None:
        _state["why"] = "no C compiler (cc) found"
        return None
    source = SOURCE.read_bytes()
    tag = hashlib.sha256(source + " ".join((cc, *FLAGS)).encode()).hexdigest()[:16]
    target = cache_dir() / f"loops-{tag}.so"
    try:
        if not target.exists():
            start = time.perf_counter()
            target.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(suffix=".so", dir=target.parent)
            os.close(fd)
            try:
                subprocess.run([cc, *FLAGS, "-o", tmp, str(SOURCE), "-lm"], check=True,
                               capture_output=True, timeout=120)
                os.replace(tmp, target)  # atomic: parallel workers never see half a file
            finally:
                if os.path.exists(tmp):
                    os.unlink(tmp)
            _state["build_seconds"] = time.perf_counter() - start
        lib = ctypes.CDLL(str(target))
    except (OSError, subprocess.SubprocessError) as exc:
        _state["why"] = f"building {SOURCE.name} failed: {exc}"
        return None
    for name, (res, args) in _SIGNATURES.items():
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = res, args
    _state["lib"] = lib
    return lib


def why() -> str:
    return _state["why"]


def build_seconds() -> float:
    """Seconds this process spent compiling loops.c (0 when the cached build was used)."""
    return _state["build_seconds"]


def kernel_pointer(compiled) -> tuple[int, int] | None:
    """(function address, user data) of a compile-layer function made by the LLVM backend,
    or None (another backend: no machine code to call)."""
    fn = getattr(compiled, "lambdify", None)
    if fn is None or not hasattr(fn, "as_ctypes"):
        return None
    cfunc, user = fn.as_ctypes()
    return ctypes.cast(cfunc, ctypes.c_void_p).value, user.value


def address(a: np.ndarray) -> int:
    return a.__array_interface__["data"][0]


class NativeModel:
    """A model_t of loops.c: the kernels of one Model plus the solve's work space."""

    def __init__(self, lib: ctypes.CDLL, kernel: tuple[int, int], n: int, m: int,
                 canonical: tuple[int, int] | None = None, keep: tuple = ()):
        self.lib, self.n, self.m = lib, n, m
        self._keep = keep  # the Lambdify objects owning the machine code
        canon = canonical or (None, None)
        self.ptr = lib.mb_model_new(kernel[0], kernel[1], canon[0], canon[1], n, m)
        self.has_canonical = canonical is not None
        self._y = np.zeros(2 * n)
        self._dy = np.zeros(2 * n)
        self._ya, self._dya = address(self._y), address(self._dy)
        weakref.finalize(self, lib.mb_model_free, self.ptr)

    def nfev(self) -> int:
        return int(self.lib.mb_nfev(self.ptr))

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        """dy/dt into a new array; raises LinAlgError on a singular matrix, as the NumPy
        solve does."""
        self._y[:] = y
        if self.lib.mb_rhs(self.ptr, t, self._ya, self._dya):
            raise np.linalg.LinAlgError("Singular matrix")
        return self._dy.copy()

    def accelerations(self, t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        n = self.n
        self._y[:n] = q
        self._y[n:] = qd
        if self.lib.mb_accel(self.ptr, t, self._ya, self._ya + 8 * n, self._dya):
            raise np.linalg.LinAlgError("Singular matrix")
        return self._dy[:n].copy()


__all__ = ["NativeModel", "build_seconds", "cache_dir", "kernel_pointer", "library", "why"]
