"""The integration methods by name: one entry each in METHODS, like scipy.integrate's
`METHODS` (name → class), saying which options the method takes (its family's, OPTIONS)
and where its class is. A module of its own, importing nothing, so that the command line
offers the names as choices and refuses an option a method does not take without loading
NumPy or SciPy; numerics.integrators.make_integrator imports a method's module when the
method is used.

Adding an integrator: a module of mechbook/numerics with a subclass of
numerics.integrator_base.Integrator (its `solve`), and one entry here.
"""

from typing import NamedTuple


class Method(NamedTuple):
    """One entry of METHODS."""

    family: str  # "scipy", "fixed", "midpoint" or "taylor": the options it takes, OPTIONS[family]
    module: str  # the module that holds its class,
    cls: str  # and the class, constructed as cls(name, **options)
    alias_of: str = ""  # another name of that method (the one its results carry)


SCIPY = "mechbook.numerics.scipy_methods"
FIXED_STEP = "mechbook.numerics.fixed_step"

METHODS: dict[str, Method] = {  # every name `integrate` takes
    "RK45": Method("scipy", SCIPY, "SciPyMethod"),  # solve_ivp's, adaptive
    "DOP853": Method("scipy", SCIPY, "SciPyMethod"),
    "Radau": Method("scipy", SCIPY, "SciPyMethod"),
    "LSODA": Method("scipy", SCIPY, "SciPyMethod"),
    "RK4": Method("fixed", FIXED_STEP, "RK4"),
    "leapfrog": Method("fixed", FIXED_STEP, "Leapfrog"),
    "verlet": Method("fixed", FIXED_STEP, "Leapfrog", alias_of="leapfrog"),
    "yoshida4": Method("fixed", FIXED_STEP, "Yoshida4"),
    "forest-ruth": Method("fixed", FIXED_STEP, "Yoshida4", alias_of="yoshida4"),
    "midpoint": Method("midpoint", FIXED_STEP, "ImplicitMidpoint"),
    "taylor": Method("taylor", "mechbook.numerics.taylor", "TaylorMethod"),  # heyoka's
}
CHOICES = tuple(m for m, e in METHODS.items() if not e.alias_of)  # one name per method
ALIASES = {m: e.alias_of for m, e in METHODS.items() if e.alias_of}  # other names of one
SCIPY_METHODS = tuple(m for m, e in METHODS.items() if e.family == "scipy")
FIXED_METHODS = tuple(m for m, e in METHODS.items() if e.family in ("fixed", "midpoint"))
TAYLOR = "taylor"  # heyoka's Taylor method

# which integrator options each kind of method takes (others do not apply to it); of the
# fixed-step methods only the implicit midpoint rule iterates (`tol`, `max_iter`)
OPTIONS = {"scipy": ("rtol", "atol", "max_step", "first_step", "dense_output", "compiled"),
           "fixed": ("step", "max_points", "compiled"),
           "midpoint": ("step", "max_points", "compiled", "tol", "max_iter"),
           "taylor": ("tol", "rtol", "max_points")}


def kind(method: str) -> str | None:
    """'scipy', 'fixed', 'midpoint' or 'taylor': the key of the options `method` takes in
    OPTIONS (None: not a method)."""
    entry = METHODS.get(method)
    return entry.family if entry is not None else None


# why an option another kind of method takes has no effect on this kind
NO_EFFECT = {
    "rtol": "a fixed-step method has no tolerance: give `step`",
    "atol": "{method}'s tolerance is relative only (`rtol` or `tol`)",
    "max_step": "a fixed-step method takes `step`",
    "first_step": "a fixed-step method takes `step`",
    "dense_output": "only SciPy's methods have a dense output",
    "step": "an adaptive method chooses its own steps: give `rtol` (and `atol`), or "
            "`max_step` to bound them",
    "max_points": "SciPy's methods record the times asked for (`t_eval`)",
    "tol": "only the implicit midpoint rule (its iteration) and the taylor method take a "
           "`tol`; SciPy's methods take `rtol` and `atol`",
    "max_iter": "only the implicit midpoint rule iterates",
    "compiled": "the taylor method is always compiled (heyoka)",
}


def why_not(option: str, method: str) -> str:
    """Why `option` has no effect on `method` (it is not among OPTIONS[kind(method)])."""
    return NO_EFFECT.get(option, "no method takes it").format(method=method)
