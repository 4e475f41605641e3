"""Scoring of eval_jsbsim_diagnose through a finding's reported aliases (tenth session, branch i9-alias).

The findings are the shape ``diagnose`` returns (the t6's seed-1 ``CY:scale`` = 1.6 case of the ninth
session's final evaluation, the alias as ``gcs_sysid.diagnose.sparse`` reports it); no flight is flown.
"""

from benchmarks.eval_jsbsim_diagnose import score_case


def _finding(cause, est, mv, gain, aliases=()):
    return {"cause": cause, "estimate": est, "model_value": mv, "std_error": 0.01, "gain": {"percent": gain},
            "aliases": list(aliases)}


_ALIAS = {"cause": "scale:CY", "estimate": 1.588, "model_value": 1.0, "std_error": 0.0005,
          "gain": {"percent": 97.0}}
_SCALE = {"injected": [{"cause": "scale:CY", "value": 0.6}]}


def test_an_injected_cause_reported_as_the_top_findings_alias_counts_with_its_own_estimate():
    sc = score_case([_finding("CY:beta", -2.302, -1.467, 97.0, [_ALIAS])], _SCALE)
    e = sc["effects"][0]
    assert not e["top"] and not sc["ok"]                      # the strict count is kept
    assert e["top_alias"] and e["via_alias"] == "CY:beta" and sc["ok_alias"]
    assert abs(e["estimate_alias"] - 0.588) < 1e-9 and e["est_alias"] and e["gain_alias"]


def test_no_alias_no_credit_and_a_wrong_alias_estimate_fails():
    assert not score_case([_finding("CY:beta", -2.302, -1.467, 97.0)], _SCALE)["effects"][0]["top_alias"]
    # an alias of a finding that is not the top one does not count for a single effect
    sc = score_case([_finding("Cn:beta", 0.1, 0.08, 60.0), _finding("CY:beta", -2.3, -1.467, 97.0, [_ALIAS])], _SCALE)
    assert not sc["effects"][0]["top_alias"]
    bad = dict(_ALIAS, estimate=1.3)                          # reads 0.3 for 0.6
    e = score_case([_finding("CY:beta", -2.302, -1.467, 97.0, [bad])], _SCALE)["effects"][0]
    assert e["top_alias"] and not e["est_alias"]


def test_a_named_cause_is_scored_first_and_clean_flights_stay_strict():
    sc = score_case([_finding("scale:CY", 1.6, 1.0, 93.0, [{"cause": "CY:beta", "estimate": -9.0, "model_value": -1.0,
                                                            "gain": {"percent": 10.0}}])], _SCALE)
    assert sc["effects"][0]["top"] and sc["effects"][0]["top_alias"] and sc["ok"] and sc["ok_alias"]
    sc = score_case([_finding("CY:beta", -2.3, -1.467, 97.0, [_ALIAS])], {"injected": []})
    assert sc["ok"] is False and sc["ok_alias"] is False


def test_the_pitot_record_keeps_each_flights_own_wind_triangle_and_the_refit_by_coefficient():
    """``_pitot_summary`` (sixteenth session, branch i9-asw): the change since the reference alone hid that the
    asw20's reference flight read +0.39 m/s on the wind triangle, which every case's change carries."""
    from benchmarks.eval_jsbsim_diagnose import _pitot_summary

    wt = {"flight": {"bias_mps": 0.717, "heading_span_deg": 26.4},
          "change": {"change_mps": 0.330, "std_error": 0.572, "flight_mps": 0.717, "reference_mps": 0.386},
          "fused": {"estimate": 0.186, "t_statistic": 0.9, "agree": True, "coefficients_mps": 0.16,
                    "coefficients_se": 0.22},
          "coefficients_rereduced": {"estimate": 2.05, "by_coefficient": {
              "CY": {"estimate": 1.37, "std_error": 0.16, "used": True, "flight": 1.3, "reference": -0.07}}},
          "screen": {"passes": False}, "why": "the screen did not pass"}
    s = _pitot_summary({"pitot": {"wind_triangle": wt}})
    assert s["triangle_flight_mps"] == 0.717 and s["triangle_reference_mps"] == 0.386
    assert s["triangle_mps"] == 0.330 and s["triangle_heading_span_deg"] == 26.4
    assert s["rereduced_by_coefficient"] == {"CY": {"estimate": 1.37, "std_error": 0.16, "used": True}}
    assert _pitot_summary({}) == {}


def test_the_first_terms_record_reads_what_the_naming_gates_read():
    """first_term_gates: the navion's seed-90 Cm entry of the fifty-eighth session's probe (t 17, PRESS drop 0.389
    against 0.4, untouched gain 23 % confirmed at slope 1.05, t 9.4), and None where nothing was selected."""
    from benchmarks.eval_jsbsim_diagnose import first_term_gates

    entry = {"terms": [{"term": "alpha^2", "estimate": -4.114, "std_error": 0.3, "std_error_naming": 0.2392},
                       {"term": "delta_e", "estimate": -0.025, "std_error": 0.01, "std_error_naming": 0.01}],
             "score": 0.389, "held_out": {"percent": 23.3, "confirmation": {"slope": 1.05, "t_statistic": 9.4}}}
    g = first_term_gates(entry)
    assert g["term"] == "alpha^2" and g["estimate"] == -4.114 and abs(g["t"] - 17.2) < 0.05
    assert (g["score"], g["gain_pct"], g["confirm_slope"], g["confirm_t"]) == (0.389, 23.3, 1.05, 9.4)
    assert g["entered_with"] is None
    assert first_term_gates({"terms": [], "score": 0.0, "held_out": {"percent": 0.0}}) is None
