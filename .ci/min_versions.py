"""Print a pip constraints file pinning every dependency of pyproject.toml, and every build
requirement (setuptools), to the lowest version its range allows (`name>=X,<Y` ->
`name==X`): the minimum-versions CI job (`make test-min`) installs with it, and builds
mechbook without build isolation with that setuptools, so that the lower bounds are
tested, not assumed."""

from __future__ import annotations

import re
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main() -> int:
    config = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))
    specs = [*config["project"]["dependencies"], *config["build-system"]["requires"]]
    for spec in specs:
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
