"""The air angles' errors that the reconstruction must not hide (estimation/angleerrors.py, airangles.py).

1. The force model's slope under errors in variables: on a synthetic record in which the aircraft heaves
   with the gust (so the kinematic alpha, which misses the gust, is correlated with it), the ordinary
   least-squares CZ_alpha is attenuated and the aided alpha too steep; the elevator-instrumented slope
   (two-stage least squares) must recover the true slope and the true alpha's scale.
2. The flight-mean vertical wind: the 1-sigma of a Gauss-Markov record's mean that ``mean_wind_sigma``
   gives from one record's fluctuation must match the scatter of the means over many records, and the
   aiding must not add an offset of its own to the kinematic alpha's mean.
"""

import numpy as np
import pytest
from scipy.signal import lfilter

from gcs_sysid.estimation.airangles import aided_air_angles, describe
from gcs_sysid.estimation.angleerrors import iv_lstsq, lagged_instruments, mean_wind_sigma

DT = 0.02
MASS, S, B, C = 1000.0, 16.0, 11.0, 1.5
CZ0, CZ_ALPHA, CZ_DE = -0.35, -5.0, -0.4


def _gauss_markov(rng, T, tau, sigma):
    phi = np.exp(-DT / tau)
    return lfilter([np.sqrt(1 - phi * phi)], [1.0, -phi], rng.normal(0.0, sigma, T))


def _heave_record(seed=5, duration=300.0, wd_mean=0.0):
    """Elevator doublets/sines move alpha through a lagged response; a vertical gust g (Gauss-Markov,
    tau 1 s) adds to the true alpha, and the aircraft heaves with it (the inertial alpha loses half of a
    0.25-s low-passed g): alpha_kin = alpha_true - g, correlated with g above 0.3 Hz. Over seeds 5-8 at
    300 s, least squares gives CZ_alpha 11-18 % low, two-stage least squares within 1.4-5.5 % either way
    (its sampling spread; at 600 s, 0.2 %)."""
    rng = np.random.default_rng(seed)
    T = int(duration / DT)
    t = np.arange(T) * DT
    d_e = (np.radians(2.0) * np.sin(2 * np.pi * 0.4 * t) + np.radians(1.0) * np.sin(2 * np.pi * 1.1 * t)
           + np.radians(1.5) * np.sign(np.sin(2 * np.pi * 0.23 * t)))
    a_lag = 1.0 - np.exp(-DT / 0.15)
    a_man = 0.05 + lfilter([a_lag], [1.0, -(1.0 - a_lag)], -0.3 * d_e)           # short-period-like lag
    V = np.full(T, 40.0)
    g = _gauss_markov(rng, T, 1.0, np.radians(0.3)) + wd_mean / V
    h_lag = 1.0 - np.exp(-DT / 0.25)
    heave = lfilter([h_lag], [1.0, -(1.0 - h_lag)], g - g.mean())                # the aircraft follows the gust
    alpha_true = a_man + g - 0.5 * heave
    alpha_kin = alpha_true - g + rng.normal(0, np.radians(0.03), T)              # the kinematics miss g
    qbar = 0.5 * 1.1 * V**2
    f = np.zeros((T, 3))
    f[:, 2] = qbar * S / MASS * (CZ0 + CZ_ALPHA * alpha_true + CZ_DE * d_e) + rng.normal(0, 0.05, T)
    rec = dict(alpha_kin=alpha_kin, beta_kin=np.zeros(T), V=V, qbar=qbar, f_body=f, rates=np.zeros((T, 3)),
               controls={"delta_e": d_e, "delta_a": np.zeros(T), "delta_r": np.zeros(T)})
    return rec, alpha_true


def _run(rec, instrument_slopes=True):
    T = len(rec["V"])
    return aided_air_angles(DT, rec["alpha_kin"], rec["beta_kin"], rec["V"], rec["qbar"], rec["f_body"],
                            rec["rates"], rec["controls"], MASS, S, B, C, np.ones(T, bool),
                            instrument_slopes=instrument_slopes)


def _scale(est, ref):
    """Regression slope of the error on the centred truth (0: right scale; +0.1: 10 % too steep)."""
    e, r = est - ref, ref - ref.mean()
    return float(np.dot(e - e.mean(), r) / np.dot(r, r))


@pytest.fixture(scope="module")
def heave():
    rec, alpha_true = _heave_record()
    return rec, alpha_true, _run(rec)


def test_instrumented_slope_recovers_cz_alpha_where_least_squares_is_attenuated(heave):
    rec, alpha_true, res = heave
    ax = res.axes[0]
    assert ax.used and ax.slope_method == "2SLS", (ax.reason, ax.slope_method)
    assert ax.first_stage_r2 > 0.3
    assert abs(ax.coef[1] / CZ_ALPHA - 1.0) < 0.04, ax.coef
    assert abs(_scale(res.alpha, alpha_true)) < 0.04
    # the same record through ordinary least squares (no instruments: no elevator column) is attenuated,
    # so this test fails if the slope goes back to plain least squares
    from gcs_sysid.estimation.airangles import _highpass
    from gcs_sysid.estimation.nodes import segments
    T = len(alpha_true)
    segs = segments(np.ones(T, bool), 250)
    ak = rec["alpha_kin"]
    A = np.column_stack([ak, (ak - ak.mean()) ** 2, rec["controls"]["delta_e"]])
    y = rec["f_body"][:, 2] * MASS / (rec["qbar"] * S)
    Ah, yh = _highpass(DT, A, segs), _highpass(DT, y[:, None], segs)[:, 0]
    c_ols, *_ = np.linalg.lstsq(Ah, yh, rcond=None)
    assert c_ols[0] / CZ_ALPHA < 0.9, c_ols             # the bias the instruments remove
    c_iv, *_ = iv_lstsq(Ah, yh, [0], _highpass(DT, lagged_instruments(DT, rec["controls"]["delta_e"]), segs))
    assert abs(c_iv[0] / CZ_ALPHA - 1.0) < 0.04
    assert "slopes by 2SLS" in describe(res)[0]
    ols = _run(rec, instrument_slopes=False).axes[0]           # the switch off: least squares, attenuated
    assert ols.slope_method == "OLS" and ols.coef[1] / CZ_ALPHA < 0.95, ols.coef


def test_weak_instruments_fall_back_to_least_squares():
    rng = np.random.default_rng(0)
    n = 4000
    x = rng.normal(size=n)
    Z = rng.normal(size=(n, 3))                      # unrelated to x
    y = 2.0 * x + rng.normal(0, 0.1, n)
    _, _, _, _, r2 = iv_lstsq(x[:, None], y, [0], Z)
    assert r2 < 0.01
    lagged = lagged_instruments(0.1, np.arange(5.0), (0.0, 0.2))
    assert lagged.shape == (5, 2) and list(lagged[:, 1]) == [0.0, 0.0, 0.0, 1.0, 2.0]


def test_mean_wind_sigma_matches_the_scatter_of_record_means():
    """Many 90-s Gauss-Markov records (tau = L_w / V): the sigma from each record's own fluctuation
    against the actual scatter of their means (Papoulis 1991 sec. 9-5)."""
    rng = np.random.default_rng(11)
    V, L, dur, sw = 40.0, 533.4, 90.0, 0.3
    n = int(dur / DT)
    recs = np.stack([_gauss_markov(rng, n, L / V, sw) for _ in range(300)])
    phi = np.exp(-DT / (L / V))
    recs = recs + np.outer(rng.normal(0, sw, 300), phi ** np.arange(n))   # a stationary initial value
    scatter = float(np.std(recs.mean(axis=1))) / V
    est = np.median([mean_wind_sigma(r - r.mean(), np.full(n, V), dur, L) for r in recs])
    assert 0.8 < est / scatter < 1.25, (est, scatter)
    assert np.isnan(mean_wind_sigma(np.zeros(3), np.full(3, V), dur))


def test_aiding_adds_no_offset_and_reports_the_mean_wind_sigma():
    """A kinematic alpha whose only constant error is a known mean vertical wind: the aided alpha keeps
    that offset (it is out of reach), adds none of its own, and its sigma covers it."""
    wd = 0.3                                          # m/s: 0.43 deg at 40 m/s
    rec, alpha_true = _heave_record(seed=8, wd_mean=wd)
    res = _run(rec)
    ax = res.axes[0]
    err = res.alpha - alpha_true
    kin_err = rec["alpha_kin"] - alpha_true
    assert abs(np.degrees(kin_err.mean()) + np.degrees(wd / 40.0)) < 0.2      # the record has the offset
    assert abs(np.degrees(err.mean() - kin_err.mean())) < 0.02       # the aiding adds none of its own
    assert np.isfinite(ax.bias_sigma) and ax.bias_sigma > 0
    assert np.all(res.alpha_sigma >= ax.bias_sigma - 1e-12)
    assert any("mean vertical wind" in n for n in describe(res))


def test_effective_n_counts_independent_samples():
    """White series keep N; two series smoothed over 25 samples keep about N / (1 + 2 sum rho^2) (Bartlett 1946)."""
    from gcs_sysid.estimation.angleerrors import effective_n

    rng = np.random.default_rng(3)
    n = 4000
    assert effective_n(rng.standard_normal(n), rng.standard_normal(n), 100) > 0.9 * n
    sm = lambda x: np.convolve(x, np.ones(25) / 5.0, "same")  # noqa: E731
    ne = effective_n(sm(rng.standard_normal(n)), sm(rng.standard_normal(n)), 100)
    # the boxcar's autocorrelation is the triangle 1 - k/25: 1 + 2 sum (1 - k/25)^2 = 17.3
    assert 0.6 * n / 17.3 < ne < 1.6 * n / 17.3


def test_first_stage_f_on_the_effective_sample_tells_a_weak_instrument_from_a_strong_one():
    """The iid F of a weak instrument on serially correlated data looks strong (N counts every sample); on the
    effective sample it is under Staiger and Stock's 10, and a strong instrument stays well above."""
    from gcs_sysid.estimation.angleerrors import first_stage_f

    rng = np.random.default_rng(4)
    n = 4000
    sm = lambda x: np.convolve(x, np.ones(25) / 5.0, "same")  # noqa: E731
    z, noise, other = sm(rng.standard_normal(n)), sm(rng.standard_normal(n)), rng.standard_normal(n)
    for scale, strong in ((0.05, False), (1.5, True)):
        A = np.c_[scale * z + noise, other]
        f, r2, n_eff = first_stage_f(A, [0], z[:, None], 100)
        f_iid = (r2 / 1) / ((1 - r2) / (n - 2))
        assert n_eff < n / 8
        assert (f > 10) == strong
        assert f_iid > 10      # what the iid count would have said


def test_fuller_k_class_is_less_biased_than_2sls_with_many_weak_instruments():
    """Twelve instruments, two of them weakly relevant (first-stage R^2 about 0.01): 2SLS leans to least squares'
    bias, Fuller's k-class (alpha 1) much less (Fuller 1977; Hahn, Hausman and Kuersteiner 2004)."""
    b2, bf, bo = [], [], []
    for seed in range(12):
        rng = np.random.default_rng(seed)
        n = 3000
        z, u, g = rng.standard_normal((n, 12)), rng.standard_normal(n), rng.standard_normal(n)
        x = z @ np.r_[0.1, 0.05, np.zeros(10)] + g + 0.5 * u
        A = np.c_[x, rng.standard_normal(n)]
        y = 2.0 * x + u
        b2.append(iv_lstsq(A, y, [0], z)[0][0])
        bf.append(iv_lstsq(A, y, [0], z, fuller_n=n)[0][0])
        bo.append(np.linalg.lstsq(A, y, rcond=None)[0][0])
    bias = lambda b: abs(np.median(b) - 2.0)  # noqa: E731
    assert bias(bo) > 0.3
    assert bias(bf) < 0.5 * bias(b2)
    # with a strong instrument both are 2SLS's (k -> 1)
    rng = np.random.default_rng(99)
    z, u = rng.standard_normal((3000, 1)), rng.standard_normal(3000)
    x = 2.0 * z[:, 0] + 0.5 * u + rng.standard_normal(3000)
    A = np.c_[x]
    y = 2.0 * x + u
    assert abs(iv_lstsq(A, y, [0], z)[0][0] - iv_lstsq(A, y, [0], z, fuller_n=3000)[0][0]) < 0.01
