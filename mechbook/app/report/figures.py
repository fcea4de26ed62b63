"""The report's figures (PNG, matplotlib's headless Agg backend): mode shapes about an
equilibrium, and the simulated frequencies of the frequency cross-check against the linear
ones. The simulated trajectory with its energy drift is mechbook.numerics.plot's figure."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mechbook.records import Status


def _pyplot():
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def mode_shapes(omegas: np.ndarray, shapes: np.ndarray, names: list[str], title: str,
                path: Path) -> Path:
    """One bar chart per normal mode: each coordinate's share of the mode (largest = 1)."""
    plt = _pyplot()
    n = shapes.shape[1]
    cols = min(n, 4)
    rows = -(-n // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(2.6 * cols + 0.6, 2.3 * rows + 0.5),
                             squeeze=False, constrained_layout=True)
    x = np.arange(len(names))
    for k in range(rows * cols):
        ax = axes[k // cols][k % cols]
        if k >= n:
            ax.axis("off")
            continue
        v = np.real(shapes[:, k])
        big = np.max(np.abs(v)) or 1.0
        v = v / big * (1 if v[np.argmax(np.abs(v))] > 0 else -1)
        ax.bar(x, v, color=["tab:blue" if c >= 0 else "tab:red" for c in v])
        ax.axhline(0, color="black", lw=0.6)
        ax.set_xticks(x, names, rotation=45 if len(names) > 3 else 0, fontsize=8)
        ax.set_ylim(-1.1, 1.1)
        ax.set_title(f"mode {k + 1}: ω = {omegas[k]:.4g}", fontsize=9)
    fig.suptitle(title, fontsize=10)
    return _save(fig, path, plt)


def crosscheck_frequencies(modes: list[dict], title: str, path: Path) -> Path | None:
    """Measured (simulated, nonlinear) against linear frequencies, one point per mode."""
    points = [(m["linear"], m["measured"], m.get("status", "")) for m in modes
              if "measured" in m and m.get("kind") != "zero"]
    if not points:
        return None
    plt = _pyplot()
    fig, (ax, ax_err) = plt.subplots(1, 2, figsize=(9, 3.4), constrained_layout=True)
    lin = np.array([p[0] for p in points])
    meas = np.array([p[1] for p in points])
    lo, hi = min(lin.min(), meas.min()) * 0.9, max(lin.max(), meas.max()) * 1.1
    ax.plot([lo, hi], [lo, hi], color="grey", lw=0.8, label="measured = linear")
    for (w, m, status) in points:
        ax.plot(w, m, "o", color="tab:green" if status == Status.PASS else "tab:red")
    ax.set_xlabel("ω of the linear system (engine)")
    ax.set_ylabel("ω measured in the simulation")
    ax.legend(fontsize=8, loc="upper left")
    rel = np.abs(meas - lin) / np.abs(lin)
    ax_err.bar(np.arange(len(rel)), np.maximum(rel, 1e-17), color="tab:blue")
    ax_err.set_yscale("log")
    ax_err.set_xticks(np.arange(len(rel)), [f"{w:.3g}" for w in lin], fontsize=8)
    ax_err.set_xlabel("mode (linear ω)")
    ax_err.set_ylabel("relative difference")
    fig.suptitle(title, fontsize=10)
    return _save(fig, path, plt)


def _save(fig, path: Path, plt) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path
