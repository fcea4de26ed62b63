"""The problem model: problem files read safely and turned into symbols and a Lagrangian.

    yamlio    YAML with line numbers, duplicate keys refused
    limits    input limits: file size, no YAML aliases or tags, depth, counts (hostile input)
    schema    JSON-Schema validation with file:line errors (schemas/*.json)
    expr      the safe expression parser (never eval)
    constants is a constant finite and real? (in double precision: cannot hang)
    catalog   where problem and answer files live, problem ids
    problem   a problem file: parameters, conditions, its systems as data
    system    one system built: coordinates, T, V, L, forces, constraints
    bodies    rigid bodies: standard shapes' inertia, kinetic energy, Euler-angle rates

May import: mechbook.core, mechbook.errors, mechbook.records.
"""
