"""``scale:CY`` against the between-flight scale of the aided sideslip (forty-third session; issue 9).

Each flight's sideslip is aided with side-force slopes fitted on that flight (``run.shared_angle_models`` passes the
reference's fit, which without ``INSTRUMENTED_BETA`` changes nothing), and the fit's errors in variables differ from
flight to flight, so the test flight's aided sideslip reads ``1 / (1 + s)`` times what the reference's would read
(the forty-third session described ``s`` as the side-force scale carried into the angle through the reference's
model; the forty-fourth measured with this script that the true ``s`` of an aircraft's two sizes differs by a median
0.01, where a scale carried that way would differ by about 0.14: ``s`` is mostly the aiding's own between-flight
scatter; ``docs/benchmarks.md``, "Forty-fourth session, lead"). The search's
``scale:CY`` then reads ``(k - 1)(1 + s) + s`` rather than ``k - 1`` (to first order), and the differential step's
``beta_scale_allowance`` fits ``s`` on Cl and Cn (their unchanged ``beta`` derivatives) for every named
``scale:CY``. For each aircraft and ``CY:scale`` size this script flies (or reuses) the flight, diagnoses it as
``eval_jsbsim_diagnose`` does, and records

* the search's ``k - 1`` (the named ``scale:CY``'s estimate less 1);
* the allowance's ``s`` and its ``beyond_scale`` estimate (CY's scale with ``s`` times the model's CY taken out);
* the true between-flight scale ``s_true = g_ref / g - 1``, where ``g`` is the least-squares slope of a flight's
  aided sideslip on JSBSim's sideslip (the truth is read here to attribute errors; the pipeline never reads it).

It prints one line per case and, over the cases whose first named cause is ``scale:CY``, how many estimates lie
within 25 % of the injected ``k - 1``: as searched, ``beyond / (1 + s)``, ``(search - s) / (1 + s)`` with the fitted
``s``, and the same with ``s_true``. Measured in ``docs/benchmarks.md``, "Forty-third session, lead".

With ``--variants`` (forty-fourth session) it also refits ``s`` from the allowance's own inputs (the residual without
the finding and the model's sideslip contributions ``n_j = beta dC_j/dbeta``, captured from the call that judges the
``scale:CY`` or ``CY:beta`` finding) in other ways (:data:`VARIANTS`: one moment alone, the moment's other lateral
slopes free beside the scale, a band of frequencies), and scores each against ``s_true`` (correlation, RMS) and by the
``(search - s) / (1 + s)`` reading. Measured in ``docs/benchmarks.md``, "Forty-fourth session, lead".

Usage::

    python benchmarks/scale_sideslip_truth.py --aircraft t6 c684 --seed 1 --out DIR [--sizes 1.6 1.3] [--json F]
        [--variants] [--clean-seeds 11 12 13 14 15] [--beta-profile]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks import eval_jsbsim_diagnose as E  # noqa: E402
from benchmarks.eval_common import append_jsonl  # noqa: E402
from benchmarks.jsbsim_harness.truth import load_truth  # noqa: E402
from gcs_sysid.aero.table import REGRESSORS  # noqa: E402

SIZES = (1.6, 1.3)                  #: the roster's ``CY:scale`` sizes
TOLERANCE = 0.25                    #: issue 9's estimate line: within 25 % of the injected change
#: Other fits of the sideslip scale ``s`` from the allowance's inputs (:func:`refit_scale`): ``coefs`` the moments it
#: is fitted on, ``free`` regressors whose slopes are fitted beside it in each moment (a change of those derivatives
#: is then not read as the sideslip's scale), ``band`` a (low, high) Hz band-pass of residual, contribution and free
#: columns (None: the whole band). ``allowance`` is the differential step's own fit (Cl and Cn, whole band).
VARIANTS = {
    "allowance": {"coefs": ("Cl", "Cn")},
    "Cn": {"coefs": ("Cn",)},
    "Cl": {"coefs": ("Cl",)},
    "Cn_free_r_rudder": {"coefs": ("Cn",), "free": ("r_hat", "delta_r")},
    "Cn_free_lateral": {"coefs": ("Cn",), "free": ("p_hat", "r_hat", "delta_a", "delta_r")},
    "free_lateral": {"coefs": ("Cl", "Cn"), "free": ("p_hat", "r_hat", "delta_a", "delta_r")},
    "above_0.1Hz": {"coefs": ("Cl", "Cn"), "band": (0.1, None)},
    "below_1Hz": {"coefs": ("Cl", "Cn"), "band": (None, 1.0)},
    "0.1_to_1Hz": {"coefs": ("Cl", "Cn"), "band": (0.1, 1.0)},
}


def _band(X: np.ndarray, rows: np.ndarray, dt: float, band) -> np.ndarray:
    """The columns of ``X`` (T, P) band-passed within each contiguous run of ``rows`` at least 60 samples long
    (:func:`gcs_sysid.estimation.nodes.segments`; each run's mean removed, second-order Butterworth, forward and back);
    NaN elsewhere."""
    from scipy.signal import butter, sosfiltfilt

    from gcs_sysid.estimation.nodes import segments

    filters = [butter(2, edge, kind, fs=1.0 / dt, output="sos") for edge, kind in zip(band, ("high", "low")) if edge]
    Y = np.full(X.shape, np.nan)
    for sg in segments(rows, 60):
        v = X[sg] - X[sg].mean(axis=0)
        for sos in filters:
            v = sosfiltfilt(sos, v, axis=0)
        Y[sg] = v
    return Y


def refit_scale(t: np.ndarray, X: np.ndarray, R: np.ndarray, N: np.ndarray, rows: np.ndarray, coefs=("Cl", "Cn"),
                free=(), band=None) -> float:
    """The sideslip scale ``s`` refitted as the allowance does (``gcs_sysid.diagnose.differential.
    angle_scale_allowance``: each moment's residual ``r_j`` on its contribution ``n_j``, centred, weighted by
    ``1 / var(r_j)``), with the options of :data:`VARIANTS`.

    Args:
        t: (T,) s. X: (T, 10) regressors. R: (T, 6) residual without the finding. N: (T, 6) the model's
            ``beta dC/dbeta``. rows: (T,) bool, the selection rows. coefs, free, band: see :data:`VARIANTS`.

    Returns:
        ``s`` (NaN where no moment has a contribution).
    """
    from gcs_sysid.aero.table import COEFFICIENTS

    ok = rows & np.isfinite(R).all(axis=1) & np.isfinite(N).all(axis=1)
    F = np.column_stack([np.nan_to_num(X[:, REGRESSORS.index(x)]) for x in free]) if free else np.zeros((len(X), 0))
    if band is not None:
        dt = float(np.median(np.diff(t))) if len(t) > 1 else 0.02
        Y = _band(np.where(ok[:, None], np.column_stack([R, N, F]), 0.0), ok, dt, band)
        R, N, F = Y[:, :6], Y[:, 6:12], Y[:, 12:]
        ok = ok & np.isfinite(R).all(axis=1) & np.isfinite(N).all(axis=1)
    num = den = 0.0
    for c in coefs:
        j = COEFFICIENTS.index(c)
        r, n = R[ok, j] - R[ok, j].mean(), N[ok, j] - N[ok, j].mean()
        if free:
            B = np.column_stack([np.ones(ok.sum()), F[ok]])
            r = r - B @ np.linalg.lstsq(B, r, rcond=None)[0]
            n = n - B @ np.linalg.lstsq(B, n, rcond=None)[0]
        if np.std(n) == 0:
            continue
        w = 1.0 / max(float(np.var(r)), 1e-30)
        num, den = num + w * float(n @ r), den + w * float(n @ n)
    return num / den if den > 0 else float("nan")


def _tlog(out: Path, ac: str, seed: int, effects: list) -> Path:
    """The .tlog that ``eval_jsbsim_diagnose`` flies for ``ac`` at ``seed`` with ``effects`` (``[(name, value)]``;
    empty: the clean flight) in ``out``, at its plan and draws."""
    return out / (E.case_stem(ac, seed, effects) + E._stem_suffix(E.PLAN, E.SENSOR_DRAW, E.TURBULENCE_DRAW) + ".tlog")


def aided_gain(t: np.ndarray, beta: np.ndarray, valid: np.ndarray, tlog: Path) -> float:
    """Least-squares slope of the aided sideslip ``beta`` (T,) rad at times ``t`` (T,) s on JSBSim's sideslip from the
    flight's ``-truth.npz`` beside ``tlog``, over the ``valid`` (T,) rows where both are finite."""
    Xt, _ = load_truth(tlog.with_name(tlog.stem + "-truth.npz")).at(t)
    ok = np.asarray(valid, bool) & np.isfinite(beta) & np.isfinite(Xt[:, 1])
    return float(np.polyfit(Xt[ok, 1], beta[ok], 1)[0])


def scale_case(ac: str, seed: int, k: float, out: Path, model_path: Path, ref_meas, g_ref: float,
               variants: bool = False) -> dict:
    """One ``CY:scale`` = ``k`` flight of ``ac`` at ``seed``, diagnosed; returns the record described above (with
    ``variants``: also ``s_variants``, :data:`VARIANTS` refitted on the first captured judgement)."""
    import gcs_sysid.diagnose as D
    import gcs_sysid.diagnose.differential as DF
    from gcs_sysid.diagnose.context import evaluate_model

    captured = {"calls": []}
    original, original_asa = D.diagnose, DF.angle_scale_allowance

    def capture(*a, **kw):
        captured["d"] = original(*a, **kw)
        return captured["d"]

    def capture_asa(X, R, train, test, model, coef, term, angle="beta", *a, **kw):
        res = original_asa(X, R, train, test, model, coef, term, angle, *a, **kw)
        if angle == "beta" and coef == "CY" and not kw.get("along_term") and (kw.get("column") is not None
                                                                              or term == "beta"):
            X1 = np.array(X, float, copy=True)
            X1[:, REGRESSORS.index("beta")] *= 1.001
            N = (evaluate_model(model, X1) - evaluate_model(model, X)) / 1e-3
            captured["calls"].append((np.asarray(X, float), np.asarray(R, float), np.asarray(train, bool), N,
                                      (res or {}).get("scale")))
        return res

    D.diagnose = capture
    if variants:
        DF.angle_scale_allowance = capture_asa
    try:
        findings, _, _ = E.diagnose_case(ac, seed, [E.Effect("CY:scale", k)], out, model_path, ref_meas)
    finally:
        D.diagnose, DF.angle_scale_allowance = original, original_asa
    d = captured["d"]
    tlog = _tlog(out, ac, seed, [("CY:scale", k)])
    ib = REGRESSORS.index("beta")
    rec = {"aircraft": ac, "seed": seed, "k": k, "named": [f["cause"] for f in findings],
           "s_true": g_ref / aided_gain(d.t, d.X[:, ib], d.train | d.test, tlog) - 1.0}
    for f in d.data["sparse"].get("findings", []):
        if f["cause"] == "scale:CY":
            allowance = f.get("evidence", {}).get("beta_scale_allowance") or {}
            rec.update(search=f["estimate"] - f.get("model_value", 1.0), s=allowance.get("scale"),
                       beyond=(allowance.get("beyond_scale") or {}).get("estimate"))
    if captured["calls"]:
        X, R, rows, N, s_allowance = captured["calls"][0]
        rec["s_variants"] = {name: refit_scale(d.t, X, R, N, rows, **opt) for name, opt in VARIANTS.items()}
        rec["s_allowance_captured"] = s_allowance
    return rec


def counts(records: list[dict]) -> dict:
    """Of the records whose first named cause is ``scale:CY``: how many estimates lie within :data:`TOLERANCE` of
    ``k - 1``, by each reading (``search``, ``beyond``, ``fitted_s``, ``true_s``)."""
    out = {"tops": 0, "search": 0, "beyond": 0, "fitted_s": 0, "true_s": 0}
    for r in records:
        if r["named"][:1] != ["scale:CY"] or r.get("search") is None:
            continue
        v, e = r["k"] - 1.0, r["search"]
        out["tops"] += 1
        readings = {"search": e, "true_s": (e - r["s_true"]) / (1.0 + r["s_true"])}
        if r.get("s") is not None:
            readings["fitted_s"] = (e - r["s"]) / (1.0 + r["s"])
            if r.get("beyond") is not None:
                readings["beyond"] = r["beyond"] / (1.0 + r["s"])
        for name, sv in (r.get("s_variants") or {}).items():
            if np.isfinite(sv):
                readings[f"s_{name}"] = (e - sv) / (1.0 + sv)
        for name, x in readings.items():
            out[name] = out.get(name, 0) + int(abs(x - v) <= TOLERANCE * abs(v))
    return out


def variant_errors(records: list[dict]) -> dict:
    """Per :data:`VARIANTS` entry, over every record that has it: ``{"n", "corr", "rms", "bias"}`` of the refitted
    ``s`` against ``s_true``."""
    out = {}
    for name in VARIANTS:
        pairs = np.array([(r["s_variants"][name], r["s_true"]) for r in records
                          if np.isfinite((r.get("s_variants") or {}).get(name, np.nan))])
        if len(pairs) < 3:
            continue
        e = pairs[:, 0] - pairs[:, 1]
        out[name] = {"n": len(pairs), "corr": float(np.corrcoef(pairs.T)[0, 1]), "rms": float(np.sqrt(np.mean(e ** 2))),
                     "bias": float(np.mean(e))}
    return out


def clean_scale(ac: str, seed: int, out: Path, ref_meas, g_ref: float) -> dict | None:
    """The true between-flight sideslip scale of a clean flight (no effect) of ``ac`` at ``seed`` in ``out`` (flown
    there before; None where it is not): the flight loaded as the diagnosis loads it (the reference's angle fits,
    the flight's air-roll table), no diagnosis run."""
    from benchmarks.jsbsim_harness.aircraft import aircraft
    from gcs_sysid.diagnose.run import air_roll_kind, load_measurements, shared_angle_models

    tlog = _tlog(out, ac, seed, [])
    if not tlog.exists():
        return None
    m = load_measurements(tlog, aircraft(ac).airframe_path, angle_models=shared_angle_models(
        ref_meas.states.angle_fits), air_roll=air_roll_kind("flight"))
    beta = np.asarray(m.table.X, float)[:, REGRESSORS.index("beta")]
    rec = {"aircraft": ac, "seed": seed, "k": 1.0, "clean": True,
           "s_true": g_ref / aided_gain(m.table.t, beta, m.table.valid, tlog) - 1.0}
    fr, ff = ref_meas.states.angle_fits.get("beta"), m.states.angle_fits.get("beta")
    if fr is not None and ff is not None and fr.used and ff.used:
        # the two flights' fitted side-force slopes and the first pass's block jackknife of each (the aiding's own
        # statement of how well this flight knows CY_beta)
        jk = [float(np.asarray(f.slope_jackknife, float)[1]) if np.size(f.slope_jackknife) > 1 else np.nan
              for f in (ff, fr)]
        rec.update(CY_beta_ratio=float(ff.coef[1] / fr.coef[1] - 1.0),
                   CY_beta_ratio_se=float(np.hypot(*jk) / abs(fr.coef[1])))
    return rec


def size_pairs(records: list[dict]) -> dict | None:
    """Over the aircraft flown at two sizes: the true sideslip scale ``s_true`` at each size (mean), the pairs'
    correlation and the mean, median and SD of the difference (larger size minus smaller). A scale that the side
    force carried into the aided angle through the reference's slopes would be ``1 / k - 1`` plus the flight's own
    (1.3 and 1.6: a difference of -0.144); one that is the aiding's own between-flight scatter does not move with
    ``k``. None with fewer than three pairs."""
    by = {}
    for r in records:
        by.setdefault(r["aircraft"], {})[r["k"]] = r["s_true"]
    sizes = sorted({r["k"] for r in records})
    if len(sizes) < 2:
        return None
    lo, hi = sizes[0], sizes[-1]
    P = np.array([(v[lo], v[hi]) for v in by.values() if lo in v and hi in v])
    if len(P) < 3:
        return None
    d = P[:, 1] - P[:, 0]
    return {"sizes": (lo, hi), "pairs": len(P), "mean": (float(P[:, 0].mean()), float(P[:, 1].mean())),
            "corr": float(np.corrcoef(P.T)[0, 1]), "diff_mean": float(d.mean()), "diff_median": float(np.median(d)),
            "diff_sd": float(d.std(ddof=1))}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--aircraft", nargs="+", required=True)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--sizes", nargs="*", type=float, default=list(SIZES),
                   help="CY:scale sizes to diagnose (none: only --clean-seeds)")
    p.add_argument("--out", required=True, help="flight folder (eval_jsbsim_diagnose's --out; reused flights)")
    p.add_argument("--json", default=None, help="append one JSON line per case here")
    p.add_argument("--draws", default="per_aircraft", choices=("shared", "per_aircraft"),
                   help="sensor noise and turbulence draws, as eval_jsbsim_diagnose's (default %(default)s)")
    p.add_argument("--variants", action="store_true", help="also refit the sideslip scale by VARIANTS (see above)")
    p.add_argument("--clean-seeds", nargs="*", type=int, default=[],
                   help="also the true sideslip scale of these clean flights already in --out (no diagnosis)")
    p.add_argument("--beta-profile", action="store_true",
                   help="aid every flight's sideslip (reference and test) with the profiled CY_beta "
                        "(gcs_sysid.diagnose.run.BETA_PROFILE = True; opt-in, off in the diagnosis)")
    a = p.parse_args(argv)
    E.SENSOR_DRAW = E.TURBULENCE_DRAW = a.draws
    if a.beta_profile:
        from gcs_sysid.diagnose import run as diagnose_run

        diagnose_run.BETA_PROFILE = True
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    records, clean = [], []
    for ac in a.aircraft:
        files, model_path, ref_meas = E.reference_model(ac, out)
        beta_ref = np.asarray(ref_meas.table.X, float)[:, REGRESSORS.index("beta")]
        g_ref = aided_gain(ref_meas.table.t, beta_ref, ref_meas.table.valid, files.tlog)
        for k in a.sizes:
            r = scale_case(ac, a.seed, k, out, model_path, ref_meas, g_ref, a.variants)
            records.append(r)
            if a.json:
                append_jsonl(a.json, [r])
            ratio = "" if r.get("search") is None else f" search/(k-1) {r['search'] / (k - 1):.2f}"
            s = "" if r.get("s") is None else f" s {r['s']:+.3f}"
            print(f"{ac:10s} s{a.seed} k {k:g} named {r['named']}{ratio}{s} s_true {r['s_true']:+.3f}", flush=True)
        for seed in a.clean_seeds:
            r = clean_scale(ac, seed, out, ref_meas, g_ref)
            if r is None:
                continue
            clean.append(r)
            if a.json:
                append_jsonl(a.json, [r])
            print(f"{ac:10s} s{seed} clean s_true {r['s_true']:+.3f}", flush=True)
    print(counts(records))
    if clean:
        c = np.array([r["s_true"] for r in clean])
        print(f"clean flights: {len(c)}, s_true mean {c.mean():+.3f}, SD {c.std():.3f}, median |s| "
              f"{np.median(np.abs(c)):.3f}")
        P = np.array([(r["s_true"], r["CY_beta_ratio"], r["CY_beta_ratio_se"]) for r in clean if "CY_beta_ratio" in r])
        if len(P) >= 3:
            b = np.polyfit(P[:, 1], P[:, 0], 1)
            z = P[:, 1] / P[:, 2]
            print(f"  against CY_beta(flight) / CY_beta(reference) - 1 ({len(P)} flights): correlation "
                  f"{np.corrcoef(P[:, 0], P[:, 1])[0, 1]:.2f}, slope {b[0]:.2f}, s_true's SD after it "
                  f"{np.std(P[:, 0] - np.polyval(b, P[:, 1])):.3f}; the ratio's jackknife standard error median "
                  f"{np.nanmedian(P[:, 2]):.3f}, SD of ratio / se {np.nanstd(z[np.isfinite(z)]):.2f}")
    pairs = size_pairs(records)
    if pairs:
        print(f"s_true at k {pairs['sizes'][0]:g} / {pairs['sizes'][1]:g}: mean {pairs['mean'][0]:+.3f} / "
              f"{pairs['mean'][1]:+.3f} over {pairs['pairs']} aircraft, pair correlation {pairs['corr']:.2f}, "
              f"difference mean {pairs['diff_mean']:+.3f}, median {pairs['diff_median']:+.3f} "
              f"(SD {pairs['diff_sd']:.3f})")
    if a.variants:
        for name, v in variant_errors(records).items():
            print(f"s by {name:18s} n {v['n']:3d}  corr with s_true {v['corr']:+.2f}  rms {v['rms']:.3f}  "
                  f"bias {v['bias']:+.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
