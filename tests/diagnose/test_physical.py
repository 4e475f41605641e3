"""Physical causes named only on their whole signature (issue 9, items 1-2).

- The gates' logic on hand-made candidates: three disjoint row sets, honest standard errors, a sensor
  bias the reference flight had too is a calibration note and not a cause.
- The real log path on the project's simulation (simulate -> write_tlog -> run_diagnose):
  a pitot reading 2 m/s high is named as ``bias:airspeed`` on its whole signature (it fails when the
  bias is missed), and a clean flight whose IMU has the turn-on biases a real one has, below what the
  reconstruction can vouch for, gets no named cause (it fails when one is invented; the code before
  this change named ``bias:gyro_x`` / ``bias:accel_x`` there).
"""

import numpy as np
import pytest

from gcs_sysid.airframe import load_airframe
from gcs_sysid.diagnose.compat import MIN_T_SENSOR, judge
from gcs_sysid.diagnose.context import held_out_blocks
from gcs_sysid.diagnose.physical import split_held_out
from gcs_sysid.diagnose.run import run_diagnose
from gcs_sysid.sim import Effects, load_model, plan_from_dict, simulate, write_tlog

from diag_flights import AIRFRAME, MODEL, plan_doc


def test_three_way_split_is_disjoint_and_covers_the_held_out_rows():
    t = np.arange(0.0, 120.0, 0.02)
    train, test = held_out_blocks(t, np.ones(t.size, bool))
    acc, gain = split_held_out(t, test)
    assert acc.sum() > 0.3 * test.sum() and gain.sum() > 0.3 * test.sum()
    assert not np.any(acc & gain) and not np.any((acc | gain) & train)
    assert np.array_equal(acc | gain, test)


def _cand(cause, est, se, score=80.0, gain=90.0, untouched=90.0):
    return {"cause": cause, "coefficient": "az", "estimate": est, "std_error": se, "score": score,
            "gain": {"percent": gain}, "evidence": {"t_statistic": est / se, "unit": "m/s^2",
                                                    "gain_untouched": {"percent": untouched}}}


def test_a_bias_the_reference_had_too_is_a_calibration_note_not_a_cause():
    ref = [("ref.tlog", [_cand("bias:accel_z", 0.31, 0.05)])]
    same = [_cand("bias:accel_z", 0.30, 0.05)]
    notes = judge(same, ref, 30.0, 10.0)
    assert not same[0]["accepted"] and same[0]["evidence"]["differential"]["verdict"] == "calibration"
    assert len(notes) == 1 and "calibration" in notes[0]
    changed = [_cand("bias:accel_z", 0.30, 0.05)]
    judge(changed, [("ref.tlog", [_cand("bias:accel_z", 0.0, 0.05)])], 30.0, 10.0)
    assert changed[0]["accepted"] and changed[0]["evidence"]["differential"]["verdict"] == "changed"
    alone = [_cand("bias:accel_z", 0.30, 0.05)]
    judge(alone, [], 30.0, 10.0)                         # no reference: named on its own evidence
    assert alone[0]["accepted"]


def test_an_offset_within_its_honest_error_or_lost_on_untouched_rows_is_not_named():
    weak = [_cand("bias:gyro_x", 0.004, 0.004 / (MIN_T_SENSOR - 0.5))]
    judge(weak, [], 30.0, 10.0)
    assert not weak[0]["accepted"] and not weak[0]["evidence"]["checks"]["significant"]
    lost = [_cand("bias:gyro_x", 0.02, 0.002, untouched=2.0)]
    judge(lost, [], 30.0, 10.0)
    assert not lost[0]["accepted"] and not lost[0]["evidence"]["checks"]["gain_untouched"]


@pytest.fixture(scope="module")
def sim_log(tmp_path_factory):
    af, m = load_airframe(AIRFRAME), load_model(MODEL)

    def make(name, effects):
        r = simulate(af, m, plan_from_dict(plan_doc(duration=90.0, seed=13, turbulence=1.5)), effects=effects)
        path = tmp_path_factory.mktemp("phys") / f"{name}.tlog"
        write_tlog(r, path, af)
        return path

    return make


def test_pitot_bias_is_named_on_its_whole_signature(sim_log, tmp_path):
    log = sim_log("pitot", Effects(airspeed_bias=2.0))
    d = run_diagnose(log, AIRFRAME, MODEL, tmp_path / "out", output_error=False)
    assert d.findings, d.data.get("pitot")
    top = d.findings[0]
    assert top["cause"] == "bias:airspeed", [(f["cause"], f["gain"]["percent"]) for f in d.findings]
    assert top["estimate"] == pytest.approx(2.0, rel=0.25)
    assert top["gain"]["percent"] >= 50.0 and 0 < top["std_error"] < 0.5
    ev = top["evidence"]
    assert all(ev["checks"].values()), ev["checks"]
    assert len(ev["signature"]["implied"]) >= 3                # many coefficients, one parameter
    # the log carries the autopilot's wind: the wind triangle and the coefficients agree (the signature
    # path, data.pitot.candidates, is judged too and would have named it on this flight)
    assert ev["domain"] == "data compatibility", ev["domain"]
    assert ev["method"] == "wind triangle + coefficient signature"
    assert ev["wind_triangle"]["change"]["change_mps"] == pytest.approx(2.0, abs=1.0)
    assert ev["fused"]["agree"] and ev["fused"]["t_statistic"] >= 3
    sig = next(c for c in d.data["pitot"]["candidates"] if c["cause"] == "bias:airspeed")
    assert sig["accepted"] and sig["gate"]["versus_terms"]["score_cause"] > sig["gate"]["versus_terms"]["score_terms"]
    assert [f["cause"] for f in d.findings].count("bias:airspeed") == 1


def test_imu_turn_on_biases_below_the_reconstruction_error_are_not_named(sim_log, tmp_path):
    # a real IMU's turn-on offsets: above the old floors (0.002 rad/s, 0.05 m/s^2), below 3 honest errors
    log = sim_log("imu", Effects(gyro_bias=(0.004, 0.0, 0.0), accel_bias=(0.08, 0.0, 0.0)))
    d = run_diagnose(log, AIRFRAME, MODEL, tmp_path / "out", output_error=False)
    assert d.findings == [], [(f["cause"], f["estimate"]) for f in d.findings]
    seen = {c["cause"]: c for c in d.data.get("sensor_candidates", [])}
    assert "bias:gyro_x" in seen and seen["bias:gyro_x"]["estimate"] == pytest.approx(0.004, abs=0.002)
