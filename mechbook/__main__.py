"""`python -m mechbook`: the command line.

Ctrl-C during the imports, before the command line's own handler is there, ends the same
way as after: one line and status 130 (mechbook.app.cli.INTERRUPTED), never a traceback.
"""

import sys

INTERRUPTED = 130  # as mechbook.app.cli.statuses.INTERRUPTED (not imported: it may be where
# the interrupt lands)


def run() -> None:
    """The entry point: the command line, with an interrupt at any moment ending in 130."""
    try:  # imported here, inside the handler: a Ctrl-C during the imports is caught too
        from mechbook.app.cli import main

        main(prog_name="mechbook")
    except KeyboardInterrupt:
        sys.stderr.write("\ninterrupted\n")
        _forget_the_interrupt()
        sys.exit(INTERRUPTED)
    except SystemExit as exc:
        if exc.code == INTERRUPTED:
            _forget_the_interrupt()
        raise


def _forget_the_interrupt() -> None:
    """Clear CPython's note of an unhandled KeyboardInterrupt, so that the status is 130.

    CPython (3.8 to 3.13) notes a KeyboardInterrupt that ends any string `exec`/`eval`,
    even one caught afterwards, and a `python -m` run whose interrupt passed through one
    then kills itself with SIGINT as it exits, whatever status it chose: its parent saw
    -2, not 130 (dataclasses, namedtuple and SymPy's lambdify build functions that way: a
    Ctrl-C during an import of a dataclass did it). The note is cleared at the start of
    each string evaluation; an empty one clears it and does nothing else."""
    exec("", {})  # a constant, empty program: nothing of any input reaches it


if __name__ == "__main__":
    run()
