"""`mechbook show`: a problem's results and checks read back from the HDF5 store."""

from __future__ import annotations

from pathlib import Path

import click

from mechbook.app.cli.common import (
    in_tree,
    numeric_text,
    problem_id_argument,
    say,
    store_option,
)
from mechbook.app.cli.statuses import failure
from mechbook.errors import MechbookError
from mechbook.model.catalog import check_id


@click.command("show")
@problem_id_argument()
@store_option("HDF5 file to read.")
@click.pass_context
def command(ctx: click.Context, problem_id: str, store_path: Path) -> None:
    """Print a problem's stored results and checks, read back from the HDF5 store."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.store import read

    path = in_tree(ctx, store_path)
    try:
        rec = read(check_id(problem_id), path)
    except MechbookError as exc:  # a malformed id: a usage error (statuses.TABLE)
        raise failure(exc) from None
    except FileNotFoundError as exc:  # no store at all; a problem not in it: NotFoundError
        raise click.ClickException(str(exc)) from None
    if rec.get("checked", True):
        _results(problem_id, rec)
        _checks(rec)
    else:
        say(f"{problem_id}: no check is stored, only simulations (`mechbook check "
            f"{problem_id}` stores one)")
    for name in rec.get("simulations", []):
        say(f"simulation stored: /problems/{problem_id}/simulations/{name}")
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.sweep.storage import stored_sweeps

    for name, text in stored_sweeps(problem_id, path):  # a damaged entry is said so
        say(f"sweep stored: /sweeps/{problem_id}/{name}: {text}")


def _results(problem_id: str, rec: dict) -> None:
    a = rec["attrs"]
    say(f"{problem_id}: {a.get('title')}  [{a.get('source')}]")
    say(f"stored {a.get('date')} by mechbook {a.get('mechbook')} (SymPy {a.get('sympy')}, "
        f"NumPy {a.get('numpy')}); {a.get('duration_s', 0):.1f} s; problem sha256 "
        f"{str(a.get('problem_sha256'))[:12]}")
    for sname, entry in rec["systems"].items():
        say(f"\n== system {sname}")
        for key, text in entry["symbolic"].items():
            say(f"{key}: {text}")
        for key, arr in entry["numeric"].items():
            if not key.endswith("/growth_rates"):
                say(f"{key} (numeric): {numeric_text(key, arr, entry['numeric'])}")
        for key, text in entry["notes"].items():
            say(f"{key}: {text}")


def _checks(rec: dict) -> None:
    say("\n== checks")
    for c in rec["checks"]:
        say(f"{c['part']:<16} {c['quantity']:<20} {c['status']:<12} {c['method']} "
            f"{c['detail']}".rstrip())
    if rec.get("crosschecks"):
        say("\n== cross-checks")
        for x in rec["crosschecks"]:
            parts = ", ".join(x.get("parts") or []) or "-"
            say(f"{x['name']} [{x['status']}, error {x.get('error', float('nan')):.1e}; "
                f"parts: {parts}] {x.get('detail', '')}")
