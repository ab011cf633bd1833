"""Regenerate the reproduction report: the three papers' headline numbers beside ours.

Run: python scripts/reproduce_papers.py [--only 000|002|003 --quick --out DIR]
Writes `reproduction.md` and `reproduction.json` under --out (default `reports`, the committed
record of every row; a run of some rows needs another --out) (rows: see
experiments/reproduction/rows.py, and experiments/reproduction/README.md).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from experiments.reproduction.rows import collect, markdown  # noqa: E402


def main(argv: list[str] | None = None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", choices=("000", "002", "003"), default=None)
    parser.add_argument("--quick", action="store_true", help="cheap rows only")
    parser.add_argument(
        "--out", type=Path, default=None, help="output folder (default: reports, full runs only)"
    )
    args = parser.parse_args(argv)
    partial = args.only is not None or args.quick
    if args.out is None:
        if partial:  # reports/reproduction.* is the committed record of every row
            parser.error("--only and --quick write a partial report: give it an --out folder")
        args.out = Path("reports")
    rows = collect(args.only, args.quick)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "reproduction.json").write_text(json.dumps(rows, indent=2) + "\n")
    (args.out / "reproduction.md").write_text(markdown(rows))
    for r in rows:
        print(
            f"{r['id']:>4s} {r['quantity']:48s} paper {r['paper_value']!s:>12s} "
            f"ours {r['value']!s:>16s} {r['unit']:6s} {'holds' if r['holds'] else 'FAILS'}"
        )
    return rows


if __name__ == "__main__":
    main()
