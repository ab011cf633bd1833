"""Where the repository's files are, for tests that read configs, models, docs or reports."""

from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
"""The repository root (the folder holding pyproject.toml)."""
