"""A linearization that is first order: E·ż = Â·z + f(t), z = (δs, δu).

A system with velocity constraints (rolling without slipping, a skate's blade) has more
coordinates than independent velocities, so its linearization is not M·δq̈ + C·δq̇ + K·δq
over one set of coordinates: it is first order in the independent coordinates δs and the
independent speeds δu (mechbook.engine.constrained builds it, as sympy.physics.mechanics'
Linearizer does with dependent speeds). The state matrix A = E⁻¹Â is what its exponents,
frequencies and stability come from; E = diag(1, M_r) with M_r the mass matrix on the
admissible velocities, kept apart so the symbolic matrices stay small (E⁻¹ is taken
numerically; `state_matrix()` gives the symbolic A on request).

Exact zero exponents are taken out before the eigenvalues are computed: a state that no
derivative depends on (a cyclic coordinate: a zero column of A) or whose derivative is zero
(a conserved speed: a zero row) adds an exponent 0 exactly; removing its row and column
leaves the rest of the spectrum unchanged (the matrix is block triangular). Left in, such
zeros form Jordan blocks that rounding splits into exponents of size ε^(1/k), which no
fixed threshold tells from a slow instability (a rolling disk keeps six of them). The rest
(`core`) is decided as the gyroscopic systems' state matrices are (mechbook.engine.linear):
an exponent with a positive real part beyond rounding is an instability; a zero cluster of
a symmetry left in the core is neutral.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import mpmath
import numpy as np
import sympy as sp

from mechbook.core.backends import FEW_CALLS_BACKEND
from mechbook.core.compile import compile_exprs
from mechbook.core.numeval import is_zero
from mechbook.engine.linear import ZERO_CLUSTER, dependent_displacements, mp_matrix
from mechbook.errors import MechbookError, UnsupportedError

FIRST_ORDER = ("has a first-order linearization (velocity constraints: more coordinates than "
               "independent velocities): {what} of M·δq̈ + C·δq̇ + K·δq do not exist; its "
               "exponents, frequencies and stability come from the state matrix")


@dataclass
class StateSpaceSystem:
    """E·ż = Â·z + f(t) about `point` (and the uniform motion `velocity`): z = (δs, δu),
    δs the independent coordinates `coords`, δu the independent speeds `speeds` (rates of
    some of them); `embedding` maps δs to every coordinate (δq = embedding·δs) and
    `speed_map` (T, R) gives δṡ = T·δu + R·δs."""

    dyn: object
    point: dict
    E: sp.Matrix
    Ahat: sp.Matrix
    f: sp.Matrix
    coords: list
    speeds: list
    embedding: sp.Matrix
    speed_map: tuple[sp.Matrix, sp.Matrix]
    velocity: dict = field(default_factory=dict)
    first_order = True

    # ---- what a second-order system has and this one does not -------------------------
    @property
    def M(self):
        raise UnsupportedError(FIRST_ORDER.format(what="M, C and K"))

    C = K = F = M

    def matrices(self, values: dict):
        raise UnsupportedError(FIRST_ORDER.format(what="M, C and K"))

    def numeric_modes(self, values: dict):
        raise UnsupportedError(FIRST_ORDER.format(what="real normal modes"))

    @property
    def frequencies(self):
        raise UnsupportedError(FIRST_ORDER.format(what="closed-form frequencies"))

    @property
    def stability_condition(self):
        raise UnsupportedError(FIRST_ORDER.format(what="Sylvester's conditions on K"))

    # ---- the linear system's coordinates ------------------------------------------------
    @property
    def q(self) -> list:
        return list(self.coords)

    @property
    def qd(self) -> list:
        return [self.dyn.qd[self.dyn.q.index(c)] for c in self.coords]

    @property
    def coord_names(self) -> list[str]:
        return [str(q) for q in self.coords]

    @property
    def states(self) -> list[str]:
        """The state's names: the independent coordinates, then the independent speeds."""
        return [f"delta_{c}" for c in self.coords] + [f"delta_{s}" for s in self.speeds]

    @property
    def dependent(self) -> dict:
        ds = sp.Matrix([q - self.point.get(q, 0) for q in self.coords])
        return dependent_displacements(self.dyn.q, self.coords, self.embedding, ds)

    @cached_property
    def gyroscopic(self) -> bool:
        return True  # velocity terms: decided from the state matrix, as with C ≠ 0

    @cached_property
    def driven(self) -> bool:
        return not all(is_zero(x) for x in self.f)

    def state_matrix(self) -> sp.Matrix:
        """A = E⁻¹Â, symbolic (the lower block solved by LU; entries cancelled)."""
        n = len(self.coords)
        low = self.E[n:, n:].LUsolve(self.Ahat[n:, :])
        return sp.Matrix.vstack(self.Ahat[:n, :], low).applyfunc(sp.cancel)

    # ---- numbers -----------------------------------------------------------------------
    @cached_property
    def core(self) -> list[int]:
        """The states left once those that add an exact zero exponent are taken out: a
        zero column of A (nothing depends on the state) or a zero row (the state is
        constant), repeatedly. An entry is zero where it vanishes to 1e-30 of the matrix
        at two random parameter points (40 digits): an entry that is not identically zero
        vanishes at a random point with probability zero."""
        rng = np.random.default_rng(20261129)
        base = dict(self.dyn.sys.numeric_values())
        free = set().union(*(x.free_symbols for x in list(self.E) + list(self.Ahat)))
        base.update({x: 0.3 + rng.uniform(0, 1) for x in free if x not in base})
        zero = None
        for _ in range(2):
            values = {k: sp.Float(v * float(np.exp(rng.uniform(-0.3, 0.3))) if k.is_positive
                                  else v + rng.uniform(-0.3, 0.3), 40) for k, v in base.items()}
            A = self._mp_state(values, 40, core=False)
            scale = max([abs(x) for x in A] + [mpmath.mpf(10) ** -300])
            here = [[abs(A[i, j]) <= mpmath.mpf(10) ** -30 * scale for j in range(A.cols)]
                    for i in range(A.rows)]
            zero = here if zero is None else [[a and b for a, b in zip(r1, r2, strict=True)]
                                              for r1, r2 in zip(zero, here, strict=True)]
        keep = list(range(self.Ahat.rows))
        changed = True
        while changed:
            changed = False
            for j in list(keep):
                if all(zero[i][j] for i in keep) or all(zero[j][i] for i in keep):
                    keep.remove(j)
                    changed = True
        return keep

    @property
    def neutral(self) -> int:
        """How many exact zero exponents the structure gives (taken out of `core`)."""
        return self.Ahat.rows - len(self.core)

    @cached_property
    def _speed_block(self) -> int | None:
        """k where E = diag(1_k, M_r) (the coordinates' rows are δṡ = …, as constrained.py
        builds it): then A's first k rows are Â's and the rest M_r⁻¹ times Â's, and only
        M_r is inverted. None for any other E."""
        k = len(self.coords)
        n = self.E.rows
        ok = all((self.E[i, j] == (1 if i == j else 0)) for i in range(k) for j in range(n)) \
            and all(self.E[i, j] == 0 for i in range(k, n) for j in range(k))
        return k if ok else None

    def _mp_state(self, values: dict, dps: int, core: bool = True):
        """A = E⁻¹Â at `values` (its `core` rows and columns only, unless core=False), at
        `dps` digits: only the entries it needs are evaluated."""
        n = self.Ahat.rows
        idx = self.core if core else list(range(n))
        k = self._speed_block
        with mpmath.workdps(dps):
            if k is None:
                E = mp_matrix(self.E, values, dps)
                Ahat = mp_matrix(self.Ahat, values, dps)
                A = mpmath.inverse(E) * Ahat if E.rows else Ahat
                rows = {i: i for i in idx}
            else:
                head = [i for i in idx if i < k]
                A = mp_matrix(self.Ahat.extract(head, idx), values, dps) if head else None
                top = {i: a for a, i in enumerate(head)}
                if k < n:
                    low = mp_matrix(self.Ahat.extract(list(range(k, n)), idx), values, dps)
                    low = mpmath.inverse(mp_matrix(self.E[k:, k:], values, dps)) * low
                rows = top
            out = mpmath.matrix(len(idx), len(idx))
            for a, i in enumerate(idx):
                for b, j in enumerate(idx):
                    if k is None:
                        out[a, b] = A[i, j]
                    else:
                        out[a, b] = A[rows[i], b] if i < k else low[i - k, b]
            return out

    def mp_state_matrix(self, values: dict, dps: int = 50):
        """The whole state matrix at `values`, in mpmath at `dps` digits."""
        return self._mp_state(values, dps, core=False)

    def numeric_state_matrix(self, values: dict, core: bool = False) -> np.ndarray:
        """The state matrix (or its `core`) at `values`, from 30-digit entries."""
        A = self._mp_state(values, 30, core)
        return np.array([[float(mpmath.re(A[i, j])) for j in range(A.cols)]
                         for i in range(A.rows)], dtype=float).reshape(A.rows, A.cols)

    def exponents(self, values: dict, precise: bool = False) -> np.ndarray:
        """Every exponent p of e^{pt}: the core's eigenvalues and the structural zeros."""
        if precise:
            return np.array([complex(x) for x in self.precise_exponents(values)])
        core = self.numeric_state_matrix(values, core=True)
        lam = np.linalg.eigvals(core) if core.size else np.zeros(0, complex)
        return np.concatenate([lam, np.zeros(self.neutral, complex)])

    def precise_exponents(self, values: dict, dps: int = 50) -> list:
        """The exponents at `dps` digits (mpmath), structural zeros exact."""
        with mpmath.workdps(dps):
            A = self._mp_state(values, dps)
            return _eigenvalues(A) + [mpmath.mpf(0)] * self.neutral

    def numeric_frequencies(self, values: dict) -> np.ndarray:
        """The oscillation frequencies: |Im p| of each exponent pair ±iω (one per pair);
        NaN for each exponent that grows without oscillating. Zero exponents (the steady
        family, cyclic coordinates, conserved speeds) are not frequencies."""
        core = self.numeric_state_matrix(values, core=True)
        lam = np.linalg.eigvals(core) if core.size else np.zeros(0, complex)
        if ambiguous_exponents(lam):
            lam = np.array([complex(x) for x in self.precise_exponents(values)[: core.shape[0]]])
        return frequencies_of_exponents(lam)

    def precise_frequencies(self, values: dict, dps: int = 50) -> list:
        """`numeric_frequencies` at `dps` digits."""
        with mpmath.workdps(dps):
            lam = self.precise_exponents(values, dps)[: len(self.core)]
            scale = max([abs(x) for x in lam] + [mpmath.mpf(1)])
            tiny = mpmath.mpf(10) ** (20 - dps) * scale
            out = [abs(mpmath.im(x)) for x in lam if mpmath.im(x) > tiny]
            out += [mpmath.nan for x in lam if abs(mpmath.im(x)) <= tiny and
                    mpmath.re(x) > tiny]
            return sorted(out, key=lambda x: (mpmath.isnan(x), x))

    @cached_property
    def _compiled_core(self):
        """(symbols, function, the core's rows among the coordinates' rows, k) for the core's
        state matrix in double precision (E = diag(1_k, M_r) only), compiled once; None
        where it cannot be."""
        k = self._speed_block
        if k is None:
            return None
        idx, n = self.core, self.Ahat.rows
        head = [i for i in idx if i < k]
        exprs = ([self.Ahat[i, j] for i in head for j in idx]
                 + [self.Ahat[i, j] for i in range(k, n) for j in idx] + list(self.E[k:, k:]))
        syms = sorted(set().union(*(sp.S(x).free_symbols for x in exprs)), key=lambda x: x.name)
        try:
            fn, _ = compile_exprs(syms, exprs, FEW_CALLS_BACKEND)
        except UnsupportedError:
            return None
        return syms, fn, head, k

    def fast_core_matrix(self, values: dict) -> np.ndarray | None:
        """The core's state matrix at `values` in double precision (Â's entries and M_r by
        the compile layer, M_r⁻¹ by LU): for the many verdicts of a boundary's rays, where
        the 30-digit matrix would dominate. None where it cannot be had (the caller then
        takes `numeric_state_matrix`)."""
        got = self._compiled_core
        if got is None:
            return None
        syms, fn, head, k = got
        if any(x not in values for x in syms):
            return None
        idx, n = self.core, self.Ahat.rows
        m, s = len(idx), n - k
        with np.errstate(all="ignore"):
            out = np.asarray(fn(np.array([float(values[x]) for x in syms])), dtype=float)
            top = out[: len(head) * m].reshape(len(head), m)
            low = out[len(head) * m: len(head) * m + s * m].reshape(s, m)
            Mr = out[len(head) * m + s * m:].reshape(s, s)
            try:
                low = np.linalg.solve(Mr, low) if s else low
            except np.linalg.LinAlgError:
                return None
        rows = {i: a for a, i in enumerate(head)}
        A = np.array([top[rows[i]] if i < k else low[i - k] for i in idx],
                     dtype=float).reshape(m, m)
        return A if np.all(np.isfinite(A)) else None

    def numeric_stability(self, values: dict) -> str:
        """'stable' or 'unstable' from the core's exponents in double precision (the core
        by the compile layer where it can be); at 40 digits where those exponents are
        ambiguous (`ambiguous_exponents`)."""
        core = self.fast_core_matrix(values)
        if core is None:
            core = self.numeric_state_matrix(values, core=True)
        if not core.size:
            return "stable"
        if not np.all(np.isfinite(core)):
            raise MechbookError("the linearized system has no finite value at this point")
        lam = np.linalg.eigvals(core)
        if ambiguous_exponents(lam):
            return self.precise_stability(values)
        return classify_exponents(lam)

    def precise_stability(self, values: dict, dps: int = 40) -> str:
        """`numeric_stability` with the core and its eigenvalues at `dps` digits."""
        with mpmath.workdps(dps):
            A = self._mp_state(values, dps)
            if not A.rows:
                return "stable"
            lam = _eigenvalues(A)
            scale = max([abs(x) for x in lam] + [mpmath.mpf(1)])
            tiny = mpmath.mpf(10) ** (12 - dps)
            live = [x for x in lam if abs(x) > mpmath.mpf(10) ** (-dps / 4) * scale]
            return "unstable" if any(mpmath.re(x) > tiny * scale for x in live) else "stable"

    def fast_matrices(self, values: dict):
        raise UnsupportedError(FIRST_ORDER.format(what="M, C and K"))


def classify_exponents(lam: np.ndarray) -> str:
    """'stable' or 'unstable' from exponents in double precision: a real part beyond 1e-8 of
    the largest is a growth; a zero cluster (ZERO_CLUSTER of the largest) is neutral."""
    if not len(lam):
        return "stable"
    scale = max(1.0, float(np.max(np.abs(lam))))
    live = lam[np.abs(lam) > ZERO_CLUSTER * scale]
    return "unstable" if np.any(live.real > 1e-8 * scale) else "stable"


def _eigenvalues(A) -> list:
    """The eigenvalues of an mpmath matrix (mpmath's eig answers a 1×1 matrix otherwise)."""
    if A.rows == 0:
        return []
    if A.rows == 1:
        return [A[0, 0]]
    return list(mpmath.eig(A, left=False, right=False))


def ambiguous_exponents(lam: np.ndarray) -> bool:
    """Exponents double precision cannot place: small ones (below 1e-4 of the largest)
    that are several (a Jordan block's zero, which rounding splits into ±ε^(1/k)) or one
    above rounding (a slow mode, or a split zero). A single exponent at rounding level is a
    plain zero. Then the exponents are taken at 40-50 digits."""
    mags = np.abs(lam)
    top = float(np.max(mags)) if len(mags) else 0.0
    small = mags[mags < 1e-4 * top]
    return len(small) >= 2 or bool(np.any(small > 1e-10 * top))


def frequencies_of_exponents(lam: np.ndarray) -> np.ndarray:
    scale = max(1e-300, float(np.max(np.abs(lam)))) if len(lam) else 1.0
    tol = 1e-9 * scale
    out = [abs(x.imag) for x in lam if x.imag > tol]
    out += [float("nan") for x in lam if abs(x.imag) <= tol and x.real > max(tol, 1e-8 * scale)]
    return np.array(sorted(out, key=lambda w: (w != w, w)))
