"""The alpha level pooled over flights (:mod:`gcs_sysid.diagnose.alpha_level`; opt-in ``run.ALPHA_LEVEL``).

Synthetic flights of one aircraft whose measured alpha carries a flight-common offset (the flight-mean vertical
wind over the airspeed): the model fitted on the reference flight holds that flight's offset in its ``CZ0``. Checks
that the model's re-expression in a moved alpha frame is exact, that the offset of a flight against the reference's
lift curve is found with an honest standard error under coloured turbulence, and that pooling four flights brings
the test flight's level to the mean of theirs. Fast (synthetic arrays, < 0.5 s).
"""

import numpy as np
import pytest

from gcs_sysid.aero.table import COEFFICIENTS, CoefficientTable
from gcs_sysid.diagnose import run
from gcs_sysid.diagnose.alpha_level import align_alpha_levels, level_offset, shift_model_alpha
from gcs_sysid.diagnose.context import evaluate_model
from gcs_sysid.diagnose.differential import Reference
from gcs_sysid.errors import InputError

CZ0, CZA, CZDE = -0.30, -4.5, -0.4
TRUE = {"CX": {"1": -0.03}, "CY": {}, "CZ": {"1": CZ0, "alpha": CZA, "delta_e": CZDE},
        "Cl": {}, "Cm": {"1": 0.02, "alpha": -1.2, "alpha^2": -3.0, "delta_e": -0.9}, "Cn": {}}


def _flight(seed: int, offset: float, T: int = 6000) -> CoefficientTable:
    """A 120-s, 50-Hz flight: a true alpha sweep, turbulence-coloured CZ noise, measured alpha = true + offset."""
    rng = np.random.default_rng(seed)
    t = np.arange(T) / 50.0
    a_true = -0.05 + 0.02 * np.sin(2 * np.pi * t / 40.0) + 0.005 * rng.standard_normal(T)
    de = -0.02 + 0.3 * (a_true + 0.05) + 0.003 * rng.standard_normal(T)
    X = np.zeros((T, 10))
    X[:, 0], X[:, 5], X[:, 9] = a_true, de, 17.0
    Y = evaluate_model(TRUE, X)
    ar = np.zeros(T)                                   # AR(1) with a 1-s time constant: coloured like the gusts
    w = rng.standard_normal(T) * 0.01
    for i in range(1, T):
        ar[i] = 0.98 * ar[i - 1] + w[i]
    Y[:, COEFFICIENTS.index("CZ")] += ar
    Xm = X.copy()
    Xm[:, 0] += offset
    return CoefficientTable(t, Xm, Y, np.ones(T, bool), np.full(T, 180.0))


def _reference_model(e_ref: float) -> dict:
    """The model as fitted on the reference flight: exact aerodynamics in that flight's alpha frame."""
    return shift_model_alpha(TRUE, e_ref)


def test_the_model_moved_to_another_alpha_frame_is_exact():
    rng = np.random.default_rng(3)
    X = rng.standard_normal((50, 10)) * 0.1
    model = {c: {} for c in COEFFICIENTS}
    model["Cm"] = {"1": 0.1, "alpha": -1.0, "alpha^2": -3.0, "alpha*V": 0.01, "alpha*delta_e": 0.7, "q_hat": -9.0}
    model["CZ"] = {"alpha": -4.0, "alpha*beta": 2.0, "V^2": 1e-4}
    L = np.radians(2.5)
    Xs = X.copy()
    Xs[:, 0] -= L
    np.testing.assert_allclose(evaluate_model(shift_model_alpha(model, L), X), evaluate_model(model, Xs), atol=1e-12)
    assert shift_model_alpha(model, L)["Cm"]["alpha^2"] == -3.0          # the curvature is frame-free


def test_a_flights_offset_against_the_reference_lift_curve_is_found_with_its_standard_error():
    e_ref, e_test = np.radians(3.0), np.radians(-1.0)
    model = _reference_model(e_ref)
    errs = []
    for seed in range(4):
        f = _flight(seed, e_test)
        lv = level_offset(f.t, f.X, f.Y, f.valid, model)
        errs.append((lv["offset_rad"] - (e_test - e_ref)) / lv["std_error_rad"])
        assert abs(lv["slope_per_rad"] - CZA) < 1e-6
    # the offset is the difference of the two flights' levels, within its batch-means standard error
    assert np.all(np.abs(errs) < 3.5)
    assert 0.2 < np.sqrt(np.mean(np.square(errs))) < 2.5       # an honest, not a vacuous, standard error


def test_pooling_four_flights_brings_the_level_to_their_mean_and_moves_the_model_with_it():
    levels = np.radians([3.0, -1.5, 0.5, -2.0])                 # reference, then three level flights
    e_test = np.radians(-3.0)
    model = _reference_model(levels[0])
    ref = _flight(10, levels[0])
    lv = [_flight(11 + k, e) for k, e in enumerate(levels[1:])]
    test = _flight(20, e_test)
    m1, tab, _, refs1, info = align_alpha_levels("pooled", model, test, None, [Reference(ref)], lv)
    a_true = test.X[:, 0] - e_test
    # the test flight now reads the flights' mean level (to the offsets' standard errors, ~0.1 deg each; the levels
    # differ by 1.5-3 deg)
    assert abs(np.mean(tab.X[:, 0] - a_true) - levels.mean()) < np.radians(0.4)
    assert abs(np.mean(refs1[0].table.X[:, 0] - (ref.X[:, 0] - levels[0])) - levels.mean()) < np.radians(0.4)
    assert info["level_flights"] == 4 and abs(info["frame_error_deg"] - np.degrees(levels.std(ddof=1)) / 2) < 0.2
    # the moved model fits both flights in the new frame: no CZ level left
    jz = COEFFICIENTS.index("CZ")
    for t in (tab, refs1[0].table):
        assert abs(np.mean(t.Y[:, jz] - evaluate_model(m1, t.X)[:, jz])) < 0.01
    # one reference: the test flight is put in the reference's frame, whose own level stays
    m2, tab2, _, _, info2 = align_alpha_levels("reference", model, test, None, [Reference(ref)])
    assert abs(np.mean(tab2.X[:, 0] - a_true) - levels[0]) < np.radians(0.4) and info2["level_deg"] == 0.0
    assert test.X[0, 0] == pytest.approx(a_true[0] + e_test)            # the inputs are not changed


def test_the_alpha_level_is_opt_in_and_checks_its_mode():
    assert run.ALPHA_LEVEL is None                              # off by default (rule 8)
    with pytest.raises(InputError, match="unknown mode"):
        align_alpha_levels("mean", TRUE, _flight(0, 0.0, T=200), None)


class _States:
    """What :func:`shift_alpha` and ``DiagContext.build`` read of a FlightStates."""

    def __init__(self, t, alpha):
        self.t, self.data = t, {"alpha": np.asarray(alpha, float)}

    def __len__(self):
        return len(self.t)


def test_a_flight_reduced_again_is_brought_into_the_common_frame_before_the_pitot_compares_it():
    # pitot._realigned_alpha: the pitot's exact re-fit re-reduces the log, which comes back in the log's own alpha
    # frame; without a pitot change it must come back as the aligned flight, whatever the frame moved by
    from gcs_sysid.airframe import Airframe
    from gcs_sysid.diagnose.alpha_level import SHIFT_KEY
    from gcs_sysid.diagnose.context import DiagContext
    from gcs_sysid.diagnose.pitot import _realigned_alpha

    levels = np.radians([3.0, -1.5, 0.5, -2.0])
    model = _reference_model(levels[0])
    ref, test = _flight(10, levels[0]), _flight(20, np.radians(-3.0))
    lv = [_flight(11 + k, e) for k, e in enumerate(levels[1:])]
    st = _States(test.t, test.X[:, 0])
    m1, tab, st1, _, info = align_alpha_levels("pooled", model, test, st, [Reference(ref)], lv)
    assert SHIFT_KEY not in st.data and np.allclose(st1.data[SHIFT_KEY], np.radians(info["shift_deg"]))
    ctx = DiagContext.build(tab, Airframe("test", 1.0, 1.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0, ()), m1, st1)
    X = _realigned_alpha(ctx, test, np.array(test.X, float), test.Y)     # the log's frame, re-aligned
    assert np.max(np.abs(X[:, 0] - tab.X[:, 0])) < 1e-9
    assert np.max(np.abs(test.X[:, 0] - tab.X[:, 0])) > np.radians(1.0)  # (without it the frames differ by degrees)


def test_the_searchs_inadequacy_with_alpha_centred_does_not_depend_on_alphas_origin():
    # sparse.THRESHOLDS["inadequacy_alpha_centre"]: the reference's ridge inadequacy predicted on the test flight is
    # the same when both flights' alpha move by one constant; on the raw library it is not (the ridge shrinks
    # standardised columns, and alpha*x + L x is another column than alpha*x)
    from gcs_sysid.airframe import Airframe
    from gcs_sysid.diagnose import sparse
    from gcs_sysid.diagnose.context import DiagContext

    af = Airframe("test", 1.0, 1.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0, ())
    rng = np.random.default_rng(7)

    def ctx(seed, shift):
        T = 1500
        r = np.random.default_rng(seed)
        X = np.cumsum(r.standard_normal((T, 10)), axis=0) * 0.002
        X[:, 0] += 0.06 + shift
        X[:, 9] = 20.0
        tab = CoefficientTable(np.arange(T) / 50.0, X, np.zeros((T, 6)), np.ones(T, bool), np.full(T, 200.0))
        return DiagContext.build(tab, af, {c: {} for c in COEFFICIENTS})

    w, noise = rng.standard_normal(6), 1e-4 * rng.standard_normal((1500, 6))
    preds = {}
    for centre in (False, True):
        for shift in (0.0, np.radians(2.5)):
            rc, tc = ctx(1, shift), ctx(2, shift)
            knots = sparse.alpha_quantile_knots(rc)
            if centre:
                names, rPhi, Phi = sparse._inadequacy_library(tc, rc, knots, sparse._reference_alpha_centre(rc))
            else:
                names, rPhi = sparse._library(rc, knots)
                Phi = sparse._aligned(*sparse._library(tc, knots), names)
            a, x = rc.X[:, 0] - 0.06 - shift, rc.X[:, 6]            # an inadequacy in alpha*delta_a on the reference
            Rr = np.outer(a * x * 40 + x * 0.3, w) + noise
            W, mu, sc, _ = sparse._ridge_cv(rPhi, Rr, 5, 4000, lambdas=(1.0,))
            p = ((Phi - mu) / sc) @ W
            preds[centre, shift] = p - p.mean(axis=0)
    scale = np.max(np.abs(preds[True, 0.0]))
    assert np.max(np.abs(preds[True, 0.0] - preds[True, np.radians(2.5)])) < 1e-6 * scale
    assert np.max(np.abs(preds[False, 0.0] - preds[False, np.radians(2.5)])) > 1e-3 * scale
    assert sparse.THRESHOLDS["inadequacy_alpha_centre"] is False      # opt-in (rule 8)
