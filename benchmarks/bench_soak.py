"""Benchmark: one hour of messages at 500 msg/s through the full listener: resident memory stays flat.

Target (issue 10): memory flat (under 50 MiB growth) over a one-hour soak at 500 messages/s, with the
full listener (UDP socket on 127.0.0.1, ``LinkReceiver`` writing ``raw.tlog``, the learner thread with
the bounded streaming GP, the MAVLink component, the schedule's ticks) running.

    python benchmarks/bench_soak.py                       # 1,800,000 messages (one hour at 500 msg/s)
    python benchmarks/bench_soak.py --messages 200000     # a shorter check

**Faster than real time.** The messages of one hour at 500 msg/s (1.8 million) are fed at ``--feed``
msg/s (default 1,500, i.e. 3x), so the run takes ~20 minutes, not an hour. The source is the sample
flight (258 msg/s as recorded) looped: each pass is re-encoded with its time fields
(``time_boot_ms``, ``time_usec``) moved on by the flight's span, so the vehicle clock runs on for
~1.9 hours of vehicle time without a reboot. The learner's window and step (arrival time) are scaled
by the feed's speed-up over the recording, so each step smooths the same vehicle time as at real
time. A sender thread in this process sends the datagrams; it pauses while more than ``--queue-cap``
records wait for the learner (this only matters if the learner falls behind; the report says how
long it paused), so a lagging learner cannot pass its backlog off as memory growth of the listener.

RSS is sampled every 10 s of wall time: VmRSS of this process (listener, sender, and the learner when
it runs here) plus, when the learner runs in the spare worker process (the default where there are
two CPUs, ``docs/live.md``), that worker's VmRSS read from ``/proc/PID/status``; the criterion is on
the sum, so moving the learner out of the listening process cannot hide its memory. ``--in-process``
runs the learner in this process instead. The curve is printed (messages received, vehicle time covered, RSS),
with the growth from the end of the first tenth of the run (JAX programs compiled, first GP fit, store filling) to
the end and the largest
RSS after it.
"""

from __future__ import annotations

import argparse
import json
import socket
import sys
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
FLIGHT = REPO / "data" / "flights" / "sim-trainer-sysid.tlog"
AIRFRAME = REPO / "data" / "airframes" / "sim-trainer.toml"
RECORDED_RATE = 258.0   # messages/s of the sample flight


def _rss_mib(pid: int | str = "self") -> float:
    """VmRSS (MiB) of process ``pid`` (this one by default); NaN when it cannot be read."""
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return float("nan")


def _base_messages():
    """(vehicle time s, message) of the sample flight's vehicle messages, and the flight's span (s)."""
    from pymavlink import mavutil

    mlog = mavutil.mavlink_connection(str(FLIGHT), dialect="ardupilotmega")
    out = []
    while (m := mlog.recv_msg()) is not None:
        if m.get_type() == "BAD_DATA":
            continue
        out.append(m)
    times = [m.time_boot_ms * 1e-3 for m in out if hasattr(m, "time_boot_ms")]
    return out, max(times) - min(times) + 1.0


def _shifted(msg, shift_s: float):
    """A copy of ``msg`` with its time fields moved on by ``shift_s``."""
    import copy

    m = copy.copy(msg)
    if hasattr(m, "time_boot_ms"):
        m.time_boot_ms = (m.time_boot_ms + int(round(shift_s * 1e3))) % 2**32
    if hasattr(m, "time_usec"):
        wrap = 2**32 if m.get_type() == "SERVO_OUTPUT_RAW" else 2**64
        m.time_usec = (m.time_usec + int(round(shift_s * 1e6))) % wrap
    return m


def sender(port: int, messages: int, feed: float, session, cap: int, stats: dict) -> None:
    from pymavlink.dialects.v20 import ardupilotmega as mavlink

    base, span = _base_messages()
    mavs = {}
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    dest = ("127.0.0.1", port)
    sent, k, paused = 0, 0, 0.0
    t0 = time.perf_counter()
    while sent < messages:
        for msg in base:
            if sent >= messages:
                break
            key = (msg.get_srcSystem(), msg.get_srcComponent())
            mav = mavs.get(key) or mavs.setdefault(key, mavlink.MAVLink(None, srcSystem=key[0],
                                                                         srcComponent=key[1]))
            m = _shifted(msg, k * span) if k else msg
            buf = m.pack(mav)
            mav.seq = (mav.seq + 1) % 256
            sock.sendto(bytes(buf), dest)
            sent += 1
            if sent % 50 == 0:
                lag = t0 + sent / feed - time.perf_counter()
                if lag > 0:
                    time.sleep(lag)
                while session._q.qsize() > cap and not session._stop.is_set():
                    p0 = time.perf_counter()
                    time.sleep(0.05)
                    paused += time.perf_counter() - p0
                    t0 += time.perf_counter() - p0
        k += 1
    sock.close()
    stats.update(sent=sent, passes=k, span_s=span, paused_s=paused, send_s=time.perf_counter() - stats["t0"])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--messages", type=int, default=1_800_000, help="messages to feed (default: 1 h at 500 msg/s)")
    ap.add_argument("--feed", type=float, default=1500.0, help="messages/s sent (default 1500 = 3x of 500 msg/s)")
    ap.add_argument("--queue-cap", type=int, default=30000, help="sender pauses while more records wait")
    ap.add_argument("--in-process", action="store_true", help="run the learner in this process (no worker)")
    ap.add_argument("--out", default=str(REPO / "benchmarks" / "out" / "soak"))
    a = ap.parse_args()

    from gcs_sysid.airframe import load_airframe
    from gcs_sysid.live.learner import LearnOptions
    from gcs_sysid.live.session import ListenOptions, LiveSession
    from gcs_sysid.telemetry.live import open_link

    speed = a.feed / RECORDED_RATE
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    for f in ("raw.tlog",):
        if (out / f).exists():
            (out / f).unlink()
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    lo = LearnOptions(window_s=30 / speed, step_s=10 / speed, lag_s=3.0, min_rows=500)
    opts = ListenOptions(connection=f"udpin:127.0.0.1:{port}", learn=lo, request=False, component=True,
                         system_id=1, console=False, use_mavsdk=False,
                         parallel=False if a.in_process else None)
    session = LiveSession(load_airframe(AIRFRAME), out, opts, link=open_link(opts.connection))
    curve: list[dict] = []
    result: dict = {}
    stats: dict = {"t0": time.perf_counter()}
    th = threading.Thread(target=lambda: result.update(snap=session.run()))
    th.start()
    snd = threading.Thread(target=sender, args=(port, a.messages, a.feed, session, a.queue_cap, stats), daemon=True)
    t0 = time.perf_counter()
    snd.start()
    qmax = 0
    while snd.is_alive():
        time.sleep(1.0)
        qmax = max(qmax, session._q.qsize())
        if not curve or time.perf_counter() - t0 - curve[-1]["wall_s"] >= 10.0:
            rec = session.receiver.stats.records
            lr = session.learner
            worker = getattr(lr, "worker_pid", None)
            own = _rss_mib()
            wrss = _rss_mib(worker) if worker else 0.0
            if hasattr(lr, "rows_stored"):   # the learner in the worker: its status copy
                stored = lr.rows_stored
            else:
                stored = len(lr.model.rows) if lr.model is not None and lr.model.rows is not None else 0
            curve.append({"wall_s": round(time.perf_counter() - t0, 1), "rss_mib": round(own + wrss, 1),
                          "rss_listener_mib": round(own, 1), "rss_worker_mib": round(wrss, 1),
                          "received": rec, "queue": session._q.qsize(), "steps": lr.steps,
                          "rows_learned": lr.n_learned, "rows_stored": stored})
            print(json.dumps(curve[-1]), file=sys.stderr, flush=True)
    time.sleep(1.0)
    session.stop()
    th.join()
    snap = result.get("snap", {})
    n = len(curve)
    ref = curve[max(n // 10, 1) - 1]
    after = curve[max(n // 10, 1) - 1:]
    rep = {"messages": stats.get("sent"), "feed_msg_s": a.feed, "speed_vs_recording": speed,
           "speed_vs_500_msg_s": a.feed / 500.0, "passes_of_the_flight": stats.get("passes"),
           "vehicle_time_s": stats.get("sent", 0) / RECORDED_RATE, "send_wall_s": stats.get("send_s"),
           "sender_paused_s": stats.get("paused_s"), "learner_queue_max": qmax,
           "learner_in_worker": any(c["rss_worker_mib"] > 0 for c in curve),
           "steps": snap.get("steps"), "samples_learned": snap.get("samples_learned"),
           "rss_start_mib": curve[0]["rss_mib"], "rss_ref_mib": ref["rss_mib"], "rss_ref_at_s": ref["wall_s"],
           "rss_end_mib": curve[-1]["rss_mib"], "rss_max_after_ref_mib": max(c["rss_mib"] for c in after),
           "growth_ref_to_end_mib": curve[-1]["rss_mib"] - ref["rss_mib"],
           "growth_ref_to_max_mib": max(c["rss_mib"] for c in after) - ref["rss_mib"]}
    rep["flat_under_50_mib"] = rep["growth_ref_to_max_mib"] < 50.0
    print("curve (wall s, RSS MiB, learner steps, rows learned, rows stored, queue):")
    for c in curve:
        print(f"  {c['wall_s']:7.0f}  {c['rss_mib']:7.1f}  {c['steps']:5d}  {c['rows_learned']:7d}  "
              f"{c['rows_stored']:6d}  {c['queue']:6d}")
    print(json.dumps(rep, indent=1))
    (out / "soak.json").write_text(json.dumps({"report": rep, "curve": curve}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
