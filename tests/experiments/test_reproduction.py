"""The cheap rows of the reproduction report, recomputed and compared with the committed JSON."""

import json

import pytest
from helpers.paths import REPO

from experiments.reproduction.rows import (
    HEADLINES,
    _isclose,
    collect,
    headline_rows,
    markdown,
    summary,
)

COMMITTED = REPO / "reports" / "reproduction.json"


def test_cheap_rows_match_committed_report():
    committed = {r["id"]: r for r in json.loads(COMMITTED.read_text())}
    rows = collect(quick=True)
    assert {r["id"] for r in rows} >= {"5", "12", "12b"}
    for row in rows:
        old = committed[row["id"]]
        assert _isclose(row["value"], old["value"]), row["id"]
        assert row["holds"] == old["holds"], row["id"]


def test_flat_walk_margin_rows_match_committed_report():
    committed = {r["id"]: r for r in json.loads(COMMITTED.read_text())}
    from experiments.reproduction.rows import cliff_flat_walk_rows

    for row in cliff_flat_walk_rows():
        old = committed[row["id"]]
        if isinstance(row["value"], list):
            assert all(_isclose(a, b) for a, b in zip(row["value"], old["value"], strict=True))
        else:
            assert _isclose(row["value"], old["value"]), row["id"]
        assert row["holds"] and old["holds"]


def test_rows_have_the_required_fields_and_markdown_lists_them():
    rows = json.loads(COMMITTED.read_text())
    keys = {"id", "paper", "quantity", "paper_value", "value", "unit", "tolerance", "holds"}
    assert all(keys <= set(r) for r in rows)
    text = markdown(rows)
    table = text.split("## All rows", 1)[1]
    assert table.count("\n| ") == len(rows) + 1  # header + one line per row


def test_summary_lists_every_headline_with_the_verdict_of_its_rows():
    rows = json.loads(COMMITTED.read_text())
    lines = summary(rows)[2:]
    assert len(lines) == len(HEADLINES)
    for (key, *_), line in zip(HEADLINES, lines, strict=True):
        picked = headline_rows(rows, key)
        assert picked, key
        assert line.startswith(f"| {key.rstrip('.')} |")
        assert line.endswith("| holds |") == all(r["holds"] for r in picked), line
    text = markdown(rows)
    assert text.index("## Summary") < text.index("## All rows")


def test_summary_fails_a_per_case_headline_when_one_case_fails():
    cases = [
        {"id": f"7b.{case}", "value": 1.0, "unit": "s", "holds": case != "b"} for case in "abc"
    ]
    other = {"id": "7b.a@max_tilt_deg=25", "value": 9.0, "unit": "s", "holds": True}
    assert headline_rows([*cases, other], "7b.") == cases
    (line,) = summary([*cases, other])[2:]
    assert line.endswith("| **fails** |") and "2 of 3 cases hold" in line


def test_bad_paper_id_is_rejected_with_choices():
    with pytest.raises(ValueError, match="000"):
        collect(only="001")


def test_stewart_paper_scenario_side_rows_match_committed_report():
    """One Stewart case in the paper's scenario (about 2 s): t_s lies inside 0.5-2.5 s and off
    the clamps, the margin holds after landing, as in the committed report."""
    from experiments.reproduction.rows import stewart_rows

    committed = {r["id"]: r for r in json.loads(COMMITTED.read_text())}
    rows = stewart_rows(cases=[("side", "LF-LR-RM")])
    assert [r["id"][:2] for r in rows] == ["6", "7b", "7c", "7."]
    for row in rows[1:]:
        old = committed[row["id"]]
        values = row["value"] if isinstance(row["value"], list) else [row["value"]]
        olds = old["value"] if isinstance(old["value"], list) else [old["value"]]
        assert all(_isclose(a, b) for a, b in zip(values, olds, strict=True)), row["id"]
        assert row["holds"] == old["holds"], row["id"]
    t_s = rows[1]["value"]
    assert 0.5 < t_s < 2.5 and rows[1]["holds"] and rows[3]["holds"]
