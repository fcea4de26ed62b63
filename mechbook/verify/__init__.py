"""Verification: the book's answer keys against the engine, one outcome per part.

    answers     answer keys: loading, against a table of quantities (the built-in one
                unless a caller passes its own)
    part        an answer key and its parts: records (frozen parts), names and parsing
    compare     deciding agreement: numerically at random admissible points, symbolically
                on request (ProofPolicy)
    context     what a part is checked in: system, names, sampler, point
    registration  a quantity's entry, a module's Family, the QuantityTable (a leaf the
                checks import)
    registry    the built-in table, built from the quantity modules it lists; a table's
                key schema; the doc table
    instances   generic tensors for statements "for all", and deciding identities on
                random instances (exact or 30-digit) with a symbolic attempt
    quantities  the checks, one module per family of quantities
    wellformed  validate_key: every part's names and expressions, before any is checked
    checker     check_problem, the one check loop: outcomes pass / fail / erratum /
                unsupported / error

May import: mechbook.numerics (trajectory quantities measured by integration),
mechbook.engine, mechbook.model, mechbook.core, mechbook.errors, mechbook.records.
"""
