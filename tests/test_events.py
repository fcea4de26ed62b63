"""DOP853 with events in the compiled loop (mechbook.numerics.events) against scipy's
solve_ivp: the same events at the same times, the same end state, terminal events and
directions honoured; the loop's atol per component as solve_ivp's vector atol; without the
compiled loop it is solve_ivp itself."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from systems import DOUBLE, DRIVEN, OSCILLATOR, load_analysis, pendulum

from mechbook.numerics import c_library, c_stepping, events
from mechbook.numerics.events import solve_with_events
from mechbook.numerics.rhs import build_model

PENDULUM = pendulum(m=1.0, l=1.0, g=1.0,
                    header="id: lim-9312\nsource: test\ntitle: simple pendulum\n")
RUNAWAY = """\
id: lim-9315
source: test
title: particle pushed off an inverted quartic hill
parameters:
  m: {value: 1.0}
coordinates:
  x: {}
kinetic: m*xdot**2/2
potential: -x**4
"""
SYSTEMS = {"oscillator": (OSCILLATOR, "9311"), "pendulum": (PENDULUM, "9312"),
           "double": (DOUBLE, "9313"), "driven": (DRIVEN, "9314"),
           "runaway": (RUNAWAY, "9315")}

pytestmark = pytest.mark.skipif(c_library.library() is None,
                                reason=f"no compiled loops here: {c_library.why()}")


def model_of(tmp_path: Path, name: str):
    text, num = SYSTEMS[name]
    an = load_analysis(tmp_path, text, num)
    model = build_model(an.system(None), an.dynamics(None), an.problem.values())
    assert model.native is not None
    return model


def event(fn, terminal=False, direction=0.0):
    fn.terminal, fn.direction = terminal, direction
    return fn


def same_as_solve_ivp(new, ref, rtol: float = 1e-12) -> None:
    """The answer of solve_with_events is solve_ivp's: status, the events' times (to
    `rtol`) and states, the end time and state."""
    assert new.status == ref.status and new.success == ref.success
    assert new.message == ref.message
    assert [len(x) for x in new.t_events] == [len(x) for x in ref.t_events]
    for te, ye, rte, rye in zip(new.t_events, new.y_events, ref.t_events, ref.y_events,
                                strict=True):
        assert np.allclose(te, rte, rtol=rtol, atol=rtol)
        if len(rte):
            assert np.allclose(ye, rye, rtol=1e-9, atol=1e-11)
    assert new.t.shape == (1,) and new.y.shape == (len(ref.y), 1)
    assert abs(new.t[-1] - ref.t[-1]) <= rtol * max(1.0, abs(ref.t[-1]))
    assert np.allclose(new.y[:, -1], ref.y[:, -1], rtol=1e-9, atol=1e-11)


CASES = {
    # x up through 0 (direction +1) and down through 0.5 in velocity, over 8 periods
    "oscillator-directions": ("oscillator", [1.0, 0.0], 25.0, 1e-12, 1e-13,
                              lambda: [event(lambda t, y: y[0], direction=1.0),
                                       event(lambda t, y: y[1] - 0.5, direction=-1.0)]),
    # either way (direction 0), at a looser tolerance and with a vector atol
    "oscillator-either": ("oscillator", [1.0, 0.0], 25.0, 1e-10, [1e-12, 1e-11],
                          lambda: [event(lambda t, y: y[0])]),
    # the third crossing ends the run (terminal = 3), a non-terminal one alongside
    "oscillator-third": ("oscillator", [1.0, 0.0], 25.0, 1e-12, 1e-13,
                         lambda: [event(lambda t, y: y[0], terminal=3),
                                  event(lambda t, y: y[1], direction=1.0)]),
    # the first swing below -0.5 ends the run (terminal, direction -1)
    "pendulum-terminal": ("pendulum", [1.0, 0.0], 30.0, 1e-12, 1e-13,
                          lambda: [event(lambda t, y: y[0] + 0.5, True, -1.0)]),
    # large swings, many crossings of both kinds
    "pendulum-many": ("pendulum", [2.5, 0.0], 60.0, 1e-12, 1e-13,
                      lambda: [event(lambda t, y: y[0]), event(lambda t, y: y[1], False, 1.0)]),
    "double": ("double", [0.5, -0.3, 0.1, 0.2], 10.0, 1e-12, 1e-13,
               lambda: [event(lambda t, y: y[0] - y[1])]),
    "driven": ("driven", [0.4, 0.3], 6.0, 1e-12, 1e-13,
               lambda: [event(lambda t, y: y[1]), event(lambda t, y: t - 2.5, True, 1.0)]),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_events_as_solve_ivp_finds_them(tmp_path, case):
    name, y0, t_end, rtol, atol, make = CASES[case]
    model = model_of(tmp_path, name)
    y0 = np.array(y0, float)
    ref = solve_ivp(model.rhs, (0.0, t_end), y0, method="DOP853", rtol=rtol, atol=atol,
                    events=make())
    assert sum(len(x) for x in ref.t_events) >= 1
    calls = model.stats["rhs_calls"]
    new = solve_with_events(model.native, model.rhs, (0.0, t_end), y0, rtol=rtol, atol=atol,
                            events=make(), stats=model.stats)
    same_as_solve_ivp(new, ref)
    assert model.stats["rhs_calls"] - calls >= new.nfev > 0  # the compiled loop's charged


def test_an_event_step_is_taken_again_as_the_same_step(tmp_path, monkeypatch):
    """SciPy takes the recorded step again in one step of the same length (first_step):
    its dense output is then the one a whole run of solve_ivp has there."""
    model = model_of(tmp_path, "pendulum")
    taken = []
    again = events._step_again

    def spy(fun, t_old, t_new, *rest):
        sub = again(fun, t_old, t_new, *rest)
        taken.append((len(sub.t), sub.t[-1] == t_new, sub.status))
        return sub

    monkeypatch.setattr(events, "_step_again", spy)
    new = solve_with_events(model.native, model.rhs, (0.0, 20.0), np.array([1.0, 0.0]),
                            rtol=1e-12, atol=1e-13,
                            events=[event(lambda t, y: y[0]), event(lambda t, y: y[1])])
    assert new.status == 0 and len(taken) == len(new.t_events[0]) + len(new.t_events[1]) > 6
    assert all(steps == 2 and whole and status == 0 for steps, whole, status in taken)


@pytest.mark.parametrize("terminal", [False, 4])
def test_small_records_go_on_exactly(tmp_path, terminal):
    """A full record goes on from its last step with the step size the loop would have
    tried next: records of 7 steps give the very numbers of one record."""
    model = model_of(tmp_path, "pendulum")
    y0 = np.array([2.0, 0.3])

    def run(rows):
        return solve_with_events(model.native, model.rhs, (0.0, 40.0), y0, rtol=1e-11,
                                 atol=1e-12, events=[event(lambda t, y: y[0], terminal)],
                                 rows=rows)

    one, many = run(100_000), run(7)
    assert one.status == many.status == (1 if terminal else 0)
    assert np.array_equal(one.t, many.t) and np.array_equal(one.y, many.y)
    assert np.array_equal(one.t_events[0], many.t_events[0])
    assert np.array_equal(one.y_events[0], many.y_events[0])


def test_a_failure_is_reported_as_solve_ivp_reports_it(tmp_path):
    """x'' = 4x³ from x = 1 runs away at t ≈ 0.37: both stop where the step size falls
    below the spacing of the numbers, with the events found on the way."""
    model = model_of(tmp_path, "runaway")
    y0 = np.array([1.0, 0.0])
    make = lambda: [event(lambda t, y: y[0] - 2.0), event(lambda t, y: y[0] - 1e3)]  # noqa: E731
    with np.errstate(all="ignore"):
        ref = solve_ivp(model.rhs, (0.0, 1.0), y0, method="DOP853", rtol=1e-10,
                        atol=1e-12, events=make())
        new = solve_with_events(model.native, model.rhs, (0.0, 1.0), y0, rtol=1e-10,
                                atol=1e-12, events=make())
    assert ref.status == new.status == -1 and not new.success
    assert new.message == ref.message
    assert [len(x) for x in new.t_events] == [len(x) for x in ref.t_events] == [1, 1]
    assert np.allclose(np.concatenate(new.t_events), np.concatenate(ref.t_events),
                       rtol=1e-12)
    assert abs(new.t[-1] - ref.t[-1]) < 1e-6


def test_without_the_compiled_loop_it_is_solve_ivp(tmp_path):
    model = model_of(tmp_path, "oscillator")
    y0 = np.array([1.0, 0.0])
    make = lambda: [event(lambda t, y: y[0], terminal=2), event(lambda t, y: y[1])]  # noqa: E731
    ref = solve_ivp(model.rhs, (0.0, 25.0), y0, method="DOP853", rtol=1e-12, atol=1e-13,
                    events=make())
    new = solve_with_events(None, model.rhs, (0.0, 25.0), y0, rtol=1e-12, atol=1e-13,
                            events=make())
    assert new.status == ref.status == 1 and new.nfev == ref.nfev
    assert new.t[-1] == ref.t[-1] and np.array_equal(new.y[:, -1], ref.y[:, -1])
    for a, b in zip(new.t_events, ref.t_events, strict=True):
        assert np.array_equal(a, b)
    bare = solve_with_events(None, model.rhs, (0.0, 1.0), y0, rtol=1e-12, atol=1e-13)
    assert bare.status == 0 and bare.t_events == [] and bare.t[-1] == 1.0


def test_vector_atol_is_solve_ivps(tmp_path):
    """One atol per component, as solve_ivp takes it: the same steps (their number and the
    evaluations; the step points to rounding, which the first steps' error estimates,
    below rounding themselves, amplify: 9.6e-9 where OpenBLAS sums solve_ivp's stages with
    its Haswell kernel, 3.2e-7 on the same machine with its AVX-512 one, as on an AVX-512
    CPU by default), and not the steps of either scalar."""
    model = model_of(tmp_path, "driven")
    y0 = np.array([0.4, 0.3])
    evals = {}
    for atol in ([1e-10, 1e-7], [1e-7, 1e-10]):
        run = c_stepping.adaptive(model.native, model.stats, "DOP853", (0, 3), y0, 1e-8, atol)
        ref = solve_ivp(model.rhs_python, (0, 3), y0, method="DOP853", rtol=1e-8, atol=atol)
        assert run.status == 0 and len(run.t) == len(ref.t)
        assert run.evaluations == ref.nfev
        assert np.allclose(run.t, ref.t, rtol=1e-6, atol=1e-12)
        assert np.max(np.abs(run.y[:, -1] - ref.y[:, -1])) < 1e-11
        evals[tuple(atol)] = run.evaluations
    for atol in (1e-10, 1e-7):
        scalar = c_stepping.adaptive(model.native, model.stats, "DOP853", (0, 3), y0, 1e-8, atol)
        assert scalar.evaluations not in evals.values()
        both = c_stepping.adaptive(model.native, model.stats, "DOP853", (0, 3), y0, 1e-8,
                                 [atol, atol])
        assert np.array_equal(both.t, scalar.t) and np.array_equal(both.y, scalar.y)
    with pytest.raises(ValueError, match="atol"):
        c_stepping.adaptive(model.native, model.stats, "DOP853", (0, 3), y0, 1e-8,
                          [1e-8, 1e-8, 1e-8])


@pytest.mark.parametrize("rows, terminal", [(4096, True), (7, True), (4096, False)])
def test_every_step_with_a_largest_step_as_solve_ivp(tmp_path, rows, terminal):
    """`max_step` bounds the steps as solve_ivp's does, and `steps` answers every step's end
    (the start first, a terminal event's state last): solve_ivp's steps, over records of any
    size, to rounding."""
    model = model_of(tmp_path, "pendulum")
    y0 = np.array([1.0, 0.0])

    def make():
        return [event(lambda t, y: y[0] + 0.5, terminal, -1.0), event(lambda t, y: y[1], False,
                                                                       1.0)]

    ref = solve_ivp(model.rhs, (0.0, 12.0), y0, method="DOP853", rtol=1e-12, atol=1e-13,
                    events=make(), max_step=0.05)
    new = solve_with_events(model.native, model.rhs, (0.0, 12.0), y0, rtol=1e-12, atol=1e-13,
                            events=make(), max_step=0.05, steps=True, rows=rows)
    assert new.status == ref.status == (1 if terminal else 0)
    assert len(ref.t) >= ref.t[-1] / 0.05 > 40  # max_step ruled the steps
    assert np.max(np.diff(new.t)) <= 0.05 * (1 + 1e-12)
    assert new.t.shape == ref.t.shape and new.y.shape == ref.y.shape
    assert np.allclose(new.t, ref.t, rtol=1e-12, atol=1e-14)
    assert np.allclose(new.y, ref.y, rtol=1e-9, atol=1e-11)
    for te, rte in zip(new.t_events, ref.t_events, strict=True):
        assert len(te) == len(rte) and np.allclose(te, rte, rtol=1e-12, atol=1e-12)
    free = solve_with_events(model.native, model.rhs, (0.0, 12.0), y0, rtol=1e-12, atol=1e-13,
                             max_step=0.05)
    assert free.t.shape == (1,) and free.t[-1] == 12.0  # without `steps`: the end alone
