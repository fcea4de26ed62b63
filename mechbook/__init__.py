"""mechbook: textbook mechanics problems as declarative Lagrangian systems, checked."""

__version__ = "0.1.0"
