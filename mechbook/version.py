"""The version, in a module of its own: every stage may read it without importing the
package, whose __init__ reaches up to the application (lazily)."""

__version__ = "0.1.0"
