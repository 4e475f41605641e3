"""The yaw gust rate in Cl's and Cn's training targets (gcs_sysid.aero.airyaw): a fit at the gyro's r_hat of the
corrected target recovers the slopes at the air-relative rate, which a fit of the measured moment does not."""

from types import SimpleNamespace

import numpy as np
import pytest

from gcs_sysid.aero.airyaw import air_yaw_target
from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS

CN_BETA, CN_R, CL_BETA, CL_R = 0.12, -0.15, -0.08, 0.10


def _record(T=6000, dt=0.02, seed=3):
    """A lateral record in which the yaw gust rate moves with the sideslip (correlation about -0.6), as a directionally
    stable aircraft's does in a lateral gust field; the moments read the air-relative yaw rate."""
    rng = np.random.default_rng(seed)

    def ar(a, s):
        x = np.zeros(T)
        for k in range(1, T):
            x[k] = a * x[k - 1] + s * rng.standard_normal()
        return x

    beta = ar(0.99, 0.004)
    r_hat_g = -0.25 * beta + ar(0.95, 0.0004)            # the yaw gust rate, as a hat
    r_hat_air = ar(0.98, 0.0006)                         # the air-relative yaw rate the moments read
    X = np.zeros((T, len(REGRESSORS)))
    X[:, REGRESSORS.index("beta")] = beta
    X[:, REGRESSORS.index("r_hat")] = r_hat_air + r_hat_g   # the gyro's
    X[:, REGRESSORS.index("p_hat")] = ar(0.97, 0.001)
    X[:, REGRESSORS.index("delta_a")] = ar(0.9, 0.005)
    X[:, REGRESSORS.index("delta_r")] = ar(0.9, 0.005)
    X[:, REGRESSORS.index("alpha")] = 0.05 + ar(0.99, 0.001)
    X[:, REGRESSORS.index("V")] = 20.0
    Y = np.zeros((T, len(COEFFICIENTS)))
    Y[:, COEFFICIENTS.index("Cn")] = CN_BETA * beta + CN_R * r_hat_air + 1e-5 * rng.standard_normal(T)
    Y[:, COEFFICIENTS.index("Cl")] = CL_BETA * beta + CL_R * r_hat_air + 1e-5 * rng.standard_normal(T)
    Y[:, COEFFICIENTS.index("CY")] = -0.5 * beta
    table = SimpleNamespace(t=np.arange(T) * dt, X=X, Y=Y, valid=np.ones(T, bool))
    return table, r_hat_g


def _slopes(table, y, rows):
    cols = [REGRESSORS.index(k) for k in ("beta", "r_hat", "p_hat", "delta_a", "delta_r")]
    A = np.column_stack([np.ones(int(rows.sum())), table.X[rows][:, cols]])
    return np.linalg.lstsq(A, y[rows], rcond=None)[0][1:3]


def test_corrected_target_at_the_gyros_rate_gives_the_air_rate_slopes():
    table, g = _record()
    train = np.arange(len(g)) < 0.8 * len(g)
    Y, info = air_yaw_target(table, table.Y, g, train, outputs=("Cl", "Cn"))
    for name, (sb, sr) in (("Cn", (CN_BETA, CN_R)), ("Cl", (CL_BETA, CL_R))):
        k = COEFFICIENTS.index(name)
        raw = _slopes(table, table.Y[:, k], train)
        fixed = _slopes(table, Y[:, k], train)
        # the measured moment at the gyro's rate: the yaw gust's moment goes into the sideslip slope (by C_r x -0.25)
        assert abs(raw[0] - sb) > 0.2 * abs(sb)
        assert abs(fixed[0] - sb) < 0.02 * abs(sb) and abs(fixed[1] - sr) < 0.02 * abs(sr), (name, raw, fixed)
        assert info["slopes"][name] == pytest.approx(sr, rel=0.02)
    # every other output, and the rows not trained on, as given
    others = [i for i, c in enumerate(COEFFICIENTS) if c not in ("Cl", "Cn")]
    assert np.array_equal(Y[:, others], table.Y[:, others])
    assert np.array_equal(Y[~train], table.Y[~train])
    assert "Cn_r" in info["note"] and "Cl_r" in info["note"]


def test_too_few_rows_leave_the_target_and_shapes_are_checked():
    table, g = _record(T=400)
    train = np.zeros(len(g), bool)
    train[:30] = True
    Y, info = air_yaw_target(table, table.Y, g, train, outputs=("Cl", "Cn"))
    assert np.array_equal(Y, table.Y) and info["slopes"] == {} and "unchanged (30 rows)" in info["note"]
    with pytest.raises(ValueError, match="air_yaw_target"):
        air_yaw_target(table, table.Y[:-1], g, train)
