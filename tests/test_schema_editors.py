"""The shipped JSON Schemas are accepted by the validators editors and CI tools use.

Editors' JSON language services (VS Code's, the YAML language server) and JavaScript
validators compile a schema's `pattern`s as ECMA-262 regular expressions with the "u" flag;
`check-jsonschema` at its defaults does too (its "default" regex variant). A Python-only
construct (`\\Z`) makes the schema itself invalid there. Each schema is compiled by ajv
(.ci/ajv, from npm) and by check-jsonschema, then every committed problem, answer key and
books.yaml is validated against its schema by both, and a few wrong files must be flagged
by both.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from mechbook.app.authoring import editor
from mechbook.model.yamlio import load

ROOT = Path(__file__).resolve().parents[1]
AJV = ROOT / ".ci" / "ajv"

PROBLEMS = sorted((ROOT / "problems").rglob("*.yaml"))
ANSWERS = sorted((ROOT / "answers").rglob("*.yaml"))
BOOKS = [ROOT / "books.yaml"]

STARTER = ROOT / "mechbook" / "app" / "authoring" / "starter"
PROBLEM = (STARTER / "problem.yaml").read_text(encoding="utf-8")  # a valid problem
ANSWERS_TEXT = (STARTER / "answers.yaml").read_text(encoding="utf-8")
# each wrong file: (schema, text, what is wrong); both validators must flag each one
WRONG = [
    ("problem", PROBLEM.replace("mybook-1.1", "mybook-1..1"), "an id with '..'"),
    ("problem", PROBLEM.replace("mybook-1.1", "Mybook-1"), "an upper-case book"),
    ("problem", PROBLEM.replace("mybook-1.1", "mybook-" + "1" * 81), "an id too long"),
    ("problem", PROBLEM.replace("id: mybook-1.1", 'id: "mybook-1.1\\n"'),
     "an id with a final newline"),
    ("problem", PROBLEM.replace("coordinates:", "coordinate:"), "a misspelt key"),
    ("problem", PROBLEM.replace("mass: m,", "mass: [m],"), "a list for an expression"),
    ("problem", PROBLEM.replace("id: mybook-1.1\n", ""), "no id"),
    ("answers", ANSWERS_TEXT.replace("quantity: lagrangian", "quantity: lagrangean"),
     "an unknown quantity"),
    ("answers", ANSWERS_TEXT.replace("about:", "abut:"), "a misspelt key of a part"),
    ("books", "books: [{id: 9x}]\n", "a book id starting with a digit"),
]
GOOD_IDS = ["mybook-2.1", "lim-2031", "symon-text-9-7-rotating-hoop", "a-" + "x" * 80]


def test_the_id_pattern_is_ecma262():
    """No Python-only escapes; and the id grammar is the same as Python's own."""
    pattern = editor.schema("problem")["properties"]["id"]["pattern"]
    assert r"\Z" not in pattern and r"\A" not in pattern and "(?P" not in pattern
    from mechbook.model.ids import ID

    for pid in GOOD_IDS:
        assert re.search(pattern, pid) and ID.fullmatch(pid), pid
    for pid in ["a-" + "x" * 81, "lim-20..31", "lim-", "Lim-1", "lim-1-", "lim-/1", "lim-1\n"]:
        assert not re.search(pattern, pid) and not ID.fullmatch(pid), pid


def _node() -> str:
    node = shutil.which("node")
    if node is None:
        pytest.skip("node is not installed: the schemas' JavaScript validation (ajv) "
                    "needs Node.js (CI installs it: .ci/run)")
    return node


@pytest.fixture(scope="module")
def ajv() -> str:
    """node, with ajv installed in .ci/ajv (installed here, by npm ci, when it is not)."""
    node = _node()
    if not (AJV / "node_modules" / "ajv" / "package.json").exists():
        npm = shutil.which("npm")
        assert npm, "node is installed but npm is not: cannot install ajv (.ci/ajv)"
        res = subprocess.run([npm, "ci", "--no-audit", "--no-fund", "--prefix", str(AJV)],
                             capture_output=True, text=True, timeout=600)
        assert res.returncode == 0, f"npm ci --prefix .ci/ajv failed:\n{res.stderr}"
    return node


def _ajv(node: str, cases: list[dict]) -> dict:
    payload = {"schemas": {n: editor.schema(n) for n in editor.NAMES}, "cases": cases}
    res = subprocess.run([node, str(AJV / "validate.mjs")], input=json.dumps(payload),
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout)


def _case(schema: str, path: Path, data=None) -> dict:
    return {"id": str(path), "schema": schema,
            "data": load(path).data if data is None else data}


def test_ajv_compiles_every_schema_and_accepts_every_committed_file(ajv):
    cases = ([_case("problem", p) for p in PROBLEMS] + [_case("answers", p) for p in ANSWERS]
             + [_case("books", p) for p in BOOKS])
    assert len(PROBLEMS) > 100 and len(ANSWERS) > 100
    out = _ajv(ajv, cases)
    assert out["schemas"] == {n: None for n in editor.NAMES}, out["schemas"]
    assert out["warnings"] == {n: [] for n in editor.NAMES}, out["warnings"]
    refused = {k: v for k, v in out["cases"].items() if v is not None}
    assert not refused, refused
    assert len(out["cases"]) == len(cases)


def test_ajv_flags_the_wrong_files(ajv, tmp_path):
    cases = []
    for i, (schema, text, _why) in enumerate(WRONG):
        path = tmp_path / f"{i}.yaml"
        path.write_text(text, encoding="utf-8")
        cases.append(_case(schema, path))
    good = tmp_path / "good.yaml"
    good.write_text(PROBLEM, encoding="utf-8")
    cases.append(_case("problem", good))
    key = tmp_path / "key.yaml"
    key.write_text(ANSWERS_TEXT, encoding="utf-8")
    cases.append(_case("answers", key))
    out = _ajv(ajv, cases)["cases"]
    assert out[str(good)] is None and out[str(key)] is None, out
    for i, (_schema, _text, why) in enumerate(WRONG):
        assert out[str(tmp_path / f"{i}.yaml")], f"ajv accepted {why}"


# ---- check-jsonschema, at its defaults ---------------------------------------------------------
def _check_jsonschema(schema: Path, files: list[Path]) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "check_jsonschema", "--schemafile",
                           str(schema), *map(str, files)],
                          capture_output=True, text=True, timeout=600)


@pytest.fixture(scope="module")
def schemas(tmp_path_factory) -> Path:
    pytest.importorskip("check_jsonschema", reason="check-jsonschema is in the dev extras "
                        "(pip install -e '.[dev]')")
    return Path(editor.write_schemas(tmp_path_factory.mktemp("schemas"))[0]).parent


@pytest.mark.parametrize("name, files", [("problem", PROBLEMS), ("answers", ANSWERS),
                                         ("books", BOOKS)])
def test_check_jsonschema_accepts_every_committed_file(schemas, name, files):
    res = _check_jsonschema(schemas / f"{name}.json", files)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "ok -- validation done" in res.stdout


@pytest.fixture(scope="module")
def check_result(tmp_path_factory) -> Path:
    """A real `mechbook check --format json` document (one small problem)."""
    res = subprocess.run([sys.executable, "-m", "mechbook", "check",
                          "classic-harmonic-oscillator", "--no-store", "--format", "json",
                          "--serial"], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    path = tmp_path_factory.mktemp("result") / "result.json"
    path.write_text(res.stdout, encoding="utf-8")
    return path


def test_both_validators_accept_a_check_result(schemas, check_result, ajv):
    res = _check_jsonschema(schemas / "check-result.json", [check_result])
    assert res.returncode == 0, res.stdout + res.stderr
    case = {"id": "r", "schema": "check-result",
            "data": json.loads(check_result.read_text(encoding="utf-8"))}
    assert _ajv(ajv, [case])["cases"] == {"r": None}
    case["data"]["problems"][0]["parts"][0]["status"] = "passed"
    assert _ajv(ajv, [case])["cases"]["r"], "ajv accepted an unknown status"


@pytest.mark.parametrize("i", range(len(WRONG)), ids=[w[2] for w in WRONG])
def test_check_jsonschema_flags_the_wrong_files(schemas, tmp_path, i):
    name, text, why = WRONG[i]
    path = tmp_path / "wrong.yaml"
    path.write_text(text, encoding="utf-8")
    res = _check_jsonschema(schemas / f"{name}.json", [path])
    assert res.returncode == 1, f"check-jsonschema accepted {why}: {res.stdout}{res.stderr}"
    assert "Schema validation errors were encountered" in res.stdout + res.stderr, \
        res.stdout + res.stderr


def test_check_jsonschema_refused_the_old_python_only_pattern(schemas, tmp_path):
    """The test can fail: the `\\Z` the problem schema had is refused at the defaults."""
    schema = json.loads((schemas / "problem.json").read_text(encoding="utf-8"))
    schema["properties"]["id"]["pattern"] = r"^[a-z]+-(?=[A-Za-z0-9._-]{1,80}\Z)[0-9.]+$"
    bad = tmp_path / "problem.json"
    bad.write_text(json.dumps(schema), encoding="utf-8")
    good = tmp_path / "p.yaml"
    good.write_text(PROBLEM, encoding="utf-8")
    res = _check_jsonschema(bad, [good])
    assert res.returncode != 0, res.stdout + res.stderr
