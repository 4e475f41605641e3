"""The project's real path (read_log -> estimate_states -> compute_coefficients) on a JSBSim flight,
scored against JSBSim's exact truth.

Thresholds FROZEN on 2026-11-21 from the first measurement on the final harness flight (c172x,
40 s, "calm" turbulence (the harness's light until the fifteenth session), seed 1, AOA_SSA = ArduPilot's AHRS estimate,
0.04 s servos, last 20 % a three-axis multisine): measured CX 1.7, CY 9.1, CZ 0.9, Cl 15.1, Cm 14.0, Cn 9.2 %; alpha
0.24 deg, beta 0.21 deg RMS error. The harness changed twice before that, for realism, not to pass (history
in docs/jsbsim.md): first schedule, ideal servos: CX 1.8, CY 5.6, CZ 0.9, Cl 20.3, Cm 19.0,
Cn 13.7 %; final multisine, ideal servos: CX 1.7, CY 9.3, CZ 0.9, Cl 17.7, Cm 17.4, Cn 11.9 %.
Thresholds are those values with a margin for platform
differences; they guard against regressions, they are NOT the issue's acceptance targets (forces
3 %, moments 8 %), which today's estimator misses on the moments (docs/benchmarks.md).
Do not retune them to pass: change them only with a new measurement recorded in docs/jsbsim.md.
"""

import numpy as np
import pytest

from benchmarks.jsbsim_harness import FlightConfig, load_truth, make_flight
from gcs_sysid.aero import compute_coefficients
from gcs_sysid.airframe import load_airframe
from gcs_sysid.estimation import estimate_states
from gcs_sysid.telemetry import read_log

from benchmarks.jsbsim_harness.scoring import score_table

#: Frozen 2026-11-21 (see the module docstring): % for coefficients, deg RMS for the air angles.
THRESHOLDS = {"CX": 3.0, "CY": 13.0, "CZ": 2.0, "Cl": 20.0, "Cm": 19.0, "Cn": 13.0,
              "alpha_deg": 0.35, "beta_deg": 0.30}


def _measure(files):
    af = load_airframe(files.airframe)
    states = estimate_states(read_log(files.tlog), af)
    return compute_coefficients(states, af)


@pytest.fixture(scope="module")
def measured(fast_flight):
    return _measure(fast_flight), load_truth(fast_flight.truth)


def test_measured_coefficients_and_air_data_against_truth(measured):
    table, truth = measured
    assert table.valid.mean() > 0.9
    s = score_table(table, truth)
    bad = {k: round(v, 2) for k, v in s.items() if not v <= THRESHOLDS[k]}
    assert not bad, f"above the frozen thresholds {THRESHOLDS}: {bad} (all: {s})"


def test_the_score_fails_against_wrong_truth(measured):
    """The same comparison against sign-flipped truth exceeds every threshold: the test can fail."""
    table, truth = measured
    s = score_table(table, truth, sign=-1.0)
    assert all(s[k] > THRESHOLDS[k] for k in THRESHOLDS), s


#: Slow cases (120 s, seed 2), thresholds FROZEN on 2026-11-21 from their first measurement on the
#: final harness (measured: sgs light CX 5.4, CY 3.4, CZ 0.5, Cl 16.0, Cm 10.6, Cn 7.8 %, alpha /
#: beta 0.41 / 0.53 deg; c172x moderate CX 3.6, CY 11.5, CZ 7.0, Cl 19.9, Cm 26.7, Cn 11.4 %,
#: 2.37 / 2.97 deg; pa28 (held out) light with vanes CX 1.1, CY 5.8, CZ 0.8, Cl 16.9, Cm 17.3,
#: Cn 7.9 %, 0.10 / 0.10 deg), with a margin of about a third. The keys name the harness levels of the
#: fifteenth session that fly those same flights: the old light (severity 1) is "calm", the old moderate
#: (severity 3, 30 kt) is "light" (severity 3, 15 kt; the same above 2000 ft, and these fly at 6000 ft).
#: In MIL-F-8785C light turbulence the sgs measured CX 7.55, CY 6.03, Cm 14.8, Cn 13.05 %, alpha 2.67 deg
#: and the pa28 CY 10.25, Cn 14.28 % (turb15).
SLOW_CASES = {
    ("sgs", "calm", "ahrs"): {"CX": 7.5, "CY": 5.0, "CZ": 1.0, "Cl": 21.0, "Cm": 14.0, "Cn": 10.5,
                              "alpha_deg": 0.55, "beta_deg": 0.7},
    ("c172x", "light", "ahrs"): {"CX": 5.0, "CY": 15.0, "CZ": 9.5, "Cl": 26.0, "Cm": 35.0, "Cn": 15.0,
                                 "alpha_deg": 3.2, "beta_deg": 4.0},
    ("pa28", "calm", "vane"): {"CX": 1.5, "CY": 8.0, "CZ": 1.2, "Cl": 22.0, "Cm": 23.0, "Cn": 10.5,
                               "alpha_deg": 0.15, "beta_deg": 0.15},
}


@pytest.mark.slow
@pytest.mark.parametrize("case", list(SLOW_CASES), ids=lambda c: "-".join(c))
def test_longer_flights_are_measured(tmp_path, case):
    """Two minutes on the glider (calm), the c172x at severity-3 turbulence ("light"; the old moderate), and
    on the pa28 (calm) with vanes
    (airframe ``[air_data] angles = "vane"``) against their frozen thresholds; the full figures are
    in docs/benchmarks.md (benchmarks/eval_jsbsim.py)."""
    aircraft, turbulence, aoa = case
    files = make_flight(FlightConfig(aircraft, duration_s=120.0, turbulence=turbulence, seed=2), tmp_path, aoa=aoa)
    s = score_table(_measure(files), load_truth(files.truth))
    limits = SLOW_CASES[case]
    bad = {k: round(v, 2) for k, v in s.items() if not v <= limits[k]}
    assert not bad, f"above the frozen thresholds {limits}: {bad}"


#: Side force against the accelerometer's noise floor, FROZEN 2026-11-22 (i8-cy) from the fast flight's
#: first measurement: the measured CY's error is 0.59 of the stationary Wiener floor of the one
#: accelerometer channel (``scoring.wiener_floor``), its regression on the true side acceleration a
#: scale of +0.27 % and a lag of 0.3 ms; the raw accelerometer is 3.3 floors. On eval_jsbsim's 90-s
#: flights (held-out segment, light turbulence) the measured CY sits at 0.73-1.19 floors
#: (docs/benchmarks.md, "Tenth session, i8-cy").
SIDE_FORCE_LIMITS = {"floors": 0.8, "scale": 0.02, "lag_s": 0.01}


def _side_force_check(table, truth, log, Y=None) -> dict[str, float]:
    """Error of the measured CY in m/s^2 of side acceleration: in floors, and its scale and lag."""
    from benchmarks.jsbsim_harness.scoring import white_noise_psd, wiener_floor

    F, c = truth.fields, truth.meta["constants"]
    Y = table.Y if Y is None else Y
    _, Yt = truth.at(table.t)
    m = table.valid & np.isfinite(Yt).all(1) & np.isfinite(Y[:, 1])
    k = np.interp(table.t, truth.t, F["qbar"]) * c["S"] / c["mass"]
    a = np.interp(table.t, truth.t, F["Fy_aero"]) / c["mass"]
    err = (Y[:, 1] * k - a)[m]
    imu = log["imu"]
    sel = (truth.t >= table.t[m][0]) & (truth.t <= table.t[m][-1])
    floor = wiener_floor(F["Fy_aero"][sel] / c["mass"], white_noise_psd(imu["ay"], float(np.median(np.diff(imu.t)))),
                         float(np.median(np.diff(truth.t))))
    A = np.stack([np.ones(m.sum()), a[m], np.gradient(a, table.t)[m]], 1)
    coef = np.linalg.lstsq(A, err, rcond=None)[0]
    return {"floors": float(np.sqrt(np.mean(err**2)) / floor), "scale": float(coef[1]), "lag_s": float(-coef[2])}


def test_side_force_error_is_accelerometer_noise(measured, fast_flight):
    """The measured CY's error is the accelerometer's noise left by the smoother, below one channel's
    Wiener floor, with no scale (mass, qbar, a thrust line's side component) or lag in it; a raw
    accelerometer and a 3 % scale error both fail the same limits."""
    table, truth = measured
    log = read_log(fast_flight.tlog)
    s = _side_force_check(table, truth, log)
    assert s["floors"] <= SIDE_FORCE_LIMITS["floors"] and abs(s["scale"]) <= SIDE_FORCE_LIMITS["scale"] \
        and abs(s["lag_s"]) <= SIDE_FORCE_LIMITS["lag_s"], s
    raw = table.Y.copy()
    c = truth.meta["constants"]
    k = np.interp(table.t, truth.t, truth.fields["qbar"]) * c["S"] / c["mass"]
    raw[:, 1] = np.interp(table.t, log["imu"].t, log["imu"]["ay"]) / k
    assert _side_force_check(table, truth, log, raw)["floors"] > SIDE_FORCE_LIMITS["floors"]
    scaled = table.Y * 1.03
    assert abs(_side_force_check(table, truth, log, scaled)["scale"]) > SIDE_FORCE_LIMITS["scale"]


def test_wiener_floor_of_white_signal_in_white_noise():
    """Flat spectra: the floor is ``sqrt(S N / (S + N) * fs / 2)``, and the noise level reads back."""
    from benchmarks.jsbsim_harness.scoring import white_noise_psd, wiener_floor

    rng = np.random.default_rng(0)
    dt, s_sig, s_noise = 0.02, 0.2, 0.05
    x = rng.normal(0.0, s_sig, 20000)
    N = white_noise_psd(rng.normal(0.0, s_noise, 20000), dt)
    assert abs(N / (2 * s_noise**2 * dt) - 1) < 0.1
    S = 2 * s_sig**2 * dt
    expect = np.sqrt(S * N / (S + N) * 0.5 / dt)
    assert abs(wiener_floor(x, N, dt) / expect - 1) < 0.05
