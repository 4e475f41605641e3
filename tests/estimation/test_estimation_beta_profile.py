"""CY_beta by the gust model's likelihood (estimation/airangles.py, ``BETA_PROFILE``; twenty-fifth session, i8-beta).

A synthetic sideslip record with a known ``CY_beta``: the aircraft's heading is a lightly damped directional oscillator
(0.2 Hz, damping 0.2) forced by the rudder's doublets and by the sideslip a first-order Gauss-Markov lateral gust adds
(Etkin, *Dynamics of Atmospheric Flight*, 1972, sec. 9.4), so the kinematic (inertial) sideslip is a noisy regressor
whose error, the gust angle, is correlated with it: below the mode the aircraft weathercocks into the gust, above it
the heading answers in anti-phase. As on the JSBSim s23 (least squares above 0.3 Hz 15-18 % steep), least squares on
the kinematic sideslip makes ``CY_beta`` steep; the filter-error estimate does not.
"""

import re

import numpy as np
from gcs_sysid.estimation.airangles import _axis

from synthetic_sideslip import directional_record

DT, T = 0.02, 4500
CY_BETA, CY_DR = -0.55, 0.15


def _record(seed: int):
    """(kinematic sideslip (T,), measured CY (T,), {"delta_r": (T,)}); rad, the rudder's doublets every 10 s."""
    rng, beta_kin, g, _, dr = directional_record(seed, T, DT, 4.0)
    cy = CY_BETA * (beta_kin + g) + CY_DR * dr + 0.0005 * rng.standard_normal(T)
    return beta_kin, cy, {"delta_r": dr}


def test_cy_beta_by_the_gust_likelihood_is_not_steep():
    ls, prof = [], []
    for seed in range(4):
        kin, cy, others = _record(seed)
        use = np.ones(T, bool)
        ls.append(_axis("beta", DT, kin, cy, others, use, 2, -1.0, False, False)[2].coef[1])
        fit = _axis("beta", DT, kin, cy, others, use, 2, -1.0, False, False, profile=True)[2]
        prof.append(fit.coef[1])
        assert "by the gust model's likelihood" in fit.slope_method
    ls, prof = np.array(ls), np.array(prof)
    # least squares reads the gust's sideslip that the heading's answer correlates with the kinematic one: steep
    assert np.mean(ls) / CY_BETA > 1.25
    # the filter-error estimate: within 10 % on average, and nearer than least squares on every record
    assert abs(np.mean(prof) / CY_BETA - 1) < 0.10
    assert np.all(np.abs(prof - CY_BETA) < np.abs(ls - CY_BETA))


def test_the_held_profiled_slope_survives_the_later_passes(monkeypatch):
    # BETA_PROFILE_HOLD (thirty-first session, i8-truereg): the later passes refit on the aided sideslip, built from
    # the side force with the last slope (circular); with the option the first pass's profiled slope is the final one
    import re

    from gcs_sysid.estimation import airangles

    kin, cy, others = _record(1)
    use = np.ones(T, bool)
    monkeypatch.setattr(airangles, "BETA_PROFILE_HOLD", False)
    free = _axis("beta", DT, kin, cy, others, use, 3, -1.0, False, False, profile=True)[2]
    monkeypatch.setattr(airangles, "BETA_PROFILE_HOLD", True)
    held = _axis("beta", DT, kin, cy, others, use, 3, -1.0, False, False, profile=True)[2]
    first = float(re.search(r"likelihood ([-+0-9.]+)", held.slope_method).group(1))
    assert "held in the later passes" in held.slope_method
    assert abs(held.coef[1] - first) < 5e-4      # the note rounds to 3 decimals
    assert "held in the later passes" not in free.slope_method
    # without the option the passes move the slope away from the first pass's (what the option stops)
    first_free = float(re.search(r"likelihood ([-+0-9.]+)", free.slope_method).group(1))
    assert abs(free.coef[1] - first_free) > 2e-3
    # the rudder's slope is still refitted with the sideslip's held, and both fits aid the angle
    assert np.isfinite(held.coef[2]) and held.used and free.used


def test_the_likelihood_ratio_test_keeps_least_squares_where_the_profile_is_not_preferred(monkeypatch):
    # BETA_PROFILE_MIN_LR (thirty-third session, i8-counts33; opt-in): the profiled slope only where the likelihood
    # ratio against least squares' slope reaches the threshold. The same record's statistic, from the objective the
    # profile maximises, decides: above it the profile is taken as without the test, below it least squares' is kept
    from gcs_sysid.estimation import airangles

    kin, cy, others = _record(2)
    use = np.ones(T, bool)
    ls = _axis("beta", DT, kin, cy, others, use, 2, -1.0, False, False)[2]
    free = _axis("beta", DT, kin, cy, others, use, 2, -1.0, False, False, profile=True)[2]
    assert "by the gust model's likelihood" in free.slope_method
    captured = []
    orig = airangles._profile_angle_slope
    monkeypatch.setattr(airangles, "_profile_angle_slope",
                        lambda *a, **k: captured.append((a, k)) or orig(*a, **k))
    _axis("beta", DT, kin, cy, others, use, 2, -1.0, False, False, profile=True)
    a = captured[0][0]
    _, nll = airangles._angle_profile_objective(*a[:10], *a[11:13])
    b_ls = float(a[9][0])
    d = float(re.search(r"likelihood ([-+0-9.]+)", free.slope_method).group(1))
    lr = 2 * (nll(b_ls) - nll(d))
    assert lr > 1.0                               # this record's profile is preferred
    monkeypatch.setattr(airangles, "_profile_angle_slope", orig)
    monkeypatch.setattr(airangles, "BETA_PROFILE_MIN_LR", 0.5 * lr)
    passed = _axis("beta", DT, kin, cy, others, use, 2, -1.0, False, False, profile=True)[2]
    assert passed.coef[1] == free.coef[1] and passed.slope_method == free.slope_method
    monkeypatch.setattr(airangles, "BETA_PROFILE_MIN_LR", 2.0 * lr)
    kept = _axis("beta", DT, kin, cy, others, use, 2, -1.0, False, False, profile=True)[2]
    assert "likelihood" not in kept.slope_method        # least squares' slope, nothing held
    assert kept.coef[1] == ls.coef[1]
