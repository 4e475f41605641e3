"""``bias:airspeed`` / ``scale:airspeed`` as a physical cause, judged on its whole signature.

A pitot that reads ``b`` m/s high does not show in the data-compatibility check when the flight
has too few heading changes to separate it from the wind: the pipeline's wind estimate
(``|v_gps - w| = V_pitot``) takes it up along the heading, and V, qbar, alpha and beta inherit it.
Its signature is then:

- **every coefficient** scaled by ``(V_true / V_meas)^2 ~ (V / (V + b))^2``, with a V-dependent size,
  the normalised rates by ``V / (V + b)``, alpha and beta moved with the air-velocity vector
  (:func:`gcs_sysid.diagnose.causes.t_bias_airspeed`); checked coefficient by coefficient by
  :func:`gcs_sysid.diagnose.physical.physical_gate`, which also makes it beat the best single term
  of each implied coefficient on the untouched rows;
- **the wind estimate shifted along the heading** by ``-b``: where the log carries the autopilot's
  own wind estimate (WIND / XKF2), the pipeline's wind minus the autopilot's, projected on the
  horizontal air-velocity direction, must agree with ``-b`` (:func:`wind_shift`);
- **differential**: the same fit on the reference flight(s) must give a different value; a pitot
  bias the reference flight had too is a calibration note, not a change.

The physical gate removes each coefficient's between-flight offset before it judges a cause
(:data:`gcs_sysid.diagnose.physical.OFFSETS_ALLOWED`). A pitot bias at one trim speed is mostly such
an offset, so when the autopilot's wind estimate confirms the bias on its own (the wind shift at least
:data:`MIN_T_WIND` of its standard errors from 0 and in agreement with the fit), the offsets the bias
makes are its evidence and the gate keeps them; without that confirmation they are an allowance,
and the bias is named only for what it explains beyond them (its V-dependent size, rates, angles).
Accepted, its symptoms (aero terms and ``scale:<coef>`` of the implied coefficients) leave the findings.

Thresholds (frozen with those of :mod:`gcs_sysid.diagnose.physical`, 2026-11-22 00:15 UTC):
``MIN_T`` on the fit's coloured-residual t statistic, and the systematic error of the autopilot's
wind estimate ``WIND_SYSTEMATIC_MPS`` in the wind check.

References:
    Morelli and Klein, *Aircraft System Identification*, 2nd ed., ch. 10 (data compatibility) and
    sec. 5.3 (coloured residuals); Cho, Kim, Lee and Kim, "Wind estimation and airspeed calibration
    using a UAV with a single-antenna GPS receiver and pitot tube", IEEE TAES 47(1), 2011.
"""

from __future__ import annotations

import numpy as np

from .candidates import Scorer, fit_sensor_causes
from .causes import _air_velocity_body, _dcm_nb, transforms
from .context import DiagContext
from .physical import physical_gate, split_held_out, with_test
from .regression import effective_samples

__all__ = ["MIN_T", "WIND_SYSTEMATIC_MPS", "MIN_T_WIND", "airspeed_cause", "wind_shift", "with_pitot"]

#: |estimate - null| / coloured standard error a pitot cause needs (as the sparse search's terms).
MIN_T = 5.0
#: 1-sigma systematic error of an autopilot's wind estimate (m/s): its slow wander.
WIND_SYSTEMATIC_MPS = 0.3
#: |b_wind| / its standard error for the autopilot's wind estimate to *confirm* a pitot error on its own
#: (then the coefficient offsets the bias makes count as its evidence, not as a between-flight allowance;
#: :data:`gcs_sysid.diagnose.physical.OFFSETS_ALLOWED`).
MIN_T_WIND = 3.0
PITOT_CAUSES = ("bias:airspeed", "scale:airspeed")


def wind_shift(ctx: DiagContext, flight) -> dict | None:
    """The pipeline's wind minus the autopilot's, along the horizontal air-velocity direction.

    A pitot bias ``b`` taken up by the wind estimate moves it by ``-b`` along that direction; so
    ``b_wind = -mean((w_pipeline - w_autopilot) . h)``.

    Args:
        ctx: context with states ``wn we phi theta psi`` on the valid rows.
        flight: the decoded flight (its ``wind`` stream, the autopilot's estimate).

    Returns:
        ``{"bias_mps", "std_error"}`` (the standard error: coloured scatter and
        :data:`WIND_SYSTEMATIC_MPS` in quadrature), or None without an autopilot wind estimate.
    """
    if flight is None or not flight.has("wind") or not ctx.has("wn", "we", "phi", "theta", "psi"):
        return None
    s = flight["wind"]
    if not all(k in s.fields for k in ("wn", "we")):
        return None
    ts = np.asarray(s.t, float)
    ap = []
    for k in ("wn", "we"):
        x = np.asarray(s[k], float)
        ok = np.isfinite(x)
        if ok.sum() < 5:
            return None
        ap.append(np.interp(ctx.t, ts[ok], x[ok], left=np.nan, right=np.nan))
    C = _dcm_nb(ctx.states["phi"], ctx.states["theta"], ctx.states["psi"])
    v_ned = np.einsum("tji,tj->ti", C, _air_velocity_body(ctx))
    hn = np.maximum(np.hypot(v_ned[:, 0], v_ned[:, 1]), 1e-3)
    d = ((ctx.states["wn"] - ap[0]) * v_ned[:, 0] + (ctx.states["we"] - ap[1]) * v_ned[:, 1]) / hn
    m = ctx.valid & np.isfinite(d)
    if m.sum() < 50:
        return None
    x = -d[m]
    se = float(np.hypot(np.std(x) / np.sqrt(effective_samples(x)), WIND_SYSTEMATIC_MPS))
    return {"bias_mps": float(np.mean(x)), "std_error": se}


def _fit(ctx: DiagContext, R: np.ndarray, proj, cause: str):
    """The cause fitted on ``ctx.train`` and scored on ``ctx.test`` (a :class:`Fitted` or None)."""
    names = [c.cause for c in transforms(ctx)]
    got = fit_sensor_causes(ctx, R, Scorer(ctx, R, proj), exclude=[n for n in names if n != cause])
    return got[0] if got and np.isfinite(got[0].std_error) and got[0].std_error > 0 else None


def _null(cause: str) -> float:
    return 1.0 if cause.startswith("scale:") else 0.0


def airspeed_cause(ctx: DiagContext, R: np.ndarray, proj=None, flight=None, references=(), airframe=None,
                   model=None, min_score: float = 30.0, min_gain_pct: float = 10.0) -> dict:
    """Fit and judge ``bias:airspeed`` and ``scale:airspeed`` on the coefficients (see the module doc).

    Args:
        ctx: the context (``train`` the selection rows, ``test`` the held-out rows, split here into
            acceptance and untouched gain rows by :func:`~gcs_sysid.diagnose.physical.split_held_out`).
        R: (T, 6) residual against the model under test. proj: the gust projector or None.
        flight: the decoded flight (for the wind check) or None.
        references: :class:`~gcs_sysid.diagnose.differential.Reference` flights (same model).
        airframe, model: for the reference contexts.
        min_score, min_gain_pct: the usual acceptance on the acceptance rows.

    Returns:
        ``{"candidates": [...], "finding": dict | None, "calibration": [str]}``; each candidate
        ``{"cause", "estimate", "std_error", "t_statistic", "score", "gain_percent", "checks": {...},
        "accepted"}``; ``finding`` the accepted one as a diagnosis finding (evidence domain
        ``"physical signature"``), ``gain`` on the untouched rows.
    """
    acc, gain_rows = split_held_out(ctx.t, ctx.test)
    ctx_a = with_test(ctx, acc)
    wind = wind_shift(ctx, flight)
    out = {"candidates": [], "finding": None, "calibration": []}
    best = None
    for cause in PITOT_CAUSES:
        f = _fit(ctx_a, np.nan_to_num(R), proj, cause)
        if f is None:
            continue
        null = _null(cause)
        tstat = (f.estimate - null) / f.std_error
        checks = {"significant": bool(abs(tstat) >= MIN_T),
                  "accepted_on_acceptance_rows": bool(f.score >= min_score and f.gain_percent >= min_gain_pct)}
        cand = {"cause": cause, "estimate": float(f.estimate), "std_error": float(f.std_error),
                "t_statistic": float(tstat), "score": float(f.score), "gain_percent": float(f.gain_percent),
                "checks": checks}
        out["candidates"].append(cand)
        if not all(checks.values()):
            cand["accepted"] = False
            continue
        # the autopilot's own wind estimate independently confirms a pitot error along the heading: then the
        # coefficient offsets the bias makes are part of its evidence, not a between-flight allowance
        b_est = f.estimate if cause == "bias:airspeed" else (f.estimate - 1.0) * float(np.median(ctx.x("V")[ctx.valid]))
        confirmed = wind is not None and abs(wind["bias_mps"]) >= MIN_T_WIND * wind["std_error"] and \
            abs(wind["bias_mps"] - b_est) <= 3.0 * np.hypot(wind["std_error"], f.std_error) + 0.25 * abs(b_est)
        gate = physical_gate(ctx, np.nan_to_num(R), f.delta, 1, proj, acc, gain_rows,
                             offsets_allowed=False if confirmed else None)
        cand["confirmed_by_wind_estimate"] = bool(confirmed)
        checks["signature"] = gate["signature"]["holds"]
        checks["beats_terms"] = bool(gate["versus_terms"]["beats"])
        cand["gate"] = gate
        if wind is not None:
            b = f.estimate if cause == "bias:airspeed" else (f.estimate - 1.0) * float(np.median(ctx.x("V")[ctx.valid]))
            checks["wind_shift"] = bool(abs(wind["bias_mps"] - b) <= 3.0 * np.hypot(wind["std_error"], f.std_error)
                                        + 0.25 * abs(b))
            cand["wind_shift"] = wind
        refs = _reference_values(references, airframe, model, cause)
        cand["references"] = refs
        same = [r for r in refs if abs(f.estimate - r["estimate"]) < 3.0 * np.hypot(f.std_error, r["std_error"])]
        checks["changed_since_reference"] = not (refs and len(same) == len(refs))
        if refs and len(same) == len(refs):
            vals = ", ".join(f"{r['estimate']:.3g}" for r in refs)
            out["calibration"].append(f"{cause} = {f.estimate:.3g} +- {f.std_error:.2g}, the same in the reference "
                                      f"flight(s) ({vals}): a calibration to correct, not a change")
        cand["accepted"] = all(checks.values())
        cand["gain_untouched"] = gate["versus_terms"].get("gain_cause", {})
        if cand["accepted"] and (best is None or f.score > best[0].score):
            best = (f, cand, gate)
    if best is not None:
        f, cand, gate = best
        main = max(cand["gain_untouched"], key=cand["gain_untouched"].get) if cand["gain_untouched"] else f.coefficient
        gu = gate["versus_terms"]["gain_cause"].get(main, 0.0)
        out["finding"] = {
            "cause": f.cause, "coefficient": main, "estimate": float(f.estimate), "std_error": float(f.std_error),
            "gain": {"percent": float(gu), "rows": "untouched (held out from selection and acceptance)"},
            "evidence": {"domain": "physical signature", "score": float(f.score),
                         "t_statistic": cand["t_statistic"], "checks": cand["checks"],
                         "signature": gate["signature"], "versus_terms": gate["versus_terms"],
                         "wind_shift": cand.get("wind_shift"),
                         "differential": {"verdict": "changed" if cand["references"] else "no reference flight",
                                          "references": cand["references"]},
                         "gain_acceptance_by_coefficient": f.gains, "separable": True, "rivals": [],
                         "summary": f"{f.cause} {f.estimate:.3g} +- {f.std_error:.2g}: every implied coefficient "
                                    f"({', '.join(gate['signature']['implied'])}) sees it"}}
    return out


def _reference_values(references, airframe, model, cause: str) -> list[dict]:
    """The same cause fitted on each reference flight's residual against the same model."""
    out = []
    for ref in references or ():
        try:
            rctx = DiagContext.build(ref.table, airframe, model, ref.states, None, None)
            if rctx.train.sum() < 100 or rctx.test.sum() < 50:
                continue
            f = _fit(rctx, np.nan_to_num(rctx.Y - rctx.model_values()), None, cause)
        except (ValueError, ArithmeticError, np.linalg.LinAlgError):
            f = None
        if f is not None:
            out.append({"label": getattr(ref, "label", "reference"), "estimate": float(f.estimate),
                        "std_error": float(f.std_error)})
    return out


def with_pitot(findings: list[dict], pitot: dict, data: dict) -> list[dict]:
    """Findings with an accepted pitot cause first; the aero terms of its implied coefficients are its
    symptoms (``evidence.explains``) and leave the list. Writes ``data["pitot"]`` (the candidates and
    their checks) and appends its calibration notes to ``data["calibration"]``.

    Args:
        findings: the diagnosis' findings. pitot: from :func:`airspeed_cause`. data: ``Diagnosis.data``.

    Returns:
        the new findings list.
    """
    data["pitot"] = {"candidates": [{k: (v if k != "gate" else {"why": v["why"], "signature": v["signature"],
                                                                  "versus_terms": v["versus_terms"]})
                                     for k, v in c.items()} for c in pitot["candidates"]]}
    if pitot["calibration"]:
        data.setdefault("calibration", []).extend(pitot["calibration"])
    f = pitot["finding"]
    if f is None:
        return findings
    implied = set(f["evidence"]["signature"]["implied"])
    # its symptoms: aero terms of an implied coefficient, and a scale of one (the sparse search's
    # ``scale:CY``: every coefficient is scaled by (V / (V + b))^2)
    symptoms = [g for g in findings if (g["cause"].split(":")[0] in implied or
                                        (g["cause"].startswith("scale:") and g["cause"][6:] in implied))
                and g.get("kind") != "fault"
                and g.get("evidence", {}).get("domain") not in ("data compatibility", "physical signature")]
    f["evidence"]["explains"] = [g["cause"] for g in symptoms]
    return [g for g in findings if g.get("kind") == "fault"] + [f] + \
        [g for g in findings if g.get("kind") != "fault" and g not in symptoms]
