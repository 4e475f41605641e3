"""One replay with the wall time and the CPU seconds of each stage, of the main process and of its worker.

    python benchmarks/replay_stage_cpu.py LOG AIRFRAME OUT >> runs.jsonl
    python benchmarks/replay_stage_cpu.py --summary BASE.jsonl NEW.jsonl    # medians of alternated pairs

Prints one JSON line: ``wall`` (s, the interpreter's start and imports included), ``stages`` (name -> [wall s,
main-process CPU s, worker CPU s], the CPU of all the main process's threads from ``os.times`` and the worker's
from ``/proc`` at the stage's start and end), ``cpu_main`` and ``cpu_worker`` (s, the whole run), ``rss_main`` (MiB,
peak), ``load`` (the 1-minute load average at the end) and ``jobs`` (each worker job: name, submitted, finished,
asked for and received, s from the start). On a shared machine the CPU seconds move less with the load than wall
times (``docs/benchmarks.md``, "Thirty-third session, speed33": an A/B alternates two trees, each with its own
``GCS_SYSID_JAX_CACHE`` filled from empty, and compares medians of these).
"""

from __future__ import annotations

import json
import os
import resource
import sys
import time
from contextlib import contextmanager

T0 = time.perf_counter()

import gcs_sysid.parallel as par  # noqa: E402  (after T0: the imports count, as in bench_replay)
import gcs_sysid.pipeline as pl  # noqa: E402

_TCK = os.sysconf("SC_CLK_TCK")


def worker_cpu() -> float:
    """CPU seconds (user + system) of this process's children now (Linux ``/proc``; 0 where unreadable)."""
    total = 0.0
    try:
        for task in os.listdir("/proc/self/task"):
            with open(f"/proc/self/task/{task}/children") as f:
                kids = f.read().split()
            for pid in kids:
                with open(f"/proc/{pid}/stat") as f:
                    fields = f.read().rsplit(")", 1)[1].split()
                total += (int(fields[11]) + int(fields[12])) / _TCK
    except OSError:
        pass
    return total


def main_cpu() -> float:
    t = os.times()
    return t.user + t.system


def summary(base: str, new: str) -> None:
    """A Markdown table of two runs' files (line ``i`` of each: the ``i``-th pair): medians and the paired median
    difference of the wall time, each process's CPU seconds and peak memory, and of each stage's three numbers."""
    import statistics

    runs = [[json.loads(line) for line in open(f)] for f in (base, new)]
    pairs = list(zip(*runs))
    rows = [("replay wall s", lambda r: r["wall"]), ("main-process CPU s", lambda r: r["cpu_main"]),
            ("worker CPU s", lambda r: r["cpu_worker"]), ("main-process peak RSS MiB", lambda r: r["rss_main"])]
    for st in runs[0][0]["stages"]:
        for i, what in enumerate(("wall s", "main CPU s", "worker CPU s")):
            rows.append((f"{st}: {what}", lambda r, st=st, i=i: r["stages"][st][i]))
    print(f"{len(pairs)} pairs; load at the end of each run: base "
          + " ".join(f"{b['load']:.1f}" for b, _ in pairs) + ", new " + " ".join(f"{n['load']:.1f}" for _, n in pairs))
    print("| measure | base median | new median | paired new - base, median (new lower in) |\n|---|---:|---:|---:|")
    for name, f in rows:
        d = [f(n) - f(b) for b, n in pairs]
        print(f"| {name} | {statistics.median(f(b) for b, _ in pairs):.2f} | "
              f"{statistics.median(f(n) for _, n in pairs):.2f} | {statistics.median(d):+.2f} "
              f"({sum(x < 0 for x in d)} of {len(d)}) |")


def main() -> None:
    if sys.argv[1] == "--summary":
        summary(sys.argv[2], sys.argv[3])
        return
    stages: dict[str, list[float]] = {}
    jobs: list[list] = []
    stage_of = pl._stage

    @contextmanager
    def stage(name, timings, bar):
        w, c, k = time.perf_counter(), main_cpu(), worker_cpu()
        with stage_of(name, timings, bar) as progress:
            yield progress
        stages[name] = [time.perf_counter() - w, main_cpu() - c, worker_cpu() - k]

    submit, result = par.Helper.submit, par.Job.result

    def submitted(self, target, *args, **kwargs):
        job = submit(self, target, *args, **kwargs)
        job._rec = rec = [target.split(":")[-1], time.perf_counter() - T0, None, None, None]
        jobs.append(rec)
        if job._future is not None:
            job._future.add_done_callback(lambda f, rec=rec: rec.__setitem__(2, time.perf_counter() - T0))
        return job

    def collected(self):
        asked = time.perf_counter() - T0
        value = result(self)
        if getattr(self, "_rec", None) is not None:
            self._rec[3], self._rec[4] = asked, time.perf_counter() - T0
        return value

    pl._stage, par.Helper.submit, par.Job.result = stage, submitted, collected
    pl.run_replay(sys.argv[1], sys.argv[2], sys.argv[3], pl.ReplayOptions(progress=False))
    wall = time.perf_counter() - T0
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    print(json.dumps({"wall": wall, "stages": stages, "cpu_main": me.ru_utime + me.ru_stime,
                      "cpu_worker": kids.ru_utime + kids.ru_stime, "rss_main": me.ru_maxrss / 1024,
                      "load": os.getloadavg()[0], "jobs": jobs}))


if __name__ == "__main__":
    main()
