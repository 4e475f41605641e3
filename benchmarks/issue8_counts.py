"""Issue 8's counts over ``eval_jsbsim.py --json`` lines, and the flips of one run against another (rule 8(b)).

Issue 8 judges the replay against JSBSim's exact truth. Since the twelfth session the project has decided GP-seed
dependent defaults by *counts* over flights x coefficients (the project's rule 8(b): at each of two GP seeds the
candidate's wins are at least twice its losses, and the aircraft that lose a count at both seeds are named). Until
the thirty-third session those counts were computed by scripts kept in ``/tmp``; this is the committed one.

Counts (the fields ``benchmarks/eval_jsbsim.py`` writes per flight; errors are ``100 RMS(est - truth) / RMS(truth)``
on the held-out segment):

  meas       the measured coefficients (``meas``) within 3 % (CX CY CZ) / 8 % (Cl Cm Cn), per flight x coefficient
  gp         the GP held out (``gp``) within 5 / 10 %, per flight x coefficient
  true_air   the GP at the true regressors with the rates JSBSim's aerodynamics reads (``true_air``) within 5 / 10 %
  gp<ls      the GP better than the stepwise least squares at the same regressors (``gp`` < ``ls``)
  gp<fair    Cl only: the GP better than the fair least-squares line (``gp`` < ``ls_airtrain``: Cl trained on the
             GP's air-rate target, ``eval_jsbsim.ls_air_target_scores``; its other five coefficients are ``ls``'s, so
             they are not counted twice; only on rows that have it, i.e. with ``air_roll_train``, the default since
             the thirtieth session)
  cov_gp     the six-output mean coverage of the replay's band (``cov_gp``) within 90-98 %, per flight
  cov_tair   the same at exact conditions with the aero rates (``cov_true_air``), per flight
  corr       a learned output correlation above 0.5 (``max_corr``), per flight: FEWER is better
  corr_false a learned output correlation above 0.5 where the truth has none: a pair of ``corr_pairs`` above 0.5 whose
             JSBSim residual correlation (``truth_resid_corr``) is below 0.3 (``eval_common.false_couplings``), per
             flight: FEWER is better. The issue's line as written; ``corr`` also counts the couplings JSBSim's own
             aerodynamics has (e.g. CZ-Cm, residual correlation 0.75-0.98 on flights that gained one in the
             sixty-eighth session). Since the sixty-ninth session in ``corr``'s place among the default counts
             (``corr`` is still tabled and can be named with ``--counts``); rows written before the fields (before
             2026-11-29) score None
  cov_tair_c the band at exact conditions per coefficient (``cov_true_air_each``) within 90-98 %, per flight x
             coefficient (since the sixty-fourth session, in ``cov_tair``'s place among the default counts of the
             flips and the verdict, :data:`DEFAULT_COUNTS`: the six-output mean hides a coefficient far below the
             band behind others near 100 %; ``cov_tair`` is still counted in the tables and can be named with
             ``--counts``)
  cov_gp_c   the replay's held-out band per coefficient (``cov_gp_each``) within 90-98 %, per flight x coefficient
             (since the seventieth session, in ``cov_gp``'s place among the default counts, for the reason
             ``cov_tair_c`` took ``cov_tair``'s: on issue 8's 75 records Cl's held-out band sits below 90 % on 42 of 75
             flights while CX, CZ and Cn sit near 98-100 % and hold the six-output mean inside; ``cov_gp`` is still
             counted in the tables and can be named with ``--counts``)

Information (no count, no flip): the held-out band per coefficient (``cov_gp_each``) and the band at exact conditions
per coefficient (``cov_true_air_each``, written since the sixty-fourth session): each one's coverage pooled over the
flights (the mean of the flights' shares; every flight has the same held-out length) and the flights within, below
and above 90-98 %. The six-output mean of ``cov_tair``
can sit in 90-98 % with one coefficient far below and the others near 100 % (``docs/benchmarks.md``, "Sixty-fourth
session").

A value that is missing or not finite satisfies no count (it is scored as not within, not better, not in the band,
not correlated). The bounds are inclusive (``<= 3``, ``90 <= cov <= 98``); ``gp < ls`` and ``max_corr > 0.5`` are
strict.

A flip is one flight x coefficient (or flight) whose count changes between the base (``--against``) and the
candidate (the positional files): a win where it becomes satisfied (for ``corr``: where a flight's correlation
drops to 0.5 or below; for ``corr_false``: where no pair above 0.5 is left that the truth does not couple), a loss the
other way. Runs are paired by flight (aircraft, turbulence, seed, AOA_SSA) and
by GP seed: the rows' ``gp_seed`` field (``eval_jsbsim.py --gp-seed``, written since the thirty-third session; 0
when absent), or ``FILE@N`` to state it for every row of a file written before that. With pairs at two or more GP
seeds the rule 8(b) verdict is printed: it holds when at every seed the wins are at least twice the losses and
there is a win (the thirty-second session's i8-clband reading: no wins, no case). An aircraft "loses a count" at a
seed when one of its counts, summed over its flights, goes down (the twenty-fifth session's table); aircraft with
a lost flip whose count does not go down are listed apart.

Files may be gzip-compressed (``.jsonl.gz``: the committed record sets in ``benchmarks/records/``).

Usage::

    python benchmarks/issue8_counts.py base-g0.jsonl                     # one run's counts
    python benchmarks/issue8_counts.py cand-g0.jsonl cand-g1.jsonl --against base-g0.jsonl base-g1.jsonl
    python benchmarks/issue8_counts.py old-s1.jsonl@1 --against main-s1.jsonl@1   # rows without gp_seed
    python benchmarks/issue8_counts.py cand-g0.jsonl cand-g1.jsonl --against base-g0.jsonl base-g1.jsonl \
        --counts meas gp true_air "gp<ls" "gp<fair"     # the flips and the verdict on these counts only
    python benchmarks/issue8_counts.py cand-g0.jsonl cand-g1.jsonl --against base-g0.jsonl base-g1.jsonl \
        --ls-loss-needs-gp-worse 0.1     # a lost gp<ls counts only where the GP's own error grew (> 0.1 point)

``--counts`` restricts the flips and the verdict to the named counts (the tables keep them all). The thirty-first
and thirty-second sessions decided with the bands and the correlation left out ("coverage not counted"); the
thirty-third session found that the sideslip profile's verdict depends on that choice (``docs/benchmarks.md``,
"Thirty-third session, lead").
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections import defaultdict
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.eval_common import false_couplings, read_lines  # noqa: E402

COEFFICIENTS = ("CX", "CY", "CZ", "Cl", "Cm", "Cn")
FORCES = COEFFICIENTS[:3]

#: the issue's lines, % of the truth's RMS: (forces, moments) per error field
WITHIN = {"meas": (3.0, 8.0), "gp": (5.0, 10.0), "true_air": (5.0, 10.0)}
#: the band criterion: the six-output mean coverage within these bounds, %
BAND = (90.0, 98.0)
#: the coefficients where the fair least-squares line differs from ``ls`` (``eval_jsbsim.ls_air_target_scores``)
FAIR_LS = ("Cl",)
#: a learned output correlation above this counts (fewer is better)
CORR_LIMIT = 0.5

#: count name -> (kind, description); kind "coef" counts flight x coefficient, "flight" counts flights
COUNTS = {
    "meas": ("coef", "measured within 3/8 %"),
    "gp": ("coef", "GP held out within 5/10 %"),
    "true_air": ("coef", "GP at the true regressors, aero rates, within 5/10 %"),
    "gp<ls": ("coef", "GP better than least squares"),
    "gp<fair": ("coef", "Cl: GP better than the fair least-squares line (ls_airtrain)"),
    "cov_gp": ("flight", "band (cov_gp) within 90-98 %"),
    "cov_tair": ("flight", "band at exact conditions (cov_true_air) within 90-98 %"),
    "corr": ("flight", "learned output correlation above 0.5 (fewer is better)"),
    "cov_tair_c": ("coef", "band at exact conditions per coefficient (cov_true_air_each) within 90-98 %"),
    "cov_gp_c": ("coef", "held-out band per coefficient (cov_gp_each) within 90-98 %"),
    "corr_false": ("flight", "learned output correlation above 0.5 where JSBSim's residual one is below 0.3 "
                             "(fewer is better)"),
}
#: the counts the flips and the verdict use unless ``--counts`` names others
DEFAULT_COUNTS = ("meas", "gp", "true_air", "gp<ls", "gp<fair", "cov_gp_c", "cov_tair_c", "corr_false")
#: counts where fewer is better
FEWER_IS_BETTER = ("corr", "corr_false")


def _num(x) -> float:
    """``x`` as a float; NaN where it is missing or not a number."""
    try:
        v = float(x)
    except (TypeError, ValueError):
        return math.nan
    return v


def item_values(row: dict) -> dict[tuple[str, str], bool | None]:
    """The count items of one flight's JSON line.

    Args:
        row: one ``eval_jsbsim.py --json`` line, parsed (``meas``, ``gp``, ``true_air``, ``ls`` and optionally
            ``ls_airtrain``: dicts coefficient -> % error; ``cov_gp``, ``cov_true_air``: %; ``max_corr``).

    Returns:
        ``{(count, coefficient or ""): satisfied}``: True / False per item; None where the row has no such field
        at all (``gp<fair`` without ``ls_airtrain``, ``corr`` without ``max_corr``, a score written before it
        existed), which is left out of the count and of the flips.
    """
    out: dict[tuple[str, str], bool | None] = {}
    for key, (f_line, m_line) in WITHIN.items():
        d = row.get(key)
        for c in COEFFICIENTS:
            out[(key, c)] = None if d is None else _num(d.get(c)) <= (f_line if c in FORCES else m_line)
    for name, ls_key, coefs in (("gp<ls", "ls", COEFFICIENTS), ("gp<fair", "ls_airtrain", FAIR_LS)):
        g, ls = row.get("gp"), row.get(ls_key)
        for c in coefs:
            out[(name, c)] = None if g is None or ls is None else _num(g.get(c)) < _num(ls.get(c))
    for name, key in (("cov_gp", "cov_gp"), ("cov_tair", "cov_true_air")):
        out[(name, "")] = None if key not in row else BAND[0] <= _num(row[key]) <= BAND[1]
    out[("corr", "")] = None if "max_corr" not in row else _num(row["max_corr"]) > CORR_LIMIT
    fc = false_couplings(row.get("corr_pairs"), row.get("truth_resid_corr"))
    out[("corr_false", "")] = None if fc is None else bool(fc)
    for name, key in (("cov_tair_c", "cov_true_air_each"), ("cov_gp_c", "cov_gp_each")):
        each = row.get(key)
        for i, c in enumerate(COEFFICIENTS):
            out[(name, c)] = (None if not isinstance(each, list) or len(each) != len(COEFFICIENTS)
                              else BAND[0] <= _num(each[i]) <= BAND[1])
    return out


def flight_key(row: dict) -> tuple:
    """A flight's identity: (aircraft, turbulence, seed, AOA_SSA variant)."""
    return (row["aircraft"], row["turbulence"], int(row["seed"]), row.get("aoa", "ahrs"))


def load_runs(specs: list[str]) -> dict[int, dict[tuple, dict]]:
    """JSON lines by GP seed and flight.

    Args:
        specs: files of ``eval_jsbsim.py --json`` lines; ``PATH@N`` states GP seed ``N`` for every row of the file
            (otherwise each row's ``gp_seed``, 0 when absent).

    Returns:
        ``{gp_seed: {flight_key: row}}``.

    Raises:
        SystemExit: a file is missing, a line does not parse, or one flight appears twice at one GP seed.
    """
    runs: dict[int, dict[tuple, dict]] = defaultdict(dict)
    for spec in specs:
        path, forced = spec, None
        if "@" in spec and not Path(spec).exists():
            path, _, n = spec.rpartition("@")
            try:
                forced = int(n)
            except ValueError:
                raise SystemExit(f"{spec}: expected FILE or FILE@GP_SEED") from None
        try:
            lines = read_lines(path)
        except (OSError, UnicodeDecodeError) as exc:
            raise SystemExit(f"{path}: {exc}") from None
        for i, line in enumerate(lines, 1):
            if not line.strip():
                continue
            try:
                row = json.loads(line)
            except json.JSONDecodeError as exc:
                raise SystemExit(f"{path}:{i}: not a JSON line ({exc})") from None
            gs = forced if forced is not None else int(row.get("gp_seed") or 0)
            k = flight_key(row)
            if k in runs[gs]:
                raise SystemExit(f"{path}:{i}: flight {k} appears twice at GP seed {gs} (one run per file set)")
            runs[gs][k] = row
    return dict(runs)


def tally(rows: dict[tuple, dict]) -> dict[str, dict[str, list[int]]]:
    """Per aircraft and count: ``[satisfied, scored]``; the key ``"total"`` sums them."""
    out: dict[str, dict[str, list[int]]] = defaultdict(lambda: {n: [0, 0] for n in COUNTS})
    for k, row in rows.items():
        for (name, _), v in item_values(row).items():
            if v is None:
                continue
            for ac in (k[0], "total"):
                out[ac][name][0] += int(v)
                out[ac][name][1] += 1
    return dict(out)


def flips(base: dict[tuple, dict], cand: dict[tuple, dict]) -> tuple[list[dict], list[tuple]]:
    """The items that change between two runs at one GP seed.

    Returns:
        ``(changes, unmatched)``: one dict per changed item (``aircraft``, ``flight``, ``count``, ``coef``,
        ``win``: True for a win) and the flights present in only one of the runs.
    """
    changes = []
    for k in sorted(set(base) & set(cand)):
        vb, vc = item_values(base[k]), item_values(cand[k])
        for item, b in vb.items():
            c = vc.get(item)
            if b is None or c is None or b == c:
                continue
            better = (not c) if item[0] in FEWER_IS_BETTER else c
            changes.append({"aircraft": k[0], "flight": k, "count": item[0], "coef": item[1], "win": bool(better)})
    return changes, sorted(set(base) ^ set(cand))


def set_aside_ls_gains(changes: list[dict], base: dict[tuple, dict], cand: dict[tuple, dict],
                       points: float) -> tuple[list[dict], list[dict]]:
    """The ``gp<ls`` losses where the GP's own held-out error did not grow: least squares got better.

    ``gp<ls`` compares two estimates of the same coefficient with the same truth, so it is lost either where the GP
    gets worse or where least squares gets better. The thirty-ninth session's rule for the wind switch
    (``docs/benchmarks.md``, "A rule for the wind switch") counts such a flip as a loss only where the GP's error
    (``gp``, % of the truth's RMS) grew by more than ``points``; the others are set aside and reported.

    Args:
        changes: flips at one GP seed (:func:`flips`). base, cand: the two runs' rows at that seed by flight.
        points: the growth of the GP's held-out error, percentage points, above which a lost ``gp<ls`` counts.

    Returns:
        ``(kept, set_aside)``: the flips still judged, and the lost ``gp<ls`` flips set aside (each with ``gp_base``,
        ``gp_cand``, ``ls_base``, ``ls_cand``: the % errors).
    """
    kept, aside = [], []
    for ch in changes:
        if ch["count"] == "gp<ls" and not ch["win"]:
            b, c = base[ch["flight"]], cand[ch["flight"]]
            e = {f"{k}_{w}": _num(r.get(k, {}).get(ch["coef"])) for k in ("gp", "ls") for w, r in
                 (("base", b), ("cand", c))}
            if e["gp_cand"] - e["gp_base"] <= points:        # NaN compares False: a lost GP error stays a loss
                aside.append(dict(ch, **e))
                continue
        kept.append(ch)
    return kept, aside


def losers(changes: list[dict]) -> tuple[list[str], list[str]]:
    """Aircraft whose count (over their flights) goes down in some count, and aircraft with a lost flip only.

    Returns:
        ``(net, flip_only)``: sorted aircraft names.
    """
    net: dict[tuple[str, str], int] = defaultdict(int)
    lost = set()
    for ch in changes:
        net[(ch["aircraft"], ch["count"])] += 1 if ch["win"] else -1
        if not ch["win"]:
            lost.add(ch["aircraft"])
    down = sorted({ac for (ac, _), n in net.items() if n < 0})
    return down, sorted(lost - set(down))


def format_counts(rows: dict[tuple, dict], title: str) -> str:
    """A markdown table of one run's counts per aircraft and in total (``satisfied`` per count; the total line
    ``satisfied/scored``)."""
    t = tally(rows)
    names = list(COUNTS)
    head = "| aircraft | flights | " + " | ".join(names) + " |"
    out = [f"### {title}", "", head, "|" + "---|" * (len(names) + 2)]
    n_fl = defaultdict(int)
    for k in rows:
        n_fl[k[0]] += 1
    for ac in sorted(a for a in t if a != "total"):
        out.append(f"| {ac} | {n_fl[ac]} | " + " | ".join(str(t[ac][n][0]) for n in names) + " |")
    if "total" in t:
        out.append(f"| **total** | {len(rows)} | " + " | ".join(f"{t['total'][n][0]}/{t['total'][n][1]}"
                                                              for n in names) + " |")
    out += ["", "; ".join(f"{n}: {COUNTS[n][1]}" for n in names)]
    return "\n".join(out)


def coverage_by_coefficient(rows: dict[tuple, dict], key: str = "cov_true_air_each"
                            ) -> dict[str, tuple[float, int, int, int, int]] | None:
    """A band per coefficient over one run's flights (information; module docstring): by default the band at exact
    conditions, ``key="cov_gp_each"`` the held-out band.

    Args:
        rows: ``{flight: row}``, rows with ``key`` (six %, :data:`COEFFICIENTS`' order).
        key: the row's field.

    Returns:
        ``{coefficient: (pooled %, within, below, above, flights)}`` over the flights with a finite value; None when
        no row has the field.
    """
    vals = [r[key] for r in rows.values() if isinstance(r.get(key), list)]
    if not vals:
        return None
    out = {}
    for i, c in enumerate(COEFFICIENTS):
        v = [x for x in (_num(r[i]) for r in vals) if math.isfinite(x)]
        out[c] = (sum(v) / len(v) if v else math.nan, sum(BAND[0] <= x <= BAND[1] for x in v),
                  sum(x < BAND[0] for x in v), sum(x > BAND[1] for x in v), len(v))
    return out


def format_coverage(cov: dict[str, tuple[float, int, int, int, int]], title: str) -> str:
    """:func:`coverage_by_coefficient` as a markdown table."""
    out = [f"#### {title}", "", "| | " + " | ".join(COEFFICIENTS) + " |", "|" + "---|" * (len(COEFFICIENTS) + 1)]
    out.append("| pooled % | " + " | ".join(f"{cov[c][0]:.1f}" for c in COEFFICIENTS) + " |")
    for j, name in ((1, "flights in 90-98 %"), (2, "below"), (3, "above")):
        out.append(f"| {name} | " + " | ".join(f"{cov[c][j]}/{cov[c][4]}" for c in COEFFICIENTS) + " |")
    return "\n".join(out)


def format_flips(changes: list[dict], unmatched: list[tuple], gp_seed: int) -> str:
    """Per aircraft and count the flips won / lost at one GP seed, the totals and the losing aircraft."""
    per: dict[str, dict[str, list[int]]] = defaultdict(lambda: {n: [0, 0] for n in COUNTS})
    for ch in changes:
        per[ch["aircraft"]][ch["count"]][0 if ch["win"] else 1] += 1
    names = list(COUNTS)
    out = [f"### flips at GP seed {gp_seed} (won/lost)", "",
           "| aircraft | " + " | ".join(names) + " | won | lost |", "|" + "---|" * (len(names) + 3)]
    for ac in sorted(per):
        w = sum(v[0] for v in per[ac].values())
        lo = sum(v[1] for v in per[ac].values())
        out.append(f"| {ac} | " + " | ".join(f"{per[ac][n][0]}/{per[ac][n][1]}" if any(per[ac][n]) else "-"
                                             for n in names) + f" | {w} | {lo} |")
    w = sum(ch["win"] for ch in changes)
    lo = len(changes) - w
    down, flip_only = losers(changes)
    out += ["", f"GP seed {gp_seed}: won {w}, lost {lo}; aircraft losing a count: {', '.join(down) or 'none'}"
            + (f"; a lost flip without a lower count: {', '.join(flip_only)}" if flip_only else "")]
    for ch in changes:
        if not ch["win"]:
            ac, turb, seed, aoa = ch["flight"]
            out.append(f"  lost: {ac} {turb} s{seed} {aoa} {ch['count']} {ch['coef']}".rstrip())
    if unmatched:
        out.append(f"  not paired (in one run only): {len(unmatched)} flights, e.g. {unmatched[0]}")
    return "\n".join(out)


def verdict(per_seed: dict[int, list[dict]]) -> tuple[bool, list[str], str]:
    """Rule 8(b) over the flips of two or more GP seeds.

    Args:
        per_seed: ``{gp_seed: changes}`` (:func:`flips`).

    Returns:
        ``(holds, aircraft losing a count at every seed, one line of text)``; ``holds`` needs at every seed
        ``wins >= 2 x losses`` and at least one win.

    Raises:
        ValueError: fewer than two GP seeds.
    """
    if len(per_seed) < 2:
        raise ValueError("rule 8(b) needs the flips at two GP seeds")
    parts, ok, both = [], True, None
    for gs, changes in sorted(per_seed.items()):
        w = sum(ch["win"] for ch in changes)
        lo = len(changes) - w
        ok &= w > 0 and w >= 2 * lo
        parts.append(f"seed {gs} +{w}/-{lo}")
        down = set(losers(changes)[0])
        both = down if both is None else both & down
    names = sorted(both or ())
    text = (f"rule 8(b) {'HOLDS' if ok else 'FAILS'} ({', '.join(parts)}; wins >= 2 x losses and a win at every "
            f"seed); aircraft losing a count at every seed: {', '.join(names) or 'none'}")
    return ok, names, text


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="+", metavar="JSONL[@GP_SEED]",
                    help="eval_jsbsim.py --json files of one run (the candidate when --against is given)")
    ap.add_argument("--against", nargs="+", default=None, metavar="JSONL[@GP_SEED]",
                    help="the base run's files: print the flips of the candidate against it per GP seed, and rule "
                         "8(b)'s verdict where two or more GP seeds are paired")
    ap.add_argument("--counts", nargs="+", default=list(DEFAULT_COUNTS), choices=list(COUNTS), metavar="COUNT",
                    help="judge the flips and the verdict on these counts only (default: "
                         + ", ".join(DEFAULT_COUNTS) + "; also: "
                         + ", ".join(c for c in COUNTS if c not in DEFAULT_COUNTS) + ")")
    ap.add_argument("--ls-loss-needs-gp-worse", type=float, default=None, metavar="POINTS",
                    help="count a lost gp<ls flip only where the GP's held-out error grew by more than POINTS "
                         "percentage points; the others (least squares got better) are listed and set aside")
    a = ap.parse_args(argv)
    cand = load_runs(a.files)
    print(f"runs: {' '.join(a.files)}" + (f" against {' '.join(a.against)}" if a.against else ""), end="\n\n")
    for gs, rows in sorted(cand.items()):
        print(format_counts(rows, f"counts, GP seed {gs}"), end="\n\n")
        for key, what in (("cov_gp_each", "held-out band"), ("cov_true_air_each", "band at exact conditions")):
            cov = coverage_by_coefficient(rows, key)
            if cov is not None:
                print(format_coverage(cov, f"{what} per coefficient, GP seed {gs} (information)"), end="\n\n")
    if a.against is None:
        return 0
    base = load_runs(a.against)
    per_seed = {}
    for gs in sorted(set(base) & set(cand)):
        changes, unmatched = flips(base[gs], cand[gs])
        changes = [ch for ch in changes if ch["count"] in a.counts]
        aside = []
        if a.ls_loss_needs_gp_worse is not None:
            changes, aside = set_aside_ls_gains(changes, base[gs], cand[gs], a.ls_loss_needs_gp_worse)
        per_seed[gs] = changes
        print(format_flips(changes, unmatched, gs), end="\n\n")
        if aside:
            print(f"GP seed {gs}: {len(aside)} lost gp<ls flips set aside (the GP's error grew by at most "
                  f"{a.ls_loss_needs_gp_worse:g} points; least squares got better):")
            for ch in aside:
                ac, turb, seed, aoa = ch["flight"]
                print(f"  {ac} {turb} s{seed} {aoa} {ch['coef']}: gp {ch['gp_base']:.2f} -> {ch['gp_cand']:.2f} %, "
                      f"ls {ch['ls_base']:.2f} -> {ch['ls_cand']:.2f} %")
            print()
    missing = sorted(set(base) ^ set(cand))
    if missing:
        print(f"GP seeds in one run only (not compared): {missing}")
    if set(a.counts) != set(DEFAULT_COUNTS):
        print(f"flips and verdict on the counts {', '.join(a.counts)} only")
    if len(per_seed) >= 2:
        print(verdict(per_seed)[2])
    elif per_seed:
        print("rule 8(b) needs pairs at two GP seeds: no verdict")
    return 0


if __name__ == "__main__":
    sys.exit(main())
