"""Air angles aided by the specific force (estimation/airangles.py) on a synthetic record with known
gusts, the gust smoother against filterpy's Kalman filter + RTS smoother, the fallbacks and the kept
kinematic angle's stated error."""

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter, rts_smoother

from gcs_sysid.estimation.airangles import (MOMENT_WINDOW_TAUS, _gust_smoother, aided_air_angles, describe,
                                            kinematic_sigma)
from gcs_sysid.estimation.kalman import steady_state

DT = 0.02
MASS, S, B, C = 1000.0, 16.0, 11.0, 1.5
CY_BETA, CY_DR, CZ_ALPHA, CZ_DE, CZ0 = -0.35, 0.12, -5.0, -0.4, -0.35


def _gauss_markov(rng, T, tau, sigma):
    phi = np.exp(-DT / tau)
    w = rng.normal(0.0, sigma * np.sqrt(1 - phi * phi), T)
    g = np.zeros(T)
    for k in range(1, T):
        g[k] = phi * g[k - 1] + w[k]
    return g


def _record(seed=3, duration=120.0, side_force=True):
    """Known air angles = kinematic ones + slow gusts (which the kinematics miss); the specific force
    from a linear CY(beta, delta_r), CZ(alpha, delta_e) with 0.05 m/s^2 accelerometer noise."""
    rng = np.random.default_rng(seed)
    T = int(duration / DT)
    t = np.arange(T) * DT
    d_r = np.radians(3.0) * np.sign(np.sin(2 * np.pi * 0.3 * t)) * (np.sin(2 * np.pi * 0.05 * t) > 0)
    d_e = np.radians(2.0) * np.sin(2 * np.pi * 0.4 * t) + np.radians(1.0) * np.sin(2 * np.pi * 1.1 * t)
    beta_true = 0.5 * d_r + np.radians(0.3) * np.sin(2 * np.pi * 0.7 * t) + _gauss_markov(rng, T, 6.0, np.radians(0.5))
    a_man = 0.05 - 0.3 * d_e + np.radians(0.4) * np.sin(2 * np.pi * 0.9 * t)     # maneuver part
    alpha_true = a_man + _gauss_markov(rng, T, 6.0, np.radians(0.4))
    gust_b = beta_true - 0.5 * d_r - np.radians(0.3) * np.sin(2 * np.pi * 0.7 * t)
    gust_a = alpha_true - a_man
    beta_kin = beta_true - gust_b + rng.normal(0, np.radians(0.03), T)
    alpha_kin = alpha_true - gust_a + rng.normal(0, np.radians(0.03), T)
    V = np.full(T, 40.0)
    qbar = 0.5 * 1.1 * V**2
    k = qbar * S / MASS
    f = np.zeros((T, 3))
    f[:, 1] = k * (CY_BETA * beta_true + CY_DR * d_r) * side_force + rng.normal(0, 0.05, T)
    f[:, 2] = k * (CZ0 + CZ_ALPHA * alpha_true + CZ_DE * d_e) + rng.normal(0, 0.05, T)
    rates = np.zeros((T, 3))
    controls = {"delta_e": d_e, "delta_a": np.zeros(T), "delta_r": d_r}
    return dict(alpha_kin=alpha_kin, beta_kin=beta_kin, V=V, qbar=qbar, f_body=f, rates=rates,
                controls=controls), alpha_true, beta_true


def _run(rec, use=None, profile_beta=None):
    T = len(rec["V"])
    return aided_air_angles(DT, rec["alpha_kin"], rec["beta_kin"], rec["V"], rec["qbar"], rec["f_body"],
                            rec["rates"], rec["controls"], MASS, S, B, C, np.ones(T, bool) if use is None else use,
                            profile_beta=profile_beta)


def _rms_deg(x):
    return float(np.degrees(np.sqrt(np.mean(x**2))))


def test_gusts_are_recovered_from_the_specific_force():
    # least squares' side-force slope (the diagnosis's estimator, gcs_sysid.diagnose.run.BETA_PROFILE): here the
    # kinematic sideslip's error is independent of it (no aircraft answers this record's gust), the textbook
    # attenuation the later passes on the aided angle undo; the replay's held likelihood slope is the next test
    rec, alpha, beta = _record()
    res = _run(rec, profile_beta=False)
    fa, fb = res.axes
    assert fa.used and fb.used, describe(res)
    kin_a, kin_b = _rms_deg(rec["alpha_kin"] - alpha), _rms_deg(rec["beta_kin"] - beta)
    aid_a, aid_b = _rms_deg(res.alpha - alpha), _rms_deg(res.beta - beta)
    assert kin_a > 0.25 and kin_b > 0.3                 # the kinematic angles miss the gusts
    # measured 0.15 x and 0.33 x (seed 3): the gusts' mean over the record stays with the kinematics
    assert aid_a < 0.3 * kin_a and aid_b < 0.45 * kin_b, (kin_a, aid_a, kin_b, aid_b)
    # the model identified on the record: its slopes within 10 %
    assert abs(fb.coef[1] / CY_BETA - 1) < 0.1 and abs(fa.coef[1] / CZ_ALPHA - 1) < 0.1, (fa.coef, fb.coef)
    assert 2.0 <= fb.tau_s <= 16.0                     # the gusts' 6 s correlation time, on the grid
    # the 1-sigma is of the right size where the smoother runs (within a factor 2 of the error)
    assert 0.5 < np.degrees(np.nanmean(res.beta_sigma)) / aid_b < 2.0


def test_the_held_likelihood_slope_keeps_an_attenuated_first_pass(monkeypatch):
    """A known limit of the opt-in profile (``BETA_PROFILE`` with ``BETA_PROFILE_HOLD``, docs/estimation.md): where
    the kinematic sideslip's error is independent of it, least squares' first pass is attenuated (here 0.90 of
    ``CY_BETA``), the likelihood, searched only flatter, keeps about it, and the hold stops the later passes from
    undoing the attenuation (they reach 1.06 without it). The aided sideslip is still most of the way there."""
    from gcs_sysid.estimation import airangles

    monkeypatch.setattr(airangles, "BETA_PROFILE_HOLD", True)
    rec, alpha, beta = _record()
    res = _run(rec, profile_beta=True)
    fb = res.axes[1]
    assert "held in the later passes" in fb.slope_method
    assert 0.8 < fb.coef[1] / CY_BETA < 0.95, fb.coef
    free = _run(rec, profile_beta=False).axes[1]
    assert abs(free.coef[1] / CY_BETA - 1) < abs(fb.coef[1] / CY_BETA - 1)
    assert _rms_deg(res.beta - beta) < 0.45 * _rms_deg(rec["beta_kin"] - beta)


def test_falls_back_to_the_kinematic_angles_with_a_reason():
    rec, _, _ = _record(duration=15.0)                 # too short for the model fit
    res = _run(rec)
    assert not any(ax.used for ax in res.axes)
    np.testing.assert_array_equal(res.alpha, rec["alpha_kin"])
    np.testing.assert_array_equal(res.beta, rec["beta_kin"])
    assert all("kinematic only" in n and "s of usable flight" in n for n in describe(res))

    rec, _, beta = _record(side_force=False)           # no side force: CY_beta not identified
    res = _run(rec)
    fa, fb = res.axes
    assert fa.used and not fb.used
    assert "CY_beta not identified" in fb.reason
    np.testing.assert_array_equal(res.beta, rec["beta_kin"])


def test_gust_smoother_equals_filterpy_kalman_and_rts():
    """The steady-state smoother of the chosen Gauss-Markov model gives filterpy's KalmanFilter +
    rts_smoother means when filterpy starts from the same (steady-state) prior."""
    rng = np.random.default_rng(1)
    z = _gauss_markov(rng, 3000, 2.0, 1.0) + rng.normal(0, 0.5, 3000)
    g, gs, tau, s_g, s_v = _gust_smoother(DT, z, [slice(0, 3000)], (0.5, 2.0, 8.0), (0.3, 3.0, 30.0))
    phi = np.exp(-DT / tau)
    s2 = s_v**2
    ratio = (s_g / s_v) ** 2
    ss = steady_state(np.array([[phi]]), np.array([[ratio * (1 - phi**2)]]), np.eye(1), np.eye(1))
    kf = KalmanFilter(dim_x=1, dim_z=1)
    kf.F, kf.H = np.array([[phi]]), np.eye(1)
    kf.Q, kf.R = np.array([[ratio * (1 - phi**2) * s2]]), np.array([[s2]])
    kf.x, kf.P = np.zeros((1, 1)), ss.Pf * s2       # the steady state's prior: filtered covariance at k = -1
    mu, cov, _, _ = kf.batch_filter(z[:, None])
    xs, Ps, _, _ = rts_smoother(mu, cov, [kf.F] * len(z), [kf.Q] * len(z))
    np.testing.assert_allclose(g, xs[:, 0, 0], atol=1e-6 * np.std(z))
    assert abs(gs[1500] ** 2 / Ps[1500, 0, 0] - 1) < 1e-6
    assert tau == 2.0


def test_slow_logs_fall_back_and_the_sideslip_mean_comes_from_cy0():
    rec, alpha, beta = _record()
    slow = aided_air_angles(0.1, rec["alpha_kin"], rec["beta_kin"], rec["V"], rec["qbar"], rec["f_body"],
                            rec["rates"], rec["controls"], MASS, S, B, C, np.ones(len(alpha), bool))
    assert not any(ax.used for ax in slow.axes) and "10.0 Hz" in slow.axes[1].reason
    # a constant 1 deg error of the kinematic sideslip (a wind error) is not a gust; a symmetric
    # airframe's CY0 ~ 0 measures it
    rec["beta_kin"] = rec["beta_kin"] + np.radians(1.0)
    res = _run(rec, profile_beta=False)      # least squares' slope (the replay's held one: the test above)
    assert abs(np.degrees(np.mean(res.beta - beta))) < 0.3
    assert abs(np.degrees(res.axes[1].mean_shift) + 1.0) < 0.3


def _with_moments(rec, alpha, beta, seed=4):
    """Add angular accelerations whose moment coefficients depend on the true angles (Cm_alpha, Cl_beta,
    Cn_beta), with noise; the rates are zero, so M = I w_dot."""
    rng = np.random.default_rng(seed)
    T = len(alpha)
    inertia = np.diag([1300.0, 1800.0, 2700.0])
    qS = rec["qbar"] * S
    Cl = -0.09 * beta - 0.2 * rec["controls"]["delta_a"] + 0.01 * rec["controls"]["delta_r"]
    Cm = 0.02 - 0.8 * alpha - 1.1 * rec["controls"]["delta_e"]
    Cn = 0.07 * beta - 0.07 * rec["controls"]["delta_r"]
    M = np.stack([Cl * qS * B, Cm * qS * C, Cn * qS * B], axis=1)
    rec["rate_dot"] = M / np.diag(inertia) + rng.normal(0, 0.02, (T, 3))
    rec["inertia"] = inertia
    return rec


def test_moment_cross_check_keeps_good_aiding_and_drops_misled_aiding():
    """The moments (gyro, not accelerometers) judge the aided angle against the kinematic one: kept when
    the force model is right; dropped, with a note, when a normal force that is not aerodynamic (here a
    slow 1.5 m/s^2 disturbance: an unmodelled force, e.g. a propeller or a bad accelerometer) fools it."""
    rec, alpha, beta = _record()
    rec = _with_moments(rec, alpha, beta)
    kw = dict(rate_dot=rec["rate_dot"], inertia=rec["inertia"])
    T = len(alpha)
    good = aided_air_angles(DT, rec["alpha_kin"], rec["beta_kin"], rec["V"], rec["qbar"], rec["f_body"],
                            rec["rates"], rec["controls"], MASS, S, B, C, np.ones(T, bool), **kw)
    assert all(ax.used for ax in good.axes), describe(good)
    for ax in good.axes:
        assert ax.moment_rss[1] < ax.moment_rss[0], ax.moment_rss     # the aided angles explain the moments better
    assert all("moment cross-check" in n for n in describe(good))
    bad_f = rec["f_body"].copy()
    bad_f[:, 2] += _gauss_markov(np.random.default_rng(9), T, 4.0, 1.5)
    bad = aided_air_angles(DT, rec["alpha_kin"], rec["beta_kin"], rec["V"], rec["qbar"], bad_f,
                           rec["rates"], rec["controls"], MASS, S, B, C, np.ones(T, bool), **kw)
    fa, fb = bad.axes
    assert fb.used and not fa.used, describe(bad)
    assert "fits Cm worse than the kinematic one" in fa.reason
    np.testing.assert_array_equal(bad.alpha, rec["alpha_kin"])
    # the kept kinematic alpha states its error (the gust the rejected aiding found, kinematic_sigma): here the
    # misleading force inflates that gust, so the statement is conservative, never blind
    err = rec["alpha_kin"] - alpha
    err = err - err.mean()                               # a flight-common offset cancels at the flight's regressors
    s = bad.alpha_sigma
    assert np.isfinite(s).all()
    assert np.sqrt(np.mean(s**2)) >= 0.8 * np.sqrt(np.mean(err**2))
    assert np.mean(np.abs(err) <= 1.96 * s) >= 0.9


def test_kinematic_sigma_states_the_kinematic_angles_gust_error():
    """``kinematic_sigma``: ``sqrt((g_hat - mean g_hat)^2 + P)`` on the aided rows, NaN elsewhere; with a right
    force model (the gust found is the true one) its RMS is the kinematic alpha's true error RMS within 20 %,
    and with the caller's moving window it covers 90-99 % of that error at 1.96 sigma."""
    rec, alpha, beta = _record()
    T = len(alpha)
    good = aided_air_angles(DT, rec["alpha_kin"], rec["beta_kin"], rec["V"], rec["qbar"], rec["f_body"],
                            rec["rates"], rec["controls"], MASS, S, B, C, np.ones(T, bool))
    assert good.axes[0].used
    m = np.isfinite(good.alpha_sigma)
    m[: T // 10] = False                                 # a stretch not aided: NaN there
    # the smoother's posterior sigma alone (the offset's share left out): alpha_sigma^2 - bias_sigma^2
    P = np.sqrt(np.maximum(good.alpha_sigma**2 - good.axes[0].bias_sigma**2, 0.0))
    s = kinematic_sigma(good.alpha, rec["alpha_kin"], P, m)
    assert np.isnan(s[~m]).all() and np.isfinite(s[m]).all()
    g = (good.alpha - rec["alpha_kin"])[m]
    np.testing.assert_allclose(s[m], np.sqrt((g - g.mean()) ** 2 + P[m] ** 2))
    err = (rec["alpha_kin"] - alpha)[m]
    err = err - err.mean()
    # the local second moment over MOMENT_WINDOW_TAUS gust correlation times (the caller's window): the band
    # covers the error near its nominal 95 % (the row's own g_hat^2 covers ~99 %)
    w = int(round(MOMENT_WINDOW_TAUS * good.axes[0].tau_s / DT))
    s_w = kinematic_sigma(good.alpha, rec["alpha_kin"], P, m, w)
    assert np.isnan(s_w[~m]).all()
    for sig in (s[m], s_w[m]):
        ratio = np.sqrt(np.mean(sig**2) / np.mean(err**2))
        assert 0.8 <= ratio <= 1.2, ratio
    assert 0.9 <= np.mean(np.abs(err) <= 1.96 * s_w[m]) <= 0.99


def test_varying_throttle_keeps_the_sideslip_mean_and_stays_out_of_the_force_model():
    """With a varying throttle the CY0 ~ 0 prior does not hold (propeller side force): the sideslip mean
    stays with the kinematics; and delta_t is no regressor of CY, CZ (the autopilot's throttle follows
    the gusts: a spurious slope)."""
    rec, alpha, beta = _record()
    rec["beta_kin"] = rec["beta_kin"] + np.radians(1.0)
    T = len(alpha)
    rec["controls"]["delta_t"] = 0.5 + 0.1 * np.sin(2 * np.pi * np.arange(T) * DT / 30.0)
    res = _run(rec)
    fa, fb = res.axes
    assert fa.used and fb.used
    assert fb.mean_shift == 0.0 and "sideslip mean kept: the throttle varies" in fb.shift_note
    assert abs(np.degrees(np.mean(res.beta - beta)) - 1.0) < 0.3          # the 1 deg error stays
    assert "delta_t" not in fa.columns and "delta_t" not in fb.columns


def _hp_slope(est, true):
    """Regression slope of ``est`` on ``true`` above 0.2 Hz (the manoeuvre band)."""
    from scipy.signal import butter, sosfiltfilt

    sos = butter(2, 0.2, "highpass", fs=1.0 / DT, output="sos")
    x, y = sosfiltfilt(sos, true - true.mean()), sosfiltfilt(sos, est - est.mean())
    return float(np.polyfit(x[500:-500], y[500:-500], 1)[0])


@pytest.mark.slow
def test_another_flights_force_model_sets_the_alpha_scale():
    """``models``: the alpha axis takes another flight's CZ slopes (its constant fitted here); the aided alpha's
    manoeuvre-band scale is then ``true slope / given slope`` on both flights alike (the differential
    diagnosis's shared scale, docs/estimation.md)."""
    rec_a, _, _ = _record(seed=3)
    rec_b, alpha_b, _ = _record(seed=8)
    fa = _run(rec_a).axes[0]
    own = _run(rec_b).axes[0]
    T = len(rec_b["V"])
    run_b = lambda models: aided_air_angles(DT, rec_b["alpha_kin"], rec_b["beta_kin"], rec_b["V"],  # noqa: E731
                                            rec_b["qbar"], rec_b["f_body"], rec_b["rates"], rec_b["controls"],
                                            MASS, S, B, C, np.ones(T, bool), models=models)
    res = run_b({"alpha": fa})
    fb = res.axes[0]
    assert fb.used and fb.slope_method.startswith("given"), fb.slope_method
    np.testing.assert_array_equal(fb.coef[1:], fa.coef[1:])           # the slopes are flight A's
    assert fb.coef[0] != fa.coef[0]                                     # the constant is this flight's
    assert not np.array_equal(own.coef[1:], fa.coef[1:])
    assert abs(_hp_slope(res.alpha, alpha_b) - 1.0) < 0.03
    # a given CZ_alpha 10 % too flat makes the aided alpha 10 % too steep in the manoeuvre band (1 / 0.9)
    flat = type(fa)(**{**fa.__dict__, "coef": np.r_[fa.coef[0], 0.9 * fa.coef[1], fa.coef[2:]]})
    k = _hp_slope(run_b({"alpha": flat}).alpha, alpha_b)
    assert abs(k - 1.0 / 0.9) < 0.03, k
    # a model with other terms is not used: the slopes are fitted here, and the note says why
    other = type(fa)(**{**fa.__dict__, "columns": fa.columns[:-1] + ("delta_t",)})
    fo = run_b({"alpha": other}).axes[0]
    np.testing.assert_allclose(fo.coef, own.coef)
    assert "not this flight's" in fo.slope_method
    assert "slopes by given: slopes of the given model" in describe(res)[0]


def _riding_record(seed: int, duration: float = 120.0):
    """A 3-kg, 2-m UAV at 18 m/s (the heave mode's corner at 1.5 Hz) in a slow vertical gust (Dryden scale
    533 m, 3 deg): below the corner it rides the gust (the kinematic alpha takes the low-passed gust with the
    opposite sign), the true alpha keeps the rest; the manoeuvre's alpha is a 2-Hz short period's answer to a
    square-wave elevator. Returns the arguments of ``aided_air_angles``, the true alpha and the corner, Hz."""
    from scipy.signal import bilinear, lfilter

    rng = np.random.default_rng(seed)
    T = int(duration / DT)
    t = np.arange(T) * DT
    mass, S_, b_, c_, V0, rho, cla = 3.0, 0.55, 2.0, 0.28, 18.0, 1.2, 4.8
    V = np.full(T, V0)
    qbar = 0.5 * rho * V**2
    w_h = qbar[0] * S_ * cla / (mass * V0)                 # heave rate, rad/s
    phi = np.exp(-DT * V0 / 533.4)
    g = lfilter([np.sqrt(1 - phi**2)], [1, -phi], rng.normal(0, np.radians(3.0), T))
    a = np.exp(-w_h * DT)
    g_lp = lfilter([1 - a], [1, -a], g)                     # the part of the gust the aircraft rides
    d_e = np.radians(2.0) * np.sign(np.sin(2 * np.pi * 0.4 * t)) + np.radians(1.0) * np.sin(2 * np.pi * 1.7 * t)
    bz, az = bilinear([14.0**2], [1, 2 * 0.5 * 14.0, 14.0**2], fs=1 / DT)
    man = lfilter(bz, az, -0.2 * d_e) + np.radians(0.3) * np.sin(2 * np.pi * 0.9 * t)
    alpha_true = 0.05 + man + (g - g_lp)
    alpha_kin = 0.05 + man - g_lp + rng.normal(0, np.radians(0.01), T)
    beta_kin = np.radians(1.0) * np.sin(2 * np.pi * 0.5 * t)
    k = qbar * S_ / mass
    f = np.zeros((T, 3))
    f[:, 1] = k * (-0.3 * beta_kin) + rng.normal(0, 0.05, T)
    f[:, 2] = k * (-0.4 - cla * alpha_true - 0.4 * d_e) + rng.normal(0, 0.05, T)
    ctrl = {"delta_e": d_e, "delta_a": np.zeros(T), "delta_r": np.radians(2.0) * np.sin(2 * np.pi * 0.5 * t)}
    args = (DT, alpha_kin, beta_kin, V, qbar, f, np.zeros((T, 3)), ctrl, mass, S_, b_, c_, np.ones(T, bool))
    return args, alpha_true, w_h / (2 * np.pi)


def test_alpha_slopes_are_fitted_above_the_heave_corner(monkeypatch):
    """Below the heave mode's corner the aircraft rides the gust and the kinematic alpha's error correlates
    with it: the slopes fitted above 0.3 Hz are attenuated, above the corner (from the wing's Helmbold slope)
    much less, and the aided alpha is better."""
    import gcs_sysid.estimation.airangles as aa

    args, alpha, f_h = _riding_record(1)
    monkeypatch.setattr(aa, "SLOPE_FLOOR", False)      # the band alone (the lift-slope floor: the next test)
    monkeypatch.setattr(aa, "HEAVE_EDGE", 1.0)         # opt-in
    res = aided_air_angles(*args)
    fa = res.axes[0]
    assert fa.used, describe(res)
    # the edge is the corner from the geometry (Helmbold 4.71 per rad for A = 7.3 against the record's 4.8)
    assert abs(fa.band_hz / f_h - 4.71 / 4.8) < 0.03, (fa.band_hz, f_h)
    assert any(f"above {fa.band_hz:.2f} Hz" in n for n in describe(res))
    monkeypatch.setattr(aa, "HEAVE_EDGE", None)
    old = aided_air_angles(*args)
    assert old.axes[0].band_hz == aa.HIGHPASS_HZ
    # measured (seeds 1-3): -3.9..-4.0 above the corner, -2.9..-3.1 above 0.3 Hz; alpha error 0.11 vs 0.19-0.24 deg
    assert abs(fa.coef[1] / -4.8 - 1) < 0.25 < abs(old.axes[0].coef[1] / -4.8 - 1), (fa.coef, old.axes[0].coef)
    assert np.std(res.alpha - alpha) < 0.7 * np.std(old.alpha - alpha)


def _with_lateral_gust(args, seed: int):
    """The riding record in isotropic turbulence: the same Dryden scale and 3 deg on the lateral axis (the kinematic
    sideslip misses it, the side force sees it through ``CY_beta`` = -0.3), the witness of the lift-slope floor."""
    from scipy.signal import lfilter

    rng = np.random.default_rng(100 + seed)
    a = list(args)
    T = len(a[1])
    phi = np.exp(-DT * 18.0 / 533.4)
    g = lfilter([np.sqrt(1 - phi**2)], [1, -phi], rng.normal(0, np.radians(3.0), T))
    f = a[5].copy()
    k = a[4] * a[9] / a[8]
    f[:, 1] = k * (-0.3 * (a[2] + g)) + rng.normal(0, 0.05, T)
    a[5] = f
    return tuple(a)


def test_attenuated_alpha_slope_is_held_at_the_wing_lift_slope(monkeypatch):
    """Where errors in variables flatten the fitted ``CZ_alpha`` below the wing's own lift slope (Helmbold, 4.79 per
    rad for the riding record's A = 7.3, against its 4.8), the first pass holds it there: the aided alpha is much
    better than with the attenuated slope, the note says so; a strong gust that leaves the slope unidentified is
    still aided; a slope fitted steeper than the floor is untouched."""
    import gcs_sysid.estimation.airangles as aa

    args, alpha, _ = _riding_record(2)
    args = _with_lateral_gust(args, 2)
    res = aided_air_angles(*args)
    monkeypatch.setattr(aa, "SLOPE_FLOOR", False)
    old = aided_air_angles(*args)
    monkeypatch.undo()
    fa, fo = res.axes[0], old.axes[0]
    assert fa.used and fo.used
    assert "held at the wing's lift slope -4.79" in fa.slope_method and "held" not in fo.slope_method
    assert any("held at the wing's lift slope" in n for n in describe(res))
    # measured (seeds 1-3): floor -4.84..-4.85 (later pass), error SD 0.041-0.049 deg; without -2.9..-3.1, 0.19-0.24
    assert abs(fa.coef[1] / -4.8 - 1) < 0.1 < 0.25 < abs(fo.coef[1] / -4.8 - 1), (fa.coef, fo.coef)
    assert np.std(res.alpha - alpha) < 0.4 * np.std(old.alpha - alpha)
    # a gust 4x stronger: the slope is not identified without the floor (the sgs126's light flights), aided with it
    a2 = list(args)
    a2[1] = args[1] + (args[1] - alpha) * 3.0          # the kinematic alpha's gust error x 4
    strong = aided_air_angles(*a2)
    monkeypatch.setattr(aa, "SLOPE_FLOOR", False)
    strong_old = aided_air_angles(*a2)
    monkeypatch.undo()
    # measured (seeds 1-3): without, CZ_alpha -0.06..-0.10 (not identified), error SD 8-17 deg; with, 0.16-0.22 deg
    assert not strong_old.axes[0].used and "not identified" in strong_old.axes[0].reason
    assert strong.axes[0].used, describe(strong)
    assert np.std(strong.alpha - alpha) < 0.1 * np.std(strong_old.alpha - alpha)
    # no lateral gust (the riding record as it is; beta aided, its gust ~0): no witness of errors in variables, so
    # the attenuated slope and the identification check stand as before the floor
    calm_args, _, _ = _riding_record(2)
    witness = aided_air_angles(*calm_args)
    assert "held" not in witness.axes[0].slope_method
    assert aa.gust_share(DT, calm_args[1], calm_args[12], witness.axes[1], aa.HIGHPASS_HZ) < aa.FLOOR_MIN_GUST_SHARE
    # a slope fitted steeper than the floor (the 1000-kg record: -5.0 against 4.77) is left alone
    rec, _, _ = _record()
    new = _run(rec)
    monkeypatch.setattr(aa, "SLOPE_FLOOR", False)
    np.testing.assert_array_equal(new.alpha, _run(rec).alpha)
    assert "held" not in new.axes[0].slope_method


def test_heavy_aircraft_keep_the_fixed_band(monkeypatch):
    """A corner below HIGHPASS_HZ (the 1000-kg record: 0.27 Hz) leaves the aiding exactly as without the heave edge,
    and the default (``HEAVE_EDGE = None``) is the fixed band."""
    import gcs_sysid.estimation.airangles as aa

    assert abs(aa.lift_slope(8.0) - 4.90) < 0.01 and abs(aa.lift_slope(1e6) / (2 * np.pi) - 1) < 1e-3
    assert np.isnan(aa.lift_slope(0.0))
    assert aa.heave_edge_hz(5.0, 0.1, 1.0) == aa.HIGHPASS_HZ and aa.heave_edge_hz(5.0, 100.0, 1.0) == aa.MAX_EDGE_HZ
    assert aa.HEAVE_EDGE is None and aa.heave_edge_hz(5.0, 100.0) == aa.HIGHPASS_HZ
    rec, _, _ = _record()
    monkeypatch.setattr(aa, "HEAVE_EDGE", 1.0)         # opt-in
    new = _run(rec)
    monkeypatch.setattr(aa, "HEAVE_EDGE", None)        # the default
    old = _run(rec)
    assert new.axes[0].band_hz == aa.HIGHPASS_HZ
    np.testing.assert_array_equal(new.alpha, old.alpha)


def _weathercock_record(seed: int, rudder: float = 1.0):
    """The riding record's 3-kg UAV on its lateral axis in a slow lateral gust (Dryden scale 533 m, 5 deg): below a
    1-Hz directional corner it weathercocks into the gust, so the kinematic sideslip takes the low-passed gust with
    the opposite sign and the yaw rate turns with it (the rates answer the gust); the manoeuvre's sideslip is the
    Dutch roll's (2 Hz, damping 0.3) answer to a square-wave rudder. ``CY = -0.5 beta + 0.1 delta_r``, no rate term.
    ``rudder`` scales the rudder. Returns the arguments of ``aided_air_angles`` and the true sideslip."""
    from scipy.signal import bilinear, lfilter

    rng = np.random.default_rng(seed)
    T = int(120.0 / DT)
    t = np.arange(T) * DT
    mass, S_, b_, c_, V0 = 3.0, 0.55, 2.0, 0.28, 18.0
    V = np.full(T, V0)
    qbar = 0.5 * 1.2 * V**2
    phi = np.exp(-DT * V0 / 533.4)
    g = lfilter([np.sqrt(1 - phi**2)], [1, -phi], rng.normal(0, np.radians(5.0), T))
    a = np.exp(-6.0 * DT)
    g_lp = lfilter([1 - a], [1, -a], g)                    # the part of the gust the aircraft turns into
    d_r = rudder * (np.radians(4.0) * np.sign(np.sin(2 * np.pi * 0.35 * t))
                    + np.radians(2.0) * np.sin(2 * np.pi * 1.3 * t))
    bz, az = bilinear([12.0**2], [1, 2 * 0.3 * 12.0, 12.0**2], fs=1 / DT)
    man = lfilter(bz, az, 0.3 * d_r)
    beta_true = man + (g - g_lp)
    beta_kin = man - g_lp + rng.normal(0, np.radians(0.01), T)
    rates = np.zeros((T, 3))
    rates[:, 2] = -np.gradient(man, DT) + np.gradient(g_lp, DT)
    alpha_kin = 0.05 + np.radians(0.5) * np.sin(2 * np.pi * 0.4 * t)
    d_e = np.radians(1.0) * np.sin(2 * np.pi * 0.4 * t)
    k = qbar * S_ / mass
    f = np.zeros((T, 3))
    f[:, 1] = k * (-0.5 * beta_true + 0.1 * d_r) + rng.normal(0, 0.05, T)
    f[:, 2] = k * (-0.4 - 4.8 * alpha_kin - 0.4 * d_e) + rng.normal(0, 0.05, T)
    ctrl = {"delta_e": d_e, "delta_a": np.zeros(T), "delta_r": d_r}
    return (DT, alpha_kin, beta_kin, V, qbar, f, rates, ctrl, mass, S_, b_, c_, np.ones(T, bool)), beta_true


def test_side_force_slopes_are_instrumented_by_the_rudder():
    """An aircraft that weathercocks into the lateral gust: least squares on the kinematic sideslip flattens
    ``CY_beta`` (measured -0.36 against the record's -0.5) and gives the yaw rate the gust's side force (``CY_r_hat``
    -0.2 against 0); with the rudder and its delays instrumenting the sideslip and the rates (the default,
    ``INSTRUMENTED_BETA``) the slopes are the record's (-0.49..-0.51, ``CY_r_hat`` within 0.03) and the aided sideslip's
    error halves (0.26 -> 0.12 deg). With a rudder too small to instrument it (first-stage R2 0.03-0.05), least
    squares in every pass, said in the note."""
    for seed in (1,):
        args, beta = _weathercock_record(seed)
        iv, ls = aided_air_angles(*args, instrument_beta=True), aided_air_angles(*args, instrument_beta=False)
        fb, fo = iv.axes[1], ls.axes[1]
        assert fb.used and fb.slope_method.startswith("2SLS (beta, r_hat instrumented)"), fb.slope_method
        assert fo.slope_method == "OLS"
        assert abs(fb.coef[1] / -0.5 - 1) < 0.06 < 0.2 < abs(fo.coef[1] / -0.5 - 1), (fb.coef, fo.coef)
        assert abs(fb.coef[2]) < 0.05 < 0.15 < abs(fo.coef[2]), (fb.coef, fo.coef)
        assert np.std(iv.beta - beta) < 0.6 * np.std(ls.beta - beta)
        assert any("2SLS (beta, r_hat instrumented)" in n for n in describe(iv))
    args, _ = _weathercock_record(1, rudder=0.1)
    weak, ls = aided_air_angles(*args, instrument_beta=True), aided_air_angles(*args, instrument_beta=False)
    assert "instruments too weak in pass 1" in weak.axes[1].slope_method, weak.axes[1].slope_method
    assert weak.axes[1].first_stage_r2 < 0.1
    np.testing.assert_array_equal(weak.beta, ls.beta)


def test_a_given_flight_decides_the_side_force_estimator(monkeypatch):
    """A differential diagnosis aids the flight under test with the reference flight's side-force estimator
    (``models={"beta": AxisFit}``): where the reference's instruments were too weak (least squares; here a first-stage
    threshold above the record's R2), the test flight uses least squares too, although its own would pass (its first
    stage is the reference's: the same regressors and controls, only the side force is scaled; the JSBSim
    t6: reference first-stage R2 0.08, its ``CY:scale`` flights 0.10-0.14, and the two estimators' different errors in
    variables read as ``CY:beta``); where the reference used 2SLS, the test flight does too, with no fallback of its
    own. The slopes stay the flight's own: a side force scaled by 1.6 gives a 1.6 times steeper ``CY_beta``."""
    import gcs_sysid.estimation.airangles as aa

    args, _ = _weathercock_record(1)
    scaled = list(args)
    scaled[5] = args[5] * np.array([1.0, 1.6, 1.0])          # the side force scaled by 1.6
    ref_iv = aided_air_angles(*args, instrument_beta=True).axes[1]
    with monkeypatch.context() as mp:
        mp.setattr(aa, "BETA_MIN_FIRST_STAGE_R2", 0.99)      # a reference whose instruments are too weak
        ref_ls = aided_air_angles(*args, instrument_beta=True).axes[1]
        forced = aided_air_angles(*scaled, instrument_beta=True, models={"beta": ref_iv}).axes[1]
    assert ref_ls.used and ref_ls.slope_method.startswith("OLS") and ref_iv.slope_method.startswith("2SLS")
    follow = aided_air_angles(*scaled, instrument_beta=True, models={"beta": ref_ls})
    ls = aided_air_angles(*scaled, instrument_beta=False)
    fb = follow.axes[1]
    assert fb.slope_method.startswith("OLS") and "estimator of the given model" in fb.slope_method, fb.slope_method
    np.testing.assert_array_equal(follow.beta, ls.beta)
    assert abs(fb.coef[1] / ref_ls.coef[1] - 1.6) < 0.05, (fb.coef, ref_ls.coef)
    assert forced.slope_method.startswith("2SLS") and "estimator of the given model" in forced.slope_method
    assert abs(forced.coef[1] / ref_iv.coef[1] - 1.6) < 0.05, (forced.coef, ref_iv.coef)
    # without INSTRUMENTED_BETA a given sideslip fit changes nothing (least squares on both flights)
    np.testing.assert_array_equal(aided_air_angles(*scaled, instrument_beta=False, models={"beta": ref_iv}).beta,
                                  ls.beta)


def test_weak_instrument_tests_of_the_side_force_slopes(monkeypatch):
    """``BETA_WEAK_TEST``: ``"f"`` keeps 2SLS where the rudder is strong (its first-stage F on the effective sample
    passes 10, said in the note) and falls back to least squares everywhere with a small rudder (identical sideslip);
    ``"fuller"`` fits the slopes by Fuller's k-class without a fallback, near the record's ``CY_beta`` -0.5 on the
    strong record."""
    import gcs_sysid.estimation.airangles as aa

    args, _ = _weathercock_record(1)
    weak_args, _ = _weathercock_record(1, rudder=0.1)
    with monkeypatch.context() as mp:
        mp.setattr(aa, "BETA_WEAK_TEST", "f")
        strong = aided_air_angles(*args, instrument_beta=True).axes[1]
        weak = aided_air_angles(*weak_args, instrument_beta=True)
        mp.setattr(aa, "BETA_WEAK_TEST", "fuller")
        fuller = aided_air_angles(*args, instrument_beta=True).axes[1]
    assert strong.slope_method.startswith("2SLS") and "first-stage F" in strong.slope_method, strong.slope_method
    assert "instruments too weak in pass 1 (first-stage F" in weak.axes[1].slope_method, weak.axes[1].slope_method
    np.testing.assert_array_equal(weak.beta, aided_air_angles(*weak_args, instrument_beta=False).beta)
    assert "Fuller's k-class" in fuller.slope_method, fuller.slope_method
    assert abs(fuller.coef[1] / -0.5 - 1) < 0.1, fuller.coef


def test_kinematic_mean_keeps_the_aided_alpha_mean_at_the_kinematic_one(monkeypatch):
    """Opt-in ``KINEMATIC_MEAN`` (eighteenth session, i8-alpha): with a curved CZ and a large slow gust error in the
    kinematic alpha the aiding's linearisation moves alpha's flight mean (measured -0.20 deg here, 0.3-0.9 deg on
    JSBSim's slow aircraft); with the flag the mean is the kinematic one and the rest of the error is unchanged."""
    import gcs_sysid.estimation.airangles as aa

    rng = np.random.default_rng(4)
    rec, alpha, _ = _record(seed=4)
    n = len(alpha)
    rec["alpha_kin"] = rec["alpha_kin"] - _gauss_markov(rng, n, 20.0, np.radians(4.0)) - np.radians(1.0)
    rec["f_body"][:, 2] += rec["qbar"] * S / MASS * 8.0 * (alpha - alpha.mean()) ** 2
    base = _run(rec)
    monkeypatch.setattr(aa, "KINEMATIC_MEAN", True)
    kept = _run(rec)
    assert base.axes[0].used and kept.axes[0].used
    d_base = np.degrees(np.mean(base.alpha - rec["alpha_kin"]))
    d_kept = np.degrees(np.mean(kept.alpha - rec["alpha_kin"]))
    assert abs(d_base) > 0.1, d_base                    # the default moves the mean (measured -0.20 deg)
    assert abs(d_kept) < 1e-6, d_kept
    sd_base, sd_kept = np.std(base.alpha - alpha), np.std(kept.alpha - alpha)
    assert abs(sd_kept / sd_base - 1.0) < 0.01, (sd_base, sd_kept)
    assert np.allclose(kept.beta, base.beta)            # beta is not touched


def test_floor_drops_curvature_leaves_the_curvature_out_of_the_floored_pass(monkeypatch):
    """Opt-in ``FLOOR_DROPS_CURVATURE`` (eighteenth session, i8-alpha): where the lift-slope floor holds, the first pass
    leaves the curvature out too and says so; the later pass fits it on the aided angle, and the aided alpha stays as
    good as with the default on the floored riding record (error SD within 20 %)."""
    import gcs_sysid.estimation.airangles as aa

    args, alpha, _ = _riding_record(2)
    args = _with_lateral_gust(args, 2)
    base = aided_air_angles(*args)
    monkeypatch.setattr(aa, "FLOOR_DROPS_CURVATURE", True)
    new = aided_air_angles(*args)
    fb, fn = base.axes[0], new.axes[0]
    assert fb.used and fn.used
    assert "(alpha - alpha0)^2" in fn.slope_method and "(alpha - alpha0)^2" not in fb.slope_method
    assert np.std(new.alpha - alpha) < 1.2 * np.std(base.alpha - alpha)


def test_beta_band_edge_is_the_side_force_slopes_band():
    # nineteenth session, i8-betaband: beta_band_hz sets the side-force model's band (measurement only); None is
    # the default edge, bit for bit, and an edge below HIGHPASS_HZ is raised to it
    from gcs_sysid.estimation.airangles import HIGHPASS_HZ
    rec, _, _ = _record(seed=7)
    T = len(rec["V"])
    args = (DT, rec["alpha_kin"], rec["beta_kin"], rec["V"], rec["qbar"], rec["f_body"], rec["rates"],
            rec["controls"], MASS, S, B, C, np.ones(T, bool))
    base, same = aided_air_angles(*args), aided_air_angles(*args, beta_band_hz=None)
    assert np.array_equal(base.beta, same.beta) and base.axes[1].band_hz == HIGHPASS_HZ
    hi, lo = aided_air_angles(*args, beta_band_hz=0.5), aided_air_angles(*args, beta_band_hz=0.1)
    assert hi.axes[1].used and hi.axes[1].band_hz == 0.5 and lo.axes[1].band_hz == HIGHPASS_HZ
    assert np.array_equal(hi.alpha, base.alpha) and not np.array_equal(hi.beta, base.beta)


def test_stated_lift_slope_moves_the_floor_and_holds_q_hat():
    """The wing-only floor is a fixed point: where the whole aircraft's lift slope is steeper (the tail's lift: here
    5.6 per rad against the wing's Helmbold 4.79), the floored pass and the later passes end at the wing's, and the
    aided alpha is read ``5.6 / 4.79`` too wide. With the airframe's stated slope (``stated_slopes``, the opt-in
    ``STATED_LIFT_SLOPE``) the floor is that slope, ``q_hat`` is held at ``-CL_q`` in the floored pass instead of
    left out, the note says so, and the scale is right."""
    args, alpha, _ = _riding_record(1, duration=90.0)
    args = list(_with_lateral_gust(args, 1))
    T, k = len(alpha), args[4] * args[9] / args[8]
    q = np.gradient(alpha - alpha.mean(), DT) * 0.5        # a pitch rate with the manoeuvre (rad/s)
    q_hat = q * args[11] / (2 * args[3])
    rates = np.zeros((T, 3))
    rates[:, 1] = q
    f = args[5].copy()
    f[:, 2] += k * (-(5.6 - 4.8) * alpha - 7.0 * q_hat)    # the record's CZ_alpha 4.8 -> 5.6, CZ_q_hat -7
    args[5], args[6] = f, rates

    def scale(r):
        x = alpha - alpha.mean()
        return float(x @ (r.alpha - r.alpha.mean()) / (x @ x))

    wing = aided_air_angles(*args)
    stated = aided_air_angles(*args, stated_slopes=(5.6, 7.0))
    fw, fs = wing.axes[0], stated.axes[0]
    assert fw.used and fs.used, (describe(wing), describe(stated))
    assert "held at the wing's lift slope -4.79" in fw.slope_method
    assert "held at the stated lift slope -5.60" in fs.slope_method
    assert "q_hat held at the stated -7.00" in fs.slope_method
    assert any("stated lift slope" in n for n in describe(stated))
    # measured: wing floor CZ_alpha -4.87, CZ_q_hat -0.85, scale 1.09, error SD 0.064 deg; stated -5.65, -6.13, 1.01,
    # 0.042 deg (seeds 1-3 without the pitch rate: wing 1.03-1.11, stated 0.95-1.02)
    assert abs(fw.coef[1] / -5.6 - 1) > 0.1 and scale(wing) > 1.08, (fw.coef, scale(wing))
    assert abs(fs.coef[1] / -5.6 - 1) < 0.03 and abs(scale(stated) - 1) < 0.04, (fs.coef, scale(stated))
    assert np.std(stated.alpha - alpha) < 0.8 * np.std(wing.alpha - alpha)
    # not stated (None, or CL_alpha None): the wing's floor, bit for bit
    np.testing.assert_array_equal(aided_air_angles(*args, stated_slopes=(None, 7.0)).alpha, wing.alpha)


def test_stated_lift_level_sets_alpha_mean():
    """A constant vertical wind over the flight puts its ``w / V`` on the kinematic alpha, and the aiding keeps it (the
    Gauss-Markov gust reverts to the kinematic mean; the fitted CZ0 takes the rest). A stated lift line (``CL0``,
    ``CL_alpha``, ``CL_delta_e``: the opt-in ``STATED_LIFT_LEVEL``) makes that mean observable: the aided alpha's mean
    moves onto the line, its flight-common 1-sigma falls, the note says so; without the line nothing changes."""
    from gcs_sysid.estimation.airangles import lift_level

    rec, alpha, _ = _record(seed=5)
    rec["alpha_kin"] = rec["alpha_kin"] + np.radians(1.0)      # the flight-mean vertical wind: +1 deg on alpha
    T = len(alpha)
    args = (DT, rec["alpha_kin"], rec["beta_kin"], rec["V"], rec["qbar"], rec["f_body"], rec["rates"],
            rec["controls"], MASS, S, B, C, np.ones(T, bool))
    line = {"CL0": -CZ0, "CL_alpha": -CZ_ALPHA, "CL_q": None, "CL_delta_e": -CZ_DE, "CL0_sigma": 0.005}
    base, lvl = aided_air_angles(*args), aided_air_angles(*args, stated_level=line)
    fb, fl = base.axes[0], lvl.axes[0]
    assert fb.used and fl.used, describe(lvl)
    off_b, off_l = np.degrees(np.mean(base.alpha - alpha)), np.degrees(np.mean(lvl.alpha - alpha))
    # measured (seed 5): +0.90 deg -> +0.08 deg (the line's own 1-sigma 0.06 deg against the mean wind's prior 0.17:
    # weight 0.90), bias_sigma 0.168 -> 0.054 deg
    assert abs(off_b) > 0.8 and abs(off_l) < 0.12, (off_b, off_l)
    assert fl.bias_sigma < 0.5 * fb.bias_sigma and fl.bias_sigma > 0, (fb.bias_sigma, fl.bias_sigma)
    assert abs(np.degrees(fl.mean_shift) + off_b) < 0.15 and "stated lift line" in fl.shift_note
    assert any("stated lift line" in n for n in describe(lvl))
    np.testing.assert_allclose(lvl.alpha - base.alpha, fl.mean_shift)      # a constant: the scale and gusts kept
    assert np.all(lvl.alpha_sigma < base.alpha_sigma)
    # a loosely stated line moves less (weighted by the two 1-sigmas) and states more
    loose = aided_air_angles(*args, stated_level=dict(line, CL0_sigma=0.2)).axes[0]
    assert abs(loose.mean_shift) < 0.8 * abs(fl.mean_shift) and loose.bias_sigma > fl.bias_sigma
    # not stated: bit for bit the aiding's
    np.testing.assert_array_equal(aided_air_angles(*args, stated_level=None).alpha, base.alpha)
    np.testing.assert_array_equal(aided_air_angles(*args, stated_level=dict(line, CL0=None)).alpha, base.alpha)
    z = np.zeros(T)
    with pytest.raises(ValueError, match="CL_alpha > 0"):
        lift_level(DT, alpha, z, z, z, z, np.ones(T, bool), 0.3, 0.0)


def _angles(rng, T, sigma_kin, sigma_ang, C=-1.0):
    """A true angle, two estimates with independent slow errors, and one moment coefficient that depends on the
    true angle with slope ``C`` beside another regressor and a slow unexplained part (gusts)."""
    true = _gauss_markov(rng, T, 3.0, 0.05)
    kin = true + _gauss_markov(rng, T, 1.0, sigma_kin)
    ang = true + _gauss_markov(rng, T, 1.0, sigma_ang)
    X_other = rng.normal(size=(T, 2))
    moments = [C * true + 0.5 * X_other[:, 0] + _gauss_markov(rng, T, 2.0, 0.02) + 0.01 * rng.normal(size=T)]
    return true, kin, ang, X_other, moments


def test_moment_lambda_standard_error_is_the_leave_one_block_out_scatter():
    """lambda and its standard error (from the blocks' normal equations) equal a brute-force delete-a-block
    jackknife of the encompassing regression refitted by lstsq on the rows left."""
    from gcs_sysid.estimation.airangles import moment_lambda
    from gcs_sysid.jackknife import block_labels

    rng = np.random.default_rng(0)
    T = 6000
    _, kin, ang, X_other, moments = _angles(rng, T, 0.02, 0.01)
    moments.append(0.3 * kin + 0.02 * rng.normal(size=T))
    m = np.ones(T, bool)
    m[:100] = False

    def brute(keep):
        Y = np.column_stack([Mo[m] for Mo in moments])
        Y = (Y - Y.mean(axis=0)) / Y.std(axis=0)           # scaled on all rows of m, as the function does
        A = np.column_stack([np.ones(m.sum()), kin[m], (ang - kin)[m], X_other[m]])
        c, *_ = np.linalg.lstsq(A[keep], Y[keep], rcond=None)
        return np.sum(c[2] * c[1]) / np.sum(c[1] ** 2)

    lam, se = moment_lambda(DT, kin, ang, X_other, moments, m)
    idx = np.nonzero(m)[0]
    k, labels = block_labels(idx * DT, 15.0)
    assert lam == pytest.approx(brute(np.ones(idx.size, bool)), rel=1e-9)
    d = np.array([brute(k != b) for b in labels])
    assert se == pytest.approx(np.sqrt((len(d) - 1) / len(d) * np.sum((d - d.mean()) ** 2)), rel=1e-9)


@pytest.mark.parametrize("sigma_kin, sigma_ang, C, closer", [
    (0.03, 0.01, -1.0, "ang"),        # the aided angle three times better: the moments follow it
    (0.01, 0.03, -1.0, "kin"),        # the misled aiding: they follow the kinematic angle, beyond their scatter
    (0.03, 0.01, 0.0, None),          # moments that do not depend on the angle: no evidence either way
])
def test_moment_lambda_reads_which_angle_the_moments_follow(sigma_kin, sigma_ang, C, closer):
    """lambda ~ var(e_kin) / (var(e_kin) + var(e_ang)): above 0.5 where the aided angle is the closer to the
    true one, below 0.5 by more than MOMENT_Z standard errors where the kinematic one is (the cross-check then
    drops the aiding), and wide where the moments carry no information on the angle."""
    from gcs_sysid.estimation.airangles import MOMENT_Z, moment_lambda

    rng = np.random.default_rng(7)
    T = 6000
    true, kin, ang, X_other, moments = _angles(rng, T, sigma_kin, sigma_ang, C)
    lam, se = moment_lambda(DT, kin, ang, X_other, moments, np.ones(T, bool))
    ek, ea = np.var(kin - true), np.var(ang - true)
    if closer == "ang":
        assert lam > 0.5 and lam + MOMENT_Z * se > 0.5, (lam, se)
        assert lam == pytest.approx(ek / (ek + ea), abs=0.15)
    elif closer == "kin":
        assert lam + MOMENT_Z * se < 0.5, (lam, se)
        assert lam == pytest.approx(ek / (ek + ea), abs=0.15)
    else:
        assert lam + MOMENT_Z * se > 0.5, (lam, se)
