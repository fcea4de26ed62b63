"""Parameter sweeps: grids, stacked eigensolvers against hand-solved systems and against the
one-point path, points that do not exist, the 30-digit accuracy check, the book drawn over,
storage with named dimensions, the drift of the nonlinear frequency, and the command."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from click.testing import CliRunner
from scipy.special import ellipk

from mechbook.app.cli import main
from mechbook.app.sweep import Sweeper, make_spec, run_sweep
from mechbook.app.sweep.storage import read_netcdf, read_store, write_netcdf, write_store
from mechbook.engine.analysis import Analysis
from mechbook.engine.linear_grid import (
    MARGINAL,
    STABLE,
    UNDEFINED,
    UNSTABLE,
    Axis,
    Grid,
    LinearSweep,
    parse_axis,
)
from mechbook.errors import InputError, MechbookError, NotFoundError
from mechbook.model.problem import load_problem

ROOT = Path(__file__).resolve().parents[1]
TREE = Path(__file__).resolve().parent / "sweeptree"  # lim-9001 rotor, lim-9002 pendulum

CHAIN = """\
id: lim-9003
source: test fixture (hand-solved)
title: two equal masses between three equal springs
parameters:
  m: {value: 1.0}
  k: {value: 2.0}
coordinates:
  x1: {}
  x2: {}
kinetic: m*(x1dot**2 + x2dot**2)/2
potential: k*(x1**2 + (x2 - x1)**2 + x2**2)/2
"""


def chain(tmp_path) -> Analysis:
    path = tmp_path / "problems" / "lim" / "9003.yaml"
    path.parent.mkdir(parents=True)
    path.write_text(CHAIN)
    return Analysis(load_problem(path))


def symbols(problem) -> list[sp.Symbol]:
    return list(problem.values())


# ---- axes and grids ---------------------------------------------------------------------------
def test_axes_parse_and_refuse_bad_text():
    assert parse_axis("k=1:3:5") == Axis("k", 1.0, 3.0, 5)
    assert np.allclose(parse_axis("k=1:100:3:log").values(), [1, 10, 100])
    for bad in ("k=1:3", "k1:3:5", "k=a:3:5", "k=1:3:0", "k=-1:3:4:log", "k=1:3:4:lin",
                "=1:2:3", "k=1:inf:3"):
        with pytest.raises(ValueError):
            parse_axis(bad)


def test_grid_is_the_outer_product_in_c_order():
    a, b, c = sp.symbols("a b c")
    grid = Grid([Axis("b", 0, 1, 2), Axis("a", 10, 30, 3)], [a, b, c], {a: 5.0, b: 6.0, c: 7.0})
    X = grid.block(0, grid.size)
    assert grid.shape == (2, 3) and X.shape == (6, 3)
    assert X[:, 2].tolist() == [7.0] * 6  # c fixed
    assert X[:, 1].tolist() == [0, 0, 0, 1, 1, 1]  # b: the first axis, slowest
    assert X[:, 0].tolist() == [10, 20, 30, 10, 20, 30]
    assert grid.values_at(4) == {a: 20.0, b: 1.0, c: 7.0}
    with pytest.raises(ValueError, match="not a parameter"):
        Grid([Axis("d", 0, 1, 2)], [a, b, c], {a: 1.0, b: 1.0, c: 1.0})


# ---- stacked eigensolvers ---------------------------------------------------------------------
def test_stacked_frequencies_of_a_hand_solved_chain(tmp_path):
    """ω² = k/m and 3k/m over a grid of k and m, and the same as the one-point path."""
    an = chain(tmp_path)
    lin = an.linear(None, {q: sp.S.Zero for q in an.system().q})
    syms = symbols(an.problem)
    sweep = LinearSweep(lin, syms)
    grid = Grid([parse_axis("m=0.5:4:40"), parse_axis("k=0.1:10:50")], syms, an.problem.values())
    got = sweep.evaluate(grid.block(0, grid.size))
    X = grid.block(0, grid.size)
    m, k = X[:, syms.index(sp.Symbol("m", positive=True))], X[:, 1]
    want = np.column_stack([np.sqrt(k / m), np.sqrt(3 * k / m)])
    assert np.allclose(got.frequencies, want, rtol=1e-13, atol=0)
    assert np.all(got.stability == STABLE)
    for flat in (0, 777, grid.size - 1):
        one = lin.numeric_frequencies(grid.values_at(flat))
        assert np.allclose(got.frequencies[flat], one, rtol=1e-13)


def test_gyroscopic_stability_map_against_the_hand_derived_condition():
    """The rotor (tests/sweeptree lim-9001): unstable exactly where
    (k1 − mΩ²)(k2 − mΩ²) < 0, stable again above both natural frequencies."""
    an = Analysis(load_problem(TREE / "problems/lim/9001.yaml"))
    lin = an.linear(None, {q: sp.S.Zero for q in an.system().q})
    assert lin.gyroscopic
    syms = symbols(an.problem)
    sweep = LinearSweep(lin, syms)
    grid = Grid([parse_axis("Omega=0.05:3:300"), parse_axis("k2=0.2:6:40")], syms,
                an.problem.values())
    X = grid.block(0, grid.size)
    got = sweep.evaluate(X)
    val = dict(zip([str(s) for s in syms], X.T, strict=True))
    product = (val["k1"] - val["m"] * val["Omega"] ** 2) * (val["k2"] - val["m"] * val["Omega"]
                                                             ** 2)
    clear = np.abs(product) > 1e-6
    assert np.all((got.stability == STABLE)[clear] == (product > 0)[clear])
    assert {STABLE, UNSTABLE} <= set(np.unique(got.stability))
    # frequencies where stable: s**2 roots of s**4 + (a + b + 4Ω²)s² + ab = 0
    a = val["k1"] / val["m"] - val["Omega"] ** 2
    b = val["k2"] / val["m"] - val["Omega"] ** 2
    p = a + b + 4 * val["Omega"] ** 2
    disc = np.sqrt(np.maximum(p**2 - 4 * a * b, 0))
    ok = product > 1e-6
    roots = np.column_stack([(p - disc) / 2, (p + disc) / 2])[ok]
    want = np.sort(np.sqrt(roots), axis=1)
    assert np.allclose(got.frequencies[ok], want, rtol=1e-9)


def test_a_point_that_does_not_exist_is_undefined_not_unstable():
    """Lim 2031's off-axis equilibrium cos θ = −g/(bω²) exists only for ω² > g/b; below,
    M and K still evaluate (cos(acos x) = x), but the point is not real."""
    an = Analysis(load_problem(ROOT / "problems/lim/2031.yaml"))
    sysm = an.system()
    g, b, omega = (sp.Symbol(n, positive=True) for n in ("g", "b", "omega"))
    lin = an.linear(None, {sysm.q[0]: sp.acos(-g / (b * omega**2))})
    syms = symbols(an.problem)
    grid = Grid([parse_axis("omega=1:10:91")], syms, an.problem.values())
    got = LinearSweep(lin, syms).evaluate(grid.block(0, grid.size))
    w = grid.coords()["omega"]
    real = w**2 > 9.81 / 0.5
    assert np.all(got.stability[~real] == UNDEFINED)
    assert np.all(np.isnan(got.frequencies[~real]))
    assert np.all(got.stability[real] == STABLE)


def test_marginal_and_unstable_codes_of_the_symmetric_path(tmp_path):
    an = chain(tmp_path)
    lin = an.linear(None, {q: sp.S.Zero for q in an.system().q})
    syms = symbols(an.problem)
    sweep = LinearSweep(lin, syms)
    X = np.array([[1.0, 2.0], [1.0, 0.0], [1.0, -1.0]])  # k > 0, k = 0, k < 0
    got = sweep.evaluate(X)
    assert got.stability.tolist() == [STABLE, MARGINAL, UNSTABLE]
    # ω² = k/m and 3k/m: both negative, the faster growth is sqrt(3)
    assert np.isnan(got.frequencies[2]).all() and got.growth[2] == pytest.approx(np.sqrt(3))


# ---- the command's pieces ---------------------------------------------------------------------
def test_lim_2031_map_agrees_with_the_book_and_a_wrong_book_does_not(tmp_path):
    spec = make_spec("lim-2031", ROOT, "stability",
                     [parse_axis("omega=0.5:10:60"), parse_axis("b=0.1:1:40")],
                     about={"theta": "pi"})
    result = run_sweep(spec, ROOT)
    assert result.book["disagree"] == 0
    assert result.attrs["max_rel_diff_float64_vs_30_digits"] < 1e-12
    assert result.attrs["accuracy_disagreements"] == 0
    assert result.attrs["accuracy"]["boundary_samples"] > 0
    codes = result.arrays["stability"]
    assert {STABLE, UNSTABLE} <= set(np.unique(codes))
    # the same sweep against a wrong "book" (the boundary at 1.2 Ω): the count catches it
    tree = tmp_path / "tree"
    for sub in ("problems", "answers"):
        (tree / sub / "lim").mkdir(parents=True)
        text = (ROOT / sub / "lim/2031.yaml").read_text()
        (tree / sub / "lim/2031.yaml").write_text(text.replace("Omega: sqrt(g/b)",
                                                               "Omega: 1.2*sqrt(g/b)"))
    wrong = run_sweep(make_spec("lim-2031", tree, "stability", list(spec.axes),
                                about={"theta": "pi"}), tree)
    assert wrong.book["disagree"] > 0


def test_the_accuracy_check_catches_a_corrupted_float_path(monkeypatch):
    spec = make_spec("lim-2036", ROOT, "frequencies",
                     [parse_axis("l1=0.5:2:30"), parse_axis("l2=0.5:2:30")])
    good = run_sweep(spec, ROOT, samples=8)
    assert good.attrs["max_rel_diff_float64_vs_30_digits"] < 1e-13
    book = good.book["max_rel_diff"]
    assert book < 1e-12  # Lim 2036 (a) over the grid

    real = LinearSweep.evaluate

    def skewed(self, X, want=("frequencies", "stability"), precise=True):
        out = real(self, X, want, precise)
        out.frequencies = out.frequencies * (1 + 1e-6)
        return out

    monkeypatch.setattr(LinearSweep, "evaluate", skewed)
    bad = run_sweep(spec, ROOT, samples=8)
    assert bad.attrs["max_rel_diff_float64_vs_30_digits"] > 5e-7


def test_the_sample_pool_is_setdiff1ds_without_its_sort():
    """The points left to sample once the boundary's are chosen: np.setdiff1d's result
    (same seed, same samples as before), including points not in the pool at all."""
    from mechbook.app.sweep.precision import points_left

    rng = np.random.default_rng(3)
    for n in (0, 1, 2, 50, 20_000):
        pool = np.unique(rng.integers(0, 3 * n + 1, n)).astype(np.int64)
        taken = pool[rng.choice(pool.size, min(pool.size, 9), replace=False)] \
            if pool.size else np.zeros(0, dtype=np.int64)
        taken = np.concatenate([taken, taken[:2], [-1, 10 ** 9]]).astype(np.int64)
        assert np.array_equal(points_left(pool, taken), np.setdiff1d(pool, taken))


def test_wrong_requests_are_refused():
    with pytest.raises(MechbookError, match="not a parameter"):
        Sweeper(make_spec("lim-2031", ROOT, "frequencies", [parse_axis("zeta=1:2:3")],
                          about={"theta": "pi"}), ROOT)
    with pytest.raises(InputError, match="positive"):
        Sweeper(make_spec("lim-2031", ROOT, "frequencies", [parse_axis("omega=0:2:3")],
                          about={"theta": "pi"}), ROOT)
    with pytest.raises(MechbookError, match="amplitude"):
        Sweeper(make_spec("lim-2031", ROOT, "drift", [parse_axis("omega=1:2:3")],
                          about={"theta": "pi"}), ROOT)
    with pytest.raises(NotFoundError, match="no such part"):
        Sweeper(make_spec("lim-2031", ROOT, "frequencies", [parse_axis("omega=1:2:3")],
                          part="nope"), ROOT)
    with pytest.raises(NotFoundError, match="not a coordinate"):
        Sweeper(make_spec("lim-2031", ROOT, "frequencies", [parse_axis("omega=1:2:3")],
                          about={"phi": "0"}), ROOT)


def test_a_steady_motion_holds_the_momenta_the_reduced_system_holds():
    """--part b of Symon 11-18 is about a steady precession: the sweep's held momenta are
    the reduced system's (the SystemLike contract), and its point says so."""
    sweeper = Sweeper(make_spec("symon-11-18", ROOT, "frequencies", [parse_axis("m=0.01:0.1:2")],
                                part="b"), ROOT)
    system = sweeper.lin.dyn.sys
    assert system.reduced and sweeper.steady == system.held_momenta
    assert [str(c) for c in sweeper.steady] == ["phi", "psi"]
    assert "; steady, momenta p_phi = " in sweeper.point_text()


def test_a_part_brings_its_assumptions(tmp_path):
    """--part c-frequency of Lim 2031 assumes ω > Ω: points below are undefined."""
    spec = make_spec("lim-2031", ROOT, "frequencies", [parse_axis("omega=2:8:25")],
                     part="c-frequency")
    result = run_sweep(spec, ROOT, samples=4)
    w = result.coords["omega"]
    below = w <= np.sqrt(9.81 / 0.5)
    assert np.all(result.arrays["stability"][below] == UNDEFINED)
    assert np.all(np.isfinite(result.arrays["frequencies"][~below]))
    assert result.book["max_rel_diff"] < 1e-12


def test_drift_of_the_pendulum_frequency_is_the_elliptic_one():
    """ω(a)/ω₀ = π / (2 K(sin²(a/2))) for a plane pendulum released at angle a."""
    spec = make_spec("lim-9002", TREE, "drift", [parse_axis("amplitude=0.05:1.5:4")])
    result = run_sweep(spec, TREE, samples=2)
    a = result.coords["amplitude"]
    want = np.pi / (2 * ellipk(np.sin(a / 2) ** 2)) - 1
    got = result.arrays["relative_error"][:, 0]
    assert np.allclose(got, want, rtol=1e-6, atol=1e-9)
    assert result.arrays["linear"][0, 0] == pytest.approx(np.sqrt(9.81 / 1.3), rel=1e-12)


def test_store_and_netcdf_keep_named_dimensions(tmp_path):
    spec = make_spec("lim-9001", TREE, "stability",
                     [parse_axis("Omega=0.5:3:7"), parse_axis("k2=1:5:5")],
                     about={"x": "0", "y": "0"})
    result = run_sweep(spec, TREE, samples=4)
    store = write_store(result, "map", tmp_path / "store.h5")
    back = read_store("lim-9001", "map", store)
    assert back["variables"]["stability"][0] == ("Omega", "k2")
    assert np.array_equal(back["variables"]["stability"][1], result.arrays["stability"])
    assert np.array_equal(back["coords"]["Omega"], result.coords["Omega"])
    assert back["variables"]["book_stable"][0] == ("Omega", "k2")
    assert back["attrs"]["quantity"] == "stability"
    nc = read_netcdf(write_netcdf(result, tmp_path / "map.nc"))
    assert nc["variables"]["growth"][0] == ("Omega", "k2")
    assert np.array_equal(nc["variables"]["stability"][1], result.arrays["stability"])
    assert nc["attrs"]["gyroscopic"] == 1
    with pytest.raises(MechbookError, match="invalid sweep name"):
        write_store(result, "../x", tmp_path / "store.h5")


@pytest.mark.slow
def test_sweep_command_prints_stores_and_plots(tmp_path):
    plot = tmp_path / "map.png"
    store = tmp_path / "store.h5"
    out = CliRunner().invoke(main, ["--root", str(TREE), "sweep", "lim-9001", "--quantity",
                                    "stability", "--param", "Omega=0.2:3:40", "--param",
                                    "k2=0.5:5:20", "--about", "x=0", "--about", "y=0",
                                    "--store", str(store), "--plot", str(plot)])
    assert out.exit_code == 0, out.output
    assert "gyroscopic" in out.output and "largest relative difference" in out.output
    assert "agrees with the engine at 800 of 800" in out.output
    assert plot.stat().st_size > 10_000
    assert read_store("lim-9001", "stability-Omega-k2", store)["attrs"]["points"] == 800
    # a check run into the same store keeps the sweep, and `show` lists it
    checked = CliRunner().invoke(main, ["--root", str(TREE), "check", "lim-9001", "--store",
                                        str(store), "--no-crosscheck", "--fresh", "-j", "1"])
    assert checked.exit_code == 0, checked.output
    listed = CliRunner().invoke(main, ["--root", str(TREE), "show", "lim-9001", "--store",
                                       str(store)])
    assert "sweep stored: /sweeps/lim-9001/stability-Omega-k2: stability over " \
        "Omega=0.2:3:40 k2=0.5:5:20 about x = 0, y = 0" in listed.output, listed.output
    bad = CliRunner().invoke(main, ["--root", str(TREE), "sweep", "lim-9001", "--param",
                                    "Omega=1:3"])
    assert bad.exit_code == 4 and "NAME=LO:HI:N" in bad.output


def test_ill_conditioned_points_are_recomputed_with_50_digits(tmp_path):
    """Two unequal masses on the chain: with m2/m1 = 1e-10 the ω² spread is beyond 1e6, the
    float64 result is not trusted there and the point is recomputed with 50 digits; the
    result is the one-point path's (which falls back the same way)."""
    path = tmp_path / "problems" / "lim" / "9004.yaml"
    path.parent.mkdir(parents=True)
    path.write_text(CHAIN.replace("lim-9003", "lim-9004").replace(
        "m: {value: 1.0}", "m1: {value: 1.0}\n  m2: {value: 1.0}").replace(
        "kinetic: m*(x1dot**2 + x2dot**2)/2", "kinetic: (m1*x1dot**2 + m2*x2dot**2)/2"))
    an = Analysis(load_problem(path))
    lin = an.linear(None, {q: sp.S.Zero for q in an.system().q})
    syms = symbols(an.problem)
    X = np.array([[1.0, 1.0, 2.0], [1.0, 1e-10, 2.0]])  # columns m1, m2, k
    assert [str(s) for s in syms] == ["m1", "m2", "k"]
    got = LinearSweep(lin, syms).evaluate(X)
    assert got.ill == 1 and got.precise == 1
    for i in range(2):
        one = lin.numeric_frequencies(dict(zip(syms, X[i], strict=True)))
        assert np.allclose(got.frequencies[i], one, rtol=1e-12)


def test_a_local_process_pool_gives_the_same_result(monkeypatch):
    import mechbook.app.sweep.runner as sweep_mod

    monkeypatch.setattr(sweep_mod, "BLOCK_ENTRIES", 2000)
    spec = make_spec("lim-9001", TREE, "frequencies",
                     [parse_axis("Omega=0.2:3:20"), parse_axis("k2=0.5:5:20")])
    one = run_sweep(spec, TREE, samples=2)
    two = run_sweep(spec, TREE, jobs=2, samples=2)
    assert two.attrs["blocks"] > 2 and "2 local processes" in two.attrs["where"]
    for key in one.arrays:
        assert np.array_equal(one.arrays[key], two.arrays[key], equal_nan=True), key
