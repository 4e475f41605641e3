"""Ranking: candidates for the flagged regions, scored by the model's own expected variance reduction.

1. Quality gate: a coefficient the model fails to predict on the held-out segment (error above
   ``gate_pct``) or cannot identify is not ranked at all; the list's context says why and what to
   fix first (data, rates, airframe file).
2. Weights: weakest coefficients (lowest confidence score) first, moment coefficients (Cl Cm Cn)
   ahead of forces (``force_weight``), or only the coefficients the user targets.
3. Regions are taken in turn from each weighted coefficient (its most uncertain first), so every
   axis has candidates. Candidates per location (regions of one slice that overlap): a doublet and a 3-2-1-1 on each
   surface that drives a weak coefficient there (elevator for CX CZ Cm, aileron for Cl, rudder for
   CY Cn) and one orthogonal multisine on all surfaces at once (Morelli 2003).
4. Score: the regressor trajectory each candidate would produce (linear model of the identified
   derivatives, :mod:`.design`) is given to the model, which returns the predictive variance at the
   region's points after observing it (``global_variance_after_many`` for the package's GP: all
   candidates in one batched closed-form update; ``variance_after`` for any other model). Priority
   = weighted mean relative reduction (active learning by variance reduction: MacKay,
   "Information-based objective functions for active data selection", Neural Computation 4(4), 1992).
   Each targeted coefficient's best candidate is kept first (moments first), the rest by priority.
5. Flagged regions are grouped by what would fix them (surface x flight condition) so the report
   shows a few fixes instead of one row per coefficient and region.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..aero.table import COEFFICIENTS, MOMENT_COEFFICIENTS, CoefficientTable
from ..airframe import CONTROLS, Airframe
from ..envelope import EnvelopeMap, FlaggedRegion, model_variance
from ..errors import InputError
from .design import RATE_OF, Context, ManeuverConfig, design, flight_condition
from .limits import effective_limits
from .linear import derivative_estimates, linear_models, modes
from .suggestion import SURFACE_NAMES, Suggestion, SuggestionList

__all__ = ["suggest_maneuvers", "quality_gate", "SURFACE_OF"]

#: Surface that drives each coefficient.
SURFACE_OF = {"CX": "delta_e", "CZ": "delta_e", "Cm": "delta_e", "Cl": "delta_a", "CY": "delta_r", "Cn": "delta_r"}
_MODE_OF = {"delta_e": "short period", "delta_a": "roll subsidence", "delta_r": "Dutch roll"}


def quality_gate(heldout_error_pct: dict[str, float] | None, identifiable: dict[str, tuple[bool, str]] | None = None,
                 gate_pct: float = 50.0) -> dict[str, dict[str, str]]:
    """Coefficients whose model fails its held-out check, with why and what to fix first.

    Args:
        heldout_error_pct: coefficient -> held-out error, % (``100 RMS(model - measured) / RMS(measured)``).
        identifiable: coefficient -> (ok, reason) from the pipeline.
        gate_pct: errors above this fail.

    Returns:
        coefficient -> ``{"why": ..., "fix": ...}`` for each failing coefficient.
    """
    out: dict[str, dict[str, str]] = {}
    for c, (ok, why) in (identifiable or {}).items():
        if not ok:
            out[c] = {"why": f"not identified: {why}",
                      "fix": "data first: log the IMU, attitude and servo outputs at 25 Hz or more (SRn_RAW_SENS, "
                             "SRn_EXTRA1, SRn_RC_CHAN), then re-fly a standard doublet set"}
    for c, e in (heldout_error_pct or {}).items():
        if c in out or e is None or not np.isfinite(e) or e <= gate_pct:
            continue
        if e > 200.0:
            fix = ("check the airframe file first (mass, inertia, servo senses and mixing, a [thrust] model), then "
                   "the data (a truncated log or a held-out segment flown outside the trained envelope); "
                   "re-identify before flying targeted maneuvers")
        else:
            fix = ("more excitation first: fly the standard doublet set on every axis across the speed range, "
                   "and check that the held-out segment lies inside the trained envelope")
        out[c] = {"why": f"held-out error {e:.0f} % (gate {gate_pct:.0f} %): the model does not generalise, so its "
                         f"variance is no guide", "fix": fix}
    return out


def _surface_for(coef: str, throw: dict[str, float]) -> str | None:
    c = SURFACE_OF[coef]
    if throw.get(c, 0.0) > 0:
        return c
    alt = {"delta_r": "delta_a", "delta_a": "delta_r"}.get(c)   # no rudder: aileron yaws too (adverse yaw)
    return alt if alt and throw.get(alt, 0.0) > 0 else None


def _fmt(k: str, v: float, V: float, airframe: Airframe) -> str:
    if k in ("alpha", "beta", "delta_e", "delta_a", "delta_r"):
        return f"{math.degrees(v) + 0.0:.1f} deg".replace("-0.0 ", "0.0 ")
    if k in RATE_OF.values():   # normalised rate -> deg/s at the condition's airspeed
        L = airframe.c if k == "q_hat" else airframe.b
        return f"{math.degrees(v * 2 * V / L) + 0.0:.0f} deg/s".replace("-0 ", "0 ")
    return f"{v:.1f} m/s" if k == "V" else f"{v + 0.0:.3f}"


_LABEL = {"p_hat": "p", "q_hat": "q", "r_hat": "r"}


def describe_region(bounds: dict[str, tuple[float, float]], V: float, airframe: Airframe) -> str:
    """Region bounds in words: angles in deg, rates in deg/s (at airspeed V), V in m/s."""
    return ", ".join(f"{_LABEL.get(k, k)} {_fmt(k, lo, V, airframe)}..{_fmt(k, hi, V, airframe)}"
                     for k, (lo, hi) in bounds.items())


def _locations(regions: list[FlaggedRegion]) -> list[list[FlaggedRegion]]:
    """Regions of one slice whose centres lie in each other's boxes form a location."""
    groups: list[list[FlaggedRegion]] = []
    inside = lambda c, b: all(b[k][0] <= c[k] <= b[k][1] for k in b)  # noqa: E731
    for r in regions:
        for g in groups:
            if g[0].axes == r.axes and (inside(r.center, g[0].bounds) or inside(g[0].center, r.bounds)):
                g.append(r)
                break
        else:
            groups.append([r])
    return groups


def _pad(X: np.ndarray, bucket: int) -> np.ndarray:
    n = len(X)
    m = int(np.ceil(n / bucket) * bucket) if bucket > 0 else n
    return np.vstack([X, np.repeat(X[-1:], m - n, axis=0)]) if m > n else X


def suggest_maneuvers(envelope: EnvelopeMap, model: Any, table: CoefficientTable, airframe: Airframe,
                      max_suggestions: int = 10, config: ManeuverConfig | None = None,
                      heldout_error_pct: dict[str, float] | None = None,
                      identifiable: dict[str, tuple[bool, str]] | None = None) -> SuggestionList:
    """Design and rank safe maneuvers that excite the flagged regions of the confidence map.

    Args:
        envelope: the confidence map (its ``outputs`` name the model's output columns).
        model: ``predict(X) -> (mean, var)`` and ``variance_after(X_extra, X_query) -> var (Q, P)``.
        table: the coefficient table (valid rows give the derivatives, air density, default limits).
        airframe: mass, inertia, geometry, surface travel and ``[limits]``.
        max_suggestions: at most this many, best first.
        config: design settings (:class:`ManeuverConfig`).
        heldout_error_pct: coefficient -> held-out error % (quality gate); None: no gate.
        identifiable: coefficient -> (ok, reason); unidentified coefficients are gated too.

    Returns:
        :class:`SuggestionList` ranked by priority (``rank`` 1 first), with its ``context`` (limits,
        gated coefficients, out-of-reach regions, groups of regions by fix, modes).

    Raises:
        InputError: ``max_suggestions`` < 1, an unknown target coefficient, or limits that contradict
            each other.

    Source: module docstring (Morelli 2003; Morelli and Klein 2016 ch. 9; Jategaonkar 2006 sec. 2.5;
    MacKay 1992).
    """
    if max_suggestions < 1:
        raise InputError(f"max_suggestions must be >= 1, got {max_suggestions}")
    cfg = config or ManeuverConfig()
    if cfg.targets is not None:
        bad = [c for c in cfg.targets if c not in COEFFICIENTS]
        if bad or not cfg.targets:
            raise InputError(f"target coefficients must be among {', '.join(COEFFICIENTS)}, got {list(cfg.targets)}")
    outs = list(envelope.outputs)
    rows = table.valid & np.all(np.isfinite(table.X), axis=1)
    limits = effective_limits(airframe, table, rows)
    gated = quality_gate(heldout_error_pct, identifiable, cfg.gate_pct)
    targets = tuple(c for c in (cfg.targets or COEFFICIENTS) if c in outs)
    weak = {c: 1.0 - (envelope.scores.get(c) if np.isfinite(envelope.scores.get(c, np.nan)) else 0.0) for c in outs}
    wmax = max(weak.values()) if weak and max(weak.values()) > 0 else 1.0
    weight = {c: (max(weak[c], 1e-3) / wmax) * (1.0 if c in MOMENT_COEFFICIENTS or cfg.targets else cfg.force_weight)
              if c in targets and c not in gated else 0.0 for c in outs}
    context: dict[str, Any] = {"limits": limits.to_dict(), "gated": gated, "out_of_reach": [], "groups": [],
                               "modes": {}, "weights": weight, "targets": list(targets)}
    regions = [r for r in envelope.regions if r.coefficient in outs and len(r.points) and weight[r.coefficient] > 0]
    d, at_ref, assumed = derivative_estimates(table, rows)
    qv = 2 * table.qbar[rows] / np.maximum(table.x("V")[rows], 1.0) ** 2
    qv = qv[np.isfinite(qv) & (qv > 0.3) & (qv < 1.6)]
    rho = float(np.median(qv)) if qv.size else 1.225
    dts = np.diff(table.t)
    ctx = Context(model, envelope, airframe, cfg, d, at_ref, assumed, dict(envelope.reference), rho, limits,
                  weight, float(np.median(dts)) if dts.size else 0.02)
    ref_fc, _ = flight_condition(ctx, envelope.reference, ())
    context["modes"] = {"V_mps": ref_fc["V"], **modes(linear_models(d, airframe, ref_fc["V"], rho, ref_fc["alpha"]))}
    if not regions:
        return SuggestionList([], context)
    context["groups"], context["out_of_reach"] = _fix_groups(ctx, regions)
    order = sorted({r.coefficient for r in regions},
                   key=lambda c: (c not in MOMENT_COEFFICIENTS and not cfg.targets, -weight[c], c))
    regions = _interleave(regions, order)
    designs, queries = [], []
    for gi, grp in enumerate(_locations(regions[:cfg.max_regions])):
        coefs = sorted({r.coefficient for r in grp}, key=lambda c: (c not in MOMENT_COEFFICIENTS and not cfg.targets,
                                                                      -weight[c], c))
        pts = {c: np.vstack([r.points for r in grp if r.coefficient == c]) for c in coefs}
        sl, k0 = {}, 0
        for c in coefs:
            sl[c] = slice(k0, k0 + len(pts[c]))
            k0 += len(pts[c])
        queries.append((_pad(np.vstack([pts[c] for c in coefs]), cfg.query_bucket), sl))
        by_surface: dict[str, list[str]] = {}
        for c in coefs:
            s = _surface_for(c, limits.throw)
            if s is not None:
                by_surface.setdefault(s, []).append(c)
        plans = [(k, (s,), tuple(cs)) for s, cs in by_surface.items() for k in ("doublet", "3211")]
        every = tuple(c for c in CONTROLS if limits.throw.get(c, 0.0) > 0)
        if by_surface and len(every) > 1:   # orthogonal multisine on all surfaces at once
            plans.append(("multisine", every, tuple(coefs)))
        for kind, controls, tgts in plans:
            lead = next(r for r in grp if r.coefficient == tgts[0])
            out = design(ctx, kind, controls, lead)
            if out is not None:
                designs.append((gi, kind, controls, tgts, lead, out[0], out[1]))
    candidates = []
    for (gi, kind, controls, tgts, lead, dsg, _), (var0, var1) in zip(designs, _variances(model, designs, queries)):
        sl = queries[gi][1]
        red = {}
        for c in tgts:
            j = outs.index(c)
            v0 = float(np.mean(var0[sl[c], j]))
            red[c] = float(np.clip(1.0 - np.mean(var1[sl[c], j]) / v0, 0.0, 1.0)) if v0 > 0 else 0.0
        prio = sum(weight[c] * red[c] for c in tgts) / np.sqrt(len(tgts))
        candidates.append((prio, gi, kind, controls, tgts, lead, dsg, red))
    best = max((float(np.mean(list(c[7].values()))) for c in candidates), default=0.0)
    floor = max(cfg.min_reduction, cfg.min_relative_reduction * best)
    candidates = [c for c in candidates if np.mean([c[7][t] for t in c[4]]) >= floor]
    candidates.sort(key=lambda x: -x[0])
    picked, seen = [], set()

    def take(cand) -> bool:
        prio, gi, kind, controls, tgts, lead, dsg, red = cand
        fc = dsg["fc"]
        same = (kind, controls, round(fc["V"]), tuple(round(math.degrees(a)) for a in dsg["amps"].values()))
        if (gi, controls) in seen or same in seen:   # one per location and surface set; no repeats
            return False
        seen.update({(gi, controls), same})
        picked.append(cand)
        return True

    for c in order:   # every targeted axis gets its best candidate first (moments first), then by priority
        if len(picked) < max_suggestions:
            next((True for cand in candidates if cand[4][0] == c and cand[7][c] >= floor and take(cand)), None)
    for cand in candidates:
        if len(picked) >= max_suggestions:
            break
        take(cand)
    picked.sort(key=lambda x: -x[0])
    chosen = SuggestionList([_suggestion(i + 1, ctx, *cand) for i, cand in enumerate(picked)], context)
    for g in context["groups"]:
        g["suggestions"] = [s.rank for s in chosen if s.fix == g["fix"]]
    return chosen


def _pct(x: float) -> str:
    """A fraction as a percentage with two significant digits (0.0022 -> '0.22 %')."""
    return f"{100 * x:.2g} %" if x < 0.1 else f"{100 * x:.0f} %"


def _fix_of(ctx: Context, r: FlaggedRegion) -> tuple[str, dict, str]:
    fc, oor = flight_condition(ctx, r.center, r.axes)
    s = _surface_for(r.coefficient, ctx.limits.throw)
    surf = SURFACE_NAMES[s] if s else "no surface"
    return f"{surf} inputs at {fc['V']:.0f} m/s", fc, oor


def _fix_groups(ctx: Context, regions: list[FlaggedRegion]) -> tuple[list[dict], list[str]]:
    """Flagged regions grouped by their fix (surface x condition, V to 1 m/s), worst first."""
    groups: dict[str, dict] = {}
    oor = []
    for r in regions:
        fix, fc, why = _fix_of(ctx, r)
        g = groups.setdefault(fix, {"fix": fix, "coefficients": [], "regions": 0, "slices": [],
                                    "worst_rel_sigma": 0.0, "V_mps": fc["V"], "alpha_deg": fc["alpha_deg"],
                                    "where": []})
        if r.coefficient not in g["coefficients"]:
            g["coefficients"].append(r.coefficient)
        g["regions"] += 1
        sl = f"{_LABEL.get(r.axes[0], r.axes[0])} x {_LABEL.get(r.axes[1], r.axes[1])}"
        if sl not in g["slices"]:
            g["slices"].append(sl)
        if len(g["where"]) < 3:
            g["where"].append(describe_region(r.bounds, fc["V"], ctx.airframe))
        g["worst_rel_sigma"] = max(g["worst_rel_sigma"], float(r.mean_rel_sigma))
        if why:
            line = f"{r.coefficient} at {describe_region(r.bounds, fc['V'], ctx.airframe)}: {why}"
            if line not in oor:
                oor.append(line)
    out = sorted(groups.values(), key=lambda g: -g["worst_rel_sigma"] * max(ctx.weight[c] for c in g["coefficients"]))
    for g in out:
        g["coefficients"].sort(key=lambda c: (c not in MOMENT_COEFFICIENTS, c))
    return out, oor


#: Regressors each surface moves (directly or through the mode it excites); a region on a slice of two
#: of them can be reached by that surface's inputs.
_REACH = {"delta_e": {"alpha", "q_hat", "delta_e", "V"},
          "delta_a": {"p_hat", "delta_a", "beta", "r_hat", "alpha", "V"},
          "delta_r": {"r_hat", "delta_r", "beta", "p_hat", "alpha", "V"}}


def _interleave(regions: list[FlaggedRegion], order: list[str]) -> list[FlaggedRegion]:
    """Regions taken in turn from each coefficient (in ``order``), so that every axis has candidates
    within ``max_regions``; per coefficient, regions its own surface can reach first (a roll input cannot
    reach a pitch-rate corner), most uncertain first."""
    per: dict[str, list[FlaggedRegion]] = {c: [] for c in order}
    reach = lambda r: set(r.axes) <= _REACH[SURFACE_OF[r.coefficient]]  # noqa: E731
    for r in sorted(regions, key=lambda r: (not reach(r), -r.mean_rel_sigma)):
        per[r.coefficient].append(r)
    out: list[FlaggedRegion] = []
    while any(per.values()):
        for c in order:
            if per[c]:
                out.append(per[c].pop(0))
    return out


def _variances(model: Any, designs: list, queries: list) -> list[tuple[np.ndarray, np.ndarray]]:
    """(variance before, variance after) at each candidate's query points, latent where possible.

    A model with ``global_variance_after_many`` (:class:`gcs_sysid.gp.LocalGlobalGP`) ranks all
    candidates in one batched call on its global layer; any other model is asked ``predict`` once
    per query set and ``variance_after`` once per candidate.
    """
    if not designs:
        return []
    batched = getattr(model, "global_variance_after_many", None)
    if batched is not None:
        return [tuple(np.asarray(v, float) for v in pair)
                for pair in batched([d[6] for d in designs], [queries[d[0]][0] for d in designs])]
    before: dict[int, np.ndarray] = {}
    out = []
    for d in designs:
        gi = d[0]
        if gi not in before:
            before[gi] = model_variance(model.predict, queries[gi][0])
        out.append((before[gi], model_variance(model.variance_after, d[6], queries[gi][0])))
    return out


def _suggestion(rank: int, ctx: Context, prio: float, gi: int, kind: str, controls: tuple[str, ...],
                targets: tuple[str, ...], region: FlaggedRegion, dsg: dict, red: dict) -> Suggestion:
    fc, amps, ex = dsg["fc"], dsg["amps"], dsg["expected"]
    mean_red = float(np.mean([red[c] for c in targets]))
    surf = " + ".join(SURFACE_NAMES[c] for c in controls)
    mode_txt = ", ".join(f"{_MODE_OF[c]} {dsg['mode_hz'][c]:.2f} Hz" for c in controls)
    relevant = {"delta_e": ("CZ", "Cm"), "delta_a": ("Cl",), "delta_r": ("CY", "Cn")}
    used = [a for a in ctx.assumed if a.split("_")[0] in {x for c in controls for x in relevant[c]}]
    amp_txt = ", ".join(f"{SURFACE_NAMES[c]} {math.degrees(a):.1f} deg" for c, a in amps.items())
    shape = (f"{kind} ({dsg['band'][0]:.2f}-{dsg['band'][1]:.2f} Hz, {dsg['input_s']:.0f} s, each surface its own "
             f"harmonics)" if kind == "multisine" else f"{kind} (pulse {dsg['pulse']:.2f} s)")
    known = region.mean_rel_sigma <= ctx.env.thresholds.get(region.coefficient, np.inf)
    where = describe_region(region.bounds, fc["V"], ctx.airframe)
    fix, _, _ = _fix_of(ctx, region)
    reason = (f"{', '.join(targets)} {'not flown' if known else 'poorly known'} at {where} (mean predictive sigma "
              f"{region.mean_rel_sigma:.2f} x the coefficient's spread, {region.n_points} samples there): "
              f"fly {'an' if surf[0] in 'aeiou' else 'a'} {surf} {shape}, amplitude {amp_txt}, at V {fc['V']:.1f} m/s "
              f"(1-g trim, alpha {fc['alpha_deg']:.1f} deg); excites the {mode_txt}; expected peaks "
              f"p {ex['p_max_dps']:.0f}, q {ex['q_max_dps']:.0f}, r {ex['r_max_dps']:.0f} deg/s, "
              f"alpha {ex['alpha_max_deg']:.1f} deg, {ex['n_min']:.2f}-{ex['n_max']:.2f} g; "
              f"expected variance reduction {_pct(mean_red)}")
    notes = list(dsg["notes"])
    if dsg["out_of_reach"]:
        notes.insert(0, dsg["out_of_reach"])
    if notes:
        reason += "; " + "; ".join(notes)
    if used:
        reason += f"; typical values assumed for {', '.join(used)}"
    reg = {"coefficient": region.coefficient, "axes": list(region.axes),
           "bounds": {k: [float(a), float(b)] for k, (a, b) in region.bounds.items()},
           "center": {k: float(region.center[k]) for k in region.axes}, "description": where,
           "mean_rel_sigma": float(region.mean_rel_sigma), "n_points": int(region.n_points)}
    main = controls[0]
    return Suggestion(rank, targets, kind, controls, amps[main], math.degrees(amps[main]), dict(amps),
                      float(dsg["pulse"]), float(dsg["duration"]), fc, mean_red, dict(red), float(prio), reason,
                      reg, dict(dsg["mode_hz"]), dsg["band"], dsg["t"], dsg["u"], used, dict(ex),
                      ctx.cfg.lead_s, float(dsg["input_s"]), fix, notes)
