"""Results that show themselves as mathematics in a notebook, and stay plain lists and dicts.

`p.eom` is a list of equations and `p.momenta` a dict: Jupyter printed them as text (only a
lone SymPy object has its own LaTeX). `MathList` and `MathDict` are a list and a dict in
every way (equality, indexing, JSON of their items) that also give Jupyter LaTeX (one item
per row, aligned) and MathML (mechbook.app.output.mathml, the report's printer). A `MathDict`
keyed by symbols is indexed by their names too (`p.equilibria[0]["theta"]`), as `about=`
takes them.
"""

from __future__ import annotations

import sympy as sp

from mechbook.app.output.mathml import math


def _latex(item) -> str:
    if isinstance(item, dict):
        return r",\ ".join(f"{_latex(k)} = {_latex(v)}" for k, v in item.items())
    return sp.latex(item)  # SymPy objects and Python numbers alike


class MathList(list):
    """A list of SymPy objects (equations, frequencies) drawn as mathematics."""

    def _repr_latex_(self) -> str:
        if not self:
            return r"$\emptyset$"
        rows = r" \\ ".join(_latex(item) for item in self)
        return r"$\displaystyle \begin{gathered}" + rows + r"\end{gathered}$"

    def _repr_html_(self) -> str:
        return math(list(self))


class MathDict(dict):
    """A mapping (coordinate: momentum, coordinate: value) drawn as equations; `label`
    names what a key's value is (the momentum p_θ of the coordinate θ) for the drawing."""

    def __init__(self, *args, label=None, **kwargs):
        super().__init__(*args, **kwargs)
        self._label = label

    def _key(self, key):
        """A name stands for the symbol of that name (`about=` takes names too), as long
        as the dict has no key that is the name itself."""
        if isinstance(key, str) and not dict.__contains__(self, key):
            for k in self:
                if isinstance(k, sp.Symbol) and k.name == key:
                    return k
        return key

    def __getitem__(self, key):
        return super().__getitem__(self._key(key))

    def __contains__(self, key) -> bool:
        return super().__contains__(self._key(key))

    def get(self, key, default=None):
        return super().get(self._key(key), default)

    def _shown(self) -> dict:
        if self._label is None:
            return dict(self)
        return {self._label(k): v for k, v in self.items()}

    def _repr_latex_(self) -> str:
        if not self:
            return r"$\emptyset$"
        rows = r" \\ ".join(f"{_latex(k)} &= {_latex(v)}" for k, v in self._shown().items())
        return r"$\displaystyle \begin{aligned}" + rows + r"\end{aligned}$"

    def _repr_html_(self) -> str:
        return math(self._shown())
