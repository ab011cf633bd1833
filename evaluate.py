"""Compare policies (analytical, PPO, zero, random) on hexapod envs and write a report.

``python evaluate.py`` runs ``configs/evaluate_default.yaml``; see ``python evaluate.py --help``.
Thin front end of the installed ``hexapod-evaluate`` command for a source checkout; the logic
lives in `agents.pipeline`.
"""

import sys

from agents.pipeline.cli import default_headless_gl, evaluate_main

if __name__ == "__main__":
    default_headless_gl()  # before MuJoCo loads
    sys.exit(evaluate_main())
