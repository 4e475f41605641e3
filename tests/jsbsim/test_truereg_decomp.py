"""benchmarks/truereg_decomp.py: the true-regressor miss split into the air angles' gain and level (synthetic
records; thirty-first session, i8-truereg)."""

import numpy as np
import pytest

from benchmarks import truereg_decomp as td
from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS


def _flight(k_beta=0.8, alpha_level=0.005, T=3000, seed=3):
    """Exact regressors and linear coefficients; the estimate reads beta scaled by ``k_beta`` and alpha shifted by
    ``alpha_level`` rad (the measured coefficients are the exact ones plus a little noise)."""
    rng = np.random.default_rng(seed)
    Xt = np.zeros((T, len(REGRESSORS)))
    Xt[:, 0] = 0.02 * rng.normal(size=T)               # alpha
    Xt[:, 1] = 0.02 * rng.normal(size=T)               # beta
    Xt[:, 5] = 0.03 * rng.normal(size=T)               # delta_e
    Xt[:, 7] = 0.03 * rng.normal(size=T)               # delta_r
    Xt[:, 9] = 60.0 + rng.normal(size=T)               # V
    Yt = np.zeros((T, len(COEFFICIENTS)))
    Yt[:, 1] = -0.5 * Xt[:, 1] + 0.2 * Xt[:, 7]                       # CY
    Yt[:, 2] = -0.4 - 5.0 * Xt[:, 0] - 0.3 * Xt[:, 5]                 # CZ
    Yt[:, 4] = 0.02 - 1.0 * Xt[:, 0] - 1.2 * Xt[:, 5]                 # Cm
    Yt[:, 5] = 0.1 * Xt[:, 1] - 0.08 * Xt[:, 7]                       # Cn
    Yt[:, 0] = -0.05 + 0.3 * Xt[:, 0]                                  # CX
    Yt[:, 3] = -0.05 * Xt[:, 1]                                        # Cl
    X = Xt.copy()
    X[:, 1] = k_beta * Xt[:, 1] + 0.0005 * rng.normal(size=T)
    X[:, 0] = Xt[:, 0] + alpha_level
    Y = Yt + 1e-4 * rng.normal(size=Yt.shape)
    held = np.arange(T) >= int(0.8 * T)
    return X, Y, Xt, Yt, ~held, held


def test_a_beta_scale_and_an_alpha_level_are_found_and_explain_the_miss():
    r = td.decompose(*_flight())
    assert r["beta_k"] == pytest.approx(0.8, abs=0.01)
    assert r["beta_lambda"] == pytest.approx(1.25, abs=0.02)       # a scale error inflates the learned slope
    assert r["slope_ratio"]["CY/beta"] == pytest.approx(1.25, abs=0.02)
    assert r["alpha_level_deg"] == pytest.approx(np.degrees(0.005), abs=1e-6)
    # good at the estimates, far off at the truth; the truth passed through beta's gain (resp. alpha's level) alone
    # gives back the held-out error of CY and Cn (resp. CZ and Cm)
    for c in ("CY", "Cn"):
        assert r["held"][c] < 4.0 and r["true"][c] > 15.0
        assert r["beta_gain"][c] < 4.0 and r["beta_est"][c] < 4.0
        assert r["alpha_level"][c] > 15.0                             # alpha's level does not reach them
    for c in ("CZ", "Cm"):
        assert r["true"][c] > 5.0 and r["alpha_level"][c] < 1.0 and r["beta_gain"][c] > 5.0


def test_exact_regressors_leave_nothing_to_explain():
    r = td.decompose(*_flight(k_beta=1.0, alpha_level=0.0))
    assert r["beta_k"] == pytest.approx(1.0, abs=0.01)
    for c in ("CY", "CZ", "Cm", "Cn"):
        assert r["true"][c] < 2.0


def test_too_few_rows_raise():
    X, Y, Xt, Yt, tr, h = _flight(T=60)
    with pytest.raises(ValueError):
        td.decompose(X, Y, Xt, Yt, tr, h)
