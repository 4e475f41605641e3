"""The learner across a vehicle reboot: the sample flight with time_boot_ms/time_usec restarted half-way
(packets re-encoded with pymavlink), fed record by record; no model is fitted (min_rows too high), so
only the decode -> smooth -> coefficients -> row selection path runs."""

import sys
from pathlib import Path

import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink

from gcs_sysid.airframe import load_airframe
from gcs_sysid.live.learner import LearnOptions, Learner, iter_tlog_records

sys.path.insert(0, str(Path(__file__).resolve().parent))
from live_helpers import AIRFRAME, FLIGHT  # noqa: E402


def _rebooted_records(t_from=40.0, t_reboot=70.0, t_to=100.0, back_s=65.0):
    """Records of the sample flight between t_from and t_to s (log time); after t_reboot the vehicle
    clock reads back_s seconds less (a reboot), sequence numbers kept."""
    parser = mavlink.MAVLink(None)
    out, t0 = [], None
    for stamp, pkt in iter_tlog_records(FLIGHT):
        t0 = stamp if t0 is None else t0
        rel = (stamp - t0) * 1e-6
        if rel < t_from:
            continue
        if rel > t_to:
            break
        if rel > t_reboot:
            m = parser.parse_char(pkt)
            if m is not None and (hasattr(m, "time_boot_ms") or hasattr(m, "time_usec")):
                if hasattr(m, "time_boot_ms"):
                    m.time_boot_ms = int(m.time_boot_ms - back_s * 1000)
                else:
                    m.time_usec = int(m.time_usec - back_s * 1e6) % (2 ** 32 if m.get_type() == "SERVO_OUTPUT_RAW"
                                                                     else 2 ** 64)
                enc = mavlink.MAVLink(None, srcSystem=m.get_srcSystem(), srcComponent=m.get_srcComponent())
                enc.seq = m.get_seq()
                pkt = bytes(m.pack(enc))
        out.append((stamp, pkt))
    return out


@pytest.mark.slow   # ~8 windows decoded and smoothed (~15 s on a shared 2-core machine)
def test_learning_resumes_on_the_new_clock_after_a_reboot():
    records = _rebooted_records()
    learner = Learner(load_airframe(AIRFRAME), LearnOptions(window_s=12, step_s=6, lag_s=2, min_rows=10 ** 9))
    for stamp, pkt in records:
        learner.feed(stamp, pkt)
    learner.finish()
    assert any("went back" in n and "reboot" in n for n in learner.notes), learner.notes
    # 60 s at 50 Hz flown: rows learned once each, except at most one window's worth after the reboot
    n = len(learner.t)
    assert 0.7 * 3000 <= n <= 3000 + 12 * 50, n
    assert learner.model is None
