"""YAML reading that remembers line numbers and refuses duplicate keys.

PyYAML silently keeps the last of two equal keys; ruamel.yaml's round-trip loader raises on
them and records where every node sits, so errors can name the file and the line.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ruamel.yaml import YAML
from ruamel.yaml.comments import CommentedMap, CommentedSeq
from ruamel.yaml.constructor import DuplicateKeyError
from ruamel.yaml.error import MarkedYAMLError

from mechbook.errors import SpecError

Path_ = tuple[str | int, ...]


class Document:
    """A loaded YAML file: plain data plus a way to find the line of any node."""

    def __init__(self, raw: Any, file: str):
        self.raw = raw
        self.file = file
        self.data = _plain(raw)

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


def _node_line(node: Any) -> int | None:
    lc = getattr(node, "lc", None)
    return lc.line + 1 if lc is not None and lc.line is not None else None


def _plain(node: Any) -> Any:
    if isinstance(node, dict):
        return {str(k): _plain(v) for k, v in node.items()}
    if isinstance(node, list):
        return [_plain(v) for v in node]
    if isinstance(node, str):
        return str(node)
    return node


def load(path: str | Path) -> Document:
    """Load a YAML file; syntax errors and duplicate keys become SpecError with a line."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SpecError(f"cannot read file: {exc.strerror}", str(path)) from None
    return loads(text, str(path))


def loads(text: str, file: str = "<string>") -> Document:
    yaml = YAML(typ="rt")
    yaml.allow_duplicate_keys = False
    try:
        raw = yaml.load(text)
    except DuplicateKeyError as exc:
        line = exc.problem_mark.line + 1 if exc.problem_mark else None
        raise SpecError(f"duplicate key: {exc.problem.strip()}", file, line) from None
    except MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark else None
        raise SpecError(f"YAML syntax error: {exc.problem or exc.context}", file, line) from None
    if raw is None:
        raise SpecError("file is empty", file, 1)
    return Document(raw, file)
