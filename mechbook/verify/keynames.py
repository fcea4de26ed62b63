"""Every name an answer key uses, resolved against its problem before anything is checked.

Expressions are parsed in their part's context (mechbook.app.authoring.validate), but several keys
hold *names*, not expressions: the coordinates of an `about:` point or a `steady:` motion,
the coordinate `unknown:` a steady rate is for, the parameter a `limit:` takes to zero, the
names a `define:` introduces. A wrong one used to pass `mechbook validate` and fail only in
`check`; here each is looked up in the problem's declarations (no system is built), and a
name that is not there is refused with its file:line and the nearest names.
"""

from __future__ import annotations

from mechbook.model.hints import did_you_mean
from mechbook.model.problem import Problem

# keys whose mapping's keys are coordinates of the part's system
COORDINATE_KEYS = ("about", "steady", "rates", "momenta")
# keys whose mapping's keys are coordinates or their velocities (`thetadot`)
STATE_KEYS = ("initial", "released")
# quantity-specific keys holding one coordinate's name
COORDINATE_NAME = {"unknown": ("steady_rates", "steady_exists"),
                   "coordinate": ("constraint_force", "excursion", "turning_points",
                                  "mean_rate", "event_time", "motion_frequency"),
                   "rate": ("mean_rate",)}


def check_names(key, problem: Problem) -> None:
    """Raise SpecError (file:line, the nearest names) for the first name of `key` that the
    problem does not declare."""
    for part in key.parts:
        check_part_names(part, problem)


def check_part_names(part, problem: Problem) -> None:
    """check_names for one part."""
    key = part.key
    abbreviations = set(key.doc.data.get("abbreviations") or {})
    symbols = set(key.symbols)
    params = set(problem.parameters)
    data = part.data
    system = _system(part, problem)
    if system is not None:
        coords = list(system.get("coordinates") or {})
        states = coords + [c + "dot" for c in coords]
        for field in COORDINATE_KEYS:
            if isinstance(data.get(field), dict):
                for name in data[field]:
                    _known(part, (field, name), name, coords, "a coordinate")
        for field in STATE_KEYS:
            if isinstance(data.get(field), dict):
                for name in data[field]:
                    _known(part, (field, name), name, states, "a coordinate or velocity")
        for field, where in COORDINATE_NAME.items():
            if part.quantity in where and isinstance(data.get(field), str) \
                    and not (field == "coordinate" and "signal" in data):
                _known(part, (field,), data[field], coords, "a coordinate")
        if part.quantity == "effective_potential":
            for i, name in enumerate(data.get("cyclic") or []):
                _known(part, ("cyclic", i), name, coords, "a coordinate")
        taken = set(coords) | set(states) | params | symbols | abbreviations
        for name in (data.get("define") or {}):
            if name in taken:
                raise part.error(("define", name), f"{name!r} is already a name of the "
                                 "problem or key: a `define:` introduces a new one")
        for name in (data.get("restrict") or {}):
            _known(part, ("restrict", name), name, params | symbols, "a parameter or symbol")
        limit = data.get("limit")
        if isinstance(limit, dict) and isinstance(limit.get("parameter"), str):
            _known(part, ("limit", "parameter"), limit["parameter"], params | symbols,
                   "a parameter or symbol")


def _system(part, problem: Problem) -> dict | None:
    """The declarations of the part's system; None where the part has none (a tensor
    quantity, a problem without systems) or names a missing one (the part's context
    reports that, with the systems there are)."""
    if not problem.systems:
        return None
    name = part.system or (next(iter(problem.systems)) if len(problem.systems) == 1 else None)
    spec = problem.systems.get(name) if name else None
    return spec.data if spec is not None else None


def _known(part, sub: tuple, name, names, what: str) -> None:
    if name not in names:
        hint = did_you_mean(str(name), names)
        raise part.error(sub, f"{name!r} is not {what} of the problem"
                         + (f" ({hint})" if hint else f" (there are: "
                            f"{', '.join(sorted(map(str, names))) or 'none'})"))
