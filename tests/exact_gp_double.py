"""TEST DOUBLE: a small exact numpy GP standing in for gcs_sysid.gp in the envelope, maneuver and
report tests. It implements only the interface those modules use (``predict``,
``variance_after``, ``summary``). Production code never imports it.

Independent outputs sharing one squared-exponential ARD kernel on inputs scaled by per-column
length-scales; Gaussian noise. Rasmussen and Williams (2006), eqs. 2.25-2.26.
"""

from __future__ import annotations

import numpy as np


class ExactGPDouble:
    """Exact GP regression, O(N^3); for N up to a few hundred.

    Args:
        X: (N, D) training inputs. Y: (N, P) training targets.
        lengthscales: (D,) length-scales (input units).
        signal_var: (P,) prior variance per output. noise_var: (P,) noise variance per output.
    """

    def __init__(self, X, Y, lengthscales, signal_var, noise_var):
        self.X = np.asarray(X, float)
        self.Y = np.asarray(Y, float)
        self.ls = np.asarray(lengthscales, float)
        self.sf2 = np.asarray(signal_var, float)
        self.sn2 = np.asarray(noise_var, float)
        self.mu = self.Y.mean(0)
        self.n_outputs = self.Y.shape[1]
        self._cache = {}

    def _k(self, A, B):
        a, b = A / self.ls, B / self.ls
        d2 = (a**2).sum(1)[:, None] + (b**2).sum(1)[None, :] - 2 * a @ b.T
        return np.exp(-0.5 * np.maximum(d2, 0.0))

    def _chol(self, K, j):
        """Cholesky factor of K + (noise/signal) I, cached per distinct noise ratio."""
        ratio = float(self.sn2[j] / self.sf2[j])
        key = (id(K), ratio)
        if key not in self._cache:
            self._cache = {k: v for k, v in self._cache.items() if k[0] == id(K)}
            self._cache[key] = np.linalg.cholesky(K + ratio * np.eye(len(K)))
        return self._cache[key]

    def predict(self, Xq):
        """Mean (Q, P) and predictive variance including noise (Q, P)."""
        from scipy.linalg import solve_triangular

        Xq = np.asarray(Xq, float)
        K = self._k(self.X, self.X)
        Ks = self._k(Xq, self.X)
        mean = np.empty((len(Xq), self.n_outputs))
        var = np.empty_like(mean)
        self._cache = {}
        for j in range(self.n_outputs):
            L = self._chol(K, j)   # sf2 (K + r I) = sf2 L L^T
            a = solve_triangular(L.T, solve_triangular(L, self.Y[:, j] - self.mu[j], lower=True), lower=False)
            mean[:, j] = self.mu[j] + Ks @ a
            v = solve_triangular(L, Ks.T, lower=True)
            var[:, j] = self.sf2[j] * (1.0 - (v**2).sum(0)) + self.sn2[j]
        return mean, var

    def variance_after(self, X_extra, X_query):
        """Predictive variance (Q, P) at X_query after adding noisy observations at X_extra."""
        from scipy.linalg import solve_triangular

        X_all = np.vstack([self.X, np.asarray(X_extra, float)])
        K = self._k(X_all, X_all)
        Ks = self._k(np.asarray(X_query, float), X_all)
        var = np.empty((len(X_query), self.n_outputs))
        self._cache = {}
        for j in range(self.n_outputs):
            v = solve_triangular(self._chol(K, j), Ks.T, lower=True)
            var[:, j] = self.sf2[j] * (1.0 - (v**2).sum(0)) + self.sn2[j]
        return var

    def summary(self):
        """Hyperparameters, JSON-able."""
        return {"kind": "ExactGPDouble", "n_train": int(len(self.X)), "lengthscales": self.ls.tolist(),
                "signal_var": self.sf2.tolist(), "noise_var": self.sn2.tolist(),
                "output_correlation": np.corrcoef(self.Y.T).tolist()}


def fit_double(X, Y, rel_lengthscale=0.5, noise_frac=0.05, max_points=300, seed=0):
    """Build an :class:`ExactGPDouble` from data: length-scales ``rel_lengthscale * std`` per column
    (1 for constant columns), signal variance the output variance, noise a fraction of it."""
    X, Y = np.asarray(X, float), np.asarray(Y, float)
    if len(X) > max_points:
        idx = np.random.default_rng(seed).choice(len(X), max_points, replace=False)
        X, Y = X[idx], Y[idx]
    sd = X.std(0)
    ls = np.where(sd > 1e-9, rel_lengthscale * sd, 1.0)
    var = Y.var(0)
    return ExactGPDouble(X, Y, ls, var, noise_frac * var)


#: Derivative model of the synthetic table (rows CX CY CZ Cl Cm Cn; columns: bias, then REGRESSORS
#: alpha beta p_hat q_hat r_hat delta_e delta_a delta_r delta_t V). Signs follow docs/conventions.md.
SYNTH_DERIVATIVES = np.array([
    # bias  alpha beta  p_hat q_hat r_hat  d_e    d_a    d_r   d_t   V
    [-0.03, 0.25, 0.0,  0.0,  0.0,  0.0,   0.0,   0.0,   0.0,  0.10, 0.0],   # CX
    [0.0,   0.0, -0.35, 0.0,  0.0,  0.25,  0.0,   0.0,   0.15, 0.0,  0.0],   # CY
    [-0.25, -4.5, 0.0,  0.0, -6.0,  0.0,  -0.35,  0.0,   0.0,  0.0,  0.0],   # CZ
    [0.0,   0.0, -0.05, -0.45, 0.0, 0.10,  0.0,  -0.20,  0.004, 0.0, 0.0],   # Cl
    [0.02, -0.6,  0.0,  0.0, -12.0, 0.0,  -1.1,   0.0,   0.0,  0.0,  0.0],   # Cm
    [0.0,   0.0,  0.07, -0.03, 0.0, -0.12, 0.0,   0.01, -0.06, 0.0,  0.0],   # Cn
])


def synthetic_table(n=600, rate_hz=20.0, seed=0):
    """A seeded CoefficientTable of a gentle flight: smooth random regressors near trim and
    coefficients from :data:`SYNTH_DERIVATIVES` plus 3 % noise. Returns the table."""
    from gcs_sysid.aero.table import CoefficientTable

    rng = np.random.default_rng(seed)
    t = 100.0 + np.arange(n) / rate_hz

    def smooth(scale, offset=0.0):
        f = rng.uniform(0.05, 0.6, 4)
        ph = rng.uniform(0, 2 * np.pi, 4)
        return offset + scale * np.sum(np.sin(2 * np.pi * f[:, None] * (t - t[0]) + ph[:, None]), 0) / 2.0

    X = np.column_stack([
        smooth(np.radians(1.5), np.radians(4.0)),    # alpha
        smooth(np.radians(1.0)),                     # beta
        smooth(0.01), smooth(0.004), smooth(0.005),  # p_hat q_hat r_hat
        smooth(np.radians(1.5), np.radians(-2.0)),   # delta_e
        smooth(np.radians(2.0)), smooth(np.radians(1.5)),  # delta_a delta_r
        np.clip(smooth(0.05, 0.55), 0, 1),           # delta_t
        smooth(1.5, 18.0),                           # V
    ])
    Y = np.column_stack([np.ones(n), X]) @ SYNTH_DERIVATIVES.T
    Y = Y + 0.03 * Y.std(0) * rng.standard_normal(Y.shape)
    qbar = 0.5 * 1.2 * X[:, -1] ** 2
    return CoefficientTable(t, X, Y, np.ones(n, bool), qbar, ["synthetic table for tests"])


def envelope_setup(airframe_path):
    """The maneuver tests' common case: a synthetic table, the exact GP double fitted on all but its
    last 80 rows, the confidence map and the airframe. Returns (table, train_mask, model, envelope, airframe)."""
    from gcs_sysid.airframe import load_airframe
    from gcs_sysid.envelope import EnvelopeConfig, confidence_map

    tab = synthetic_table(n=400, seed=2)
    train = np.ones(len(tab.t), bool)
    train[-80:] = False
    model = fit_double(tab.X[train], tab.Y[train], rel_lengthscale=2.0, max_points=200)
    env = confidence_map(model, tab, train, EnvelopeConfig(n_grid=16))
    return tab, train, model, env, load_airframe(airframe_path)
