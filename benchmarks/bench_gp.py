"""Benchmark of the local + global GP (gcs_sysid.gp): fit and predict time and peak memory.

Prints, for N = 3000, 10000, 30000 rows of a synthetic 50 Hz flight (10 regressors, 6
coefficients, M = 128 inducing points): the cold fit (with JAX compilation), the median of
warm repeats of fit and of predict over all N rows, the held-out error, and each run's peak
resident memory (each N in its own process). Baseline in the same run: the exact dense GP
(same prior and hyperparameters, O((N P)^3)) against the sparse global layer on N = 1000
rows, time ratio and agreement. Also: inducing points chosen by mutual information vs
k-means vs random (VFE bound and held-out error, same hyperparameters). And the maneuver
ranking: 24 candidate trajectories of 64 rows, variance at 256 query rows, by the batched
closed-form ``global_variance_after_many`` against the exact ``variance_after`` per candidate
(baseline, same run), with their largest difference on the global layer.

Each worker runs as the replay pipeline does: one OpenBLAS thread (``limit_blas_threads``) and
the persistent compilation cache in a fresh, empty directory, so "cold fit" includes compiling.

Run: ``python benchmarks/bench_gp.py`` (``--quick`` for one repeat and N = 3000, 10000).
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import subprocess
import sys
import time
from dataclasses import replace

import numpy as np

DERIVATIVES = np.array([
    [-0.03, 0.25, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.10, 0.002],
    [0.0, 0.0, -0.35, 0.0, 0.0, 0.25, 0.0, 0.0, 0.15, 0.0, 0.0],
    [-0.25, -4.5, 0.0, 0.0, -6.0, 0.0, -0.35, 0.0, 0.0, 0.0, 0.0],
    [0.0, 0.0, -0.05, -0.45, 0.0, 0.10, 0.0, -0.20, 0.004, 0.0, 0.0],
    [0.02, -0.6, 0.0, 0.0, -12.0, 0.0, -1.1, 0.0, 0.0, 0.0, 0.0],
    [0.0, 0.0, 0.07, -0.03, 0.0, -0.12, 0.0, 0.01, -0.06, 0.0, 0.0],
])


def flight(n: int, seed: int = 0, rate_hz: float = 50.0):
    """Smooth sysid-like regressors ``(n, 10)`` and coefficients ``(n, 6)``: derivative model, stall-like
    bends, a beta^2 drag term and 3 % noise. Returns ``(X, Y_noisy, Y_true)``."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / rate_hz

    def smooth(scale, offset=0.0):
        f, ph = rng.uniform(0.02, 1.5, 6), rng.uniform(0, 2 * np.pi, 6)
        return offset + scale * np.sum(np.sin(2 * np.pi * f[:, None] * t + ph[:, None]), 0) / 2.5

    X = np.column_stack([
        smooth(np.radians(4.0), np.radians(4.0)), smooth(np.radians(3.0)), smooth(0.03), smooth(0.015),
        smooth(0.015), smooth(np.radians(4.0), np.radians(-2.0)), smooth(np.radians(4.0)), smooth(np.radians(3.0)),
        np.clip(smooth(0.15, 0.55), 0, 1), smooth(3.0, 18.0)])
    Yt = np.column_stack([np.ones(n), X]) @ DERIVATIVES.T
    alpha, beta = X[:, 0], X[:, 1]
    Yt[:, 0] += -2.0 * beta**2
    Yt[:, 2] += 30.0 * np.maximum(alpha - np.radians(8.0), 0.0) ** 2
    Yt[:, 4] += -0.3 * np.sin(alpha * 25.0) + 8.0 * np.maximum(alpha - np.radians(8.0), 0.0) ** 2
    return X, Yt + 0.03 * Yt.std(0) * rng.standard_normal(Yt.shape), Yt


def error_pct(est, ref):
    return 100 * np.sqrt(np.mean((est - ref) ** 2, 0)) / np.sqrt(np.mean(ref**2, 0))


def peak_rss_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def run_size(n: int, repeats: int) -> dict:
    """Fit on the first 80 % of ``n`` rows, predict all ``n``; held-out error on the last 20 %."""
    from gcs_sysid.gp import GPConfig, fit_gp

    X, Y, Yt = flight(n, seed=1)
    cut = int(0.8 * n)
    cfg = GPConfig(n_inducing=128)
    t = time.perf_counter()
    model, hist = fit_gp(X[:cut], Y[:cut], cfg)
    cold = time.perf_counter() - t
    fits, preds, stages = [], [], []
    for r in range(repeats):
        t = time.perf_counter()
        model, hist = fit_gp(X[:cut], Y[:cut], replace(cfg, seed=r))
        fits.append(time.perf_counter() - t)
        stages.append(hist.timings)
        t = time.perf_counter()
        mean, var = model.predict(X)
        preds.append(time.perf_counter() - t)
    mg, _ = model.predict_global(X[cut:])
    return {"n": n, "cold_fit_s": cold, "fit_s": statistics.median(fits), "predict_s": statistics.median(preds),
            "stages": {k: statistics.median(s[k] for s in stages) for k in stages[0]},
            "err_heldout_pct": error_pct(mean[cut:], Yt[cut:]).round(2).tolist(),
            "err_heldout_global_pct": error_pct(mg, Yt[cut:]).round(2).tolist(),
            "z2_heldout": float(np.mean((Y[cut:] - mean[cut:]) ** 2 / var[cut:])),
            "peak_rss_mib": peak_rss_mib()}


def run_baseline(n: int = 1000, repeats: int = 3) -> dict:
    """Exact dense GP vs sparse global layer with the same hyperparameters, same rows."""
    import jax
    import jax.numpy as jnp

    from gcs_sysid.gp import GPConfig, fit_gp
    from gcs_sysid.gp.batching import global_posterior, global_predict, global_stats
    from gcs_sysid.gp.exact import exact_predict

    X, Y, Yt = flight(n + 500, seed=2)
    model, _ = fit_gp(X[:n], Y[:n], GPConfig(n_inducing=128, local=False))
    Xs, Ys, Xq = model.scaler.x(X[:n]), model.scaler.y(Y[:n]), model.scaler.x(X[n:])
    p = model.params
    exact = jax.jit(exact_predict)

    def sparse_run():
        post = global_posterior(p, global_stats(p, Xs, Ys, 2048))
        return global_predict(p, post, Xq, 2048)

    def exact_run():
        return jax.block_until_ready(exact(p, jnp.asarray(Xs), jnp.asarray(Ys), jnp.asarray(Xq)))

    out = {}
    for name, fn in (("sparse", sparse_run), ("exact", exact_run)):
        fn()  # compile
        times = []
        for _ in range(repeats):
            t = time.perf_counter()
            res = fn()
            times.append(time.perf_counter() - t)
        out[name] = (statistics.median(times), np.asarray(res[0]), np.asarray(res[1]))
    (ts, ms, vs), (te, me, ve) = out["sparse"], out["exact"]
    back = model.scaler.y_std
    return {"n": n, "sparse_s": ts, "exact_s": te, "ratio_exact_over_sparse": te / ts,
            "sparse_err_pct": error_pct(ms * back + model.scaler.y_mean, Yt[n:]).round(2).tolist(),
            "exact_err_pct": error_pct(me * back + model.scaler.y_mean, Yt[n:]).round(2).tolist(),
            "max_sd_ratio_sparse_over_exact": float(np.max(np.sqrt(vs / ve))),
            "min_sd_ratio_sparse_over_exact": float(np.min(np.sqrt(vs / ve)))}


def run_selection(n: int = 3000, m: int = 64) -> dict:
    """VFE bound and held-out error of the global layer for three ways of choosing ``m`` inducing points."""
    import jax.numpy as jnp

    from gcs_sysid.gp import GPConfig, fit_gp
    from gcs_sysid.gp.batching import global_posterior, global_predict, global_stats
    from gcs_sysid.gp.selection import select_inducing
    from gcs_sysid.gp.sparse import GlobalParams, elbo

    X, Y, Yt = flight(n, seed=3)
    cut = int(0.8 * n)
    model, _ = fit_gp(X[:cut], Y[:cut], GPConfig(n_inducing=m, local=False))
    Xs, Ys = model.scaler.x(X[:cut]), model.scaler.y(Y[:cut])
    out = {}
    for method in ("mi", "kmeans", "random"):
        vals, errs = [], []
        for seed in range(3):
            t = time.perf_counter()
            Z = select_inducing(Xs, m, np.asarray(model.params.lengthscale), method, seed=seed)
            dt = time.perf_counter() - t
            p = GlobalParams(**{**model.params.__dict__, "Z": jnp.asarray(Z)})
            st = global_stats(p, Xs, Ys, 2048)
            mean, _ = global_predict(p, global_posterior(p, st), model.scaler.x(X[cut:]), 2048)
            vals.append(float(elbo(p, st)))
            errs.append(float(np.mean(error_pct(mean * model.scaler.y_std + model.scaler.y_mean, Yt[cut:]))))
        out[method] = {"elbo_median": statistics.median(vals), "mean_err_pct_median": statistics.median(errs),
                       "select_s": dt}
    return out


def run_ranking(n: int = 10000, candidates: int = 24) -> dict:
    """Batched global-layer ranking vs one exact ``variance_after`` per candidate."""
    from gcs_sysid.gp import GPConfig, fit_gp

    X, Y, _ = flight(n, seed=3)
    model, _ = fit_gp(X, Y, GPConfig())
    rng = np.random.default_rng(5)
    extras = [X[i:i + 64] + 0.5 * X.std(0) * rng.standard_normal(10) for i in rng.choice(n - 64, candidates)]
    query = X[rng.choice(n, 256)] + X.std(0)
    model.global_variance_after_many(extras[:1], [query])          # warm (compiles nothing; numpy)
    t = time.perf_counter()
    out = model.global_variance_after_many(extras, [query] * candidates)
    batched = time.perf_counter() - t
    model.variance_after(extras[0], query)                          # compile outside the timing
    times, diffs = [], []
    for k in range(3):
        t = time.perf_counter()
        model.variance_after(extras[k], query)
        times.append(time.perf_counter() - t)
        ref = model.update(extras[k], np.zeros((64, 6)), exchange=False).predict_global(query, include_noise=False)[1]
        diffs.append(float(np.max(np.abs(out[k][1] - ref) / ref)))
    per = statistics.median(times)
    return {"candidates": candidates, "batched_s": batched, "exact_per_candidate_s": per,
            "exact_all_s_estimate": per * candidates, "ratio": per * candidates / batched,
            "max_rel_diff_global": max(diffs)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    from gcs_sysid.jaxconfig import enable_compilation_cache, enable_x64, limit_blas_threads

    enable_x64()
    if args.worker:
        import tempfile

        limit_blas_threads(1)
        enable_compilation_cache(tempfile.mkdtemp(prefix="gcs-sysid-bench-jax-"))
        kind, value = args.worker.split(":")
        res = {"size": lambda: run_size(int(value), args.repeats), "baseline": lambda: run_baseline(int(value)),
               "selection": lambda: run_selection(int(value)), "ranking": lambda: run_ranking(int(value))}[kind]()
        res["peak_rss_mib"] = peak_rss_mib()
        print(json.dumps(res))
        return
    sizes = (3000, 10000) if args.quick else (3000, 10000, 30000)
    repeats = 1 if args.quick else args.repeats
    jobs = [("baseline", 1000)] + [("size", n) for n in sizes] + [("selection", 3000), ("ranking", 10000)]
    results = {}
    for kind, value in jobs:
        out = subprocess.run([sys.executable, __file__, "--worker", f"{kind}:{value}", "--repeats", str(repeats)],
                             capture_output=True, text=True, check=True)
        results[f"{kind}:{value}"] = res = json.loads(out.stdout.strip().splitlines()[-1])
        print(f"{kind} {value}: {json.dumps(res)}", flush=True)
    print("\nsummary")
    b = results["baseline:1000"]
    print(f"  N=1000 condition+predict 500: exact dense {b['exact_s']:.3f} s, sparse M=128 {b['sparse_s']:.3f} s, "
          f"ratio {b['ratio_exact_over_sparse']:.1f}x; held-out error exact {b['exact_err_pct']} "
          f"sparse {b['sparse_err_pct']}")
    for n in sizes:
        r = results[f"size:{n}"]
        print(f"  N={n:>6}: cold fit {r['cold_fit_s']:.1f} s, fit {r['fit_s']:.1f} s (median of {repeats}), "
              f"predict {r['predict_s']:.2f} s, peak RSS {r['peak_rss_mib']:.0f} MiB, "
              f"held-out error % {r['err_heldout_pct']}")
    s = results["selection:3000"]
    for k, v in ((k, v) for k, v in s.items() if isinstance(v, dict)):
        print(f"  inducing by {k:>6}: ELBO {v['elbo_median']:.1f}, "
              f"mean held-out error {v['mean_err_pct_median']:.2f} %")
    r = results["ranking:10000"]
    print(f"  ranking {r['candidates']} maneuvers: batched {r['batched_s']:.3f} s, exact variance_after "
          f"{r['exact_per_candidate_s']:.3f} s each (~{r['exact_all_s_estimate']:.1f} s), ratio {r['ratio']:.0f}x, "
          f"largest relative difference on the global layer {r['max_rel_diff_global']:.1e}")


if __name__ == "__main__":
    main()
