"""The compile layer's backends by name, in the order one hands over to the next
(mechbook.core.compile). A module of its own, importing nothing, so that the command line
offers them as choices without loading SymPy or NumPy."""

BACKENDS = ("llvm", "symengine", "sympy")
DEFAULT_BACKEND = "llvm"

# A function evaluated at a few dozen points (a cross-check's random states): SymEngine's
# interpreter builds it five to ten times sooner than LLVM compiles it, and the calls it
# costs more (~5 µs against ~3 µs) are fewer than the milliseconds it saves.
FEW_CALLS_BACKEND = "symengine"
