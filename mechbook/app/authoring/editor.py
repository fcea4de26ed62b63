"""The JSON Schemas of mechbook's files, for the author's editor (and for scripts).

An editor with a YAML language server (VS Code's YAML extension, Neovim's yamlls, Helix,
JetBrains) completes keys and underlines mistakes while one types, given a schema: a
first-line comment `# yaml-language-server: $schema=<path>` names it. `mechbook schema`
prints or writes them; `mechbook init` writes them into the new tree (`schemas/`) and puts
the comment in the files it writes. The answers schema comes from the registry of
quantities (each quantity's own keys), so it is written, not copied: after an upgrade of
mechbook, `mechbook schema --write schemas` refreshes a tree's copies.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from mechbook.app.outputs import OutputError, refuse_special, write_file
from mechbook.errors import MechbookError

NAMES = ("problem", "answers", "books", "check-result")
DIRECTORY = "schemas"  # where `mechbook init` puts them, at the tree's root
MODELINE = "# yaml-language-server: $schema="


def schema(name: str) -> dict:
    """The JSON Schema `name` (one of NAMES)."""
    if name == "problem" or name == "books":
        # at call time: `mechbook schema NAME` loads only the schema it prints (verify: SymPy)
        from mechbook.model.schema import bundled

        return bundled(name)
    if name == "answers":
        # at call time: `mechbook schema NAME` loads only the schema it prints (verify: SymPy)
        from mechbook.verify.registry import answers_schema

        return answers_schema()
    if name == "check-result":
        # at call time: `mechbook schema NAME` loads only the schema it prints (verify: SymPy)
        from mechbook.app.output.formats import schema as check_result

        return check_result()
    raise MechbookError(f"no schema {name!r} (schemas: {', '.join(NAMES)})")


def text(name: str) -> str:
    return json.dumps(schema(name), indent=1, ensure_ascii=False) + "\n"


def write_schemas(directory: Path) -> list[Path]:
    """Every schema as `<directory>/<name>.json` (made if missing), each by the link-safe
    writer (mechbook.app.outputs.write_file): a link, FIFO or directory at any of the paths is
    refused before anything is written. The files written; OutputError names a failure."""
    directory = Path(directory)
    if os.path.lexists(directory) and not os.path.isdir(directory):
        raise OutputError(directory, "it exists and is not a directory", "schema directory")
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(directory, exc.strerror or str(exc), "schema directory") from None
    paths = {name: directory / f"{name}.json" for name in NAMES}
    for path in paths.values():  # all refused before any is written
        refuse_special(path, "schema")
    return [write_file(path, text(name).encode("utf-8"), "schema")
            for name, path in paths.items()]


def modeline(yaml_file: Path, schema_file: Path) -> str:
    """The comment that hands `schema_file` to the editor of `yaml_file` (a relative
    path, so that the tree can move)."""
    rel = os.path.relpath(schema_file, yaml_file.parent)
    return MODELINE + Path(rel).as_posix()
