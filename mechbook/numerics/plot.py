"""Plots of a simulation: coordinates against time, the phase portrait of each coordinate,
and the relative drift of every monitored conserved quantity. Headless (a Figure with its own
Agg canvas, no pyplot): to a file, or as PNG bytes for a notebook."""

from __future__ import annotations

from pathlib import Path


def plot_simulation(sim, path: str | Path) -> Path:
    """Write a PNG (or any format matplotlib infers from the suffix) of `sim` to `path`."""
    fig = simulation_figure(sim)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return path


def simulation_png(sim, dpi: int = 90) -> bytes:
    """The same figure as PNG bytes, for a notebook's inline display (nothing written)."""
    import io

    out = io.BytesIO()
    simulation_figure(sim).savefig(out, format="png", dpi=dpi)
    return out.getvalue()


def simulation_figure(sim):
    """The matplotlib Figure of `sim`: coordinates, phase portrait, drifts. Made without
    pyplot (its own Agg canvas): headless, never a window, and a notebook's backend is left
    as it is."""
    from matplotlib.figure import Figure

    traj = sim.trajectory
    names = sim.model.names
    n = len(names)
    rows = 2 if sim.drifts else 1
    fig = Figure(figsize=(11, 4.2 * rows), constrained_layout=True)
    grid = fig.add_gridspec(rows, 2)
    ax_t = fig.add_subplot(grid[0, 0])
    for i, name in enumerate(names):
        ax_t.plot(traj.t, traj.q[i], lw=1.0, label=name)
    ax_t.set_xlabel("t")
    ax_t.set_ylabel("q")
    ax_t.set_title("coordinates")
    ax_t.legend(loc="best", fontsize=8)
    ax_p = fig.add_subplot(grid[0, 1])
    for i, name in enumerate(names):
        ax_p.plot(traj.q[i], traj.qd[i], lw=0.8, label=name)
        ax_p.plot(traj.q[i, :1], traj.qd[i, :1], "o", ms=4, color=ax_p.lines[-1].get_color())
    ax_p.set_xlabel("q")
    ax_p.set_ylabel("q̇")
    ax_p.set_title("phase portrait" + (" (each coordinate)" if n > 1 else ""))
    if n > 1:
        ax_p.legend(loc="best", fontsize=8)
    if sim.drifts:
        ax_d = fig.add_subplot(grid[1, :])
        for d in sim.drifts:
            ax_d.plot(traj.t, (d.values - d.initial) / d.scale, lw=0.8,
                      label=f"{d.name} (max {d.relative:.2e})")
        ax_d.set_xlabel("t")
        ax_d.set_ylabel("(Q − Q₀) / scale")
        ax_d.set_title("drift of the conserved quantities")
        ax_d.legend(loc="best", fontsize=8)
        ax_d.ticklabel_format(axis="y", style="sci", scilimits=(-3, 3))
    settings = traj.settings
    info = ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                     for k, v in settings.items())
    fig.suptitle(f"{sim.problem_id} [{sim.system}]: {info}", fontsize=10)
    return fig

