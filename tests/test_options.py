"""Issue 21: every numeric option refuses NaN and infinities and has an upper bound (NaN used
to remove the time limit and the memory bound, `--t-end nan` spun for 600 s, a huge
`--points` or a 10^8-point sweep ran out of memory); names and output paths are checked
before any work (`simulate --name ../x` failed only after the integration)."""

from __future__ import annotations

import time

import pytest
from hostile import ROOT, pendulum_tree, run

import mechbook.app.running.simrun as simrun
import mechbook.app.sweep as sweep

PID = "lim-2031"

# (command and its fixed arguments, option, hostile values)
OPTIONS = [
    (["check", PID, "--no-store"], "--timeout", ["nan", "inf", "-inf", "0", "1e300"]),
    (["check", PID, "--no-store"], "--memory", ["nan", "inf", "-1", "1e300"]),
    (["check", PID, "--no-store"], "--prove-seconds", ["nan", "inf", "0", "1e9"]),
    (["check", PID, "--no-store"], "--jobs", ["-1", "99999999", "1e3", "nan"]),
    (["simulate", PID, "--no-store"], "--t-end", ["nan", "inf", "0", "-1", "1e300"]),
    (["simulate", PID, "--no-store"], "--rtol", ["nan", "inf", "0", "1", "-1e-8"]),
    (["simulate", PID, "--no-store"], "--atol", ["nan", "inf", "-1", "1e300"]),
    (["simulate", PID, "--no-store"], "--accuracy", ["nan", "inf", "0", "2"]),
    (["simulate", PID, "--no-store"], "--max-step", ["nan", "0", "-1", "inf"]),
    (["simulate", PID, "--no-store"], "--step", ["nan", "0", "inf"]),
    (["simulate", PID, "--no-store"], "--points", ["99999999999999999999", "0", "1", "nan"]),
    (["simulate", PID, "--no-store"], "--timeout", ["nan", "inf"]),
    (["simulate", PID, "--no-store"], "--memory", ["nan", "inf"]),
    (["sweep", PID, "--param", "omega=1:2:3", "--no-store"], "--timeout", ["nan", "inf"]),
    (["sweep", PID, "--param", "omega=1:2:3", "--no-store"], "--memory", ["nan", "inf"]),
    (["sweep", PID, "--param", "omega=1:2:3", "--no-store"], "--samples", ["-1", "1e9", "nan"]),
    (["sweep", PID, "--param", "omega=1:2:3", "--no-store"], "--jobs", ["0", "100000"]),
    (["report", PID], "--seconds", ["nan", "inf", "0"]),
    (["report", PID], "--simplify-seconds", ["nan", "inf", "-1"]),
    (["report", PID], "--t-end", ["nan", "inf", "0"]),
    (["report", PID], "--jobs", ["-1", "99999999"]),
]
CASES = [(cmd, opt, v) for cmd, opt, values in OPTIONS for v in values]


@pytest.mark.parametrize("cmd, option, value", CASES,
                         ids=[f"{c[0]}{o}={v}" for c, o, v in CASES])
def test_hostile_numbers_are_refused_before_anything_runs(monkeypatch, cmd, option, value):
    """Refused by the option itself (usage error, exit 2, the option named), in well under
    a second: nothing is loaded, nothing runs."""
    monkeypatch.setattr(simrun, "run_simulation", _must_not_run)
    monkeypatch.setattr(sweep, "run_sweep", _must_not_run)
    start = time.perf_counter()
    result = run("--root", ROOT, *cmd, f"{option}={value}")
    assert result.exit_code == 4, result.output
    assert option in result.output or option.lstrip("-")[0] in result.output
    assert ("not a finite number" in result.output or "not in the range" in result.output
            or "is not a valid" in result.output), result.output
    assert "Traceback" not in result.output
    assert time.perf_counter() - start < 5


def _must_not_run(*args, **kwargs):
    raise AssertionError("the run started although an option was refused")


@pytest.mark.parametrize("value", ["10", "1e-3", "600"])
def test_sane_numbers_are_still_accepted(value):
    from mechbook.app import options

    assert options.seconds().convert(value, None, None) == float(value)


@pytest.mark.parametrize("param", ["omega=0.5:10:100000000", "omega=0.5:10:1000000000000000000000",
                                   "omega=1:2:4000,b=1:2:4000"])
def test_a_sweep_grid_too_large_is_refused_before_anything_is_allocated(monkeypatch, param):
    monkeypatch.setattr(sweep, "run_sweep", _must_not_run)
    args = []
    for p in param.split(","):
        args += ["--param", p]
    result = run("--root", ROOT, "sweep", PID, *args, "--no-store")
    assert result.exit_code == 4, result.output
    assert "points; at most 10,000,000" in result.output


def test_a_sweep_grid_past_the_memory_bound_is_refused(monkeypatch):
    monkeypatch.setattr(sweep, "run_sweep", _must_not_run)
    result = run("--root", ROOT, "sweep", PID, "--param", "omega=0.5:10:5000000",
                 "--memory", "100", "--no-store")
    assert result.exit_code == 4, result.output
    assert "more than the memory bound of 100 MB" in result.output


@pytest.mark.parametrize("name", ["../x", "a/b", ".hidden", "", "x" * 200, "bad\x1bname"])
def test_a_bad_run_name_is_refused_before_the_run(monkeypatch, name):
    monkeypatch.setattr(simrun, "run_simulation", _must_not_run)
    monkeypatch.setattr(sweep, "run_sweep", _must_not_run)
    result = run("--root", ROOT, "simulate", PID, "--name", name)
    assert result.exit_code == 1, result.output
    assert "invalid simulation name" in result.output
    result = run("--root", ROOT, "sweep", PID, "--param", "omega=1:2:3", "--name", name)
    assert result.exit_code == 4 and "invalid sweep name" in result.output


@pytest.mark.parametrize("command", [["simulate", PID], ["sweep", PID, "--param",
                                                          "omega=1:2:3"]])
def test_a_plot_whose_format_is_unknown_is_refused_before_the_run(monkeypatch, command):
    monkeypatch.setattr(simrun, "run_simulation", _must_not_run)
    monkeypatch.setattr(sweep, "run_sweep", _must_not_run)
    result = run("--root", ROOT, *command, "--plot", "x.xyz", "--no-store")
    assert result.exit_code == 4, result.output
    assert "the suffix names the format" in result.output


def test_a_device_as_output_is_refused_and_left_alone(tmp_path, monkeypatch):
    """`--out /dev/null` (a device) used to be replaced by the rename of the new file."""
    monkeypatch.setattr(sweep, "run_sweep", _must_not_run)
    result = run("--root", ROOT, "sweep", PID, "--param", "omega=1:2:3", "--out", "/dev/null",
                 "--no-store")
    assert result.exit_code == 1, result.output
    assert "/dev/null: it is a character device, not a regular file" in result.output


def test_simulate_nan_in_parameters_and_initial_values_is_a_clear_error(tmp_path):
    base = pendulum_tree(tmp_path)
    for option in ("--param", "--init"):
        name = "m" if option == "--param" else "theta"
        result = run("--root", base, "simulate", "lim-2101", option, f"{name}=nan",
                     "--no-store", "--serial")
        assert result.exit_code == 1
        assert "unknown name 'nan'" in result.output and "Traceback" not in result.output


@pytest.mark.parametrize("timeout, memory", [(float("nan"), 100.0), (10.0, float("nan")),
                                             (0.0, 100.0), (10.0, -1.0)])
def test_the_batch_itself_refuses_nan_limits(timeout, memory):
    """Past the command line (the Python API, the fuzzer): a NaN limit is refused, not
    taken as no limit."""
    from mechbook.app.running.batch import BatchOptions
    from mechbook.errors import MechbookError

    with pytest.raises(MechbookError, match="batch limits must be numbers"):
        BatchOptions(timeout=timeout, memory_mb=memory)


def test_a_nan_cpu_time_limit_is_refused_not_ignored():
    from mechbook.core.timeout import time_limit

    with pytest.raises(ValueError, match="NaN"), time_limit(float("nan")):
        pass
