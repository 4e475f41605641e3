"""Fly-next cards open the report; printable test cards; the plan file `gcs-sysid simulate` flies."""

import dataclasses
import json
import math

import pytest

from gcs_sysid.maneuvers import SuggestionList, quality_gate
from gcs_sysid.report import load_result, write_report
from gcs_sysid.report.html import SECTIONS
from gcs_sysid.sim import load_plan


@pytest.fixture(scope="module")
def gated(replay_result):
    """The synthetic result with Cn failing its held-out check (330 %)."""
    s = replay_result.suggestions
    ctx = dict(s.context, gated=quality_gate({"Cn": 330.0}))
    return dataclasses.replace(replay_result, suggestions=SuggestionList(list(s), ctx))


@pytest.fixture(scope="module")
def files(gated, tmp_path_factory):
    from gcs_sysid.report.plots import FIGURES

    blank = {name: ([] if name == "envelope" else b"") for name in FIGURES}   # test_report.py checks the figures
    return write_report(gated, tmp_path_factory.mktemp("cards"), figures=blank)


def test_fly_next_opens_the_report(gated, files):
    assert SECTIONS[0] == ("flynext", "Fly next")
    page = files["html"].read_text()
    body = page[page.index("<main>"):]
    assert body.index('id="flynext"') < body.index('id="summary"')
    s = gated.suggestions[0]
    card = page[page.index("Card 1:"):page.index("Card 2:")]
    for text in ("condition", f"V {s.flight_condition['V']:.1f} m/s", "density altitude",
                 f"{math.degrees(s.amplitude_rad):.1f} deg", "expected", "deg/s", " g", "why", "will reduce"):
        assert text in card, text
    md = files["markdown"].read_text()
    assert md.index("## Fly next") < md.index("## Summary")
    assert "### Card 1:" in md and "**amplitude**" in md and "Not ranked (quality gate)" in md
    assert "**Cn**: held-out error 330 %" in md and "airframe file" in md
    assert "Limits respected by every card" in md and "12.0-25.0 m/s" in md


def test_printable_cards_and_plan(gated, files, tmp_path):
    md = files["testcards_md"].read_text()
    assert md.startswith("# Test cards:") and md.count("## Card ") == len(gated.suggestions)
    page = files["testcards_html"].read_text()
    assert page.count('class="card"') == len(gated.suggestions) and "<script" not in page and "@media print" in page
    plan = load_plan(files["plan"])
    assert len(plan.maneuvers) == len(gated.suggestions)
    assert [m.kind for m in plan.maneuvers] == [s.kind for s in gated.suggestions]
    doc = json.loads(files["suggestions"].read_text())
    assert doc["gated"]["Cn"]["fix"] and doc["limits"]["V_max_mps"] == 25.0
    s0 = doc["suggestions"][0]
    assert {"p_max_dps", "q_max_dps", "r_max_dps", "n_max", "alpha_max_deg"} <= set(s0["expected"])
    assert len(s0["waveform"]["t"]) == len(s0["waveform"][s0["controls"][0]])


def test_context_survives_save_and_load(gated, files):
    back = load_result(files["result_json"].parent)
    assert back.suggestions.context["gated"] == gated.suggestions.context["gated"]
    assert back.suggestions[0].expected == pytest.approx(gated.suggestions[0].expected, rel=1e-5)
    assert back.suggestions[0].fix == gated.suggestions[0].fix
