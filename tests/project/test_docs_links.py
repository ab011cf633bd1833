"""Every relative link of the hand-written documentation points at a file that exists, and
every ``#anchor`` at a heading of that file (GitHub's anchor rules)."""

import re
from pathlib import Path

import pytest
from helpers.paths import REPO

PAGES = [
    REPO / "README.md",
    REPO / "benchmarks" / "README.md",
    *sorted((REPO / "docs").glob("*.md")),
    *sorted((REPO / "experiments").glob("*/README.md")),
]
LINK = re.compile(r"\]\(([^)\s]+)\)")


def anchor(heading: str) -> str:
    """GitHub's anchor of a Markdown heading: lower case, punctuation dropped, spaces to '-'."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def anchors(page: Path) -> set[str]:
    text = re.sub(r"```.*?```", "", page.read_text(), flags=re.S)  # no headings in code
    return {anchor(m) for m in re.findall(r"^#+ (.+)$", text, flags=re.M)}


def test_anchor_follows_github():
    assert anchor("3-UPU hexapod (Li et al. 2018)") == "3-upu-hexapod-li-et-al-2018"
    assert anchor("Hybrid policies: learning on top") == "hybrid-policies-learning-on-top"


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(REPO)))
def test_relative_links_resolve(page):
    broken = []
    for target in LINK.findall(page.read_text()):
        if re.match(r"[a-z]+:", target):  # http:, https:, mailto:
            continue
        path, _, fragment = target.partition("#")
        file = (page.parent / path).resolve() if path else page
        if not file.exists():
            broken.append(f"{target}: no file {file.relative_to(REPO)}")
        elif fragment and file.suffix == ".md" and fragment not in anchors(file):
            broken.append(f"{target}: no heading with anchor #{fragment}")
    assert not broken, f"{page.relative_to(REPO)}: " + "; ".join(broken)
