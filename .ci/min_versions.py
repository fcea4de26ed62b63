"""Print a pip constraints file pinning every dependency of pyproject.toml to the lowest
version its range allows (`name>=X,<Y` -> `name==X`): the minimum-versions CI job
(`make test-min`) installs with it, so that the lower bounds are tested, not assumed."""

from __future__ import annotations

import re
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main() -> int:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))["project"]
    for spec in project["dependencies"]:
        m = re.match(r"\s*([A-Za-z0-9_.\-]+)\s*(\[[^\]]*\])?\s*(.*)", spec)
        name, ranges = m.group(1), m.group(3)
        low = re.search(r">=\s*([0-9][^,;\s]*)", ranges)
        if low is None:
            print(f"{name} has no lower bound in pyproject.toml", file=sys.stderr)
            return 1
        print(f"{name}=={low.group(1)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
