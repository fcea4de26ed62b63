"""The report's animation draws what the bodies are, not only where (issue 34): rigid links
and fixed pivots found in the motion itself (mechbook.app.report.linkage), and each rigid
body's outline turned with it (mechbook.app.report.outlines)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mechbook.app.report.linkage import links
from mechbook.app.report.outlines import N, shape_lines

ROOT = Path(__file__).resolve().parents[1]
t = np.linspace(0, 5, 200)


def test_a_pendulum_hangs_from_its_pivot_and_a_double_one_has_a_rod_between():
    th1, th2 = 0.3 * np.cos(2.1 * t), 0.5 * np.sin(3.3 * t)
    upper = np.column_stack([0.75 * np.sin(th1), 1 - 0.75 * np.cos(th1)])  # pivot (0, 1)
    lower = upper + np.column_stack([np.sin(th2), -np.cos(th2)])
    pairs, pivots = links(np.stack([upper, lower], axis=1), [], set(), 2.0)
    assert pairs == [(0, 1)]
    assert [k for k, _ in pivots] == [0]  # the lower bob turns about no fixed point
    assert np.allclose(pivots[0][1], [0, 1], atol=1e-9)  # the circle's centre, found


def test_what_is_not_a_rod_is_not_drawn_as_one():
    x = 0.2 * np.sin(3 * t)
    side_by_side = np.stack([np.column_stack([x, 0 * t]), np.column_stack([x + 1, 0 * t])],
                            axis=1)  # constant distance, but the pair never turns
    assert links(side_by_side, [], set(), 2.0) == ([], [])
    stretching = np.stack([np.column_stack([np.cos(t), np.sin(t)]),
                           np.column_stack([2 * np.cos(1.7 * t), 2 * np.sin(1.7 * t)])],
                          axis=1)  # each turns about the origin, at its own rate
    pairs, pivots = links(stretching, [], set(), 4.0)
    assert pairs == [] and [k for k, _ in pivots] == [0, 1]  # each on its own circle
    sprung = stretching.copy()
    sprung[:, 1] = sprung[:, 0] + np.column_stack([np.cos(2 * t), np.sin(2 * t)])
    assert links(sprung, [], {frozenset((0, 1))}, 4.0)[0] == []  # a spring, not a rod
    assert links(sprung, [], set(), 4.0)[0] == [(0, 1)]


def test_shapes_in_their_own_axes():
    (rod,) = shape_lines("rod", {"length": 2.0})
    assert rod == [[0, 0, -1.0], [0, 0, 1.0]]
    rim, axle = shape_lines("disk", {"radius": 0.5})
    assert np.allclose(np.linalg.norm(np.array(rim)[:, :2], axis=1), 0.5)
    assert len(shape_lines("block", {"sides": [1, 2, 3]})) == 6  # 2 faces, 4 edges
    assert shape_lines("point", {}) == []


@pytest.mark.slow  # derives and simulates a top with a disk
def test_a_disk_turns_with_its_euler_angles():
    """symon-11-13's disk (radius a, Euler angles): the outline is its rim turned by R(q);
    a circle of radius a seen from any side is an ellipse whose longest radius is a, so
    every frame's rim reaches a from the centre and never beyond, whatever R is, if R is
    a rotation applied right (a wrong row or a scaled R would reach elsewhere)."""
    from mechbook.app.report.animation import frames
    from mechbook.engine.analysis import Analysis
    from mechbook.model.problem import load_problem
    from mechbook.numerics.simulate import simulate

    analysis = Analysis(load_problem(ROOT / "problems" / "symon" / "11-13.yaml"))
    name = next(iter(analysis.problem.systems))
    sys_ = analysis.system(name)
    sim = simulate(analysis, name, t_span=(0.0, 1.0), points=101,
                   init={"theta": "0.6", "phidot": "1.5", "psidot": "8"})
    motion = frames(sys_, sim.trajectory, analysis.problem.values())
    disk = next(o for o in motion["outlines"]
                if motion["bodies"][o["body"]]["name"] == "disk")
    a = float(analysis.problem.values()[analysis.problem.parameters["a"].symbol])
    rim, axle = np.array(disk["lines"][0]), np.array(disk["lines"][1])
    centre = np.array(motion["bodies"][disk["body"]]["path"])
    reach, skew = [], []
    for k, r in enumerate(disk["turns"]):
        R2 = np.array(r).reshape(2, 3)
        reach.append(np.max(np.linalg.norm(rim @ R2.T, axis=1)))
        axis = (axle[1] - axle[0]) @ R2.T  # the disk's own z, drawn
        skew.append(abs(axis[0] * centre[k][1] - axis[1] * centre[k][0]) / (np.linalg.norm(axis) *
                                                      np.linalg.norm(centre[k]) + 1e-12))
    # the rim is N points: its sampled reach is within cos(pi/N) of the true one (and the
    # frames' numbers are rounded to 1e-5)
    assert a * np.cos(np.pi / N) - 1e-9 <= min(reach) and max(reach) <= a * (1 + 5e-4), \
        (min(reach), max(reach), a)
    # the disk sits on its axle, 3a/2 out from the fixed point along its own z: the axis
    # drawn points at the centre (R against its transpose, say, would not)
    assert max(skew) < 2e-3, max(skew)
    assert len(disk["turns"]) == len(motion["t"])
