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
    from mechbook.engine.part_energy import part_energy
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
    from mechbook.engine.linear_grid import parse_axis

    with pytest.raises(InputError, match=message) as info:
        parse_axis(text)
    assert isinstance(info.value, MechbookError) and isinstance(info.value, ValueError)


def test_the_sweep_command_says_what_an_axis_should_look_like(tmp_path):
    res = run("--root", ROOT, "sweep", "lim-2031", "--quantity", "stability", "--about",
              "theta=pi", "--param", "omega=1:2", "--no-store")
    assert res.exit_code != 0 and "expected NAME=LO:HI:N" in res.output
    assert "Traceback" not in res.output


# ---- the store: a problem, a simulation or a sweep that is not there -----------------------
def _store(tmp_path, *groups: str):
    import h5py

    path = tmp_path / "s.h5"
    with h5py.File(path, "w") as f:
        f.attrs["format"] = 1  # what every mechbook store holds
        for g in groups:
            f.create_group(g)
    return path


def test_a_problem_not_in_the_store_names_those_that_are(tmp_path):
    from mechbook.app.store import read

    path = _store(tmp_path, "problems/lim-2031", "problems/lim-2032")
    with pytest.raises(NotFoundError) as info:
        read("lim-2033", path)
    assert isinstance(info.value, KeyError)  # old callers too
    assert str(info.value) == (f"lim-2033 is not in {path} (problems stored: lim-2031, "
                               "lim-2032); run `mechbook check lim-2033`")
    with pytest.raises(NotFoundError, match=r"\(no problem is stored\)"):
        read("lim-2033", _store(tmp_path))


def test_a_simulation_or_sweep_not_in_the_store_names_those_that_are(tmp_path):
    from mechbook.app.store import read_simulation
    from mechbook.app.sweep.storage import read_store

    path = _store(tmp_path, "problems/lim-2031/simulations/main-RK45", "sweeps/lim-2031/map")
    with pytest.raises(NotFoundError, match=r"^no simulation 'main-DOP853' of lim-2031 in .*"
                                            r" \(simulations stored: main-RK45\)$"):
        read_simulation("lim-2031", "main-DOP853", path)
    with pytest.raises(NotFoundError, match=r"\(no simulation is stored\)$"):
        read_simulation("lim-2032", "main-RK45", path)
    with pytest.raises(NotFoundError, match=r"^no sweep 'mop' of lim-2031 in .* \(sweeps "
                                            r"stored: map\)$"):
        read_store("lim-2031", "mop", path)
    with pytest.raises(NotFoundError, match=r"\(no sweep is stored\)$"):
        read_store("lim-2032", "map", path)


def test_many_stored_names_are_counted_and_the_nearest_named():
    from mechbook.app.store.reader import there

    names = [f"lim-20{n}" for n in range(28, 68)]
    assert there("lim-2063x", names, "problem") == "40 problems stored; did you mean 'lim-2063'?"
    assert there("xyz", names, "problem") == "40 problems stored"


def test_show_of_a_problem_not_in_the_store_is_a_clean_message(tmp_path):
    path = _store(tmp_path, "problems/lim-2031")
    res = run("--root", ROOT, "show", "lim-2032", "--store", path)
    assert res.exit_code == 1
    assert res.output == (f"Error: lim-2032 is not in {path} (problems stored: lim-2031); "
                          "run `mechbook check lim-2032`\n")


def test_check_of_a_problem_with_no_file_is_not_found(tmp_path):
    from mechbook.app.running.service import resolve_ids

    with pytest.raises(NotFoundError, match=r"^no problem lim-2013 \(no file .*2013\.yaml; "
                       r"`mechbook list` shows the problems there are\)$"):
        resolve_ids(["lim-2013"], ROOT)
    res = run("--root", ROOT, "check", "lim-2013", "--no-store")
    assert res.exit_code != 0 and "Traceback" not in res.output
    assert res.output.startswith("Error: no problem lim-2013 (no file ")
