"""What the Python API's checks and simulations return: `CheckResult` and `Simulation`,
plain objects that also show themselves in a notebook and convert to pandas and xarray."""

from __future__ import annotations

import html
from dataclasses import dataclass, field
from pathlib import Path

from mechbook.app.api import args
from mechbook.app.api.animation import Animation, Picture
from mechbook.app.report import animation
from mechbook.app.store import write_simulation
from mechbook.core.optional import require
from mechbook.errors import UnsupportedError
from mechbook.numerics.plot import plot_simulation, simulation_png
from mechbook.records import FAILING, CrossCheck, Outcome


@dataclass
class CheckResult:
    """The outcome of checking one problem: one Outcome per answer part, the cross-checks.

    Attributes
    ----------
    problem : str
        The problem's id.
    outcomes : list of mechbook.records.Outcome
        One per answer part: `part`, `quantity`, `status`, `method`, `detail`, `power`.
    crosschecks : list of mechbook.records.CrossCheck
        The independent cross-checks and their outcomes.
    error : str or None
        Why the problem could not be checked at all, if it could not.
    seconds : float
        How long the check took.
    """

    problem: str
    outcomes: list[Outcome]
    crosschecks: list[CrossCheck] = field(default_factory=list)
    error: str | None = None
    seconds: float = 0.0

    @property
    def ok(self) -> bool:
        """No part failed or errored, no cross-check failed, and the problem ran."""
        return (self.error is None and all(o.status not in FAILING
                                           for o in self.outcomes)
                and not any(x.failed for x in self.crosschecks))

    def to_frame(self):
        """The outcomes as a table.

        Returns
        -------
        pandas.DataFrame
            One row per answer part (part, quantity, status, method, detail, power, ...).

        Raises
        ------
        MissingDependencyError
            Without pandas (``pip install 'mechbook[data]'``); an ImportError too.

        Examples
        --------
        >>> result = mechbook.load("lim-2031").check()      # doctest: +SKIP
        >>> result.to_frame()[["part", "status"]]            # doctest: +SKIP
        """
        pd = require("pandas", "data", "CheckResult.to_frame()")
        return pd.DataFrame([o.as_dict() for o in self.outcomes])

    def __repr__(self) -> str:
        rows = [f"{o.part:<16} {o.quantity:<20} {o.status:<12} {o.method}"
                for o in self.outcomes]
        head = f"{self.problem}: " + (self.error or ("ok" if self.ok else "FAILED"))
        return "\n".join([head, *rows])

    def _repr_html_(self) -> str:
        rows = "".join(f"<tr><td>{html.escape(o.part)}</td><td>{html.escape(o.quantity)}</td>"
                       f"<td>{html.escape(o.status)}</td><td>{html.escape(o.method)}</td>"
                       f"<td>{html.escape(o.detail)}</td></tr>" for o in self.outcomes)
        return (f"<p>{html.escape(self.problem)}: {html.escape(self.error or '')}</p>"
                "<table><tr><th>part</th><th>quantity</th><th>outcome</th><th>method</th>"
                f"<th>detail</th></tr>{rows}</table>")


class Simulation:
    """A finished simulation: the trajectory, the drift of every conserved quantity.

    Attributes
    ----------
    t : numpy.ndarray
        The sample times, shape (N,).
    q, qdot : numpy.ndarray
        The coordinates and their rates, shape (n, N), in the order of `coordinates`.
    coordinates : list of str
        The coordinates' names.
    drifts : dict of str to float
        The largest relative drift of each conserved quantity the engine found.
    """

    def __init__(self, run, system=None):
        self.run = run
        self._system = system  # the model's system, for animate() (None: not animated)

    t = property(lambda self: self.run.trajectory.t)
    q = property(lambda self: self.run.trajectory.q)
    qdot = property(lambda self: self.run.trajectory.qd)
    coordinates = property(lambda self: list(self.run.model.names))

    @property
    def drifts(self) -> dict[str, float]:
        return {d.name: float(d.relative) for d in self.run.drifts}

    def to_xarray(self):
        """The trajectory as an xarray Dataset, laid out as the store keeps it.

        Returns
        -------
        xarray.Dataset
            ``q`` and ``qdot`` over (coordinate, t), each monitored conserved quantity
            over t (``monitor_<name>``), and the run's settings (method, tolerances,
            initial state, parameter values) as attributes.

        Raises
        ------
        MissingDependencyError
            Without xarray (``pip install 'mechbook[xarray]'``); an ImportError too.

        Examples
        --------
        >>> ds = mechbook.load("lim-2031").simulate(t_end=5).to_xarray()   # doctest: +SKIP
        >>> ds.q.sel(coordinate="theta").plot()                            # doctest: +SKIP
        """
        xr = require("xarray", "xarray", "Simulation.to_xarray()")
        run = self.run
        data = {"q": (("coordinate", "t"), self.q), "qdot": (("coordinate", "t"), self.qdot)}
        data.update({f"monitor_{d.name}": ("t", d.values) for d in run.drifts})
        attrs = {k: v for k, v in run.settings().items()
                 if isinstance(v, str | int | float | bool)}
        return xr.Dataset(data, coords={"t": self.t, "coordinate": self.coordinates},
                          attrs=attrs)

    def plot(self, path: str | Path | None = None) -> Path | Picture:
        """Draw the coordinates against time, the phase portrait and the drifts.

        Parameters
        ----------
        path : str or pathlib.Path, optional
            The image file to write (PNG, SVG or PDF, by its suffix). Without it, the
            picture itself, which a notebook shows inline (nothing is written).

        Returns
        -------
        pathlib.Path or Picture
            The file written; or the picture (its PNG in ``.png``).

        Examples
        --------
        >>> run = mechbook.load("lim-2031").simulate(t_end=5)   # doctest: +SKIP
        >>> run.plot()                  # shown inline in a notebook   # doctest: +SKIP
        >>> run.plot("run.png")                                  # doctest: +SKIP
        """
        if path is None:
            return Picture(simulation_png(self.run), self._title())
        return plot_simulation(self.run, args.path("path", path))

    def animate(self, frames: int = animation.MAX_FRAMES) -> Animation:
        """The bodies moving as simulated, for a notebook (Jupyter shows it: a canvas and
        a small script, offline), as the report animates them.

        Parameters
        ----------
        frames : int, default 240
            At most this many frames (samples of the run, evenly spaced).

        Returns
        -------
        Animation
            Shown by Jupyter's rich display; ``html()`` is the markup, ``motion`` the
            frames.

        Raises
        ------
        UnsupportedError
            When the positions of the bodies cannot be evaluated along the run.

        Examples
        --------
        >>> run = mechbook.load("lim-2031").simulate(t_end=5)   # doctest: +SKIP
        >>> run.animate()                                        # doctest: +SKIP
        """
        if self._system is None:
            raise UnsupportedError("this simulation keeps no system to draw")
        values = {self._system.params[n].symbol: v for n, v in self.run.values.items()
                  if n in self._system.params}
        motion = animation.frames(self._system, self.run.trajectory, values,
                                  max(2, int(frames)))
        if motion is None:
            raise UnsupportedError(f"{self._title()}: the bodies' positions cannot be "
                                   "evaluated along the run: nothing to animate")
        return Animation(motion, self._title())

    def _title(self) -> str:
        return f"{self.run.problem_id} [{self.run.system}]"

    def store(self, path: str | Path, name: str | None = None) -> str:
        """Write the run into an HDF5 store, as `mechbook simulate` does.

        Parameters
        ----------
        path : str or pathlib.Path
            The store (created if absent).
        name : str, optional
            The run's name there (default ``<system>-<method>``).

        Returns
        -------
        str
            The run's group in the store (``/problems/<id>/simulations/<name>``).

        Examples
        --------
        >>> run = mechbook.load("lim-2031").simulate(t_end=5)   # doctest: +SKIP
        >>> run.store("results/mechbook.h5")                     # doctest: +SKIP
        '/problems/lim-2031/simulations/main-DOP853'
        """
        run = self.run
        path = args.path("path", path)
        name = args.text("name", name) or f"{run.system}-{run.trajectory.method}"
        write_simulation(run.problem_id, name, run.arrays(), run.settings(),
                         {f"monitors/{d.name}": d.attrs() for d in run.drifts}, path)
        return f"/problems/{run.problem_id}/simulations/{name}"

    def _repr_html_(self) -> str:
        rows = "".join(f"<tr><td>{html.escape(k)}</td><td>{v:.2e}</td></tr>"
                       for k, v in self.drifts.items())
        traj = self.run.trajectory
        return (f"<p>{html.escape(self.run.problem_id)} [{html.escape(self.run.system)}]: "
                f"{html.escape(traj.method)}, {len(traj.t)} samples to t = "
                f"{traj.t[-1]:.4g}</p><table><tr><th>conserved quantity</th>"
                f"<th>relative drift</th></tr>{rows}</table>")

    def __repr__(self) -> str:
        return (f"<simulation of {self.run.problem_id} [{self.run.system}], "
                f"{self.run.trajectory.method}, drifts {self.drifts}>")
