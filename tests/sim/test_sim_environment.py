"""ISA and Dryden turbulence: standard values, and the forming filters give the specified rms and correlation."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gcs_sysid.sim.core import _gust, _turb_update, turbulence_init
from gcs_sysid.sim.environment import W20_BY_INTENSITY, dryden_scales, isa


def test_isa_standard_values():
    p, T, rho = isa(np.array([0.0, 1000.0, 3000.0]))
    assert np.allclose(p, [101325.0, 89874.6, 70108.5], rtol=2e-4)
    assert np.allclose(rho, [1.2250, 1.1116, 0.9091], rtol=2e-4)
    assert T[1] == pytest.approx(281.65)


def test_dryden_scales_low_altitude():
    L, sigma = dryden_scales(100.0, W20_BY_INTENSITY["light"])
    h = 100.0 / 0.3048
    assert L[2] == pytest.approx(100.0) and L[0] == pytest.approx(h / (0.177 + 0.000823 * h) ** 1.2 * 0.3048)
    assert sigma[2] == pytest.approx(0.1 * 15 * 0.514444) and sigma[0] > sigma[2]


def test_forming_filters_have_the_dryden_rms_and_correlation():
    V, dt, n = 20.0, 0.02, 100_000
    L, sigma = dryden_scales(60.0, 8.0)
    rng = np.random.default_rng(3)
    zeta = jnp.asarray(rng.normal(size=(n, 3)))

    def step(turb, z):
        g, b = _gust(turb, jnp.asarray(L), jnp.asarray(sigma), V)
        return _turb_update(turb, b, z, dt), g

    _, g = jax.lax.scan(step, turbulence_init(rng.normal(size=5), L, sigma, V), zeta)
    g = np.asarray(g)
    assert np.allclose(g.std(0), sigma, rtol=0.08)
    # u gust: exponential autocorrelation exp(-V tau / L_u); check at tau = L_u / V
    lag = int(round(L[0] / V / dt))
    rho_u = np.corrcoef(g[:-lag, 0], g[lag:, 0])[0, 1]
    assert rho_u == pytest.approx(np.exp(-1.0), abs=0.1)
