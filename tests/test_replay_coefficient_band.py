"""`replay --coefficient-band stated`: the coefficient's band of CZ, Cm and Cn from the blocked validation's
residual and the estimator's stated measurement error (gcs_sysid.gp.coefband); the means, the measurement's band
and the other outputs' bands do not move."""

from pathlib import Path

import numpy as np
import pytest

from gcs_sysid.aero.coefficients import stated_output_variance
from gcs_sysid.aero.table import COEFFICIENTS
from gcs_sysid.airframe import load_airframe
from gcs_sysid.cli import _replay_options, build_parser
from gcs_sysid.errors import InputError
from gcs_sysid.estimation.states import FlightStates
from gcs_sysid.gp import load_gp
from gcs_sysid.gp.coefband import stated_band_variance
from gcs_sysid.pipeline import STATED_BAND_LESS_WHITE, STATED_BAND_SIGN, ReplayOptions, check_replay, run_replay

DATA = Path(__file__).resolve().parents[1] / "data"
LOG, AIRFRAME = DATA / "flights" / "sim-trainer-sysid.tlog", DATA / "airframes" / "sim-trainer.toml"


def test_coefficient_band_flag_reaches_the_options_and_a_bad_name_is_refused(tmp_path):
    base = ["replay", "x.tlog", "--airframe", "a.toml", "--out", "o"]
    assert _replay_options(build_parser().parse_args(base)).coefficient_band is None
    assert _replay_options(build_parser().parse_args(base + ["--coefficient-band", "stated"])).coefficient_band \
        == "stated"
    with pytest.raises(InputError, match="coefficient band 'wide': expected one of white, stated"):
        check_replay(LOG, AIRFRAME, tmp_path / "o", ReplayOptions(coefficient_band="wide"))


def test_stated_output_variance_by_hand():
    af = load_airframe(AIRFRAME)
    n = 4
    sig = {"ax": np.full(n, 0.1), "ay": np.full(n, 0.2), "az": np.full(n, 0.3), "p_dot": np.full(n, 0.5),
           "q_dot": np.full(n, 0.4), "r_dot": np.full(n, 0.25)}
    qbar = np.array([200.0, 250.0, 0.0, 300.0])
    st = FlightStates(np.arange(n) * 0.02, 50.0, {"qbar": qbar}, sigma=sig)
    v = stated_output_variance(st, af)
    qS = qbar[0] * af.S
    expect = [(af.mass * 0.1 / qS) ** 2, (af.mass * 0.2 / qS) ** 2, (af.mass * 0.3 / qS) ** 2,
              ((af.Ixx * 0.5) ** 2 + (af.Ixz * 0.25) ** 2) / (qS * af.b) ** 2, (af.Iyy * 0.4 / (qS * af.c)) ** 2,
              ((af.Izz * 0.25) ** 2 + (af.Ixz * 0.5) ** 2) / (qS * af.b) ** 2]
    np.testing.assert_allclose(v[0], expect, rtol=1e-12)
    assert np.isnan(v[2]).all()                                   # no dynamic pressure: nothing stated
    np.testing.assert_allclose(v[1] * (250.0 / 200.0) ** 2, v[0], rtol=1e-12)
    assert stated_output_variance(FlightStates(st.t, 50.0, {"qbar": qbar}), af) is None
    part = stated_output_variance(FlightStates(st.t, 50.0, {"qbar": qbar}, sigma={"az": sig["az"]}), af)
    assert np.isfinite(part[[0, 1, 3], 2]).all() and np.isnan(np.delete(part, 2, axis=1)).all()


def test_stated_band_moves_only_its_outputs_bands(tmp_path, monkeypatch):
    """On a part of the sample flight: the outputs of STATED_BAND_SIGN take the stated band (recomputed here from the
    saved model and the states); CX, named in WHITE_BAND_NO_STATED_INPUT for this run, the white band with NIGP's
    learned input noise alone (latent + learned input term + noise, less the white share); CY and Cl keep the white
    one (the measurement's band less the white share), which the stated band also falls back to where nothing is
    stated."""
    from gcs_sysid import pipeline

    monkeypatch.setattr(pipeline, "WHITE_BAND_NO_STATED_INPUT", ("CX",))
    opts = dict(progress=False, parallel=False, t_from=60.0, t_to=150.0)
    stated = run_replay(LOG, AIRFRAME, tmp_path / "stated", ReplayOptions(coefficient_band="stated", **opts))
    model = load_gp(Path(stated.model_path))
    assert model.n_outputs == 6
    w = model.noise_var() - model.noise_var(False)
    white = np.sqrt(np.maximum(stated.pred_sigma_obs**2 - w[None], 0.0))
    rows = stated.table.valid & np.all(np.isfinite(stated.table.X), axis=1)
    X = stated.table.X[rows]
    if model.n_mean_only:
        a = stated.table.alpha_dot_hat[rows]
        X = np.c_[X, np.where(np.isfinite(a), a, 0.0)]
    sign = np.array([STATED_BAND_SIGN.get(c, np.nan) for c in COEFFICIENTS])
    less_white = np.array([c in STATED_BAND_LESS_WHITE for c in COEFFICIENTS])
    v = stated_band_variance(model, X, stated_output_variance(stated.states, load_airframe(AIRFRAME))[rows], sign,
                             less_white=less_white)
    _, _, lat, learned = model.predict_parts(X)
    learned_band = np.sqrt(np.maximum(lat + learned + model.noise_var()[None] - w[None], 0.0))
    no_stated = np.array([c == "CX" for c in COEFFICIENTS])
    expect = np.where(np.isfinite(v), np.sqrt(v), np.where(no_stated[None], learned_band, white[rows]))
    np.testing.assert_allclose(stated.pred_sigma[rows], expect, rtol=1e-9, atol=1e-15)
    for k, c in enumerate(COEFFICIENTS):          # the stated band differs from the white one where it applies
        moved = np.mean(np.abs(stated.pred_sigma[rows, k] - white[rows, k]) > 1e-6 * np.abs(white[rows, k]))
        assert (moved > 0.5) == (c in STATED_BAND_SIGN or c == "CX"), (c, moved)
    assert (stated.pred_sigma[rows, 0] <= white[rows, 0] * (1 + 1e-9)).all()   # a term left out, never added
