"""Foundations shared by every stage: time limits (timeout), fast numeric evaluation with a
cancellation scale and numeric zero tests (numeval), the compile layer turning SymPy
expressions into fast functions (compile; its backends' names: backends), and Taylor
expansion of a Lagrangian (expansion), optional dependencies imported with the
install line when missing (optional), counts in words (words: plural).

May import: mechbook.errors, mechbook.records. Nothing else of mechbook.
"""
