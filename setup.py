"""Build hook (the metadata is in pyproject.toml): the wheel carries the repository's configs/
and models/ as package data of `agents`, in agents/_shipped/, so that an installed
``hexapod-evaluate`` finds the default suite and the shipped models from any folder
(`agents.run_files.shipped`). The repository root keeps the one copy; an editable install reads
it there and copies nothing."""

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
SHIPPED_DIRS = ("configs", "models")  # agents.run_files.shipped.SHIPPED_DIRS
TARGET = Path("agents", "_shipped")


class BuildPyWithShippedData(build_py):
    def run(self) -> None:
        super().run()
        if getattr(self, "editable_mode", False):
            return
        for name in SHIPPED_DIRS:
            dest = Path(self.build_lib) / TARGET / name
            shutil.rmtree(dest, ignore_errors=True)
            shutil.copytree(ROOT / name, dest, ignore=shutil.ignore_patterns("__pycache__"))


setup(cmdclass={"build_py": BuildPyWithShippedData})
