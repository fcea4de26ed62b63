"""Install mechbook by the README's own words, in clean virtual environments, and use it.

The README's "Install" section marks two shell blocks (`<!-- install: ... -->`); this runs
every line of them as written: the first in a copy of the repository's tracked files (what a
clone holds) — a venv, `pip install .` with the dependencies from the package index,
`mechbook init`, `check` and `report` — and the second (a wheel built there and installed
into another fresh venv, `mechbook docs`). Then it checks what they left: the report's
index, and a mechbook that is the wheel's, not the clone's. `make test-install` runs it
(CI does); the README cannot say a command that does not work.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MARK = "<!-- install:"


def blocks() -> list[str]:
    text = (ROOT / "README.md").read_text("utf-8")
    if MARK not in text:
        sys.exit(f"README.md has no {MARK} ... --> section")
    found = re.findall(r"```sh\n(.*?)```", text.split(MARK, 1)[1], re.S)[:2]
    if len(found) != 2:
        sys.exit("README.md's install section needs two ```sh blocks")
    return found


def clone(dest: Path) -> None:
    """The files git knows (tracked, and new ones not ignored) as they are now: a clone
    of this commit with its edits."""
    files = subprocess.run(["git", "ls-files", "-z", "--cached", "--others",
                            "--exclude-standard"], cwd=ROOT, check=True,
                           capture_output=True).stdout.decode().split("\0")
    for name in filter(None, files):
        src = ROOT / name
        if src.is_file():
            (dest / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / name)


def run(script: str, cwd: Path, env: dict, before: str = "") -> None:
    print(f"--- in {cwd}:\n{script}", flush=True)
    subprocess.run(["bash", "-euo", "pipefail", "-c", before + script], cwd=cwd, env=env,
                   check=True)


def main() -> int:
    first, second = blocks()
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "VIRTUAL_ENV", "MECHBOOK_ROOT", "PYTHONHOME")}
    with tempfile.TemporaryDirectory(prefix="mechbook-install-") as tmp:
        src = Path(tmp) / "mechbook"
        src.mkdir()
        clone(src)
        run(first, src, env)
        index = src / "mytree" / "results" / "report" / "index.html"
        assert index.is_file(), f"no report at {index}"
        other = Path(tmp) / "elsewhere"  # a second clean venv, for the wheel
        subprocess.run([sys.executable, "-m", "venv", str(other)], check=True)
        run(second, src, env, before=f". {other}/bin/activate\n")
        where = subprocess.run([str(other / "bin" / "python"), "-c",
                                "import mechbook; print(mechbook.__file__)"], env=env,
                               cwd=tmp, check=True, capture_output=True, text=True).stdout
        assert where.startswith(str(other)), f"mechbook imported from {where}"
    print("install by the README's words: ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
