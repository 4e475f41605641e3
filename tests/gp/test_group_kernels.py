"""Per-group latent kernels (``GPConfig.output_groups = "kernels"``, thirteenth session, issue 8).

Each output group (the longitudinal CX CZ Cm and the lateral-directional CY Cl Cn) has its own latent
kernel with its own length-scales and a coregionalisation over its own outputs only (``docs/gp.md``,
"Per-group kernels").
"""

from __future__ import annotations

import numpy as np
import pytest

from gcs_sysid.aero.table import COEFFICIENTS
from gcs_sysid.errors import InputError
from gcs_sysid.gp import GPConfig
from gcs_sysid.gp.fit import group_embedding, group_factors, output_groups


def test_group_factors_load_on_their_group_only():
    """``A_g A_g^T`` is group ``g``'s block of ``B_g`` and 0 elsewhere; a smaller group's extra column is 0;
    the six coefficients split by axis; the settings that do not fit with it are refused."""
    groups = output_groups(COEFFICIENTS, GPConfig(output_groups="kernels"))
    np.testing.assert_array_equal(groups, [0, 1, 0, 1, 0, 1])          # CX CY CZ Cl Cm Cn
    assert output_groups(["y0", "y1"], GPConfig(output_groups="kernels")) is None
    rng = np.random.default_rng(3)
    for g in (np.array([0, 1, 0, 0, 1]),):                             # unequal groups: one padded column
        G, P = int(g.max()) + 1, len(g)
        E = group_embedding(g)
        L = rng.normal(size=(G, P, P))
        B = np.einsum("gpr,gqr->gpq", L, L) + 0.1 * np.eye(P)
        A = np.asarray(group_factors(E, B))
        assert A.shape == (G, P, max(np.bincount(g)))
        for k in range(G):
            rows = g == k
            BA = A[k] @ A[k].T
            np.testing.assert_allclose(BA[np.ix_(rows, rows)], B[k][np.ix_(rows, rows)], rtol=1e-12)
            assert np.all(BA[~rows] == 0.0) and np.all(BA[:, ~rows] == 0.0)
            assert np.all(A[k][:, rows.sum():] == 0.0)
    with pytest.raises(InputError, match="latent_kernels=1"):
        GPConfig(output_groups="kernels", latent_kernels=2)
    with pytest.raises(InputError, match="coupling_validation"):
        GPConfig(output_groups="kernels", coupling_validation=True)


@pytest.mark.slow
def test_group_kernels_keep_each_axis_own_length_scales(tmp_path):
    """Longitudinal outputs driven by a fast function of delta_e, lateral ones by a slow function of beta
    and delta_a: the one shared kernel takes the lateral length-scales and loses the longitudinal outputs
    (held-out error above 50 %), the per-group kernels keep both (below 20 %), with no cross-axis output
    correlation. Saved and loaded the same; the maneuver ranking's closed form equals an exact update."""
    from gcs_sysid.gp import fit_gp, load_gp

    rng = np.random.default_rng(0)
    N = 900
    X = rng.normal(size=(N, 10))
    f_lon, f_lat = np.sin(3.0 * X[:, 5]), np.sin(0.7 * X[:, 1] + 0.5 * X[:, 6])
    Y = np.column_stack([f_lon + 0.1 * X[:, 0], f_lat, -f_lon, 0.5 * f_lat, 0.7 * f_lon, -f_lat])
    Y = Y + 0.05 * rng.normal(size=Y.shape)
    tr, te = slice(0, 700), slice(700, None)

    def err(m):
        e = m.predict(X[te])[0] - Y[te]
        return 100 * np.sqrt(np.mean(e**2, 0) / np.mean(Y[te] ** 2, 0))

    icm = fit_gp(X[tr], Y[tr], GPConfig(n_inducing=64))[0]
    grp = fit_gp(X[tr], Y[tr], GPConfig(n_inducing=64, output_groups="kernels"))[0]
    lon = [0, 2, 4]
    assert np.all(err(icm)[lon] > 50.0)
    assert np.all(err(grp) < 20.0)
    c = grp.output_correlation()
    assert np.all(c[np.ix_(lon, [1, 3, 5])] == 0.0)
    ls = np.asarray(grp.params.lengthscales)                               # (2, 10): kernel 0 longitudinal
    assert ls[0, 5] < 0.5 * ls[1, 5] and ls[1, 1] < 0.5 * ls[0, 1]
    grp.save(tmp_path / "gp")
    np.testing.assert_allclose(load_gp(tmp_path / "gp").predict(X[te])[0], grp.predict(X[te])[0], rtol=1e-12)
    far = X[te][:20] + 1.0
    [(v0, v1)] = grp.global_variance_after_many([far], [X[te][20:60]])
    exact = grp.update(far, np.zeros((20, 6)), exchange=False).predict_global(X[te][20:60], False)[1]
    np.testing.assert_allclose(v1, exact, rtol=1e-7)
    np.testing.assert_allclose(v0, grp.predict_global(X[te][20:60], False)[1], rtol=1e-7)
