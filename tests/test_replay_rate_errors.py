"""`replay --rate-errors`: the gyro rates' stated errors reach the saved model's band at exact conditions and nothing
else (gcs_sysid.aero.rateerrors)."""

from pathlib import Path

import numpy as np

from gcs_sysid.aero.table import REGRESSORS
from gcs_sysid.cli import _replay_options, build_parser
from gcs_sysid.gp import load_gp
from gcs_sysid.pipeline import ReplayOptions, run_replay

DATA = Path(__file__).resolve().parents[1] / "data"


def test_rate_errors_flag_reaches_the_options():
    base = ["replay", "x.tlog", "--airframe", "a.toml", "--out", "o"]
    assert _replay_options(build_parser().parse_args(base)).rate_errors is None
    assert _replay_options(build_parser().parse_args(base + ["--rate-errors", "on"])).rate_errors is True
    assert _replay_options(build_parser().parse_args(base + ["--rate-errors", "off"])).rate_errors is False


def test_rate_errors_change_the_band_at_exact_conditions_only(tmp_path):
    """On the sample flight: the same predictions and bands at the flight's regressors; the saved model states a
    yaw-rate map (and a roll-rate scale where the roll fit holds), and its band at exact conditions is wider."""
    log, airframe = DATA / "flights" / "sim-trainer-sysid.tlog", DATA / "airframes" / "sim-trainer.toml"
    opts = dict(progress=False, parallel=False, t_from=60.0, t_to=150.0, targets=("Cn",))
    off = run_replay(log, airframe, tmp_path / "off", ReplayOptions(rate_errors=False, **opts))
    on = run_replay(log, airframe, tmp_path / "on", ReplayOptions(rate_errors=True, **opts))
    np.testing.assert_array_equal(on.pred_mean, off.pred_mean)
    np.testing.assert_array_equal(on.pred_sigma, off.pred_sigma)
    note = [n for n in on.notes if n.startswith("rates' errors in the band at exact conditions")]
    assert len(note) == 1 and not any(n.startswith("rates' errors") for n in off.notes), on.notes
    m_on, m_off = load_gp(Path(on.model_path)), load_gp(Path(off.model_path))
    ir, ip = REGRESSORS.index("r_hat"), REGRESSORS.index("p_hat")
    assert np.any(np.asarray(m_on.map_cov)[ir] != 0)
    assert m_off.map_cov is None or not np.any(np.asarray(m_off.map_cov)[ir] != 0)
    if "p_hat scale error" in note[0]:
        assert np.asarray(m_on.scale_var)[ip] > 0
    rows = on.table.valid & np.all(np.isfinite(on.table.X), axis=1)
    X = on.table.X[rows]
    if m_on.n_mean_only:
        X = np.c_[X, np.zeros((len(X), m_on.n_mean_only))]
    mu_on, v_on = m_on.predict(X, include_noise=False, input_noise=False)
    mu_off, v_off = m_off.predict(X, include_noise=False, input_noise=False)
    np.testing.assert_allclose(mu_on, mu_off, rtol=1e-9, atol=1e-12)
    assert np.all(np.asarray(v_on) >= np.asarray(v_off) - 1e-15)
    assert np.mean(np.asarray(v_on)) > np.mean(np.asarray(v_off))
