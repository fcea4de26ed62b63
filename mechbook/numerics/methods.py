"""The integration methods by name (mechbook.numerics.integrators holds the classes). A
module of its own, importing nothing, so that the command line offers them as choices
without loading NumPy or SciPy."""

SCIPY_METHODS = ("RK45", "DOP853", "Radau", "LSODA")  # solve_ivp's, adaptive
FIXED_METHODS = ("RK4", "leapfrog", "verlet", "yoshida4", "forest-ruth", "midpoint")
ALIASES = {"verlet": "leapfrog", "forest-ruth": "yoshida4"}  # other names of the same method
TAYLOR = "taylor"  # heyoka's Taylor method
METHODS = SCIPY_METHODS + FIXED_METHODS + (TAYLOR,)  # every name `integrate` takes
CHOICES = tuple(m for m in METHODS if m not in ALIASES)  # one name per method

# which integrator options each kind of method takes (others do not apply to it); of the
# fixed-step methods only the implicit midpoint rule iterates (`tol`, `max_iter`)
OPTIONS = {"scipy": ("rtol", "atol", "max_step", "first_step", "dense_output", "compiled"),
           "fixed": ("step", "max_points", "compiled"),
           "midpoint": ("step", "max_points", "compiled", "tol", "max_iter"),
           "taylor": ("tol", "rtol", "max_points")}


def kind(method: str) -> str | None:
    """'scipy', 'fixed', 'midpoint' or 'taylor': the key of the options `method` takes in
    OPTIONS (None: not a method)."""
    if method in SCIPY_METHODS:
        return "scipy"
    if method == "midpoint":
        return "midpoint"
    if method in FIXED_METHODS:
        return "fixed"
    return "taylor" if method == TAYLOR else None


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
