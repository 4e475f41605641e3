"""Benchmark: replay of a 10-minute 50 Hz flight, end to end, against bare pymavlink decoding.

Target (issue 2): the whole pipeline within 3x the bare decode time of the same log measured in
the same run, and peak memory under 1 GiB.

    python benchmarks/bench_replay.py [--repeats 3] [--minutes 10] [--serial] [--cold] [--gp-noise independent]

It simulates the flight once (cached in benchmarks/out/), then alternates: a bare pymavlink decode
(``mavutil.mavlink_connection`` + ``recv_match()`` until the end, no processing) and the full
``run_replay`` (decode, estimation, coefficients, GP fit and prediction, confidence map,
suggestions, report), each in a fresh subprocess so that JAX compilation and imports count and the
peak resident memory of each run can be read: the replay's own and its worker process's
(:mod:`gcs_sysid.parallel`), and their sum sampled every 10 ms (what the replay held at once). ``--serial`` also
times the replay without its worker. Medians and the ratio are printed.

JAX's persistent compilation cache (:func:`gcs_sysid.jaxconfig.enable_compilation_cache`) decides
whether a replay compiles its GP programs or loads them, so the script says which it measured: by
default the user's cache (``$GCS_SYSID_JAX_CACHE`` or ``~/.cache/gcs-sysid/jax``), with the number of
programs each replay added to it (0: warm, every program loaded); with ``--cold`` every replay gets a
new empty cache directory (a fresh machine, e.g. CI). Each run also prints the load average at its
start (the box is shared) and the CPU seconds of the replay's main process and of its worker, which
move less with the load than wall times.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import threading
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
import json, resource, sys, time
t0 = time.perf_counter()
from gcs_sysid.pipeline import ReplayOptions, run_replay   # as `gcs-sysid replay` does: JAX is set up inside
r = run_replay(sys.argv[1], sys.argv[2], sys.argv[3], ReplayOptions(progress=False, parallel=sys.argv[4] == "1",
                                                                  gp_noise=sys.argv[5] if len(sys.argv) > 5 else None))
wall = time.perf_counter() - t0
# peak RSS of this process and of its worker (a waited-for child), KiB on Linux; CPU s of each
me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
print(json.dumps({"wall": wall, "timings": r.timings, "cpu_main": me.ru_utime + me.ru_stime,
                  "cpu_worker": kids.ru_utime + kids.ru_stime,
                  "rss_main": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
                  "rss_worker": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024,
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


def _rss_tree_mib(pid: int) -> float:
    """Resident memory of ``pid`` and its descendants now (Linux /proc), MiB; 0 where unreadable."""
    total, todo = 0.0, [pid]
    while todo:
        p = todo.pop()
        try:
            with open(f"/proc/{p}/status") as f:
                total += next(int(x.split()[1]) for x in f if x.startswith("VmRSS")) / 1024.0
            with open(f"/proc/{p}/task/{p}/children") as f:
                todo.extend(int(c) for c in f.read().split())
        except (OSError, StopIteration, ValueError):
            continue
    return total


def cache_entries(path: Path) -> int:
    """Compiled programs in a JAX compilation-cache directory (0 when it does not exist)."""
    try:
        return sum(1 for p in path.iterdir() if p.name.endswith("-cache"))
    except OSError:
        return 0


def run_child(code: str, *args: str, env_extra: dict[str, str] | None = None) -> tuple[str, float]:
    """Run ``code`` in a fresh interpreter; returns the last line of its stdout and the largest
    resident memory of it and its descendants together, sampled every 10 ms (MiB)."""
    env = dict(os.environ, PYTHONPATH=str(REPO), **(env_extra or {}))
    p = subprocess.Popen([sys.executable, "-c", code, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True, env=env)
    peak = [0.0]

    def sample():
        while p.poll() is None:
            peak[0] = max(peak[0], _rss_tree_mib(p.pid))
            time.sleep(0.01)

    th = threading.Thread(target=sample, daemon=True)
    th.start()
    out, err = p.communicate()
    th.join()
    if p.returncode:
        raise subprocess.CalledProcessError(p.returncode, "benchmark child", out, err)
    return out.strip().splitlines()[-1], peak[0]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--minutes", type=float, default=10.0)
    ap.add_argument("--serial", action="store_true", help="also time the replay without its worker process")
    ap.add_argument("--gp-noise", default=None,
                    help="the replay GP's noise (gcs_sysid.pipeline.GP_NOISE_MODES, e.g. 'independent', the default "
                         "until the twenty-fifth session); default: the package's (learned)")
    ap.add_argument("--cold", action="store_true",
                    help="give every replay a new empty JAX compilation cache (a fresh machine) instead of the user's")
    a = ap.parse_args()
    sys.path.insert(0, str(REPO))
    from gcs_sysid.jaxconfig import default_cache_dir

    cache = default_cache_dir()
    cold_root = Path(tempfile.mkdtemp(prefix="bench-replay-cold-")) if a.cold else None
    if cold_root is not None:
        print(f"compilation cache: cold, a new empty directory per replay under {cold_root}")
    else:
        print(f"compilation cache: {cache} ({cache_entries(cache)} programs at the start)")
    t0 = time.perf_counter()
    log = make_flight(a.minutes)
    print(f"flight: {log} ({log.stat().st_size / 1e6:.1f} MB), made in {time.perf_counter() - t0:.1f} s")
    decode, pipe, serial, stages, cpu_main, cpu_worker = [], [], [], [], [], []
    peak_main = peak_worker = peak_tree = 0.0
    airframe = str(REPO / "data/airframes/sim-trainer.toml")
    compiled = []

    def cache_for(tag: str) -> tuple[dict[str, str], Path]:
        if cold_root is None:
            return {}, cache
        d = cold_root / tag
        return {"GCS_SYSID_JAX_CACHE": str(d)}, d

    for i in range(a.repeats):
        load = os.getloadavg()[0]
        secs, n = run_child(DECODE, str(log))[0].split()
        decode.append(float(secs))
        env, cdir = cache_for(f"run-{i}")
        before = cache_entries(cdir)
        noise = () if a.gp_noise is None else (a.gp_noise,)
        out, tree = run_child(PIPELINE, str(log), airframe, str(OUT / f"report-{i}"), "1", *noise, env_extra=env)
        added = cache_entries(cdir) - before
        compiled.append(added)
        r = json.loads(out)
        cpu_main.append(r["cpu_main"])
        cpu_worker.append(r["cpu_worker"])
        peak_tree = max(peak_tree, tree)
        pipe.append(r["wall"])
        stages.append(r["timings"])
        peak_main, peak_worker = max(peak_main, r["rss_main"]), max(peak_worker, r["rss_worker"])
        line = (f"run {i + 1} (load {load:.1f}): bare decode {float(secs):6.2f} s ({n} messages) | pipeline "
                f"{r['wall']:6.2f} s, CPU {r['cpu_main']:5.2f} s + worker {r['cpu_worker']:5.2f} s, "
                f"{added} programs compiled into the cache | peak RSS {r['rss_main']:4.0f} + worker "
                f"{r['rss_worker']:4.0f} MiB, together {tree:4.0f} MiB")
        if a.serial:
            env, _ = cache_for(f"serial-{i}")
            s = json.loads(run_child(PIPELINE, str(log), airframe, str(OUT / f"report-serial-{i}"), "0", *noise,
                                     env_extra=env)[0])
            serial.append(s["wall"])
            line += f" | serial {s['wall']:6.2f} s"
        print(line)
    md, mp = statistics.median(decode), statistics.median(pipe)
    print("\nstage medians (s): " + ", ".join(
        f"{k} {statistics.median(s[k] for s in stages):.2f}" for k in stages[0]))
    print(f"held-out errors of the last run (%): " + ", ".join(f"{k} {v:.1f}" for k, v in r["errors"].items()))
    print(f"\nbare pymavlink decode  median {md:7.2f} s")
    if a.cold:
        state = "cold compilation cache: every run compiled"
    elif not any(compiled):
        state = "warm compilation cache: no run compiled a program"
    else:
        state = f"compilation cache NOT all warm: runs compiled {compiled} programs"
    print(f"gcs-sysid replay       median {mp:7.2f} s  (incl. interpreter start, imports, JIT; {state})")
    print(f"ratio pipeline/decode  {mp / md:7.2f}x   (target <= 3x; runs: "
          + ", ".join(f"{p / d:.2f}x" for p, d in zip(pipe, decode)) + ")")
    print(f"replay CPU             median {statistics.median(cpu_main):7.2f} s main process, "
          f"{statistics.median(cpu_worker):.2f} s worker")
    if serial:
        ms = statistics.median(serial)
        print(f"without the worker     median {ms:7.2f} s  ({ms / md:.2f}x decode; GCS_SYSID_PARALLEL=0)")
    # the two peaks need not coincide: their sum bounds what the replay held; the sampled total is what it held
    print(f"peak RSS               {peak_tree:7.0f} MiB main and worker together, sampled (target < 1024 MiB); "
          f"separate peaks {peak_main:.0f} + {peak_worker:.0f} MiB")
    print(f"load average at the end {os.getloadavg()[0]:.1f} "
          f"(2-core box shared with other jobs: read ratios, not seconds)")
    if cold_root is not None:
        import shutil

        shutil.rmtree(cold_root, ignore_errors=True)


if __name__ == "__main__":
    main()
