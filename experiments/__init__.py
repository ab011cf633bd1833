"""Research studies: one folder per study, each with its scripts and a README of its findings.

Not installed with the package (the wheel holds `hexapod_envs` and `agents` only) and never
imported by them (`tests/project/test_layers.py`). The studies use the library like any user; pytest
makes this folder importable from the repository root (``pythonpath`` in pyproject.toml), and
every study script puts the repository root on ``sys.path`` itself.
"""
