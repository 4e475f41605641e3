"""Issue 9's roster counts over ``eval_jsbsim_diagnose.py`` records, and one roster against another.

Issue 9 judges the diagnosis on JSBSim flights with one effect hidden in the aircraft's definition: the injected cause
must be the top finding, its estimate within 25 % of the injected value and its held-out gain at least 50 %, and a
clean flight must name nothing (reported model inadequacy is fine). ``eval_jsbsim_diagnose.py`` scores each case
(``score_case``) and writes one JSON line per case to ``<out>/results.jsonl``; until the thirty-fifth session the
roster's table was added up by scripts kept in ``/tmp`` (the thirty-first session's ``assemble.py`` and ``table.py``,
since lost). This is the committed one.

Counts per case with one injected effect (the fields ``score_case`` writes):

  top     the injected cause is the first finding (``score.effects[0].top``)
  est     its estimate within 25 % of the injected value (``est``); counted wherever the cause is named, first or not
  gain    its held-out gain at least 50 % (``gain``); the same
  all     all three (``score.ok``)

A clean flight counts when nothing is named (``score.ok``). A case whose aircraft left the envelope (``score.error``)
counts as a miss on every count. Cases with two effects (``--pairs``) are counted apart, as the share of pairs with
both effects found. Records are keyed by (aircraft, seed, effects); where several files hold a key, the **last file
given** wins, so a re-run overrides an earlier layer case by case.

Against another roster (``--against``): for each effect, the top rate and its difference from the base's with a
two-sigma band for two independent binomial samples, ``2 sqrt(p (1 - p) (1/n1 + 1/n2))`` with ``p`` the pooled rate;
a difference inside the band is "within draw scatter" (thirty-fifth session's rule: the rosters' draws differ, so
the question is whether a difference is larger than a change of draws alone would give).

Where the two rosters share cases flown alike (the same aircraft, seed and effects, and the same ``plan``,
``sensor_draw`` and ``turbulence_draw`` fields), ``--against`` also pairs them case by case (:func:`flips`; the
thirty-sixth and thirty-seventh sessions' rule for a change of method on the same flights): each count that a case
gains is a win, each it loses a loss, a clean flight that stops naming a cause a win of ``clean``, and a pair whose
both effects become found a win of ``pair``. The flights are the same, so every flip is the method's doing.

Records may be gzip-compressed (``.jsonl.gz``: the committed record sets in ``benchmarks/records/``).

Usage::

    python benchmarks/issue9_counts.py A/results.jsonl B/results.jsonl           # the table and the totals
    python benchmarks/issue9_counts.py new/*.jsonl --against old/*.jsonl       # and the rates against another roster
    python benchmarks/issue9_counts.py new/*.jsonl --against benchmarks/records/issue9-roster-*.jsonl.gz   # paired
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections import defaultdict
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.eval_common import read_lines  # noqa: E402

#: The six effects of issue 9's roster, in the table's column order (``benchmarks/jsbsim_harness/effects.py``).
EFFECTS = ("Cm:alpha^2", "Cl:alpha*beta", "Cn:delta_a", "CY:scale", "delay:delta_e", "bias:airspeed")
#: The roster's aircraft classes, as the thirty-first session's table grouped them (docs/benchmarks.md,
#: "Thirty-first session, i9-roster31"); an aircraft not listed is grouped as "other".
CLASSES = {
    "gliders": ("sgs", "sgs126", "asw20", "eternity"),
    "light GA": ("c172x", "c172p", "pa28", "j3cub", "c182", "navion"),
    "small UAVs": ("ultrastick", "us25e", "rascal"),
    "vintage / racer": ("dr1", "iar80", "c684"),
    "trainers / fighters": ("t6", "t37", "f16", "f4n"),
    "transports": ("b737", "b747", "ka350", "fokker50", "s23"),
}
COUNTS = ("top", "est", "gain", "all")
#: The classes in the tables' order, the unlisted aircraft last.
_CLASS_ORDER = (*CLASSES, "other")


def aircraft_class(name: str) -> str:
    """The class of aircraft ``name`` in :data:`CLASSES` (``"other"`` when it has none)."""
    return next((c for c, names in CLASSES.items() if name in names), "other")


def load(paths) -> dict[tuple, dict]:
    """The records of ``results.jsonl`` files keyed by (aircraft, seed, effects), a later file's record
    overriding an earlier one's.

    Raises:
        ValueError: a line that is not JSON or lacks ``aircraft``, ``seed``, ``effects`` or ``score``, naming the
            file and the line.
    """
    out: dict[tuple, dict] = {}
    for p in paths:
        for n, ln in enumerate(read_lines(p), 1):
            if not ln.strip():
                continue
            try:
                r = json.loads(ln)
                key = (r["aircraft"], int(r["seed"]), tuple((e[0], float(e[1])) for e in r["effects"]))
                if not isinstance(r["score"], dict):
                    raise TypeError("score is not an object")
            except (json.JSONDecodeError, KeyError, TypeError, IndexError, ValueError) as exc:
                raise ValueError(f"{p}:{n}: not an eval_jsbsim_diagnose record (aircraft, seed, effects, "
                                 f"score expected): {exc}") from None
            out[key] = r
    return out


def case_counts(r: dict) -> dict[str, bool]:
    """The four counts (:data:`COUNTS`) of one single-effect record; all False where the aircraft left the
    envelope (``score.error``) or the score has no effect row."""
    sc = r["score"]
    rows = sc.get("effects") or []
    if "error" in sc or not rows:
        return dict.fromkeys(COUNTS, False)
    e = rows[0]
    return {"top": bool(e.get("top")), "est": bool(e.get("est")), "gain": bool(e.get("gain")),
            "all": bool(sc.get("ok"))}


def tally(recs: dict[tuple, dict]) -> dict:
    """Counts by aircraft and effect, clean flights by aircraft, and the pairs.

    Returns:
        ``{"cells": {(aircraft, effect): {"n", "top", "est", "gain", "all"}}, "clean": {aircraft: [none named, n]},
        "named_clean": {aircraft: [(seed, [causes])]}, "pairs": [n with both found, n]}``.
    """
    cells: dict = defaultdict(lambda: dict.fromkeys(("n",) + COUNTS, 0))
    clean: dict = defaultdict(lambda: [0, 0])
    named_clean: dict = defaultdict(list)
    pairs = [0, 0]
    for (ac, seed, effs), r in sorted(recs.items()):
        if not effs:
            clean[ac][1] += 1
            if r["score"].get("ok"):
                clean[ac][0] += 1
            else:
                named_clean[ac].append((seed, list(r["score"].get("named", []))))
        elif len(effs) == 1:
            c = cells[(ac, effs[0][0])]
            c["n"] += 1
            for k, v in case_counts(r).items():
                c[k] += v
        else:
            pairs[1] += 1
            rows = r["score"].get("effects") or []
            pairs[0] += bool(rows) and "error" not in r["score"] and all(e.get("found") for e in rows)
    return {"cells": dict(cells), "clean": dict(clean), "named_clean": dict(named_clean), "pairs": pairs}


def effect_totals(t: dict) -> dict[str, dict[str, int]]:
    """Per effect: ``{"n", "top", "est", "gain", "all"}`` summed over the aircraft."""
    out = {e: dict.fromkeys(("n",) + COUNTS, 0) for e in EFFECTS}
    for (_, e), c in t["cells"].items():
        if e in out:
            for k in out[e]:
                out[e][k] += c[k]
    return out


def binomial_band(k1: int, n1: int, k2: int, n2: int) -> tuple[float, float]:
    """The difference of two rates, percentage points, and its two-sigma band under one pooled rate.

    Returns:
        ``(100 (k1/n1 - k2/n2), 200 sqrt(p (1 - p) (1/n1 + 1/n2)))`` with ``p = (k1 + k2) / (n1 + n2)``.

    Raises:
        ValueError: ``n1`` or ``n2`` not positive.
    """
    if n1 <= 0 or n2 <= 0:
        raise ValueError(f"both samples need cases (got n1={n1}, n2={n2})")
    p = (k1 + k2) / (n1 + n2)
    return 100.0 * (k1 / n1 - k2 / n2), 200.0 * math.sqrt(p * (1.0 - p) * (1.0 / n1 + 1.0 / n2))


def _pct(k: int, n: int) -> str:
    return f"{k} ({100.0 * k / n:.0f} %)" if n else "0"


def roster_table(t: dict) -> str:
    """The markdown table: per aircraft, top/estimate/gain/all three per effect, the clean flights, the row sums."""
    acs = sorted({a for a, _ in t["cells"]} | set(t["clean"]), key=lambda a: (_CLASS_ORDER.index(aircraft_class(a)), a))
    lines = ["| class | aircraft | " + " | ".join(f"`{e}`" for e in EFFECTS) + " | clean | top | all three |",
             "|" + "---|" * (len(EFFECTS) + 5)]
    for a in acs:
        cells, top, ok, n = [], 0, 0, 0
        for e in EFFECTS:
            c = t["cells"].get((a, e))
            if c is None:
                cells.append("-")
                continue
            cells.append(f"{c['top']}/{c['est']}/{c['gain']}/{c['all']} of {c['n']}")
            top, ok, n = top + c["top"], ok + c["all"], n + c["n"]
        cl = t["clean"].get(a, [0, 0])
        lines.append(f"| {aircraft_class(a)} | {a} | " + " | ".join(cells)
                     + f" | {cl[0]}/{cl[1]} | {top}/{n} | {ok}/{n} |")
    return "\n".join(lines)


def totals_table(t: dict) -> str:
    """The markdown totals: all effects, each effect, each class; clean flights with nothing named."""
    tot = effect_totals(t)
    lines = ["| group | cases | top | estimate | gain | all three | clean: none named |",
             "|---|---|---|---|---|---|---|"]
    s = {k: sum(v[k] for v in tot.values()) for k in ("n",) + COUNTS}
    cn, cd = sum(v[0] for v in t["clean"].values()), sum(v[1] for v in t["clean"].values())
    lines.append(f"| all | {s['n']} | " + " | ".join(_pct(s[k], s["n"]) for k in COUNTS) + f" | {cn}/{cd} |")
    for e in EFFECTS:
        v = tot[e]
        lines.append(f"| `{e}` | {v['n']} | " + " | ".join(_pct(v[k], v["n"]) for k in COUNTS) + " | |")
    for cls in _CLASS_ORDER:
        acs = ({a for a, _ in t["cells"] if aircraft_class(a) == cls}
               | {a for a in t["clean"] if aircraft_class(a) == cls})
        if not acs:
            continue
        v = {k: sum(c[k] for (a, _), c in t["cells"].items() if a in acs) for k in ("n",) + COUNTS}
        cl = [sum(t["clean"].get(a, [0, 0])[i] for a in acs) for i in (0, 1)]
        lines.append(f"| {cls} ({', '.join(sorted(acs))}) | {v['n']} | "
                     + " | ".join(_pct(v[k], v["n"]) for k in COUNTS)
                     + f" | {cl[0]}/{cl[1]} |")
    if t["pairs"][1]:
        lines.append(f"\nPairs with both effects found: {t['pairs'][0]} of {t['pairs'][1]}.")
    return "\n".join(lines)


def against_table(t: dict, base: dict) -> str:
    """Each effect's top rate against the base roster's, with the two-sigma band (:func:`binomial_band`)."""
    new, old = effect_totals(t), effect_totals(base)
    lines = ["| effect | top | base top | difference (points) | 2-sigma band | reading |", "|---|---|---|---|---|---|"]
    for e in EFFECTS:
        a, b = new[e], old[e]
        if not a["n"] or not b["n"]:
            continue
        d, band = binomial_band(a["top"], a["n"], b["top"], b["n"])
        reading = "within draw scatter" if abs(d) <= band else ("higher" if d > 0 else "lower")
        lines.append(f"| `{e}` | {_pct(a['top'], a['n'])} | {_pct(b['top'], b['n'])} | {d:+.0f} | +-{band:.0f} | "
                     f"{reading} |")
    return "\n".join(lines)


#: The record fields that say how a case was flown; two records pair only where they agree (absent counts as
#: a value of its own).
FLOWN_AS = ("plan", "sensor_draw", "turbulence_draw")


def _label(key: tuple) -> str:
    ac, seed, effs = key
    return f"{ac} s{seed} " + (" + ".join(f"{e}={v:g}" for e, v in effs) if effs else "clean")


def _pair_found(r: dict) -> bool:
    rows = r["score"].get("effects") or []
    return bool(rows) and "error" not in r["score"] and all(e.get("found") for e in rows)


def flips(recs: dict[tuple, dict], base: dict[tuple, dict]) -> dict:
    """The cases of ``recs`` against the same cases of ``base``, flown alike (:data:`FLOWN_AS`), count by count.

    Args:
        recs, base: :func:`load` results (the candidate and the base roster).

    Returns:
        ``{"paired": n, "unpaired": n, "counts": {count: {"wins": [label...], "losses": [label...]}}}`` with the
        counts :data:`COUNTS` (single-effect cases), ``"clean"`` (a clean flight names nothing) and ``"pair"``
        (both effects of a two-effect case found); a label reads ``"sgs s1 Cn:delta_a=-0.06"``. A case in only one
        roster, or flown differently, is unpaired.
    """
    out = {k: {"wins": [], "losses": []} for k in (*COUNTS, "clean", "pair")}
    paired = unpaired = 0
    for key in sorted(set(recs) | set(base)):
        r, b = recs.get(key), base.get(key)
        if r is None or b is None or any(r.get(f) != b.get(f) for f in FLOWN_AS):
            unpaired += 1
            continue
        paired += 1
        effs = key[2]
        if not effs:
            now, was = {"clean": bool(r["score"].get("ok"))}, {"clean": bool(b["score"].get("ok"))}
        elif len(effs) == 1:
            now, was = case_counts(r), case_counts(b)
        else:
            now, was = {"pair": _pair_found(r)}, {"pair": _pair_found(b)}
        for k in now:
            if now[k] != was[k]:
                out[k]["wins" if now[k] else "losses"].append(_label(key))
    return {"paired": paired, "unpaired": unpaired, "counts": out}


def flips_table(f: dict) -> str:
    """The markdown table of :func:`flips`, and each flipped case."""
    lines = [f"Paired case by case: {f['paired']} cases ({f['unpaired']} unpaired).", "",
             "| count | wins | losses | net |", "|---|---|---|---|"]
    for k, v in f["counts"].items():
        lines.append(f"| {k} | {len(v['wins'])} | {len(v['losses'])} | {len(v['wins']) - len(v['losses']):+d} |")
    for k, v in f["counts"].items():
        for side, word in (("wins", "win"), ("losses", "loss")):
            if v[side]:
                lines.append(f"- {k} {word}: " + "; ".join(v[side]))
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("results", nargs="+", metavar="JSONL", help="eval_jsbsim_diagnose results.jsonl files (later wins)")
    p.add_argument("--against", nargs="+", metavar="JSONL", default=None, help="the base roster's results files")
    a = p.parse_args(argv)
    try:
        recs = load(a.results)
        base_recs = load(a.against) if a.against else None
        t = tally(recs)
        base = tally(base_recs) if base_recs is not None else None
    except (OSError, ValueError) as exc:
        print(f"issue9_counts: {exc}", file=sys.stderr)
        return 2
    print(roster_table(t) + "\n\n" + totals_table(t))
    named = [f"{ac} s{s}: {', '.join(c)}" for ac, v in sorted(t["named_clean"].items()) for s, c in v]
    if named:
        print("\nClean flights that named a cause: " + "; ".join(named) + ".")
    if base is not None:
        print("\n" + against_table(t, base))
        f = flips(recs, base_recs)
        if f["paired"]:
            print("\n" + flips_table(f))
    return 0


if __name__ == "__main__":
    sys.exit(main())
