"""Text out: what a check prints and writes, and mathematics as MathML.

    text       strings made safe for each output: HDF5, JSON, XML and a terminal
    console    a check's progress on stderr and its table of outcomes
    formats    check results as JSON (schemas/check-result.json) and JUnit XML
    mathml     SymPy expressions as MathML (the report, notebooks)
    linebreak  long formulas broken into lines that fit a column

Import each part from its module (`from mechbook.app.output.text import for_terminal`):
this `__init__` imports nothing, since the command line reads `text` at start-up and must
not load SymPy for `mathml`.

May import: the stages below mechbook.app and its shared modules (outputs, bounded); nothing else of
mechbook.app: every other package writes through it.
"""
