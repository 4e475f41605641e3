"""``scale:CY`` against the sideslip scale it carries into the aided angle (forty-third session; issue 9).

The test flight's sideslip is aided with the reference flight's side-force model (``run.shared_angle_models``), so
a side force ``k`` times the reference's also reaches the angle: the flight's aided sideslip reads ``1 / (1 + s)``
times what the reference's would. The search's ``scale:CY`` then reads ``(k - 1)(1 + s) + s`` rather than ``k - 1``
(to first order), and the differential step's ``beta_scale_allowance`` fits ``s`` on Cl and Cn (their unchanged
``beta`` derivatives) for every named ``scale:CY``. For each aircraft and ``CY:scale`` size this script flies (or
reuses) the flight, diagnoses it as ``eval_jsbsim_diagnose`` does, and records

* the search's ``k - 1`` (the named ``scale:CY``'s estimate less 1);
* the allowance's ``s`` and its ``beyond_scale`` estimate (CY's scale with ``s`` times the model's CY taken out);
* the true between-flight scale ``s_true = g_ref / g - 1``, where ``g`` is the least-squares slope of a flight's
  aided sideslip on JSBSim's sideslip (the truth is read here to attribute errors; the pipeline never reads it).

It prints one line per case and, over the cases whose first named cause is ``scale:CY``, how many estimates lie
within 25 % of the injected ``k - 1``: as searched, ``beyond / (1 + s)``, ``(search - s) / (1 + s)`` with the fitted
``s``, and the same with ``s_true``. Measured in ``docs/benchmarks.md``, "Forty-third session, lead".

Usage::

    python benchmarks/scale_sideslip_truth.py --aircraft t6 c684 --seed 1 --out DIR [--sizes 1.6 1.3] [--json F]
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


def aided_gain(t: np.ndarray, beta: np.ndarray, valid: np.ndarray, tlog: Path) -> float:
    """Least-squares slope of the aided sideslip ``beta`` (T,) rad at times ``t`` (T,) s on JSBSim's sideslip from the
    flight's ``-truth.npz`` beside ``tlog``, over the ``valid`` (T,) rows where both are finite."""
    Xt, _ = load_truth(tlog.with_name(tlog.stem + "-truth.npz")).at(t)
    ok = np.asarray(valid, bool) & np.isfinite(beta) & np.isfinite(Xt[:, 1])
    return float(np.polyfit(Xt[ok, 1], beta[ok], 1)[0])


def scale_case(ac: str, seed: int, k: float, out: Path, model_path: Path, ref_meas, g_ref: float) -> dict:
    """One ``CY:scale`` = ``k`` flight of ``ac`` at ``seed``, diagnosed; returns the record described above."""
    import gcs_sysid.diagnose as D

    captured = {}
    original = D.diagnose

    def capture(*a, **kw):
        captured["d"] = original(*a, **kw)
        return captured["d"]

    D.diagnose = capture
    try:
        findings, _, _ = E.diagnose_case(ac, seed, [E.Effect("CY:scale", k)], out, model_path, ref_meas)
    finally:
        D.diagnose = original
    d = captured["d"]
    tlog = out / (E.case_stem(ac, seed, [("CY:scale", k)]) + E._stem_suffix(E.PLAN, E.SENSOR_DRAW, E.TURBULENCE_DRAW)
                  + ".tlog")
    ib = REGRESSORS.index("beta")
    rec = {"aircraft": ac, "seed": seed, "k": k, "named": [f["cause"] for f in findings],
           "s_true": g_ref / aided_gain(d.t, d.X[:, ib], d.train | d.test, tlog) - 1.0}
    for f in d.data["sparse"].get("findings", []):
        if f["cause"] == "scale:CY":
            allowance = f.get("evidence", {}).get("beta_scale_allowance") or {}
            rec.update(search=f["estimate"] - f.get("model_value", 1.0), s=allowance.get("scale"),
                       beyond=(allowance.get("beyond_scale") or {}).get("estimate"))
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
        for name, x in readings.items():
            out[name] += int(abs(x - v) <= TOLERANCE * abs(v))
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--aircraft", nargs="+", required=True)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--sizes", nargs="+", type=float, default=list(SIZES))
    p.add_argument("--out", required=True, help="flight folder (eval_jsbsim_diagnose's --out; reused flights)")
    p.add_argument("--json", default=None, help="append one JSON line per case here")
    p.add_argument("--draws", default="per_aircraft", choices=("shared", "per_aircraft"),
                   help="sensor noise and turbulence draws, as eval_jsbsim_diagnose's (default %(default)s)")
    a = p.parse_args(argv)
    E.SENSOR_DRAW = E.TURBULENCE_DRAW = a.draws
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    records = []
    for ac in a.aircraft:
        files, model_path, ref_meas = E.reference_model(ac, out)
        beta_ref = np.asarray(ref_meas.table.X, float)[:, REGRESSORS.index("beta")]
        g_ref = aided_gain(ref_meas.table.t, beta_ref, ref_meas.table.valid, files.tlog)
        for k in a.sizes:
            r = scale_case(ac, a.seed, k, out, model_path, ref_meas, g_ref)
            records.append(r)
            if a.json:
                append_jsonl(a.json, [r])
            ratio = "" if r.get("search") is None else f" search/(k-1) {r['search'] / (k - 1):.2f}"
            s = "" if r.get("s") is None else f" s {r['s']:+.3f}"
            print(f"{ac:10s} s{a.seed} k {k:g} named {r['named']}{ratio}{s} s_true {r['s_true']:+.3f}", flush=True)
    print(counts(records))
    return 0


if __name__ == "__main__":
    sys.exit(main())
