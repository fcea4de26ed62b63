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
from pathlib import Path

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
        from mechbook.app.formats import schema as check_result

        return check_result()
    raise MechbookError(f"no schema {name!r} (schemas: {', '.join(NAMES)})")


def text(name: str) -> str:
    return json.dumps(schema(name), indent=1, ensure_ascii=False) + "\n"


def write_schemas(directory: Path) -> list[Path]:
    """Every schema as `<directory>/<name>.json`; the files written."""
    directory.mkdir(parents=True, exist_ok=True)
    out = []
    for name in NAMES:
        path = directory / f"{name}.json"
        path.write_text(text(name), encoding="utf-8")
        out.append(path)
    return out


def modeline(yaml_file: Path, schema_file: Path) -> str:
    """The comment that hands `schema_file` to the editor of `yaml_file` (a relative
    path, so that the tree can move)."""
    import os

    rel = os.path.relpath(schema_file, yaml_file.parent)
    return MODELINE + Path(rel).as_posix()
