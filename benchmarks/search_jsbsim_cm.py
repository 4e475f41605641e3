"""What limits the sparse search on JSBSim flights: the search alone, on cached flights, against the truth.

``benchmarks.eval_jsbsim_diagnose`` runs the whole ``diagnose`` (about a minute per flight on the
shared box); this script runs only :func:`gcs_sysid.diagnose.sparse.sparse_search` on the same
flights (the decoded measurements cached as pickles next to them, the reference model fitted once
per variant), so a variant of the thresholds or of the angle of attack is measured on every tuning
flight in about a minute. It reads the harness's truth (``-truth.npz``, ``-effects.json``), which
the pipeline never sees, to say how wrong the measured alpha is and what the search's residual is
made of:

* ``--true-alpha``: the test flight's alpha replaced by JSBSim's ``aero/alpha-rad`` (the reference
  flight keeps its measured alpha): is a miss the alpha or the search?
* ``--instrumented-slopes``: the whole flight decoded with
  ``gcs_sysid.estimation.airangles.INSTRUMENTED_SLOPES = True`` (the elevator-instrumented lift slope
  of the aided alpha), reference model refitted.
* ``--truth-in-both alpha beta rates`` (fifteenth session, branch i9-turb): JSBSim's ``aero/alpha-rad``,
  ``aero/beta-rad`` and/or aero rates (``p_aero``, ``q_aero``, ``r_aero``: the rates the aerodynamics see, the
  rotational gusts removed: the measured normalised rate plus JSBSim's aero-minus-body rate, normalised with
  JSBSim's airspeed) in place of the measured ones in *both* flights, and the reference model refitted on them
  (``gcs_sysid.diagnose.fit.fit_model``): which regressor a miss in turbulence comes from.
* ``--decompose``: for ``Cm:alpha^2`` flights, the untouched-segment gain that the *exact* injected
  term (``k alpha_true^2``) would give on the search's own Cm residual (the ceiling of any search at
  this residual), again with the gust pitch rate (JSBSim's ``q_aero - q``, which the model's
  ``Cm_q`` sees and the gyro does not) removed, and the RMS of the coefficient's own measurement
  error (measured Cm minus JSBSim's).

Usage::

    python -m benchmarks.search_jsbsim_cm DIR AIRCRAFT [--glob Cm_alpha2] [--thresholds '{"lift_alpha_hz": 0.2}']
        [--true-alpha] [--instrumented-slopes] [--decompose]

``DIR`` is an ``eval_jsbsim_diagnose --out`` directory of the ``sweep`` plan (``<ac>-ref-sweep.tlog``
and the test flights with their truth). One line per flight: the truth, the first three named
findings (estimate minus the model's value, untouched gain, score), the selected terms of the
injected coefficient, the measured alpha's error against the truth (mean / standard deviation, and
the slope of measured on true alpha); ``--summary`` counts top / estimate within 25 % / gain >= 50 %
as ``eval_jsbsim_diagnose`` scores them (single effects; clean flights: nothing named).
"""

from __future__ import annotations

import argparse
import json
import pickle
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

__all__ = ["decoded", "with_truth", "search_flight", "decompose_cm", "main"]


def decoded(tlog: Path, airframe: Path, cache: Path):
    """``(table, states, airframe)`` of a tlog, decoded once and cached as a pickle in ``cache``."""
    from gcs_sysid.diagnose.run import load_measurements

    c = cache / (tlog.stem + ".pkl")
    if c.exists():
        return pickle.loads(c.read_bytes())
    m = load_measurements(tlog, airframe)
    v = (m.table, m.states, m.airframe)
    c.write_bytes(pickle.dumps(v))
    return v


def _alpha_error(table, truth) -> dict:
    am = np.interp(truth["t"], table.t, table.X[:, 0])
    at = truth["alpha"]
    ok = np.isfinite(am) & np.isfinite(at)
    e = am[ok] - at[ok]
    return {"mean_deg": float(np.degrees(e.mean())), "sd_deg": float(np.degrees(e.std())),
            "slope": float(np.polyfit(at[ok], am[ok], 1)[0])}


def with_truth(table, truth: dict, which, airframe):
    """A copy of ``table`` with JSBSim's truth in place of the measured regressors named in ``which``.

    Args:
        table: the coefficient table (regressors ``X`` (T, 10), alpha beta in rad, rates normalised).
        truth: the flight's ``-truth.npz`` arrays (``t``, ``alpha``, ``beta``, ``V``, ``p``/``q``/``r`` and
            ``p_aero``/``q_aero``/``r_aero`` in rad/s).
        which: any of ``"alpha"``, ``"beta"``, ``"rates"`` (the aero rates: the gyro's normalised rate plus
            JSBSim's aero-minus-body rate normalised with the true airspeed, ``b/(2V)`` or ``c/(2V)``).
        airframe: the airframe (``b``, ``c`` in m).

    Returns:
        the modified copy (the original is unchanged).
    """
    import copy

    out = copy.deepcopy(table)
    interp = lambda y: np.interp(out.t, truth["t"], y)  # noqa: E731
    if "alpha" in which:
        out.X[:, 0] = interp(truth["alpha"])
    if "beta" in which:
        out.X[:, 1] = interp(truth["beta"])
    if "rates" in which:
        V = interp(truth["V"])
        for k, n, ref_len in ((2, "p", airframe.b), (3, "q", airframe.c), (4, "r", airframe.b)):
            out.X[:, k] = out.X[:, k] + interp(truth[f"{n}_aero"] - truth[n]) * ref_len / (2.0 * V)
    return out


def search_flight(tlog: Path, model: dict, reference, airframe: Path, cache: Path, thresholds: dict,
                  true_alpha: bool = False, truth_in_both=()):
    """The sparse search on one cached flight; returns (result with residual, context, truth arrays, injected)."""
    from gcs_sysid.diagnose.context import DiagContext
    from gcs_sysid.diagnose.sparse import sparse_search

    table, states, af = decoded(tlog, airframe, cache)
    truth = dict(np.load(tlog.with_name(tlog.stem + "-truth.npz")))
    injected = json.loads(tlog.with_name(tlog.stem + "-effects.json").read_text())["injected"]
    if truth_in_both:
        table = with_truth(table, truth, truth_in_both, af)
    if true_alpha:
        table.X[:, 0] = np.interp(table.t, truth["t"], truth["alpha"])
    ctx = DiagContext.build(table, af, model, states)
    from gcs_sysid.diagnose.core import _angle_sigma

    res = sparse_search(ctx, ctx.Y - ctx.model_values(), reference, thresholds=thresholds, keep_residual=True,
                        angle_sigma=_angle_sigma(states, ctx.t))
    res["alpha_error"] = _alpha_error(table, truth)
    return res, ctx, truth, injected


def decompose_cm(res: dict, ctx, truth: dict, k: float) -> dict:
    """Untouched gain of the exact ``k alpha_true^2`` on the search's Cm residual, with and without the gust pitch rate.

    Args:
        res: :func:`sparse_search` result with ``keep_residual``. ctx: its context. truth: the
            harness's truth arrays. k: the injected ``Cm:alpha^2`` (1/rad^2).

    Returns:
        ``{"exact_gain_pct", "exact_gain_no_gust_q_pct", "residual_rms", "measurement_error_rms"}``
        (RMS over the untouched rows, the training mean removed).
    """
    r = res["residual"][:, 4]
    tr, te = res["rows"]["train"], res["rows"]["untouched"]
    at = np.interp(ctx.t, truth["t"], truth["alpha"])
    inj = k * at**2
    dq = np.interp(ctx.t, truth["t"], truth["q_aero"] - truth["q"])

    def rms(x):
        return float(np.sqrt(np.mean((x[te] - x[tr].mean()) ** 2)))

    # the gust pitch rate's share, fitted with the exact term on the training rows
    A = np.c_[np.ones(tr.size), dq[tr], inj[tr]]
    c = np.linalg.lstsq(A, r[tr], rcond=None)[0]
    r2 = r - c[1] * dq
    y_true = np.interp(ctx.t, truth["t"], truth["Y"][:, 4])
    return {"exact_gain_pct": 100 * (1 - rms(r - inj) / rms(r)),
            "exact_gain_no_gust_q_pct": 100 * (1 - rms(r2 - inj) / rms(r2)),
            "residual_rms": rms(r), "measurement_error_rms": rms(np.nan_to_num(ctx.Y[:, 4]) - y_true)}


def _change(f: dict) -> float:
    if f["cause"].startswith("scale:"):
        return f["estimate"] - 1.0
    if f["cause"].startswith(("delay:", "bias:")):
        return f["estimate"]
    return f["estimate"] - f.get("model_value", 0.0)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("flights", help="an eval_jsbsim_diagnose --out directory (sweep plan)")
    p.add_argument("aircraft")
    p.add_argument("--glob", default="", help="only flights whose name contains this (e.g. Cm_alpha2)")
    p.add_argument("--thresholds", default="{}", help="JSON overrides of sparse.THRESHOLDS")
    p.add_argument("--true-alpha", action="store_true")
    p.add_argument("--instrumented-slopes", action="store_true")
    p.add_argument("--decompose", action="store_true")
    p.add_argument("--truth-in-both", nargs="+", default=(), choices=("alpha", "beta", "rates"),
                   help="JSBSim's truth in place of these regressors in both flights, reference model refitted")
    a = p.parse_args(argv)
    from benchmarks.jsbsim_harness.aircraft import aircraft
    from gcs_sysid.diagnose import run_fit
    from gcs_sysid.diagnose.context import model_as_dict
    from gcs_sysid.diagnose.sparse import reference_context
    from gcs_sysid.estimation import airangles
    from gcs_sysid.sim.model_file import load_model

    airangles.INSTRUMENTED_SLOPES = bool(a.instrumented_slopes)
    run = Path(a.flights)
    af = aircraft(a.aircraft).airframe_path
    cache = run / f"search-cache-{'iv' if a.instrumented_slopes else 'ls'}"
    cache.mkdir(exist_ok=True)
    ref_tlog = run / f"{a.aircraft}-ref-sweep.tlog"
    if not ref_tlog.exists():
        print(f"{ref_tlog}: no reference flight (run eval_jsbsim_diagnose with --out {run} first)", file=sys.stderr)
        return 2
    model_path = cache / "model.toml"
    if not model_path.exists():
        run_fit(ref_tlog, af, model_path)
    model = model_as_dict(load_model(model_path))
    rt, rs, raf = decoded(ref_tlog, af, cache)
    if a.truth_in_both:
        from gcs_sysid.diagnose.fit import fit_model

        rt = with_truth(rt, dict(np.load(run / f"{a.aircraft}-ref-sweep-truth.npz")), a.truth_in_both, raf)
        model = model_as_dict(fit_model(rt)[0])
    reference = reference_context((rt, rs), raf, model)
    thr = json.loads(a.thresholds)
    print(f"reference alpha error: {_alpha_error(rt, dict(np.load(run / f'{a.aircraft}-ref-sweep-truth.npz')))}")
    counts = {"cases": 0, "top": 0, "est": 0, "gain": 0, "all": 0, "clean": 0, "clean_ok": 0}
    for tlog in sorted(run.glob(f"{a.aircraft}-s*.tlog")):
        if a.glob not in tlog.name:
            continue
        t0 = time.perf_counter()
        res, ctx, truth, inj = search_flight(tlog, model, reference, af, cache, thr, a.true_alpha, a.truth_in_both)
        named = [f"{f['cause']} {_change(f):.4g} g{f['gain']['percent']:.0f}% sc{f['evidence']['score']:.2f}"
                 for f in res["findings"][:3]]
        terms = ""
        for e in inj:
            coef = e["cause"].split(":")[0]
            en = next((x for x in res["coefficients"] if x["coefficient"] == coef), None)
            if en:
                terms += f" [{coef}: " + ", ".join(f"{x['term']}={x['estimate']:.3g}" for x in en["terms"]) \
                    + f"; score {en['score']:.2f}, gain {en['held_out']['percent']:.0f}%]"
        ae = res["alpha_error"]
        what = "; ".join(f"{e['cause']}={e['value']:g}" for e in inj) or "clean"
        line = (f"{tlog.stem:44s} {what:22s} -> "
                f"{' | '.join(named) or '-'}{terms} alpha err {ae['mean_deg']:+.2f}/{ae['sd_deg']:.2f} deg "
                f"slope {ae['slope']:.3f}")
        k = [e["value"] for e in inj if e["cause"] == "Cm:alpha^2"]
        if a.decompose and k:
            d = decompose_cm(res, ctx, truth, k[0])
            line += (f" | exact term's untouched gain {d['exact_gain_pct']:.0f}% ({d['exact_gain_no_gust_q_pct']:.0f}% "
                     f"without the gust pitch rate); Cm residual {d['residual_rms']:.5f}, measurement error "
                     f"{d['measurement_error_rms']:.5f}")
        mark = ""
        if not inj:
            counts["clean"] += 1
            counts["clean_ok"] += not res["findings"]
        elif len(inj) == 1:
            e, fs = inj[0], res["findings"]
            counts["cases"] += 1
            ok = [bool(fs) and fs[0]["cause"] == e["cause"], False, False]
            if ok[0]:
                ok[1] = abs(_change(fs[0]) - e["value"]) <= 0.25 * abs(e["value"])
                ok[2] = fs[0]["gain"]["percent"] >= 50.0
            for key, v in zip(("top", "est", "gain"), ok):
                counts[key] += v
            counts["all"] += all(ok)
            mark = " {" + "".join(c if v else "-" for c, v in zip("TEG", ok)) + "}"
        print(line + mark + f" ({time.perf_counter() - t0:.0f} s)", flush=True)
    print(f"single effects: top {counts['top']}/{counts['cases']}, "
          f"estimate within 25 % {counts['est']}/{counts['cases']}, "
          f"gain >= 50 % {counts['gain']}/{counts['cases']}, all three {counts['all']}/{counts['cases']}; "
          f"clean flights with nothing named "
          f"{counts['clean_ok']}/{counts['clean']}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
