"""Plots of a sweep (matplotlib, Agg): frequency curves or maps, stability regions with the
book's boundary drawn over the engine's, and the drift of the measured frequency from the
linear one against amplitude.

One swept axis gives curves against it; two give maps over the plane (further axes: the
plot takes their first value and says so). The book's answer, where the key has one at the
same point, is drawn dashed over the engine's.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mechbook.engine.linear_grid import MARGINAL, STABLE, UNDEFINED, UNSTABLE

COLORS = {STABLE: "#9ecae1", MARGINAL: "#fdd49e", UNSTABLE: "#fc9272", UNDEFINED: "#d9d9d9"}
LABELS = {STABLE: "stable", MARGINAL: "marginal", UNSTABLE: "unstable",
          UNDEFINED: "undefined (no such point)"}


def plot_sweep(result, path: str | Path) -> Path:
    """Write the sweep's figure to `path` (format from the suffix)."""
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    names = list(result.coords)
    cut, note = _first_two(result, names)
    q = result.attrs["quantity"]
    if q == "stability":
        fig = _stability(plt, result, names[:2], cut)
    elif q == "frequencies":
        fig = _frequencies(plt, result, names[:2], cut)
    else:
        fig = _drift(plt, result, names[:2], cut)
    a = result.attrs
    title = f"{a['problem']}: {a['quantity']} about {a['point']}"
    if note:
        title += f"\n{note}"
    fig.suptitle(title, fontsize=10)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _first_two(result, names):
    """Index that keeps the first two axes whole and the others at their first value."""
    cut = tuple(slice(None) if i < 2 else 0 for i in range(len(names)))
    note = ""
    if len(names) > 2:
        note = "at " + ", ".join(f"{n} = {result.coords[n][0]:g}" for n in names[2:])
    return cut, note


def _stability(plt, result, axes, cut):
    codes = result.arrays["stability"][cut]
    book = result.book
    fig, ax = plt.subplots(figsize=(7.5, 5.5), constrained_layout=True)
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    order = [UNDEFINED, UNSTABLE, MARGINAL, STABLE]
    cmap = ListedColormap([COLORS[c] for c in order])
    index = np.searchsorted(order, codes)
    handles = [Patch(color=COLORS[c], label="engine: " + LABELS[c]) for c in order
               if np.any(codes == c)]
    if len(axes) == 1:
        x = result.coords[axes[0]]
        growth = result.arrays["growth"][cut]
        edges = _edges(x)
        for i in range(len(x)):
            ax.axvspan(edges[i], edges[i + 1], color=COLORS[int(codes[i])], lw=0)
        ax.plot(x, growth, color="k", lw=1.2, label="growth rate (engine)")
        ax.set_xlabel(axes[0])
        ax.set_ylabel("largest growth rate (1/s)")
        if "stable" in book:
            flips = np.flatnonzero(np.diff(book["stable"][cut].astype(int)) != 0)
            for j, k in enumerate(flips):
                ax.axvline((x[k] + x[k + 1]) / 2, color="k", ls="--", lw=1.5,
                           label=f"{_who(book)}: {book['condition']}" if j == 0 else None)
        ax.legend(handles=handles + ax.get_legend_handles_labels()[0], fontsize=8,
                  loc="best")
        ax.set_xlim(x[0], x[-1])
        return fig
    x, y = result.coords[axes[0]], result.coords[axes[1]]
    ax.pcolormesh(x, y, index.T, cmap=cmap, vmin=-0.5, vmax=3.5, shading="nearest")
    engine_stable = (codes == STABLE).astype(float)
    defined = codes != UNDEFINED
    if np.any(engine_stable[defined]) and not np.all(engine_stable[defined]):
        ax.contour(x, y, np.where(defined, engine_stable, np.nan).T, levels=[0.5],
                   colors="k", linewidths=1.0)
        handles.append(plt.Line2D([], [], color="k", lw=1.0, label="engine's boundary"))
    freq = result.arrays["frequencies"][cut]
    lowest = np.min(np.where((codes[..., None] == STABLE) & np.isfinite(freq), freq, np.inf),
                    axis=-1)
    lowest = np.where(np.isfinite(lowest), lowest, np.nan)
    if np.any(np.isfinite(lowest)) and np.nanmax(lowest) > np.nanmin(lowest):
        cs = ax.contour(x, y, lowest.T, levels=6, colors="#4d4d4d", linewidths=0.6,
                        alpha=0.8)
        ax.clabel(cs, fontsize=7, fmt="%.3g")
        handles.append(plt.Line2D([], [], color="#4d4d4d", lw=0.6,
                                  label="lowest frequency where stable (rad/s)"))
    if "stable" in book:
        field = book["margin"][cut] if "margin" in book else book["stable"][cut].astype(float)
        level = 0.0 if "margin" in book else 0.5
        if np.nanmin(field) < level < np.nanmax(field):
            ax.contour(x, y, field.T, levels=[level], colors="#08306b", linewidths=2.2,
                       linestyles="--")
        handles.append(plt.Line2D([], [], color="#08306b", lw=2.2, ls="--",
                                  label=f"{_who(book)}: {book['condition']}"))
    ax.set_xlabel(axes[0])
    ax.set_ylabel(axes[1])
    ax.legend(handles=handles, fontsize=8, loc="upper left", framealpha=0.9)
    return fig


def _frequencies(plt, result, axes, cut):
    f = result.arrays["frequencies"][cut]
    book = result.book.get("frequencies")
    if len(axes) == 1:
        fig, ax = plt.subplots(figsize=(7.5, 5), constrained_layout=True)
        x = result.coords[axes[0]]
        codes = result.arrays["stability"][cut]
        edges = _edges(x)
        for code in (UNDEFINED, UNSTABLE):
            for i in np.flatnonzero(codes == code):
                ax.axvspan(edges[i], edges[i + 1], color=COLORS[code], lw=0,
                           label=LABELS[code] if i == np.flatnonzero(codes == code)[0]
                           else None)
        for m in range(f.shape[-1]):
            ax.plot(x, f[:, m], lw=1.6, label=f"engine, mode {m}")
        if book is not None:
            b = book[cut]
            for m in range(b.shape[-1]):
                ax.plot(x, b[:, m], "k--", lw=1.0, label=_who(result.book) if m == 0 else None)
        ax.set_xlabel(axes[0])
        ax.set_ylabel("ω (rad/s)")
        ax.set_xlim(x[0], x[-1])
        ax.legend(fontsize=8)
        return fig
    n = f.shape[-1]
    fig, axs = plt.subplots(1, n, figsize=(5.2 * n, 4.6), constrained_layout=True,
                            squeeze=False)
    x, y = result.coords[axes[0]], result.coords[axes[1]]
    for m in range(n):
        ax = axs[0, m]
        mesh = ax.pcolormesh(x, y, f[..., m].T, shading="nearest", cmap="viridis")
        fig.colorbar(mesh, ax=ax, label="ω (rad/s)")
        ax.set_title(f"mode {m}", fontsize=9)
        ax.set_xlabel(axes[0])
        ax.set_ylabel(axes[1])
    return fig


def _drift(plt, result, axes, cut):
    rel = np.abs(result.arrays["relative_error"][cut])
    names = list(result.coords)
    a_name = "amplitude"
    fig, ax = plt.subplots(figsize=(7.5, 5), constrained_layout=True)
    if len(axes) == 1:
        amp = result.coords[a_name]
        for m in range(rel.shape[-1]):
            if np.any(np.isfinite(rel[:, m])):
                lin = np.nanmedian(result.arrays["linear"][cut][:, m])
                ax.loglog(amp, rel[:, m], "o-", ms=3, label=f"mode {m} (ω₀ = {lin:.4g})")
        ok = np.isfinite(rel[:, 0]) & (rel[:, 0] > 0)
        if ok.any():
            j = np.flatnonzero(ok)[len(np.flatnonzero(ok)) // 2]
            ax.loglog(amp, rel[j, 0] * (amp / amp[j]) ** 2, ":", color="grey",
                      label="∝ amplitude²")
        for tol in (1e-3, 1e-2):
            ax.axhline(tol, color="k", lw=0.6, ls="--")
        ax.set_xlabel("amplitude (largest coordinate displacement)")
        ax.set_ylabel("|ω(amplitude) − ω₀| / ω₀")
        ax.legend(fontsize=8)
        return fig
    other = [n for n in axes if n != a_name][0]
    amp, par = result.coords[a_name], result.coords[other]
    field = np.log10(np.nanmax(rel, axis=-1))
    if names.index(a_name) > names.index(other):
        field = field.T
    mesh = ax.pcolormesh(amp, par, field.T, shading="nearest", cmap="magma")
    fig.colorbar(mesh, ax=ax, label="log10 |relative error| (worst mode)")
    cs = ax.contour(amp, par, field.T, levels=[-3, -2, -1], colors="w", linewidths=1)
    ax.clabel(cs, fmt=lambda v: f"{10**v:g}", fontsize=8)
    ax.set_xscale("log")
    ax.set_xlabel("amplitude")
    ax.set_ylabel(other)
    return fig


def _who(book: dict) -> str:
    return "book" if book.get("origin", "book") == "book" else f"key ({book['origin']})"


def _edges(x: np.ndarray) -> np.ndarray:
    if len(x) == 1:
        return np.array([x[0] - 0.5, x[0] + 0.5])
    mid = (x[1:] + x[:-1]) / 2
    return np.concatenate(([x[0] - (mid[0] - x[0])], mid, [x[-1] + (x[-1] - mid[-1])]))
