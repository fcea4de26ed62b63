"""`python -m mechbook`: the command line.

Ctrl-C during the imports, before the command line's own handler is there, ends the same
way as after: one line and status 130 (mechbook.app.cli.INTERRUPTED), never a traceback.
"""

import sys


def run() -> None:
    """The entry point: the command line, with an interrupt at any moment ending in 130."""
    try:  # imported here, inside the handler: a Ctrl-C during the imports is caught too
        from mechbook.app.cli import main

        main(prog_name="mechbook")
    except KeyboardInterrupt:
        sys.stderr.write("\ninterrupted\n")
        sys.exit(130)


if __name__ == "__main__":
    run()
