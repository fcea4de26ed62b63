"""Checks and sweeps on a Dask cluster (a local one, started here): the same results as the
local run, and the time limit still acting inside a worker."""

from __future__ import annotations

import shutil
import time
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

pytest.importorskip("distributed")

from dask.distributed import Client  # noqa: E402

import mechbook.app.sweep.runner as sweep_mod  # noqa: E402
from mechbook.app.cli import main  # noqa: E402
from mechbook.app.running.distributed import ENV, limited, local_cluster  # noqa: E402
from mechbook.app.sweep import make_spec, run_sweep  # noqa: E402
from mechbook.engine.linear_grid import parse_axis  # noqa: E402
from mechbook.errors import MechbookError  # noqa: E402

pytestmark = pytest.mark.slow  # a Dask cluster

ROOT = Path(__file__).resolve().parents[1]
TREE = Path(__file__).resolve().parent / "sweeptree"


@pytest.fixture(scope="module")
def address():
    cluster = local_cluster(2)
    try:
        yield cluster.scheduler_address
    finally:
        cluster.close()


def tree(tmp_path: Path, ids: list[str]) -> Path:
    for pid in ids:
        book, num = pid.split("-", 1)
        for sub in ("problems", "answers"):
            (tmp_path / sub / book).mkdir(parents=True, exist_ok=True)
            shutil.copy(ROOT / sub / book / f"{num}.yaml", tmp_path / sub / book / f"{num}.yaml")
    return tmp_path


def rows(out: str) -> list[str]:
    """The table's rows without the seconds (problem, part, quantity, outcome, detail)."""
    return [ln for ln in out.splitlines() if ln.startswith("lim-")]


def test_check_on_the_cluster_matches_the_local_pool(tmp_path, address, monkeypatch):
    ids = ["lim-2031", "lim-2036"]
    base = tree(tmp_path, ids)
    runner = CliRunner()
    local = runner.invoke(main, ["--root", str(base), "check", *ids, "-j", "2", "--no-store"])
    monkeypatch.setenv(ENV, address)  # the one-line change: the scheduler's address
    cluster = runner.invoke(main, ["--root", str(base), "check", *ids, "--no-store"])
    assert local.exit_code == 0 and cluster.exit_code == 0, local.output + cluster.output
    assert rows(cluster.output) == rows(local.output) and len(rows(local.output)) >= 8


def test_the_time_limit_acts_inside_a_worker(tmp_path, address):
    """Lim 2057's equilibria asked for by equations (about 30 s) run past a 3 s limit on the
    cluster: the problem comes back as an error naming the limit and its stage, at once."""
    base = tree(tmp_path, ["lim-2057"])
    (base / "answers/lim/2057.yaml").write_text("""\
problem: lim-2057
source: a test
parts:
  - part: slow
    cite: a test
    quantity: equilibrium
    system: planar
    book: {where: ["X = 0"]}
""")
    start = time.monotonic()
    out = CliRunner().invoke(main, ["--root", str(base), "check", "lim-2057", "--timeout", "3",
                                    "--no-store", "--no-crosscheck", "--scheduler", address])
    assert out.exit_code == 1
    line = next(ln for ln in out.output.splitlines() if ln.startswith("lim-2057"))
    assert "time limit of 3 s" in line and "part slow (equilibrium)" in line
    assert time.monotonic() - start < 20
    with Client(address) as client:  # a sweep block's limit: the sidecar is killed
        fut = client.submit(limited, time.sleep, (30,), 1.0, 0.0, pure=False)
        with pytest.raises(MechbookError, match="time limit of 1 s"):
            fut.result(timeout=30)
        assert client.submit(limited, abs, (-3,), 5.0, 0.0, pure=False).result() == 3


def test_sweeps_on_the_cluster_are_identical_to_the_local_run(address, monkeypatch):
    monkeypatch.setattr(sweep_mod, "BLOCK_ENTRIES", 3000)  # several blocks, several workers
    spec = make_spec("lim-9001", TREE, "stability",
                     [parse_axis("Omega=0.2:3:30"), parse_axis("k2=0.5:5:20")],
                     about={"x": "0", "y": "0"})
    local = run_sweep(spec, TREE, samples=4)
    remote = run_sweep(spec, TREE, scheduler=address, samples=4)
    assert remote.attrs["blocks"] > 2 and "Dask" in remote.attrs["where"]
    assert local.arrays.keys() == remote.arrays.keys()
    for key in local.arrays:
        assert np.array_equal(local.arrays[key], remote.arrays[key], equal_nan=True), key
    drift = make_spec("lim-9002", TREE, "drift", [parse_axis("amplitude=0.1:1:3")])
    a, b = run_sweep(drift, TREE, samples=1), run_sweep(drift, TREE, scheduler=address,
                                                        samples=1)
    assert np.array_equal(a.arrays["measured"], b.arrays["measured"], equal_nan=True)
