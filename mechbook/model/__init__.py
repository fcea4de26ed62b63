"""The problem model: problem files read safely and turned into symbols and a Lagrangian.

    yamlio    YAML with line numbers, duplicate keys refused
    limits    input limits: file size, no YAML aliases or tags, depth, counts (hostile input)
    schema    JSON-Schema validation with file:line errors (schemas/*.json)
    expr      the safe expression parser (never eval)
    constants is a constant finite and real? (in double precision: cannot hang)
    tensorexpr  the same parser for vectors and tensors (and bodies' functions)
    tensorfuncs the whitelisted functions of tensor expressions
    ids       problem ids <book>-<number>: the one grammar (split_id, check_id)
    books     books.yaml: the declared books, an id's book and number checked against them
    catalog   where problem and answer files live (an id parsed once per lookup)
    problem   a problem file: parameters, conditions, its systems as data
    protocol  SystemLike: what a system offers the engine (kept by System and by Routh's
              reduced system: `reduced`, `full`, `held_momenta`, `held`)
    system    one system built: coordinates, T, V, L, forces, constraints
    declared  a problem's named vectors, bodies made of parts, named tensors
    bodies    rigid bodies: standard shapes' inertia, bodies of parts, kinetic energy
              (a package)
    attitude  attitude charts: chains of elementary rotations, rotation matrix, body rates
    loads     torques as generalized forces, attracting point masses, averaging over an angle
    friction  sliding (Coulomb) friction at a contact: sliding velocity, the sliding law's
              generalized forces, what the stick-slip integrator needs
    field     a string's displacement field as names (u, udot, x, integral())

May import: mechbook.core, mechbook.errors, mechbook.records.
"""
