"""docs/observations.md is the rendering of the envs' observation_structure (kept in sync)."""

from helpers.paths import REPO

from hexapod_envs.observation_docs import render

PAGE = REPO / "docs" / "observations.md"


def test_observation_page_matches_the_code():
    assert PAGE.read_text() == render(), (
        "docs/observations.md is stale: python -m hexapod_envs.observation_docs > "
        "docs/observations.md"
    )
