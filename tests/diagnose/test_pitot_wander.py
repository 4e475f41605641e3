"""The Gauss-Markov wind-error fit of ``benchmarks/pitot_wander.py`` (issue 9's pitot floor analysis)."""

import numpy as np

from benchmarks.pitot_wander import gm_fit, gm_gls


def _flight(seed, bias, tau=20.0, sigma_w=0.3, sigma_n=0.2, T=200.0, rate=25.0, two_headings=False):
    """Pitot residual of a synthetic flight: bias + the wander along the air velocity + white noise."""
    rng = np.random.default_rng(seed)
    dt = 1.0 / rate
    t = np.arange(0.0, T, dt)
    a = np.exp(-dt / tau)
    w = np.zeros((t.size, 2))
    w[0] = rng.normal(0, sigma_w, 2)
    e = rng.normal(0, sigma_w * np.sqrt(1 - a * a), (t.size, 2))
    for i in range(1, t.size):
        w[i] = a * w[i - 1] + e[i]
    psi = np.where(t < T / 2, 0.5, 0.5 + (np.pi if two_headings else 0.0))
    h = np.stack([np.cos(psi), np.sin(psi)], 1)
    r = bias + np.sum(h * w, 1) + rng.normal(0, sigma_n, t.size)
    return {"t": t, "r": r, "h": h}


def test_the_wander_fit_recovers_a_bias_and_its_time_constant_and_counts_the_wander_in_the_error():
    for seed in (1,):
        f = _flight(seed, 1.0)
        g = gm_fit(f)
        assert 5.0 <= g["tau_s"] <= 80.0
        assert abs(g["bias_mps"] - 1.0) < 3.5 * g["std_error"]
        # the wander's variance is in the standard error: far above the white-noise one (0.2 / sqrt(7500))
        assert g["std_error"] > 0.05
    # a longer correlation time leaves fewer independent looks at the wander: a larger error
    f = _flight(3, 0.0)
    tb = np.arange(0.0, 200.0, 1.0) + 0.5
    hb = np.tile([np.cos(0.5), np.sin(0.5)], (tb.size, 1))
    rb = np.interp(tb, f["t"], f["r"])
    assert gm_gls(tb, rb, hb, 40.0, 0.1)[1] > gm_gls(tb, rb, hb, 10.0, 0.1)[1]
