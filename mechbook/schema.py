"""JSON-Schema validation of problem and answer files, with errors that name file and line."""

from __future__ import annotations

import json
from functools import cache
from importlib import resources

import jsonschema

from .yamlio import Document


@cache
def schema(name: str) -> dict:
    """The bundled JSON Schema `name` ('problem' or 'answers')."""
    text = resources.files("mechbook").joinpath("schemas", f"{name}.json").read_text("utf-8")
    return json.loads(text)


def validate(doc: Document, name: str) -> None:
    """Raise SpecError for the first (deepest, then earliest) schema violation in `doc`."""
    validator = jsonschema.Draft202012Validator(schema(name))
    errors = list(validator.iter_errors(doc.data))
    if not errors:
        return
    best = jsonschema.exceptions.best_match(errors)
    # best_match descends into oneOf branches; report the leaf that is most specific
    path = tuple(best.absolute_path)
    if best.validator == "additionalProperties" and isinstance(best.instance, dict):
        extra = sorted(set(best.instance) - set(best.schema.get("properties", {})))
        if extra:  # point at the offending key's own line
            line = doc.line(path + (extra[0],))
            err = doc.error(path, _message(best))
            err.line = line
            raise type(err)(err.bare, doc.file, line)
    raise doc.error(path, _message(best))


def _message(error: jsonschema.ValidationError) -> str:
    if error.validator == "additionalProperties":
        extra = sorted(set(error.instance) - set(error.schema.get("properties", {})))
        allowed = ", ".join(sorted(error.schema.get("properties", {})))
        return f"unknown key(s) {', '.join(map(repr, extra))}; allowed: {allowed}"
    if error.validator == "required":
        return error.message.replace("is a required property", "is required")
    if error.validator == "enum":
        return f"{error.instance!r} is not one of {error.validator_value}"
    return error.message
