"""Fixtures of the gp tests: one flight-like data set and one model fitted on it (session scope)."""

import numpy as np
import pytest

from gp_data import FAST, flight_regressors, nonlinear_truth


@pytest.fixture(scope="session")
def flight():
    """``(X (600, 10), Y (600, 6) noisy, Y_true)`` with 2 % noise."""
    X = flight_regressors(600, seed=11)
    Yt = nonlinear_truth(X)
    rng = np.random.default_rng(12)
    return X, Yt + 0.02 * Yt.std(0) * rng.standard_normal(Yt.shape), Yt


@pytest.fixture(scope="session")
def fitted(flight):
    """A model fitted on the first 400 rows of :func:`flight` with :data:`FAST`."""
    from gcs_sysid.gp import fit_gp

    X, Y, _ = flight
    return fit_gp(X[:400], Y[:400], FAST)
