"""Differential diagnosis: an effect in the reference flight too is model inadequacy; one only here is a change.

Synthetic coefficient tables (``diag_synthetic``): the reference flight and the new flight have
different excitation (different seeds). The model under test lacks ``Cm:alpha^2`` (in both flights:
model inadequacy); the elevator loses effectiveness mid-flight (``Cm:delta_e`` +0.4 from 55 s, only in
the new flight: a change with its onset).
"""

import numpy as np
import pytest

from gcs_sysid.airframe import load_airframe
from gcs_sysid.diagnose.core import diagnose
from gcs_sysid.diagnose.differential import Reference, onset_of_change

from diag_flights import AIRFRAME
from diag_synthetic import BASE, measured

EFFECT, VALUE = "Cm:alpha^2", -2.0


@pytest.fixture(scope="module")
def airframe():
    return load_airframe(AIRFRAME)


def _flight(seed, hidden=None, onset=None, duration=100.0, value=VALUE):
    """(table, states) with EFFECT hidden, from ``onset`` (vehicle time, s) on when given."""
    clean, states = measured(BASE, seed=seed, hidden=None, duration=duration)
    if hidden is None:
        return clean, states
    eff, _ = measured(BASE, seed=seed, hidden=hidden, value=value, duration=duration)
    if onset is not None:
        eff.Y[:] = np.where((eff.t >= onset)[:, None], eff.Y, clean.Y)
    return eff, states


def test_effect_in_the_reference_too_is_model_inadequacy(airframe):
    table, states = _flight(3, EFFECT)
    ref_table, ref_states = _flight(8, EFFECT)
    d = diagnose(table, airframe, BASE, states, output_error=False,
                 references=[Reference(ref_table, ref_states, label="ref.tlog")])
    assert EFFECT not in [f["cause"] for f in d.findings], d.findings     # not reported as a change
    inad = {m["cause"]: m for m in d.model_inadequacy}
    assert EFFECT in inad, d.data["differential"]
    m = inad[EFFECT]
    assert m["extension"]["value"] == pytest.approx(VALUE, rel=0.25)
    assert m["in_references"][0]["label"] == "ref.tlog" and m["in_references"][0]["same"]
    assert "alpha_deg" in m["where"] and m["where"]["alpha_deg"][1] > m["where"]["alpha_deg"][0]
    assert m["rms_contribution"] > 0
    assert d.to_json()["model_inadequacy"] == d.model_inadequacy
    assert d.model_extended["Cm"]["alpha^2"] == pytest.approx(VALUE, rel=0.25)   # the extension that fixes it


def test_effect_only_in_this_flight_is_a_change_with_onset(airframe):
    onset = 55.0
    table, states = _flight(3, "Cm:delta_e", onset=onset, value=0.4)
    ref_table, ref_states = _flight(8)
    d = diagnose(table, airframe, BASE, states, output_error=False,
                 references=[Reference(ref_table, ref_states, label="clean.tlog")])
    assert d.model_inadequacy == []
    top = d.findings[0]
    assert top["cause"] == "Cm:delta_e"
    diff = top["evidence"]["differential"]
    assert diff["verdict"] == "changed" and not diff["references"][0]["same"]
    assert top["onset_s"] == pytest.approx(onset, abs=4.0)
    assert diff["after_onset"]["estimate"] == pytest.approx(BASE["Cm"]["delta_e"] + 0.4, rel=0.25)
    assert abs(diff["references"][0]["correction"]) < 3 * diff["references"][0]["std_error"] + 0.02


def test_onset_search_finds_a_step_and_not_a_constant():
    rng = np.random.default_rng(0)
    t = np.arange(0, 100, 0.02)
    delta = np.zeros((t.size, 6))
    delta[:, 4] = -np.sin(t * 3.0)
    step = np.where(t >= 40.0, 1.0, 0.0)
    R_wo = -(step[:, None] * delta) + rng.normal(0, 0.3, delta.shape)
    on = onset_of_change(t, R_wo, delta, np.ones(t.size, bool))
    assert on["onset_s"] == pytest.approx(40.0, abs=4.0) and on["amplitude_after"] == pytest.approx(1.0, abs=0.1)
    always = onset_of_change(t, -delta + rng.normal(0, 0.3, delta.shape), delta, np.ones(t.size, bool))
    assert always["onset_s"] is None


def test_reference_flights_recorded_by_fit_are_found_again(tmp_path):
    """``fit`` records the flight (path, SHA-256, window); ``diagnose`` uses it only while it is the same file."""
    import json

    from gcs_sysid.diagnose.differential import fit_record, reference_logs

    log = tmp_path / "ref.tlog"
    log.write_bytes(b"\xfe" * 1000)
    model = tmp_path / "m.toml"
    rec = fit_record(log, 10.0, None)
    assert rec["log"] == str(log.resolve()) and len(rec["sha256"]) == 64 and rec["window_s"] == [10.0, None]
    assert reference_logs(model) == ([], [])                               # no record: no reference
    model.with_suffix(".fit.json").write_text(json.dumps({"reference_flights": [rec]}))
    assert reference_logs(model) == ([{"log": str(log.resolve()), "window_s": [10.0, None]}], [])
    assert reference_logs(model, ["other.tlog"])[0] == [{"log": "other.tlog", "window_s": [None, None]}]
    assert reference_logs(model, []) == ([], [])                           # --no-reference
    log.write_bytes(b"\xfd" * 1000)
    refs, notes = reference_logs(model)
    assert refs == [] and "changed since the fit" in notes[0]
    log.unlink()
    refs, notes = reference_logs(model)
    assert refs == [] and "not found" in notes[0] and "--reference" in notes[0]


@pytest.mark.slow
def test_cli_fit_then_diagnose_uses_the_fitted_flight(tmp_path):
    """simulate two flights -> ``gcs-sysid fit`` on the clean one -> ``gcs-sysid diagnose`` the other: the
    hidden delay is a change (not in the fitted flight), compared against the flight the fit recorded."""
    import json

    from diag_flights import effects, plan_doc

    from gcs_sysid.cli import main
    from gcs_sysid.sim import load_model, plan_from_dict, simulate, write_tlog

    from diag_flights import MODEL

    af = load_airframe(AIRFRAME)
    truth = load_model(MODEL)
    for name, seed, eff in (("ref", 7, effects(None, None)), ("flight", 8, effects("delay:delta_e", 0.08))):
        r = simulate(af, truth, plan_from_dict(plan_doc(duration=90.0, seed=seed)), effects=eff)
        write_tlog(r, tmp_path / f"{name}.tlog", af)
    assert main(["fit", str(tmp_path / "ref.tlog"), "--airframe", str(AIRFRAME), "--out",
                 str(tmp_path / "m.toml"), "--from", "30"]) == 0
    assert main(["diagnose", str(tmp_path / "flight.tlog"), "--airframe", str(AIRFRAME), "--model",
                 str(tmp_path / "m.toml"), "--out", str(tmp_path / "d"), "--from", "30"]) == 0
    doc = json.loads((tmp_path / "d" / "diagnosis.json").read_text())
    diff = doc["data"]["differential"]
    assert diff["references"][0]["label"] == "ref.tlog"
    assert "model_inadequacy" in doc
    top = doc["findings"][0]
    assert top["cause"] == "delay:delta_e" and top["evidence"]["differential"]["verdict"] == "changed"


def test_missing_reference_log_is_a_one_line_error_before_decoding(tmp_path, capsys):
    from diag_flights import MODEL, ROOT

    from gcs_sysid.cli import main

    rc = main(["diagnose", str(ROOT / "data" / "flights" / "sim-trainer-sysid.tlog"), "--airframe", str(AIRFRAME),
               "--model", str(MODEL), "--out", str(tmp_path / "d"), "--reference", str(tmp_path / "nope.tlog")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and "--reference" in err[0] and "nope.tlog" in err[0]
    assert not (tmp_path / "d").exists()
