"""The between-flight allowances of the diagnosis on JSBSim flights (issue 9, items 1 and 5); slow.

The evaluation's own path (``benchmarks/eval_jsbsim_diagnose.py``: fit on a clean reference flight, then
``diagnose --search`` differential against it, with the decoded reference flight): a clean c172x flight
gets no named cause (it fails when ``wind``, ``mass`` or a ``CZ`` term is invented), and a pitot reading
2 or 1 m/s high is named as ``bias:airspeed`` (it fails when the bias is missed).

All fly "calm" turbulence (the harness's light until the fifteenth session): the allowances were set
on these flights and the tests check the mechanism. In MIL-F-8785C light turbulence (severity 3) the
1 m/s bias was not named (``scale:CY`` instead; turb15).
"""

import pytest

from benchmarks.eval_jsbsim_diagnose import diagnose_case, reference_model, score_case
from benchmarks.jsbsim_harness.effects import Effect


@pytest.fixture(scope="module")
def c172x(tmp_path_factory):
    out = tmp_path_factory.mktemp("gates")
    _, model_path, ref = reference_model("c172x", out, turbulence="calm")
    return out, model_path, ref


@pytest.mark.slow
def test_clean_flight_gets_no_named_cause(c172x):
    out, model_path, ref = c172x
    findings, truth, _ = diagnose_case("c172x", 12, [], out, model_path, ref, turbulence="calm")
    assert truth["injected"] == []
    assert findings == [], [(f["cause"], f["estimate"], f["gain"].get("percent")) for f in findings]


@pytest.mark.slow
@pytest.mark.parametrize("size", [2.0, 1.0])
def test_pitot_bias_is_named(c172x, size):
    """The wind triangle (pitot against GPS minus the autopilot's wind) and the coefficients' exact
    signature agree: named at both sizes within 25 % (the code before named neither on these flights:
    ``scale:CY``, ``Cn:beta``, ``Cl:delta_a`` at 2 m/s, nothing at 1 m/s)."""
    out, model_path, ref = c172x
    findings, truth, _ = diagnose_case("c172x", 1, [Effect("bias:airspeed", size)], out, model_path, ref,
                                       turbulence="calm")
    sc = score_case(findings, truth)
    row = sc["effects"][0]
    assert row["top"] and row["est"], (sc["named"], row)
    ev = findings[0]["evidence"]
    assert ev["domain"] == "data compatibility" and ev["method"] == "wind triangle + coefficient signature"
    assert all(ev["checks"].values()) and ev["fused"]["agree"]
    assert abs(ev["wind_triangle"]["change"]["change_mps"] - size) < 0.6
    assert findings[0]["gain"]["percent"] >= 40.0
