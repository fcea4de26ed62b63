"""The safe expression parser: what it accepts, exactly, and what it refuses, safely."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
import sympy as sp

from mechbook.errors import ExpressionError
from mechbook.model.expr import parse, parse_equation

x, y = sp.symbols("x y", real=True)
m = sp.Symbol("m", positive=True)
NAMES = {"x": x, "y": y, "m": m}
PWNED = Path("/tmp/pwned")


# ---- accepted input -------------------------------------------------------------------------
@pytest.mark.parametrize("text, expected", [
    ("1 + 2*3", sp.Integer(7)),
    ("7/2", sp.Rational(7, 2)),
    ("2**10", sp.Integer(1024)),
    ("-x**2", -x**2),
    ("(x + y)**2", (x + y) ** 2),
    ("x**-2", x**-2),
    ("x**(1/2)", sp.sqrt(x)),
    ("+x - -y", x + y),
    ("m*x/y", m * x / y),
    ("sin(x)**2 + cos(x)**2", sp.sin(x) ** 2 + sp.cos(x) ** 2),
    ("sqrt(m)", sp.sqrt(m)),
    ("atan2(y, x)", sp.atan2(y, x)),
    ("tan(x) + cot(x) + sec(x) + csc(x)", sp.tan(x) + sp.cot(x) + sp.sec(x) + sp.csc(x)),
    ("asin(x) + acos(x) + atan(x)", sp.asin(x) + sp.acos(x) + sp.atan(x)),
    ("sinh(x) + cosh(x) + tanh(x)", sp.sinh(x) + sp.cosh(x) + sp.tanh(x)),
    ("exp(x) + log(m) + log(m, 2)", sp.exp(x) + sp.log(m) + sp.log(m, 2)),
    ("Abs(x) + abs(y) + sign(x) + cbrt(m)", sp.Abs(x) + sp.Abs(y) + sp.sign(x) + sp.cbrt(m)),
    ("2*pi", 2 * sp.pi),
    ("cos(pi)", sp.Integer(-1)),
    ("  x  ", x),
    ("1_000", sp.Integer(1000)),
])
def test_accepted(text, expected):
    got = parse(text, NAMES)
    assert sp.simplify(got - expected) == 0
    assert isinstance(got, sp.Basic)


@pytest.mark.parametrize("text, expected", [
    ("0.1", sp.Rational(1, 10)),
    ("0.5*x", x / 2),
    ("1e-3", sp.Rational(1, 1000)),
    ("2.5e3", sp.Integer(2500)),
    ("9.81", sp.Rational(981, 100)),
    ("1.25", sp.Rational(5, 4)),
])
def test_decimal_literals_are_exact_rationals(text, expected):
    got = parse(text, NAMES)
    assert got == expected  # structurally equal: no Float anywhere
    assert not got.atoms(sp.Float)


def test_numbers_not_strings_are_accepted():
    assert parse(2) == 2
    assert parse(0.1) == sp.Rational(1, 10)
    assert not parse(0.1).atoms(sp.Float)


def test_long_decimal_literal_is_read_exactly():
    assert parse("1.0000000000000001") == sp.Rational("1.0000000000000001")


def test_declared_names_map_to_given_objects():
    q = sp.Symbol("q", real=True)
    assert parse("q", {"q": q}) is q
    # a name may stand for an expression (a driven coordinate, a defined variable)
    assert parse("alpha + 1", {"alpha": x - sp.pi}) == x - sp.pi + 1


def test_declared_name_shadows_nothing_dangerous():
    # names are looked up only in the mapping: 'x' without it is unknown
    with pytest.raises(ExpressionError, match="unknown name 'x'"):
        parse("x")


# ---- equations and relations ----------------------------------------------------------------
def test_parse_equation():
    assert parse_equation("x = y", NAMES) == x - y
    assert parse_equation("x**2 + y", NAMES) == x**2 + y
    assert parse_equation("m*x = -y", NAMES) == m * x + y
    assert parse_equation(3) == 3


def test_parse_equation_rejects_two_equals():
    with pytest.raises(ExpressionError, match="more than one '='"):
        parse_equation("x = y = 1", NAMES)


@pytest.mark.parametrize("text", ["x = ", "= y", "x == y", "x <= y"])
def test_parse_equation_rejects_malformed(text):
    with pytest.raises(ExpressionError):
        parse_equation(text, NAMES)


@pytest.mark.parametrize("text", ["x < y", "x <= y", "x > 2*y", "x >= 1", "x < y < 2",
                                  "x < 1 and y > 2", "x < 1 or y > 2"])
def test_relations_only_with_allow_relations(text):
    with pytest.raises(ExpressionError, match="not allowed here"):
        parse(text, NAMES)
    rel = parse(text, NAMES, allow_relations=True)
    assert isinstance(rel, sp.logic.boolalg.Boolean)


def test_relation_values():
    rel = parse("x < y", NAMES, allow_relations=True)
    assert rel.subs({x: 1, y: 2}) == sp.true
    assert rel.subs({x: 3, y: 2}) == sp.false
    chain = parse("0 < x < y", NAMES, allow_relations=True)
    assert chain.subs({x: 1, y: 2}) == sp.true
    assert chain.subs({x: 3, y: 2}) == sp.false
    assert chain.subs({x: -1, y: 2}) == sp.false


# ---- hostile input --------------------------------------------------------------------------
def _rejected(text, match=None, names=NAMES, **kw) -> ExpressionError:
    with pytest.raises(ExpressionError, match=match) as info:
        parse(text, names, **kw)
    message = str(info.value)
    assert message  # never an empty message
    return info.value


def test_import_os_system_does_not_run(tmp_path):
    marker = tmp_path / "pwned"
    pre_existing = PWNED.exists()
    for target in (PWNED, marker):
        err = _rejected(f"__import__('os').system('touch {target}')")
        assert "whitelisted functions" in str(err) or "not allowed" in str(err)
        assert not marker.exists()
    if not pre_existing:
        assert not PWNED.exists()


def test_import_rejected_with_and_without_relations():
    for rel in (False, True):
        _rejected("__import__('os')", allow_relations=rel)


@pytest.mark.parametrize("text, match", [
    ("x.__class__", "Attribute is not allowed"),
    ("x.real", "Attribute is not allowed"),
    ("().__class__.__bases__[0].__subclasses__()", "allowed"),
    ("__x", "leading underscore"),
    ("__builtins__", "leading underscore"),
    ("_", "leading underscore"),
    ("lambda: 1", "Lambda is not allowed"),
    ("(lambda q: q)(x)", "only calls of whitelisted functions"),
    ("[q for q in (1, 2)]", "ListComp is not allowed"),
    ("sum(q for q in (1, 2))", "not allowed|unknown function"),
    ("{q: q for q in (1,)}", "DictComp is not allowed"),
    ("x[0]", "Subscript is not allowed"),
    ("sin(x=1)", "keyword arguments"),
    ("foo(x)", "unknown function 'foo'"),
    ("eval('1')", "unknown function 'eval'"),
    ("getattr(x, 'real')", "unknown function 'getattr'"),
    ("open('/etc/passwd')", "unknown function 'open'"),
    ("z", "unknown name 'z'"),
    ("os", "unknown name 'os'"),
    ("'abc'", "not a number"),
    ("b'abc'", "not a number"),
    ("True", "not a number"),
    ("None", "not a number"),
    ("1j", "not a number"),
    ("...", "not a number"),
    ("f'{x}'", "JoinedStr is not allowed"),
    ("(y := 2)", "NamedExpr is not allowed"),
    ("x if y else 1", "IfExp is not allowed"),
    ("x @ y", "MatMult is not allowed"),
    ("x // y", "FloorDiv is not allowed"),
    ("x % y", "Mod is not allowed"),
    ("x << y", "LShift is not allowed"),
    ("~x", "Invert is not allowed"),
    ("not x", "Not is not allowed"),
    ("(1, 2)", "Tuple is not allowed"),
    ("[x]", "List is not allowed"),
    ("{x}", "Set is not allowed"),
    ("{1: 2}", "Dict is not allowed"),
    ("sin(*[x])", "not allowed"),
    ("sin", "without a call"),
    ("sin()", "takes 1 argument"),
    ("sin(x, y)", "takes 1 argument"),
    ("atan2(x)", "takes 2 argument"),
    ("x.__class__.__mro__", "not allowed"),
])
def test_hostile_or_unsupported_syntax(text, match):
    err = _rejected(text, match)
    assert text in str(err) or "expression" in str(err)


@pytest.mark.parametrize("text", ["2**10**9", "x**1000000000", "10**100", "x**-1000",
                                  "2**(10**9)", "x**(2**100)", "9**9**9", "sqrt(x)**1000",
                                  "x**65", "x**(64 + 1)", "x**(0.5*200)"])
def test_too_large_exponent(text):
    _rejected(text, "too large")


def test_exponent_at_limit_is_fine():
    assert parse("x**64", NAMES) == x**64
    assert parse("x**-64", NAMES) == x**-64


def test_too_large_integer_literal():
    _rejected("1" * 40, "too large")


@pytest.mark.parametrize("text", [
    "(" * 5000 + "x" + ")" * 5000,
    "(" * 61 + "x" + ")" * 61,
    "sin(" * 3000 + "x" + ")" * 3000,
    "[" * 5000,
    "-" * 5000 + "x",
    "-" * 19_990 + "x",
    "x**" * 3000 + "x",
    "+".join(["x"] * 5000),
])
def test_deep_nesting_is_rejected_not_crashing(text):
    _rejected(text)


def test_deep_nesting_in_fresh_interpreter():
    """Deep nesting must not crash (segfault / RecursionError escape) the interpreter."""
    code = textwrap.dedent("""
        from mechbook.model.expr import parse
        from mechbook.errors import ExpressionError
        for text in ['(' * 5000 + 'x' + ')' * 5000, '-' * 19000 + 'x', 'x**' * 5000 + 'x',
                     '(' * 100000]:
            try:
                parse(text, {})
            except ExpressionError:
                pass
            else:
                raise SystemExit('accepted ' + text[:20])
        print('survived')
    """)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "survived" in proc.stdout


def test_nesting_within_limit_is_accepted():
    assert parse("(" * 20 + "x" + ")" * 20, NAMES) == x


def test_flat_sum_of_many_terms_is_not_nesting():
    text = " + ".join(f"{i}*x**{i % 5}" for i in range(1, 81))  # 80 terms, ~600 characters
    expected = sum(sp.Integer(i) * x ** (i % 5) for i in range(1, 81))
    assert sp.expand(parse(text, NAMES) - expected) == 0


def test_extremely_long_input():
    _rejected("x+" * 200_000 + "x", "longer than")
    _rejected("x" * 1_000_000, "longer than")


@pytest.mark.parametrize("text", ["", "   ", "\n\t"])
def test_empty_input(text):
    _rejected(text, "empty")


@pytest.mark.parametrize("text", ["x +", "x y", "(x", "x)", "*x", "sin(x", "1 +* 2", "x\n+y",
                                  "x = 1", "x; y", "x; import os", "import os",
                                  "x\nimport os", "del x", "x += 1", "pass", "def f(): pass"])
def test_syntax_errors_and_statements(text):
    err = _rejected(text)
    assert "syntax error" in str(err) or "not allowed" in str(err)


def test_non_string_input():
    for bad in (True, None, [1], {"a": 1}, object()):
        with pytest.raises(ExpressionError, match="expected an expression"):
            parse(bad)


def test_error_message_names_position():
    err = _rejected("x + foo(y)")
    assert "column 5" in str(err)
    assert err.text == "x + foo(y)"


def test_overflowing_float_literal():
    _rejected("1e400")
    _rejected("m*1e400")


# Power towers hidden behind a numeric factor, (2*x)**64, used to escape the size limits.


def _tower_rejected_quickly(text: str, seconds: float = 5) -> None:
    code = textwrap.dedent(f"""
        import resource
        resource.setrlimit(resource.RLIMIT_AS, (1_500_000_000, 1_500_000_000))
        import sympy as sp
        from mechbook.model.expr import parse
        from mechbook.errors import ExpressionError
        try:
            parse({text!r}, {{'x': sp.Symbol('x')}})
        except ExpressionError:
            print('rejected')
    """)
    try:
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                              timeout=seconds, env={**os.environ, "PYTHONHASHSEED": "0"})
    except subprocess.TimeoutExpired:
        pytest.fail(f"parsing {text!r} ran past {seconds} s")
    assert "rejected" in proc.stdout, proc.stderr[-500:]


def test_power_tower_is_bounded():
    _tower_rejected_quickly("(((((2**64)**64)**64)**64)**64)**64")


@pytest.mark.parametrize("text", ["((x**64)**64)**64", "((2**64)**64)**64",
                                  "((2**0.5*2**64)**64)**64"])
def test_small_power_towers_rejected(text):
    _rejected(text, "too large")


def test_power_tower_with_symbol_factor_is_bounded():
    _tower_rejected_quickly("((((((2*x)**64)**64)**64)**64)**64)**64")


def test_power_tower_with_symbol_factor_digit_limit():
    # the coefficient 2**262144 has 78,914 digits, far over MAX_DIGITS
    _rejected("(((2*x)**64)**64)**64", "too large")
