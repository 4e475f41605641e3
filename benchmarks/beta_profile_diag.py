"""Why the sideslip profile helps or hurts an aircraft: its likelihood curve and the lateral slopes, profile on and off.

The replay's sideslip aiding takes ``CY_beta`` from the gust model's likelihood in its first pass and holds it
(``gcs_sysid.estimation.airangles.BETA_PROFILE``, ``BETA_PROFILE_HOLD``; ``docs/estimation.md``, "The side-force
slope by the gust model's likelihood"). For each flight this replays the log with the profile off (least squares)
and on, and prints (a diagnosis: it reads JSBSim's truth, and only to score):

  profile    least squares' first-pass ``CY_beta`` (``b_ls``), the profiled one (``b_prof``), the likelihood ratio
             ``2 (nll(b_ls) - nll(b_prof))`` of the two, the curvature's standard error of the profiled slope
             (``se``: ``1 / sqrt(nll'')`` at the optimum, by a parabola through the grid) and the curve
             ``nll(d) - nll(b_prof)`` over ``d / b_ls`` in :data:`GRID` (``curve`` in the JSON)
  scale      the aided sideslip regressed on JSBSim's (``eval_jsbsim.cy_diagnosis``'s ``beta_scale``), held-out rows;
             ``beta_read``: JSBSim's sideslip regressed on the replay's with the replay's other lateral regressors
             beside it (``factor``: what a moment's sideslip slope on the replay's regressors is multiplied by), and
             the SD of the replay's sideslip beside those regressors (``partial_sd_deg``) and in all (``sd_deg``)
  slopes     the GP's and JSBSim's local slopes of CY, Cl and Cn on the true regressors with the aero rates
             (``beta p_hat r_hat delta_a delta_r``, least squares with a constant on the held-out rows), and the GP's
             % error there (``eval_jsbsim``'s ``true_air``); ``meas_on_est`` / ``meas_on_true``: the measured
             coefficient's slopes on the replay's / on JSBSim's regressors (all valid rows)

Usage::

    python benchmarks/beta_profile_diag.py --aircraft s23 --seeds 1 2 3 --work DIR --json out.jsonl [--gp-seed 1]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.eval_common import append_jsonl  # noqa: E402
from benchmarks.eval_jsbsim import (CY_DIAG_COLUMNS, _errs, aero_reads_air_rates, cy_diagnosis,  # noqa: E402
                                    true_alpha_dot)
from benchmarks.jsbsim_harness import FlightConfig, load_truth, make_flight  # noqa: E402
from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS  # noqa: E402
from gcs_sysid.pipeline import ReplayOptions, run_replay  # noqa: E402

#: the candidate slopes of the likelihood curve, multiples of least squares' first-pass slope
GRID = tuple(np.round(np.arange(0.50, 1.201, 0.05), 3))
#: the lateral outputs whose local slopes are compared
LATERAL = ("CY", "Cl", "Cn")


def local_slopes(X: np.ndarray, y: np.ndarray) -> dict[str, float]:
    """Least-squares slopes of ``y`` (N,) on the :data:`CY_DIAG_COLUMNS` of ``X`` (N, 10), with a constant."""
    idx = [REGRESSORS.index(k) for k in CY_DIAG_COLUMNS]
    ok = np.isfinite(X[:, idx]).all(1) & np.isfinite(y)
    A = np.c_[np.ones(ok.sum()), X[ok][:, idx]]
    c, *_ = np.linalg.lstsq(A, y[ok], rcond=None)
    return {k: float(c[j + 1]) for j, k in enumerate(CY_DIAG_COLUMNS)}


def profile_curve(args: tuple, kwargs: dict, b_prof: float) -> dict:
    """The first pass's likelihood around least squares' slope, from the arguments ``_profile_angle_slope`` was
    called with (``airangles._angle_profile_objective``, the same objective)."""
    from gcs_sysid.estimation import airangles as aa

    dt, Ahm, yhm, A, coeff, kin, ang, m, segs, cr, sign, taus, ratios = args[:13]
    edge = kwargs.get("edge_hz", -1.0)
    _, nll = aa._angle_profile_objective(dt, Ahm, yhm, A, coeff, kin, ang, m, segs, cr, taus, ratios, edge)
    b = float(cr[0])
    n_opt = nll(b_prof)
    curve = [float(nll(g * b) - n_opt) for g in GRID]
    # curvature at the optimum from a parabola through three points 2 % of b apart
    h = 0.02 * abs(b)
    f0, fm, fp = n_opt, nll(b_prof - h), nll(b_prof + h)
    d2 = (fp - 2 * f0 + fm) / h**2
    return {"b_ls": b, "b_prof": float(b_prof), "lr": float(2 * (nll(b) - n_opt)),
            "se": float(1 / np.sqrt(d2)) if d2 > 0 else float("nan"), "n_rows": int(np.sum(m)),
            "grid": list(map(float, GRID)), "curve": curve}


def diagnose(aircraft: str, seed: int, turbulence: str, duration: float, work: Path, profile: bool,
             gp_seed: int = 0) -> dict:
    """One flight replayed with the sideslip profile on or off; the fields of the module docstring."""
    from gcs_sysid.estimation import airangles as aa
    from gcs_sysid.gp import load_gp

    calls = []
    orig = aa._profile_angle_slope

    def recorder(*args, **kwargs):     # records the first pass's inputs; the result is the function's own
        out = orig(*args, **kwargs)
        calls.append((args, kwargs, float(out[0][0])))
        return out

    saved = aa.BETA_PROFILE
    aa.BETA_PROFILE, aa._profile_angle_slope = profile, recorder
    try:
        files = make_flight(FlightConfig(aircraft, duration_s=duration, turbulence=turbulence, seed=seed), work,
                            aoa="ahrs", reuse=True)
        t0 = time.process_time()
        res = run_replay(files.tlog, files.airframe, work / f"{files.tlog.stem}-diag",
                         ReplayOptions(progress=False, gp_seed=gp_seed))
        cpu = time.process_time() - t0
    finally:
        aa.BETA_PROFILE, aa._profile_angle_slope = saved, orig
    truth = load_truth(files.truth)
    tab = res.table
    Xt, Yt = truth.at(tab.t)
    Xa = Xt.copy()
    cst = truth.meta["constants"]
    air = aero_reads_air_rates(aircraft)
    for j, (ax, ref) in enumerate(zip("pqr", ("b", "c", "b"))):
        if air[ax]:
            Xa[:, 2 + j] = np.interp(tab.t, truth.t, truth.fields[f"{ax}_aero"]) * cst[ref] / (2 * Xt[:, 9])
    h = tab.valid & np.isfinite(Yt).all(1) & res.held_out
    model = load_gp(Path(res.model_path))
    Xq = Xa
    if model.n_mean_only:
        adt = np.interp(tab.t, truth.t, true_alpha_dot(truth)) * cst["c"] / (2 * Xt[:, 9])
        Xq = np.c_[Xa, adt]
    ma = np.asarray(model.predict(Xq[h], include_noise=False, input_noise=False)[0])
    row = {"aircraft": aircraft, "seed": seed, "turbulence": turbulence, "profile": profile, "gp_seed": gp_seed,
           "cpu_replay_s": round(cpu, 1), "true_air": _errs(ma, Yt[h]), "gp": _errs(res.pred_mean[h], Yt[h])}
    row["cy_diag"] = cy_diagnosis(tab.X[h], Xa[h], ma[:, 1], Yt[h, 1])
    ok = tab.valid & np.isfinite(tab.Y).all(1) & np.isfinite(tab.X).all(1) & np.isfinite(Xa).all(1)
    for c in LATERAL:
        i = COEFFICIENTS.index(c)
        row[f"slopes_{c}"] = {"model": local_slopes(Xa[h], ma[:, i]), "true": local_slopes(Xa[h], Yt[h, i]),
                              # the measured coefficient itself, all valid rows, on the replay's and on JSBSim's
                              # regressors: whether a flat slope is in the data at the aided sideslip or in the model
                              "meas_on_est": local_slopes(tab.X[ok], tab.Y[ok, i]),
                              "meas_on_true": local_slopes(Xa[ok], tab.Y[ok, i])}
    # the sideslip a moment slope reads: JSBSim's sideslip regressed on the replay's one with the replay's other lateral
    # regressors beside it (all valid rows). A moment linear in the true sideslip then has its slope on the replay's
    # regressors times this factor; the aided angle's error hurts more where the rates explain most of the sideslip
    idx = [REGRESSORS.index(k) for k in CY_DIAG_COLUMNS]
    G = np.c_[np.ones(ok.sum()), tab.X[ok][:, idx]]
    lam, *_ = np.linalg.lstsq(G, Xa[ok, 1], rcond=None)
    other = np.c_[np.ones(ok.sum()), tab.X[ok][:, idx[1:]]]
    part = tab.X[ok, 1] - other @ np.linalg.lstsq(other, tab.X[ok, 1], rcond=None)[0]
    row["beta_read"] = {"factor": float(lam[1]), "partial_sd_deg": float(np.degrees(np.std(part))),
                        "sd_deg": float(np.degrees(np.std(tab.X[ok, 1])))}
    if calls:
        args, kwargs, b_prof = calls[0]
        row["profile_first_pass"] = profile_curve(args, kwargs, b_prof)
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--aircraft", nargs="+", default=["s23"])
    ap.add_argument("--seeds", nargs="+", type=int, default=[1, 2, 3])
    ap.add_argument("--turbulence", default="light")
    ap.add_argument("--duration", type=float, default=120.0)
    ap.add_argument("--gp-seed", type=int, default=0)
    ap.add_argument("--work", required=True, help="the flights (flown there if missing; reused by fingerprint)")
    ap.add_argument("--json", default=None)
    a = ap.parse_args(argv)
    for ac in a.aircraft:
        for seed in a.seeds:
            for profile in (False, True):
                r = diagnose(ac, seed, a.turbulence, a.duration, Path(a.work), profile, a.gp_seed)
                append_jsonl(a.json, [r])
                d = r["cy_diag"]
                br = r["beta_read"]
                print(f"{ac} {a.turbulence} s{seed} profile {'on ' if profile else 'off'}: beta scale "
                      f"{d['beta_scale']:.3f}, read by the moments x{br['factor']:.3f} (partial SD "
                      f"{br['partial_sd_deg']:.2f} of {br['sd_deg']:.2f} deg); true-air "
                      + " ".join(f"{c} {r['true_air'][c]:.1f}" for c in COEFFICIENTS))
                for c in LATERAL:
                    s = r[f"slopes_{c}"]
                    print(f"    {c}: " + "  ".join(f"{k} {s['model'][k]:+.4f}/{s['true'][k]:+.4f}"
                                                   for k in CY_DIAG_COLUMNS) + "  (GP / JSBSim); measured on the "
                          f"replay's / JSBSim's regressors: beta {s['meas_on_est']['beta']:+.4f} / "
                          f"{s['meas_on_true']['beta']:+.4f}")
                p = r.get("profile_first_pass")
                if p:
                    print(f"    first pass CY_beta: LS {p['b_ls']:+.4f} profiled {p['b_prof']:+.4f} "
                          f"(LR {p['lr']:.1f}, se {p['se']:.4f}, {p['n_rows']} rows); nll - min over d/b_ls "
                          + " ".join(f"{g:.2f}:{v:.1f}" for g, v in zip(p["grid"], p["curve"])), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
