"""A YAML file's plain data: mappings, lists and scalars, the type every reader hands on.

A module of its own below both readers (mechbook.model.yamlio, the round-trip parser, and
mechbook.model.fastyaml, libyaml's fast reading) and the system contract
(mechbook.model.protocol), so that none of them imports another only for a type hint."""

from __future__ import annotations

Data = dict[str, "Data"] | list["Data"] | str | int | float | bool | None
