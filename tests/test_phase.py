"""Phase-space flow (mechbook/phase.py) and the checks built on it (`phase_area`,
`phase_region`): the flow against closed-form solutions, Liouville's theorem where it holds
and a shrinking area where it does not, and wrong areas and regions failing."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
from systems import pendulum

from mechbook.engine.analysis import Analysis
from mechbook.engine.phase import PhaseFlow, box_boundary, image_area, shoelace
from mechbook.model.problem import load_problem
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

ROOT = Path(__file__).resolve().parents[1]

OSCILLATOR = """\
parameters:
  m: {value: 0.7}
  k: {value: 2.3}
coordinates:
  x: {}
kinetic: m*xdot**2/2
potential: k*x**2/2
"""

DAMPED = OSCILLATOR + "forces:\n  x: -m*gamma*xdot\n"
DAMPED = DAMPED.replace("  k: {value: 2.3}\n", "  k: {value: 2.3}\n  gamma: {value: 0.4}\n")

PENDULUM = pendulum(m=1.3, l=0.7)

CYCLOTRON = """\
parameters:
  m: {value: 0.9}
  q: {value: 1.1}
  B: {value: 1.7}
  k: {value: 0.6}
coordinates:
  x: {}
  y: {}
kinetic: m*(xdot**2 + ydot**2)/2
potential: k*(x**2 + 2*y**2)/2 + x**3/3
velocity_potential: -q*B*(x*ydot - y*xdot)/2
"""

RELATIVISTIC = """\
parameters:
  m: {value: 1.0}
  c: {value: 1.5}
  k: {value: 2.0}
coordinates:
  x: {}
lagrangian: -m*c**2*sqrt(1 - xdot**2/c**2) - k*x**2/2
"""


def analysis(tmp_path: Path, body: str, num: str = "2001") -> Analysis:
    text = f"id: lim-{num}\nsource: hand-derived test\ntitle: a test system\n" + body
    path = tmp_path / f"{num}.yaml"
    path.write_text(text, encoding="utf-8")
    return Analysis(load_problem(path))


def run(tmp_path: Path, an: Analysis, parts: list[dict], symbols: dict | None = None):
    doc = {"problem": an.problem.id, "source": "hand-derived test",
           "symbols": symbols or {"a": {"value": 0.5}, "b": {"value": 0.3},
                                  "tau": {"value": 0.8}},
           "parts": [{"cite": "test", **p} for p in parts]}
    path = tmp_path / "key.yaml"
    path.write_text(json.dumps(doc), encoding="utf-8")  # JSON is YAML
    return check_problem(an, load_answers(path))


def values(an: Analysis) -> dict:
    return dict(an.problem.values())


# ---- the flow itself -------------------------------------------------------------------------
def test_oscillator_flow_matches_closed_form(tmp_path):
    an = analysis(tmp_path, OSCILLATOR)
    flow = PhaseFlow(an.system(), an.dynamics())
    v = values(an)
    m, k = 0.7, 2.3
    w = np.sqrt(k / m)
    x0, p0 = np.array([0.3, -1.2, 0.0]), np.array([0.5, 0.1, -2.0])
    for t in (1.7, -0.9):
        x, p = flow.map(v, x0, p0, t)
        xe = x0 * np.cos(w * t) + p0 / (m * w) * np.sin(w * t)
        pe = p0 * np.cos(w * t) - m * w * x0 * np.sin(w * t)
        assert np.allclose(x, xe, rtol=1e-10, atol=1e-11)
        assert np.allclose(p, pe, rtol=1e-10, atol=1e-11)


def test_two_degrees_of_freedom_flow_is_symplectic(tmp_path):
    """A charge in a magnetic field and an anharmonic well: p = m v + A(q) is linear in the
    velocities with an offset. The flow's Jacobian (central differences) is symplectic,
    JᵀΩJ = Ω, hence volume-preserving, and the flow is undone by running it back."""
    an = analysis(tmp_path, CYCLOTRON)
    flow = PhaseFlow(an.system(), an.dynamics())
    v = values(an)
    X = np.array([0.2, -0.3, 0.4, 0.1])
    h = 1e-5
    pts = [X]
    for i in range(4):
        for s in (1, -1):
            pts.append(X + s * h * np.eye(4)[i])
    P = np.array(pts)
    Q1, P1 = flow.map(v, P[:, :2], P[:, 2:], 1.3)
    Y = np.column_stack((Q1, P1))
    J = np.column_stack([(Y[1 + 2 * i] - Y[2 + 2 * i]) / (2 * h) for i in range(4)])
    omega = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.eye(2), np.zeros((2, 2))]])
    assert np.allclose(J.T @ omega @ J, omega, atol=1e-7)
    assert abs(np.linalg.det(J) - 1) < 1e-7
    Qb, Pb = flow.map(v, Q1, P1, 0.0, 1.3)
    assert np.allclose(np.column_stack((Qb, Pb)), P, atol=1e-10)


def test_momenta_nonlinear_in_velocities(tmp_path):
    """Relativistic momentum p = m v / sqrt(1 - v²/c²): q̇ from p by Newton's method."""
    an = analysis(tmp_path, RELATIVISTIC)
    flow = PhaseFlow(an.system(), an.dynamics())
    par = flow._par(values(an))
    V = np.array([[-1.4, -0.3, 0.0, 0.9, 1.49]])
    Q = np.zeros_like(V)
    P, _ = flow.momenta(0.0, Q, V, par)
    assert np.allclose(P, V / np.sqrt(1 - V**2 / 1.5**2))
    assert np.allclose(flow.velocities(0.0, Q, P, par), V, rtol=1e-12, atol=1e-14)
    area, _ = image_area(flow, values(an), (-0.2, -0.5), (0.3, 1.0), 2.0)
    assert abs(area - 0.75) < 1e-8 * 0.75


def test_shoelace_orientation():
    q, p = box_boundary((0.0, 0.0), (2.0, 3.0), 5)
    assert abs(shoelace(q, p) - 6.0) < 1e-14


def test_nonlinear_flow_area_to_tolerance(tmp_path):
    """A pendulum carried a long way (the box's edges become strongly curved): the
    extrapolated shoelace area keeps the initial area to well within 1e-8."""
    an = analysis(tmp_path, PENDULUM)
    flow = PhaseFlow(an.system(), an.dynamics())
    area, err = image_area(flow, values(an), (0.5, -0.3), (2.5, 0.6), 3.0)
    assert abs(area - 1.8) < 1e-9 * 1.8
    assert err < 1e-8


# ---- the checks ------------------------------------------------------------------------------
OSC_REGION = {"x": ["-a", "a"], "p_x": ["-b", "b"]}
OSC_BOOK = ["-a < x*cos(sqrt(k/m)*t) - p_x*sin(sqrt(k/m)*t)/sqrt(k*m) < a",
            "-b < p_x*cos(sqrt(k/m)*t) + sqrt(k*m)*x*sin(sqrt(k/m)*t) < b"]


@pytest.mark.parametrize("book, status", [("4*a*b", "pass"), ("2*a*b", "fail"),
                                          ("4*a*b*(1 + t)", "fail"), ("-4*a*b", "fail")])
def test_oscillator_area(tmp_path, book, status):
    an = analysis(tmp_path, OSCILLATOR)
    out = run(tmp_path, an, [{"part": "area", "quantity": "phase_area", "region": OSC_REGION,
                              "time": "tau", "book": book}])[0]
    assert out.status == status, (out.status, out.detail)


@pytest.mark.slow
def test_oscillator_region(tmp_path):
    an = analysis(tmp_path, OSCILLATOR)
    wrong = [OSC_BOOK[0].replace("- p_x*sin", "+ p_x*sin"), OSC_BOOK[1]]
    outs = run(tmp_path, an, [
        {"part": "right", "quantity": "phase_region", "region": OSC_REGION, "time": "tau",
         "book": OSC_BOOK},
        {"part": "wrong", "quantity": "phase_region", "region": OSC_REGION, "time": "tau",
         "book": wrong},
        {"part": "initial", "quantity": "phase_region", "region": OSC_REGION, "time": "tau",
         "book": ["-a < x < a", "-b < p_x < b"]}])
    assert [o.status for o in outs] == ["pass", "fail", "fail"], [o.detail for o in outs]
    assert "carries it back" in outs[1].detail


def _symon_33() -> tuple[Analysis, dict]:
    key = load_answers(ROOT / "answers" / "symon" / "09-33.yaml")
    an = Analysis(load_problem(ROOT / "problems" / "symon" / "09-33.yaml"))
    return an, copy.deepcopy(key.doc.data)


def _run_doc(tmp_path, an, doc, part, **changes):
    doc = copy.deepcopy(doc)
    p = next(x for x in doc["parts"] if x["part"] == part)
    p.update(changes)
    doc["parts"] = [p]
    path = tmp_path / "key.yaml"
    path.write_text(json.dumps(doc), encoding="utf-8")
    return check_problem(an, load_answers(path))[0]


@pytest.mark.slow
def test_free_fall_symon_9_33(tmp_path):
    an, doc = _symon_33()
    assert _run_doc(tmp_path, an, doc, "region").status == "pass"
    assert _run_doc(tmp_path, an, doc, "area").status == "pass"
    sheared = _run_doc(tmp_path, an, doc, "region",
                       book=["-b < p_z + m*g*t < b", "-a < z + p_z*t/m - g*t**2/2 < a"])
    assert sheared.status == "fail", sheared.detail
    unshifted = _run_doc(tmp_path, an, doc, "region",
                         book=["-b < p_z < b", "-a < z - p_z*t/m - g*t**2/2 < a"])
    assert unshifted.status == "fail", unshifted.detail
    for wrong in ("2*a*b", "4*a*b*(1 + t)"):
        out = _run_doc(tmp_path, an, doc, "area", book=wrong)
        assert out.status == "fail", (wrong, out.detail)


@pytest.mark.parametrize("book, status", [("4*a*b*exp(-gamma*t)", "pass"), ("4*a*b", "fail"),
                                          ("4*a*b*exp(-2*gamma*t)", "fail")])
def test_damped_oscillator_area_shrinks(tmp_path, book, status):
    """With the damping force -m*gamma*xdot the flow contracts phase area by exp(-gamma*t):
    the area is measured, so a non-Hamiltonian flow is not reported area-preserving."""
    an = analysis(tmp_path, DAMPED)
    out = run(tmp_path, an, [{"part": "area", "quantity": "phase_area", "region": OSC_REGION,
                              "time": "tau", "book": book}])[0]
    assert out.status == status, (out.status, out.detail)


def test_malformed_region_is_an_error(tmp_path):
    an = analysis(tmp_path, OSCILLATOR)
    outs = run(tmp_path, an, [
        {"part": "missing", "quantity": "phase_area", "region": {"x": ["-a", "a"]},
         "time": "tau", "book": "4*a*b"},
        {"part": "no-time", "quantity": "phase_area", "region": OSC_REGION, "book": "4*a*b"},
        {"part": "not-phase", "quantity": "phase_region", "region": OSC_REGION,
         "time": "tau", "book": ["a < b"]}])
    assert [o.status for o in outs] == ["error"] * 3, [o.detail for o in outs]


def test_damped_region_is_found(tmp_path):
    """Region of a damped free particle (no spring): p = p0 exp(-gamma t),
    x = x0 + p0 (1 - exp(-gamma t))/(m gamma)."""
    body = ("parameters:\n  m: {value: 0.7}\n  gamma: {value: 0.4}\ncoordinates:\n  x: {}\n"
            "kinetic: m*xdot**2/2\nforces:\n  x: -m*gamma*xdot\n")
    an = analysis(tmp_path, body)
    book = ["-b < p_x*exp(gamma*t) < b",
            "-a < x - p_x*(exp(gamma*t) - 1)/(m*gamma) < a"]
    outs = run(tmp_path, an, [
        {"part": "region", "quantity": "phase_region", "region": OSC_REGION, "time": "tau",
         "book": book},
        {"part": "area", "quantity": "phase_area", "region": OSC_REGION, "time": "tau",
         "book": "4*a*b*exp(-gamma*t)"}])
    assert [o.status for o in outs] == ["pass", "pass"], [o.detail for o in outs]



@pytest.mark.slow
def test_two_degrees_of_freedom_region(tmp_path):
    """A projectile in the plane: the 4-dimensional box is sheared in x and y and shifted
    in p_y; a region check runs in n = 2, and the area check says it needs n = 1."""
    body = ("parameters:\n  m: {value: 0.6}\n  g: {}\ncoordinates:\n  x: {}\n  y: {}\n"
            "particles:\n  ball: {mass: m, position: [x, y]}\ngravity: {}\n")
    an = analysis(tmp_path, body)
    region = {"x": ["-a", "a"], "y": ["0", "a"], "p_x": ["-b", "b"], "p_y": ["b", "2*b"]}
    right = ["-a < x - p_x*t/m < a", "0 < y - p_y*t/m - g*t**2/2 < a",
             "-b < p_x < b", "b < p_y + m*g*t < 2*b"]
    wrong = right[:1] + ["0 < y - p_y*t/m + g*t**2/2 < a"] + right[2:]
    outs = run(tmp_path, an, [
        {"part": "right", "quantity": "phase_region", "region": region, "time": "tau",
         "book": right},
        {"part": "wrong", "quantity": "phase_region", "region": region, "time": "tau",
         "book": wrong},
        {"part": "area", "quantity": "phase_area", "region": region, "time": "tau",
         "book": "a"}])
    assert [o.status for o in outs] == ["pass", "fail", "unsupported"], [o.detail for o in outs]
