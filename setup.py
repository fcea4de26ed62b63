"""The build, beyond what pyproject.toml declares: the docs/ pages go into the package as
mechbook/docs/ (a wheel's user has no checkout; `mechbook docs` reads them there), copied
when the package is built, so docs/ stays the one place they are edited."""

from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

DOCS = Path(__file__).resolve().parent / "docs"
SHIPPED = ("*.md", "images/*.png")


class BuildWithDocs(build_py):
    """build_py, then docs/*.md and docs/images/*.png into the built package."""

    def run(self) -> None:
        super().run()
        target = Path(self.build_lib) / "mechbook" / "docs"
        for pattern in SHIPPED:
            for src in sorted(DOCS.glob(pattern)):
                dest = target / src.relative_to(DOCS)
                dest.parent.mkdir(parents=True, exist_ok=True)
                self.copy_file(str(src), str(dest))


setup(cmdclass={"build_py": BuildWithDocs})
