"""`python -m mechbook`: the command line."""

from mechbook.app.cli import main

main(prog_name="mechbook")
