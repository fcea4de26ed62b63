"""A fast first reading of a YAML file by libyaml (PyYAML's C parser), exact or nothing.

ruamel.yaml's round-trip loader, which remembers every node's line, reads about 20,000
nodes a second in pure Python: reading the 317 files of the tree took `mechbook list` two
seconds. libyaml reads them in a few hundredths. The two parsers differ in details (PyYAML
resolves YAML 1.1, ruamel.yaml 1.2), so this reading resolves only the scalars on which
both agree for certain — plain decimal integers and floats, true/false, null, text — and
gives up (returns None) on anything else: a hexadecimal or octal number, a date, a merge
key, a duplicate key, a collection as a key, any error or limit. The caller then reads the
file with the round-trip parser, which says what is wrong with file and line; the lines of
a file read here are found the same way, only when an error needs one
(mechbook.model.yamlio). tests/test_fastyaml.py compares both readings on every committed
file and on thousands of mutated ones.
"""

from __future__ import annotations

import re
from functools import cache
from typing import Any

try:  # PyYAML is a dependency; libyaml is in its wheels, but a source build may lack it
    import yaml
    from yaml import CBaseLoader as _Loader
except ImportError:  # pragma: no cover - then every file takes the round-trip path
    yaml = None
    _Loader = None

from mechbook.errors import SpecError
from mechbook.model.data import Data

# the scalars resolved here; ruamel.yaml's YAML 1.2 resolvers give the same values for them
_INT = re.compile(r"[-+]?(?:0|[1-9][0-9]*)")
_FLOAT = re.compile(r"[-+]?[0-9]+\.[0-9]*(?:[eE][-+]?[0-9]+)?|[-+]?[0-9]+[eE][-+]?[0-9]+"
                    r"|[-+]?\.[0-9]+(?:[eE][-+][0-9]+)?")
_BOOL = {"true": True, "True": True, "TRUE": True, "false": False, "False": False,
         "FALSE": False}
_NULL = {"", "~", "null", "Null", "NULL"}


# tabs, line breaks other than \n, byte-order marks and control characters: the two
# scanners treat them differently (libyaml takes a tab inside a plain scalar that ruamel.yaml
# refuses), so a file holding one is left to the round-trip parser
_ODD = re.compile(r"[\x00-\x09\x0b-\x1f\x7f-\x9f\u2028\u2029\ufeff\ud800-\udfff\ufffe\uffff]")


class _Unsure(Exception):
    """The fast reading cannot promise the round-trip parser's result."""


def fast_data(text: str, file: str, check_events) -> Data:
    """The plain data of `text`, or None where only the round-trip parser can say (an
    error, a limit, a scalar the two parsers might read differently). `check_events`
    (mechbook.model.input_limits) runs on the event stream first; a refusal there also gives
    None, so that the message is the round-trip parser's."""
    if yaml is None or _ODD.search(text):
        return None
    try:
        check_events(_events(text), file)  # as they come: a limit stops the parser early
        node = yaml.compose(text, Loader=_Loader)
        return _plain(node)
    except (yaml.YAMLError, SpecError, _Unsure, RecursionError, ValueError, OverflowError):
        return None


def _events(text: str):
    """libyaml's events one by one, as ruamel.yaml would give them (a plain scalar's style
    None, not ''): never the whole list first. libyaml takes time quadratic in the nesting
    to parse a document to its end (120 KB of '[' took 45 s), while the limits refuse it at
    its 33rd level, a few events in."""
    for ev in yaml.parse(text, Loader=_Loader):
        if getattr(ev, "version", None) or getattr(ev, "tags", None):
            raise _Unsure("a %YAML or %TAG directive: the round-trip parser's business")
        if getattr(ev, "style", None) == "":
            ev.style = None
        yield ev


def _plain(node) -> Any:
    if node is None:
        return None
    if isinstance(node, yaml.MappingNode):
        out: dict = {}
        for key_node, value_node in node.value:
            if not isinstance(key_node, yaml.ScalarNode):
                raise _Unsure("a collection as a key")
            key = _scalar(key_node)
            if not key_node.style and key_node.value == "<<":
                raise _Unsure("a merge key")
            if any(type(k) is type(key) and k == key for k in out):
                raise _Unsure("a duplicate key")
            out[key] = _plain(value_node)
        return out
    if isinstance(node, yaml.SequenceNode):
        return [_plain(v) for v in node.value]
    return _scalar(node)


def _scalar(node) -> Any:
    value = node.value
    if node.style:  # quoted or a block scalar: text ('' or None: plain)
        return value
    if value in _NULL:
        return None
    if value in _BOOL:
        return _BOOL[value]
    if _INT.fullmatch(value):
        return int(value)
    if _FLOAT.fullmatch(value):
        return float(value)
    first, patterns = _special()
    if value[0] in first and any(rx.match(value) for rx in patterns):  # a number, date,
        raise _Unsure(value)  # merge key ... of another form: the round-trip parser decides
    return value


@cache
def _special() -> tuple[frozenset, list]:
    """ruamel.yaml's own YAML 1.2 implicit resolvers (the first characters they apply to,
    and their patterns): a plain scalar that one of them matches is not text to it."""
    from ruamel.yaml.resolver import implicit_resolvers

    mine = [(rx, first) for versions, _tag, rx, first in implicit_resolvers
            if (1, 2) in versions]
    return (frozenset(c for _, first in mine for c in first),
            [rx.lazy_self() for rx, _ in mine])
