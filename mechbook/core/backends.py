"""The compile layer's backends by name, in the order one hands over to the next
(mechbook.core.compile). A module of its own, importing nothing, so that the command line
offers them as choices without loading SymPy or NumPy."""

BACKENDS = ("llvm", "symengine", "sympy")
DEFAULT_BACKEND = "llvm"
