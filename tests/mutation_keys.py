"""Which answer keys the two mutation tests run in which tier (tests/test_checker.py's
structural mutants, tests/test_power.py's 1 % mutants).

Every key, in `make test-mutation` (CI); a sample of six in `make test` (and, for the
structural mutants, `make test-quick`), chosen to cover both books, every chapter of
Symon's and scalar, tensor, constraint-force, turning-point and stability quantities.
"""

from __future__ import annotations

from pathlib import Path

import pytest

# the keys both mutation tests always run: both books, every chapter of Symon's, and scalar,
# tensor, constraint-force, turning-point and stability quantities
MUTATION_SAMPLE = {"lim-2041", "symon-09-12", "symon-10-15", "symon-11-03", "symon-11-22",
                   "symon-12-21"}


def per_key(answer_files: list[Path], *sample_marks: pytest.MarkDecorator) -> list:
    """One parameter per answer key for a mutation test: a key of MUTATION_SAMPLE with
    `sample_marks`, every other key marked `slow` and `mutation` (`make test-mutation`)."""
    names = {f"{p.parent.name}-{p.stem}": p for p in answer_files}
    missing = MUTATION_SAMPLE - set(names)
    assert not missing, f"a key of the mutation sample is gone, pick another: {missing}"
    return [pytest.param(p, id=name, marks=sample_marks if name in MUTATION_SAMPLE else
                         (pytest.mark.slow, pytest.mark.mutation))
            for name, p in names.items()]
