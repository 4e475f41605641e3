"""The reference's inadequacy predicted at the angles brought to the reference's level
(``sparse.THRESHOLDS["angle_offset_level"]``, :func:`gcs_sysid.diagnose.sparse._inadequacy_at_reference_level`).

A ridge inadequacy fitted on the reference flight with a weight on ``alpha*delta_a`` and predicted on a test flight
whose measured alpha is offset by ``d`` (the flight-mean vertical wind over the airspeed: the JSBSim ultrastick's
seed 1 reads 5.35 deg below the reference's calibration) moves by ``w d delta_a``: a change of the control's slope
that is no change of the aircraft. Predicted on the corrected library it does not. Fast (synthetic arrays, < 0.1 s).
"""

import numpy as np

from gcs_sysid.diagnose.sparse import THRESHOLDS, _inadequacy_at_reference_level


def _library(alpha, delta_a):
    return ["alpha", "delta_a", "alpha*delta_a"], np.column_stack([alpha, delta_a, alpha * delta_a])


def test_the_inadequacy_at_the_reference_level_does_not_read_an_alpha_offset_as_a_control_slope():
    assert THRESHOLDS["angle_offset_level"] is False          # opt-in (rule 8)
    rng = np.random.default_rng(1)
    T = 2000
    alpha_true = 0.053 + 0.03 * np.sin(np.arange(T) / 90.0)
    delta_a = 0.05 * rng.standard_normal(T)
    rnames, rPhi = _library(alpha_true, delta_a)
    mu, sc = rPhi.mean(axis=0), rPhi.std(axis=0)
    W = np.zeros((3, 6))
    W[2, 1] = 0.5 * sc[2]                                     # CY inadequacy 0.5 alpha*delta_a (standardised)
    ridge = (W, mu, sc, np.ones(6))
    tr = np.arange(1500)
    d = -0.0934                                               # the measured alpha's offset on the test flight, rad
    names_m, Phi_m = _library(alpha_true + d, delta_a)        # the library on the measured angles
    base_meas, _ = _inadequacy_at_reference_level(names_m, Phi_m, rnames, ridge, None, np.ones((T, 6)), tr)
    base_corr, jk = _inadequacy_at_reference_level(rnames, rPhi, rnames, ridge, [W, 2 * W], np.ones((T, 6)), tr)
    slope = lambda b: float(np.linalg.lstsq(np.column_stack([np.ones(T), delta_a]), base_meas[:, 1] - b[:, 1],
                                            rcond=None)[0][1])
    assert abs(slope(base_corr) - 0.5 * d) < 1e-3               # the offset read as a delta_a slope of w d
    assert abs(base_corr[tr].mean(axis=0)).max() < 1e-12          # centred on the training rows
    assert len(jk) == 2 and np.allclose(jk[1], 2 * jk[0])
    off = np.ones((T, 6))
    off[:, 1] = 0.0                                               # a coefficient the inadequacy left out stays out
    assert not _inadequacy_at_reference_level(rnames, rPhi, rnames, ridge, None, off, tr)[0][:, 1].any()
