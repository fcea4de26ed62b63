"""The engine: everything derived from a system, lazily and without simplification unless a
reader asks (mechbook solve).

    lagrange    Lagrange's and Hamilton's equations, momenta, conservation (Dynamics)
    equilibria  static equilibria, and the linearization about a point
    linear      the linear system about a point: frequencies, modes, stability
    routh       Routh's reduction about a steady motion
    steady      steady motions: residuals of a uniform motion, conditions at fixed rates or
                momenta, a family's real rates and their existence, effective potential
    steady_search  steady motions found numerically: counts in a region, each one's
                stability
    levelset    the motion on a level set of the first integrals, reduced to one coordinate
    phase       the phase-space flow in (q, p)
    analysis    one problem's results, cached per system and point (what checks pull from)
    response    linear response: complex exponents and modes, decay rates, harmonic
                response, forced initial-value motion, Jordan blocks (secular growth)
    perturbation  perturbation theory's objects exactly (50 digits): unperturbed normal
                coordinates, W', exact eigenpairs, shifted equilibria
    sweep       a linear system over a grid of parameters: compiled once, stacked
                eigensolvers, the 30-digit path at single points
    derive      results as text for a reader, and the summary a check run stores
    extremum    where a function is largest or smallest (one variable, 30 digits; a torus
                of phases)
    parts       the energy of one part of a system along the linearized motion
    access      whether a configuration is reached on a level set of the first integrals
    adiabatic   the action of a frozen oscillation, and a simulated slow change

May import: mechbook.model, mechbook.core, mechbook.errors, mechbook.records.
"""
