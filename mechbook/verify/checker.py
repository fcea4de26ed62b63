"""Running an answer key against the engine: one outcome per part (the one check loop: the
command line, the Python API and the tests all call `check_problem`, after `validate_key`,
mechbook.verify.wellformed).

Outcomes: pass · fail · erratum (the book's value fails, the key's corrected value passes and
the key carries the derivation) · unsupported (the engine cannot compute it yet; never a pass)
· error (the part could not be evaluated: a malformed key or an engine fault; counts as fail).
"""

from __future__ import annotations

import time
from collections.abc import Callable

from mechbook.engine.analysis import Analysis
from mechbook.errors import (
    MechbookError,
    SpecError,
    UnsupportedError,
    WrongAnswerError,
    describe,
)
from mechbook.records import Outcome, Status
from mechbook.verify.answers import AnswerKey, Part
from mechbook.verify.compare import NUMERIC, ProofPolicy
from mechbook.verify.context import Context
from mechbook.verify.proof import unproved_reason
from mechbook.verify.registration import QuantityTable

Stage = Callable[[str], None]  # told the stage a check is in, e.g. "part a (frequencies)"


def check_part(analysis: Analysis, part: Part, policy: ProofPolicy = NUMERIC,
               quantities: QuantityTable | None = None, stage: Stage | None = None) -> Outcome:
    """The part's outcome (never raises for the part's own faults: they are its outcome).
    `quantities`: the table to check with (default: the one its key was read against);
    `stage`: told the progress of a long computation inside the part."""
    start = time.perf_counter()
    out = Outcome(analysis.problem.id, part.name, part.quantity, part.data["cite"], Status.ERROR,
                  origin=part.data.get("origin", "book"))
    try:
        if "unsupported" in part.data:
            out.status, out.detail = Status.UNSUPPORTED, part.data["unsupported"]
            return out
        ctx = Context(analysis, part, policy, quantities=quantities, stage=stage)
        fn = ctx.quantity.check
        verdict = fn(ctx, part.data.get("book"))
        if "erratum" in part.data:
            corrected = fn(ctx, part.data["erratum"]["corrected"])
            if verdict.ok:
                out.status = Status.FAIL
                out.detail = "an erratum is recorded but the book's value agrees with the engine"
            elif not corrected.ok:
                out.status = Status.FAIL
                out.detail = f"the corrected value fails too: {corrected.detail}"
            else:
                out.status, out.method = Status.ERRATUM, _method(corrected, policy)
                out.detail = f"book value fails ({verdict.detail}); corrected value passes"
                out.power = _power(part, corrected)
        else:
            out.status = Status.PASS if verdict.ok else Status.FAIL
            out.method, out.detail = verdict.method, verdict.detail
            if verdict.ok:
                out.method = _method(verdict, policy)
            if verdict.ok:
                out.power = _power(part, verdict)
    except UnsupportedError as exc:
        out.status, out.detail = Status.UNSUPPORTED, exc.capability
    except WrongAnswerError as exc:  # the answer's point, steady rate or shape is wrong
        out.status, out.detail = Status.FAIL, str(exc)
    except SpecError as exc:
        out.status, out.detail = Status.ERROR, str(exc)
    except MechbookError as exc:
        out.status, out.detail = Status.ERROR, str(exc)
    except Exception as exc:  # an engine fault must not hide the other parts
        out.status = Status.ERROR
        out.detail = describe(exc)  # a message; the traceback goes to the debug log
    finally:
        out.seconds = time.perf_counter() - start
    return out


def _method(verdict, policy: ProofPolicy) -> str:
    """A pass's method; with --prove, one not proved says why ("numeric(6 points, …);
    unproved: holds floating-point numbers")."""
    if not policy.prove or verdict.method == "symbolic":
        return verdict.method
    why = getattr(verdict, "unproved", "") or unproved_reason(verdict.method)
    return f"{verdict.method}; unproved: {why}"


def _power(part: Part, verdict) -> str:
    """The pass's power in words: the verdict's own statement (or its method), and that a
    `partial:` answer leaves the rest of the engine's values unchecked."""
    power = verdict.power or verdict.method
    if part.data.get("partial") and "partial" not in power:
        power += "; partial: the book lists a subset, the rest is unchecked"
    return power


def require_same_problem(key: AnswerKey, problem_id: str) -> None:
    """SpecError at the key's `problem:` unless the key is for the problem `problem_id`."""
    if key.problem_id != problem_id:
        raise key.doc.error(("problem",), f"answer key is for {key.problem_id!r}, problem file "
                            f"is {problem_id!r}")


def check_problem(analysis: Analysis, key: AnswerKey, policy: ProofPolicy = NUMERIC,
                  stage: Stage | None = None,
                  quantities: QuantityTable | None = None) -> list[Outcome]:
    """One outcome per part of `key`, in order (the key must be for the analysed problem);
    `stage` is told "part NAME (QUANTITY)" before each part is checked, so a check stopped
    from outside says where it was. Validate the key first (`validate_key`): a malformed
    part comes out here as an error, but `mechbook check` refuses such a key whole."""
    require_same_problem(key, analysis.problem.id)
    outcomes = []
    for part in key.parts:
        if stage is not None:
            stage(f"part {part.name} ({part.quantity})")
        outcomes.append(check_part(analysis, part, policy, quantities, stage))
    return outcomes
