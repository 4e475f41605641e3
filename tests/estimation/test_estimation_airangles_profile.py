"""The alpha aiding's elevator slope by the gust model's likelihood (``airangles.ALPHA_PROFILE_COLUMNS``): in closed
loop the elevator follows the gust the kinematic alpha misses, least squares gives ``CZ_delta_e`` the gust's normal
force and the aided alpha carries ``-CZ_delta_e / CZ_alpha`` of the elevator; the profile takes the slope back."""

import numpy as np

from gcs_sysid.estimation import airangles
from gcs_sysid.estimation.airangles import aided_air_angles

DT = 0.02
MASS, S, B, C = 1000.0, 16.0, 11.0, 1.5
CZ_ALPHA, CZ_DE, CZ0 = -5.0, -0.4, -0.35


def _closed_loop(seed: int, duration: float = 90.0):
    """A vertical gust angle (Gauss-Markov, 1 s, 1 deg) that the kinematic alpha misses; the elevator is a doublet
    train plus the stabilising loop's answer to the gust (1 rad per rad, 0.2 s later); CZ linear in the true alpha and
    the elevator, 0.05 m/s^2 accelerometer noise. Returns the arguments of ``aided_air_angles`` and the true alpha."""
    rng = np.random.default_rng(seed)
    T = int(duration / DT)
    t = np.arange(T) * DT
    phi = np.exp(-DT / 1.0)
    w = rng.normal(0.0, np.radians(1.0) * np.sqrt(1 - phi * phi), T)
    g = np.zeros(T)
    for k in range(1, T):
        g[k] = phi * g[k - 1] + w[k]
    man = np.radians(2.0) * np.sign(np.sin(2 * np.pi * 0.4 * t)) * (np.sin(2 * np.pi * 0.07 * t) > 0)
    d_e = man + 1.0 * np.roll(g, 10)
    alpha_true = 0.05 - 0.3 * man + np.radians(0.4) * np.sin(2 * np.pi * 0.9 * t) + g
    alpha_kin = alpha_true - g + rng.normal(0, np.radians(0.03), T)
    V = np.full(T, 40.0)
    qbar = 0.5 * 1.1 * V**2
    f = np.zeros((T, 3))
    f[:, 2] = qbar * S / MASS * (CZ0 + CZ_ALPHA * alpha_true + CZ_DE * d_e) + rng.normal(0, 0.05, T)
    ctrl = {"delta_e": d_e, "delta_a": np.zeros(T), "delta_r": np.zeros(T)}
    beta = np.zeros(T)
    return (DT, alpha_kin, beta, V, qbar, f, np.zeros((T, 3)), ctrl, MASS, S, B, C, np.ones(T, bool)), alpha_true, d_e


def _loading(alpha, alpha_true, d_e):
    """The aided alpha's error's slope on the elevator (rad per rad), the mean and the true alpha's part removed."""
    A = np.column_stack([np.ones(len(d_e)), alpha_true, d_e])
    return float(np.linalg.lstsq(A, alpha - alpha_true, rcond=None)[0][2])


def test_elevator_slope_by_the_gust_likelihood_removes_the_elevator_loading(monkeypatch):
    args, alpha_true, d_e = _closed_loop(5)
    monkeypatch.setattr(airangles, "ALPHA_PROFILE_COLUMNS", ())
    ls = aided_air_angles(*args)
    monkeypatch.setattr(airangles, "ALPHA_PROFILE_COLUMNS", ("delta_e",))
    ml = aided_air_angles(*args)
    fa_ls, fa_ml = ls.axes[0], ml.axes[0]
    assert fa_ls.used and fa_ml.used
    j = list(fa_ls.columns).index("delta_e")
    # least squares: the gust's force in CZ_delta_e (-1.28 against -0.4), the aided alpha loaded with the elevator
    assert abs(fa_ls.coef[j] - CZ_DE) > 0.6
    assert abs(_loading(ls.alpha, alpha_true, d_e)) > 0.1
    # the likelihood: CZ_delta_e and the loading at most half as far off (measured -0.76, loading 0.047 against 0.123;
    # CZ_alpha's own errors in variables stay: this option moves only the profiled column)
    assert abs(fa_ml.coef[j] - CZ_DE) < 0.5 * abs(fa_ls.coef[j] - CZ_DE)
    assert abs(_loading(ml.alpha, alpha_true, d_e)) < 0.5 * abs(_loading(ls.alpha, alpha_true, d_e))
    assert "gust model's likelihood" in fa_ml.slope_method and not np.isfinite(fa_ml.coef_sigma[j])


def test_the_call_argument_is_the_module_option_for_one_call(monkeypatch):
    """``aided_air_angles(alpha_profile=)`` (what the live learner's ``LearnOptions.alpha_profile`` hands down through
    ``estimate_states``) gives the module option's result for that call only, either way round."""
    args, _, _ = _closed_loop(5)
    monkeypatch.setattr(airangles, "ALPHA_PROFILE_COLUMNS", ("delta_e",))
    glob = aided_air_angles(*args)
    monkeypatch.setattr(airangles, "ALPHA_PROFILE_COLUMNS", ())
    call = aided_air_angles(*args, alpha_profile=("delta_e",))
    plain = aided_air_angles(*args)
    assert np.array_equal(call.alpha, glob.alpha) and not np.array_equal(call.alpha, plain.alpha)
    monkeypatch.setattr(airangles, "ALPHA_PROFILE_COLUMNS", ("delta_e",))
    assert np.array_equal(aided_air_angles(*args, alpha_profile=()).alpha, plain.alpha)
