"""User errors are MechbookError subclasses with a clear message (file:line where there is
one), never a bare KeyError or ValueError and never a traceback (issue: contracts by
imitation)."""

from __future__ import annotations

import pytest
from hostile import ROOT, pendulum_tree, run

from mechbook.errors import InputError, MechbookError, NotFoundError


def test_an_unknown_system_is_a_mechbook_error_that_reads_as_its_message():
    from mechbook.model.problem import load_problem
    from mechbook.model.system import system_of

    problem = load_problem(ROOT / "problems" / "lim" / "2032.yaml")
    with pytest.raises(NotFoundError) as info:
        system_of(problem, "nosuch")
    exc = info.value
    assert isinstance(exc, MechbookError) and isinstance(exc, KeyError)  # old callers too
    assert str(exc) == "lim-2032 has no system 'nosuch' (has free, driven)"  # not quoted


def test_the_python_api_names_the_systems_and_coordinates_there_are():
    import mechbook

    p = mechbook.load("lim-2032", ROOT)
    with pytest.raises(NotFoundError, match=r"lim-2032 has no system 'nosuch' \(free, driven\)"):
        p.system("nosuch")
    with pytest.raises(MechbookError, match="has several systems"):
        p.system()
    with pytest.raises(NotFoundError, match="'nosuch' is not a coordinate of lim-2032"):
        p.system("free").frequencies(about={"nosuch": 0})


def test_the_command_line_says_which_systems_there_are_without_quotes_or_traceback(tmp_path):
    base = pendulum_tree(tmp_path)
    res = run("--root", base, "solve", "lim-2101", "--system", "nosuch")
    assert res.exit_code != 0
    assert "Error: lim-2101 has no system 'nosuch' (has main)\n" in res.output
    assert "Traceback" not in res.output and '"lim-2101' not in res.output


def test_an_answer_part_naming_no_such_system_is_an_error_at_its_line(tmp_path):
    base = pendulum_tree(tmp_path)
    key = base / "answers" / "lim" / "2101.yaml"
    key.write_text(key.read_text() + "  - part: b\n    cite: t\n    quantity: eom\n"
                   "    system: nosuch\n    book: [\"l*thetaddot + g*sin(theta) = 0\"]\n")
    res = run("--root", base, "check", "--serial", "--no-crosscheck", "--no-store")
    assert "2101.yaml:11: parts/1/system: lim-2101 has no system 'nosuch' (has main)" \
        in res.output
    assert "Traceback" not in res.output and "KeyError" not in res.output


def test_a_particle_or_body_that_is_not_there_names_those_that_are():
    from mechbook.engine.parts import part_energy
    from mechbook.model.problem import load_problem
    from mechbook.model.system import system_of

    sys = system_of(load_problem(ROOT / "problems" / "lim" / "2031.yaml"))
    with pytest.raises(NotFoundError, match=r"no particle or rigid body 'nosuch' in system "
                                            r"'main' \(its parts: "):
        part_energy(sys, "nosuch")


def test_a_declared_body_that_is_not_there_names_those_that_are():
    from mechbook.crosscheck.assembly import composite_inertia
    from mechbook.model.problem import load_problem

    problem = load_problem(ROOT / "problems" / "symon" / "10-29.yaml")
    with pytest.raises(NotFoundError, match=r"no body 'nosuch' declared \(declared: "):
        composite_inertia(problem, "nosuch")


@pytest.mark.parametrize("text, message", [
    ("omega", "expected NAME=LO:HI:N"),
    ("omega=a:2:3", "LO and HI must be numbers"),
    ("omega=1:2:3:lin", "the fourth field may only be 'log'"),
    ("omega=0:2:3:log", "a log axis needs LO, HI > 0"),
])
def test_a_sweep_axis_that_does_not_read_is_an_input_error(text, message):
    from mechbook.engine.sweep import parse_axis

    with pytest.raises(InputError, match=message) as info:
        parse_axis(text)
    assert isinstance(info.value, MechbookError) and isinstance(info.value, ValueError)


def test_the_sweep_command_says_what_an_axis_should_look_like(tmp_path):
    res = run("--root", ROOT, "sweep", "lim-2031", "--quantity", "stability", "--about",
              "theta=pi", "--param", "omega=1:2", "--no-store")
    assert res.exit_code != 0 and "expected NAME=LO:HI:N" in res.output
    assert "Traceback" not in res.output
