"""Benchmark: `listen` message handling at 2,000 messages/s over real UDP, with the learner running.

Target (issue 10): 2,000 msg/s sustained, per-message handling p99 under 5 ms, no received packet
missing from raw.tlog, the GP work (in its own thread) never starving the link.

    python benchmarks/bench_live.py [--rate 2000] [--seconds 60] [--no-learn] [--no-parallel]
    python benchmarks/bench_live.py --soak --rate 500 --seconds 120    # memory curve (RSS every 5 s)

The log player (`gcs-sysid-player`, a subprocess) streams the sample flight (258 msg/s recorded) at
rate/258 x onto 127.0.0.1; first a bare pymavlink receive loop (``recv_msg`` until the stream ends,
no processing: the baseline), then a :class:`gcs_sysid.live.LiveSession` with the learner on
(window/step/lag scaled by the speed-up) and handling times measured per message
(``LinkReceiver(measure=True)``: raw-log write, stats, queueing). Prints the figures as JSON.

The learner runs in the worker process (``gcs_sysid.live.remote``) when there is one; ``--no-parallel``
runs it in the listening process (a thread), as before that change. ``rss_mib_every_5s`` is the
listening process's resident size; ``learner_rss_mib`` the worker's at the end (when it has one).
"""

from __future__ import annotations

import argparse
import json
import re
import socket
import statistics
import subprocess
import sys
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
FLIGHT = REPO / "data" / "flights" / "sim-trainer-sysid.tlog"
AIRFRAME = REPO / "data" / "airframes" / "sim-trainer.toml"
RECORDED_RATE = 258.0   # messages/s of the sample flight (61,930 in 240 s)


def _port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _player(port: int, speed: float, seconds: float) -> subprocess.Popen:
    exe = Path(sys.executable).with_name("gcs-sysid-player")
    return subprocess.Popen([str(exe), str(FLIGHT), "--link", f"udpout:127.0.0.1:{port}", "--speed", f"{speed:.3f}",
                             "--from", "20", "--to", f"{20 + seconds * speed:.1f}", "--no-answer"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _sent(out: str) -> tuple[int, float]:
    m = re.search(r"sent (\d+) packets .* in ([\d.]+) s", out)
    return int(m.group(1)), float(m.group(2))


def baseline(speed: float, seconds: float) -> dict:
    from gcs_sysid.telemetry.live import open_link

    port = _port()
    link = open_link(f"udpin:127.0.0.1:{port}")
    proc = _player(port, speed, seconds)
    n = 0
    while proc.poll() is None or n == 0:
        m = link.recv_msg()
        if m is None:
            time.sleep(0.0005)
        elif m.get_type() != "BAD_DATA":
            n += 1
    while (m := link.recv_msg()) is not None:
        n += 1
    out, _ = proc.communicate()
    link.close()
    sent, dur = _sent(out)
    return {"sent": sent, "received": n, "send_rate": sent / dur}


def listen(speed: float, seconds: float, learn: bool, out_dir: Path, parallel: bool | None = None) -> dict:
    from gcs_sysid.airframe import load_airframe
    from gcs_sysid.live.learner import LearnOptions, iter_tlog_records
    from gcs_sysid.live.session import ListenOptions, LiveSession
    from gcs_sysid.telemetry.live import open_link

    port = _port()
    lo = LearnOptions(window_s=30 / speed, step_s=10 / speed, lag_s=3.0, min_rows=500) if learn else None
    opts = ListenOptions(connection=f"udpin:127.0.0.1:{port}", learn=lo, request=False, component=True,
                         system_id=1, console=False, use_mavsdk=False,
                         **({} if parallel is None else {"parallel": parallel}))
    session = LiveSession(load_airframe(AIRFRAME), out_dir, opts, link=open_link(opts.connection))
    session.receiver.handle_s = __import__("collections").deque(maxlen=1_000_000)
    qmax = [0]
    rss: list[tuple[float, float]] = []
    remote = getattr(session.learner, "worker_pid", None) is not None
    learner_rss = [float("nan")]

    def watch():
        t_last = -1e9
        while not session._stop.is_set():
            qmax[0] = max(qmax[0], session._q.qsize() + getattr(session.learner, "in_flight", 0))
            if remote:
                learner_rss[0] = getattr(session.learner, "rss_mib", learner_rss[0])
            if time.perf_counter() - t_last >= 5.0:
                t_last = time.perf_counter()
                rss.append((round(t_last - t0, 1), _rss_mib()))
            time.sleep(0.05)

    result = {}
    th = threading.Thread(target=lambda: result.update(snap=session.run()))
    t0 = time.perf_counter()
    th.start()
    threading.Thread(target=watch, daemon=True).start()
    proc = _player(port, speed, seconds)
    out, _ = proc.communicate()
    t_stream = time.perf_counter() - t0
    time.sleep(0.5)
    session.stop()
    th.join()
    t_total = time.perf_counter() - t0
    sent, dur = _sent(out)
    h = sorted(session.receiver.handle_s)
    q = lambda f: h[min(int(f * len(h)), len(h) - 1)] * 1e3  # noqa: E731
    raw = sum(1 for _ in iter_tlog_records(out_dir / "raw.tlog"))
    return {"sent": sent, "send_rate": sent / dur, "received_in_raw_tlog": raw,
            "handle_ms": {"median": q(0.5), "p99": q(0.99), "max": h[-1] * 1e3, "n": len(h)},
            "learner_queue_max": qmax[0], "steps": result["snap"].get("steps"),
            "learner_in": "worker process" if remote else "listening process",
            "learner_rss_mib": learner_rss[0] if remote else None,
            "samples_learned": result["snap"].get("samples_learned"), "stream_s": t_stream,
            "steps_coalesced": result["snap"].get("steps_coalesced"),
            "map_refreshes_deferred": result["snap"].get("map_refreshes_deferred"),
            "drain_after_stream_s": t_total - t_stream, "rss_mib_every_5s": rss,
            "rss_growth_mib_after_first_minute": (max(r for _, r in rss) - next((r for t, r in rss if t >= 60),
                                                                                rss[-1][1])) if rss else None}


def _rss_mib() -> float:
    """Resident memory of this process, MiB (Linux /proc)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    return float("nan")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rate", type=float, default=2000.0, help="messages/s to stream (default 2000)")
    ap.add_argument("--seconds", type=float, default=60.0, help="seconds of streaming (default 60)")
    ap.add_argument("--no-learn", action="store_true")
    ap.add_argument("--no-parallel", action="store_true", help="run the learner in the listening process")
    ap.add_argument("--soak", action="store_true", help="skip the baseline; report the memory curve")
    ap.add_argument("--out", default=str(REPO / "benchmarks" / "out" / "live"))
    a = ap.parse_args()
    speed = a.rate / RECORDED_RATE
    if a.seconds * speed > 215:
        a.seconds = 215 / speed
    base = {"received": 0} if a.soak else baseline(speed, a.seconds)
    out_dir = Path(a.out)
    if (out_dir / "raw.tlog").exists():
        (out_dir / "raw.tlog").unlink()
    live = listen(speed, a.seconds, not a.no_learn, out_dir, False if a.no_parallel else None)
    live["handle_p99_under_5ms"] = live["handle_ms"]["p99"] < 5.0
    if not a.soak:
        live["lost_vs_baseline"] = base["received"] - live["received_in_raw_tlog"]
    print(json.dumps({"rate_asked": a.rate, "speed": speed, "baseline": base, "listen": live}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
