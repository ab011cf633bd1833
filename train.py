"""Train PPO on a hexapod env from a YAML config: ``python train.py --config configs/<name>.yaml``.

Thin front end of the installed ``hexapod-train`` command for a source checkout; the logic lives
in `agents.pipeline` (see ``python train.py --help``).
"""

import sys

from agents.pipeline.cli import train_main

if __name__ == "__main__":
    sys.exit(train_main())
