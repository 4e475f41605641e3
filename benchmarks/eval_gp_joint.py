"""When does the joint (coregionalised) GP beat six independent GPs? Learning curve, heterotopic rows,
correlated gust noise, against JSBSim's exact truth (issue 8 item 3).

Uses the cached flights of ``benchmarks/eval_gp_jsbsim.py`` (``--make`` there, or here: the same
``.npz`` files, same harness, same replay). For each flight the training rows (the first 80 % of the
flight, as the replay takes them) are cut to their first ``L`` seconds (``--lengths``; ``0`` means all,
72 s of a 90-s flight): a shorter log, contiguous in time as a log gives it. On those rows:

  pattern ``none`` (isotopic: every coefficient on every row)
    ``joint``    ``fit_gp(X, Y, GPConfig())``: the replay's model (ICM, one noise variance per output,
                 input noise, blocked validation)
    ``jointa``   ``joint`` with ``GPConfig(output_groups="axes")``: each shared factor of ``B`` on the
                 longitudinal (CX CZ Cm) or the lateral-directional (CY Cl Cn) outputs only
    ``jointk``   ``joint`` with ``GPConfig(output_groups="kernels")``: one latent kernel (own length-scales)
                 per axis, loading on that axis's outputs only
    ``jointf``   ``joint`` with ``GPConfig(output_groups="kernels-free")``: the same kernels, loadings free
    ``jointo``   ``joint`` with ``GPConfig(output_groups="output-kernels")``: one kernel per output, its latent
                 loading on that output's axis
    ``jointn``   the same with the full 6 x 6 noise covariance in the likelihood
                 (``GPConfig.noise_correlation``: the gusts' correlated error between outputs)
    ``dec``      ``joint`` with its cross-output coupling removed after the fit (``gp.joint.decoupled_model``:
                 ``B`` diagonal, every other hyperparameter kept): ``joint - dec`` is what the coupling does
    ``jointnf``  ``jointn`` with the shared error started in the noise (``GPConfig.noise_start = "noise"``:
                 ``B`` starts diagonal, the noise correlation at the ridge residual's)
    ``jointnt``  ``jointn`` with the hyperparameters learned on every 10th training row (``GPConfig.hyper_stride``:
                 0.2 s apart at 50 Hz, where the gusts' coloured error is less alike)
    ``decntc``   ``GPConfig(noise_correlation=True, hyper_stride=10, coupling="off")``: ``decnt`` with the coupling
                 removed inside the fit (before the blocked validation and the posterior), eighteenth session
    ``decnta``   the same with the stride from the training residual's decorrelation time (``hyper_stride=0``;
                 ``pipeline.DECORRELATED_GP``)
    ``decn``     the same for ``jointn`` (``B`` and the noise covariance diagonal); ``decnf`` for ``jointnf``,
                 ``decnt`` for ``jointnt``
    ``indep``    six one-output GPs, ``GPConfig()`` each (each its own length-scales and noise)
    ``jointsel`` per output ``joint`` or that output's ``indep`` GP, whichever has the lower blocked
                 cross-validation error on the training rows (``gp.joint.select_outputs``, 5 time blocks,
                 margin 1, hyperparameters those of the fits on all training rows: ``fit_selected``'s
                 ``hyper="fixed"``); needs ``joint`` and ``indep``
    ``jointself`` ``jointsel`` with only the forces (CX CY CZ) free to leave the joint model; the moments keep it
                 (``select_outputs(outputs=(0, 1, 2))``)
    ``jointse``  the same blocked errors, the one-standard-error rule: ``joint`` unless the output's own GP
                 is better by more than one standard error of the five blocks' differences
                 (``select_outputs(rule="1se")``)
    ``jointfwd`` the same choice by the forward error with every hyperparameter learned again
                 (``gp.joint.forward_errors``: ``joint`` and each ``indep`` GP refitted on the first 80 % of
                 the training rows, scored on the last 20 %; ``fit_selected``'s default); needs ``joint``, ``indep``
    ``lmc``      (``--lmc``) ``GPConfig(latent_kernels=2)``: two latent kernels, per-output length-scales
  pattern ``rates`` / ``block`` (heterotopic: the moments Cl Cm Cn removed on 30 % of those rows,
  ``eval_gp_jsbsim.missing_rows``: the fastest rates, as a rejected angular-acceleration estimate;
  or the 35-65 % stretch of the time, a dropout of the gyro stream)
    ``hjoint``   the joint GP on every row, moments missing where removed (what the pipeline does,
                 ``pipeline.training_rows``)
    ``hdec``     ``hjoint`` decoupled after the fit
    ``hdrop``    the joint GP on the complete rows only (a row with a missing coefficient dropped)
    ``hindep``   six one-output GPs, each on the rows that carry its coefficient (the forces' GPs are
                 those of ``indep``: the same rows)

Scores (one JSON line per flight, length, pattern and model): ``err`` the held-out error
``100 RMS(mean - truth) / RMS(truth)`` per coefficient on the held-out last 20 % (never trained on),
``err_gap`` on the training rows whose moments were removed (the gap the joint model fills from the
forces of the same rows); for the joint models ``corr_learned`` and the truth's output correlation with
the flags of ``eval_gp_jsbsim._correlations`` (learned ``|corr| > 0.5`` where the truth's nonlinear
parts correlate below 0.2). ``--summarize`` prints the pair counts (better / worse by more than 0.05
points / within) and medians per length, turbulence and pattern.

Usage::

    python benchmarks/eval_gp_joint.py --cache DIR --aircraft c172x pa28 t37 --seeds 1 2 \\
        --turbulence light moderate --lengths 10 20 40 0 --json J.jsonl
    python benchmarks/eval_gp_joint.py --summarize J.jsonl
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.eval_common import append_jsonl  # noqa: E402
from benchmarks.eval_gp_jsbsim import (  # noqa: E402
    CARRIES, MOMENTS, TRUTH_NONE, _correlations, add_flight_args, errors, make, missing_rows)
from gcs_sysid.aero.table import COEFFICIENTS  # noqa: E402
from gcs_sysid.gp import GPConfig, fit_gp  # noqa: E402
from gcs_sysid.gp.joint import SelectedOutputs, decoupled_model, forward_errors, select_outputs  # noqa: E402

PATTERNS = ("none", "rates", "block")
ISO_MODELS = ("joint", "joint0", "jointv", "jointvn", "jointa", "jointk", "jointf", "jointo", "jointn", "jointnf",
              "jointnt", "dec", "decn", "decnf", "decnt", "decntc", "decnta", "indep", "jointsel", "jointself",
              "jointse", "jointfwd", "lmc")
HET_MODELS = ("hjoint", "hdec", "hdrop", "hindep")
#: the comparisons ``--summarize`` counts: (model, against, pattern)
PAIRS = (("joint", "indep", "none"), ("joint0", "indep", "none"), ("joint", "joint0", "none"),
         ("jointv", "indep", "none"), ("jointv", "joint", "none"),
         ("jointvn", "indep", "none"), ("jointvn", "joint", "none"),
         ("jointself", "indep", "none"), ("jointself", "joint", "none"),
         ("jointse", "indep", "none"), ("jointse", "joint", "none"),
         ("jointfwd", "indep", "none"), ("jointfwd", "joint", "none"),
         ("jointsel", "indep", "none"), ("jointsel", "joint", "none"),
         ("jointa", "indep", "none"), ("jointa", "joint", "none"),
         ("jointk", "indep", "none"), ("jointk", "joint", "none"),
         ("jointf", "indep", "none"), ("jointf", "joint", "none"),
         ("jointo", "indep", "none"), ("jointo", "joint", "none"),
         ("jointn", "indep", "none"), ("jointnf", "indep", "none"), ("jointnf", "joint", "none"),
         ("jointnf", "jointn", "none"), ("jointnf", "decnf", "none"),
         ("jointnt", "indep", "none"), ("jointnt", "joint", "none"), ("jointnt", "jointn", "none"),
         ("jointnt", "decnt", "none"), ("decnt", "indep", "none"), ("decnt", "joint", "none"),
         ("decntc", "indep", "none"), ("decntc", "joint", "none"), ("decnta", "indep", "none"),
         ("decnta", "joint", "none"), ("decnta", "decntc", "none"), ("lmc", "indep", "none"),
         ("joint", "dec", "none"), ("jointn", "decn", "none"), ("jointn", "joint", "none"),
         ("hjoint", "hindep", "rates"), ("hjoint", "hdec", "rates"), ("hjoint", "hdrop", "rates"),
         ("hjoint", "hindep", "block"), ("hjoint", "hdec", "block"), ("hjoint", "hdrop", "block"))


def first_seconds(t: np.ndarray, tr: np.ndarray, length: float) -> np.ndarray:
    """The training rows ``tr`` ``(N,)`` within ``length`` s of the first one (``length <= 0``: all)."""
    if length <= 0:
        return tr.copy()
    t0 = t[tr][0]
    return tr & (t <= t0 + length)


def _selected_correlations(sel, joint_corr: dict) -> dict:
    """``joint_corr`` (:func:`_correlations` of the joint model) with the learned correlation of the selected
    model (``SelectedOutputs.output_correlation``: 0 for an output predicted by its own GP) and its flags."""
    learned = sel.output_correlation()
    P = learned.shape[0]
    truth = np.asarray(joint_corr["truth"]["signal_corr"]).reshape(P, P)
    latent, noise = np.asarray(joint_corr["latent_std"]), np.asarray(joint_corr["noise_std"])
    carries = latent >= CARRIES * noise
    flags = [(i, j) for i in range(P) for j in range(i + 1, P)
             if abs(learned[i, j]) > 0.5 and abs(truth[i, j]) < TRUTH_NONE]
    name = lambda i, j: f"{COEFFICIENTS[i]}-{COEFFICIENTS[j]}"  # noqa: E731
    return dict(joint_corr, corr_learned=[float(f"{x:.4g}") for x in learned.ravel()],
                flags=[name(i, j) for i, j in flags],
                flags_carrying=[name(i, j) for i, j in flags if carries[i] and carries[j]],
                use_joint=[bool(u) for u in sel.use_joint],
                cv_ratio=[float(f"{x:.4g}") for x in sel.err_joint / sel.err_indep])


def _pred(model, X):
    return model.predict(X, include_noise=False)[0]


def score(path: Path, lengths, patterns, lmc: bool = False, models=ISO_MODELS):
    """Every model on one cached flight; yields one JSON-able dict per length, pattern and model
    (isotopic rows: those of ``models`` only; ``dec``/``decn`` need ``joint``/``jointn``)."""
    d = np.load(path)
    t, X, Y, Xt, Yt = d["t"], d["X"], d["Y"], d["Xt"], d["Yt"]
    ok = d["valid"] & np.isfinite(Yt).all(1) & np.isfinite(X).all(1)
    tr_all = d["train"] & np.isfinite(Y).all(1) & np.isfinite(X).all(1)
    h = d["held"] & ok
    meta = dict(zip(("aircraft", "seed", "turbulence", "aoa"), path.stem.split("-")))
    base = GPConfig()
    P = Y.shape[1]
    models_wanted = set(models)
    for length in lengths:
        tr = first_seconds(t, tr_all, length)
        info = dict(meta, length=float(length), n_train=int(tr.sum()),
                    span_s=round(float(t[tr][-1] - t[tr][0]), 2))
        indep: list = []
        for pattern in patterns:
            models: dict = {}
            times: dict = {}
            corr: dict = {}
            gone = np.zeros(len(X), bool)
            if pattern == "none":
                for v, cfg in (("joint", base), ("joint0", replace(base, coupling_validation=False)),
                               ("jointv", replace(base, coupling_validation=True)),
                               ("jointvn", replace(base, coupling_validation=True, noise_correlation=True)),
                               ("jointa", replace(base, output_groups="axes")),
                               ("jointk", replace(base, output_groups="kernels")),
                               ("jointf", replace(base, output_groups="kernels-free")),
                               ("jointo", replace(base, output_groups="output-kernels")),
                               ("jointn", replace(base, noise_correlation=True)),
                               ("jointnf", replace(base, noise_correlation=True, noise_start="noise")),
                               ("jointnt", replace(base, noise_correlation=True, hyper_stride=10)),
                               ("decntc", replace(base, noise_correlation=True, hyper_stride=10, coupling="off")),
                               ("decnta", replace(base, noise_correlation=True, hyper_stride=0, coupling="off")),
                               ("lmc", replace(base, latent_kernels=2))):
                    if (v == "lmc" and not lmc) or v not in models_wanted:
                        continue
                    t0 = time.perf_counter()
                    models[v], hist = fit_gp(X[tr], Y[tr], cfg)
                    times[v] = time.perf_counter() - t0
                    corr[v] = _correlations(models[v], X[tr], Xt[tr], Yt[tr])
                    for k in ("coupled", "ratio", "noise_coupled", "noise_ratio"):   # the coupling gate's choice
                        if k in hist.validation:
                            corr[v]["gate_" + k] = hist.validation[k]
                for v, src in (("dec", "joint"), ("decn", "jointn"), ("decnf", "jointnf"), ("decnt", "jointnt")):
                    if v in models_wanted and src in models:
                        models[v], times[v] = decoupled_model(models[src]), 0.0
                preds = {v: _pred(m, X[h]) for v, m in models.items()}
                if "indep" in models_wanted:
                    t0 = time.perf_counter()
                    indep = [fit_gp(X[tr], Y[tr][:, [p]], base, output_names=[COEFFICIENTS[p]])[0] for p in range(P)]
                    times["indep"] = time.perf_counter() - t0
                    preds["indep"] = np.column_stack([_pred(m, X[h])[:, 0] for m in indep])
                if "jointsel" in models_wanted and "joint" in models and indep:
                    t0 = time.perf_counter()
                    sel = select_outputs(models["joint"], indep, X[tr], Y[tr])
                    times["jointsel"] = times["joint"] + times["indep"] + time.perf_counter() - t0
                    preds["jointsel"] = sel.predict(X[h], include_noise=False)[0]
                    corr["jointsel"] = _selected_correlations(sel, corr["joint"])
                if "jointself" in models_wanted and "joint" in models and indep:
                    t0 = time.perf_counter()
                    sel = select_outputs(models["joint"], indep, X[tr], Y[tr], outputs=(0, 1, 2))
                    times["jointself"] = times["joint"] + times["indep"] + time.perf_counter() - t0
                    preds["jointself"] = sel.predict(X[h], include_noise=False)[0]
                    corr["jointself"] = _selected_correlations(sel, corr["joint"])
                if "jointse" in models_wanted and "joint" in models and indep:
                    t0 = time.perf_counter()
                    sel = select_outputs(models["joint"], indep, X[tr], Y[tr], rule="1se")
                    times["jointse"] = times["joint"] + times["indep"] + time.perf_counter() - t0
                    preds["jointse"] = sel.predict(X[h], include_noise=False)[0]
                    corr["jointse"] = _selected_correlations(sel, corr["joint"])
                if "jointfwd" in models_wanted and "joint" in models and indep:
                    t0 = time.perf_counter()
                    ej, ei = forward_errors(X[tr], Y[tr], base, COEFFICIENTS, 5)
                    sel = SelectedOutputs(models["joint"], tuple(indep), ej < ei, ej, ei)
                    times["jointfwd"] = times["joint"] + times["indep"] + time.perf_counter() - t0
                    preds["jointfwd"] = sel.predict(X[h], include_noise=False)[0]
                    corr["jointfwd"] = _selected_correlations(sel, corr["joint"])
                gaps = {}
            else:
                gone, _ = missing_rows(pattern, X, tr)
                Ym = Y.copy()
                Ym[np.ix_(gone, MOMENTS)] = np.nan
                t0 = time.perf_counter()
                models["hjoint"] = fit_gp(X[tr], Ym[tr], base)[0]
                times["hjoint"] = time.perf_counter() - t0
                corr["hjoint"] = _correlations(models["hjoint"], X[tr], Xt[tr], Yt[tr])
                models["hdec"] = decoupled_model(models["hjoint"])
                times["hdec"] = 0.0
                keep = tr & ~gone
                t0 = time.perf_counter()
                models["hdrop"] = fit_gp(X[keep], Y[keep], base)[0]
                times["hdrop"] = time.perf_counter() - t0
                t0 = time.perf_counter()
                hind = list(indep) if indep else [None] * P
                for p in range(P):
                    if p in MOMENTS or hind[p] is None:
                        rows = tr & np.isfinite(Ym[:, p])
                        hind[p] = fit_gp(X[rows], Y[rows][:, [p]], base, output_names=[COEFFICIENTS[p]])[0]
                if not indep:          # the forces' GPs see the same rows under every pattern: fitted once
                    indep = [m if p not in MOMENTS else None for p, m in enumerate(hind)]
                times["hindep"] = time.perf_counter() - t0
                preds = {v: _pred(m, X[h]) for v, m in models.items()}
                preds["hindep"] = np.column_stack([_pred(m, X[h])[:, 0] for m in hind])
                gaps = {v: _pred(m, X[gone]) for v, m in models.items()}
                gaps["hindep"] = np.column_stack([_pred(m, X[gone])[:, 0] for m in hind])
            for v, mean in preds.items():
                row = dict(info, pattern=pattern, variant=v, n_missing=int(gone.sum()),
                           err=dict(zip(COEFFICIENTS, errors(mean, Yt[h]).round(3).tolist())),
                           t_fit_s=round(times[v], 2))
                if v in gaps:
                    row["err_gap"] = dict(zip(COEFFICIENTS, errors(gaps[v], Yt[gone]).round(3).tolist()))
                if v in corr:
                    row.update(corr[v])
                yield row


def _pairs(rows, a, b, pattern, key="err", cols=COEFFICIENTS, group=lambda r: True):
    by: dict = {}
    for r in rows:
        if r["pattern"] == pattern and group(r):
            by.setdefault((r["aircraft"], r["seed"], r["turbulence"], r["length"]), {})[r["variant"]] = r
    return [(f[a][key][c], f[b][key][c]) for f in by.values() if a in f and b in f and key in f[a] for c in cols]


def _count(pairs) -> str:
    if not pairs:
        return ""
    x, y = np.array(pairs).T
    better, worse = int(np.sum(x < y - 0.05)), int(np.sum(x > y + 0.05))
    return (f"{better} / {worse} / {len(x) - better - worse}, {np.median(x):.2f} vs {np.median(y):.2f} %, "
            f"ratio of medians {np.median(x) / np.median(y):.3f}")


def summarize(paths) -> str:
    """Pair counts per comparison, length and turbulence (markdown)."""
    rows = [json.loads(line) for p in paths for line in open(p) if line.strip()]
    last = {(r["aircraft"], r["seed"], r["turbulence"], r["length"], r["pattern"], r["variant"]): r for r in rows}
    rows = list(last.values())
    lengths = sorted({r["length"] for r in rows}, key=lambda v: (v <= 0, v))
    turbs = sorted({r["turbulence"] for r in rows})
    flights = sorted({(r["aircraft"], r["seed"], r["turbulence"]) for r in rows})
    out = [f"{len(flights)} flights: " + ", ".join(f"{a} s{s} {t}" for a, s, t in flights), ""]
    mom = [COEFFICIENTS[i] for i in MOMENTS]
    for a, b, pattern in PAIRS:
        for key, cols, what in (("err", COEFFICIENTS, "held-out, all six"),) if pattern == "none" else (
                ("err", mom, "held-out, moments"), ("err_gap", mom, "gap, moments")):
            lines = []
            for L in lengths:
                for tb in turbs + ["both"]:
                    g = (lambda r, L=L, tb=tb: r["length"] == L and (tb == "both" or r["turbulence"] == tb))
                    s = _count(_pairs(rows, a, b, pattern, key, cols, g))
                    if s:
                        lines.append(f"| {'all' if L <= 0 else f'{L:g} s'} | {tb} | {s} |")
            if lines:
                out += [f"\n{a} vs {b}, pattern {pattern}, {what} "
                        f"(better / worse by > 0.05 points / within; medians)\n",
                        "| training | turbulence | pairs |", "|---|---|---|"] + lines
    # joint vs indep per aircraft and length, forces and moments apart (where the shared kernel helps or costs)
    out += ["\njoint (and jointa) vs indep per aircraft (both turbulence levels; better / worse / within; medians)\n",
            "| model | aircraft | training | forces CX CY CZ | moments Cl Cm Cn |", "|---|---|---|---|---|"]
    for v in ("joint", "joint0", "jointv", "jointvn", "jointself", "jointse", "jointfwd", "jointsel", "jointa",
              "jointk", "jointf", "jointo"):
        for ac in sorted({r["aircraft"] for r in rows}):
            for L in lengths:
                g = (lambda r, L=L, ac=ac: r["length"] == L and r["aircraft"] == ac)
                f = _count(_pairs(rows, v, "indep", "none", "err", COEFFICIENTS[:3], g))
                m = _count(_pairs(rows, v, "indep", "none", "err", mom, g))
                if f or m:
                    out.append(f"| {v} | {ac} | {'all' if L <= 0 else f'{L:g} s'} | {f} | {m} |")
    # learned correlations above 0.5 where the truth's nonlinear parts have none (< 0.2)
    out.append("\nlearned |corr| > 0.5 where the truth's < 0.2 (pairs flagged / of which both carrying / pairs)\n")
    out += ["| model | training | flagged | carrying | pairs |", "|---|---|---|---|---|"]
    for v in ("joint", "joint0", "jointv", "jointvn", "jointself", "jointse", "jointfwd", "jointsel", "jointa",
              "jointk", "jointf", "jointo", "jointn", "jointnf", "jointnt", "lmc", "hjoint"):
        for L in lengths:
            rs = [r for r in rows if r["variant"] == v and r["length"] == L and "flags" in r]
            if rs:
                out.append(f"| {v} | {'all' if L <= 0 else f'{L:g} s'} | {sum(len(r['flags']) for r in rs)} | "
                           f"{sum(len(r['flags_carrying']) for r in rs)} | {15 * len(rs)} |")
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_flight_args(ap, ["c172x"], make_help="fly, replay and cache the flights that are missing")
    ap.add_argument("--lengths", nargs="+", type=float, default=[10.0, 20.0, 40.0, 0.0],
                    help="training lengths in s from the first training row (0: all)")
    ap.add_argument("--patterns", nargs="+", default=list(PATTERNS), choices=PATTERNS)
    ap.add_argument("--lmc", action="store_true", help="also fit the two-kernel LMC (isotopic rows)")
    ap.add_argument("--models", nargs="+", default=[m for m in ISO_MODELS if m != "lmc"], choices=ISO_MODELS,
                    help="the isotopic models to fit (default: all but lmc; dec/decn come with joint/jointn)")
    ap.add_argument("--json", default=None, help="append one JSON line per flight, length, pattern and model")
    ap.add_argument("--summarize", nargs="+", default=None, metavar="JSONL")
    a = ap.parse_args(argv)
    if a.summarize:
        print(summarize(a.summarize))
        return 0
    cache = Path(a.cache)
    cache.mkdir(parents=True, exist_ok=True)
    for ac in a.aircraft:
        for turb in a.turbulence:
            for seed in a.seeds:
                path = cache / f"{ac}-{seed}-{turb}-ahrs.npz"
                if not path.is_file():
                    if not a.make:
                        print(f"no cached flight {path} (run with --make)", file=sys.stderr)
                        return 2
                    path = make(ac, seed, turb, "ahrs", 90.0, cache)
                for r in score(path, a.lengths, a.patterns, a.lmc, tuple(a.models) + (("lmc",) if a.lmc else ())):
                    print(f"{path.stem:26s} {r['length']:4.0f} s {r['pattern']:5s} {r['variant']:6s} err "
                          + " ".join(f"{r['err'][c]:6.2f}" for c in COEFFICIENTS)
                          + ("" if "err_gap" not in r else "  gap " + " ".join(
                              f"{r['err_gap'][COEFFICIENTS[i]]:6.2f}" for i in MOMENTS))
                          + f"  ({r['n_train']} rows, {r['t_fit_s']:.1f} s)", flush=True)
                    append_jsonl(a.json, [r])
    return 0


if __name__ == "__main__":
    sys.exit(main())
