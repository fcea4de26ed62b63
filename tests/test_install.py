"""mechbook as someone else installs it: a wheel (not the editable checkout) in a fresh
virtual environment, then `mechbook init` and `mechbook check` in a new directory.

The wheel is built by pip (with build isolation, from pyproject.toml) and installed into a
new venv without its dependencies; those are borrowed from the test's own environment by a
path file (appended after the venv's own site-packages, and without running that
environment's .pth files, so its editable mechbook stays out). The wheel must carry
everything a new user needs: the schemas, the report's assets, the starter tree, py.typed,
the documentation pages (`mechbook docs`), the license and the metadata (an SPDX license,
classifiers, the extras). `make test-install` goes further, by the README's own words
(.ci/readme_install.py): a clean venv with its dependencies from the index.
"""

from __future__ import annotations

import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_init_and_check_from_a_wheel_in_a_fresh_venv(tmp_path):
    wheels = tmp_path / "wheels"
    built = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet",
                            "-w", str(wheels), str(ROOT)], capture_output=True, text=True,
                           timeout=900)
    assert built.returncode == 0, built.stdout + built.stderr
    (wheel,) = wheels.glob("mechbook-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    for needed in ("mechbook/py.typed", "mechbook/app/authoring/starter/problem.yaml",
                   "mechbook/app/authoring/starter/Makefile", "mechbook/model/schemas/problem.json",
                   "mechbook/app/report/assets/animate.js",
                   "mechbook/app/report/templates/problem.html",
                   "mechbook/docs/schema.md", "mechbook/docs/answers.md",
                   "mechbook/docs/images/sweep-lim-2031-stability.png",
                   "mechbook-0.1.0.dist-info/licenses/LICENSE"):
        assert needed in names, needed
    metadata = zipfile.ZipFile(wheel).read("mechbook-0.1.0.dist-info/METADATA").decode()
    assert "License-Expression: MIT" in metadata  # SPDX (PEP 639), no deprecated table
    assert "Classifier: Topic :: Scientific/Engineering :: Physics" in metadata
    assert "Provides-Extra: xarray" in metadata
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=300)
    py = venv / "bin" / "python"
    site = subprocess.run([str(py), "-c", "import sysconfig; print(sysconfig.get_paths()"
                           "['purelib'])"], capture_output=True, text=True, check=True)
    Path(site.stdout.strip(), "borrowed-deps.pth").write_text(
        sysconfig.get_paths()["purelib"] + "\n", "utf-8")
    installed = subprocess.run([str(py), "-m", "pip", "install", "--quiet", "--no-deps",
                                "--no-index", str(wheel)], capture_output=True, text=True,
                               timeout=300)
    assert installed.returncode == 0, installed.stderr
    where = subprocess.run([str(py), "-c", "import mechbook; print(mechbook.__file__)"],
                           capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert where.stdout.startswith(str(venv)), where.stdout + where.stderr
    tree = tmp_path / "mine"
    mechbook = venv / "bin" / "mechbook"
    made = subprocess.run([str(mechbook), "init", str(tree)], capture_output=True, text=True,
                          cwd=tmp_path, timeout=300)
    assert made.returncode == 0, made.stdout + made.stderr
    checked = subprocess.run([str(mechbook), "check", "-j", "1"], capture_output=True,
                             text=True, cwd=tree, timeout=900)
    assert checked.returncode == 0, checked.stdout + checked.stderr
    assert "3 parts: 3 pass" in checked.stdout
    assert "Traceback" not in checked.stderr and "Warning" not in checked.stderr
    # the docs the messages name come with the wheel
    page = subprocess.run([str(mechbook), "docs", "schema"], capture_output=True, text=True,
                          cwd=tmp_path, timeout=120)
    assert page.returncode == 0 and page.stdout.startswith("# Problem files"), page.stderr
    where = subprocess.run([str(mechbook), "docs", "--path"], capture_output=True, text=True,
                           cwd=tmp_path, timeout=120)
    assert where.stdout.strip().startswith(str(venv)), where.stdout
