"""The book's answer over a sweep's grid, beside the engine's: what the plot draws over the
engine's result and what the command counts disagreements of.

From the answer key, the parts about the same point of the same system as the sweep (or the
part `--part` names): a `stability_condition` part's relation is evaluated at every grid
point (and, for one relation, its margin lhs − rhs, whose zero line is the book's boundary);
a `frequencies` part's values (without `limit:`) are evaluated at every grid point. The
book's expressions are compiled with the same batch entry as the engine's matrices; nothing
here is parsed but through the answer key's own safe parser.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from mechbook.core.compile import compile_batch
from mechbook.core.words import plural
from mechbook.engine.linear_grid import MARGINAL, STABLE, UNDEFINED, relations, truth
from mechbook.errors import MechbookError, UnsupportedError
from mechbook.verify.context import Context
from mechbook.verify.registry import default_quantities


def book_overlay(sweeper, result) -> dict:
    """{"stable": bool grid, "margin": float grid, "condition": text, "frequencies": (…, m),
    "cite": ..., "lines": [summary lines]} for what the key has at this point."""
    key = sweeper.key
    out: dict = {"lines": []}
    if key is None or sweeper.spec.quantity == "drift":
        return out

    table = default_quantities()
    for part in key.parts:
        entry = table.get(part.quantity)  # the registration names the sweeps that draw it
        if entry is None or sweeper.spec.quantity not in entry.sweeps or "limit" in part.data:
            continue
        if sweeper.spec.part is not None and part.name != sweeper.spec.part:
            continue
        try:
            ctx = Context(sweeper.analysis, part)
            if ctx.system.name != sweeper.system.name:
                continue
            if sweeper.spec.part is None and not _same_point(ctx, sweeper):
                continue
            if sweeper.spec.quantity == "stability":
                _stability(out, ctx, part, sweeper, result)
            else:
                _frequencies(out, ctx, part, sweeper, result)
        except (MechbookError, UnsupportedError, KeyError, ValueError, TypeError) as exc:
            out["lines"].append(f"book ({part.name}): not drawn ({exc})")
            continue
        break  # the first matching part
    return out


def _same_point(ctx, sweeper) -> bool:
    """The part's point (and steady rates) equal the sweep's, numerically at the defaults
    and two other parameter points."""
    try:
        lin = ctx.linear()
    except (MechbookError, UnsupportedError):
        return False
    mine = sweeper.lin
    if set(lin.point) != set(mine.point) or [str(q) for q in lin.q] != [str(q) for q in mine.q]:
        return False
    steady_a = dict(lin.dyn.sys.held_momenta)  # {} about an equilibrium
    steady_b = dict(mine.dyn.sys.held_momenta)
    if set(steady_a) != set(steady_b):
        return False
    pairs = [(lin.point[q], mine.point[q]) for q in lin.point]
    pairs += [(steady_a[c], steady_b[c]) for c in steady_a]
    base = {**sweeper.grid.fixed}
    for factor in (1.0, 1.13, 0.91):
        env = {s: v * factor if getattr(s, "is_positive", False) else v for s, v in base.items()}
        for a, b in pairs:
            try:
                d = complex(sp.N(sp.S(a - b).subs(env), 20))
                s = max(1.0, abs(complex(sp.N(sp.S(a).subs(env), 20))))
            except (TypeError, ValueError):
                return False
            if not abs(d) <= 1e-12 * s:
                return False
    return True


def _columns(sweeper, exprs: list[sp.Expr], extra: dict) -> np.ndarray:
    """The expressions at every grid point, (N, len(exprs)) (NaN where not real)."""
    grid = sweeper.grid
    symbols = list(grid.symbols)
    missing = set().union(*(e.free_symbols for e in exprs)) - set(symbols)
    for s in missing:  # answer symbols the grid does not hold
        if s not in extra:
            raise MechbookError(f"the book's value uses {s}, which has no value here")
    symbols += sorted(missing, key=str)
    fn = compile_batch(symbols, exprs, sweeper.spec.backend)
    out = []
    step = 200_000
    for a in range(0, grid.size, step):
        b = min(a + step, grid.size)
        X = grid.block(a, b)
        if missing:
            X = np.hstack([X, np.tile([extra[s] for s in sorted(missing, key=str)],
                                      (b - a, 1))])
        out.append(fn(X))
    return np.concatenate(out, axis=0)


def _stability(out: dict, ctx, part, sweeper, result) -> None:
    cond = ctx.parse(part.data["book"], ("book",), relation=True)
    rels = relations(cond)
    extra = dict(sweeper.key.symbol_values)
    margins = _columns(sweeper, [r.lhs - r.rhs for r in rels], extra) if rels else \
        np.zeros((sweeper.grid.size, 0))
    cols = {r: margins[:, i] for i, r in enumerate(rels)}
    stable = truth(cond, cols, sweeper.grid.size)
    shape = sweeper.grid.shape
    out["stable"] = stable.reshape(shape)
    if len(rels) == 1:
        out["margin"] = margins[:, 0].reshape(shape)
    text = str(part.data["book"])
    out["condition"] = text + _abbreviations(sweeper.key, text)
    out["cite"] = part.data.get("cite", part.name)
    out["part"] = part.name
    out["origin"] = part.data.get("origin", "book")
    codes = result.arrays["stability"].reshape(-1)
    decided = (codes != UNDEFINED) & (codes != MARGINAL) & np.all(np.isfinite(margins), axis=1)
    engine = codes == STABLE
    differ = decided & (engine != stable)
    out["disagree"] = int(differ.sum())
    where = ""
    if differ.any():
        idx = np.unravel_index(np.flatnonzero(differ)[0], shape)
        where = " (first at " + ", ".join(f"{a.name}={result.coords[a.name][i]:.4g}" for a, i
                                         in zip(sweeper.grid.axes, idx, strict=True)) + ")"
    out["lines"].append(f"{_who(out)} ({out['cite']}): {out['condition']}; agrees with the "
                        f"engine at {int(decided.sum()) - out['disagree']} of {int(decided.sum())} "
                        f"decided points{where}")


def _who(out: dict) -> str:
    """'book', or 'key (derived)' for a part with no printed answer."""
    return "book" if out.get("origin", "book") == "book" else f"key ({out['origin']})"


def _abbreviations(key, text: str) -> str:
    """' (Omega = sqrt(g/b))' for the key's abbreviations that `text` uses."""
    import re

    abbr = key.doc.data.get("abbreviations") or {}
    used = [f"{k} = {v}" for k, v in abbr.items() if re.search(rf"\b{re.escape(k)}\b", text)]
    return f" ({'; '.join(used)})" if used else ""


def _frequencies(out: dict, ctx, part, sweeper, result) -> None:
    book = ctx.as_list(part.data["book"], ("book",))
    exprs = [ctx.parse(v, ("book", i)) for i, v in enumerate(book)]
    vals = _columns(sweeper, exprs, dict(sweeper.key.symbol_values))
    vals = np.sort(vals, axis=1)
    shape = sweeper.grid.shape
    out["frequencies"] = vals.reshape(*shape, vals.shape[1])
    out["cite"] = part.data.get("cite", part.name)
    out["part"] = part.name
    out["origin"] = part.data.get("origin", "book")
    engine = result.arrays["frequencies"].reshape(-1, result.arrays["frequencies"].shape[-1])
    if vals.shape[1] == engine.shape[1]:
        with np.errstate(all="ignore"):
            rel = np.abs(vals - engine) / np.maximum(np.abs(engine), 1e-300)
        ok = np.all(np.isfinite(rel), axis=1)
        worst = float(np.max(rel[ok])) if ok.any() else float("nan")
        out["max_rel_diff"] = worst
        out["lines"].append(f"{_who(out)} ({out['cite']}): largest relative difference from the "
                            f"engine {worst:.2e} over {plural(int(ok.sum()), 'point')} where "
                            f"both are "
                            "real")
    else:
        out["lines"].append(f"{_who(out)} ({out['cite']}): gives {vals.shape[1]} frequencies, the "
                            f"engine {engine.shape[1]} (drawn, not compared)")
