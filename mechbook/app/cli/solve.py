"""`mechbook solve`: a problem's derived results, simplified for a reader."""

from __future__ import annotations

import click

from mechbook.app.cli.common import numeric_text, problem_id_argument, resolve_root, system_option
from mechbook.app.cli.statuses import failure
from mechbook.errors import MechbookError


@click.command("solve")
@problem_id_argument()
@system_option()
@click.option("--no-simplify", is_flag=True, help="Skip SymPy simplification (faster).")
@click.pass_context
def command(ctx: click.Context, problem_id: str, system: str | None, no_simplify: bool) -> None:
    """Derive and print a problem's results (what its `compute:` asks for), simplified."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.api import load
    from mechbook.engine.continuum import field_equation, squared_frequencies
    from mechbook.engine.derive import declared_results, derive

    base = resolve_root(ctx)
    try:
        problem = load(problem_id, base, simplify=not no_simplify)
        names = [system] if system else problem.systems
        click.echo(f"{problem.id}: {problem.title}  [{problem.source}]")
        for name in names:
            res = derive(problem.analysis, name)
            if len(problem.systems) > 1:
                click.echo(f"\n== system {name}")
            for key, text in res.text.items():
                click.echo(f"{key}:\n    {text}")
            for key, arr in res.arrays.items():
                if not key.endswith("/growth_rates"):
                    click.echo(f"{key} (numeric, default parameters):\n    "
                               f"{numeric_text(key, arr, res.arrays)}")
            for key, text in res.notes.items():
                click.echo(f"{key}: {text}")
        field = problem.analysis.built.field()
        if field is not None:  # a continuous field: its equation and lowest frequencies
            click.echo(f"\n== field {field.name} on a {field.domain}")
            click.echo(f"field equation:\n    {field_equation(field)} = 0")
            point = problem.analysis.problem.values()
            try:
                lams = squared_frequencies(field, point, 6)
                click.echo("frequencies (numeric, default parameters):\n    " +
                           ", ".join(f"{float(v) ** 0.5:.10g}" for v in lams))
            except MechbookError as exc:
                click.echo(f"frequencies: {exc}")
        if (not names and field is None) or any(k in problem.model.doc.data
                                                for k in ("vectors", "tensors", "bodies")):
            problem.analysis.declared()  # a problem's own vectors, tensors and bodies
            res = declared_results(problem.analysis)
            click.echo("\n== declared vectors, tensors and bodies")
            for key, text in res.text.items():
                click.echo(f"{key}:\n    {text}")
    except (MechbookError, KeyError) as exc:
        raise failure(exc) from None
