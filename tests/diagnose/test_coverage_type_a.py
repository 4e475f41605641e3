"""The naming's coverage test without the type-B air-angle components (``sparse.THRESHOLDS["coverage_type_a"]``).

The type-B components of a named term's combined uncertainty (:func:`gcs_sysid.diagnose.uncertainty.angle_sensitivity`)
refit the same residual on columns built from the rescaled angle, so they are proportional to the change: zero when
nothing changed, about ``2 u |k|`` for ``k alpha^2`` under a stated scale uncertainty ``u``. With ``u`` = 0.43 (the
c684's estimator) no ``alpha^2`` change of any size passes ``|change| > 2 u_c``. Fast (synthetic arrays, < 0.1 s)."""

import numpy as np

from gcs_sysid.diagnose.sparse import beyond_expanded_uncertainty
from gcs_sysid.diagnose.uncertainty import angle_sensitivity


def _fit(k, u=0.43, seed=0):
    rng = np.random.default_rng(seed)
    T = 3000
    X = np.zeros((T, 10))
    X[:, 0] = 0.002 + 0.026 * np.sin(np.arange(T) / 70.0)          # alpha, rad: 1.5 deg about 0.1 deg
    r = k * X[:, 0] ** 2 + rng.normal(0, 2e-4, T)

    def columns(Xp):
        return np.column_stack([np.ones(T), Xp[:, 0], Xp[:, 0] ** 2])

    return angle_sensitivity(columns, X, r, np.arange(T), 2, 0, u, 0.0)["scale"]


def test_the_type_b_scale_component_is_proportional_to_the_change():
    assert _fit(0.0) < 0.05
    for k in (-4.0, -8.0, -16.0):
        assert _fit(k) > 0.5 * abs(k)           # 2 u_c > |change| whatever the size: never named


def test_the_coverage_test_can_read_type_a_only():
    f = {"estimate": -5.41, "model_value": 0.0, "std_error": 7.054,
         "evidence": {"uncertainty": {"type_b": {"alpha_scale": 7.044, "alpha_offset": 0.012, "beta_scale": 0.0},
                                      "combined": 7.054}}}
    assert not beyond_expanded_uncertainty(f, 2.0)["beyond"]
    d = beyond_expanded_uncertainty(f, 2.0, type_a_only=True)
    assert d["beyond"] and d["combined_std_uncertainty"] < 0.5
    f0 = dict(f, estimate=-0.5, std_error=0.66,
              evidence={"uncertainty": {"type_b": {"alpha_scale": 0.1}, "combined": 0.66}})
    assert not beyond_expanded_uncertainty(f0, 2.0, type_a_only=True)["beyond"]   # a type-A-sized change stays out
