"""The diagnosis at the air-relative roll rate (gcs_sysid.diagnose.air_roll, run.AIR_ROLL_RATE) on a simulated roll
axis.

One-axis roll dynamics ``Ixx p_dot = qbar S b Cl`` with ``Cl = Cl_beta beta + Cl_p (p - p_g) b/(2V) + Cl_delta_a
delta_a (+ k alpha beta)``, ``p_g`` MIL-F-8785C's first-order rolling gust, and a roll loop ``delta_a = cmd - K p``
that flies against any moment, so ``p`` and ``delta_a`` answer a hidden ``k alpha beta`` (the s23's
``Cl:alpha*beta`` flights). Fitted at the gyro's ``p_hat`` the model's ``Cl_p`` and ``Cl_delta_a`` are attenuated
and the residual reads the hidden term low (0.69-0.79 of it on seeds 1-5); fitted at the reference flight's own
``p_hat - p_hat_g`` it reads 0.85-0.99 of it. The flight under test keeps the gyro's rate by default (``"reference"``):
its own gust estimate takes up the hidden moment (``"both"``), which the test measures too.
"""

from types import SimpleNamespace

import numpy as np
import pytest
from scipy.signal import lfilter

from gcs_sysid.aero.rollgust import dryden_roll_tau
from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS, CoefficientTable
from gcs_sysid.diagnose import run
from gcs_sysid.diagnose.air_roll import air_roll_table
from gcs_sysid.estimation.gustrates import dryden_rate_sigma, gust_intensity

DT, SUB = 0.02, 5                  # grid step, s; integration substeps per grid step
V, B, S, IXX, QBAR = 40.0, 10.0, 16.0, 2000.0, 1000.0
CLP, CLB, CLDA = -0.5, -0.1, -0.25
SIG_PG, K_LOOP = 0.08, 0.1         # rad/s, the rolling gust's SD; rad of aileron per rad/s of roll rate
COL = REGRESSORS.index
JL = COEFFICIENTS.index("Cl")


def _flight(seed, k_ab=0.0, n=4000):
    """A table and states of the roll axis with a hidden ``k_ab alpha beta`` in Cl; ``(table, states, g_true)``."""
    rng = np.random.default_rng(seed)
    h, kq = B / (2 * V), QBAR * S * B / IXX
    m, d = n * SUB, DT / SUB
    a = np.exp(-d / dryden_roll_tau(B, V))
    pg = lfilter([np.sqrt(1 - a * a) * SIG_PG], [1, -a], rng.normal(size=m))
    cmd = np.repeat(rng.normal(0, 0.05, m // (40 * SUB) + 1), 40 * SUB)[:m]
    beta = np.repeat(rng.normal(0, 0.06, m // (150 * SUB) + 1), 150 * SUB)[:m]       # steady sideslips
    beta = lfilter([1 - np.exp(-d / 0.5)], [1, -np.exp(-d / 0.5)], beta)
    alpha = 0.08 + 0.04 * np.sin(2 * np.pi * np.arange(m) * d / 37.0)                 # a slow speed sweep
    p, da = np.zeros(m), np.zeros(m)
    for i in range(m):
        da[i] = cmd[i] - K_LOOP * p[i]
        pdot = kq * (CLB * beta[i] + CLP * h * (p[i] - pg[i]) + CLDA * da[i] + k_ab * alpha[i] * beta[i])
        if i + 1 < m:
            p[i + 1] = p[i] + d * pdot
    j = np.arange(0, m, SUB)
    X = np.zeros((n, len(REGRESSORS)))
    X[:, COL("alpha")], X[:, COL("beta")], X[:, COL("p_hat")] = alpha[j], beta[j], p[j] * h
    X[:, COL("delta_a")], X[:, COL("V")] = da[j], V
    Y = np.zeros((n, len(COEFFICIENTS)))
    Y[:, JL] = IXX * np.gradient(p[j], DT) / (QBAR * S * B)
    table = CoefficientTable(np.arange(n) * DT, X, Y, np.ones(n, bool), np.full(n, QBAR))
    # a wind whose Dryden rolling gust is the simulated one (the fit's check against MIL-F-8785C)
    w = np.c_[np.cumsum(rng.normal(size=(n, 2)), 0), np.zeros(n)]
    w *= np.std(pg[j] * h) / (dryden_rate_sigma(gust_intensity(DT, w, np.full(n, V)), B)[0] * h)
    states = SimpleNamespace(data={"p": p[j], "wn": w[:, 0], "we": w[:, 1], "wd": w[:, 2]})
    return table, states, pg[j] * h


def _cl_fit(X, y, cols=("beta", "p_hat", "delta_a")):
    A = np.c_[np.ones(len(X)), X[:, [COL(c) for c in cols]]]
    return np.linalg.lstsq(A, y, rcond=None)[0]


def _term_read(theta, X, y, term):
    """The hidden term read from the residual against the model ``theta`` (least squares with a constant)."""
    r = y - np.c_[np.ones(len(X)), X[:, [COL(c) for c in ("beta", "p_hat", "delta_a")]]] @ theta
    return np.linalg.lstsq(np.c_[np.ones(len(X)), term], r, rcond=None)[0][1]


def test_reference_at_its_air_rate_reads_a_hidden_rolling_moment_that_the_flights_own_gust_would_take():
    air = SimpleNamespace(Ixx=IXX, S=S, b=B)
    ref, ref_st, g_ref = _flight(1)
    ref_air, info = air_roll_table(ref, ref_st, air)
    assert info["applied"]
    g_hat = ref.X[:, COL("p_hat")] - ref_air.X[:, COL("p_hat")]
    assert np.corrcoef(g_hat, g_ref)[0, 1] > 0.85           # the estimated gust taken out of p_hat
    assert np.array_equal(np.delete(ref_air.X, COL("p_hat"), 1), np.delete(ref.X, COL("p_hat"), 1))
    th_gyro, th_air = _cl_fit(ref.X, ref.Y[:, JL]), _cl_fit(ref_air.X, ref_air.Y[:, JL])
    assert th_gyro[2] > CLP + 0.1 and abs(th_air[2] - CLP) < abs(th_gyro[2] - CLP) / 2     # Cl_p -0.37, -0.45
    k = 3.0
    fl, fl_st, _ = _flight(2, k_ab=k)
    term = fl.X[:, COL("alpha")] * fl.X[:, COL("beta")]
    assert not run.air_roll_for("flight", "reference") and run.air_roll_for("reference", "reference")
    read_gyro = _term_read(th_gyro, fl.X, fl.Y[:, JL], term)
    read_air = _term_read(th_air, fl.X, fl.Y[:, JL], term)       # "reference": the flight at the gyro's rate
    assert abs(read_air - k) < 0.2 * k < abs(read_gyro - k)      # 2.60 and 2.12 of 3
    # "both": the flight's own gust estimate takes up a share of the hidden moment (circular)
    fl_air, _ = air_roll_table(fl, fl_st, air)
    read_both = _term_read(th_air, fl_air.X, fl_air.Y[:, JL], term)
    assert read_both < read_air - 0.03 * k                       # 2.43


def test_air_roll_mode_checked_and_the_reference_cl_target_by_default():
    """The default since the fiftieth session: the fit's and the reference's Cl target at the air rate, the flight
    under test as measured; ``"off"`` moves nothing."""
    assert run.AIR_ROLL_RATE == "reference:Cl"
    assert run.air_roll_for("fit") and run.air_roll_for("reference") and not run.air_roll_for("flight")
    assert not any(run.air_roll_for(r, "off") for r in ("fit", "reference", "flight"))
    assert run.air_roll_for("flight", "both")
    assert run.air_roll_for("fit", "fit") and not run.air_roll_for("reference", "fit")
    assert run.air_roll_for("fit", "reference") and not run.air_roll_for("flight", "reference")
    with pytest.raises(ValueError, match="mode"):
        run.air_roll_for("reference", "gyro")
    with pytest.raises(ValueError, match="role"):
        run.air_roll_for("test", "both")
    # what load_measurements moves, per role: the kind, not the module's mode read again at load time
    assert [run.air_roll_kind(r) for r in ("fit", "reference", "flight")] == ["Cl", "Cl", "off"]
    assert [run.air_roll_kind(r, "reference") for r in ("fit", "reference", "flight")] == ["p_hat", "p_hat", "off"]
    assert run.air_roll_kind("flight", "both") == "p_hat" and run.air_roll_kind("reference", "off") == "off"


@pytest.mark.parametrize("kind", [True, False, "on", "reference:Cl"])
def test_load_measurements_refuses_an_air_roll_that_is_not_a_kind(kind):
    """``load_measurements(air_roll=)`` takes one of ``AIR_ROLL_KINDS``; a bool (which meant "whatever the module's
    mode says" before the fifty-first session) or a mode's name is refused before the log is read."""
    with pytest.raises(ValueError, match="air_roll must be one of"):
        run.load_measurements("no-such.tlog", "no-such.toml", air_roll=kind)


def test_reference_cl_target_moves_only_cl_and_reads_the_hidden_moment():
    """``"reference:Cl"``: the reference's Cl target at its air rate, every regressor (``p_hat`` too) the gyro's.
    Fitted on it, the model's ``Cl_p`` is not attenuated and the flight under test (at the gyro's rate) reads the
    hidden ``3 alpha beta`` as the ``"reference"`` mode does."""
    from gcs_sysid.diagnose.air_roll import air_roll_cl_table

    air = SimpleNamespace(Ixx=IXX, S=S, b=B)
    ref, ref_st, _ = _flight(1)
    ref_cl, info = air_roll_cl_table(ref, ref_st, air)
    assert info["applied"] and np.isfinite(info["Cl_p"])
    assert np.array_equal(ref_cl.X, ref.X)                                   # no regressor moves
    moved = np.flatnonzero(np.any(ref_cl.Y != ref.Y, axis=0))
    assert list(moved) == [JL]                                               # only Cl's target
    th_gyro, th_cl = _cl_fit(ref.X, ref.Y[:, JL]), _cl_fit(ref_cl.X, ref_cl.Y[:, JL])
    assert abs(th_cl[2] - CLP) < abs(th_gyro[2] - CLP) / 2                   # Cl_p no longer attenuated
    k = 3.0
    fl, _, _ = _flight(2, k_ab=k)
    term = fl.X[:, COL("alpha")] * fl.X[:, COL("beta")]
    read_gyro = _term_read(th_gyro, fl.X, fl.Y[:, JL], term)
    read_cl = _term_read(th_cl, fl.X, fl.Y[:, JL], term)
    assert abs(read_cl - k) < 0.2 * k < abs(read_gyro - k)
    assert run.air_roll_for("fit", "reference:Cl") and run.air_roll_for("reference", "reference:Cl")
    assert not run.air_roll_for("flight", "reference:Cl")
    # the moved target is told apart by the table, so the differential fits no air angle's scale on it
    from gcs_sysid.diagnose.air_roll import moved_targets

    assert moved_targets(ref_cl) == {"Cl"} and moved_targets(ref) == frozenset() and moved_targets(fl) == frozenset()
    assert ref_cl.corrected_targets == ("Cl",) and ref_cl.select(ref_cl.valid).corrected_targets == ("Cl",)
    # the field, not the note, says it: a note alone moves nothing
    from dataclasses import replace

    from gcs_sysid.diagnose.air_roll import unlike_targets

    assert moved_targets(replace(ref, notes=list(ref_cl.notes))) == frozenset()
    refs = [SimpleNamespace(table=ref_cl), SimpleNamespace(table=ref)]
    assert unlike_targets(fl, refs) == ("Cl",) and unlike_targets(ref_cl, refs[:1]) == ()
    assert unlike_targets(fl, refs[1:]) == ()
