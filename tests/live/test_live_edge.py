"""The live edge's forward filter against the analytic rates of a known motion (and the console renders)."""

import numpy as np
from rich.console import Console

from gcs_sysid.live.console import render
from gcs_sysid.live.edge import LiveEdge


def test_filtered_angular_acceleration_tracks_a_sine():
    rng = np.random.default_rng(3)
    t = np.arange(0, 12, 0.02)                       # 50 Hz gyro
    w = 2 * np.pi * 0.8                              # a 0.8 Hz pitch oscillation, 0.3 rad/s
    q = 0.3 * np.sin(w * t)
    edge = LiveEdge()
    est = []
    for ti, qi in zip(t, q + rng.normal(0, 0.01, len(t))):
        edge.feed("RAW_IMU", {"p": 0.0, "q": qi, "r": 0.0, "ax": 0, "ay": 0, "az": -9.8}, ti)
        est.append((edge.values["q"], edge.values["q_dot"]))
    est = np.array(est)[100:]                        # after 2 s of start-up
    q_dot = (0.3 * w * np.cos(w * t))[100:]
    err = 100 * np.sqrt(np.mean((est[:, 1] - q_dot) ** 2)) / np.sqrt(np.mean(q_dot ** 2))
    assert err < 30.0                                 # causal: it lags (23 % measured), no look-ahead
    assert np.sqrt(np.mean((est[:, 0] - q[100:]) ** 2)) < 0.01
    # a reboot (time going back) restarts the filter instead of differentiating across it
    edge.feed("RAW_IMU", {"p": 0.0, "q": 0.1, "r": 0.0}, 1.0)
    assert edge.values["t"] == t[-1] and edge.updates == len(t)


def test_console_renders_a_snapshot():
    snap = {"connection": "udpin:0.0.0.0:14550", "link": "receiving", "vehicle": [1, 1], "packets": 10,
            "raw_records": 10, "bad_data": 0, "seq_lost": 0, "rates": {"ATTITUDE": 49.0}, "asked": {"ATTITUDE": 50},
            "requests": {"ATTITUDE": "accepted"}, "events": ["vehicle: system 1, component 1"], "params": {},
            "samples_learned": 600, "steps": 3, "queue": 0, "confidence": {"Cm": 0.3},
            "top_suggestion": "fly an elevator doublet", "costs": ["gyro at 4.0 Hz"],
            "edge": {"p": 0.0, "q": 0.1, "r": 0.0, "q_dot": 0.5, "eas": 18.0, "alpha_ap": 0.05}}
    c = Console(record=True, width=120)
    c.print(render(snap))
    text = c.export_text()
    assert "ATTITUDE" in text and "Cm" in text and "elevator doublet" in text and "EAS 18.0" in text
