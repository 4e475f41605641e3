"""Synthetic coefficient tables with a known model and a known hidden cause (the test controls the truth).

The regressors follow smooth multisine-like excitation on all axes; the "measured"
coefficients are computed forward from the true model and then passed through
the hidden cause the way the estimation layer would see it.
"""

from __future__ import annotations

import numpy as np

from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS, CoefficientTable
from gcs_sysid.diagnose.context import evaluate_model

BASE = {
    "CX": {"1": -0.03, "alpha": 0.25, "alpha^2": 2.0},
    "CY": {"beta": -0.35, "delta_r": 0.15},
    "CZ": {"1": -0.30, "alpha": -4.8, "q_hat": -5.0, "delta_e": -0.40},
    "Cl": {"beta": -0.06, "p_hat": -0.45, "r_hat": 0.10, "delta_a": 0.15, "delta_r": 0.005},
    "Cm": {"1": 0.02, "alpha": -0.70, "q_hat": -12.0, "delta_e": -1.10},
    "Cn": {"beta": 0.07, "p_hat": -0.03, "r_hat": -0.10, "delta_a": -0.01, "delta_r": -0.06},
}


def smooth(rng, n, dt, bw_hz, amp):
    """Band-limited random signal, RMS ``amp``."""
    f = np.fft.rfftfreq(n, dt)
    spec = (rng.normal(size=f.size) + 1j * rng.normal(size=f.size)) * (f < bw_hz) * (f > 0.02)
    x = np.fft.irfft(spec, n)
    s = np.std(x)
    return amp * x / s if s > 0 else x


def regressors(seed=0, duration=120.0, rate=50.0):
    rng = np.random.default_rng(seed)
    n = int(duration * rate)
    dt = 1 / rate
    t = np.arange(n) * dt + 10.0
    V = 18.0 + smooth(rng, n, dt, 0.1, 2.0)
    X = np.zeros((n, len(REGRESSORS)))
    X[:, 0] = 0.06 + smooth(rng, n, dt, 1.0, 0.04)
    X[:, 1] = smooth(rng, n, dt, 1.0, 0.04)
    X[:, 2] = smooth(rng, n, dt, 2.0, 0.03)
    X[:, 3] = smooth(rng, n, dt, 2.0, 0.01)
    X[:, 4] = smooth(rng, n, dt, 2.0, 0.02)
    for i in (5, 6, 7):
        X[:, i] = smooth(rng, n, dt, 2.0, 0.06)
    X[:, 8] = np.clip(0.55 + smooth(rng, n, dt, 0.2, 0.1), 0, 1)
    X[:, 9] = V
    qbar = 0.5 * 1.2 * V**2
    psi = np.cumsum(smooth(rng, n, dt, 0.05, 0.15)) * dt
    states = {"phi": smooth(rng, n, dt, 0.5, 0.3), "theta": 0.05 + smooth(rng, n, dt, 0.5, 0.08), "psi": psi,
              "p_dot": smooth(rng, n, dt, 3.0, 1.5), "q_dot": smooth(rng, n, dt, 3.0, 1.0),
              "r_dot": smooth(rng, n, dt, 3.0, 0.8)}
    return t, X, qbar, states


class FakeStates:
    def __init__(self, t, data):
        self.t, self.data = t, data

    def __len__(self):
        return len(self.t)


def table(model, X, Y, t, qbar, noise=(0.004, 0.004, 0.01, 0.002, 0.004, 0.0015), seed=1, colour_s=0.3):
    """A CoefficientTable with coloured (turbulence-like) plus white noise added to Y."""
    rng = np.random.default_rng(seed)
    n = len(t)
    dt = t[1] - t[0]
    E = np.column_stack([smooth(rng, n, dt, 1 / colour_s, s) + rng.normal(0, s, n) for s in noise])
    return CoefficientTable(t, X, Y + E, np.ones(n, bool), qbar, [])


def measured(model, seed=0, duration=120.0, hidden=None, value=None):
    """(table, states) with ``hidden`` applied; see the test for the forward physics."""
    t, X, qbar, st = regressors(seed, duration)
    Xtrue = X.copy()
    Xmeas = X.copy()
    Y = None
    if hidden is None:
        Y = evaluate_model(model, Xtrue)
    elif ":" in hidden and hidden.split(":")[0] in COEFFICIENTS:
        coef, term = hidden.split(":")
        m = {c: dict(v) for c, v in model.items()}
        m[coef][term] = m[coef].get(term, 0.0) + value
        Y = evaluate_model(m, Xtrue)
    elif hidden.startswith("delay:"):
        i = REGRESSORS.index(hidden[6:])
        Xtrue[:, i] = np.interp(t - value, t, X[:, i])
        Y = evaluate_model(model, Xtrue)
    elif hidden == "bias:alpha":
        Xmeas[:, 0] = X[:, 0] + value
        Y = evaluate_model(model, Xtrue)
    elif hidden == "stuck:delta_e":
        onset, us = value
        Xtrue[t >= onset, 5] = us
        Y = evaluate_model(model, Xtrue)
    elif hidden == "bias:accel_z":
        Y = evaluate_model(model, Xtrue)
        Y[:, 2] += 3.0 * value / (qbar * 0.55)
    elif hidden == "scale:airspeed":
        Y = evaluate_model(model, Xtrue)
        Y = Y / value**2
        Xmeas[:, 9] = X[:, 9] * value
        Xmeas[:, 2:5] = X[:, 2:5] / value
        qbar = qbar * value**2
    return table(model, Xmeas, Y, t, qbar), FakeStates(t, st)
