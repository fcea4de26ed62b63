"""Tensors and bodies: the tensor expression parser, bodies made of parts (checked by hand
and against the cross-check's integration), problems without a system (load, validate,
check, store, list), and the tensor quantities — each passes what is right and fails what
is wrong."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest
import sympy as sp
from click.testing import CliRunner

from mechbook.app.cli import main
from mechbook.crosscheck.assembly import composite_inertia
from mechbook.engine.analysis import Analysis
from mechbook.errors import ExpressionError, SpecError
from mechbook.model.declared import declared
from mechbook.model.problem import load_problem
from mechbook.model.tensorexpr import parse_tensor, parse_tensor_equation
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

a, b, c = sp.symbols("a b c", real=True)


# ---- the tensor expression parser ---------------------------------------------------------
def test_vectors_tensors_and_their_products():
    A = parse_tensor("[5, -3, 2]")
    B = parse_tensor("[0, 5, 10]")
    names = {"A": A, "B": B, "x": a}
    T = parse_tensor("dyad(A, B) + dyad(B, A)", names)
    assert T == sp.Matrix([[0, 25, 50], [25, -30, -20], [50, -20, 40]])
    assert parse_tensor("dot(A, B)", names) == 5
    assert parse_tensor("cross(A, B)", names) == sp.Matrix([-40, -50, 25])
    names["T"] = T
    assert parse_tensor("T*A", names) == T * sp.Matrix(A)
    assert parse_tensor("trace(T)", names) == 10 and parse_tensor("det(T)", names) == 0
    assert parse_tensor("second_invariant(T)", names) == -4725
    assert parse_tensor("x*unit()", names) == a * sp.eye(3)
    assert parse_tensor("entry(T, 1, 2) + entry(A, 3)", names) == 27
    R = parse_tensor("rotation([0, 0, 1], x)", names)
    assert sp.simplify(R - sp.Matrix([[sp.cos(a), -sp.sin(a), 0], [sp.sin(a), sp.cos(a), 0],
                                      [0, 0, 1]])) == sp.zeros(3, 3)
    w = sp.Matrix([a, b, c])
    names["w"] = sp.ImmutableMatrix(w)
    C = sp.Matrix(sp.symbols("c1:4"))
    names["C"] = sp.ImmutableMatrix(C)
    assert sp.expand(parse_tensor("skew(w)*C", names) - w.cross(C)) == sp.zeros(3, 1)
    assert parse_tensor("T**-1", {"T": sp.ImmutableMatrix(sp.diag(1, 2, 4))}) == \
        sp.diag(1, sp.Rational(1, 2), sp.Rational(1, 4))


@pytest.mark.parametrize("text, why", [
    ("T + 1", "cannot combine"),
    ("A*A", "cannot combine"),
    ("sin(T)", "scalars only"),
    ("2**T", "integer exponent"),
    ("T**(1/2)", "integer exponent"),
    ("[1, 2]", "a list is a vector"),
    ("entry(T, 4, 1)", "1, 2 or 3"),
    ("dot(T, 3)", "dot of a tensor and a scalar"),
    ("mass(T)", "no body"),
    ("rotation([0, 0, 0], 1)", "zero vector"),
    ("T.T", "not allowed"),
    ("__import__('os')", "unknown function"),
])
def test_wrong_tensor_expressions_are_refused(text, why):
    names = {"T": sp.ImmutableMatrix(sp.eye(3)), "A": sp.ImmutableMatrix([1, 2, 3])}
    with pytest.raises(ExpressionError, match=why):
        parse_tensor(text, names)


def test_equations_of_tensors():
    T = sp.ImmutableMatrix(sp.diag(1, 2, 3))
    lhs, rhs = parse_tensor_equation("T*T - T*T = 0", {"T": T})
    assert lhs == sp.zeros(3, 3) and rhs == sp.zeros(3, 3)
    with pytest.raises(ExpressionError, match="differ in kind"):
        parse_tensor_equation("trace(T) = T", {"T": T})


# ---- problem trees ------------------------------------------------------------------------
def tree(tmp_path: Path, num: str, problem: str, answers: str | None = None) -> Path:
    (tmp_path / "problems" / "symon").mkdir(parents=True, exist_ok=True)
    (tmp_path / "answers" / "symon").mkdir(parents=True, exist_ok=True)
    head = f"id: symon-{num}\nsource: a test\ntitle: a test problem\n"
    path = tmp_path / "problems" / "symon" / f"{num}.yaml"
    path.write_text(head + textwrap.dedent(problem), encoding="utf-8")
    if answers is not None:
        key = f"problem: symon-{num}\nsource: a test\n" + textwrap.dedent(answers)
        (tmp_path / "answers" / "symon" / f"{num}.yaml").write_text(key, encoding="utf-8")
    return path


BODY = """\
parameters:
  m: {value: 0.7}
  M: {value: 1.9}
  a: {value: 0.8}
  h: {value: 1.3}
  th: {positive: false, value: 0.4}
vectors:
  k: [0, 0, 1]
bodies:
  thing:
    parts:
      - {shape: point, mass: m, position: [a, 0, 0]}
      - {shape: rod, mass: m, from: [0, 0, 0], to: [0, a, a]}
      - {shape: disk, mass: M, radius: a, position: [0, 0, h], axis: [1, 1, 0]}
      - {shape: cone, mass: M, radius: a, height: h, apex: [a, a, 0], axis: [0, 1, 2]}
      - {shape: block, mass: m, sides: [a, h, 1], position: [1, 2, 3],
         rotation: {axis: [1, 2, 2], angle: th}}
      - {shape: solid_ellipsoid, mass: M, semi_axes: [a, h, 2], position: [0, -1, 0],
         rotation: {axis: k, angle: th}}
  pair:
    parts:
      - {shape: point, mass: m, position: [a, 0, 0]}
      - {shape: point, mass: m, position: [-a, 0, 0]}
"""


def test_a_body_of_parts_by_hand_and_by_integration(tmp_path):
    problem = load_problem(tree(tmp_path, "10-90", BODY))
    bodies = declared(problem).bodies
    m, a_ = problem.parameters["m"].symbol, problem.parameters["a"].symbol
    pair = bodies["pair"]
    assert pair.mass == 2 * m
    assert pair.center_of_mass == sp.zeros(3, 1)
    assert sp.simplify(pair.inertia() - 2 * m * a_**2 * sp.diag(0, 1, 1)) == sp.zeros(3, 3)
    # moment about the line through (0, 0, a) along y: each mass is sqrt(2) a from it
    assert sp.simplify(pair.moment(sp.Matrix([0, 0, a_]), sp.Matrix([0, 1, 0]))
                       - 4 * m * a_**2) == 0
    # every part kind, placed and turned: the engine's table, rotations and parallel axes
    # against the cross-check's integration, quaternions and Gram-Schmidt frames
    thing = bodies["thing"]
    mass, com, inertia = composite_inertia(problem, "thing")
    values = {k: sp.Rational(str(v)) for k, v in problem.values().items()}
    for ours, theirs in ((thing.mass, mass), *zip(thing.center_of_mass, com, strict=True),
                         *zip(thing.inertia(), inertia, strict=True)):
        assert abs(complex(sp.N((ours - theirs).subs(values), 30))) < 1e-20


def test_a_wrong_table_entry_would_be_caught(tmp_path, monkeypatch):
    import mechbook.model.bodies.composite as composite

    problem = load_problem(tree(tmp_path, "10-90", BODY))
    right = composite.shape_inertia

    def wrong(shape, m, dims):
        out = right(shape, m, dims)
        return out * sp.Rational(5, 4) if shape == "cone" else out

    monkeypatch.setattr(composite, "shape_inertia", wrong)
    thing = declared(problem).bodies["thing"]
    _, _, inertia = composite_inertia(problem, "thing")
    values = {k: sp.Rational(str(v)) for k, v in problem.values().items()}
    assert max(abs(complex(sp.N((x - y).subs(values)))) for x, y in
               zip(thing.inertia(), inertia, strict=True)) > 1e-3


@pytest.mark.parametrize("part, why", [
    ("{shape: block, mass: m, sides: [a, a, a], position: [0, 0, 0], axis: [0, 0, 1]}",
     "not symmetric about an axis"),
    ("{shape: disk, mass: m, radius: a, from: [0, 0, 0], to: [1, 0, 0]}", "place a rod"),
    ("{shape: disk, mass: m, radius: a, apex: [0, 0, 0]}", "only a cone has an apex"),
    ("{shape: disk, mass: m, radius: a}", "place the part"),
    ("{shape: rod, mass: m, from: [0, 0, 0], to: [0, 0, 0]}", "must differ"),
    ("{shape: block, mass: m, sides: [a, a], position: [0, 0, 0]}", "three sides"),
    ("{shape: cone, mass: m, radius: a, position: [0, 0, 0]}", "needs 'height'"),
    ("{shape: disk, mass: m, radius: a, position: [0, 0, 0], rotation: [[1, 1, 0], [0, 1, 0], "
     "[0, 0, 1]]}", "proper orthogonal"),
])
def test_bad_parts_are_refused_with_their_line(tmp_path, part, why):
    text = f"parameters:\n  m: {{}}\n  a: {{}}\nbodies:\n  b1:\n    parts:\n      - {part}\n"
    path = tree(tmp_path, "10-91", text)
    with pytest.raises(SpecError, match=why) as err:
        declared(load_problem(path))
    assert ":10:" in str(err.value)  # the part's line


def test_names_must_not_clash(tmp_path):
    path = tree(tmp_path, "10-92", "parameters:\n  A: {}\nvectors:\n  A: [1, 2, 3]\n")
    with pytest.raises(SpecError, match="already taken"):
        declared(load_problem(path))


def test_a_system_key_without_coordinates_is_still_an_error(tmp_path):
    path = tree(tmp_path, "10-93", "parameters:\n  m: {}\nparticles:\n  p: {mass: m, "
                "position: [0, 0]}\n")
    with pytest.raises(SpecError, match="'coordinates' is required"):
        load_problem(path)


# ---- a problem without a system -------------------------------------------------------------
KEY = """\
parts:
  - part: frame
    cite: test
    quantity: components
    tensor: inertia(pair)
    book: [[0, 0, 0], [0, "2*m*a**2", 0], [0, 0, "2*m*a**2"]]
  - part: det
    cite: test
    quantity: identity
    for_all: {R: orthogonal, T: tensor}
    book: "det(R*T*transpose(R)) = det(T)"
"""


@pytest.mark.slow
def test_a_problem_without_a_system_loads_checks_stores_and_is_listed(tmp_path):
    tree(tmp_path, "10-94", BODY, KEY)
    problem = load_problem(tmp_path / "problems" / "symon" / "10-94.yaml")
    assert problem.systems == {}
    analysis = Analysis(problem)
    with pytest.raises(KeyError):
        analysis.system()
    runner = CliRunner()
    out = runner.invoke(main, ["--root", str(tmp_path), "list"])
    assert "symon-10-94" in out.output and "2 parts" in out.output
    out = runner.invoke(main, ["--root", str(tmp_path), "validate",
                               str(tmp_path / "problems" / "symon" / "10-94.yaml"),
                               str(tmp_path / "answers" / "symon" / "10-94.yaml")])
    assert out.exit_code == 0, out.output
    assert "0 system(s)" in out.output and "2 body(ies)" in out.output
    out = runner.invoke(main, ["--root", str(tmp_path), "check", "symon-10-94", "--serial",
                               "--fresh"])
    assert out.exit_code == 0, out.output
    assert "2 pass" in out.output
    assert "inertia:pair" not in out.output or "fail" not in out.output
    out = runner.invoke(main, ["--root", str(tmp_path), "show", "symon-10-94"])
    assert "pair/inertia" in out.output and "n.a." in out.output


def test_a_system_quantity_in_a_problem_without_a_system_is_an_error(tmp_path):
    tree(tmp_path, "10-95", BODY, """\
parts:
  - part: wrong
    cite: test
    quantity: expression
    of: kinetic
    book: "m"
""")
    problem = load_problem(tmp_path / "problems" / "symon" / "10-95.yaml")
    key = load_answers(tmp_path / "answers" / "symon" / "10-95.yaml")
    out = check_problem(Analysis(problem), key)[0]
    assert out.status == "error" and "needs a system" in out.detail


# ---- the quantities pass what is right and fail what is wrong -------------------------------
def outcome(tmp_path: Path, part: str, problem: str = BODY) -> tuple[str, str, str]:
    num = f"10-{96 + len(list(tmp_path.glob('problems/symon/*.yaml')))}"
    tree(tmp_path, num, problem, "parts:\n" + textwrap.indent(textwrap.dedent(part), "  "))
    analysis = Analysis(load_problem(tmp_path / "problems" / "symon" / f"{num}.yaml"))
    out = check_problem(analysis, load_answers(tmp_path / "answers" / "symon" / f"{num}.yaml"))
    return out[0].status, out[0].method, out[0].detail


IDENTITIES = [
    ("det(Q*T*transpose(Q)) = det(T)", "{Q: orthogonal, T: tensor}", "pass"),
    ("det(Q*T*transpose(Q)) = 2*det(T)", "{Q: orthogonal, T: tensor}", "fail"),
    ("Q*cross(A, B) = cross(Q*A, Q*B)", "{Q: rotation, A: vector, B: vector}", "pass"),
    # true for rotations, false for reflections: `orthogonal` checks both
    ("Q*cross(A, B) = cross(Q*A, Q*B)", "{Q: orthogonal, A: vector, B: vector}", "fail"),
    ("trace(S*T) = trace(T*S)", "{S: tensor, T: tensor}", "pass"),
    ("S*T = T*S", "{S: tensor, T: tensor}", "fail"),
    ("S*T = T*S", "{S: diagonal, T: diagonal}", "pass"),
    ("transpose(W) = -W", "{W: antisymmetric}", "pass"),
    ("dot(n, n) = 1", "{n: unit_vector}", "pass"),
    ("cos(x)**2 + sin(x)**2 = 1", "{x: angle}", "pass"),
    ("cos(x)**2 - sin(x)**2 = 1", "{x: angle}", "fail"),
]


@pytest.mark.parametrize("statement, for_all, status", IDENTITIES)
def test_identities(tmp_path, statement, for_all, status):
    got, method, detail = outcome(tmp_path, f"""\
        - part: p
          cite: test
          quantity: identity
          for_all: {for_all}
          book: "{statement}"
        """)
    assert got == status, detail
    if "cos(x)" in statement and status == "pass":
        assert method.startswith("numeric(12 instances")  # transcendental: 30 digits
    elif status == "pass":
        assert method == "symbolic" or method.startswith("exact(12 instances")


@pytest.mark.parametrize("book, status", [
    ('[0, "2*m*a**2", "2*m*a**2"]', "pass"),
    ('["2*m*a**2", 0, "2*m*a**2"]', "pass"),  # any order
    ('[0, "2*m*a**2", "m*a**2"]', "fail"),
    ('[0, 0, "4*m*a**2"]', "fail"),  # same sum, wrong multiset
])
def test_eigenvalues(tmp_path, book, status):
    got, _, detail = outcome(tmp_path, f"""\
        - part: p
          cite: test
          quantity: eigenvalues
          tensor: inertia(pair)
          book: {book}
        """)
    assert got == status, detail


def test_complex_eigenvalues_of_rotations(tmp_path):
    part = """\
        - part: p
          cite: test
          quantity: eigenvalues
          for_all: {{A: rotation}}
          define: {{alpha: "acos((trace(A) - 1)/2)"}}
          tensor: A
          book: [{first}, "expi(alpha)", "expi(-alpha)"]
        """
    assert outcome(tmp_path, part.format(first=1))[0] == "pass"
    assert outcome(tmp_path, part.format(first=-1))[0] == "fail"


@pytest.mark.parametrize("entries, status, why", [
    ('[{value: 0, axis: [1, 0, 0]}, {value: "2*m*a**2", plane: [1, 0, 0]}]', "pass", ""),
    ('[{value: 0, axis: [-3, 0, 0]}]', "pass", ""),  # up to scale and sign
    ('[{value: 0, axis: [1, 1, 0]}]', "fail", ""),  # not an eigenvector
    ('[{value: "2*m*a**2", axis: [1, 0, 0]}]', "fail", ""),  # wrong value
    ('[{value: 0, axis: [0, 0, 0]}]', "fail", "direction vanishes"),
    ('[{value: "2*m*a**2", axis: [0, 1, 0]}, {value: "2*m*a**2", axis: [0, 2, 0]}, '
     '{value: 0, axis: [1, 0, 0]}]', "fail", "determinant of the three axes vanishes"),
    ('[{value: "2*m*a**2", plane: [0, 1, 0]}]', "fail", ""),
])
def test_principal_axes(tmp_path, entries, status, why):
    got, _, detail = outcome(tmp_path, f"""\
        - part: p
          cite: test
          quantity: principal_axes
          tensor: inertia(pair)
          book: {entries}
        """)
    assert got == status, detail
    assert why in detail


def test_components_in_other_axes_and_their_checks(tmp_path):
    part = """\
        - part: p
          cite: test
          quantity: components
          tensor: inertia(pair)
          axes: {axes}
          book: {book}
        """
    turned = '[[0, 1, 0], [1, 0, 0], [0, 0, -1]]'
    assert outcome(tmp_path, part.format(axes=turned, book='{"11": "2*m*a**2", "22": 0}'))[0] \
        == "pass"
    assert outcome(tmp_path, part.format(axes=turned, book='{"11": 0}'))[0] == "fail"
    got = outcome(tmp_path, part.format(axes='[[1, 1, 0], [0, 1, 0], [0, 0, 1]]',
                                        book='{"11": 0}'))
    assert got[0] == "error" and "not orthonormal" in got[2]


@pytest.mark.parametrize("book, status", [
    ('"2*m*a**2*(y**2 + z**2) = 1"', "pass"),
    ('"y**2 + z**2 = 1/(2*m*a**2)"', "pass"),  # any multiple
    ('"2*m*a**2*(y**2 + 2*z**2) = 1"', "fail"),
    ('"2*m*a**2*(y**2 + z**2) = 0"', "fail"),  # no constant: not an ellipsoid of inertia
])
def test_inertia_ellipsoid(tmp_path, book, status):
    got, _, detail = outcome(tmp_path, f"""\
        - part: p
          cite: test
          quantity: inertia_ellipsoid
          tensor: inertia(pair)
          book: {book}
        """)
    assert got == status, detail


@pytest.mark.parametrize("book, status", [("[[2, 0, 0], [0, 2, 0], [0, 0, 2]]", "pass"),
                                          ("[[2, 0, 0], [0, 2, 0], [0, 0, 3]]", "fail")])
def test_solves(tmp_path, book, status):
    got, _, detail = outcome(tmp_path, f"""\
        - part: p
          cite: test
          quantity: solves
          unknown: S
          equations: ["S*S = 4*unit()", "trace(S) = 6"]
          book: {book}
        """)
    assert got == status, detail


# ---- a composite body in a system ------------------------------------------------------------
SPINNING = BODY + """\
coordinates:
  phi: {}
rigid_bodies:
  top:
    position: [0, 0, 0]
    inertia: {body: thing}
    euler_angles: [phi, 0.3, 0]
"""


def test_a_composite_body_in_a_system(tmp_path):
    from mechbook.crosscheck.newton import newton_crosscheck
    from mechbook.model.system import system_of

    problem = load_problem(tree(tmp_path, "10-97", SPINNING))
    sys = system_of(problem)
    thing = declared(problem).bodies["thing"]
    assert sys.masses["top"] == thing.mass
    phidot = sys.qd[0]
    # rotation about the space z axis at rate phidot: T = phidot² k·I_G·k / 2 in body axes
    w = sp.Matrix([0, sp.sin(sp.Rational(3, 10)), sp.cos(sp.Rational(3, 10))]) * phidot
    expected = (w.T * thing.inertia() * w)[0, 0] / 2
    values = problem.values() | {phidot: sp.Rational(7, 10)}
    assert abs(complex(sp.N((sys.kinetic - expected).subs(values), 30))) < 1e-20
    x = newton_crosscheck(Analysis(problem))
    assert x.status == "pass", x.detail


def test_a_composite_body_with_a_wrong_mass_is_refused(tmp_path):
    from mechbook.model.system import system_of

    text = SPINNING.replace("    inertia: {body: thing}", "    mass: M\n    inertia: {body: thing}")
    with pytest.raises(SpecError, match="mass differs"):
        system_of(load_problem(tree(tmp_path, "10-98", text)))


def test_vectors_and_tensors_are_operands_and_comparisons_are_not():
    """The parser refuses a comparison as an operand, `(a < b)**2`; a vector or a tensor is
    an operand like any number (the merge of the input limits once refused `-l*u/2`)."""
    import pytest as _pytest

    from mechbook.errors import ExpressionError
    from mechbook.model.tensorexpr import parse_tensor

    l_ = sp.Symbol("l", positive=True)
    u = sp.Matrix([1, 2, 3])
    assert sp.Matrix(parse_tensor("-l*u/2", {"l": l_, "u": u})) == -l_ * u / 2
    with _pytest.raises(ExpressionError, match="comparison"):
        parse_tensor("(l < 1)*u", {"l": l_, "u": u})


AXES_KEY = """\
parts:
  - part: axes
    cite: test
    quantity: principal_axes
    tensor: "dyad(k, k)"
    book:
      - {value: 1, axis: [0, 0, 1]}
      - {value: 0, axis: [1, 0, 0]}
      - {value: 0, axis: [0, 1, 0]}
  - part: unknown
    cite: test
    quantity: principal_axes
    tensor: "dyad(k, q)"
    book:
      - {value: 1, axis: [0, 0, 1]}
"""


def test_a_tensor_part_is_validated_as_it_is_checked(tmp_path, monkeypatch):
    """`mechbook validate` (and the check's validation) builds a tensor part's statement as
    the check's decide does, without SymPy's intermediate cancel of matrix products
    (dotprodsimp: seconds for a 3×3 determinant of symbolic axes, Symon 10-26); a part
    that names an unknown object is still refused at its line, the good one is not."""
    import sympy.matrices.utilities as mu

    from mechbook.verify.quantities import tensors
    from mechbook.verify.wellformed import validate_key

    tree(tmp_path, "10-96", BODY, AXES_KEY)
    problem = load_problem(tmp_path / "problems" / "symon" / "10-96.yaml")
    key = load_answers(tmp_path / "answers" / "symon" / "10-96.yaml")
    states = []
    parse = tensors.tparse

    def recording(*args):
        states.append(mu._dotprodsimp_state.state)
        return parse(*args)

    monkeypatch.setattr(tensors, "tparse", recording)
    faults = validate_key(Analysis(problem), key)
    assert set(faults) == {"unknown"} and "q" in str(faults["unknown"])
    assert states and set(states) == {False}
    states.clear()
    good = [p for p in key.parts if p.name == "axes"]
    key.parts[:] = good
    outcomes = check_problem(Analysis(problem), key)
    assert [o.status.value for o in outcomes] == ["pass"]
    assert states and set(states) == {False}
