"""YAML reading that remembers line numbers, refuses duplicate keys and stays bounded.

PyYAML silently keeps the last of two equal keys; ruamel.yaml's round-trip loader raises on
them and records where every node sits, so errors can name the file and the line. Before
anything is built, the file's size, its event stream (no anchors, aliases or tags; bounded
depth and node count) and then every scalar (plain JSON-like values, finite numbers) are
checked against mechbook.model.input_limits.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ruamel.yaml import YAML
from ruamel.yaml.comments import CommentedMap, CommentedSeq
from ruamel.yaml.constructor import DuplicateKeyError
from ruamel.yaml.error import MarkedYAMLError, YAMLError

from mechbook.errors import SpecError
from mechbook.model.data import Data  # what `Document.data` holds (named here for its readers)
from mechbook.model.fastyaml import fast_data
from mechbook.model.hints import yaml_hint
from mechbook.model.input_limits import (
    MAX_FILE_BYTES,
    check_events,
    check_scalar,
    check_text,
    read_text,
)

Path_ = tuple[str | int, ...]


class Document:
    """A loaded YAML file: plain data plus a way to find the line of any node.

    A file read by libyaml (mechbook.model.fastyaml) has no line numbers of its own: the
    round-trip parser reads it again the first time an error needs a line."""

    def __init__(self, raw: object, file: str, data: Data = None, text: str | None = None):
        self._raw = raw
        self._text = text
        self.file = file
        self.data = self._plain(raw if text is None else data, ())

    @property
    def raw(self) -> object:
        """The round-trip parser's nodes (with their lines), read on first use."""
        if self._raw is None and self._text is not None:
            try:
                self._raw = _round_trip(self._text, self.file)
            except SpecError:  # libyaml read it and ruamel.yaml cannot: no lines then
                self._raw = {}
            self._text = None
        return self._raw

    def line(self, path: Path_) -> int | None:
        """1-based line of the node at `path` (its key's line for mapping entries)."""
        node, best = self.raw, _node_line(self.raw)
        for key in path:
            if isinstance(node, CommentedMap) and key in node:
                try:
                    best = node.lc.key(key)[0] + 1
                except (KeyError, TypeError, AttributeError):
                    pass
                node = node[key]
            elif isinstance(node, CommentedSeq) and isinstance(key, int) and key < len(node):
                try:
                    best = node.lc.item(key)[0] + 1
                except (KeyError, TypeError, AttributeError):
                    pass
                node = node[key]
            else:
                break
        return best

    def error(self, path: Path_, message: str) -> SpecError:
        where = "/".join(str(p) for p in path)
        text = f"{where}: {message}" if where else message
        return SpecError(text, self.file, self.line(path))


    def _plain(self, node: Any, path: Path_) -> Any:
        """JSON-like data: str keys; str, bool, None and finite numbers as values."""
        if isinstance(node, dict):
            out = {}
            for k, v in node.items():
                if isinstance(k, dict | list | tuple):
                    raise self.error(path, "a mapping key must be a plain name, not a "
                                     "collection")
                check_text(str(k), lambda k=k: (self.file, self.line(path + (k,))))
                out[str(k)] = self._plain(v, path + (k,))
            return out
        if isinstance(node, list):
            return [self._plain(v, path + (i,)) for i, v in enumerate(node)]
        if isinstance(node, str):
            return check_scalar(str(node), lambda: (self.file, self.line(path)))
        return check_scalar(node, lambda: (self.file, self.line(path)))


def _node_line(node: Any) -> int | None:
    lc = getattr(node, "lc", None)
    return lc.line + 1 if lc is not None and lc.line is not None else None


def load(path: str | Path) -> Document:
    """Load a YAML file; syntax errors, duplicate keys and anything past the limits
    (mechbook.model.input_limits) become SpecError with a line."""
    return loads(read_text(path), str(path))


def loads(text: str, file: str = "<string>") -> Document:
    """`text` read as YAML: by libyaml when its reading is certain to be the round-trip
    parser's (mechbook.model.fastyaml), else by the round-trip parser, whose errors name
    the line."""
    if len(text) > MAX_FILE_BYTES:
        raise SpecError(f"text too large (more than {MAX_FILE_BYTES} characters)", file)
    data = fast_data(text, file, check_events)
    if data is not None:
        return Document(None, file, data, text)
    raw = _round_trip(text, file)
    if raw is None:
        raise SpecError("file is empty", file, 1)
    return Document(raw, file)


def _round_trip(text: str, file: str) -> Any:
    """ruamel.yaml's round-trip reading (nodes with lines), after the event checks."""
    yaml = YAML(typ="rt")
    yaml.allow_duplicate_keys = False
    try:
        check_events(YAML(typ="rt").parse(text), file)  # before anything is built
        raw = yaml.load(text)
    except DuplicateKeyError as exc:
        line = exc.problem_mark.line + 1 if exc.problem_mark else None
        raise SpecError(f"duplicate key: {exc.problem.strip()}", file, line) from None
    except MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark else None
        raise SpecError(f"YAML syntax error: {yaml_hint(str(exc.problem or exc.context))}",
                        file, line) from None
    except YAMLError as exc:  # the reader's errors (control characters) carry no mark
        raise SpecError(f"YAML error: {_first_line(exc)}", file, _position_line(exc, text)) \
            from None
    except (ValueError, OverflowError, RecursionError) as exc:  # a constructor's last resort
        raise SpecError(f"YAML value cannot be read: {_first_line(exc)}", file) from None
    return raw


def _first_line(exc: BaseException) -> str:
    return (str(exc).strip().splitlines() or [type(exc).__name__])[0]


def _position_line(exc: BaseException, text: str) -> int | None:
    position = getattr(exc, "position", None)
    return text[:position].count("\n") + 1 if isinstance(position, int) else None
