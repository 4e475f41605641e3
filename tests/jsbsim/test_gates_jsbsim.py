"""The between-flight allowances of the diagnosis on JSBSim flights (issue 9, items 1 and 5); slow.

The evaluation's own path (``benchmarks/eval_jsbsim_diagnose.py``: fit on a clean reference flight, then
``diagnose --search`` differential against it, with the decoded reference flight): a clean c172x flight
gets no named cause (it fails when ``wind``, ``mass`` or a ``CZ`` term is invented), and a pitot reading
2 m/s high is named as ``bias:airspeed`` (it fails when the bias is missed).
"""

import pytest

from benchmarks.eval_jsbsim_diagnose import diagnose_case, reference_model, score_case
from benchmarks.jsbsim_harness.effects import Effect


@pytest.fixture(scope="module")
def c172x(tmp_path_factory):
    out = tmp_path_factory.mktemp("gates")
    _, model_path, ref = reference_model("c172x", out)
    return out, model_path, ref


@pytest.mark.slow
def test_clean_flight_gets_no_named_cause(c172x):
    out, model_path, ref = c172x
    findings, truth, _ = diagnose_case("c172x", 12, [], out, model_path, ref)
    assert truth["injected"] == []
    assert findings == [], [(f["cause"], f["estimate"], f["gain"].get("percent")) for f in findings]


@pytest.mark.slow
def test_pitot_bias_is_named(c172x):
    out, model_path, ref = c172x
    findings, truth, _ = diagnose_case("c172x", 1, [Effect("bias:airspeed", 2.0)], out, model_path, ref)
    sc = score_case(findings, truth)
    row = sc["effects"][0]
    assert row["top"] and row["est"], (sc["named"], row)
    top = findings[0]
    assert top["evidence"]["domain"] == "physical signature" and top["evidence"]["checks"]["wind_shift"]
