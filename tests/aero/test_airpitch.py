"""The air-relative pitch rate (gcs_sysid.aero.airpitch): the pitch gust column's share in Cm is fitted with either
sign, moves q_hat to the air's rate only where the fit shows it, and a least-squares fit on the moved table reads the
air-rate slopes that a fit at the gyro's rate does not."""

import numpy as np
import pytest

from gcs_sysid.aero.airpitch import MIN_T, air_pitch_fit, air_pitch_table
from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS, CoefficientTable

CM_ALPHA, CM_Q, CM_DE = -0.8, -14.0, -1.1
IQ, ICM = REGRESSORS.index("q_hat"), COEFFICIENTS.index("Cm")


def _record(sign, gust=1.0, T=6000, dt=0.02, seed=5):
    """A longitudinal record: Cm reads the air-relative ``q_hat``; the gyro's is that plus ``sign`` times the pitch
    gust hat ``g`` (``sign`` +1: Etkin's ``q_g``, -1: JSBSim's turbulence); ``g`` as estimated carries 30 % noise.
    In a pitch manoeuvre ``q`` leads alpha, so the alpha slope takes a share of the gust's moment at the gyro's rate."""
    rng = np.random.default_rng(seed)

    def ar(a, s, n=T):
        x = np.zeros(n)
        for k in range(1, n):
            x[k] = a * x[k - 1] + s * rng.standard_normal()
        return x

    de = ar(0.97, 0.004)
    q_air = ar(0.9, 0.0003) - 0.02 * np.gradient(de) / dt * 0.02
    alpha = 0.05 + np.cumsum(q_air) * 0.4 + ar(0.99, 0.0005)
    g = gust * ar(0.8, 0.00025)
    X = np.zeros((T, len(REGRESSORS)))
    X[:, REGRESSORS.index("alpha")] = alpha
    X[:, IQ] = q_air + sign * g
    X[:, REGRESSORS.index("delta_e")] = de
    X[:, REGRESSORS.index("beta")] = ar(0.98, 0.002)
    X[:, REGRESSORS.index("V")] = 30.0 + ar(0.999, 0.02)
    Y = np.zeros((T, len(COEFFICIENTS)))
    Y[:, ICM] = 0.02 + CM_ALPHA * alpha + CM_Q * q_air + CM_DE * de + 2e-4 * rng.standard_normal(T)
    Y[:, COEFFICIENTS.index("CZ")] = -5.0 * alpha
    g_est = g + 0.3 * np.std(g) * rng.standard_normal(T)
    table = CoefficientTable(t=np.arange(T) * dt, X=X, Y=Y, valid=np.ones(T, bool),
                             qbar=np.full(T, 550.0), notes=["as computed"])
    return table, g_est, q_air


def _ls(table, rows):
    cols = [REGRESSORS.index(k) for k in ("alpha", "q_hat", "delta_e", "beta", "V")]
    A = np.column_stack([np.ones(int(rows.sum())), table.X[rows][:, cols]])
    return np.linalg.lstsq(A, table.Y[rows, ICM], rcond=None)[0][1:4]


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_the_share_is_fitted_with_its_sign_and_the_moved_table_reads_the_air_rate_slopes(sign):
    table, g, q_air = _record(sign)
    train = np.arange(len(g)) < 0.8 * len(g)
    fit = air_pitch_fit(table, g, train)
    assert fit["applied"] and abs(fit["t"]) >= MIN_T, fit
    # kappa is the gust estimate's regression share: the sign of the world, below 1 with a noisy estimate
    assert np.sign(fit["kappa"]) == sign and 0.6 < abs(fit["kappa"]) < 1.05, fit
    moved = air_pitch_table(table, g, fit)
    raw, air = _ls(table, train), _ls(moved, train)
    assert abs(raw[1] - CM_Q) > 0.15 * abs(CM_Q)                       # the gyro's rate: Cm_q attenuated
    assert abs(air[1] - CM_Q) < 0.1 * abs(CM_Q), (raw, air)
    assert abs(air[0] - CM_ALPHA) < abs(raw[0] - CM_ALPHA), (raw, air)
    # every row moved (held-out ones too), only q_hat, towards the air's rate; the input table as it was
    assert np.std(moved.X[:, IQ] - q_air) < 0.6 * np.std(table.X[:, IQ] - q_air)
    others = [j for j in range(len(REGRESSORS)) if j != IQ]
    assert np.array_equal(moved.X[:, others], table.X[:, others]) and np.array_equal(moved.Y, table.Y)
    assert table.notes == ["as computed"] and "air-relative estimate" in moved.notes[-1]
    assert ("opposite" in moved.notes[-1]) == (sign < 0) and "Etkin's" in moved.notes[-1]


def test_no_gust_moment_leaves_the_gyros_rate():
    table, g, _ = _record(1.0, gust=0.0)       # the gyro reads the air's rate: no gust moment in Cm
    g_unrelated = np.random.default_rng(9).standard_normal(len(g)) * 3e-4
    fit = air_pitch_fit(table, g_unrelated, np.ones(len(g), bool))
    assert not fit["applied"] and "not applied" in fit["note"] and f"< {MIN_T:g}" in fit["note"]
    kept = air_pitch_table(table, g_unrelated, fit)
    assert np.array_equal(kept.X, table.X) and kept.notes[-1] == fit["note"]


def test_too_few_rows_and_bad_shapes():
    table, g, _ = _record(1.0, T=300)
    train = np.zeros(len(g), bool)
    train[:100] = True
    fit = air_pitch_fit(table, g, train)
    assert not fit["applied"] and np.isnan(fit["kappa"]) and "100 rows" in fit["note"]
    with pytest.raises(ValueError, match="air_pitch_fit"):
        air_pitch_fit(table, g[:-1], train)


def test_the_pool_is_the_fit_with_a_level_per_window():
    from dataclasses import replace

    from gcs_sysid.aero.airpitch import AirPitchPool

    table, g, _ = _record(-1.0)
    T = len(g)
    one = np.zeros(T, bool)
    one[:1500] = True
    pool = AirPitchPool()
    assert pool.add(table, g, one) == 1500
    a, b = pool.fit(), air_pitch_fit(table, g, one)
    for k in ("kappa", "t", "c_g", "Cm_q"):             # one window pooled: the window's own fit, to rounding
        assert a[k] == pytest.approx(b[k], rel=1e-6), k
    assert a["applied"] == b["applied"] and a["windows"] == 1 and "1 windows pooled" in a["note"]
    # t is the gust coefficient's t statistic: c_g / sqrt(s^2 [(A^T A)^-1]_gg), A = [1, varying regressors, g]
    X = table.X[one]
    A = np.column_stack([np.ones(1500), X[:, np.std(X, 0) > 0], g[one]])
    coef = np.linalg.lstsq(A, table.Y[one, ICM], rcond=None)[0]
    r = table.Y[one, ICM] - A @ coef
    se = np.sqrt(r @ r / (1500 - A.shape[1]) * np.linalg.inv(A.T @ A)[-1, -1])
    assert b["t"] == pytest.approx(coef[-1] / se, rel=1e-6)
    # four 30-s windows, each with its own Cm level (a window's trim and alpha level): the pool reads the share the
    # whole record has; one fit over the four with a single level takes the jumps as noise
    Y = table.Y.copy()
    wins = [np.arange(T) // 1500 == k for k in range(4)]
    for k, w in enumerate(wins):
        Y[w, ICM] += 0.01 * (-1) ** k
    jumpy = replace(table, Y=Y)
    pool = AirPitchPool()
    for w in wins:
        pool.add(jumpy, g, w)
    p, whole = pool.fit(), air_pitch_fit(table, g, np.ones(T, bool))
    assert p["applied"] and p["windows"] == 4 and p["rows"] == T
    assert p["kappa"] == pytest.approx(whole["kappa"], abs=0.02) and abs(p["t"]) > abs(a["t"])
    single = air_pitch_fit(jumpy, g, np.ones(T, bool))
    assert abs(single["t"]) < 0.5 * abs(p["t"])
    # a window too short for its own level adds nothing; wrong shapes are refused
    short = np.zeros(T, bool)
    short[:10] = True
    assert pool.add(table, g, short) == 0 and pool.rows == T
    with pytest.raises(ValueError, match="AirPitchPool.add"):
        pool.add(table, g[:-1], short)
    assert not AirPitchPool().fit()["applied"] and "0 rows pooled" in AirPitchPool().fit()["note"]


def test_the_pool_says_which_column_does_not_vary():
    from gcs_sysid.aero.airpitch import AirPitchPool

    table, g, _ = _record(1.0, T=1000)
    pool = AirPitchPool()
    pool.add(table, np.zeros(len(g)), np.ones(len(g), bool))     # a window whose wind carries no gust
    fit = pool.fit()
    assert not fit["applied"] and "the pitch gust rate does not vary over the 1000 pooled rows" in fit["note"]
