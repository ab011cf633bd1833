"""scripts/reproduce_papers.py keeps the committed record whole: a run of some rows needs a
folder of its own."""

import subprocess
import sys

from helpers.paths import REPO


def test_a_partial_reproduction_needs_an_output_folder():
    for partial in (["--quick"], ["--only", "003"]):
        run = subprocess.run(
            [sys.executable, str(REPO / "scripts" / "reproduce_papers.py"), *partial],
            cwd=REPO,
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert run.returncode == 2, run.stderr[-2000:]
        assert "write a partial report: give it an --out folder" in run.stderr
