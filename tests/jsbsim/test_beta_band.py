"""benchmarks/beta_band.py: the omitted-variable accounting of the side-force model's rate slope and the
directional corner from the yawing moment (synthetic records; nineteenth session, i8-betaband)."""

import numpy as np
import pytest
from scipy.signal import butter, sosfiltfilt

from benchmarks import beta_band as bb

DT = 0.02


def _noise(rng, T, lo, hi):
    """Band-limited unit-ish noise, Hz."""
    x = rng.normal(size=T)
    return sosfiltfilt(butter(2, [lo, hi], "bandpass", fs=1 / DT, output="sos"), x)


def test_gust_regression_predicts_the_least_squares_rate_slope():
    # the kinematic sideslip misses a gust g that the yaw rate follows (g = 1.8 r_hat + rest): least squares of
    # CY on (beta_kin, r_hat) then reads CY_beta x 1.8 as a rate slope that the true model does not have
    rng = np.random.default_rng(5)
    T = 4500
    r_hat = 0.01 * _noise(rng, T, 0.1, 3.0)
    beta_kin = 0.02 * _noise(rng, T, 0.1, 2.0)
    g = 1.8 * r_hat + 0.005 * _noise(rng, T, 0.05, 3.0)
    cy_beta = -1.0
    cy = cy_beta * (beta_kin + g) + 1e-4 * rng.normal(size=T)
    X = np.column_stack([beta_kin, r_hat, np.zeros(T)])
    coef = bb.gust_regression(DT, g, X, 0.3, None)
    assert abs(coef[1] - 1.8) < 0.1 and abs(coef[0]) < 0.1 and np.isnan(coef[2])
    fit = bb.gust_regression(DT, cy, X, 0.3, None)         # the same band regression is the model's least squares
    assert fit[1] < -1.0
    assert abs(fit[1] - cy_beta * coef[1]) < 0.02           # omitted-variable formula
    with pytest.raises(ValueError):
        bb.gust_regression(DT, g[:-1], X, 0.3, None)
    with pytest.raises(ValueError):
        bb.gust_regression(DT, np.r_[np.nan, g[1:]], X, 0.3, None)


def test_directional_corner_from_the_yawing_moment():
    rng = np.random.default_rng(6)
    T = 4500
    beta = 0.02 * _noise(rng, T, 0.1, 2.0)
    r_hat = 0.01 * _noise(rng, T, 0.1, 2.0)
    cn = 0.09 * beta - 0.1 * r_hat + 1e-5 * rng.normal(size=T)
    qbar, S, b, izz = 250.0, 0.98, 2.8, 1.2
    f, cn_beta = bb.directional_hz(DT, beta, r_hat[:, None], cn, qbar, S, b, izz)
    assert abs(cn_beta - 0.09) < 0.005
    assert abs(f - np.sqrt(qbar * S * b * 0.09 / izz) / (2 * np.pi)) < 0.02
    assert bb.directional_hz(DT, beta, r_hat[:, None], -cn, qbar, S, b, izz)[0] == 0.0   # unstable: no corner


def test_rows_and_command_line():
    r = {"flight": "x-light-s1-ahrs", "true_sd": 1.0, "kin_err_sd": 3.0, "wc_hz": 0.64,
         "edges": {"0.3": {"used": True, "beta": -0.69, "r_hat": -1.86, "err_sd": 0.66, "scale": 1.0},
                   "1.2": {"used": False, "err_sd": 1.0, "scale": 1.0}},
         "gust": {"0.3-": {"beta": -0.34, "r_hat": 1.85}}}
    e, g = bb.show(r)
    assert "-0.69 / -1.86 / 0.66 / 1.00" in e and "not aided" in e and e.count("|") == 4 + len(bb.EDGES) + 1
    assert g == "| x-light-s1-ahrs | -0.34 / +1.85 |"
    a = bb.work_parser("d", json_out=True).parse_args(["D1", "D2", "--aircraft", "rascal", "--json", "f"])
    assert a.work == ["D1", "D2"] and a.aircraft == "rascal" and a.json == "f" and a.turbulence is None
