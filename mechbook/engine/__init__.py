"""The engine: everything derived from a system, lazily and without simplification unless a
reader asks (mechbook solve).

    lagrange    Lagrange's and Hamilton's equations, momenta, conservation (Dynamics)
    equilibria  static equilibria, and the linearization about a point
    linear      the linear system about a point: frequencies, modes, stability
    routh       Routh's reduction about a steady motion
    phase       the phase-space flow in (q, p)
    analysis    one problem's results, cached per system and point (what checks pull from)
    response    linear response: complex exponents and modes, decay rates, harmonic
                response, forced initial-value motion, Jordan blocks (secular growth)
    steady      steady motions in general: residuals of a uniform motion, counts at fixed
                rates or momenta, stability at a numerically found one
    perturbation  perturbation theory's objects exactly (50 digits): unperturbed normal
                coordinates, W', exact eigenpairs, shifted equilibria
    derive      results as text for a reader, and the summary a check run stores

May import: mechbook.model, mechbook.core, mechbook.errors, mechbook.records.
"""
