"""Which cross-checks vouch for a part: the names its quantity's registration declares."""

from __future__ import annotations

from mechbook.verify.registry import default_quantities

# the names a registration's `crosschecks=` may hold, and what each runs
CROSSCHECKS = {
    "newton": "the system's equations against Newton's and Euler's laws (newton.py)",
    "modes": "the frequencies at the part's point measured by simulation (frequencies.py)",
    "response": "the steady amplitude measured from the driven motion (response.py)",
    "first_integrals": "the named first integrals constant along a run (conserved.py)",
    "energy_integral": "the part's energy function or Hamiltonian constant along a run",
    "steady": "each steady rate kept by a simulation of the full equations (motion.py)",
    "trajectory": "the turning points of the level set measured by integration (motion.py)",
    "trajectory_period": "with `trajectory`: the period measured too",
    "trajectory_advance": "with `trajectory`: a coordinate's advance per period measured too",
}


def crosschecks_of(quantity: str) -> tuple[str, ...]:
    """The cross-checks the registration of `quantity` declares (none for an unknown one)."""
    entry = default_quantities().get(quantity)
    return entry.crosschecks if entry is not None else ()
