"""Benchmark: replay of a 10-minute 50 Hz flight, end to end, against bare pymavlink decoding.

Target (issue 2): the whole pipeline within 3x the bare decode time of the same log measured in
the same run, and peak memory under 1 GiB.

    python benchmarks/bench_replay.py [--repeats 3] [--minutes 10]

It simulates the flight once (cached in benchmarks/out/), then alternates: a bare pymavlink decode
(``mavutil.mavlink_connection`` + ``recv_match()`` until the end, no processing) and the full
``run_replay`` (decode, estimation, coefficients, GP fit and prediction, confidence map,
suggestions, report), each in a fresh subprocess so that JAX compilation and imports count and the
peak resident memory of each run can be read. Medians and the ratio are printed.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
import tomllib
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
OUT = REPO / "benchmarks" / "out"

DECODE = """
import sys, time
from pymavlink import mavutil
t0 = time.perf_counter()
m = mavutil.mavlink_connection(sys.argv[1], dialect="ardupilotmega")
n = 0
while m.recv_match() is not None:
    n += 1
print(time.perf_counter() - t0, n)
"""

PIPELINE = """
import json, sys, time
t0 = time.perf_counter()
from gcs_sysid.jaxconfig import enable_x64
enable_x64()
from gcs_sysid.pipeline import ReplayOptions, run_replay
r = run_replay(sys.argv[1], sys.argv[2], sys.argv[3], ReplayOptions(progress=False))
print(json.dumps({"wall": time.perf_counter() - t0, "timings": r.timings,
                  "errors": {k: v["error_pct_heldout"] for k, v in r.metrics.items()}}))
"""


def make_flight(minutes: float) -> Path:
    """Simulate the sysid plan repeated to ``minutes`` of flight (cached)."""
    path = OUT / f"flight-{minutes:g}min.tlog"
    if path.exists():
        return path
    sys.path.insert(0, str(REPO))
    from gcs_sysid.airframe import load_airframe
    from gcs_sysid.jaxconfig import enable_x64
    from gcs_sysid.sim import load_model, plan_from_dict, simulate, write_tlog

    enable_x64()
    doc = tomllib.loads((REPO / "data/plans/sysid-trainer.toml").read_text())
    base = float(doc["duration_s"])
    total = 60.0 * minutes
    reps = int(total // base) + 1
    for key in ("maneuver", "setpoint"):
        items = doc.get(key, [])
        doc[key] = [dict(m, start_s=m["start_s"] + k * base) for k in range(reps) for m in items
                    if m["start_s"] + k * base < doc["start_time_s"] + total - 10]
    doc["duration_s"] = total
    airframe = load_airframe(REPO / "data/airframes/sim-trainer.toml")
    sim = simulate(airframe, load_model(REPO / "data/models/sim-trainer.toml"), plan_from_dict(doc, "bench"))
    OUT.mkdir(parents=True, exist_ok=True)
    write_tlog(sim, path, airframe)
    return path


def run_child(code: str, *args: str) -> tuple[str, float]:
    """Run ``code`` in a fresh interpreter; returns its stdout and its peak RSS in MiB."""
    env = dict(os.environ, PYTHONPATH=str(REPO))
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    p = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, env=env, check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    # ru_maxrss of children is the max over all waited-for children: it only tells this child's peak
    # when that exceeds all earlier ones, so the pipeline (the larger) runs are what it reports.
    return p.stdout.strip().splitlines()[-1], max(after, before) / 1024.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--minutes", type=float, default=10.0)
    a = ap.parse_args()
    t0 = time.perf_counter()
    log = make_flight(a.minutes)
    print(f"flight: {log} ({log.stat().st_size / 1e6:.1f} MB), made in {time.perf_counter() - t0:.1f} s")
    decode, pipe, peak, stages = [], [], 0.0, []
    for i in range(a.repeats):
        out, _ = run_child(DECODE, str(log))
        secs, n = out.split()
        decode.append(float(secs))
        out, rss = run_child(PIPELINE, str(log), str(REPO / "data/airframes/sim-trainer.toml"),
                             str(OUT / f"report-{i}"))
        r = json.loads(out)
        pipe.append(r["wall"])
        stages.append(r["timings"])
        peak = max(peak, rss)
        print(f"run {i + 1}: bare decode {float(secs):6.2f} s ({n} messages) | pipeline {r['wall']:6.2f} s "
              f"| peak RSS so far {rss:6.0f} MiB")
    md, mp = statistics.median(decode), statistics.median(pipe)
    print("\nstage medians (s): " + ", ".join(
        f"{k} {statistics.median(s[k] for s in stages):.2f}" for k in stages[0]))
    print(f"held-out errors of the last run (%): " + ", ".join(f"{k} {v:.1f}" for k, v in r["errors"].items()))
    print(f"\nbare pymavlink decode  median {md:7.2f} s")
    print(f"gcs-sysid replay       median {mp:7.2f} s  (incl. interpreter start, imports, JIT)")
    print(f"ratio pipeline/decode  {mp / md:7.2f}x   (target <= 3x)")
    print(f"peak RSS (pipeline)    {peak:7.0f} MiB (target < 1024 MiB)")


if __name__ == "__main__":
    main()
