"""The aided angles' flight-common linear error (``AxisFit.map_cov``, estimation/airangles.py).

In moderate turbulence the aided angle's error follows the manoeuvre (the force model's slopes biased by
errors in variables): 2.5-10 times the per-sample sigma, against 0.5-1.5 times once that common linear map
is taken out (``docs/estimation.md``). The estimator states the map's second moment from the aided angle's
disagreement with the kinematic one along every column of the force model.
"""

import numpy as np

from gcs_sysid.aero.coefficients import stated_map_covariance
from gcs_sysid.aero.table import REGRESSORS
from gcs_sysid.estimation.airangles import AxisFit, _map_disagreement
from gcs_sysid.estimation.states import FlightStates

DT = 0.02


def _smooth(rng, T, tau):
    phi = np.exp(-DT / tau)
    w = rng.normal(0.0, np.sqrt(1 - phi * phi), T)
    x = np.zeros(T)
    for k in range(1, T):
        x[k] = phi * x[k - 1] + w[k]
    return x


def test_map_disagreement_recovers_a_known_linear_error():
    """aided = true + 0.05 (true - mean) + 0.2 q_hat, kinematic = true - gust (gust independent of both):
    the slopes of (aided - kinematic) on [aided, q_hat] are 0.05/1.05 and 0.2 - 0.2 * 0.05/1.05."""
    rng = np.random.default_rng(4)
    T = 6000
    true = np.radians(2.0) * _smooth(rng, T, 0.7)
    q = 0.01 * _smooth(rng, T, 0.4)
    gust = np.radians(0.3) * _smooth(rng, T, 3.0)
    kin = true - gust
    ang = true + 0.05 * (true - true.mean()) + 0.2 * q
    m = np.ones(T, bool)
    m[:50] = False
    cols, C = _map_disagreement(DT, "alpha", ang, kin, ["q_hat", "delta_e"],
                                np.column_stack([q, np.zeros(T)]), m)        # a column that never moves: dropped
    assert cols == ("alpha", "q_hat") and C.shape == (2, 2)
    assert np.all(np.linalg.eigvalsh(C) >= -1e-15)
    np.testing.assert_allclose(np.sqrt(np.diag(C)), [0.05 / 1.05, 0.2 - 0.2 * 0.05 / 1.05], rtol=0.25)
    short = _map_disagreement(DT, "alpha", ang[:100], kin[:100], [], np.zeros((100, 0)), m[:100])
    assert short[0] == () and short[1].shape == (0, 0)                    # too few rows: nothing stated


def test_stated_map_covariance_places_each_axis_block():
    fa = AxisFit("alpha", True, "", map_columns=("alpha", "q_hat", "delta_e"),
                 map_cov=np.array([[4.0, 1.0, 0.0], [1.0, 9.0, 0.5], [0.0, 0.5, 1.0]]))
    fb = AxisFit("beta", False, "not aided", map_columns=("beta",), map_cov=np.ones((1, 1)))
    st = FlightStates(np.arange(3) * DT, 50.0, {}, angle_fits={"alpha": fa, "beta": fb})
    out = stated_map_covariance(st)
    assert out.shape == (10, 10, 10)
    ia = [REGRESSORS.index(c) for c in ("alpha", "q_hat", "delta_e")]
    np.testing.assert_array_equal(out[0][np.ix_(ia, ia)], fa.map_cov)
    assert np.count_nonzero(out) == np.count_nonzero(fa.map_cov)          # beta not aided: nothing
    assert stated_map_covariance(FlightStates(np.arange(3) * DT, 50.0, {})) is None
