"""`listen --can` end to end with a live bus: a `LiveSession` (the CLI's code path, learner on) receives the
lagging-servo flight's MAVLink from the log player over UDP on 127.0.0.1 and, at the same time, DroneCAN
actuator Status frames of the true surface positions on python-can's virtual bus; the learner merges the
measured deflections into its windows.

The CAN "servos" are a thread of this process (the virtual bus is per process) sending each surface's
position when the vehicle is at that time: the vehicle clock is read from the MAVLink packets the session
receives (the least-delayed ``time_boot_ms`` against the arrival stamp), so the bus and the link share the
ground station's clock as on a real aircraft. Samples the bus would have sent before the link was up are
not sent.

Asserted on content: the learned rows' delta_e come from DroneCAN and are the surfaces (not the lagged
PWM); the learned rows equal (to 1e-5) those of the same session replayed from its ``raw.tlog`` + ``can.log``
(``learn_from_tlog(can_log=)``); the elevator derivative of a least-squares fit to the learned rows
(Cm_delta_e) differs from the PWM-only replay's and is the closer to the simulation's truth (-0.9).
"""

from __future__ import annotations

import sys
import threading
import time
import uuid
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

can = pytest.importorskip("can")
dronecan = pytest.importorskip("dronecan")

from gcs_sysid.airframe import CanActuator, load_airframe  # noqa: E402
from gcs_sysid.live.learner import LearnOptions, learn_from_tlog  # noqa: E402
from gcs_sysid.live.session import ListenOptions, LiveSession  # noqa: E402
from gcs_sysid.parallel import default_enabled  # noqa: E402
from gcs_sysid.sim import load_model, simulate  # noqa: E402
from gcs_sysid.sim.tlog import write_tlog  # noqa: E402
from gcs_sysid.telemetry.can import frames_of  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "estimation"))
from live_helpers import AIRFRAME, REPO, free_port, player  # noqa: E402
from test_measured_deflection import CONTROLS, _plan  # noqa: E402   (the lagging-servo flight of the offline test)

#: decode + smooth only (no GP: its cold compilation alone would take a minute); rows are still kept
LEARN = LearnOptions(window_s=8.0, step_s=4.0, lag_s=1.0, min_rows=10 ** 9)
ACTS = (CanActuator(10, "aileron", -1.0, 2.0, 0.05), CanActuator(11, "elevator"), CanActuator(12, "rudder"))
LATE_S = 0.02   # a sample whose send time passed more than this ago is not sent (the bus was not up yet)


class VehicleClock:
    """A consumer of the session's receiver: vehicle time (s) minus arrival time (s), least-delayed packet."""

    def __init__(self):
        self.offset: float | None = None

    def __call__(self, stamp_us, buf, msg):
        boot = getattr(msg, "time_boot_ms", None)
        if boot is not None:
            off = boot * 1e-3 - stamp_us * 1e-6
            self.offset = off if self.offset is None else max(self.offset, off)


def _servos(channel, t, positions, clock, stop, sent):
    # sent: [frames, transfers]
    """Send each sample's actuator Status frames when the vehicle reaches its time ``t[k]`` (s)."""
    bus = can.Bus(interface="virtual", channel=channel)
    Status = dronecan.uavcan.equipment.actuator.Status
    try:
        k = 0
        while k < len(t) and not stop.is_set():
            if clock.offset is None:
                time.sleep(0.002)
                continue
            due = t[k] - clock.offset            # host time of vehicle time t[k]
            wait = due - time.time()
            if wait > 0:
                time.sleep(min(wait, 0.05))
                continue
            if wait > -LATE_S:
                for a, pos in zip(ACTS, positions[:, k]):
                    for m in frames_of([Status(actuator_id=a.actuator_id, position=float(pos))], source_node_id=30):
                        bus.send(m)
                        sent[0] += 1
                    sent[1] += 1
            k += 1
    finally:
        bus.shutdown()


def _cm_delta_e(learner):
    """Cm_delta_e of an ordinary least-squares linear fit to the learned rows (X (N, 10) -> Cm)."""
    X, Y = learner.X, learner.Y
    m = np.isfinite(X).all(1) & np.isfinite(Y[:, 4])
    W, *_ = np.linalg.lstsq(np.c_[np.ones(m.sum()), X[m]], Y[m, 4], rcond=None)
    return float(W[1 + 5])


def _delta_e_error(learner, sim):
    idx = np.clip(np.round((learner.t - sim.t[0]) * sim.rate_hz).astype(int), 0, len(sim.t) - 1)
    return float(np.sqrt(np.mean((learner.X[:, 5] - sim.truth["delta_e"][idx]) ** 2)))


def test_listen_with_a_live_can_bus_learns_the_measured_deflections(tmp_path):
    af = load_airframe(AIRFRAME)
    sim = simulate(af, load_model(REPO / "data" / "models" / "sim-trainer.toml"), _plan())
    tlog = tmp_path / "lag.tlog"
    write_tlog(sim, tlog)
    defl = np.linalg.pinv(af.mixing) @ np.stack([sim.truth[c] for c in CONTROLS])   # each servo's surface
    positions = np.stack([defl[i] / (a.sign * a.scale) + a.zero for i, a in enumerate(ACTS)])  # what it reports
    af_can = replace(af, can_actuators=ACTS)

    channel = f"gcs-sysid-{uuid.uuid4().hex[:8]}"
    port = free_port()
    opts = ListenOptions(connection=f"udpin:127.0.0.1:{port}", learn=LEARN, request=False, component=False,
                         console=False, use_mavsdk=False, can=f"virtual:{channel}", duration_s=90)
    session = LiveSession(af_can, tmp_path / "live", opts)
    clock = VehicleClock()
    session.receiver.consumers.append(clock)
    result, stop, sent = {}, threading.Event(), [0, 0]
    th = threading.Thread(target=lambda: result.update(snap=session.run()))
    servos = threading.Thread(target=_servos, args=(channel, sim.t, positions, clock, stop, sent))
    th.start()
    servos.start()
    proc = player(tlog, f"udpout:127.0.0.1:{port}", "--speed", 1, "--no-answer")
    try:
        out, err = proc.communicate(timeout=60)
        servos.join(10)
        time.sleep(0.5)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
        stop.set()
        servos.join(5)
        session.stop()
        th.join(120)
    assert proc.returncode == 0, err
    snap = result["snap"]

    # the bus: every frame sent is in can.log and decoded (most of the flight's samples were sent live)
    assert sent[1] > 0.8 * 3 * len(sim.t), (sent, len(sim.t))
    assert snap["can"]["frames"] == sent[0]
    assert snap["can"]["transfers"] == {"uavcan.equipment.actuator.Status": sent[1]}
    # the learner took the measured surfaces, not the PWM, for every control
    assert all("DroneCAN" in snap["control_sources"][c] for c in CONTROLS), snap["control_sources"]
    assert not any(n.startswith(("CAN not merged", "learning stopped")) for n in snap["learner_notes"])
    assert snap["learner_in"] == ("worker process" if default_enabled() else "this process")
    live = session.learner
    assert live.steps >= 4 and len(live.t) > 500

    # the same session replayed from its raw.tlog + can.log learns the same rows (to 1e-5)
    again = learn_from_tlog(tmp_path / "live" / "raw.tlog", af_can, LEARN, can_log=tmp_path / "live" / "can.log",
                            coalesced_at=snap["coalesced_at_us"])
    assert np.array_equal(again.t, live.t)
    # not bit for bit: can.log keeps the frames' stamps to the microsecond, the live decoder had them exact
    # (measured: regressors within 5e-7 rad, coefficients equal); allowed: 1e-5 (rad for the deflections)
    dx = np.nanmax(np.abs(again.X - live.X), axis=0)
    dy = np.nanmax(np.abs(again.Y - live.Y), axis=0)
    print("max |replay - live|: X", dx, "Y", dy)
    assert np.all(dx < 1e-5) and np.all(dy < 1e-5), (dx, dy)
    assert np.array_equal(np.isnan(again.Y), np.isnan(live.Y))
    # ... and the commanded PWM alone (the same raw.tlog, no CAN) does not: the lag is in its regressors
    pwm = learn_from_tlog(tmp_path / "live" / "raw.tlog", replace(af, can_actuators=()), LEARN)
    assert pwm.control_sources["delta_e"].startswith("servo PWM")
    assert _delta_e_error(live, sim) < 0.25 * _delta_e_error(pwm, sim)
    cm_live, cm_pwm = _cm_delta_e(live), _cm_delta_e(pwm)
    print("Cm_delta_e live", cm_live, "replay", _cm_delta_e(again), "PWM", cm_pwm, "delta_e RMS error (rad) live",
          _delta_e_error(live, sim), "PWM", _delta_e_error(pwm, sim), "CAN transfers", sent[1])
    assert cm_live == pytest.approx(_cm_delta_e(again), rel=1e-4)
    assert abs(cm_live - cm_pwm) > 0.2, (cm_live, cm_pwm)                    # truth -0.9
    assert abs(cm_live - (-0.9)) < abs(cm_pwm - (-0.9)), (cm_live, cm_pwm)
