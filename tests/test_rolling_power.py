"""The checker's power over constrained and rolling systems: every small wrong answer fails.

The same mutants as tests/test_power.py (mechbook.verify.mutate: each number and parameter
occurrence scaled by 1 + δ, the value shifted by δ of its size, a count moved by one), for
δ = 1e-2 and 1e-6, over keys of the classic systems of tests/constrained_systems.py whose
answers are derived there. A mutant may pass only where it provably means the same
(mechbook.verify.power.same_meaning)."""

from __future__ import annotations

import copy
from fractions import Fraction

import pytest
from constrained_systems import CIRCLE, COIN, HOOP, SLEIGH, SPHERICAL, key, write_tree

from mechbook.engine.analysis import Analysis
from mechbook.model.problem import load_problem
from mechbook.verify.answers import Part, load_answers
from mechbook.verify.checker import check_part
from mechbook.verify.context import Context
from mechbook.verify.mutate import COUNTS, part_mutants, shift_sizes
from mechbook.verify.power import same_meaning

UPRIGHT = "    about: {phi: 0, theta: pi/2, psi: 0}\n    steady: {psi: Omega}\n"
KEYS = {
    "coin": (COIN.replace("SHAPE", "disk"), key(
        f"  - part: a\n    cite: s\n    quantity: stability\n{UPRIGHT}"
        "    book: \"Omega**2 > g/(3*R)\"\n"
        f"  - part: b\n    cite: w\n    quantity: frequencies\n{UPRIGHT}"
        "    assume: [\"Omega**2 > g/(3*R)\"]\n"
        "    book: [\"sqrt((12*Omega**2 - 4*g/R)/5)\"]\n"
        "  - part: c\n    cite: f\n    quantity: mode_count\n"
        "    book: {configuration: 5, velocity: 3}\n")),
    "sleigh": (SLEIGH, key(
        "  - part: a\n    cite: e\n    quantity: exponents\n    about: {theta: 0}\n"
        "    steady: {x: v}\n    partial: true\n    book: [\"-m*a*v/(I + m*a**2)\"]\n"
        "  - part: b\n    cite: s\n    quantity: stability\n    about: {theta: 0}\n"
        "    steady: {x: v}\n    book: \"a*v > 0\"\n")),
    "hoop": (HOOP, key(
        "  - part: a\n    cite: eom\n    quantity: eom\n    book: [\"xddot = g*sin(alpha)/2\"]\n"
        "  - part: b\n    cite: friction\n    quantity: constraint_force\n"
        "    constraint: contact\n    coordinate: x\n    book: \"-m*g*sin(alpha)/2\"\n"
        "  - part: c\n    cite: energy\n    quantity: conserved\n"
        "    book: \"E = m*xdot**2/2 + m*R**2*phidot**2/2 - m*g*x*sin(alpha)\"\n")),
    "circle": (CIRCLE, key(
        "  - part: a\n    cite: energy\n    quantity: conserved\n"
        "    book: \"E = m*(xdot**2 + ydot**2)/2 + m*g*y\"\n"
        "  - part: b\n    cite: f\n    quantity: frequencies\n    about: {x: 0, y: -l}\n"
        "    book: [\"sqrt(g/l)\"]\n")),
    "spherical": (SPHERICAL, key(
        "  - part: a\n    cite: f\n    quantity: mode_count\n    book: 2\n"
        "  - part: b\n    cite: w\n    quantity: frequencies\n    about: {x: 0, y: 0, z: -l}\n"
        "    book: [\"sqrt(g/l)\", \"sqrt(g/l)\"]\n")),
}


def _get(data, path):
    for p in path:
        data = data[p]
    return data


def _put(data, path, value):
    _get(data, path[:-1])[path[-1]] = value


@pytest.mark.slow
@pytest.mark.parametrize("delta", [Fraction(1, 100), Fraction(1, 10**6)], ids=["1e-2", "1e-6"])
@pytest.mark.parametrize("name", sorted(KEYS))
def test_every_small_mutant_fails(tmp_path, name, delta):
    problem, answers = KEYS[name]
    ppath, apath = write_tree(tmp_path, "9601", problem, answers)
    analysis = Analysis(load_problem(ppath))
    answer_key = load_answers(apath)
    names = set(analysis.problem.parameters) | set(answer_key.symbols)
    survivors, tried = [], 0
    for part in answer_key.parts:
        original = check_part(analysis, part)
        assert original.status == "pass", (part.name, original.detail)
        value = part.data["book"]
        ctx = Context(analysis, part)
        for m in part_mutants(value, ("book",), names, delta,
                              shift_sizes(ctx, value, ("book",)),
                              counts=part.quantity in COUNTS):
            tried += 1
            data = copy.deepcopy(part.data)
            _put(data, m.path, m.value)
            got = check_part(analysis, Part(answer_key, part.index, data))
            if got.status in ("fail", "error"):
                continue
            if not same_meaning(ctx, m.path, _get(part.data, m.path), m.value, m.token):
                survivors.append(f"{part.name} [{part.quantity}] {m.label}: {got.status} "
                                 f"{got.detail[:160]}")
    assert tried >= 3
    assert not survivors, f"{len(survivors)} of {tried} mutants passed:\n  " + \
        "\n  ".join(survivors)
