"""`--prove`: every proof path proves a true identity and never a wrong one, and a passing
part that is not proved says why.

The identities are the textbook ones, written out here (sin 2x = 2 sin x cos x, √a·√b =
√(ab) for a > 0, ...); each wrong variant differs by a coefficient 1e-6 (exact, 1/10⁶), far
below what a plot would show, and must never be proved.
"""

from __future__ import annotations

import json
from pathlib import Path

import sympy as sp
import yaml

from mechbook.core.identity import decide_zero
from mechbook.engine.analysis import Analysis
from mechbook.model.problem import load_problem
from mechbook.records import ProofPolicy, Status
from mechbook.verify import proof
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem
from mechbook.verify.compare import Sampler, all_vanish, equal, vanishes

ROOT = Path(__file__).resolve().parents[1]
PROVE = ProofPolicy(True, 5.0)
EPS = sp.Rational(1, 10**6)

a, b, m, g, L = sp.symbols("a b m g L", positive=True)
x, y, t = sp.symbols("x y t", real=True)

# (name, an identity's two sides): each path of mechbook.core.identity once
IDENTITIES = [
    ("rational", (a + b) ** 3 / (a - b), (a**3 + 3 * a**2 * b + 3 * a * b**2 + b**3) / (a - b)),
    ("double angle", sp.sin(2 * x), 2 * sp.sin(x) * sp.cos(x)),
    ("sum of angles", sp.cos(x - y), sp.cos(x) * sp.cos(y) + sp.sin(x) * sp.sin(y)),
    ("half angles", sp.sin(x), 2 * sp.sin(x / 2) * sp.cos(x / 2)),
    ("tangent", sp.tan(x) * sp.cos(x) ** 2, sp.sin(x) * sp.cos(x)),
    ("pythagoras in a fraction", m * g / (m * sp.sin(x) ** 2 + m * sp.cos(x) ** 2), g),
    ("constant angle", sp.sin(x + sp.pi / 3), sp.sin(x) / 2 + sp.sqrt(3) * sp.cos(x) / 2),
    ("merged roots", sp.sqrt(a + b) * sp.sqrt(a * (a - b) ** 2 + b), sp.sqrt(
        sp.expand((a + b) * (a * (a - b) ** 2 + b)))),
    ("root of a fraction", sp.sqrt(g**2 / m**2 + 4 * a**2) / 2,
     sp.sqrt(g**2 + 4 * m**2 * a**2) / (2 * m)),
    ("root squared", sp.sqrt(L**2 - 2 * L * a * sp.cos(x) + a**2) ** 3,
     (L**2 - 2 * L * a * sp.cos(x) + a**2) * sp.sqrt(a**2 + L**2 - 2 * a * L * sp.cos(x))),
    ("inverse sine inside", sp.sin(x + sp.asin(y)),
     sp.sin(x) * sp.sqrt(1 - y**2) + sp.cos(x) * y),
    ("exponentials", sp.exp(2 * t) * sp.exp(-t), sp.exp(t)),
    ("hyperbolic", sp.cosh(t) ** 2 - sp.sinh(t) ** 2, sp.Integer(1)),
]


def test_every_path_proves_its_identity():
    for name, lhs, rhs in IDENTITIES:
        assert decide_zero(lhs - rhs).zero is True, name


def test_a_coefficient_wrong_by_1e_6_is_never_proved():
    """The right side scaled by 1 + 1e-6, or shifted by 1e-6 times a term of its own: no
    path may call that 0 (the canonical form is exact: a remainder of 1e-6 stays)."""
    for name, lhs, rhs in IDENTITIES:
        for wrong in ((1 + EPS) * rhs, rhs + EPS * sp.Add.make_args(sp.expand(rhs))[0]):
            assert decide_zero(lhs - wrong).zero is not True, name


def test_decided_false_only_where_the_form_is_complete():
    """A trigonometric rational function that is not 0 is decided (no simplify needed);
    one with a free generator (a function kept whole) is only left open."""
    assert decide_zero(sp.sin(x) ** 2 - sp.cos(x) ** 2 - EPS).zero is False
    assert decide_zero(sp.sin(x) ** 2 + sp.cos(x) ** 2 - 1 + EPS * sp.cos(2 * x)).zero is False
    assert decide_zero(sp.Abs(x) - x).zero is None  # true for x ≥ 0 only: never decided


def test_floats_are_never_proved():
    """0.1 is not 1/10 in binary: a difference holding floating-point numbers is not proved
    even where SymPy's arithmetic would make it 0."""
    assert decide_zero(sp.Add(sp.Float(0.1) * x, -x / 10, evaluate=False)).zero is None
    sampler = _sampler()
    unevaluated = sp.Add(sp.Float(0.5) * x, -x / 2, evaluate=False)
    assert proof.prove_zero(unevaluated, sampler) == proof.Proof(False, proof.FLOATS)
    # SymPy itself folds 0.1·x − x/10 to 0: the comparison looks at both sides first
    v = equal(sp.Float(0.1) * x, x / 10, sampler)
    assert v.ok and v.method != "symbolic" and v.unproved == proof.FLOATS


def _sampler(conditions=(), derived=None, rtol=1e-10, fixed=()):
    base = {a: 1.3, b: 0.7, m: 2.0, g: 9.8, L: 1.1}
    return Sampler(base, list(conditions), policy=PROVE, derived=derived, rtol=rtol,
                   fixed=list(fixed))


def test_a_condition_is_used_as_the_proof_domain():
    """√(3a − 3b)·√(1/(a − b)) = √3 holds where a > b (the problem's condition), not for
    a < b: proved with the condition, never without it."""
    expr = sp.sqrt(3 * a - 3 * b) * sp.sqrt(1 / (a - b)) - sp.sqrt(3)
    assert proof.prove_zero(expr, _sampler([a > b])).ok
    assert not proof.prove_zero(expr, _sampler()).ok
    assert not proof.prove_zero(expr + EPS, _sampler([a > b])).ok


def test_a_restricted_symbol_is_replaced_by_its_expression():
    """restrict: b = a/2: a − 2b = 0 there (proved), a − 2b − 1e-6·a not."""
    sampler = _sampler(derived={b: a / 2})
    assert proof.prove_zero(a - 2 * b, sampler).ok
    assert not proof.prove_zero(a - 2 * b - EPS * a, sampler).ok


def test_the_reasons_are_stated():
    """An estimate and a root's branch are decided at once, with their phrase."""
    est = _sampler(rtol=1e-3, fixed=[a])
    assert proof.prove_zero(a - a * (1 + EPS), est) == proof.Proof(False, proof.ESTIMATE)
    branch = sp.sqrt(a**2 - 2 * a * b + b**2) - (a - b)  # |a − b|: a sign not fixed
    assert proof.prove_zero(branch, _sampler()) == proof.Proof(False, proof.BRANCH)
    v = vanishes(branch, _sampler([a > b]))
    assert v.ok and v.method == "symbolic"  # with a > b the sign is fixed: proved
    assert proof.unproved_reason("boundary(6 crossings to 1e-08)") == proof.BOUNDARY
    assert proof.unproved_reason("numeric(asymptotic)") == proof.LIMIT


def test_comparisons_prove_and_refuse():
    """vanishes/equal/all_vanish with --prove: symbolic for the identity; for a 1e-6 wrong
    one the numeric comparison fails first (and no proof is ever attempted)."""
    s = _sampler()
    lhs, rhs = sp.sin(2 * x), 2 * sp.sin(x) * sp.cos(x)
    assert equal(lhs, rhs, s).method == "symbolic"
    assert not equal(lhs, (1 + EPS) * rhs, s).ok
    assert all_vanish([lhs - rhs, sp.cos(x) ** 2 + sp.sin(x) ** 2 - 1], s).method == "symbolic"
    assert not all_vanish([lhs - rhs, lhs - (1 + EPS) * rhs], s).ok


def _lim_key(tmp_path: Path, pid: str, edit) -> Path:
    data = yaml.safe_load((ROOT / "answers" / "lim" / f"{pid}.yaml").read_text())
    edit(data)
    f = tmp_path / f"{pid}.yaml"
    f.write_text(json.dumps(data))
    return f


def test_a_book_problem_proved_and_its_wrong_key_failed(tmp_path):
    """Lim 2059 (hoop and bead): the Lagrangian, both equations and the normal modes are
    proved; the first equation with a coefficient wrong by 1e-6 fails (numerically, before
    any proof), and so does a mode shape wrong by 1e-6."""
    an = Analysis(load_problem(ROOT / "problems" / "lim" / "2059.yaml"))
    right = check_problem(an, load_answers(_lim_key(tmp_path, "2059", lambda d: None)), PROVE)
    methods = {o.part: o.method for o in right}
    assert all(o.status == Status.PASS for o in right)
    for part in ("a-lagrangian", "a", "b-modes"):
        assert methods[part] == "symbolic", (part, methods[part])

    def wrong_eom(d):
        eq = d["parts"][1]["book"]
        eq[0] = eq[0].replace("(M + m)*g*sin(theta)", "(M + m)*g*(1 + 1e-6)*sin(theta)")

    def wrong_mode(d):
        part = next(p for p in d["parts"] if p["quantity"] == "normal_modes")
        shape = part["book"][0]["shape"]
        k = next(iter(shape))
        shape[k] = f"(1 + 1e-6)*({shape[k]})"

    for edit in (wrong_eom, wrong_mode):
        out = check_problem(an, load_answers(_lim_key(tmp_path, "2059", edit)), PROVE)
        assert any(o.status == Status.FAIL for o in out), edit.__name__
        assert not any(o.status == Status.FAIL and o.method == "symbolic" for o in out)


def test_every_unproved_pass_says_why(tmp_path):
    """Lim 2067 (an angle through asin): its passes that are not proved name their reason
    in the method column; a plain check's methods carry no such tail."""
    an = Analysis(load_problem(ROOT / "problems" / "lim" / "2067.yaml"))
    key = load_answers(ROOT / "answers" / "lim" / "2067.yaml")
    proved = check_problem(an, key, PROVE)
    plain = check_problem(an, key)
    assert [o.status for o in proved] == [o.status for o in plain]
    for o in proved:
        assert o.method == "symbolic" or "; unproved: " in o.method, o.method
    assert any(proof.BRANCH in o.method for o in proved)
    assert not any("unproved" in o.method for o in plain)


def test_a_first_order_linearizations_frequencies_are_unproved_not_an_error():
    """The coin rolling upright (velocity constraints: a first-order linearization) under
    --prove: its wobble frequencies pass as in a plain check and say why they are unproved
    (they raised AttributeError: the prover asked it for closed-form frequencies)."""
    an = Analysis(load_problem(ROOT / "problems" / "classic" / "coin-rolling-upright.yaml"))
    key = load_answers(ROOT / "answers" / "classic" / "coin-rolling-upright.yaml")
    proved = check_problem(an, key, PROVE)
    plain = check_problem(an, key)
    assert [o.status for o in proved] == [o.status for o in plain]
    assert all(o.status == Status.PASS for o in proved), [o.detail for o in proved]
    wobbles = [o for o in proved if o.part.endswith("wobble")]
    assert len(wobbles) == 3
    assert all("first-order linearization" in o.method for o in wobbles)


def test_frequencies_proved_as_roots_of_the_secular_polynomial(tmp_path):
    """Lim 2055 (six coupled pendulums in a ring, two double roots): each book ω² makes
    det(K − ω²M) and, for a double root, its derivative vanish identically: proved without
    solving the sextic. A frequency wrong by 1e-6 fails."""
    an = Analysis(load_problem(ROOT / "problems" / "lim" / "2055.yaml"))

    def only_b(d):
        d["parts"] = [p for p in d["parts"] if p["part"] == "b"]

    right = check_problem(an, load_answers(_lim_key(tmp_path, "2055", only_b)), PROVE)
    assert [(o.status, o.method) for o in right] == [(Status.PASS, "symbolic")]

    def wrong(d):
        only_b(d)
        d["parts"][0]["book"][1] = f"(1 + 1e-6)*{d['parts'][0]['book'][1]}"

    out = check_problem(an, load_answers(_lim_key(tmp_path, "2055", wrong)), PROVE)
    assert out[0].status == Status.FAIL


def test_an_initial_value_motion_is_proved(tmp_path):
    """Lim 2043 (c): the book's motion satisfies the linearized equations and the initial
    values exactly (unique solution): proved; its amplitude wrong by 1e-6 fails."""
    an = Analysis(load_problem(ROOT / "problems" / "lim" / "2043.yaml"))

    def only(d):
        d["parts"] = [p for p in d["parts"] if p["part"] == "c-solution"]

    right = check_problem(an, load_answers(_lim_key(tmp_path, "2043", only)), PROVE)
    assert [(o.status, o.method) for o in right] == [(Status.PASS, "symbolic")]

    def wrong(d):
        only(d)
        book = d["parts"][0]["book"]
        k = next(iter(book))
        book[k] = f"(1 + 1e-6)*({book[k]})"

    out = check_problem(an, load_answers(_lim_key(tmp_path, "2043", wrong)), PROVE)
    assert out[0].status == Status.FAIL


def test_normal_coordinates_are_proved(tmp_path):
    """Lim 2028 (b): K·adj(M)·c = ω²·det(M)·c for each form, exactly; the centre-of-mass
    form with its coefficient wrong by 1e-6 fails."""
    an = Analysis(load_problem(ROOT / "problems" / "lim" / "2028.yaml"))

    def only(d):
        d["parts"] = [p for p in d["parts"] if p["part"] == "b"]

    right = check_problem(an, load_answers(_lim_key(tmp_path, "2028", only)), PROVE)
    assert [(o.status, o.method) for o in right] == [(Status.PASS, "symbolic")]

    def wrong(d):
        only(d)
        d["parts"][0]["book"][0]["coordinate"] = "x + (1 + 1e-6)*m*b*theta/(m + M)"

    out = check_problem(an, load_answers(_lim_key(tmp_path, "2028", wrong)), PROVE)
    assert out[0].status == Status.FAIL


def test_undefined_values_are_never_proved():
    """nan and infinities are no numbers: nothing holding one is proved."""
    for e in (sp.Add(sp.nan, -x, evaluate=False), sp.Mul(sp.zoo, x, evaluate=False) - x):
        assert decide_zero(e).zero is not True


def test_a_float_inside_an_angle_is_never_rationalized():
    """sin(0.1·x) is not sin(x/10): the canonical form refuses the angle, never rounds it."""
    e = sp.Add(sp.sin(sp.Float(0.1) * x), -sp.sin(x / 10), evaluate=False)
    assert decide_zero(e).zero is None


def test_integrations_and_estimates_are_named_as_such():
    """A pass measured by integration (an event time, turning points off a level set, a
    phase flow) or an estimate at the book's numbers says so, not "no proof path": those
    are out of any proof's reach (bench/prove.py counts them apart)."""
    for method in ("measured(3 points, rtol 1e-07)", "measured(1 point, rtol 0.02)",
                   "numeric(3 points, flow DOP853 rtol 1e-12, rtol 1e-08)",
                   "numeric(5 points, measured)"):
        assert proof.unproved_reason(method) == proof.MEASURED, method
    assert proof.unproved_reason("estimate(rtol 0.1)") == proof.ESTIMATE
    assert proof.unproved_reason("numeric(6 points, polynomial roots)") == proof.NO_PATH
    assert proof.unproved_reason("level set(6 points, rtol 1e-10)") == proof.NO_PATH


def test_simplify_is_not_tried_beyond_the_size_any_proof_had():
    """log(ab) = log a + log b for a, b > 0: the canonical forms leave it open (log a free
    generator) and simplify proves it; the same identity times a product of 3000-odd
    operations is refused at once with its reason (no simplify of that size ever proved one
    within the budget)."""
    small = sp.log(a * b) - sp.log(a) - sp.log(b)
    assert decide_zero(small).zero is None
    assert proof.prove_zero(small, _sampler()).ok
    big = sp.Mul(*[sum(sp.Symbol(f"c{i}_{j}") * x**j for j in range(12)) for i in range(130)])
    assert sp.count_ops(big) > proof.MAX_SIMPLIFY_OPS
    assert proof.prove_zero(small * big, _sampler()) == proof.Proof(False, proof.TOO_LARGE)


def test_one_branch_still_found_and_other_roots_screened_out():
    """√(y(x + 1)²) = (x + 1)√y holds for x > −1 only: a root's branch (found exactly, the
    float screen passing it on); √(z + 1)·y = z is no branch of anything: the screen
    (R(r)·R(−r) far from 0 at a point of the variety) says so without the exact product."""
    z, w = sp.Symbol("z"), sp.Symbol("w", positive=True)
    branch = sp.sqrt(x**2 * w + 2 * x * w + w) - (x + 1) * sp.sqrt(w)
    assert decide_zero(branch).why == "a root's branch"
    assert decide_zero(branch + 2 * (x + 1) * sp.sqrt(w)).why == "a root's branch"  # −√ ...
    assert decide_zero(sp.sqrt(z + 1) * w - z).why == "not reduced to 0 (roots)"
    assert decide_zero(branch + EPS * sp.sqrt(w)).why == "not reduced to 0 (roots)"


def test_no_simplify_once_a_canonical_form_refuses(monkeypatch):
    """all_vanish of [log(ab) − log a − log b (open: simplify proves it), √(x²) − x (one
    branch: x may be negative)]: the second refuses in the canonical pass, so the whole
    cannot be proved and simplify is not run on the first; alone, the first is proved."""
    calls = []
    real = sp.simplify
    monkeypatch.setattr(proof.sp, "simplify", lambda e, *k, **kw: calls.append(e) or real(e))
    z = sp.Symbol("z", real=True)
    u, v = sp.symbols("u v", positive=True)  # not met elsewhere: no cached proof
    opened = sp.log(u * v) - sp.log(u) - sp.log(v)
    branch = sp.sqrt(z**2 * a + 2 * z * a + a) - (z + 1) * sp.sqrt(a)
    sampler = Sampler({a: 1.3, u: 0.8, v: 1.7}, [], policy=PROVE)
    out = all_vanish([opened, branch], sampler)
    assert out.ok and out.method != "symbolic" and proof.BRANCH in out.unproved and not calls
    assert all_vanish([opened], sampler).method == "symbolic" and calls


def test_a_rotations_eigenvalues_are_proved_by_eulers_formula(tmp_path):
    """Symon 10-19: a rotation's eigenvalues 1, e^{±iα} with cos α = (tr A − 1)/2 (their
    sum 1 + 2 cos α = tr A, pair products the same, product 1 = det A): with
    e^{iα} = cos α + i sin α the generic statement's canonical form is 0, so symbolic; the
    angle 1e-6 or 1 % off fails (at the instances, before any proof)."""
    problem = load_problem(ROOT / "problems" / "symon" / "10-19.yaml")
    data = yaml.safe_load((ROOT / "answers" / "symon" / "10-19.yaml").read_text())
    data["parts"] = [p for p in data["parts"] if p["quantity"] == "eigenvalues"]
    f = tmp_path / "10-19.yaml"
    f.write_text(yaml.safe_dump(data, sort_keys=False))
    out = check_problem(Analysis(problem), load_answers(f), PROVE)
    assert [(o.status, o.method) for o in out] == [(Status.PASS, "symbolic")] * 2
    for factor in ("(1 + 1/10**6)", "(101/100)"):
        for p in data["parts"]:
            p["book"][1] = f"expi(alpha*{factor})"
        f.write_text(yaml.safe_dump(data, sort_keys=False))
        out = check_problem(Analysis(problem), load_answers(f), PROVE)
        assert [o.status for o in out] == [Status.FAIL] * 2


def test_a_square_factor_of_known_sign_fixes_the_branch():
    """(δ²sin²α + δ²cos²α)^(7/2) = δ⁷ for δ > 0: factored, SymPy takes δ⁷ out and the
    rest's radicand reduces to the number 1, whose root is 1 (exact), so it is proved; with
    δ of unknown sign it is not (|δ|⁷), and 1e-6 off it is never proved."""
    d, s = sp.Symbol("d", positive=True), sp.Symbol("s", real=True)
    inner = d**2 * sp.sin(x) ** 2 + d**2 * sp.cos(x) ** 2
    assert proof.prove_zero(inner ** sp.Rational(7, 2) - d**7, _sampler()).ok
    assert not proof.prove_zero(inner ** sp.Rational(7, 2) - d**7 * (1 + EPS), _sampler()).ok
    unsigned = (s**2 * sp.sin(x) ** 2 + s**2 * sp.cos(x) ** 2) ** sp.Rational(7, 2) - s**7
    assert not proof.prove_zero(unsigned, _sampler()).ok
    assert decide_zero(sp.sqrt(4 * sp.sin(x) ** 2 + 4 * sp.cos(x) ** 2) - 2).zero is True
    assert decide_zero(sp.sqrt(4 * sp.sin(x) ** 2 + 4 * sp.cos(x) ** 2) - 2 - EPS).zero is False
