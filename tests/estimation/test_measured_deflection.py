"""Measured deflection beats commanded PWM: the simulation flies with lagging, delayed actuators; the tlog
has the commanded PWM (as an autopilot logs it), a CAN log written by python-can's logger has DroneCAN
actuator Status frames of the true surface positions on the ground station's clock. With the airframe's
[[can_actuator]] map the regressors, the coefficients and a least-squares model fitted to them are closer
to the simulation's truth than from PWM; a servo without a measurement falls back to PWM with a note."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

can = pytest.importorskip("can")
dronecan = pytest.importorskip("dronecan")

from gcs_sysid.aero import compute_coefficients  # noqa: E402
from gcs_sysid.airframe import CanActuator, load_airframe  # noqa: E402
from gcs_sysid.estimation import estimate_states  # noqa: E402
from gcs_sysid.sim import load_model, plan_from_dict, simulate  # noqa: E402
from gcs_sysid.sim.tlog import LOG_EPOCH_S, write_tlog  # noqa: E402
from gcs_sysid.telemetry import read_log  # noqa: E402
from gcs_sysid.telemetry.can import frames_of  # noqa: E402
from gcs_sysid.telemetry.can_merge import merge_can_log  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
CONTROLS = ("delta_e", "delta_a", "delta_r")


def _plan():
    """20 s at 50 Hz (the shape of tests/sim's short plan, so the compiled loop is shared), servos lag
    0.12 s behind a 0.04 s delay."""
    doc = {
        "name": "lagging-servos", "duration_s": 20.0, "rate_hz": 50.0, "internal_rate_hz": 200.0,
        "start_time_s": 30.0, "seed": 5,
        "initial": {"airspeed_mps": 20.0, "altitude_m": 150.0, "heading_deg": 30.0},
        "home": {"alt_m": 50.0},
        "maneuver": [
            {"kind": "3211", "control": "delta_e", "start_s": 32.0, "pulse_s": 0.3, "amplitude_deg": 3.0,
             "mode": "open"},
            {"kind": "doublet", "control": "delta_a", "start_s": 38.0, "pulse_s": 0.4, "amplitude_deg": 5.0},
            {"kind": "doublet", "control": "delta_r", "start_s": 42.0, "pulse_s": 0.5, "amplitude_deg": 5.0},
            {"kind": "multisine", "controls": ["delta_e", "delta_a"], "start_s": 44.0, "duration_s": 5.0,
             "band_hz": [0.4, 2.0], "amplitude_deg": [2.0, 3.0]},
        ],
        "wind": {"speed_mps": 3.0, "from_deg": 200.0},
        "turbulence": {"w20_mps": 2.0},
        "effects": {"lag_s": {c: 0.12 for c in CONTROLS}, "delay_s": {c: 0.04 for c in CONTROLS}},
    }
    return plan_from_dict(doc, "lagging-servos.toml")


@pytest.fixture(scope="module")
def flown(tmp_path_factory):
    """(sim, tlog path, CAN log path, airframe with the actuator map)."""
    tmp = tmp_path_factory.mktemp("measured")
    af = load_airframe(ROOT / "data" / "airframes" / "sim-trainer.toml")
    sim = simulate(af, load_model(ROOT / "data" / "models" / "sim-trainer.toml"), _plan())
    tlog = tmp / "lag.tlog"
    write_tlog(sim, tlog)
    # each servo's true surface deflection (the simulation's truth holds the mixed controls)
    defl = np.linalg.pinv(af.mixing) @ np.stack([sim.truth[c] for c in CONTROLS])
    acts = (CanActuator(10, "aileron", -1.0, 2.0, 0.05), CanActuator(11, "elevator"), CanActuator(12, "rudder"))
    Status = dronecan.uavcan.equipment.actuator.Status
    gap = (sim.t > 40.0) & (sim.t < 41.0)                    # the elevator's reports stop for a second
    with can.Logger(str(tmp / "servos.blf")) as log:
        for k, tv in enumerate(sim.t):
            for i, a in enumerate(acts):
                if a.servo == "elevator" and gap[k]:
                    continue
                pos = defl[i, k] / (a.sign * a.scale) + a.zero     # what the servo reports
                for m in frames_of([Status(actuator_id=a.actuator_id, position=float(pos))]):
                    m.timestamp = LOG_EPOCH_S + float(tv) + 0.003   # ground station's clock, 3 ms CAN delay
                    log.on_message_received(m)
    return sim, tlog, tmp / "servos.blf", replace(af, can_actuators=acts)


def _evaluate(sim, states, airframe):
    table = compute_coefficients(states, airframe)
    idx = np.clip(np.round((table.t - sim.t[0]) * sim.rate_hz).astype(int), 0, len(sim.t) - 1)
    reg_err = {c: float(np.degrees(np.sqrt(np.nanmean((table.X[:, 5 + j] - sim.truth[c][idx]) ** 2))))
               for j, c in enumerate(CONTROLS)}
    m = table.valid & np.isfinite(table.X).all(1) & np.isfinite(table.Y).all(1)
    W, *_ = np.linalg.lstsq(np.c_[np.ones(m.sum()), table.X[m]], table.Y[m], rcond=None)
    pred = np.c_[np.ones(len(sim.X)), sim.X] @ W                 # the fitted linear model at the true regressors
    model_err = 100 * np.sqrt(np.mean((pred - sim.Y) ** 2, 0)) / np.sqrt(np.mean(sim.Y ** 2, 0))
    return reg_err, model_err, W


def test_measured_deflection_beats_pwm(flown):
    sim, tlog, can_log, af_can = flown
    flight = read_log(tlog)
    merged = merge_can_log(flight, tlog, can_log)
    pwm_states = estimate_states(flight, replace(af_can, can_actuators=()))
    can_states = estimate_states(merged, af_can)
    assert pwm_states.sources["delta_e"].startswith("servo PWM")
    assert "DroneCAN" in can_states.sources["delta_e"] and "elevator mixed" in can_states.sources["delta_e"]
    # measured surfaces move continuously: not step inputs of the rate smoother (PWM commands are)
    assert "jumps at steps of delta_e" in pwm_states.sources["p"]
    assert "jumps at steps of delta_t)" in can_states.sources["p"]     # the throttle stays a PWM step
    assert any(n.startswith("elevator: measured position (DroneCAN actuator 11") and "PWM elsewhere" in n
               for n in can_states.notes)
    reg_pwm, model_pwm, W_pwm = _evaluate(sim, pwm_states, af_can)
    reg_can, model_can, W_can = _evaluate(sim, can_states, af_can)
    # measured: the regressors are the surfaces (float16 and the 1 s gap aside); PWM: off by the lag
    for c in CONTROLS:
        assert reg_can[c] < 0.25 * reg_pwm[c], (c, reg_can, reg_pwm)
    assert reg_pwm["delta_e"] > 0.5                                      # deg: the lag matters here
    # control derivatives (truth: Cm_delta_e -0.9, Cl_delta_a -0.25): the lagged PWM shrinks them
    for coef, reg, true in ((4, 5, -0.9), (3, 6, -0.25)):
        assert abs(W_can[1 + reg, coef] - true) < abs(W_pwm[1 + reg, coef] - true)
    # the moment model evaluated at the true regressors against the true coefficients
    assert model_can[3:].mean() < 0.6 * model_pwm[3:].mean(), (model_can, model_pwm)


def test_servo_without_its_actuator_falls_back_to_pwm(flown):
    sim, tlog, can_log, af_can = flown
    acts = (af_can.can_actuators[1], CanActuator(99, "rudder"))
    states = estimate_states(merge_can_log(read_log(tlog), tlog, can_log), replace(af_can, can_actuators=acts))
    assert "DroneCAN" in states.sources["delta_e"]
    assert states.sources["delta_r"].startswith("servo PWM") and states.sources["delta_a"].startswith("servo PWM")
    assert any("no DroneCAN actuator 99 in the data; commanded PWM used" in n for n in states.notes)
    assert any("actuator10, actuator12 in the data but not in the airframe's [[can_actuator]] map" in n
               for n in states.notes)


def test_live_learner_merges_the_can_log_per_window(flown):
    """The listener's learner (replayed from its raw log and CAN log) takes the measured surfaces too."""
    from gcs_sysid.live.learner import LearnOptions, learn_from_tlog

    sim, tlog, can_log, af_can = flown
    opts = LearnOptions(window_s=8.0, step_s=4.0, lag_s=1.0, min_rows=10 ** 9)   # no GP: decode + smooth only
    with_can = learn_from_tlog(tlog, af_can, opts, can_log=can_log)
    assert with_can.steps >= 4
    assert all("DroneCAN" in with_can.control_sources[c] for c in CONTROLS), with_can.control_sources
    without = learn_from_tlog(tlog, af_can, opts)
    assert without.control_sources["delta_e"].startswith("servo PWM")
    # the kept rows' delta_e against the truth: measured beats PWM
    def err(learner):
        idx = np.clip(np.round((learner.t - sim.t[0]) * sim.rate_hz).astype(int), 0, len(sim.t) - 1)
        return np.sqrt(np.mean((learner.X[:, 5] - sim.truth["delta_e"][idx]) ** 2))
    assert err(with_can) < 0.25 * err(without)


def _cli(*args):
    import subprocess
    import sys

    return subprocess.run([sys.executable, "-m", "gcs_sysid.cli", *map(str, args)], capture_output=True, text=True,
                          timeout=600)


def _airframe_file(af, path):
    import tomli_w

    from gcs_sysid.airframe import airframe_to_dict

    path.write_bytes(tomli_w.dumps(airframe_to_dict(af)).encode())
    return path


def test_replay_can_log_errors_are_one_line(flown, tmp_path):
    sim, tlog, can_log, af_can = flown
    af = _airframe_file(af_can, tmp_path / "af.toml")
    p = _cli("replay", tlog, "--airframe", af, "--out", tmp_path / "o", "--quiet", "--can-log", tmp_path / "no.blf")
    assert p.returncode == 2 and p.stderr.strip().count("\n") == 0, p.stderr
    assert "--can-log" in p.stderr and "no such file" in p.stderr and not (tmp_path / "o").exists()


@pytest.mark.slow
def test_replay_with_can_log_end_to_end(flown, tmp_path):
    """``gcs-sysid replay --can-log``: the report's notes say what was merged and where delta_e came from."""
    sim, tlog, can_log, af_can = flown
    af = _airframe_file(af_can, tmp_path / "af.toml")
    p = _cli("replay", tlog, "--airframe", af, "--out", tmp_path / "o", "--quiet", "--can-log", can_log)
    assert p.returncode == 0, p.stderr
    text = (tmp_path / "o" / "summary.md").read_text()
    assert "merged actuator10" in text and "DroneCAN actuator 11" in text


def _angle_errors(sim, states):
    """{angle: (mean, rms)} error of the estimated alpha, beta against the simulation's truth, deg, valid rows."""
    idx = np.clip(np.round((states.t - sim.t[0]) * sim.rate_hz).astype(int), 0, len(sim.t) - 1)
    out = {}
    for k in ("alpha", "beta"):
        e = (states.data[k] - sim.truth[k][idx])[states.valid]
        out[k] = (float(np.degrees(e.mean())), float(np.degrees(np.sqrt(np.mean(e**2)))))
    return out


def test_specific_force_aiding_is_no_worse_than_kinematic(flown):
    """A short (20 s), powered flight in strong low-altitude turbulence with lagging servos: the specific-force
    aiding of alpha and beta must not make them worse than the kinematic angles, with measured deflections
    or with the lagged PWM. (It did: the autopilot's throttle, which follows the gusts, took a spurious CZ
    slope, aided alpha 0.78 deg RMS against 0.55 kinematic; the CY0 ~ 0 prior moved beta's mean by -0.42 deg.)"""
    sim, tlog, can_log, af_can = flown
    flight = read_log(tlog)
    for fl, af in ((merge_can_log(flight, tlog, can_log), af_can), (flight, replace(af_can, can_actuators=()))):
        aided = estimate_states(fl, af)
        kin = estimate_states(fl, af, aid_air_angles=False)
        ea, ek = _angle_errors(sim, aided), _angle_errors(sim, kin)
        for k in ("alpha", "beta"):
            assert ea[k][1] <= ek[k][1], (k, ea, ek)                      # RMS error, deg
            assert abs(ea[k][0]) <= abs(ek[k][0]) + 0.05, (k, ea, ek)      # mean error, deg
        assert any("sideslip mean kept: the throttle varies" in n for n in aided.notes), aided.notes
