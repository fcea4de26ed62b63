"""An exponent such as 2·(1 + 1e-19) is valid input, but SymPy's exact algebra turns it into
a polynomial of degree 1e19 and gmp aborts the process: proofs and the power bench's
equivalence must leave such an expression to the numbers (found by bench/power.py's full
run: its equivalence step died on symon-11-08's polhode mutant)."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import sympy as sp

from mechbook.core.algebra_reach import within_exact_reach

ROOT = Path(__file__).resolve().parents[1]
HUGE = "10000000000000000001/5000000000000000000"  # 2·(1 + 1e-19)


def test_small_rational_exponents_are_within_reach_and_huge_ones_not():
    x, y = sp.symbols("x y", positive=True)
    assert within_exact_reach(sp.sqrt(x) + x**sp.Rational(3, 2) * y**-3, 5, "text")
    assert not within_exact_reach(x**sp.Rational(HUGE))
    assert not within_exact_reach(y + x**sp.Rational(1, 10**5))
    assert within_exact_reach(x**sp.Rational(1, 10**4))


def _tree(tmp_path: Path) -> Path:
    """symon-11-08 alone, its polhode's I3**2 moved to I3**(2·(1 + 1e-19))."""
    for sub in ("problems/symon", "answers/symon"):
        (tmp_path / sub).mkdir(parents=True)
    shutil.copy(ROOT / "books.yaml", tmp_path)
    shutil.copy(ROOT / "problems/symon/11-08.yaml", tmp_path / "problems/symon")
    key = (ROOT / "answers/symon/11-08.yaml").read_text()
    old = 'book: "I1**2*x1**2 + I2**2*x2**2 + I3**2*x3**2"'
    assert key.count(old) == 1
    key = key.replace(old, f'book: "I1**2*x1**2 + I2**2*x2**2 + I3**({HUGE})*x3**2"')
    (tmp_path / "answers/symon/11-08.yaml").write_text(key)
    return tmp_path


def test_prove_leaves_a_huge_exponent_to_the_numbers_and_ends_normally(tmp_path):
    tree = _tree(tmp_path)
    got = subprocess.run([sys.executable, "-m", "mechbook", "--root", str(tree), "check",
                          "symon-11-08", "--prove", "--serial", "--no-store", "-v"],
                         capture_output=True, text=True, timeout=600)
    out = got.stdout + got.stderr
    assert got.returncode in (0, 1), out  # an outcome for every part: not an abort (-6)
    assert "died" not in out and "Traceback" not in out and "error" not in out.lower(), out
    row = next(line for line in out.splitlines() if "a-polhode" in line and "conserved " in line)
    # the mutant is not conserved: d/dt leaves 2e-19·ln(I3)·I3²·d(x3²)/dt, ~1e-20, at
    # 1e-26 to 1e-34 of the cancellation scale (4e6 to 2e13 at these points), real at 60
    # digits: judged numerically, never proved, and a fail whatever the hash seed
    assert "symbolic" not in row, row
    assert " fail " in row and "not rounding" in row, row
    assert got.returncode == 1, out
