"""Where an injected term's signal goes on its way to the sparse search (attribution only; forty-ninth session).

Issue 9's misses of ``Cl:alpha*beta`` (and part of ``Cm:alpha^2``'s) are cases where the search's first term in the
coefficient is the injected one but reads a third of its size, so that neither its PRESS drop nor its held-out gain
passes. This script follows the injected term through the residuals the diagnosis forms, for each case of one effect
that ``eval_jsbsim_diagnose.py`` (or ``pool_eval.py issue9``) left in a work directory, and reads the term's share of
each by least squares on JSBSim's own regressors over the search's training rows (the term's column beside a constant
and the lower-order column the term's share must not borrow from: ``beta`` for ``alpha*beta``, ``alpha`` for
``alpha^2``):

* ``R``: the measured coefficient less the reference model, as the diagnosis starts from;
* ``base``: the reference flight's ridge inadequacy predicted on this flight (``sparse.sparse_search``'s
  ``inadequacy_prediction``), which the search subtracts;
* ``Rd``: what the search selects on (``R`` less ``base`` and the angle nuisance);
* ``ideal``: JSBSim's coefficient *without* the injected term less the reference model: the model's own error on this
  flight, which a perfect ``base`` would equal.

Each is printed as a share of the injected value (1 for ``Rd`` is the whole term found). ``R`` below 1 where
``ideal`` is negative is the reference model's own error on the response the loop flies against the term (the
attenuated ``Cl_p`` and ``Cl_delta_a`` of a model fitted at the gyro's rate in rolling gusts; ``docs/diagnose.md``,
"The air-relative roll rate"); ``base`` above 0 is the ridge reading that response as the reference's inadequacy (a
share of the term taken out). The truth is read only here, to attribute; the pipeline never reads it.

Usage::

    python benchmarks/term_shares.py WORK --seed 3 --effect Cl:alpha*beta [--aircraft c172x dr1] [--out shares.jsonl]

``WORK`` holds the cases' files directly or in sub-folders (``pool_eval.py``'s ``<arm>-<aircraft>-<group>/``); the
reference model and flight are read from the case's folder (fitted there if absent). The flights use the evaluation's
plan (``sweep``) and per-aircraft draws.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

#: effect -> (coefficient, the term's column, the column it must not borrow from), as functions of JSBSim's truth
TERMS = {
    "Cl:alpha*beta": ("Cl", lambda a, b: a * b, lambda a, b: b),
    "Cm:alpha^2": ("Cm", lambda a, b: a * a, lambda a, b: a),
}
_COEFS = ("CX", "CY", "CZ", "Cl", "Cm", "Cn")


def share(y: np.ndarray, term: np.ndarray, lower: np.ndarray, rows: np.ndarray) -> float:
    """Least-squares coefficient of ``term`` in ``y`` beside a constant and ``lower``, on ``rows``.

    Args:
        y, term, lower: (T,) arrays. rows: integer row indices.

    Returns:
        The coefficient of ``term`` (units of ``y`` per unit of ``term``).
    """
    A = np.column_stack([np.ones(rows.size), lower[rows], term[rows]])
    return float(np.linalg.lstsq(A, y[rows], rcond=None)[0][2])


def _capture():
    """Wrap ``sparse.sparse_search`` so that each call keeps its residual and rows; returns the dict it fills."""
    import gcs_sysid.diagnose.sparse as sparse

    cap: dict = {}
    original = sparse.sparse_search

    def wrapped(ctx, R, reference=None, *args, **kw):
        kw["keep_residual"] = True
        res = original(ctx, R, reference, *args, **kw)
        # the diagnosis pops the residual and the rows from its result after the call: keep copies
        cap.update(ctx=ctx, R=np.array(R), Rd=np.array(res["residual"]), rows=dict(res["rows"]),
                   base=None if res.get("inadequacy_prediction") is None else np.array(res["inadequacy_prediction"]),
                   inadequacy=list(res.get("inadequacy") or []))
        return res

    sparse.sparse_search = wrapped
    return cap


def case_shares(work: Path, ac: str, seed: int, effect: str, value: float, cap: dict,
                refs: dict | None = None) -> dict | None:
    """Diagnose one case as the evaluation does and read the injected term's shares.

    ``refs``: the reference fits already made, by folder (filled here; both sizes of an aircraft share one).

    Returns:
        ``{"aircraft", "value", "top", "R", "base", "Rd", "ideal", "base_rms", "ref_explained"}`` (shares of
        ``value``; ``base_rms`` the inadequacy prediction's RMS on this flight's training rows, ``ref_explained`` the
        RMS it explained on the reference), or None when the case's files are not in ``work``.
    """
    from benchmarks import eval_jsbsim_diagnose as E
    from benchmarks.jsbsim_harness.effects import Effect, case_stem

    stem = case_stem(ac, seed, [(effect, value)]) + E._stem_suffix(E.PLAN, E.SENSOR_DRAW, E.TURBULENCE_DRAW)
    hits = sorted(work.glob(f"**/{stem}.tlog"))
    if not hits:
        return None
    # a folder whose reference model is already fitted, else the first
    d = next((h.parent for h in hits if any(h.parent.glob(f"{ac}-ref-*-model.toml"))), hits[0].parent)
    refs = {} if refs is None else refs
    if d not in refs:                            # fitted once per folder, not once per case
        refs[d] = E.reference_model(ac, d, plan=E.PLAN)[1:]
    model_path, ref = refs[d]
    findings, _, _ = E.diagnose_case(ac, seed, [Effect(effect, value)], d, model_path, ref, plan=E.PLAN)
    coef, term_fn, lower_fn = TERMS[effect]
    j = _COEFS.index(coef)
    ctx, R, Rd, tr = cap["ctx"], np.nan_to_num(cap["R"][:, j]), cap["Rd"][:, j], np.asarray(cap["rows"]["train"])
    truth = np.load(d / f"{stem}-truth.npz")
    a = np.interp(ctx.t, truth["t"], truth["alpha"])
    b = np.interp(ctx.t, truth["t"], truth["beta"])
    term, lower = term_fn(a, b), lower_fn(a, b)
    model = np.nan_to_num(ctx.Y[:, j]) - R
    measured_free = np.interp(ctx.t, truth["t"], truth["Y"][:, j]) - value * term
    base = cap["base"][:, j] if cap["base"] is not None else None
    explained = [i.get("rms_explained") for i in cap["inadequacy"] if i.get("coefficient") == coef]
    return {"aircraft": ac, "value": value, "top": bool(findings and findings[0]["cause"] == effect),
            "R": share(R, term, lower, tr) / value,
            "base": None if base is None else share(base, term, lower, tr) / value,
            "Rd": share(Rd, term, lower, tr) / value,
            "ideal": share(measured_free - model, term, lower, tr) / value,
            "base_rms": None if base is None else float(np.std(base[tr])),
            "ref_explained": explained[0] if explained else None}


def main(argv=None) -> int:
    from benchmarks import eval_jsbsim_diagnose as E
    from benchmarks.jsbsim_harness.effects import SIZES

    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("work", type=Path)
    p.add_argument("--seed", type=int, required=True)
    p.add_argument("--effect", required=True, choices=sorted(TERMS))
    p.add_argument("--aircraft", nargs="+", default=None, help="default: every aircraft with the effect's files")
    p.add_argument("--out", type=Path, default=None, help="append one JSON line per case")
    p.add_argument("--air-roll-rate", default=None, choices=("off", "fit", "reference", "both", "reference:Cl"),
                   help="gcs_sysid.diagnose.run.AIR_ROLL_RATE for the run (default: the package's)")
    a = p.parse_args(argv)
    if a.air_roll_rate is not None:
        from gcs_sysid.diagnose import run as diagnose_run

        diagnose_run.AIR_ROLL_RATE = a.air_roll_rate
    E.SENSOR_DRAW, E.TURBULENCE_DRAW = "per_aircraft", "per_aircraft"
    names = a.aircraft or sorted({f.name.split("-s")[0] for f in a.work.glob(f"**/*-s{a.seed}-*.tlog")})
    cap, refs = _capture(), {}
    rows = []
    print("| aircraft | value | top | R | base | Rd | ideal | base RMS / reference's |")
    print("|---|---|---|---|---|---|---|---|")
    for ac in names:
        for value in SIZES[a.effect]:
            r = case_shares(a.work, ac, a.seed, a.effect, value, cap, refs)
            if r is None:
                continue
            rows.append(r)
            ratio = r["base_rms"] / r["ref_explained"] if r["base_rms"] and r["ref_explained"] else float("nan")
            print(f"| {ac} | {value:g} | {'yes' if r['top'] else 'no'} | {r['R']:.2f} | "
                  f"{float('nan') if r['base'] is None else r['base']:.2f} | {r['Rd']:.2f} | {r['ideal']:.2f} | "
                  f"{ratio:.2f} |", flush=True)
            if a.out:
                with a.out.open("a") as f:
                    f.write(json.dumps(r) + "\n")
    for top in (True, False):
        sel = [r for r in rows if r["top"] == top and r["base"] is not None]
        if sel:
            med = {k: float(np.median([r[k] for r in sel])) for k in ("R", "base", "Rd", "ideal")}
            print(f"{'tops' if top else 'misses'} ({len(sel)}): median shares " + ", ".join(f"{k} {v:.2f}"
                                                                                          for k, v in med.items()))
    return 0 if rows else 1


if __name__ == "__main__":
    sys.exit(main())
