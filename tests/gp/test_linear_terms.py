"""Linear terms that earn their place (``GPConfig.linear_terms="significant"``, opt-in): each output's
linear mean keeps only the regressors whose slope is significant with coloured-residual standard errors
(``gp.colored.significant_inputs``; docs/gp.md).

The weakness these tests guard: a linear mean with every regressor, fitted by a likelihood that counts
each 50 Hz row as independent, turns a slowly varying measurement error into a derivative of any
regressor that happens to vary as slowly (a spurious regression; Granger and Newbold 1974). On the
JSBSim T-6 that put ``Cn_delta_a`` and ``Cn_q_hat`` into the GP's Cn, which the aircraft does not have.
"""

import numpy as np
import pytest
from scipy.signal import lfilter

from gcs_sysid.diagnose.regression import ols
from gcs_sysid.gp import GPConfig, fit_gp
from gcs_sysid.gp.colored import T_KEEP, ols_coloured_t, significant_inputs
from gcs_sysid.gp.fit import linear_prior_std


def _ar1(rng, n, phi, std):
    return lfilter([1.0], [1.0, -phi], std * rng.standard_normal(n))


def _case(seed: int, n: int = 3000):
    """``y = 2 x0 - x1 + e``: ``x2`` and the error ``e`` are slow AR(1) processes (phi 0.98, about 50
    rows), independent of each other; ``x0`` a two-tone signal, ``x1`` a square wave (50 Hz rows)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / 50.0
    x0 = np.sin(2 * np.pi * 0.7 * t) + 0.5 * np.sin(2 * np.pi * 1.9 * t + 1.0) + 0.1 * rng.standard_normal(n)
    x1 = np.sign(np.sin(2 * np.pi * 0.23 * t)) + 0.1 * rng.standard_normal(n)
    x2 = _ar1(rng, n, 0.98, 0.1)
    e = _ar1(rng, n, 0.98, 0.02) + 0.01 * rng.standard_normal(n)
    return np.column_stack([x0, x1, x2]), 2.0 * x0 - x1 + e


def test_coloured_t_equals_the_stepwise_regressions():
    """Same sandwich and lag window as the stepwise regression's partial F (diagnose.regression)."""
    X, y = _case(3, 1500)
    _, t = ols_coloured_t(X, y)
    r = ols(np.column_stack([np.ones(len(y)), X]), y, ["1", "a", "b", "c"], colored=True)
    np.testing.assert_allclose(t, np.abs(r.theta[1:] / r.std_error[1:]), rtol=1e-8)


def test_a_slow_error_does_not_make_a_slow_regressor_a_term():
    """20 flights: the true terms are kept in all; the spurious ``x2`` in at most 5 (white standard
    errors would call it significant in at least 12: the old mean kept it in all 20)."""
    kept = white = 0
    for seed in range(20):
        X, y = _case(seed)
        keep = significant_inputs(X, y[:, None], np.ones(3, bool))[0]
        assert keep[0] and keep[1]
        kept += int(keep[2])
        r = ols(np.column_stack([np.ones(len(y)), X]), y, ["1", "a", "b", "c"], colored=False)
        white += int(abs(r.theta[3] / r.std_error[3]) >= T_KEEP)
    assert kept <= 5 and white >= 12, (kept, white)


def test_missing_entries_inactive_inputs_and_the_prior_std():
    """Each output uses its own finite rows; an inactive regressor is never a term; the prior std is
    ``prior_std`` on the intercept and the kept terms, 0 elsewhere (and 0 without a linear mean)."""
    X, y = _case(5)
    Y = np.column_stack([y, -y])
    Y[::3, 1] = np.nan
    active = np.array([True, True, False])
    keep = significant_inputs(X, Y, active)
    assert keep.shape == (2, 3) and not keep[:, 2].any() and keep[:, :2].all()
    S = linear_prior_std(GPConfig(prior_std=3.0), keep, 2, 3)
    np.testing.assert_array_equal(S, [[3, 3, 3, 0], [3, 3, 3, 0]])
    assert not linear_prior_std(GPConfig(linear_mean=False), keep, 2, 3).any()
    few = significant_inputs(X[:9], Y[:9], np.ones(3, bool))          # too few rows: every active term
    assert few.all()


@pytest.mark.slow
def test_gp_mean_leaves_the_spurious_slope_out_and_predicts_better():
    """The fitted GP: slope of ``x2`` exactly 0 with ``linear_terms="significant"`` (opt-in), not with
    every regressor (``"all"``, the default); on a later segment where ``x2`` moves 3x as far, the
    ``"significant"`` model's error against the noise-free truth is lower."""
    X, y = _case(9, 2400)
    seen = 0
    cfg = dict(n_inducing=32, n_inducing_hyper=16, steps=60, local=False)
    rng = np.random.default_rng(0)
    Xq = X[:400].copy()
    Xq[:, 2] = 3.0 * _ar1(rng, 400, 0.98, 0.1)
    truth = 2.0 * Xq[:, 0] - Xq[:, 1]
    errs = {}
    for terms in ("significant", "all"):
        model, hist = fit_gp(X, y[:, None], GPConfig(linear_terms=terms, **cfg))
        slope = model.linear_derivatives()[1][0, 2]
        if terms == "significant":
            assert slope == 0.0 and hist.validation["linear_terms"] == [[0, 1]]
        else:
            seen = abs(slope)
        errs[terms] = float(np.sqrt(np.mean((np.asarray(model.predict(Xq)[0])[:, 0] - truth) ** 2)))
    assert seen > 0.0
    assert errs["significant"] < errs["all"], errs


@pytest.mark.slow
@pytest.mark.parametrize("missing", [False, True])
def test_per_output_prior_std_equals_the_exact_gp(missing):
    """A ``(P, D+1)`` prior std with zeros (terms left out of an output's mean): the sparse layer with
    inducing points at the data equals the exact GP with covariance ``blockdiag_p(Xa V_p Xa^T) + B kron
    K + noise`` (bound and posterior; complete and per-output statistics)."""
    import jax
    import jax.numpy as jnp

    from gcs_sysid.gp import exact, sparse
    from gcs_sysid.gp.kernels import coregionalisation
    from gcs_sysid.gp.sparse import GlobalParams

    rng = np.random.default_rng(3)
    X = rng.uniform(-2, 2, (20, 2))
    f = np.sin(2 * X[:, 0]) + 0.5 * X[:, 1]
    Y = np.column_stack([f, 0.7 * f + 0.2 * X[:, 0], -0.3 * f + np.cos(X[:, 1])]) + 0.1 * rng.standard_normal((20, 3))
    Xq = rng.uniform(-2.5, 2.5, (6, 2))
    B = coregionalisation(jnp.asarray([[0.9], [0.7], [-0.3]]), jnp.array([0.1, 0.2, 0.05]))
    S = np.array([[1.0, 2.0, 0.0], [1.0, 0.0, 0.5], [3.0, 1.0, 1.0]])
    p = GlobalParams(lengthscale=jnp.array([0.8, 1.3]), A=jnp.linalg.cholesky(B), noise=jnp.array([0.01, 0.03, 0.02]),
                     Z=jnp.asarray(X), prior_std=jnp.asarray(S), jitter=jnp.asarray(1e-10))
    mask = None
    if missing:
        mask = np.ones(Y.shape, bool)
        mask[::4, 1] = False
    st = jax.jit(sparse.stats_of)(p, jnp.asarray(X), jnp.asarray(np.where(mask, Y, 0.0) if missing else Y), None,
                                  None if mask is None else jnp.asarray(mask, float))
    want = float(jax.jit(lambda q: exact.exact_log_marginal(q, jnp.asarray(X), jnp.asarray(Y), mask=mask))(p))
    assert float(jax.jit(sparse.elbo)(p, st)) == pytest.approx(want, rel=1e-6)
    m, v = jax.jit(sparse.predict_global_chunk)(p, jax.jit(sparse.posterior)(p, st), jnp.asarray(Xq))
    me, ve = jax.jit(lambda q: exact.exact_predict(q, jnp.asarray(X), jnp.asarray(Y), jnp.asarray(Xq), mask=mask))(p)
    np.testing.assert_allclose(m, me, rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(v, ve, rtol=1e-5, atol=1e-8)


def test_validated_terms_only_for_outputs_the_validation_found_linear():
    """``linear_terms="validated"`` (the default): the elimination runs only for the outputs whose latent
    GP the blocked validation shrank to the smallest scale; the others keep every regressor."""
    import jax.numpy as jnp

    from gcs_sysid.gp.fit import FitHistory, _validated_terms
    from gcs_sysid.gp.sparse import GlobalParams
    from gcs_sysid.gp.validation import GLOBAL_GRID

    X, y = _case(0)
    Y = np.column_stack([y, y])
    p = GlobalParams(lengthscale=jnp.ones(3), A=jnp.eye(2), noise=jnp.ones(2), Z=jnp.zeros((4, 3)),
                     prior_std=jnp.asarray(3.0), jitter=jnp.asarray(1e-6))
    hist = FitHistory()
    hist.validation["latent_scale"] = [GLOBAL_GRID[0], 1.0]
    S = np.asarray(_validated_terms(p, X, Y, np.ones(3, bool), hist).prior_std)
    np.testing.assert_array_equal(S, [[3, 3, 3, 0], [3, 3, 3, 3]])
    assert hist.validation["linear_terms"] == [[0, 1], [0, 1, 2]]
    hist.validation["latent_scale"] = [1.0, 0.3]                      # nothing found linear: unchanged
    assert _validated_terms(p, X, Y, np.ones(3, bool), hist) is p
