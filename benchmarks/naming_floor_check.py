"""Injected size against the sparse search's naming floor on issue 9's records (fifty-third session; analysis only).

``eval_jsbsim_diagnose.py`` records carry, per case, each coefficient's ``naming_floor``
(:func:`gcs_sysid.diagnose.sparse.naming_floor`: the smallest change of a common term the search's share gates let
it name on that flight). For the term effects whose term is one of :data:`gcs_sysid.diagnose.sparse.FLOOR_TERMS`
(``Cl:alpha*beta``, ``Cm:alpha^2``) this prints, by bands of ``r = |k| / k_min`` (the injected size over the flight's
floor), how many cases there are and how many name the injected cause first, then each case. Cases repeated in the
file (one pool job per effect group) count once. Measured in ``docs/benchmarks.md``, "Fifty-third session, lead".

Usage::

    python benchmarks/naming_floor_check.py RESULTS.jsonl [RESULTS.jsonl ...]
"""

from __future__ import annotations

import argparse
import json

#: The term effects the floor speaks to: effect -> (coefficient, library term).
TERMS = {"Cl:alpha*beta": ("Cl", "alpha*beta"), "Cm:alpha^2": ("Cm", "alpha^2")}
BANDS = ((0.0, 0.5), (0.5, 1.0), (1.0, 1.5), (1.5, 2.5), (2.5, float("inf")))


def ratios(paths: list[str]) -> list[dict]:
    """One row per case: ``{"effect", "aircraft", "size", "ratio", "top", "named"}`` (``ratio`` None without a
    floor)."""
    cases = {}
    for p in paths:
        for line in open(p):
            r = json.loads(line)
            if not r.get("effects") or r["effects"][0][0] not in TERMS:
                continue
            eff, k = r["effects"][0]
            coef, term = TERMS[eff]
            fl = (r.get("naming_floor") or {}).get(coef) or {}
            kmin = (fl.get("min_change") or {}).get(term)
            e = (r["score"].get("effects") or [{}])[0]
            cases[(r["aircraft"], r["seed"], eff, k)] = {
                "effect": eff, "aircraft": r["aircraft"], "size": k, "ratio": abs(k) / kmin if kmin else None,
                "top": bool(e.get("top")), "named": [f["cause"] for f in r.get("findings", [])][:3]}
    return list(cases.values())


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("results", nargs="+")
    a = p.parse_args(argv)
    rows = ratios(a.results)
    for eff in TERMS:
        sub = [x for x in rows if x["effect"] == eff]
        no = [x for x in sub if x["ratio"] is None]
        print(f"{eff}: {len(sub)} cases ({len(no)} without a floor: the flight left the envelope or was not searched)")
        for lo, hi in BANDS:
            b = [x for x in sub if x["ratio"] is not None and lo <= x["ratio"] < hi]
            if b:
                print(f"  |k| / k_min in [{lo:g}, {hi:g}): {len(b)} cases, {sum(x['top'] for x in b)} top")
        for x in sorted((x for x in sub if x["ratio"] is not None), key=lambda x: x["ratio"]):
            print(f"    {x['aircraft']:<10s} {x['size']:>6g}  r {x['ratio']:6.2f}  top {str(x['top']):5s}  "
                  f"named {', '.join(x['named']) or 'nothing'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
