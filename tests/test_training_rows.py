"""The replay's GP training rows keep rows that miss some coefficients, and say what is missing."""

import numpy as np

from gcs_sysid.pipeline import training_rows


def test_rows_with_missing_moments_are_kept_and_named():
    X = np.arange(12.0).reshape(6, 2)
    Y = np.ones((6, 3))
    Y[1, 2] = np.nan                 # a moment rejected
    Y[2, :] = np.nan                 # nothing measured: dropped
    X[3, 0] = np.nan                 # a regressor missing: dropped
    Xk, Yk, note = training_rows(X, Y, ["CX", "CZ", "Cm"])
    assert len(Xk) == 4 and np.isnan(Yk[1, 2]) and np.isfinite(Xk).all()
    assert "Cm missing on 1 of 4" in note and "CX" not in note


def test_complete_rows_give_no_note():
    X, Y = np.zeros((3, 2)), np.ones((3, 2))
    assert training_rows(X, Y, ["CX", "CY"])[2] == ""


def test_fit_refuses_an_output_with_almost_no_values():
    import pytest

    from gcs_sysid.errors import DataError
    from gcs_sysid.gp import fit_gp

    X = np.random.default_rng(0).normal(size=(20, 2))
    Y = np.column_stack([X[:, 0], X[:, 1]])
    Y[2:, 1] = np.nan
    with pytest.raises(DataError, match="y1: fewer than 3 finite values"):
        fit_gp(X, Y)
