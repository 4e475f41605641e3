"""The side-force model by generalised least squares under the gust model (estimation/airangles.py, ``BETA_GLS``).

A synthetic sideslip record whose exact side force has no yaw-rate term: the heading is a lightly damped directional
oscillator (0.2 Hz, damping 0.2; Etkin, *Dynamics of Atmospheric Flight*, 1972, sec. 9.4) forced by the rudder and by
the sideslip a first-order Gauss-Markov lateral gust adds, and a yaw damper moves the rudder against the yaw rate, so
both the yaw rate and the rudder answer the gust the kinematic sideslip misses (it carries the mechanics: the held
slopes, the signs, the fallback). On the JSBSim C.684 least squares on the kinematic sideslip gives them the gust's
side force (``CY_r_hat`` -1.35 and ``CY_delta_r`` -0.11 against zero); on the gust model's innovations a regressor
that answers the gust depends on its past innovations only (the first test, on a regression built for it).
"""

import numpy as np
from scipy.signal import lfilter

from gcs_sysid.estimation import airangles
from gcs_sysid.estimation.airangles import _axis, _gls_gust_fit

from synthetic_sideslip import directional_record

DT, T = 0.02, 6000
CY_BETA, CY_DR = -0.55, 0.15
B_2V = 0.25      # b / (2 V), s: r_hat = B_2V r


def _record(seed: int, damper: float = 1.5):
    """(kinematic sideslip (T,), measured CY (T,), {"r_hat", "delta_r": (T,)}); rad; rudder doublets every 10 s plus a
    yaw damper ``-damper r``."""
    rng, beta_kin, g, r, dr = directional_record(seed, T, DT, 2.0, damper)
    cy = CY_BETA * (beta_kin + g) + CY_DR * dr + 0.005 * rng.standard_normal(T)
    return beta_kin, cy, {"r_hat": B_2V * r, "delta_r": dr}


def test_gls_gives_a_regressor_that_answers_the_gust_no_share_of_it():
    # y = 2 x + g + v: x partly answers the gust's past innovations (as the yaw rate and a yaw damper's rudder answer
    # the lateral gust), so least squares on the levels gives x the gust's share; on the innovations it has none
    rng = np.random.default_rng(1)
    phi = np.exp(-DT / 2.0)
    for _ in range(4):
        n = 6000
        w = rng.standard_normal(n) * np.sqrt(1 - phi * phi)
        g = lfilter([1.0], [1, -phi], w)                                  # Gauss-Markov gust, tau 2 s
        x = lfilter([1.0], [1, -0.9], rng.standard_normal(n)) * 0.3 + lfilter([0, 1.0], [1, -0.97], w)
        y = 2.0 * x + g + 0.05 * rng.standard_normal(n)
        x, y = x - x.mean(), y - y.mean()
        ols = np.linalg.lstsq(x[:, None], y, rcond=None)[0][0]
        c = _gls_gust_fit(DT, x[:, None], y, [slice(0, n)], airangles.TAUS_S, airangles.RATIOS)[0]
        assert ols > 2.4                      # measured 2.58-2.72
        assert abs(c[0] - 2.0) < 0.06         # measured 2.028-2.030


def test_gls_on_a_record_with_a_yaw_damper(monkeypatch):
    monkeypatch.setattr(airangles, "BETA_GLS_SIGNS", {})
    for seed in range(2):
        kin, cy, others = _record(seed)
        use = np.ones(T, bool)
        fit = _axis("beta", DT, kin, cy, others, use, 2, -1.0, False, False, gls=True)[2]
        assert fit.columns == ("1", "beta", "r_hat", "delta_r")
        assert fit.slope_method.startswith("GLS under the gust model") and fit.used
        assert abs(fit.coef[1] / CY_BETA - 1) < 0.05 and abs(fit.coef[3] - CY_DR) < 0.02
        assert np.isfinite(fit.coef_sigma[1:]).all()


def test_gls_slopes_are_held_in_the_later_passes(monkeypatch):
    monkeypatch.setattr(airangles, "BETA_GLS_SIGNS", {})
    kin, cy, others = _record(4)
    use = np.ones(T, bool)
    two = _axis("beta", DT, kin, cy, others, use, 2, -1.0, False, False, gls=True)[2]
    four = _axis("beta", DT, kin, cy, others, use, 4, -1.0, False, False, gls=True)[2]
    np.testing.assert_allclose(two.coef[1:], four.coef[1:], rtol=0, atol=1e-12)
    # the first pass's jackknife is stated (on the innovations at the chosen gust model)
    assert np.isfinite(two.slope_jackknife[1:]).all()


def test_a_wrong_sign_is_held_at_zero_and_the_others_refitted(monkeypatch):
    kin, cy, others = _record(5)
    use = np.ones(T, bool)
    others = dict(others, delta_r=-others["delta_r"])     # a rudder wired the other way: CY_delta_r < 0 fitted
    monkeypatch.setattr(airangles, "BETA_GLS_SIGNS", {"delta_r": 1.0})
    fit = _axis("beta", DT, kin, cy, others, use, 2, -1.0, False, False, gls=True)[2]
    j = fit.columns.index("delta_r")
    assert fit.coef[j] == 0.0 and "delta_r held at 0 (wrong sign)" in fit.slope_method
    assert np.isnan(fit.coef_sigma[j]) and np.isfinite(fit.coef_sigma[1])
    monkeypatch.setattr(airangles, "BETA_GLS_SIGNS", {})
    free = _axis("beta", DT, kin, cy, others, use, 2, -1.0, False, False, gls=True)[2]
    assert free.coef[j] < -0.1


def test_not_identified_on_the_innovations_falls_back_to_least_squares(monkeypatch):
    kin, cy, others = _record(6)
    use = np.ones(T, bool)
    ls = _axis("beta", DT, kin, cy, others, use, 2, -1.0, False, False)[2]
    real = airangles._gls_gust_fit

    def flat(*args, **kw):          # a slope of the wrong sign on the innovations
        c, se, *rest = real(*args, **kw)
        return (np.r_[0.01, c[1:]], se, *rest)

    monkeypatch.setattr(airangles, "_gls_gust_fit", flat)
    fit = _axis("beta", DT, kin, cy, others, use, 2, -1.0, False, False, gls=True)[2]
    assert fit.slope_method.startswith("OLS; GLS under the gust model not identified (beta +0.01")
    assert fit.used
    np.testing.assert_allclose(fit.coef, ls.coef, rtol=0, atol=1e-12)


def test_gls_gust_fit_recovers_an_exogenous_slope_and_states_its_error():
    # y = 2 x + e, e a Gauss-Markov gust (tau 2 s) plus white noise: GLS is unbiased and its standard error honest
    rng = np.random.default_rng(7)
    est, se = [], []
    for _ in range(20):
        n = 3000
        x = lfilter([1.0], [1, -0.9], rng.standard_normal(n))
        phi = np.exp(-DT / 2.0)
        e = lfilter([np.sqrt(1 - phi * phi)], [1, -phi], rng.standard_normal(n)) * 3.0 + 0.3 * rng.standard_normal(n)
        y = 2.0 * x + e
        c, s, res, cov, tau, ratio, Wa, wy = _gls_gust_fit(DT, x[:, None], y, [slice(0, n)], airangles.TAUS_S,
                                                            airangles.RATIOS)
        assert res.shape == (n,) and cov.shape == (1, 1) and Wa.shape == (n, 1) and wy.shape == (n,)
        assert tau in airangles.TAUS_S and ratio in airangles.RATIOS
        est.append(c[0])
        se.append(s[0])
    est, se = np.array(est), np.array(se)
    assert abs(est.mean() - 2.0) < 3 * est.std() / np.sqrt(len(est))
    # the stated standard error within a factor 1.5 of the scatter over 20 records (whose own SD is good to about
    # 16 %): measured 1.23; the same estimate's standard error from the residual's level, as if the error were white,
    # is 3.0 times the scatter and fails this
    assert 1 / 1.5 < np.median(se) / est.std() < 1.5


def test_gls_is_off_on_every_path_and_each_switch_reaches_it(monkeypatch):
    """On the project's sample flight: neither the replay's estimator nor the diagnosis's loader runs the GLS fit by
    default; ``estimate_states(gls_beta=True)`` and the diagnosis's own switch ``diagnose.run.BETA_GLS`` do, and the
    loader's ``gls_beta`` argument wins over that switch."""
    from pathlib import Path

    from gcs_sysid.airframe import load_airframe
    from gcs_sysid.diagnose import run as diagnose_run
    from gcs_sysid.estimation import estimate_states
    from gcs_sysid.telemetry import read_log

    data = Path(__file__).resolve().parents[2] / "data"
    log, airframe = data / "flights" / "sim-trainer-sysid.tlog", data / "airframes" / "sim-trainer.toml"
    assert not airangles.BETA_GLS and not diagnose_run.BETA_GLS
    calls = []
    real = airangles._gls_gust_fit
    monkeypatch.setattr(airangles, "_gls_gust_fit", lambda *a, **k: calls.append(1) or real(*a, **k))
    flight, af = read_log(log), load_airframe(airframe)
    assert estimate_states(flight, af).angle_fits["beta"].used and calls == []
    diagnose_run.load_measurements(log, airframe)
    assert calls == []
    on = estimate_states(flight, af, gls_beta=True).angle_fits["beta"]
    assert calls and on.slope_method.startswith("GLS under the gust model")
    n = len(calls)
    monkeypatch.setattr(diagnose_run, "BETA_GLS", True)
    meas = diagnose_run.load_measurements(log, airframe)
    assert len(calls) > n and meas.states.angle_fits["beta"].slope_method.startswith("GLS under the gust model")
    # the loader's own argument wins over the module switch either way (eval_jsbsim's least-squares line asks for the
    # replay's estimator through run_fit(gls_beta=))
    off = diagnose_run.load_measurements(log, airframe, gls_beta=False).states.angle_fits["beta"]
    assert not off.slope_method.startswith("GLS")
    monkeypatch.setattr(diagnose_run, "BETA_GLS", False)
    on = diagnose_run.load_measurements(log, airframe, gls_beta=True).states.angle_fits["beta"]
    assert on.slope_method.startswith("GLS under the gust model")
