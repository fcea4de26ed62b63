"""Answers given in words (`force` along a trajectory, `proof`): not checkable yet, so
always reported unsupported with the capability they lack.
"""

from __future__ import annotations

from mechbook.errors import UnsupportedError
from mechbook.verify.compare import Verdict
from mechbook.verify.context import Context
from mechbook.verify.registration import Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity


@quantity('force',
          book='—',
          how=('unsupported so far: constraint forces along a trajectory (multipliers '
               'combined with a first integral)'))
def check_force(ctx: Context, val) -> Verdict:
    raise UnsupportedError("constraint forces along a trajectory (Lagrange multipliers "
                           "combined with a first integral)")


@quantity('proof',
          book='—',
          how='unsupported: a proof in words')
def check_proof(ctx: Context, val) -> Verdict:
    raise UnsupportedError("a proof in words")
