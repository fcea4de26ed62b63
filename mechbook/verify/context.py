"""The context an answer part is checked in: its system, names, sampler and point.

A part's check reads everything it needs through a `Context`: the system the part names,
the names it may use (parameters, coordinates, answer symbols, abbreviations, `define:`
forms, momenta p_<q>), a `Sampler` of admissible parameter points (conditions and `assume:`
honoured, with the user's proof policy), and the equilibrium or steady motion it refers to
(`about:`, `steady:`), linearized by the engine on demand. Small helpers shared by several
families of quantities live here too.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import sympy as sp

from mechbook.engine.analysis import Analysis
from mechbook.engine.lagrange import solve_accelerations
from mechbook.engine.linear import LinearSystem
from mechbook.errors import WrongAnswerError
from mechbook.model.expr import DOUBLE_DIGITS, decimal_digits, split_single_equals
from mechbook.model.hints import did_you_mean
from mechbook.model.manifold import manifold_of
from mechbook.records import NUMERIC, ProofPolicy
from mechbook.verify.compare import Sampler, value, vanishes
from mechbook.verify.part import Part
from mechbook.verify.registration import Quantity, QuantityTable


@dataclass
class Context:
    """What one part is checked in, built in named steps: the quantity's entry (from
    `quantities`, by default the table its key was read against), the system and the names
    the part may use, its `define:` forms, and the sampler of admissible points."""

    analysis: Analysis
    part: Part
    policy: ProofPolicy = NUMERIC
    validate_only: bool = False  # tensor parts: build the statement once, judge nothing
    quantities: QuantityTable | None = None  # None: the table the part's key was read with
    # told how a long computation goes ("part a (lyapunov): t = 400 of 1000"), as the
    # checker's stage: a check stopped from outside then says how far it got
    stage: Callable[[str], None] | None = None

    def __post_init__(self):
        self.quantity: Quantity = self._entry()
        self.tensor_mode = not self.quantity.needs_system
        self.system, self.names, self.unavailable = self._system_and_names()
        self._add_defines()
        self.sampler = self._sampler()

    def _entry(self) -> Quantity:
        """The part's quantity in the table; SpecError at `quantity:` if it is not there."""
        table = self.part.key.quantities if self.quantities is None else self.quantities
        entry = table.get(self.part.quantity)
        if entry is None:
            hint = did_you_mean(self.part.quantity, list(table))
            raise self.part.error(("quantity",), f"{self.part.quantity!r} is not a quantity "
                                  f"of the table this check uses ({len(table)} quantities"
                                  + (f"; {hint})" if hint else ")"))
        return entry

    def _system_and_names(self) -> tuple:
        """(the part's system or None, the names it may use, {abbreviation: why it does not
        parse here}): a system's names with the momenta p_<q> and the multipliers
        lambda_<constraint>, or the problem's declared ones for a tensor or body quantity."""
        problem = self.analysis.problem
        if self.part.system is None and (self.tensor_mode or not problem.systems):
            decl = self.analysis.declared()  # a tensor or body quantity, or no system
            return (None, *self.part.names(decl.names, tensor=True, bodies=decl.bodies))
        try:
            system = self.analysis.system(self.part.system)
        except KeyError as exc:  # no `system:` in a multi-system problem, or a wrong one
            raise self.part.error(("system",) if self.part.system else (),
                                  str(exc.args[0]) + "; name it with `system:`") from None
        names = dict(system.names)
        bodies = None
        if self.tensor_mode:
            decl = self.analysis.declared()
            _merge_declared(names, decl.names, self.part)
            bodies = decl.bodies
        names, unavailable = self.part.names(names, tensor=self.tensor_mode, bodies=bodies)
        for c in system.coord_names:  # momenta, for Hamiltonians: p_<coordinate>
            names.setdefault("p_" + c, sp.Symbol("p_" + c, real=True))
        for c, _ in list(system.constraints) + list(system.velocity_constraints):
            name = "lambda_" + c  # a constraint's multiplier, as the engine names it
            names.setdefault(name, sp.Symbol(name, real=True))
        return system, names, unavailable

    def _add_defines(self) -> None:
        """The part's `define:` forms (e.g. alpha = theta - pi) and their rates, as names."""
        if self.system is not None and not self.tensor_mode:
            for k, v in (self.part.data.get("define") or {}).items():
                if k in self.names:
                    raise self.part.error(("define", k), f"{k!r} is already a name")
                f = self.parse(v, ("define", k))
                self.names[k] = f
                self.names[k + "dot"] = self.system.dt(f)
                self.names[k + "ddot"] = self.system.dt(self.system.dt(f))
        elif self.part.data.get("define") and not self.tensor_mode:
            raise self.part.error(("define",), "`define` needs a system (it names "
                                  "combinations of coordinates)")

    def _sampler(self) -> Sampler:
        """The admissible points: the problem's conditions and the part's `assume:`, its
        `restrict:` (symbols given by the others), a constrained system's manifold, and an
        `estimate:`'s one point and tolerance."""
        conds = list(self.analysis.problem.conditions)
        conds += [self.parse(c, ("assume", i), relation=True)
                  for i, c in enumerate(self.part.data.get("assume", []))]
        base = dict(self.analysis.problem.values())
        base.update(self.part.key.symbol_values)
        derived = self._restrictions(base)
        # a constrained system's states are drawn on its constraint manifold
        manifold = (manifold_of(self.system) if self.system is not None and
                    not self.tensor_mode else None)
        approximate = self._written_digits() > DOUBLE_DIGITS
        if "estimate" not in self.part.data:
            return Sampler(base, conds, policy=self.policy, derived=derived,
                           manifold=manifold, approximate=approximate)
        est = self.part.data["estimate"]  # a number the book computed: one point, its rtol
        for k, v in (est.get("values") or {}).items():
            sym = self.names.get(k)
            if not isinstance(sym, sp.Symbol) or sym not in base:
                raise self.part.error(("estimate", "values", k), f"{k!r} is not a "
                                      "parameter or answer symbol")
            val = self.parse(v, ("estimate", "values", k))
            if not val.is_number:
                raise self.part.error(("estimate", "values", k), "a number is expected")
            base[sym] = float(val)
        return Sampler(base, conds, policy=self.policy, rtol=float(est["rtol"]),
                       fixed=list(base), derived=derived, manifold=manifold,
                       approximate=approximate)

    def _written_digits(self) -> int:
        """The most digits a decimal number is written with in the part or the key's
        abbreviations (a root to 36 digits: true to those, not exact)."""
        texts = [self.part.data, self.part.key.doc.data.get("abbreviations") or {}]
        most = 0
        while texts:
            t = texts.pop()
            if isinstance(t, dict):
                texts.extend(v for k, v in t.items() if k not in PROSE)
            elif isinstance(t, list):
                texts.extend(t)
            else:
                most = max(most, decimal_digits(t))
        return most

    def _restrictions(self, base: dict) -> dict:
        """The part's `restrict:`: {symbol: its expression in the other symbols}."""
        derived = {}
        for k, v in (self.part.data.get("restrict") or {}).items():
            sym = self.names.get(k)
            if not isinstance(sym, sp.Symbol) or sym not in base:
                raise self.part.error(("restrict", k), f"{k!r} is not a parameter or symbol")
            expr = self.parse(v, ("restrict", k))
            if expr.free_symbols & ({sym} | set(derived)):
                raise self.part.error(("restrict", k), "a restricted symbol is given by the "
                                      "others, not by itself or another restricted one")
            derived[sym] = expr
        return derived

    @property
    def dyn(self):
        if self.system is None:
            raise self.part.error(("quantity",), f"{self.part.quantity!r} needs a system "
                                  "(coordinates and a Lagrangian); this problem has none")
        return self.analysis.dynamics(self.part.system)

    @property
    def bodies(self) -> dict:
        """The problem's declared bodies (for the body functions of tensor expressions)."""
        return self.analysis.declared().bodies

    def parse(self, text, sub: tuple, equation: bool = False, relation: bool = False,
              names: dict | None = None) -> sp.Basic:
        """`text` parsed with the part's names (or `names`, e.g. with a quantity's extra
        ones); SpecError at `sub` if it does not parse."""
        return self.part.parse(text, sub, self.names if names is None else names, equation,
                               relation, self.quantity.complex_values, self.unavailable)

    def point(self) -> dict:
        about = self.part.data.get("about")
        if about is None:
            return self.analysis.default_point(self.part.system)
        point = {}
        for k, v in about.items():
            if k not in self.system.coord_names:
                raise self.part.error(("about", k), f"{k!r} is not a coordinate")
            point[self.system.q[self.system.coord_names.index(k)]] = self.parse(v, ("about", k))
        return point

    def rates(self) -> dict:
        """The rates of a steady motion (`steady:`), by coordinate symbol."""
        rates = {}
        for k, v in (self.part.data.get("steady") or {}).items():
            if k not in self.system.coord_names:
                raise self.part.error(("steady", k), f"{k!r} is not a coordinate")
            rates[self.system.q[self.system.coord_names.index(k)]] = \
                self.parse(v, ("steady", k))
        return rates

    def linear(self) -> LinearSystem:
        if "steady" in self.part.data:
            if "about" not in self.part.data:
                raise self.part.error(("steady",), "a steady motion needs `about:` for the "
                                      "coordinates that stay put")
            # Routh's reduction holds the cyclic momenta; with multiplier constraints the
            # motion is linearized in full, constraints and all (engine.constrained)
            constrained = bool(self.system.constraints or self.system.velocity_constraints)
            return self.analysis.steady_linear(self.part.system, self.rates(), self.point(),
                                               self.part.data.get("reduce", not constrained),
                                               self.sampler.derived)
        if "reduce" in self.part.data:
            raise self.part.error(("reduce",), "`reduce:` applies to a steady motion")
        return self.analysis.linear(self.part.system, self.point(), self.sampler.derived)

    def as_list(self, val, sub) -> list:
        if isinstance(val, list):
            return val
        raise self.part.error(sub, "expected a list")

    def as_map(self, val, sub) -> dict:
        if isinstance(val, dict):
            return val
        raise self.part.error(sub, "expected a mapping")

    def initial(self) -> tuple[dict[int, sp.Expr], dict[int, sp.Expr]]:
        """The part's `initial:` as ({coordinate index: value}, {index: velocity}): keys are
        coordinates (x) and their velocities (xdot); anything else is an error at its key."""
        init = self.as_map(self.part.data["initial"], ("initial",))
        names = list(self.system.coord_names)
        q0, v0 = {}, {}
        for k, text in init.items():
            x = self.parse(text, ("initial", k))
            if k in names:
                q0[names.index(k)] = x
            elif k.endswith("dot") and k[:-3] in names:
                v0[names.index(k[:-3])] = x
            else:
                raise self.part.error(("initial", k), "initial values are given for "
                                      "coordinates (x) and their velocities (xdot)")
        return q0, v0

    def settled(self, q0, qd0, pt: dict) -> tuple:
        """A start (arrays of the coordinates and velocities) on the constraint manifold:
        what `initial:` does not state is solved from the constraints (least change from
        zero); a start whose stated values break a constraint is an error at `initial:`."""
        manifold = self.sampler.manifold
        if manifold is None:
            return q0, qd0
        import numpy as np

        given = self.as_map(self.part.data.get("initial") or {}, ("initial",))
        names = self.system.coord_names
        stated = {self.system.q[names.index(k)] for k in given if k in names}
        stated |= {self.system.qd[names.index(k[:-3])] for k in given
                   if k.endswith("dot") and k[:-3] in names}
        params = {k: v for k, v in pt.items() if k in self.analysis.problem.values()}
        out = manifold.settle(params, q0, qd0, 0.0, manifold.state - stated)
        if out is None:
            raise self.part.error(("initial",), "the start breaks the constraints, and what "
                                  "it leaves unstated cannot make them hold: state a start "
                                  "on the constraint manifold (or leave the dependent "
                                  "coordinates and velocities out, to be solved for)")
        return np.array(out[0]), np.array(out[1])

    def mode_shape(self, shape, sub) -> sp.Matrix:
        """A mode shape over the linear system's coordinates (a steady motion reduced by
        Routh has lost its cyclic ones); a coordinate left out is 0. On a constraint
        manifold the shape is over the independent coordinates; a dependent coordinate the
        book also gives must move as the constraints make it (WrongAnswerError if not)."""
        shape = self.as_map(shape, sub)
        lin = self.linear()
        names = lin.coord_names
        dependent = {str(q): q for q in lin.dependent}
        unknown = set(shape) - set(names) - set(dependent)
        if unknown:
            raise self.part.error(sub + (sorted(unknown)[0],), "not a coordinate of the "
                                  "linear system")
        u = sp.Matrix([self.parse(shape[c], sub + (c,)) if c in shape else 0
                       for c in names])
        for c in sorted(set(shape) & set(dependent)):
            i = lin.dyn.q.index(dependent[c])
            implied = sum((lin.embedding[i, j] * u[j] for j in range(len(names))), sp.S.Zero)
            got = vanishes(self.parse(shape[c], sub + (c,)) - implied, self.sampler,
                           symbolic=False)
            if not got.ok:
                raise WrongAnswerError(f"the shape's {c} is not what the constraints make it "
                                       f"({sp.sstr(implied)} for the other entries given): "
                                       f"{got.detail}")
        return u


PROSE = ("part", "cite", "origin", "quantity", "note", "transcription")  # words, not values


def _merge_declared(names: dict, extra: dict, part: Part) -> None:
    """The problem's vectors and tensors beside a system's names (parameters are shared)."""
    for k, v in extra.items():
        if k in names and names[k] is not v:
            raise part.error(("quantity",), f"{k!r} is both a name of the system and a "
                             "declared vector or tensor")
        names[k] = v


def split_named(text) -> tuple[str | None, object]:
    """(name, value) of a first integral written `name = value` (the book names the
    quantity: `p_psi = I3*omega3`), or (None, text) for a bare one; '= const' is dropped."""

    text = strip_const(text)
    if not isinstance(text, str):
        return None, text
    pieces = split_single_equals(text)
    if len(pieces) == 2:
        return pieces[0].strip(), pieces[1]
    return None, text


def strip_const(text):
    """A first integral's text without a trailing '= constant' (or '= const')."""
    if isinstance(text, str):
        for tail in ("= constant", "= const", "=constant", "=const"):
            if text.rstrip().endswith(tail):
                return text.rstrip()[: -len(tail)]
    return text


def linear_accelerations(lin: LinearSystem) -> dict:
    """q̈ solved from the linear equations M·q̈ + C·q̇ + K·δq = F."""
    n = len(lin.q)
    rhs = lin.F - lin.C * sp.Matrix(lin.qd) - lin.K * lin.displacement()
    sol = solve_accelerations(lin.M, rhs, list(lin.qdd))
    return {lin.qdd[i]: sol[i] for i in range(n)}


def numbers(exprs, pt) -> list[float]:
    """Real values of expressions at a point (NaN where a value is not real)."""
    out = []
    for e in exprs:
        z = value(e, pt)
        out.append(z.real if abs(z.imag) <= 1e-12 * max(1, abs(z)) else float("nan"))
    return out
