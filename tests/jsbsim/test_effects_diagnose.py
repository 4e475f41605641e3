"""Hidden effects injected into JSBSim (benchmarks/jsbsim_harness/effects.py) and found by the
differential sparse search of ``diagnose --search`` (gcs_sysid/diagnose/sparse.py); issue 9.

Default suite: the XML edits themselves (no flight), the injected Cn:delta_a seen in the exact
truth, one short flight with adverse yaw found as the top finding, and a clean flight on which
the search must name nothing. Slow: more effects on both tuning aircraft.
"""

import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from benchmarks.eval_jsbsim_diagnose import score_case
from benchmarks.jsbsim_harness import FlightConfig, aircraft
from benchmarks.jsbsim_harness.effects import SIZES, Effect, inject_xml, make_effect_flight, stock_model_dir
from gcs_sysid.diagnose import diagnose, run_fit
from gcs_sysid.diagnose.run import load_measurements
from gcs_sysid.sim.model_file import load_model

SHORT_S = 90.0


def _stock(name):
    spec = aircraft(name)
    return spec, ET.parse(stock_model_dir(spec) / f"{spec.model}.xml").getroot()


def test_xml_edits_add_the_terms_and_leave_the_stock_file_alone():
    spec, root = _stock("c172x")
    before = ET.tostring(root)
    new = inject_xml(root, spec, [Effect("Cn:delta_a", -0.06), Effect("delay:delta_e", 0.1),
                                  Effect("CY:scale", 1.3)])
    assert ET.tostring(root) == before                                   # a copy is edited
    yaw = next(a for a in new.iter("axis") if a.get("name") == "YAW")
    f = yaw.find("function[@name='aero/coefficient/injected_Cn_delta_a']")
    assert f is not None and float(f.find("product/value").text) == pytest.approx(0.5 * -0.06 * spec.aileron_sign)
    aero = new.find("aerodynamics")
    props = [p.text.strip() for p in aero.iter("property")]
    assert "fcs/elevator-pos-rad" not in props and "fcs/elevator-pos-delayed-rad" in props
    delay = new.find("flight_control/channel/actuator/delay")
    assert delay.get("type") == "frames" and delay.text == "20"          # 0.1 s at 200 Hz
    side = next(a for a in new.iter("axis") if a.get("name") == "SIDE")
    assert all(fn.find("product/value").text == "1.3" for fn in side.findall("function"))
    with pytest.raises(ValueError, match="unknown effect"):
        Effect("Cm:sin(alpha)", 1.0)


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """A clean 90-s c172x flight (seed 100) and the model fitted on it."""
    out = tmp_path_factory.mktemp("effects")
    files = make_effect_flight(FlightConfig("c172x", duration_s=SHORT_S, seed=100), [], out, stem="ref")
    run_fit(files.tlog, files.airframe, out / "ref.toml")
    return out, load_model(out / "ref.toml"), load_measurements(files.tlog, files.airframe)


def _diagnose(reference, effects, seed):
    out, model, ref = reference
    files = make_effect_flight(FlightConfig("c172x", duration_s=SHORT_S, seed=seed), effects, out)
    truth = json.loads(files.tlog.with_name(files.tlog.stem + "-effects.json").read_text())
    meas = load_measurements(files.tlog, files.airframe)
    diag = diagnose(meas.table, meas.airframe, model, meas.states, output_error=False, search=True,
                    search_reference=(ref.table, ref.states))
    return diag, truth, files


def test_adverse_yaw_is_the_top_finding_with_its_size(reference):
    diag, truth, files = _diagnose(reference, [Effect("Cn:delta_a", SIZES["Cn:delta_a"][1])], seed=2)
    # the effect is in the exact truth: Cn against delta_a moved by the injected amount
    d = np.load(files.truth, allow_pickle=True)
    X, Y = d["X"], d["Y"]
    A = np.column_stack([np.ones(len(X)), X[:, 1], X[:, 2], X[:, 4], X[:, 6], X[:, 7]])
    cn_da = np.linalg.lstsq(A, Y[:, 5], rcond=None)[0][4]
    assert cn_da == pytest.approx(-0.005 - 0.06, abs=0.01)
    sc = score_case(diag.findings, truth)
    assert diag.findings and diag.findings[0]["cause"] == "Cn:delta_a", sc
    row = sc["effects"][0]
    assert row["est"], row                                       # within 25 % of -0.06
    assert diag.data["sparse"]["differential"]


def test_clean_flight_gets_no_named_term(reference):
    diag, truth, _ = _diagnose(reference, [], seed=3)
    assert truth["injected"] == []
    assert diag.data["sparse"]["findings"] == [], diag.data["sparse"]["findings"]
    aero = [f["cause"] for f in diag.findings if f["cause"].split(":")[0] in ("CX", "CY", "CZ", "Cl", "Cm", "Cn")]
    assert aero == [], diag.findings


def test_score_case_fails_a_wrong_or_invented_cause():
    truth = {"injected": [{"cause": "Cn:delta_a", "value": -0.06}]}
    good = [{"cause": "Cn:delta_a", "estimate": -0.065, "std_error": 0.003, "model_value": -0.005,
             "gain": {"percent": 70.0}}]
    assert score_case(good, truth)["ok"]
    assert not score_case([{"cause": "cg_offset", "estimate": 0.1, "std_error": 0.01, "gain": {"percent": 80}}]
                          + good, truth)["ok"]
    off = [dict(good[0], estimate=-0.02)]
    assert not score_case(off, truth)["ok"]
    assert not score_case(good, {"injected": []})["ok"]        # a clean flight with a named cause


@pytest.mark.slow
@pytest.mark.parametrize("ac,name", [("c172x", "delay:delta_e"), ("sgs", "Cn:delta_a"), ("sgs", "CY:scale"),
                                     ("c172x", "Cl:alpha*beta")])
def test_more_effects_are_found(tmp_path, ac, name):
    """Flies "calm" (the harness's light until the fifteenth session): the search's thresholds were
    frozen on these flights and the test checks the mechanism, not a level of turbulence. In
    MIL-F-8785C light turbulence (severity 3) c172x ``delay:delta_e`` was named without its estimate
    and c172x ``Cl:alpha*beta`` and sgs ``CY:scale`` were not named (fifteenth session, turb15)."""
    from benchmarks.eval_jsbsim_diagnose import diagnose_case, reference_model

    _, model_path, ref = reference_model(ac, tmp_path, turbulence="calm")
    findings, truth, _ = diagnose_case(ac, 2, [Effect(name, SIZES[name][1])], tmp_path, model_path, ref,
                                       turbulence="calm")
    sc = score_case(findings, truth)
    assert sc["effects"][0]["top"] and sc["effects"][0].get("est"), sc


def test_summary_table_counts_each_score(tmp_path):
    from benchmarks.eval_jsbsim_diagnose import summarize

    hit = {"cause": "Cn:delta_a", "value": -0.06, "found": True, "top": True, "estimate": -0.058,
           "std_error": 0.002, "est": True, "gain_pct": 70.0, "gain": True, "cover": True}
    miss = {"cause": "Cn:delta_a", "value": -0.03, "found": False, "top": False}
    recs = [{"aircraft": "c172x", "seed": 1, "effects": [["Cn:delta_a", -0.06]],
             "score": {"ok": True, "effects": [hit], "named": ["Cn:delta_a"]}},
            {"aircraft": "c172x", "seed": 2, "effects": [["Cn:delta_a", -0.03]],
             "score": {"ok": False, "effects": [miss], "named": ["CX:alpha"]}},
            {"aircraft": "c172x", "seed": 11, "effects": [], "score": {"ok": False, "named": ["CX:alpha"]}}]
    p = tmp_path / "r.jsonl"
    p.write_text("\n".join(json.dumps(r) for r in recs) + "\n")
    lines = summarize([str(p)]).splitlines()
    row = next(ln for ln in lines if "| Cn:delta_a |" in ln)
    # records scored before the aliases (no ``*_alias`` keys) leave the with-aliases column empty
    assert "| 2 | 1/2 | 1/2 | 1/2 | 1/2 | | 1/1 |" in row and "[CX:alpha]" in row
    # scored with aliases (i9-alias): the column counts top, estimate, gain and all three
    hit.update(top_alias=True, est_alias=True, gain_alias=True)
    miss.update(top_alias=False, est_alias=False, gain_alias=False)
    recs[0]["score"]["ok_alias"], recs[1]["score"]["ok_alias"] = True, False
    p.write_text("\n".join(json.dumps(r) for r in recs) + "\n")
    row = next(ln for ln in summarize([str(p)]).splitlines() if "| Cn:delta_a |" in ln)
    assert "| 2 | 1/2 | 1/2 | 1/2 | 1/2 | 1/2, 1/2, 1/2, 1/2 | 1/1 |" in row
    clean = next(ln for ln in lines if "| clean |" in ln)
    assert "no named cause 0/1" in clean and "CX:alpha" in clean


def test_side_force_scale_is_scored_against_the_wind_axis_factor(tmp_path):
    """``CY:scale`` multiplies JSBSim's wind-axis side force by k, and the search's ``scale:CY`` candidate is
    the model's wind-axis side force, so the scored truth is k - 1 (branch i9-scale). The body-axis CY keeps
    its drag part ``-C_D sin(beta)``: a single factor on it would read ``(k - 1) CY_beta,w / (CY_beta,w - C_D)``,
    kept beside as ``body_axis_value`` (synthetic exact truth: wind-axis side force ``-0.3 beta``, drag 0.05)."""
    from benchmarks.eval_jsbsim_diagnose import scoring_truth, side_force_scale_truth

    rng = np.random.default_rng(0)
    T, k = 3000, 1.6
    a = np.radians(2.0 + rng.normal(0, 1.5, T))
    b = np.radians(rng.normal(0, 3.0, T))
    D, Yw, L = 0.05 + 0 * a, k * (-0.3 * b), 0.4 + 5 * a          # wind-axis drag, side (scaled), lift
    # body from wind (JSBSim Tw2b), forces (-D, Y_w, -L)
    ca, sa, cb, sb = np.cos(a), np.sin(a), np.cos(b), np.sin(b)
    CX = ca * cb * -D - ca * sb * Yw - sa * -L
    CY = sb * -D + cb * Yw
    CZ = sa * cb * -D - sa * sb * Yw + ca * -L
    X = np.zeros((T, 10))
    X[:, 0], X[:, 1] = a, b
    Y = np.zeros((T, 6))
    Y[:, 0], Y[:, 1], Y[:, 2] = CX, CY, CZ
    np.savez(tmp_path / "t.npz", X=X, Y=Y)
    body = (k - 1) * -0.3 / (-0.3 - 0.05)
    assert abs(side_force_scale_truth(tmp_path / "t.npz", k) - body) < 0.01 * body
    doc = scoring_truth({"injected": [{"cause": "scale:CY", "value": k - 1, "scale": k}]}, tmp_path / "t.npz")
    assert (doc["injected"][0]["value"] == pytest.approx(0.6)
            and doc["injected"][0]["wind_axis_value"] == pytest.approx(0.6))
    assert doc["injected"][0]["body_axis_value"] == pytest.approx(body, rel=0.01)
    assert scoring_truth(doc, tmp_path / "t.npz")["injected"][0]["value"] == pytest.approx(0.6)     # idempotent
    # scored against it: 0.57 is within 25 % of 0.6; 0.43 (the body-axis single factor) is not
    f = [{"cause": "scale:CY", "estimate": 1.57, "std_error": 0.01, "model_value": 1.0, "gain": {"percent": 80}}]
    assert score_case(f, doc)["ok"]
    assert not score_case([dict(f[0], estimate=1.43)], doc)["ok"]


@pytest.mark.slow
def test_one_mps_pitot_bias_reads_within_25_percent(tmp_path):
    """The C182's 1 m/s pitot bias (seed 2) read 0.65 m/s: the exact re-fit's coefficient estimate (0.66) had
    the closed-form fit's reference value (+0.01) subtracted, while the same re-fit reads -0.18 on the
    reference flight. Measured against the re-reduced reference, coefficient by coefficient, it reads 0.82
    (branch i9-scale, docs/diagnose.md). Flies "calm" (the harness's light until the fifteenth session,
    the flights this was measured on); in MIL-F-8785C light turbulence nothing was named (turb15)."""
    from benchmarks.eval_jsbsim_diagnose import diagnose_case, reference_model

    _, model_path, ref = reference_model("c182", tmp_path, turbulence="calm")
    findings, truth, _ = diagnose_case("c182", 2, [Effect("bias:airspeed", 1.0)], tmp_path, model_path, ref,
                                       turbulence="calm")
    sc = score_case(findings, truth)
    assert sc["effects"][0]["top"] and sc["effects"][0]["est"], [(f["cause"], f["estimate"]) for f in findings]


@pytest.mark.slow
@pytest.mark.parametrize("ac,seed", [("sgs", 15), ("pa28", 14)])
def test_windy_clean_flights_name_no_cause(tmp_path, ac, seed):
    """The two clean windy flights that named a cause before the air-angle scale allowance carried its
    uncertainty (sgs s15: ``CY:beta``, a 3.0 % small sideslip; pa28 s14: ``Cm:alpha``, a 6 % alpha
    scale; docs/benchmarks.md, branch i9-clean) name nothing."""
    from benchmarks.eval_jsbsim_diagnose import diagnose_case, reference_model

    _, model_path, ref = reference_model(ac, tmp_path)
    findings, truth, _ = diagnose_case(ac, seed, [], tmp_path, model_path, ref)
    assert score_case(findings, truth)["ok"], [f["cause"] for f in findings]


def test_one_term_side_force_scale_is_read_by_its_term():
    """On a model whose side force reads beta alone (eternity, t6, b737 ...), a ``CY:beta`` finding reads an
    injected ``CY:scale`` in the with-aliases scores, as the relative change of the derivative against the
    body-axis factor; the strict scores are untouched, and a side force of several terms gets no such alias."""
    truth = {"injected": [{"cause": "scale:CY", "value": 0.6, "body_axis_value": 0.55,
                           "side_variables": ["aero/beta-rad"]}]}
    f = [{"cause": "CY:beta", "estimate": -0.35, "model_value": -0.226, "std_error": 0.03, "gain": {"percent": 80}}]
    sc = score_case(f, truth)
    row = sc["effects"][0]
    assert not sc["ok"] and not row["top"]                                     # strict: still not named
    assert sc["ok_alias"] and row["top_alias"] and row["est_alias"] and row["gain_alias"]
    assert row["estimate_alias"] == pytest.approx(0.35 / 0.226 - 1)
    # a factor 1.29 for 1.55 is not within 25 %; no reference value: no estimate score; gain below 50 %: no gain
    assert not score_case([dict(f[0], estimate=-0.292)], truth)["effects"][0]["est_alias"]
    assert not score_case([dict(f[0], model_value=None)], truth)["effects"][0]["est_alias"]
    assert not score_case([dict(f[0], gain={"percent": 40})], truth)["effects"][0]["gain_alias"]
    # several side-force terms, or another top finding: no alias
    many = {"injected": [dict(truth["injected"][0], side_variables=["aero/beta-rad", "fcs/rudder-pos-rad"])]}
    assert not score_case(f, many)["effects"][0]["top_alias"]
    assert not score_case([{"cause": "Cm:delta_e", "estimate": 0.1, "gain": {"percent": 80}}] + f,
                          truth)["effects"][0]["top_alias"]


def test_side_axis_variables_reads_the_flown_model():
    from benchmarks.eval_jsbsim_diagnose import side_axis_variables

    assert side_axis_variables("eternity") == ["aero/beta-rad"] == side_axis_variables("t6")
    assert ("fcs/rudder-pos-rad" in side_axis_variables("c172x")
            and "velocities/r-aero-rad_sec" in side_axis_variables("c172x"))
    assert side_axis_variables("ultrastick") == ["aero/coefficient/CY"]     # summed elsewhere: not one term
    assert side_axis_variables("no-such-aircraft") == []


@pytest.mark.slow
def test_the_sideslip_aidings_own_yaw_rate_term_is_not_named_on_a_clean_flight(tmp_path, monkeypatch):
    """The SGS 1-26's clean seed 12 (the roster record's draws: per-aircraft sensor noise and turbulence, the sweep
    plan) named ``CY:r_hat`` -1.07 against -0.55: the two flights' sideslip aidings read ``CY_r_hat`` -1.07 and -0.54
    (JSBSim's side force has no yaw-rate term) and a side-force fit on the aided sideslip gives it back. With the
    aidings' first-pass jackknife carried under no change (``sparse.THRESHOLDS["coverage_beta_along"]``) it is within
    2 x 0.50 and nothing is named; without it, it is named (docs/benchmarks.md, *Forty-second session, lead*)."""
    import benchmarks.eval_jsbsim_diagnose as E
    from gcs_sysid.diagnose import sparse

    monkeypatch.setattr(E, "SENSOR_DRAW", "per_aircraft")
    monkeypatch.setattr(E, "TURBULENCE_DRAW", "per_aircraft")
    assert sparse.THRESHOLDS["coverage_beta_along"]
    _, model_path, ref = E.reference_model("sgs126", tmp_path, plan="sweep")
    findings, truth, _ = E.diagnose_case("sgs126", 12, [], tmp_path, model_path, ref, plan="sweep")
    assert score_case(findings, truth)["ok"], [f["cause"] for f in findings]
    monkeypatch.setitem(sparse.THRESHOLDS, "coverage_beta_along", False)
    findings, _, _ = E.diagnose_case("sgs126", 12, [], tmp_path, model_path, ref, plan="sweep")
    assert [f["cause"] for f in findings] == ["CY:r_hat"]
