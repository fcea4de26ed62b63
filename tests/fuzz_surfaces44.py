"""Fuzzing the surfaces issue 44 attacked (kinds of tests/fuzz.py): velocity constraints and
rolling contacts, driven coordinates and Floquet periods, `schema --write`, `--lf`'s record,
id patterns, and the Python API's arguments. Each generator returns the JSON-able spec of a
case; each runner takes the case's folder and its spec and returns (status, message), with
the statuses of tests/fuzz_surfaces.py (ok, refused, crash, outside, unsafe; the batch adds
hang and bomb).
"""

from __future__ import annotations

import json
import os
import random
from pathlib import Path

from fuzz_surfaces import MARKER, Guard, _crash, _refused, _special, _tree

TRACEBACK = "Traceback (most recent call last)"


def _write(tree: Path, pid: str, problem: str, key: str) -> Path:
    book, num = pid.split("-", 1)
    for kind, text in (("problems", problem), ("answers", key)):
        path = tree / kind / book / f"{num}.yaml"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text.replace("NUM", num), encoding="utf-8")
    return tree / "problems" / book / f"{num}.yaml"


def _validate_then_check(tree: Path, pid: str, ppath: Path) -> tuple[str, str]:
    """validate the problem; if it is valid, check it (no cross-checks): a traceback in the
    run's log or an error detail is a crash."""
    from mechbook.app.authoring.validate import validate_file
    from mechbook.app.running.run import RunOptions, run_problem
    from mechbook.errors import MechbookError

    try:
        validate_file(ppath)
    except MechbookError as exc:
        return _refused(exc, ppath.name)
    run = run_problem(pid, tree, RunOptions(crosscheck=False), lambda stage: None)
    texts = [run.error or ""] + [o.detail for o in run.outcomes]
    crash = next((t for t in run.debug + texts if TRACEBACK in t), None)
    if crash:
        return "crash", crash[-3000:]
    raw = ("NonInvertibleMatrixError", "ZeroDivisionError", "AttributeError")
    bad = next((t for t in texts if any(r in t for r in raw)), None)
    if bad:
        return "crash", f"a raw error as a part's detail: {bad[:500]}"
    return ("refused", run.error) if run.error else \
        ("ok", ", ".join(f"{o.part} {o.status}" for o in run.outcomes))


# ---- velocity constraints and rolling ------------------------------------------------------
SLEIGH = """\
id: lim-NUM
source: fuzz
title: a sleigh with a fuzzed velocity constraint
parameters:
  m: {value: 1.5}
  I: {value: 0.2}
  a: {value: 0.4, positive: false}
coordinates:
  x: {}
  y: {}
  theta: {}
rigid_bodies:
  sled:
    mass: m
    position: [x + a*cos(theta), y + a*sin(theta)]
    inertia: I
    angular_velocity: thetadot
velocity_constraints:
  - {name: blade, expr: "EXPR"}
"""
COIN = """\
id: lim-NUM
source: fuzz
title: a coin rolling on a fuzzed surface
parameters:
  m: {value: 0.4}
  R: {value: 0.3}
  g: {}
coordinates:
  x: {}
  y: {}
  phi: {}
  theta: {range: [0, pi]}
  psi: {}
rigid_bodies:
  coin:
    mass: m
    position: [x, y, R*sin(theta)]
    inertia: {shape: SHAPE, radius: R}
    euler_angles: [phi, theta, psi]
gravity: {}
rolling:
  - {name: contact, body: coin, SURFACE}
"""
SHAPES = ["disk", "ring", "solid_sphere", "spherical_shell", "solid_cylinder", "rod"]
KEY = """\
problem: lim-NUM
source: fuzz
parts:
  - part: a
    cite: freedoms
    quantity: mode_count
    book: {configuration: 3, velocity: 2}
  - part: b
    cite: energy
    quantity: conserved
    book: ["m*(xdot**2 + ydot**2)/2"]
"""
FACTORS = ["xdot", "ydot", "thetadot", "Abs(xdot)", "sign(ydot)*ydot", "sqrt(xdot**2)",
           "xdot**2", "xdot*ydot", "exp(xdot)", "1/xdot", "xdot**(1/2)", "cos(xdot)",
           "xdot*sin(theta)", "ydot*cos(theta)", "t", "1", "xddot", "theta", "atan(ydot)",
           "(xdot + ydot)**2 - (xdot - ydot)**2 - 4*xdot*ydot", "xdot**0", "xdot**-1"]
COEFFICIENTS = ["1", "-1", "1e-12", "1e12", "1e-90", "1e90", "3", "sin(theta)", "0", "a",
                "exp(-50)", "2**-40", "cos(theta)**2 + sin(theta)**2"]
NORMALS = ["[0, 0, 1]", "[0, 0, 1e-12]", "[0, 0, 0]", "[1, 1, 1]", "[0, 1]", "[0, 0, theta]",
           "[0, 0, -1]", "[1e-90, 0, 1]", "[1, 0, 0]", "[0, 0, 1e90]"]
VELOCITIES = ["[0, 0, 0]", "[-y, x, 0]", "[1e12, 0, 0]", "[xdot, 0, 0]", "[Abs(xdot), 0, 0]",
              "[0, 0, 1]", "[t, 0, 0]", "[0, 0]"]


def velocity_spec(rng: random.Random) -> dict:
    if rng.random() < 0.7:
        terms = [f"{rng.choice(COEFFICIENTS)}*({rng.choice(FACTORS)})"
                 for _ in range(rng.randint(1, 3))]
        return {"kind": "constraint", "expr": " + ".join(terms)}
    surface = {"normal": rng.choice(NORMALS)} if rng.random() < 0.7 else {}
    if rng.random() < 0.5:
        surface["velocity"] = rng.choice(VELOCITIES)
    return {"kind": "rolling", "surface": surface, "shape": rng.choice(SHAPES),
            "point": rng.choice([None, "[x, y, 0]", "[x, y]", "[x, y, R]", "[xdot, y, 0]"])}


def run_velocity(where: Path, spec: dict) -> tuple[str, str]:
    """A sleigh's velocity constraint, or a coin's rolling contact, fuzzed: validated, then
    checked when valid; never a traceback or a raw linear-algebra error."""
    tree = _tree(where)
    if spec["kind"] == "constraint":
        problem = SLEIGH.replace("EXPR", spec["expr"])
    else:
        extra = []
        if spec["surface"]:
            inner = ", ".join(f"{k}: {v}" for k, v in spec["surface"].items())
            extra.append(f"surface: {{{inner}}}")
        if spec["point"]:
            extra.append(f"point: {spec['point']}")
        problem = COIN.replace(", SURFACE", (", " + ", ".join(extra)) if extra else "") \
            .replace("SHAPE", spec["shape"])
    ppath = _write(tree, "lim-9801", problem, KEY)
    return _validate_then_check(tree, "lim-9801", ppath)


# ---- driven coordinates and Floquet periods --------------------------------------------------
MATHIEU = """\
id: lim-NUM
source: fuzz
title: Mathieu's equation, a fuzzed period
parameters:
  alpha: {value: 1.0}
coordinates:
  x: {}
kinetic: xdot**2/2
potential: (alpha - 3*cos(2*t)/5)*x**2/2
"""
KAPITZA = """\
id: lim-NUM
source: fuzz
title: a pendulum on a pivot driven up and down, a fuzzed drive
parameters:
  m: {value: 1.0}
  omega: {value: 40.0}
coordinates:
  theta: {}
driven:
  y0: DRIVE
particles:
  bob: {mass: m, position: [sin(theta), y0 - cos(theta)]}
gravity: {g: 981/100}
"""
PERIODS = ["1e-30", "1e-12", "1e-9", "1e-6", "pi", "2*pi", "pi/2", "-pi", "0", "1e30", "1e99",
           "1e-99", "sqrt(-1)", "1/0", "alpha", "x", "t", "exp(800)", "3.14159", "nan", "oo",
           "pi*(1 + 1e-15)", "2*pi/omega", "pi/omega", "1e6*pi"]
DRIVES = ["cos(omega*t)/10", "cos(omega*t)*exp(t)/10", "cos(1e-30*t)/10", "cos(1e30*t)/10",
          "Abs(cos(omega*t))/10", "t**2", "sin(omega*t)**2/10", "cos(omega*t)/1e90",
          "cos(omega*t) + cos(sqrt(2)*omega*t)", "1e90*cos(omega*t)", "theta", "thetadot",
          "cos(omega*t", "0"]


def periods_spec(rng: random.Random) -> dict:
    period = rng.choice(PERIODS) if rng.random() < 0.8 else \
        repr(10 ** rng.uniform(-40, 40) * rng.choice([1, -1]))
    return {"system": rng.choice(["mathieu", "kapitza"]), "period": period,
            "drive": rng.choice(DRIVES), "declare": rng.random() < 0.8,
            "quantity": rng.choice(["stability", "stability_condition"])}


def run_periods(where: Path, spec: dict) -> tuple[str, str]:
    """A linearization with periodic coefficients (Mathieu's equation, or Kapitza's
    pendulum with a fuzzed drive), its stability checked with a fuzzed `period:`."""
    tree = _tree(where)
    if spec["system"] == "mathieu":
        problem, about, book = MATHIEU, "{x: 0}", "alpha > 0"
    else:
        problem = KAPITZA.replace("DRIVE", json.dumps(spec["drive"]))
        about, book = "{theta: pi}", "omega > 10"
    part = (f"  - part: a\n    cite: stability\n    quantity: {spec['quantity']}\n"
            f"    about: {about}\n")
    part += "    book: stable\n" if spec["quantity"] == "stability" else f"    book: {book}\n"
    if spec["declare"]:
        part += f"    period: {json.dumps(spec['period'])}\n"
    key = f"problem: lim-NUM\nsource: fuzz\nparts:\n{part}"
    ppath = _write(tree, "lim-9802", problem, key)
    return _validate_then_check(tree, "lim-9802", ppath)


# ---- schema --write ------------------------------------------------------------------------
SCHEMA_NAMES = ["problem.json", "answers.json", "books.json", "check-result.json"]
SCHEMA_PLANTS = ["fifo", "devzero", "directory", "dangling", "loop", "outside-link", "sparse",
                 "empty", "none", "dir-is-file", "dir-is-link", "dir-is-dangling",
                 "dir-is-fifo", "old-file"]


def schema_spec(rng: random.Random) -> dict:
    return {"plant": rng.choice(SCHEMA_PLANTS), "name": rng.choice(SCHEMA_NAMES),
            "dir": rng.choice(["schemas", "a/b/schemas", "."])}


def run_schema(where: Path, spec: dict) -> tuple[str, str]:
    """`mechbook schema --write DIR` with something planted at DIR or at one of its files:
    nothing written outside the tree, through a link or into a special file; on success
    the four schemas are regular files holding JSON."""
    from click.testing import CliRunner

    from mechbook.app.cli import main

    guard = Guard(where)
    tree = where / "tree"
    tree.mkdir()
    target = tree / spec["dir"]
    plant = spec["plant"]
    if plant == "dir-is-file":
        target.parent.mkdir(parents=True, exist_ok=True)
        if target != tree:
            target.write_text("a file where the folder goes")
    elif plant == "dir-is-link":  # DIR a link the user named: followed, as init's DIR is,
        if target != tree:  # so it points inside the tree (a linked folder below DIR is not)
            (tree / "real").mkdir()
            target.parent.mkdir(parents=True, exist_ok=True)
            target.symlink_to(tree / "real", target_is_directory=True)
    elif plant in ("dir-is-dangling", "dir-is-fifo"):
        if target != tree:
            target.parent.mkdir(parents=True, exist_ok=True)
            _special(target, "dangling" if plant == "dir-is-dangling" else "fifo", guard)
    elif plant == "old-file":
        target.mkdir(parents=True, exist_ok=True)
        (target / spec["name"]).write_text("{}\n")
    elif plant != "none":
        _special(target / spec["name"], plant, guard)
    cwd = os.getcwd()
    os.chdir(tree)
    try:
        res = CliRunner().invoke(main, ["schema", "--write", spec["dir"]])
    finally:
        os.chdir(cwd)
    moved = guard.changed()
    if moved:
        return "outside", moved
    if res.exception is not None and not isinstance(res.exception, SystemExit):
        import traceback

        return "crash", "".join(traceback.format_exception(res.exception))[-2000:]
    if res.exit_code != 0:
        message = res.output.strip()
        return ("refused", message) if message.startswith("Error: ") else \
            ("crash", f"exit {res.exit_code} without a message: {message[:300]}")
    for name in SCHEMA_NAMES:
        path = target / name
        if path.is_symlink() or not path.is_file():
            return "unsafe", f"schema --write succeeded but {path} is not a regular file"
        try:
            json.loads(path.read_text(encoding="utf-8"))
        except ValueError as exc:
            return "unsafe", f"{path} is not JSON after a successful write: {exc}"
    return "ok", f"wrote the schemas into {spec['dir']}"


# ---- --lf's record -------------------------------------------------------------------------
RECORD_PLANTS = ["fifo", "devzero", "directory", "dangling", "loop", "outside-link", "sparse",
                 "empty", "nested", "random", "shapes", "bytes", "good", "none"]


def lastfailed_spec(rng: random.Random) -> dict:
    return {"plant": rng.choice(RECORD_PLANTS), "seed": rng.randrange(2**31),
            "failed": rng.random() < 0.5}


def run_lastfailed(where: Path, spec: dict) -> tuple[str, str]:
    """`--lf`'s record replaced by what anyone can leave there: read it (bounded, no
    block), select with it, write it again; nothing outside the tree changes, nothing of
    the outside shows in what was selected, and a written record reads back."""
    from mechbook.app.selection import last_failed, lastfailed_path, record

    tree = _tree(where, pids=("lim-2101", "lim-2102"))
    guard = Guard(where)
    store = tree / "results" / "mechbook.h5"
    store.parent.mkdir(parents=True, exist_ok=True)
    path = lastfailed_path(store)
    rng = random.Random(spec["seed"])
    plant = spec["plant"]
    if plant == "nested":
        path.write_text("[" * rng.choice([40, 1000, 100_000]) + "]" * 10)
    elif plant == "random":
        path.write_text(json.dumps({"failed": [rng.choice(["lim-2101", "lim-9999", 7, None,
                                                           "../../x", "a" * 5000])
                                               for _ in range(rng.randint(0, 30))]}))
    elif plant == "shapes":
        path.write_text(json.dumps(rng.choice([[], {}, {"failed": "lim-2101"}, 3, None,
                                               {"failed": {"a": 1}}])))
    elif plant == "bytes":
        path.write_bytes(bytes(rng.randrange(256) for _ in range(rng.randint(1, 3000))))
    elif plant == "good":
        path.write_text(json.dumps({"failed": ["lim-2102"]}))
    elif plant != "none":
        _special(path, plant, guard)
    try:
        before = last_failed(store)
        if MARKER in " ".join(map(str, before)):
            return "leak", "the outside's marker was read as a failure"
        failed = ["lim-2101"] if spec["failed"] else []
        try:
            record(store, ["lim-2101"], failed)
        except OSError as exc:
            moved = guard.changed()
            return ("outside", moved) if moved else _refused(exc)
        after = last_failed(store)
    except Exception as exc:  # noqa: BLE001
        return _crash(exc)
    moved = guard.changed()
    if moved:
        return "outside", moved
    if path.is_symlink() or not path.is_file():
        return "unsafe", f"the record {path} is not a regular file after it was written"
    if ("lim-2101" in after) != spec["failed"]:
        return "lost", f"the record does not say what was written: {sorted(after)[:5]}"
    return "ok", f"{len(before)} read, {len(after)} kept"


# ---- id patterns ---------------------------------------------------------------------------
PATTERN_PIECES = ["[", "]", "*", "?", "[!", "[a-z]", "[z-a]", "lim-", "2101", "-", "\\",
                  "**", "[]]", "[[]", "é", "\x00", "\n", "..", "/", "[^0-9]", "{a,b}"]


def patterns_spec(rng: random.Random) -> dict:
    if rng.random() < 0.3:
        piece = rng.choice(PATTERN_PIECES)
        return {"pattern": "lim-" + piece * rng.choice([100, 511, 513, 5000, 30_000])}
    return {"pattern": "".join(rng.choice(PATTERN_PIECES) for _ in range(rng.randint(1, 30)))}


def run_patterns(where: Path, spec: dict) -> tuple[str, str]:
    """An id pattern as `check` and `report` resolve it: refused with a message or
    resolved, within the batch's time limit whatever its size."""
    from mechbook.app.selection import select
    from mechbook.errors import MechbookError

    tree = _tree(where, pids=("lim-2101", "lim-2102"))
    try:
        ids = select([spec["pattern"]], tree)
    except MechbookError as exc:
        return _refused(exc)
    except Exception as exc:  # noqa: BLE001
        return _crash(exc)
    return "ok", f"{len(ids)} id(s)"


# ---- the Python API's arguments ------------------------------------------------------------
API_VALUES = ["inf", "-inf", "nan", "-1", "0", "'5'", "None", "10**400", "True", "[1.0]",
              "1e-3", "0.5", "complex(1, 1)", "np.float64('nan')", "np.int64(50)", "10**12",
              "1.5", "{}", "{'m': 2}", "{'m': 10**400}", "[('m', 2)]", "{'theta': 'pi'}",
              "{'nope': 1}", "{'m': 'sqrt(-1)'}", "{'m': float('inf')}", "{'theta': 10**400}",
              "object()", "'x' * 100000", "b'1'", "-10**400", "2", "11"]
API_CALLS = [
    "p.simulate(t_end={v}, points=11)", "p.simulate(t_end=0.5, points={v})",
    "p.simulate(t_end=0.5, points=11, rtol={v})", "p.simulate(t_end=0.5, points=11, step={v}, "
    "method='RK4')", "p.simulate(t_end=0.5, points=11, params={v})",
    "p.simulate(t_end=0.5, points=11, init={v})", "p.simulate(t_end=0.5, points=11, atol={v})",
    "p.simulate(t_end=0.5, points=11, max_step={v})", "p.simulate(t_end=0.5, method={v})",
    "p.frequencies(numeric=True, params={v})", "p.frequencies(about={v})",
    "p.modes(params={v})", "p.ode_function(params={v})", "p.ode_function().initial(init={v})",
    "p.system({v})", "p.linearize(about={v})", "mechbook.load({v})",
    "mechbook.results({v})"]


def api_spec(rng: random.Random) -> dict:
    return {"call": rng.choice(API_CALLS), "value": rng.choice(API_VALUES)}


def run_api(where: Path, spec: dict) -> tuple[str, str]:
    """One public function of the API given a hostile argument: mechbook's own error (or a
    TypeError for an unknown keyword, as Python's own), or a result; never another
    exception, a hang or a huge allocation."""
    import numpy as np

    import mechbook
    from mechbook.errors import MechbookError

    tree = _tree(where)
    guard = Guard(where)
    p = mechbook.load("lim-2101", root_dir=tree)
    call = spec["call"].format(v=spec["value"])
    env = {"p": p, "mechbook": mechbook, "np": np, "inf": float("inf"), "nan": float("nan")}
    cwd = os.getcwd()
    os.chdir(where)
    try:
        eval(call, env)  # noqa: S307 - the fuzzer's own call text, not input
    except MechbookError as exc:
        return _refused(exc)
    except FileNotFoundError as exc:  # results() of a path with no store: documented
        return "refused", str(exc)
    except Exception as exc:  # noqa: BLE001
        return _crash(exc)
    finally:
        os.chdir(cwd)
    moved = guard.changed()
    if moved:
        return "outside", moved
    return "ok", call[:200]


GENERATORS = {"velocity": velocity_spec, "periods": periods_spec, "schema": schema_spec,
              "lastfailed": lastfailed_spec, "patterns": patterns_spec, "api": api_spec}
RUNNERS = {"velocity": run_velocity, "periods": run_periods, "schema": run_schema,
           "lastfailed": run_lastfailed, "patterns": run_patterns, "api": run_api}
