"""Verification: the book's answer keys against the engine, one outcome per part.

    answers     answer keys: loading (which registers every quantity)
    part        one part of a key: its names and parsing (plain data, under the checks)
    compare     deciding agreement: numerically at random admissible points, symbolically
                on request (ProofPolicy)
    context     what a part is checked in: system, names, sampler, point
    registration  a quantity's entry and the decorator (a leaf the checks import)
    registry    every answer quantity: name -> check, schema fragment, doc line
    instances   generic tensors for statements "for all", and deciding identities on
                random instances (exact or 30-digit) with a symbolic attempt
    quantities  the checks, one module per family of quantities
    checker     running a key: outcomes pass / fail / erratum / unsupported / error

May import: mechbook.numerics (trajectory quantities measured by integration),
mechbook.engine, mechbook.model, mechbook.core, mechbook.errors, mechbook.records.
"""
