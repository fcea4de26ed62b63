"""Perturbation theory and asymptotic checks: the `perturbation` quantity on a hand-solved
two-mode system, `limit:` orders measured at 50 digits, and the parser's Operator names."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import sympy as sp
from systems import load_analysis as load

from mechbook.engine import perturbation as pert
from mechbook.engine.analysis import Analysis
from mechbook.errors import ExpressionError
from mechbook.model.expr import Operator, parse
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

# unit masses, W0 = (1, 4), V' = eps*(a*x1**2/2 + c*x1*x2 + d*x2**2/2)
TWO = """\
id: lim-9501
source: test
title: two oscillators, weakly coupled
parameters:
  a: {value: 0.7}
  c: {value: 0.9}
  d: {value: -0.4, positive: false}
  eps: {value: 1.0}
coordinates:
  x1: {}
  x2: {}
particles:
  p1: {mass: 1, position: [x1]}
  p2: {mass: 1, position: [x2]}
potential: (x1**2 + 4*x2**2)/2 + eps*(a*x1**2/2 + c*x1*x2 + d*x2**2/2)
"""


def run(tmp_path: Path, an: Analysis, part: dict):
    d = tmp_path / "answers" / "lim"
    d.mkdir(parents=True, exist_ok=True)
    f = d / f"{an.problem.id.split('-')[1]}.yaml"
    f.write_text(json.dumps({"problem": an.problem.id, "source": "test",
                             "parts": [{"cite": "t", **part}]}))
    return check_problem(an, load_answers(f))[0]


def part(order: int, book: str, **extra) -> dict:
    return {"part": "p", "quantity": "perturbation", "about": {"x1": 0, "x2": 0},
            "approximates": "squared_frequency", "mode": 1,
            "limit": {"parameter": "eps", "to": "0", "order": order}, "book": book, **extra}


FIRST = "W0(1) + Wp(1, 1)"
SECOND = "W0(1) + Wp(1, 1) - sum(Wp(1, r)**2/(W0(r) - W0(1)), r, 1)"


def test_the_split_by_hand(tmp_path):
    """W0 = (1, 4); W' = eps*[[a, c], [c, d]] in these (already normal, unit-mass) coordinates."""
    an = load(tmp_path, TWO, "9501")
    lin = an.linear(None, {q: sp.S.Zero for q in an.system().q})
    eps, a, c, d = (an.problem.parameters[n].symbol for n in ("eps", "a", "c", "d"))
    values = {eps: sp.Float("0.01", 30), a: sp.Float("0.7", 30), c: sp.Float("0.9", 30),
              d: sp.Float("-0.4", 30)}
    s = pert.split(lin, values, {eps: 0})
    assert [float(w) for w in s.W0] == pytest.approx([1.0, 4.0])
    assert float(s.Wp[0, 0]) == pytest.approx(0.007, rel=1e-12)
    assert abs(float(s.Wp[0, 1])) == pytest.approx(0.009, rel=1e-12)
    assert float(s.Wp[1, 1]) == pytest.approx(-0.004, rel=1e-12)


def test_orders_are_measured(tmp_path):
    an = load(tmp_path, TWO, "9501")
    assert run(tmp_path, an, part(1, FIRST)).status == "pass"
    assert run(tmp_path, an, part(2, FIRST)).status == "fail"  # only first order right
    assert run(tmp_path, an, part(2, SECOND)).status == "pass"
    wrong_sign = SECOND.replace(" - sum", " + sum")
    out = run(tmp_path, an, part(2, wrong_sign))
    assert out.status == "fail" and "falls like eps**2" in out.detail


def test_mode_components_to_first_order(tmp_path):
    an = load(tmp_path, TWO, "9501")
    comp = part(1, "-Wp(j, 1)/(W0(j) - W0(1))", approximates="component", component="j")
    assert run(tmp_path, an, comp).status == "pass"
    assert run(tmp_path, an, dict(comp, book="Wp(j, 1)/(W0(j) - W0(1))")).status == "fail"


def test_operator_names_in_the_parser():
    f = sp.Function("W0")
    names = {"W0": Operator("W0", f, (1, 1)), "j": sp.Symbol("j", integer=True)}
    assert parse("W0(j) + 1", names) == f(sp.Symbol("j", integer=True)) + 1
    with pytest.raises(ExpressionError, match="without a call"):
        parse("W0 + 1", names)
    with pytest.raises(ExpressionError, match="argument"):
        parse("W0(1, 2)", names)
    with pytest.raises(ExpressionError, match="unknown function"):
        parse("W0(1)", {})


@pytest.mark.parametrize("name, words", [
    ("b", "'b' is a name of the problem"),       # the text's friction table b(j, r)
    ("r", "index 'r' is already a name"),        # a default index name
])
def test_a_name_of_the_problem_that_is_also_the_texts_notation_is_refused(tmp_path, name,
                                                                         words):
    """A parameter named like the text's notation is refused with the reason, not silently
    shadowed (the coupling c renamed)."""
    text = TWO.replace("  c: {value: 0.9}", f"  {name}: {{value: 0.9}}") \
        .replace("c*x1*x2", f"{name}*x1*x2")
    an = load(tmp_path, text, "9501")
    out = run(tmp_path, an, part(1, FIRST))
    assert out.status == "error" and words in out.detail, out.detail



def test_a_formula_that_divides_by_zero_at_one_index_is_compared_at_the_others():
    """Symon 12-20's C_j = -i ω0(1) b(j,1)/(W0(j) − W0(1)) is zoo at j = 1: that index is
    not a number (skipped), not an AttributeError; the power bench's equivalence step ended
    in one on the mutant √(−1) → √(−(1 + 7e-8)), which scales the first-order term and is
    not equivalent."""
    from mechbook.model.problem import load_problem
    from mechbook.verify.context import Context
    from mechbook.verify.power import same_meaning

    root = Path(__file__).resolve().parents[1]
    analysis = Analysis(load_problem(root / "problems" / "symon" / "12-20.yaml"))
    key = load_answers(root / "answers" / "symon" / "12-20.yaml")
    part = next(p for p in key.parts if p.name == "a-mode")
    old = "-sqrt(-1)*omega0(1)*b(j, 1)/(W0(j) - W0(1))"
    assert same_meaning(Context(analysis, part), ("book",), old, old) != ""
    new = "-sqrt(-(1*(100000007/100000000)))*omega0(1)*b(j, 1)/(W0(j) - W0(1))"
    assert same_meaning(Context(analysis, part), ("book",), old, new) == ""
