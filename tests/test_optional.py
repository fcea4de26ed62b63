"""Optional parts that are not installed fail well: the command or call that needs one
ends in an error that names it and the extra that installs it (`pip install
'mechbook[...]'`), exit status 1 on the command line; never a bare ModuleNotFoundError, and
never another method in place of the one asked for (issue 34 item 3).

"Not installed" is made here by blocking the import (None in sys.modules makes `import`
raise ImportError, as a missing package does)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

import mechbook
from mechbook.app.cli import main
from mechbook.errors import MissingDependencyError

ROOT = Path(__file__).resolve().parents[1]


def block(monkeypatch, *modules: str) -> None:
    for name in modules:
        monkeypatch.setitem(sys.modules, name, None)


def refused(result, extra: str) -> str:
    """The output of a command that must have ended in a clear error naming `extra`."""
    out = result.output
    assert result.exit_code == 1, out
    assert isinstance(result.exception, SystemExit), repr(result.exception)
    assert f"pip install 'mechbook[{extra}]'" in out, out
    assert "Traceback" not in out and "ModuleNotFoundError" not in out, out
    return out


def test_check_on_a_cluster_without_dask(monkeypatch):
    block(monkeypatch, "dask", "dask.distributed", "distributed")
    result = CliRunner().invoke(main, ["--root", str(ROOT), "check", "lim-2031", "--fresh",
                                       "--no-store", "--scheduler", "tcp://127.0.0.1:9"])
    assert "--scheduler (a Dask cluster) needs dask" in refused(result, "cluster")


def test_a_sweep_on_a_cluster_without_dask(monkeypatch, tmp_path):
    block(monkeypatch, "dask", "dask.distributed", "distributed")
    result = CliRunner().invoke(main, ["--root", str(ROOT), "sweep", "lim-2031",
                                       "--quantity", "frequencies", "--about", "theta=pi",
                                       "--param", "omega=1:10:4", "--scheduler",
                                       "tcp://127.0.0.1:9", "--out",
                                       str(tmp_path / "s.nc")])
    refused(result, "cluster")


def test_simulate_taylor_without_heyoka_is_an_error_not_another_method(monkeypatch,
                                                                       tmp_path):
    block(monkeypatch, "heyoka")
    store = tmp_path / "runs.h5"
    result = CliRunner().invoke(main, ["--root", str(ROOT), "simulate", "lim-2031",
                                       "--method", "taylor", "--t-end", "1", "--serial",
                                       "--store", str(store)])
    out = refused(result, "taylor")
    assert "DOP853" not in out and not store.exists(), out


def test_frames_and_xarray_without_pandas_and_xarray(monkeypatch):
    run = mechbook.load("lim-2031", ROOT).simulate(t_end=0.5, points=11)
    block(monkeypatch, "pandas", "xarray")
    from mechbook.app.api import CheckResult

    with pytest.raises(MissingDependencyError, match=r"pip install 'mechbook\[data\]'"):
        CheckResult("lim-2031", []).to_frame()
    with pytest.raises(ImportError, match=r"mechbook.results\(\) needs pandas"):
        mechbook.results(ROOT / "no-such-store.h5")
    with pytest.raises(ImportError, match=r"pip install 'mechbook\[xarray\]'"):
        run.to_xarray()
