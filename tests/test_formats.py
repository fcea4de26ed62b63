"""Machine-readable check results (JSON against its schema, JUnit XML), shell completion,
and a command line that answers without loading the engine."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import jsonschema
import pytest
from click.testing import CliRunner

from mechbook.app.cli import main
from mechbook.app.output.formats import schema

ROOT = Path(__file__).resolve().parents[1]
HEAVY = ("sympy", "scipy", "numpy", "h5py", "matplotlib", "pandas", "mechbook.engine",
         "mechbook.verify", "mechbook.numerics")

WRONG = """\
problem: lim-2031
source: a key with one wrong part
parts:
  - part: wrong
    cite: test
    quantity: eom
    book: ["b*thetaddot + b*omega**2*sin(theta)*cos(theta) - g*sin(theta) = 0"]
  - part: right
    cite: test
    quantity: eom
    book: ["b*thetaddot - b*omega**2*sin(theta)*cos(theta) - g*sin(theta) = 0"]
  - part: later
    cite: test
    quantity: normal_modes
    unsupported: "a capability the engine lacks"
"""


def run(*args: str, **kw):
    return CliRunner().invoke(main, list(args), **kw)


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    """lim-2031 checked once, with its cross-checks: the JSON document and the JUnit file."""
    tmp = tmp_path_factory.mktemp("good")
    junit = tmp / "junit.xml"
    result = run("--root", str(ROOT), "check", "lim-2031", "--serial", "--format", "json",
                 "--store", str(tmp / "s.h5"), "--junit-xml", str(junit))
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout), ET.parse(junit)


@pytest.fixture(scope="module")
def wrong(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("wrong")
    for sub in ("problems", "answers"):
        (tmp / sub / "lim").mkdir(parents=True)
    shutil.copy(ROOT / "problems" / "lim" / "2031.yaml", tmp / "problems" / "lim")
    (tmp / "answers" / "lim" / "2031.yaml").write_text(WRONG, encoding="utf-8")
    (tmp / "problems" / "lim" / "2032.yaml").write_text("id: lim-2032\n", encoding="utf-8")
    (tmp / "answers" / "lim" / "2032.yaml").write_text("problem: lim-2032\n", encoding="utf-8")
    junit = tmp / "junit.xml"
    result = run("--root", str(tmp), "check", "lim-2031", "lim-2032", "--serial",
                 "--no-crosscheck", "--no-store", "--format", "json", "--junit-xml", str(junit))
    assert result.exit_code == 1, result.output
    return json.loads(result.stdout), ET.parse(junit)


def test_json_output_follows_its_schema(good):
    doc, _ = good
    jsonschema.Draft202012Validator.check_schema(schema())
    jsonschema.validate(doc, schema())
    (problem,) = doc["problems"]
    assert problem["id"] == "lim-2031" and problem["error"] is None
    assert [p["status"] for p in problem["parts"]] == ["pass"] * len(problem["parts"])
    assert problem["crosschecks"] and doc["summary"]["ok"] is True
    assert doc["summary"]["pass"] == len(problem["parts"]) and doc["summary"]["failures"] == 0
    vouched = {c for p in problem["parts"] for c in p["crosschecks"]}
    assert vouched <= {x["name"] for x in problem["crosschecks"]}


def test_json_output_reports_failures_and_errors(wrong):
    doc, _ = wrong
    jsonschema.validate(doc, schema())
    by_id = {p["id"]: p for p in doc["problems"]}
    statuses = {p["part"]: p["status"] for p in by_id["lim-2031"]["parts"]}
    assert statuses == {"wrong": "fail", "right": "pass", "later": "unsupported"}
    assert by_id["lim-2032"]["error"] and by_id["lim-2032"]["parts"] == []
    s = doc["summary"]
    assert (s["fail"], s["pass"], s["unsupported"], s["problem_errors"]) == (1, 1, 1, 1)
    assert s["failures"] == 2 and s["ok"] is False


@pytest.mark.parametrize("breakage", [
    lambda d: d["problems"][0]["parts"][0].update(status="passed"),
    lambda d: d["summary"].pop("failures"),
    lambda d: d["problems"][0].update(id="../etc"),
    lambda d: d["problems"][0]["parts"][0].update(extra=1),
])
def test_the_schema_refuses_a_malformed_document(good, breakage):
    doc = json.loads(json.dumps(good[0]))
    breakage(doc)
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(doc, schema())


def test_junit_xml_counts(good, wrong):
    doc, tree = good
    top = tree.getroot()
    (suite,) = top.findall("testsuite")
    cases = suite.findall("testcase")
    n = len(doc["problems"][0]["parts"]) + len(doc["problems"][0]["crosschecks"])
    assert len(cases) == n == int(suite.get("tests")) == int(top.get("tests"))
    assert top.get("failures") == "0" and top.get("errors") == "0"
    _, bad = wrong
    suites = {s.get("name"): s for s in bad.getroot().findall("testsuite")}
    cases = {c.get("name"): c for c in suites["lim-2031"].findall("testcase")}
    assert cases["wrong [eom]"].find("failure") is not None
    assert cases["right [eom]"].find("failure") is None
    assert cases["later [normal_modes]"].find("skipped") is not None
    assert suites["lim-2032"].find("testcase/error") is not None
    assert bad.getroot().get("failures") == "1" and bad.getroot().get("errors") == "1"


def _imported_after(code: str) -> list[str]:
    """Heavy modules loaded by a fresh interpreter running `code`."""
    probe = (code + "\nimport sys\nprint('HEAVY:' + ','.join(m for m in " + repr(HEAVY)
             + " if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         cwd=ROOT, check=True, env={**os.environ, "MECHBOOK_ROOT": str(ROOT)})
    line = out.stdout.strip().splitlines()[-1]
    assert line.startswith("HEAVY:"), out.stdout
    return [m for m in line.removeprefix("HEAVY:").split(",") if m]


@pytest.mark.parametrize("args", [["--help"], ["check", "--help"], ["list"],
                                  ["check", "--bogus"], ["completion", "bash"]])
def test_cli_answers_without_the_engine(args):
    code = ("from click.testing import CliRunner\nfrom mechbook.app.cli import main\n"
            f"r = CliRunner().invoke(main, {args!r})\nprint(r.exit_code)")
    assert _imported_after(code) == []


@pytest.mark.slow
def test_import_mechbook_is_light_and_load_is_lazy():
    assert _imported_after("import mechbook\nmechbook.__version__") == []
    assert "sympy" in _imported_after("import mechbook\nmechbook.load")


def test_completion_of_commands_and_problem_ids():
    env = {"_MECHBOOK_COMPLETE": "bash_complete", "COMP_WORDS": "mechbook check lim-203",
           "COMP_CWORD": "2", "MECHBOOK_ROOT": str(ROOT)}
    result = run(env=env, prog_name="mechbook")
    ids = [ln.split(",", 1)[1] for ln in result.output.splitlines()]
    assert "lim-2031" in ids and all(i.startswith("lim-203") for i in ids), result.output
    env.update(COMP_WORDS="mechbook re", COMP_CWORD="1")
    result = run(env=env, prog_name="mechbook")
    assert [ln.split(",", 1)[1] for ln in result.output.splitlines()] == ["report", "restore"]
    script = run("completion", "bash")
    assert script.exit_code == 0 and "_MECHBOOK_COMPLETE=bash_complete" in script.output
    assert run("completion", "tcsh").exit_code != 0
