"""Seeded flight-like data and small, fast GP settings shared by the gp tests (a helper module, not tests)."""

import numpy as np

from gcs_sysid.gp import GPConfig

#: Derivative model (rows CX CY CZ Cl Cm Cn; columns bias, alpha beta p_hat q_hat r_hat d_e d_a d_r d_t V).
DERIVATIVES = np.array([
    [-0.03, 0.25, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.10, 0.002],
    [0.0, 0.0, -0.35, 0.0, 0.0, 0.25, 0.0, 0.0, 0.15, 0.0, 0.0],
    [-0.25, -4.5, 0.0, 0.0, -6.0, 0.0, -0.35, 0.0, 0.0, 0.0, 0.0],
    [0.0, 0.0, -0.05, -0.45, 0.0, 0.10, 0.0, -0.20, 0.004, 0.0, 0.0],
    [0.02, -0.6, 0.0, 0.0, -12.0, 0.0, -1.1, 0.0, 0.0, 0.0, 0.0],
    [0.0, 0.0, 0.07, -0.03, 0.0, -0.12, 0.0, 0.01, -0.06, 0.0, 0.0],
])

#: Small settings: every fitted model in the gp tests shares these shapes (one compile each).
FAST = GPConfig(n_inducing=24, n_train_max=300, steps=150, learning_rate=0.1, mi_pool=300, local_neighbours=16,
                local_batch=32, local_steps=30, batch_size=256)


def flight_regressors(n: int, seed: int, rate_hz: float = 20.0) -> np.ndarray:
    """Smooth random regressors ``(n, 10)`` near trim (rad, -, m/s), like a sysid flight."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / rate_hz

    def smooth(scale, offset=0.0):
        f, ph = rng.uniform(0.05, 0.8, 4), rng.uniform(0, 2 * np.pi, 4)
        return offset + scale * np.sum(np.sin(2 * np.pi * f[:, None] * t + ph[:, None]), 0) / 2.0

    return np.column_stack([
        smooth(np.radians(3.0), np.radians(4.0)), smooth(np.radians(2.0)), smooth(0.02), smooth(0.01),
        smooth(0.01), smooth(np.radians(3.0), np.radians(-2.0)), smooth(np.radians(3.0)), smooth(np.radians(2.5)),
        np.clip(smooth(0.1, 0.55), 0, 1), smooth(2.0, 18.0)])


def linear_truth(X: np.ndarray) -> np.ndarray:
    """Coefficients ``(n, 6)`` of the derivative model at ``X``."""
    return np.column_stack([np.ones(len(X)), X]) @ DERIVATIVES.T


def nonlinear_truth(X: np.ndarray) -> np.ndarray:
    """Linear model plus smooth nonlinear terms (a lift-curve bend in CZ and Cm, a beta^2 drag term in CX)."""
    Y = linear_truth(X)
    alpha, beta = X[:, 0], X[:, 1]
    Y[:, 0] += -2.0 * beta**2
    Y[:, 2] += 30.0 * np.maximum(alpha - np.radians(5.0), 0.0) ** 2
    Y[:, 4] += -0.3 * np.sin(alpha * 25.0)
    return Y


def error_pct(est: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """Per-output ``100 * RMS(est - ref) / RMS(ref)``, shape ``(6,)``."""
    return 100 * np.sqrt(np.mean((est - ref) ** 2, 0)) / np.sqrt(np.mean(ref ** 2, 0))


def envelope_expansion_case(seed: int = 41):
    """Issue 10's envelope-expansion case: ``(X, Yt, Y, flown, test, train_new)``: 2,000 rows, the
    envelope flown is alpha below its 70th percentile, the new region above it (every 4th row held
    out for scoring, the rest streamed in); ``Y`` = truth plus 2 % noise."""
    X = flight_regressors(2000, seed=seed)
    Yt = nonlinear_truth(X)
    Y = Yt + 0.02 * Yt.std(0) * np.random.default_rng(seed + 1).standard_normal(Yt.shape)
    flown = X[:, 0] < np.quantile(X[:, 0], 0.7)
    new = np.flatnonzero(~flown)
    test = new[::4]
    return X, Yt, Y, flown, test, np.setdiff1d(new, test)


def exact_gp_data():
    """The small data set of the tests of the sparse global layer against the exact dense GP (test_kernels_exact,
    test_heterotopic): 25 rows of two inputs uniform on [-2, 2], three correlated outputs of one smooth function plus
    0.1 Gaussian noise, and 7 query rows uniform on [-2.5, 2.5] (seed 3).

    Returns:
        ``(X, Y, Xq)``: (25, 2), (25, 3), (7, 2).
    """
    rng = np.random.default_rng(3)
    X = rng.uniform(-2, 2, (25, 2))
    f = np.sin(2 * X[:, 0]) + 0.5 * X[:, 1]
    Y = np.column_stack([f, 0.7 * f + 0.2 * X[:, 0], -0.3 * f + np.cos(X[:, 1])]) + 0.1 * rng.standard_normal((25, 3))
    return X, Y, rng.uniform(-2.5, 2.5, (7, 2))
