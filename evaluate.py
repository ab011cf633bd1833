"""Compare policies (analytical, PPO, zero, random) on hexapod envs and write a report.

``python evaluate.py`` runs ``configs/evaluate_default.yaml``; see ``python evaluate.py --help``.
Thin front end of the installed ``hexapod-evaluate`` command for a source checkout; the logic
lives in `agents.pipeline`.
"""

import os
import sys

os.environ.setdefault("MUJOCO_GL", "egl")  # headless rendering for --frames

from agents.pipeline.cli import evaluate_main  # noqa: E402

if __name__ == "__main__":
    sys.exit(evaluate_main())
