"""Independent cross-checks of the engine, run beside the answer key's checks.

None of them looks at the book's answers. Which of them vouch for a part is declared by its
quantity's registration (`crosschecks=`, names in vouch.py):
    frequencies  normal frequencies measured from a simulation of the nonlinear equations
                 (modal.py: the modes and how they sit in the full model)
    newton       the engine's equations against Newton's and Euler's laws, with kinematics
                 computed here independently (kinematics.py)
    conserved    the book's first integrals constant along a simulated trajectory
    response     a steady-state amplitude measured from the driven nonlinear motion
                 (frequencies.py also measures damped modes' decay rates)
    amplitude    the frequency measured at a finite amplitude (for `mechbook sweep
                 --quantity drift`: where the linear answer stops being good)
    motion       steady motions kept by a simulation; trajectory quantities of the level
                 set measured by integration
    inertia      each declared body's inertia: the engine's table and parallel axes against
                 integration over its parts (assembly.py)
A problem's checks are chosen and ordered in problem.py (points.py: one frequency check per
distinct point); each runs under the one guard of guard.py, which decides n.a. vs error;
what they read of an answer part goes through partview.py, the one door into verify.

May import: mechbook.verify (how an answer part names its point: `about:`, `steady:`,
`assume:`, through partview.py), mechbook.numerics, mechbook.engine (the results under
test), mechbook.core, mechbook.model — but never the engine's kinematics
`mechbook.model.bodies` (a test enforces it). Outcomes (mechbook.records.Status): pass ·
fail · n.a. (does not apply, with the reason) · error (the check itself could not run:
counts as a fail).
"""

from __future__ import annotations

from mechbook.crosscheck.problem import crosscheck_problem

__all__ = ["crosscheck_problem"]
