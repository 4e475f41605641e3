"""Benchmark of the bounded streaming GP (``LocalGlobalGP.update``): update cost, memory over a long
stream, and the envelope-expansion case against a full refit.

Three jobs, each in its own process as the pipeline runs (one OpenBLAS thread, compilation cache in a
fresh directory):

* ``latency``: a model with M = 256 inducing points (fitted on 3,000 rows of the synthetic 50 Hz flight
  of ``bench_gp.py``) is updated with 50-row batches (1 s of data each) from further along the flight;
  per call: median and 95th percentile latency of ``update`` and the per-sample amortised cost; then the
  latency of the first prediction after an update (the posterior is refactored lazily there, once per
  prediction, ``O((P M)^3)``) and of a hyperparameter refresh.
* ``soak``: one hour at 50 rows/s of synthetic coefficient rows (180,000 rows, ``--rows``) streamed in
  50-row batches into a default-budget model (M = 128, ``store_max`` 30,000 rows, hyperparameters
  refreshed every 60,000 rows); at ten points: resident memory (VmRSS), rows stored, saved-state size,
  and the held-out error on the last 2,000 rows of the flight; the update cost per sample over the run.
* ``refresh``: the envelope case's streamed model refreshed under several budgets (the full
  ``refresh_hyperparameters`` and :func:`gcs_sysid.gp.streaming.light_refresh` budgets): CPU seconds and
  held-out error in the new region against the refit.
* ``envelope``: fit on the envelope flown (alpha below its 70th percentile, 20,000 rows), stream the
  new region's rows (50-row batches), then one hyperparameter refresh, against ``fit_gp`` on all rows
  (the baseline, same run): held-out error in the new region and CPU seconds of each step.

Run: ``python benchmarks/bench_gp_stream.py`` (``--quick``: 36,000 soak rows; ``--only latency --gp-noise learned``: the
latency job with the replay's noise, whose cost the twenty-sixth session compared with the default `independent`).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_gp import error_pct, flight  # noqa: E402


def rss_mib() -> float:
    """Current resident memory of this process (VmRSS), MiB."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def run_latency(calls: int = 60, gp_noise: str = "independent") -> dict:
    """The ``latency`` job; ``gp_noise``: the GP's noise by name (:func:`gcs_sysid.pipeline.gp_noise_fields`;
    ``independent``, ``GPConfig()``'s, is the live learner's default, ``learned`` the replay's)."""
    from gcs_sysid.gp import GPConfig, fit_gp
    from gcs_sysid.gp.streaming import light_refresh
    from gcs_sysid.pipeline import gp_noise_fields

    X, Y, _ = flight(3000 + 50 * calls + 1000, seed=4)
    t = time.process_time()
    model, _ = fit_gp(X[:3000], Y[:3000], GPConfig(n_inducing=256, **gp_noise_fields(gp_noise)))
    fit_cpu = time.process_time() - t
    model.predict(X[:10])
    lat, swaps = [], 0
    Z0 = np.asarray(model.params.Z)
    for k in range(calls):
        a = 3000 + 50 * k
        t = time.perf_counter()
        model = model.update(X[a:a + 50], Y[a:a + 50])
        lat.append(time.perf_counter() - t)
    swaps = int(np.sum(np.any(np.asarray(model.params.Z) != Z0, 1)))
    model.predict(X[-1000:])                     # compile the 1000-row prediction
    model = model.update(X[-1050:-1000], Y[-1050:-1000])
    t = time.perf_counter()
    model.predict(X[-1000:])                     # refactors the posterior, rebuilds the local tree
    first_predict = time.perf_counter() - t
    t = time.perf_counter()
    model.predict(X[-1000:])
    next_predict = time.perf_counter() - t
    t = time.perf_counter()
    model.refresh_hyperparameters()
    refresh = time.perf_counter() - t
    light = []
    for _ in range(3):      # the live learner's refresh (every LearnOptions.hyper_every rows); the first compiles
        t = time.perf_counter()
        light_refresh(model)
        light.append(time.perf_counter() - t)
    warm = lat[5:]          # the first calls compile the update's programs
    return {"gp_noise": gp_noise, "fit_3000_cpu_s": fit_cpu, "light_refresh_s": statistics.median(light[1:]),
            "M": 256, "batch_rows": 50, "calls": calls, "update_median_ms": 1e3 * statistics.median(warm),
            "update_p95_ms": 1e3 * float(np.percentile(warm, 95)), "update_max_ms": 1e3 * max(warm),
            "per_sample_median_ms": 1e3 * statistics.median(warm) / 50,
            "per_sample_mean_ms": 1e3 * float(np.mean(warm)) / 50,
            "inducing_points_moved": swaps, "first_predict_1000_s": first_predict,
            "next_predict_1000_s": next_predict, "refresh_s": refresh}


def run_soak(rows: int) -> dict:
    from gcs_sysid.gp import GPConfig, fit_gp

    X, Y, Yt = flight(rows + 5000, seed=6)
    test = slice(rows + 3000, rows + 5000)
    cfg = GPConfig(hyper_every=60000)
    model, _ = fit_gp(X[:3000], Y[:3000], cfg)
    tmp = Path(tempfile.mkdtemp(prefix="gcs-sysid-soak-"))
    points, times = [], []
    marks = set(np.linspace(3000, rows + 3000, 11).astype(int)[1:])
    t0 = time.perf_counter()
    for a in range(3000, rows + 3000, 50):
        t = time.perf_counter()
        model = model.update(X[a:a + 50], Y[a:a + 50])
        times.append(time.perf_counter() - t)
        if any(a < m <= a + 50 for m in marks):
            mean = model.predict(X[test])[0]
            path = model.save(tmp / "gp")
            points.append({"rows_seen": a + 50, "rss_mib": rss_mib(), "rows_stored": len(model.rows),
                           "saved_kib": (os.path.getsize(path) + os.path.getsize(tmp / "gp.json")) / 1024,
                           "mean_err_pct": float(np.mean(error_pct(mean, Yt[test]))),
                           "elapsed_s": time.perf_counter() - t0})
            print(json.dumps(points[-1]), file=sys.stderr, flush=True)
    return {"rows": rows, "points": points, "update_per_sample_median_ms": 1e3 * statistics.median(times) / 50,
            "update_p99_ms": 1e3 * float(np.percentile(times, 99)), "update_max_s": max(times),
            "rss_growth_mib_after_first_point": points[-1]["rss_mib"] - points[0]["rss_mib"]}


def envelope_split(n: int):
    """The envelope-expansion case: ``(X, Y, Yt, flown, test, train_new)``; the envelope flown is alpha
    below its 70th percentile, the new region above it (every 4th row held out, the rest streamed)."""
    X, Y, Yt = flight(n, seed=7)
    flown = X[:, 0] < np.quantile(X[:, 0], 0.7)
    new = np.flatnonzero(~flown)
    test = new[::4]
    return X, Y, Yt, flown, test, np.setdiff1d(new, test)


def run_envelope(n: int = 28600) -> dict:
    from gcs_sysid.gp import GPConfig, fit_gp

    X, Y, Yt, flown, test, train_new = envelope_split(n)
    model, _ = fit_gp(X[flown], Y[flown], GPConfig())
    before = error_pct(model.predict(X[test])[0], Yt[test])
    c0, t0 = time.process_time(), time.perf_counter()
    for a in range(0, len(train_new), 50):
        r = train_new[a:a + 50]
        model = model.update(X[r], Y[r])
    mean = model.predict(X[test])[0]
    stream_cpu, stream_wall = time.process_time() - c0, time.perf_counter() - t0
    streamed = error_pct(mean, Yt[test])
    from gcs_sysid.gp.streaming import RefreshBudget, light_refresh

    light = {}
    for name, budget in (("light", RefreshBudget()), ("light_reselect", RefreshBudget(reselect=True))):
        light_refresh(model, RefreshBudget(steps=2, rows=budget.rows, local_steps=2))   # compile its shapes
        c0, t0 = time.process_time(), time.perf_counter()
        lm = light_refresh(model, budget)
        lmean = lm.predict(X[test])[0]
        light[name] = {"cpu_s": time.process_time() - c0, "wall_s": time.perf_counter() - t0,
                       "err_pct": error_pct(lmean, Yt[test]), "budget": budget.__dict__}
    c0, t0 = time.process_time(), time.perf_counter()
    model = model.refresh_hyperparameters()
    mean = model.predict(X[test])[0]
    refresh_cpu, refresh_wall = time.process_time() - c0, time.perf_counter() - t0
    refreshed = error_pct(mean, Yt[test])
    c0, t0 = time.process_time(), time.perf_counter()
    refit, _ = fit_gp(np.vstack([X[flown], X[train_new]]), np.vstack([Y[flown], Y[train_new]]), GPConfig())
    mean = refit.predict(X[test])[0]
    refit_cpu, refit_wall = time.process_time() - c0, time.perf_counter() - t0
    full = error_pct(mean, Yt[test])
    return {"rows_flown": int(flown.sum()), "rows_new": len(train_new), "held_out_new": len(test),
            "err_before_pct": before.round(2).tolist(), "err_streamed_pct": streamed.round(2).tolist(),
            "err_refreshed_pct": refreshed.round(2).tolist(), "err_refit_pct": full.round(2).tolist(),
            "ratio_streamed": float(streamed.mean() / full.mean()),
            "ratio_refreshed": float(refreshed.mean() / full.mean()),
            "stream_cpu_s": stream_cpu, "stream_wall_s": stream_wall, "refresh_cpu_s": refresh_cpu,
            "refresh_wall_s": refresh_wall, "refit_cpu_s": refit_cpu, "refit_wall_s": refit_wall,
            "refresh_over_refit_cpu": refresh_cpu / refit_cpu,
            **{f"{k}_{f}": (v[f].round(2).tolist() if f == "err_pct" else v[f]) for k, v in light.items()
               for f in ("cpu_s", "wall_s", "err_pct", "budget")},
            **{f"{k}_ratio_to_refit": float(v["err_pct"].mean() / full.mean()) for k, v in light.items()},
            **{f"{k}_cpu_over_refit": v["cpu_s"] / refit_cpu for k, v in light.items()}}


def run_refresh_grid(n: int = 28600) -> dict:
    """The envelope case's streamed model refreshed under several budgets (CPU s and error against a refit)."""
    from gcs_sysid.gp import GPConfig, fit_gp
    from gcs_sysid.gp.streaming import RefreshBudget, light_refresh

    X, Y, Yt, flown, test, train_new = envelope_split(n)
    model, _ = fit_gp(X[flown], Y[flown], GPConfig())
    for a in range(0, len(train_new), 50):
        r = train_new[a:a + 50]
        model = model.update(X[r], Y[r])
    model.predict(X[test])
    c0 = time.process_time()
    refit, _ = fit_gp(np.vstack([X[flown], X[train_new]]), np.vstack([Y[flown], Y[train_new]]), GPConfig())
    refit_cpu = time.process_time() - c0
    full = error_pct(refit.predict(X[test])[0], Yt[test])
    out = {"refit_cpu_s": refit_cpu, "err_refit_pct": full.round(2).tolist(), "variants": []}
    variants = [None, RefreshBudget(), RefreshBudget(40, 400, 40), RefreshBudget(80, 400, 40),
                RefreshBudget(20, 1000, 40), RefreshBudget(40, 400, 10), RefreshBudget(40, 400, 0)]
    for b in variants:
        if b is not None:   # compile this budget's shapes first
            light_refresh(model, RefreshBudget(2, b.rows, min(2, b.local_steps)))
        c0 = time.process_time()
        m2 = model.refresh_hyperparameters() if b is None else light_refresh(model, b)
        cpu = time.process_time() - c0
        e = error_pct(m2.predict(X[test])[0], Yt[test])
        out["variants"].append({"budget": "full" if b is None else b.__dict__, "cpu_s": cpu,
                                "cpu_over_refit": cpu / refit_cpu, "err_pct": e.round(2).tolist(),
                                "err_over_refit": float(e.mean() / full.mean())})
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--rows", type=int, default=180000)
    ap.add_argument("--only", choices=("latency", "soak", "envelope", "refresh"))
    ap.add_argument("--gp-noise", default="independent", help="the latency job's GP noise (a name of "
                    "gcs_sysid.pipeline.GP_NOISE_MODES; default independent, the live learner's)")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        from gcs_sysid.jaxconfig import enable_compilation_cache, enable_x64, limit_blas_threads

        enable_x64()
        limit_blas_threads(1)
        enable_compilation_cache(tempfile.mkdtemp(prefix="gcs-sysid-bench-jax-"))
        kind, value = args.worker.split(":")
        res = {"latency": lambda: run_latency(gp_noise=value or "independent"), "soak": lambda: run_soak(int(value)),
               "envelope": lambda: run_envelope(), "refresh": lambda: run_refresh_grid()}[kind]()
        res["peak_rss_mib"] = __import__("resource").getrusage(__import__("resource").RUSAGE_SELF).ru_maxrss / 1024
        print(json.dumps(res))
        return
    rows = 36000 if args.quick else args.rows
    jobs = [("latency", args.gp_noise), ("envelope", 0), ("refresh", 0), ("soak", rows)]
    if args.only:
        jobs = [j for j in jobs if j[0] == args.only]
    for kind, value in jobs:
        out = subprocess.run([sys.executable, __file__, "--worker", f"{kind}:{value}"], capture_output=True, text=True,
                             check=True)
        res = json.loads(out.stdout.strip().splitlines()[-1])
        print(f"{kind}: {json.dumps(res)}", flush=True)
        if kind == "latency":
            print(f"  update of 50 rows at M=256: median {res['update_median_ms']:.1f} ms, "
                  f"p95 {res['update_p95_ms']:.1f} ms"
                  f" -> {res['per_sample_median_ms']:.3f} ms per sample (mean {res['per_sample_mean_ms']:.3f});"
                  f" predict 1000 rows after an update {res['first_predict_1000_s']:.2f} s (posterior + tree), again"
                  f" {res['next_predict_1000_s']:.2f} s; refresh {res['refresh_s']:.1f} s, light "
                  f"{res['light_refresh_s']:.1f} s; fit on 3,000 rows {res['fit_3000_cpu_s']:.1f} CPU s "
                  f"({res['gp_noise']})")
        elif kind == "envelope":
            print(f"  new region: before {res['err_before_pct']}, streamed {res['err_streamed_pct']} (mean ratio to "
                  f"refit {res['ratio_streamed']:.2f}, CPU {res['stream_cpu_s']:.1f} s for {res['rows_new']} rows), "
                  f"+ refresh "
                  f"{res['err_refreshed_pct']} (ratio {res['ratio_refreshed']:.2f}, CPU {res['refresh_cpu_s']:.1f} s), "
                  f"full refit {res['err_refit_pct']} (CPU {res['refit_cpu_s']:.1f} s)")
            for k in ("light", "light_reselect"):
                print(f"  {k} refresh {res[k + '_budget']}: {res[k + '_err_pct']} (ratio to refit "
                      f"{res[k + '_ratio_to_refit']:.2f}), CPU {res[k + '_cpu_s']:.2f} s = "
                      f"{res[k + '_cpu_over_refit']:.2f} of the refit "
                      f"(full refresh: {res['refresh_over_refit_cpu']:.2f})")
        elif kind == "refresh":
            for v in res["variants"]:
                print(f"  refresh {v['budget']}: {v['err_pct']} (error / refit {v['err_over_refit']:.2f}), CPU "
                      f"{v['cpu_s']:.2f} s = {v['cpu_over_refit']:.2f} of the refit ({res['refit_cpu_s']:.2f} s)")
        else:
            for p in res["points"]:
                print(f"  {p['rows_seen']:>7} rows: RSS {p['rss_mib']:.0f} MiB, stored {p['rows_stored']}, saved "
                      f"{p['saved_kib']:.0f} KiB, held-out mean error {p['mean_err_pct']:.2f} %, "
                      f"{p['elapsed_s']:.0f} s")


if __name__ == "__main__":
    main()
