"""Variants of the differential step of ``diagnose`` on one diagnosis per case (issue 9).

:mod:`benchmarks.eval_jsbsim_diagnose` runs ``diagnose`` once per case. The between-flight allowances
of :func:`gcs_sysid.diagnose.differential.differential` are its last step and read nothing the earlier
steps change, so the variants compared here share everything up to it: each case is diagnosed once
(with its reference flight, as the CLI does), the differential step is held back, and then run once
per variant on a deep copy of the diagnosis. Scores and ``results-<variant>.jsonl`` are as
:func:`benchmarks.eval_jsbsim_diagnose.score_case` and its ``results.jsonl`` (``--summary`` there
reads them).

Variants (``VARIANTS``): the differential step's switches (``angle_scale_se``, ``alpha_scale``,
``search_residual``, ``delay_same_fit``, ``alpha_jackknife_s``:
:func:`~gcs_sysid.diagnose.differential.differential`), and optionally
``module``: the path of another ``differential.py`` (e.g. main's, from ``git archive``) whose
``differential`` is run instead, loaded into the ``gcs_sysid.diagnose`` package so its relative
imports take this tree's modules (valid only when those are the same as that tree's).

Usage::

    python -m benchmarks.eval_jsbsim_diagnose_variants --aircraft sgs --seeds 1 2 3 \\
        --clean-seeds 11 12 13 14 15 --pairs "Cm:alpha^2,Cn:delta_a" --effects $EFF --out DIR \\
        [--main-differential /path/to/main/gcs_sysid/diagnose/differential.py]
"""

from __future__ import annotations

import argparse
import copy
import importlib.util
import json
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from benchmarks.eval_jsbsim_diagnose import (DURATION_S, PLAN, _cases, _flight, reference_model,  # noqa: E402
                                             score_case, scoring_truth)
from benchmarks.jsbsim_harness import FlightConfig  # noqa: E402

__all__ = ["VARIANTS", "diagnose_held", "main"]

#: name -> switches of the differential step ("module": "main" takes ``--main-differential``)
VARIANTS = {
    "main": {"module": "main"},
    "default": {},
    "scale_se": {"angle_scale_se": True, "alpha_scale": False},
    "search_residual": {"search_residual": True},
    "main_search_residual": {"module": "main", "search_residual": True},
    # branch i9-delay (2026-11-22): the two rules of the differential step added there, each off and both
    "i9delay_before": {"delay_same_fit": False, "alpha_jackknife_s": 0.0, "delay_change_min_t": 0.0},
    "i9delay_after": {"delay_same_fit": True, "alpha_jackknife_s": 15.0, "delay_change_min_t": 0.0},
    "i9delay_no_jackknife": {"delay_same_fit": True, "alpha_jackknife_s": 0.0, "delay_change_min_t": 0.0},
    "i9delay_no_same_fit": {"delay_same_fit": False, "alpha_jackknife_s": 15.0, "delay_change_min_t": 0.0},
    "i9delay_after2": {"delay_same_fit": True, "alpha_jackknife_s": 15.0, "delay_change_min_t": 3.0},
}


def _load_differential(path: str):
    """``differential`` from another ``differential.py``, as a module of the ``gcs_sysid.diagnose`` package."""
    spec = importlib.util.spec_from_file_location("gcs_sysid.diagnose._differential_variant", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


def _memo_structure(modules) -> None:
    """Make each module's ``residual_structure`` (the residual GP on the reference flights, which every
    variant computes on the same residual) compute once per residual and threshold."""
    import hashlib

    import numpy as np

    from gcs_sysid.diagnose.residual_gp import residual_structure

    cache: dict = {}

    def memo(ctx, R, threshold_pct=20.0, **kw):
        key = (hashlib.sha1(np.ascontiguousarray(np.nan_to_num(R)).tobytes()).hexdigest(), ctx.t.size,
               float(threshold_pct), tuple(sorted(kw.items())))
        if key not in cache:
            cache.clear() if len(cache) > 8 else None
            cache[key] = residual_structure(ctx, R, threshold_pct=threshold_pct, **kw)
        return cache[key]

    for m in modules:
        m.residual_structure = memo


def diagnose_held(ac: str, seed: int, effects, out: Path, model_path: Path, ref_meas):
    """Diagnose one case with its reference flight, the differential step held back.

    Returns:
        (diagnosis, references, airframe, differential kwargs core passed, truth doc, seconds).
    """
    import gcs_sysid.diagnose.differential as dmod
    from gcs_sysid.diagnose import diagnose, sparse
    from gcs_sysid.diagnose.differential import Reference
    from gcs_sysid.diagnose.run import load_measurements
    from gcs_sysid.sim.model_file import load_model

    files = _flight(FlightConfig(ac, duration_s=DURATION_S, seed=seed, plan=PLAN), effects, out)
    truth = scoring_truth(json.loads(files.tlog.with_name(files.tlog.stem + "-effects.json").read_text()),
                          files.tlog.with_name(files.tlog.stem + "-truth.npz"))
    t0 = time.perf_counter()
    meas = load_measurements(files.tlog, files.airframe)
    held = {}

    def hold(diag, references, airframe, **kw):
        held.update(diag=diag, references=references, airframe=airframe, kw=kw)
        return {"model_inadequacy": [], "held": True}

    real = dmod.differential
    keep = sparse.THRESHOLDS.get("allowance_on_search_residual", False)
    dmod.differential = hold
    sparse.THRESHOLDS["allowance_on_search_residual"] = True       # so that core keeps the search's residual
    try:
        diagnose(meas.table, meas.airframe, load_model(model_path), meas.states, output_error=False,
                 flight=meas.flight, search=True, search_reference=(ref_meas.table, ref_meas.states),
                 references=[Reference(ref_meas.table, ref_meas.states, ref_meas.flight, label=f"{ac}-ref")])
    finally:
        dmod.differential = real
        sparse.THRESHOLDS["allowance_on_search_residual"] = keep
    return held["diag"], held["references"], held["airframe"], held["kw"], truth, time.perf_counter() - t0


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--aircraft", nargs="+", default=["sgs", "pa28"])
    p.add_argument("--seeds", nargs="*", type=int, default=[1, 2, 3])
    p.add_argument("--clean-seeds", nargs="*", type=int, default=[11, 12, 13, 14, 15])
    p.add_argument("--effects", nargs="+", default=None)
    p.add_argument("--pairs", nargs="*", default=["Cm:alpha^2,Cn:delta_a"])
    p.add_argument("--out", required=True)
    p.add_argument("--variants", nargs="+", default=list(VARIANTS))
    p.add_argument("--main-differential", default=None, help="main's differential.py (for the 'main' variants)")
    p.add_argument("--skip-done", action="store_true",
                   help="skip the cases already in the first variant's results file (a run resumed)")
    a = p.parse_args(argv)
    import gcs_sysid.diagnose.differential as dmod

    fns, mods = {"this": dmod.differential}, [dmod]
    if any(VARIANTS[v].get("module") == "main" for v in a.variants):
        if not a.main_differential:
            p.error("the 'main' variants need --main-differential")
        mm = _load_differential(a.main_differential)
        fns["main"], mods = mm.differential, mods + [mm]
    _memo_structure(mods)
    done = set()
    out_path = Path(a.out) / f"results-{a.variants[0]}.jsonl"
    if a.skip_done and out_path.exists():
        for ln in out_path.read_text().splitlines():
            r = json.loads(ln)
            done.add((r["aircraft"], r["seed"], tuple(tuple(e) for e in r["effects"])))
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    pairs = [tuple(x.split(",")) for x in a.pairs]
    refs = {}
    fhs = {v: open(out / f"results-{v}.jsonl", "a") for v in a.variants}
    for ac, seed, effects in _cases(a.aircraft, a.seeds, a.clean_seeds, pairs):
        if a.effects and effects and not all(e.name in a.effects for e in effects):
            continue
        if (ac, seed, tuple((e.name, e.value) for e in effects)) in done:
            continue
        if ac not in refs:
            refs[ac] = reference_model(ac, out)
        _, model_path, ref_meas = refs[ac]
        try:
            diag, references, airframe, kw, truth, secs = diagnose_held(ac, seed, effects, out, model_path, ref_meas)
        except RuntimeError as exc:
            print(f"{ac} s{seed} {effects}: {exc}", flush=True)
            continue
        tag = "+".join(f"{e.name}={e.value:g}" for e in effects) or "clean"
        line = []
        for v in a.variants:
            spec = dict(VARIANTS[v])
            fn = fns[spec.pop("module", "this")]
            sr = kw.get("search_residual") if spec.pop("search_residual", False) else None
            d = copy.deepcopy(diag)
            t1 = time.perf_counter()
            d.data["differential"] = fn(d, list(references), airframe, threshold_pct=kw.get("threshold_pct", 20.0),
                                        search_residual=sr, **spec)
            sc = score_case(d.findings, truth)
            rec = {"aircraft": ac, "seed": seed, "plan": PLAN, "effects": [[e.name, e.value] for e in effects],
                   "score": sc, "diagnose_s": secs + time.perf_counter() - t1, "variant": v,
                   "findings": [{k: f.get(k) for k in ("cause", "estimate", "std_error", "model_value")}
                                | {"gain_pct": f.get("gain", {}).get("percent")} for f in d.findings],
                   "allowance": [{"cause": x["cause"], "why": x.get("why", "")[:300]}
                                 for x in d.data["differential"].get("allowance", [])]}
            fhs[v].write(json.dumps(rec, default=float) + "\n")
            fhs[v].flush()
            line.append(f"{v}:{'P' if sc['ok'] else 'f'}{sc.get('named', [])[:2]}")
        print(f"{ac:6s} s{seed:<3d} {tag:36s} [{secs:.0f} s] " + "  ".join(line), flush=True)
    for fh in fhs.values():
        fh.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
