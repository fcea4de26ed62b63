"""JSON-Schema validation of problem and answer files, with errors that name file and line."""

from __future__ import annotations

import json
from functools import cache
from importlib import resources

import jsonschema

from mechbook.model.hints import did_you_mean
from mechbook.model.ids import BOOK
from mechbook.model.ids import PATTERN as ID_PATTERN
from mechbook.model.yamlio import Document


@cache
def bundled(name: str) -> dict:
    """The bundled JSON Schema `name` ('problem', or 'answers': the base that
    mechbook.verify.registry completes with the registered quantities)."""
    text = resources.files("mechbook.model").joinpath("schemas", f"{name}.json") \
        .read_text("utf-8")
    schema = json.loads(text)
    if name == "problem":  # the id grammar has one owner (mechbook.model.ids)
        # ends with "no character follows", not `$`: Python's `$` also matches before a
        # final newline, and `\Z` is Python's alone (ECMA-262 has neither meaning)
        schema["properties"]["id"]["pattern"] = f"^{ID_PATTERN}(?![\\s\\S])"
    elif name == "books":
        schema["$defs"]["book"]["properties"]["id"]["pattern"] = f"^{BOOK}$"
    return schema


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
    """The violation in words, with the likely fix (the nearest allowed name, or the
    indentation when a mapping came out empty or as text)."""
    if error.validator == "additionalProperties":
        known = error.schema.get("properties", {})
        extra = sorted(set(error.instance) - set(known))
        empty = [k for k, v in error.instance.items() if v is None and k in known]
        if empty:  # `parameters:` with its entries not indented under it
            return (f"unknown key(s) {', '.join(map(repr, extra))} beside the empty "
                    f"{empty[0]!r}: if they belong under {empty[0]!r}, indent them "
                    "(further right than it)")
        hint = did_you_mean(extra[0], known) if len(extra) == 1 else ""
        if hint:
            return f"unknown key {extra[0]!r}; {hint}"
        allowed = ", ".join(sorted(known))
        return f"unknown key(s) {', '.join(map(repr, extra))}; allowed: {allowed}"
    if error.validator == "required":
        return error.message.replace("is a required property", "is required")
    if error.validator == "enum":
        choices = [str(c) for c in error.validator_value]
        hint = did_you_mean(str(error.instance), choices) if isinstance(error.instance, str) \
            else ""
        if hint:
            return f"{error.instance!r} is not one of the {len(choices)} allowed; {hint}"
        return f"{error.instance!r} is not one of {error.validator_value}"
    if error.validator == "type" and _wants_collection(error.validator_value):
        where = str(error.absolute_path[-1]) if error.absolute_path else "the file"
        kind = "a list" if _wants(error.validator_value, "array") and \
            not _wants(error.validator_value, "object") else "a mapping"
        if error.instance is None:
            return (f"{where!r} is empty, but {kind} is expected here: if its entries "
                    "follow, indent them under it (further right than "
                    f"{where!r})")
        if isinstance(error.instance, str | int | float):
            return (f"{error.instance!r} is a single value, but {kind} is expected under "
                    f"{where!r}: write its entries on the lines below, indented, or in "
                    "braces {...} / brackets [...]")
    return error.message


def _wants(types, name: str) -> bool:
    return name == types or (isinstance(types, list) and name in types)


def _wants_collection(types) -> bool:
    return (_wants(types, "object") or _wants(types, "array")) and not _wants(types, "null")
