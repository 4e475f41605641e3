"""``benchmarks/eval_jsbsim.py``'s ``band_terms``: the two scored bands taken apart (twelfth session, i8-cover).

Each term is ``100 sqrt(mean(var_term)) / RMS(truth)`` per coefficient, so the squares add up to the band's
own ``100 sqrt(mean(var)) / RMS(truth)``; the sums must be the replay's coefficient band
(``predict(X, x_var=..., white_noise=False)``) and ``gcs-sysid predict``'s band at exact conditions
(``predict(X, include_noise=False, input_noise=False)``). ``docs/gp.md``, "Which term sets the band's width".
"""

import numpy as np
import pytest

from benchmarks.eval_jsbsim import band_terms
from gcs_sysid.gp.discrepancy import with_offset_covariance


@pytest.mark.slow          # 6-14 s (load 8-11), most of it compiling: a benchmark's diagnosis, not the suite's
def test_band_terms_add_up_to_the_two_scored_bands(fitted, flight):
    model, _ = fitted
    X, _, Yt = flight
    D = model.n_inputs
    rng = np.random.default_rng(3)
    L = rng.normal(size=(D, D)) * 0.05
    C = np.zeros((D, D, D))
    C[1] = L @ L.T                                                  # beta's common linear error
    sv = np.zeros(D)
    sv[0] = 0.04                                                    # alpha's scale (no map for alpha)
    model = with_offset_covariance(model, np.diag(np.r_[1e-6, np.zeros(D - 1)]), scale_var=sv, map_cov=C)
    Xq, Xtrue, ref = X[400:], X[400:] + rng.normal(scale=0.01, size=X[400:].shape), Yt[400:]
    xv = np.full(Xq.shape, np.nan)
    xv[:, 1] = 9.0 * np.asarray(model.input_var)[1] * model.scaler.x_std[1] ** 2     # a stated beta variance
    bt = band_terms(model, Xq, Xtrue, xv, ref)
    rms = np.sqrt(np.mean(ref**2, axis=0))
    sig_gp = 100 * np.sqrt(np.mean(model.predict(Xq, x_var=xv, white_noise=False)[1], axis=0)) / rms
    sig_true = 100 * np.sqrt(np.mean(model.predict(Xtrue, include_noise=False, input_noise=False)[1], axis=0)) / rms
    np.testing.assert_allclose(bt["gp"]["sigma"], sig_gp, rtol=2e-3)
    np.testing.assert_allclose(bt["true"]["sigma"], sig_true, rtol=2e-3)
    for band, terms in (("gp", ("latent", "input", "coloured")),
                        ("true", ("latent", "offset", "scale", "map", "discrepancy"))):
        parts = np.array([bt[band][t] for t in terms])
        assert (parts >= 0).all()
        np.testing.assert_allclose(np.sqrt(np.sum(parts**2, axis=0)), bt[band]["sigma"], rtol=2e-3)
    for t in ("offset", "scale", "map"):                             # each set term shows where it acts
        assert max(bt["true"][t]) > 0, t
    assert (np.array(bt["gp"]["input"]) >= np.array(bt["gp"]["input_learned"]) - 1e-9).all()
    assert len(bt["gp"]["white"]) == model.n_outputs and min(bt["gp"]["white"]) > 0      # the white share left out
