"""benchmarks/eval_jsbsim.py: the markdown summary of its JSON lines, and (slow) one scored flight."""

import json
import math

import numpy as np
import pytest

from benchmarks import eval_jsbsim
from gcs_sysid.aero.table import COEFFICIENTS

KEYS = ("meas", "gp", "true", "ls")


def _row(ac, seed, base):
    errs = {k: {c: base + seed + i for i, c in enumerate(COEFFICIENTS)} for k in KEYS}
    return {"aircraft": ac, "turbulence": "light", "aoa": "ahrs", "seed": seed, **errs, "cov_gp": 80.0 + seed,
            "cov_true": 90.0, "alpha_deg": 0.1 * seed, "beta_deg": 0.2, "alpha_rms_deg": 0.5, "beta_rms_deg": 1.0}


def test_summary_is_the_median_over_seeds(tmp_path):
    p = tmp_path / "r.jsonl"
    p.write_text("\n".join(json.dumps(_row("c172x", s, 10.0)) for s in (1, 2, 6)) + "\n"
                 + json.dumps(_row("pa28", 1, 50.0)) + "\n")
    text = eval_jsbsim.summarize([str(p)])
    lines = [ln for ln in text.splitlines() if ln.startswith("| c172x") and "| measured |" in ln]
    assert len(lines) == 1
    cells = [c.strip() for c in lines[0].split("|")]
    # median over seeds 1, 2, 6 of base + seed + i: base + 2 + i
    assert cells[6:12] == [f"{10.0 + 2 + i:.1f}" for i in range(6)]
    assert "0.20 / 0.20" in lines[0]
    assert any(ln.startswith("| pa28 | light") for ln in text.splitlines())     # used since 2026-11-22
    assert "forces" in text and "19.8" in text
    assert "aero rates" not in text                  # rows without the score: no row for it


def test_summary_has_the_aero_rate_score_when_the_rows_have_it(tmp_path):
    rows = [_row("sgs", s, 10.0) for s in (1, 2)]
    for r in rows:
        r["true_air"] = {c: 1.0 + r["seed"] for c in COEFFICIENTS}
        r["cov_true_air"] = 97.0
    p = tmp_path / "r.jsonl"
    p.write_text("\n".join(json.dumps(r) for r in rows) + "\n")
    line = [ln for ln in eval_jsbsim.summarize([str(p)]).splitlines() if "aero rates |" in ln]
    assert len(line) == 1 and "| 2.5 |" in line[0] and "| 97 |" in line[0]


def test_cy_diagnosis_splits_a_spurious_rate_slope_from_the_bias():
    """A model with JSBSim's CY_beta, a spurious CY_r_hat and an offset: the diagnosis returns the model's and the
    truth's local slopes, a sideslip scale of 1 for an unbiased estimate, and the error as bias + linear (no rest)."""
    rng = np.random.default_rng(5)
    n = 2000
    Xt = rng.standard_normal((n, 10)) * 0.05
    Xe = Xt.copy()
    Xe[:, 1] += 0.01 * rng.standard_normal(n)
    cy_true = -1.0 * Xt[:, 1]
    cy_model = cy_true - 1.8 * Xt[:, 4] + 0.01
    d = eval_jsbsim.cy_diagnosis(Xe, Xt, cy_model, cy_true)
    assert d["CY_beta_true"] == pytest.approx(-1.0, abs=1e-9) and d["CY_beta_model"] == pytest.approx(-1.0, abs=1e-9)
    assert d["CY_r_hat_model"] == pytest.approx(-1.8, abs=1e-9) and d["CY_r_hat_true"] == pytest.approx(0.0, abs=1e-9)
    assert d["beta_scale"] == pytest.approx(1.0, abs=0.02)
    assert d["rest_pct"] < 1e-6
    assert d["err_pct"] ** 2 == pytest.approx(d["bias_pct"] ** 2 + d["linear_pct"] ** 2, rel=1e-2)
    assert d["linear_pct"] == pytest.approx(180.0, rel=0.1)   # 1.8 x RMS(r_hat) / RMS(beta), equal RMS


@pytest.mark.slow
def test_one_flight_is_scored(tmp_path):
    row = eval_jsbsim.evaluate("sgs", 4, "light", "vane", 40.0, tmp_path)
    for k in KEYS + ("meas_all", "meas_true_accel", "meas_flat", "meas_offset", "true_air"):
        assert set(row[k]) == set(COEFFICIENTS)
        assert all(math.isfinite(v) for v in row[k].values()), (k, row[k])
    assert max(row["meas_true_accel"][c] for c in ("Cl", "Cm", "Cn")) < 2.0   # truth accelerations: exact moments
    assert row["alpha_deg"] < 0.2 and 0 <= row["cov_gp"] <= 100
    assert np.isfinite(row["beta_rms_deg"])
    # JSBSim's Cl is linear in the air-relative rates: at them the model leaves less than at the gyro's
    assert row["true_air"]["Cl"] < row["true"]["Cl"]


def test_gp_noise_defaults_to_learned_and_takes_independent(capsys):
    """``--gp-noise``: ``learned`` by default (twenty-fifth session, i8-learned), ``independent`` (the old default,
    one noise variance per output) by name; the choice is what sets the pipeline's three noise constants."""
    with pytest.raises(SystemExit):
        eval_jsbsim.main(["--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "default learned" in text and "independent" in text
    import gcs_sysid.pipeline as pipeline

    assert pipeline.GP_NOISE == "learned"
    assert pipeline.GP_NOISE_MODES["independent"] == (False, "full", "signal")


def test_fair_least_squares_line_trains_cl_on_the_gps_air_rate_target():
    """``ls_air_target_scores`` (twenty-ninth session, i8-guard): the LS line with Cl trained on the target the GP
    gets with ``air_roll_train`` and asked at the held-out air rate. On the simulated roll axis of
    ``tests/aero/test_rollgust.py`` (gust in the moment) it is closer to the air-rate Cl than the same stepwise fit
    of the measured Cl asked at the same rate; the other coefficients are the given LS model's."""
    import sys
    from pathlib import Path
    from types import SimpleNamespace

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "aero"))
    from test_rollgust import B, CLB, CLDA, CLP, IXX, S, _record, _roll_case

    from benchmarks.eval_jsbsim import ls_air_target_scores
    from gcs_sysid.aero.table import REGRESSORS

    X, Y, p, g = _record(seed=1)
    n = len(X)
    rng = np.random.default_rng(3)
    il = 3
    Y[:, [0, 1, 2, 4, 5]] = 0.01 * rng.normal(size=(n, 5))
    held, st, tab = _roll_case(X, Y, p, g, rng)
    res = SimpleNamespace(table=tab, states=st, train=~held, held_out=held)
    j, cb, cd = (REGRESSORS.index(k) for k in ("p_hat", "beta", "delta_a"))
    Yt = np.zeros_like(Y)
    Yt[:, il] = CLB * X[:, cb] + CLP * (X[:, j] - g) + CLDA * X[:, cd]      # Cl at the air rate
    Yt[:, [0, 1, 2, 4, 5]] = 1.0
    ls = SimpleNamespace(evaluate=lambda Xq: np.zeros((len(Xq), 6)))
    out = ls_air_target_scores(res, SimpleNamespace(Ixx=IXX, S=S, b=B), held, Yt, ls, "predicted:Cl")
    assert out["ls_airtrain_applied"]
    assert out["ls_airtrain"]["Cl"] < 0.7 * out["ls_airtab"]["Cl"]
    for c in ("CX", "CY", "CZ", "Cm", "Cn"):
        assert out["ls_airtrain"][c] == out["ls_airtab"][c] == 100.0


def test_eval_gp_jsbsim_scores_cl_with_the_replays_air_rate_pair(tmp_path):
    """``eval_gp_jsbsim`` (thirtieth session, i8-airfit): the cache holds the replay's air-rate pair
    (:func:`benchmarks.eval_gp_jsbsim.air_rate_arrays`) and ``score`` trains Cl on its target and asks it at the
    held-out air rate by default. On the simulated roll axis of ``tests/aero/test_rollgust.py`` the independent GPs' Cl
    is closer to the air-rate Cl with the pair than without (``air_roll=False``, the old tables); the other outputs' GPs
    see the same rows and targets either way (identical errors); ``ls`` is the fair line; a cache made before the pair's
    arrays is refused unless ``air_roll=False``."""
    import sys
    from pathlib import Path
    from types import SimpleNamespace

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "aero"))
    from test_rollgust import B, CLB, CLDA, CLP, IXX, S, _record, _roll_case

    from benchmarks.eval_gp_jsbsim import air_rate_arrays, score
    from gcs_sysid.aero.table import REGRESSORS

    X, Y, p, g = _record(seed=1)
    n = len(X)
    rng = np.random.default_rng(3)
    il, others = 3, [0, 1, 2, 4, 5]
    Y[:, others] = 0.01 * rng.normal(size=(n, 5))
    held, st, tab = _roll_case(X, Y, p, g, rng)
    res = SimpleNamespace(table=tab, states=st, train=~held, held_out=held)
    j, cb, cd = (REGRESSORS.index(k) for k in ("p_hat", "beta", "delta_a"))
    Xt_air = X.copy()
    Xt_air[:, j] = X[:, j] - g
    Yt = np.ones_like(Y)
    Yt[:, il] = CLB * X[:, cb] + CLP * (X[:, j] - g) + CLDA * X[:, cd]      # Cl at the air rate
    ls = SimpleNamespace(evaluate=lambda Xq: np.zeros((len(Xq), 6)))
    air = air_rate_arrays(res, SimpleNamespace(Ixx=IXX, S=S, b=B), ls)
    assert air["air_applied"] and not np.array_equal(air["X_air"][held], X[held])
    np.testing.assert_array_equal(air["X_air"][~held], X[~held])
    np.testing.assert_array_equal(air["Y_air"][:, others], Y[:, others])
    base = dict(t=tab.t, X=X, Y=Y, valid=np.ones(n, bool), held=held, train=~held, Xt=X, Yt=Yt,
                gp_mean=np.zeros_like(Y), gp_sigma=np.zeros_like(Y), ls=ls.evaluate(X),
                x_offset_cov=np.full((10, 10), np.nan))
    old, new = tmp_path / "sim-1-light-ahrs.npz", tmp_path / "new" / "sim-1-light-ahrs.npz"
    new.parent.mkdir()
    np.savez(old, **base)
    np.savez(new, **base, **air, Xt_air=Xt_air)
    with pytest.raises(ValueError, match="air-rate"):
        list(score(old, ["ls"]))
    on = {r["variant"]: r for r in score(new, ["ls", "indep"], thin=4)}
    off = {r["variant"]: r for r in score(new, ["ls", "indep"], thin=4, air_roll=False)}
    assert on["indep"]["air_roll"] and not off["indep"]["air_roll"] and off["indep"]["aoa"].endswith("/gyro-Cl")
    assert on["indep"]["err"]["Cl"] < 0.8 * off["indep"]["err"]["Cl"]
    assert on["indep"]["err_true"]["Cl"] < off["indep"]["err_true"]["Cl"]
    assert on["ls"]["err"]["Cl"] < 100.0 == off["ls"]["err"]["Cl"]                     # the fair line's Cl fitted
    for c in ("CX", "CY", "CZ", "Cm", "Cn"):
        assert on["indep"]["err"][c] == off["indep"]["err"][c]


def test_gp_seed_option_reaches_the_replay(monkeypatch, tmp_path):
    """``--gp-seed N`` is handed to :func:`eval_jsbsim.evaluate` (which passes it as ``ReplayOptions.gp_seed``);
    0 by default, as before the option existed. ``--beta-gls on|off`` arrives as ``beta_gls`` True / False (the
    replay's ``ReplayOptions.beta_gls``), None without the flag; ``--rate-errors on|off`` likewise as
    ``rate_errors``."""
    import gcs_sysid.estimation.airangles as aa

    seen = []

    class Stop(Exception):
        pass

    def fake_evaluate(*args, beta_gls=None, air_yaw=None, rate_errors=None, air_pitch=None):
        seen.append(("air_pitch", air_pitch) if air_pitch is not None else
                    (args[-1], beta_gls) if rate_errors is None else ("rate_errors", rate_errors))
        raise Stop               # stop before the printing, which needs a scored row

    monkeypatch.setattr(eval_jsbsim, "evaluate", fake_evaluate)
    monkeypatch.setattr(aa, "BETA_GLS", aa.BETA_GLS)       # --beta-gls also sets the aiding's module switch
    for argv, want in (([], (0, None)), (["--gp-seed", "1"], (1, None)), (["--beta-gls", "on"], (0, True)),
                       (["--beta-gls", "off"], (0, False)), (["--rate-errors", "on"], ("rate_errors", True)),
                       (["--rate-errors", "off"], ("rate_errors", False)),
                       (["--air-pitch", "on"], ("air_pitch", True)), (["--air-pitch", "off"], ("air_pitch", False))):
        with pytest.raises(Stop):
            eval_jsbsim.main(["--aircraft", "sgs", "--turbulence", "light", "--work", str(tmp_path), *argv])
        assert seen[-1] == want


def test_band_output_sets_one_outputs_stated_band_regime(monkeypatch):
    """``--band-output C=SPEC`` edits the pipeline's ``STATED_BAND_SIGN`` / ``STATED_BAND_LESS_WHITE`` /
    ``WHITE_BAND_NO_STATED_INPUT`` for one output (rule 75's arms: ``CX=white`` against ``CX=d``; rule 76's against
    ``CX=white-learned``) and refuses an unknown output or regime."""
    import gcs_sysid.pipeline as pipeline

    monkeypatch.setattr(pipeline, "STATED_BAND_SIGN", {"CZ": 1.0, "Cm": 1.0, "Cn": 0.0})
    monkeypatch.setattr(pipeline, "STATED_BAND_LESS_WHITE", ())
    monkeypatch.setattr(pipeline, "WHITE_BAND_NO_STATED_INPUT", ())
    eval_jsbsim._band_output(pipeline, "CX=white-learned")
    assert "CX" not in pipeline.STATED_BAND_SIGN and pipeline.WHITE_BAND_NO_STATED_INPUT == ("CX",)
    eval_jsbsim._band_output(pipeline, "CX=d")
    assert pipeline.WHITE_BAND_NO_STATED_INPUT == ()
    assert pipeline.STATED_BAND_SIGN["CX"] == 0.0 and pipeline.STATED_BAND_LESS_WHITE == ("CX",)
    eval_jsbsim._band_output(pipeline, "CX=white")
    assert "CX" not in pipeline.STATED_BAND_SIGN and pipeline.STATED_BAND_LESS_WHITE == ()
    eval_jsbsim._band_output(pipeline, "Cn=-1")
    assert pipeline.STATED_BAND_SIGN == {"CZ": 1.0, "Cm": 1.0, "Cn": -1.0}
    for bad in ("CQ=d", "CX=2", "CX"):
        with pytest.raises(SystemExit, match="--band-output"):
            eval_jsbsim._band_output(pipeline, bad)
