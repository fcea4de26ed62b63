"""JSON-Schema validation of problem and answer files, with errors that name file and line."""

from __future__ import annotations

import json
from functools import cache
from importlib import resources

import jsonschema

from mechbook.model.yamlio import Document


@cache
def bundled(name: str) -> dict:
    """The bundled JSON Schema `name` ('problem', or 'answers': the base that
    mechbook.verify.registry completes with the registered quantities)."""
    text = resources.files("mechbook.model").joinpath("schemas", f"{name}.json") \
        .read_text("utf-8")
    return json.loads(text)


def validate(doc: Document, schema: dict | str) -> None:
    """Raise SpecError for the first (deepest, then earliest) schema violation in `doc`."""
    if isinstance(schema, str):
        schema = bundled(schema)
    validator = jsonschema.Draft202012Validator(schema)
    errors = list(validator.iter_errors(doc.data))
    if not errors:
        return
    best = jsonschema.exceptions.best_match(errors, key=_relevance)
    # best_match descends into oneOf branches; report the leaf that is most specific
    path = tuple(best.absolute_path)
    if best.validator == "additionalProperties" and isinstance(best.instance, dict):
        extra = sorted(set(best.instance) - set(best.schema.get("properties", {})))
        if extra:  # point at the offending key's own line
            line = doc.line(path + (extra[0],))
            err = doc.error(path, _message(best))
            err.line = line
            raise type(err)(err.bare, doc.file, line)
    if _is_key_rule(best):  # a key that does not apply to the part's quantity
        key = best.instance
        part = doc.data
        for p in path:
            part = part[p]
        line = doc.line(path + (key,))
        message = (f"key {key!r} does not apply to quantity {part.get('quantity')!r} "
                   f"(its keys: {', '.join(best.validator_value)})")
        err = doc.error(path, message)
        raise type(err)(err.bare, doc.file, line)
    raise doc.error(path, _message(best))


def _is_key_rule(error: jsonschema.ValidationError) -> bool:
    return error.validator == "enum" and "propertyNames" in error.schema_path


def _relevance(error: jsonschema.ValidationError):
    key = jsonschema.exceptions.relevance(error)
    return (not _is_key_rule(error), *key) if isinstance(key, tuple) else key


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
