"""Least squares, coloured-residual covariance, fit statistics and stepwise regression."""

import numpy as np
import pytest

from gcs_sysid.diagnose.regression import colored_covariance, effective_samples, ols, stepwise
from gcs_sysid.diagnose.terms import VOCABULARY, canonical_term, split_cause, term_matrix
from gcs_sysid.errors import DataError, InputError


def test_vocabulary_matches_model_file():
    from gcs_sysid.sim.model_file import VOCABULARY as SIM_VOCAB

    assert VOCABULARY == SIM_VOCAB
    assert canonical_term("beta*alpha") == "alpha*beta"
    assert canonical_term("alpha*alpha") == "alpha^2"
    assert split_cause("Cm:alpha^2") == ("Cm", "alpha^2")
    for bad in ("gamma", "alpha*beta*p_hat", "alpha^3"):
        with pytest.raises(InputError):
            canonical_term(bad)
    with pytest.raises(InputError):
        split_cause("Cq:alpha")


def test_ols_matches_reference_and_statistics():
    rng = np.random.default_rng(0)
    N = 400
    X = np.column_stack([np.ones(N), rng.normal(size=N), 20 + rng.normal(size=N)])
    z = X @ [0.5, -1.0, 0.1] + 0.05 * rng.normal(size=N)
    res = ols(X, z, ["1", "a", "b"], colored=False)
    ref, *_ = np.linalg.lstsq(X, z, rcond=None)
    assert np.allclose(res.theta, ref, atol=1e-10)
    v = z - X @ ref
    s2 = v @ v / (N - 3)
    assert np.isclose(res.s2, s2)
    assert np.allclose(res.std_error_white, np.sqrt(np.diag(s2 * np.linalg.inv(X.T @ X))), rtol=1e-8)
    sst = np.sum((z - z.mean()) ** 2)
    assert np.isclose(res.r2, 1 - v @ v / sst)
    assert np.isclose(res.f0, ((sst - v @ v) / 2) / s2)
    assert np.isclose(res.pse, v @ v / N + sst / N * 3 / N)
    with pytest.raises(DataError):
        ols(X[:2], z[:2], ["1", "a", "b"])


def _ar1(rng, N, phi):
    """AR(1) noise of length N, unit innovations, zero start."""
    e = np.zeros(N)
    w = rng.normal(size=N)
    for i in range(1, N):
        e[i] = phi * e[i - 1] + w[i]
    return e


def test_colored_covariance_against_monte_carlo():
    """AR(1) residuals: the corrected standard error matches the spread over repeated experiments."""
    rng = np.random.default_rng(1)
    N, phi = 1500, 0.9
    x = np.convolve(rng.normal(size=N + 100), np.ones(30) / 30, "same")[:N]   # slow regressor
    X = np.column_stack([np.ones(N), x / x.std()])
    est, se_c, se_w = [], [], []
    for _ in range(150):
        e = _ar1(rng, N, phi)
        r = ols(X, X @ [1.0, 2.0] + 0.1 * e, ["1", "x"])
        est.append(r.theta[1])
        se_c.append(r.std_error[1])
        se_w.append(r.std_error_white[1])
    spread = np.std(est)
    assert 0.7 < np.mean(se_c) / spread < 1.3          # corrected: right size
    assert np.mean(se_w) / spread < 0.5                  # white formula: far too optimistic
    # white residuals: the correction changes little
    v = rng.normal(size=N)
    C = colored_covariance(X, v)
    W = np.linalg.inv(X.T @ X) * np.var(v)
    assert np.allclose(np.sqrt(np.diag(C)), np.sqrt(np.diag(W)), rtol=0.2)
    assert effective_samples(rng.normal(size=2000)) > 1500


def test_stepwise_recovers_structure():
    rng = np.random.default_rng(2)
    N = 3000
    X = rng.normal(size=(N, 10)) * 0.1
    X[:, 8] = 0.5 + 0.1 * rng.normal(size=N)
    X[:, 9] = 20 + rng.normal(size=N)
    z = 0.1 - 0.8 * X[:, 0] + 3 * X[:, 0] ** 2 - 0.5 * X[:, 5] + 0.01 * rng.normal(size=N)
    res = stepwise(X, z, VOCABULARY[1:])
    assert set(res.fit.terms) == {"1", "alpha", "alpha^2", "delta_e"}
    th = dict(zip(res.fit.terms, res.fit.theta))
    assert th["alpha^2"] == pytest.approx(3.0, rel=0.03)
    assert [h["action"] for h in res.history][-1] == "stop"
    assert term_matrix(X, ["alpha*beta"])[:, 0] == pytest.approx(X[:, 0] * X[:, 1])


def test_morelli_klein_covariance_covers_the_spread_of_coloured_estimates():
    """Morelli and Klein's all-lags form (sec. 5.3, SIDPAC r_colores): right size under AR(1) residuals
    that stay correlated for longer than the Bartlett window's default lags."""
    rng = np.random.default_rng(3)
    N, phi = 1500, 0.98
    x = np.convolve(rng.normal(size=N + 200), np.ones(60) / 60, "same")[:N]
    X = np.column_stack([np.ones(N), x / x.std()])
    est, se_mk, se_b = [], [], []
    for _ in range(120):
        e = _ar1(rng, N, phi)
        z = X @ [1.0, 2.0] + 0.05 * e
        est.append(ols(X, z, ["1", "x"], cov_method="morelli").theta[1])
        se_mk.append(ols(X, z, ["1", "x"], cov_method="morelli").std_error[1])
        se_b.append(ols(X, z, ["1", "x"]).std_error[1])
    spread = np.std(est)
    assert 0.6 < np.mean(se_mk) / spread < 1.4
    assert np.mean(se_mk) > np.mean(se_b)                  # the short lag window under-states it here
    v = rng.normal(size=N)                                  # white residuals: about s^2 (X'X)^-1
    W = np.linalg.inv(X.T @ X) * np.var(v)
    assert np.allclose(np.sqrt(np.diag(colored_covariance(X, v, method="morelli"))), np.sqrt(np.diag(W)), rtol=0.3)
    with pytest.raises(ValueError, match="method"):
        colored_covariance(X, v, method="hac")
