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

**First, the wind triangle and the coefficients together** (added 2026-11-22, branch i9-pitot;
``docs/diagnose.md``, "The pitot by the wind triangle and the coefficients together"): the pitot
against GPS minus the autopilot's wind (:mod:`gcs_sysid.diagnose.wind_triangle`) and the bias fitted
on the coefficients are independent measurements of one change since the reference flight; when they
agree and their fused change is at least :data:`MIN_T_FUSED` standard errors, the coefficients are
refitted with the bias's exact effect (the pipeline re-run with the pitot corrected, one estimate per
coefficient, their median) and the bias is named if the coefficients on their own see it
(:data:`MIN_T_COEF_CONFIRM`, since 2026-11-23; asked only where their standard error is at most
:data:`COEF_WITNESS_MAX_SE_MPS`, since 2026-11-26) and that correction gains on the untouched rows. Only
when that path does not name it does the signature path below decide. An accepted pitot finding comes
first (:data:`RANK_BY_GAIN`).

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

from .alpha_level import SHIFT_KEY
from .candidates import Scorer, fit_sensor_causes
from .causes import _air_velocity_body, _dcm_nb, transforms
from .context import DiagContext
from .physical import physical_gate, split_held_out, with_test
from .regression import effective_samples
from .wind_triangle import WIND_SYSTEMATIC_MPS, autopilot_wind  # noqa: F401  (WIND_SYSTEMATIC_MPS: re-exported)

__all__ = ["MIN_T", "WIND_SYSTEMATIC_MPS", "MIN_T_WIND", "COEF_SYSTEMATIC_MPS", "REFIT_SYSTEMATIC_MPS", "MIN_T_FUSED",
           "REFIT_SYSTEMATIC_REL", "SENSOR_GAIN", "MIN_T_SCREEN", "MIN_T_SCREEN_TRIANGLE", "MAX_SE_COEF_MPS",
           "MIN_T_COEF_CONFIRM", "COEF_WITNESS_MAX_SE_MPS", "MIN_T_TRIANGLE_CONFIRM", "SIGNATURE_TRIANGLE_AGREE",
           "SIGNATURE_SYSTEMATIC", "RANK_BY_GAIN",
           "signature_agrees_with_triangle", "airspeed_cause", "coefficients_confirm", "triangle_confirms",
           "wind_shift", "fuse_pitot_evidence", "screen", "with_pitot", "LIMITING_SHARE", "pitot_resolution"]

#: |estimate - null| / coloured standard error a pitot cause needs (as the sparse search's terms).
MIN_T = 5.0
#: |b_wind| / its standard error for the autopilot's wind estimate to *confirm* a pitot error on its own
#: (then the coefficient offsets the bias makes count as its evidence, not as a between-flight allowance;
#: :data:`gcs_sysid.diagnose.physical.OFFSETS_ALLOWED`).
MIN_T_WIND = 3.0
PITOT_CAUSES = ("bias:airspeed", "scale:airspeed")
#: 1-sigma between-flight systematic error (m/s) of a pitot bias fitted on the coefficients: what the
#: coloured standard error misses (the model's own flight-to-flight inadequacy). Set from the clean tuning
#: flights (c172x/sgs seeds 11-12: fitted biases -0.02 to +0.20 m/s with coloured errors 0.03-0.07).
COEF_SYSTEMATIC_MPS = 0.2
#: 1-sigma between-flight systematic error (m/s) of the *exact re-fit's* estimate of the bias (the median over the
#: coefficients of :func:`_fit_unit_delta`, the estimate that decides), in quadrature with its scatter-based standard
#: error. Until the forty-seventh session it was :data:`COEF_SYSTEMATIC_MPS`, set for the closed-form fit, a
#: different estimator (which keeps it for the screen and the signature path). Against the truth on the 267 re-fits
#: of the committed JSBSim records the standardised error's robust SD is 1.15 with 0.2 (1.41 on the
#: ``bias:airspeed`` cases), 1.0 with 0.45; 0.45 was measured on fresh flights by a rule written before the runs and
#: lost (clean +1 of 250, 1 m/s bias tops -3 of 50: ``docs/benchmarks.md``, "Forty-seventh session, lead"), so 0.2
#: stays.
REFIT_SYSTEMATIC_MPS = 0.2
#: The exact re-fit's systematic term relative to the flight's median airspeed (dimensionless; 0: off): its error is
#: taken as ``sqrt(REFIT_SYSTEMATIC_MPS^2 + (REFIT_SYSTEMATIC_REL * V)^2)``. Why relative: the coefficients see a
#: pitot bias only along the scaling of the model's own parameters (``(V / (V + b))^2``; fitted beside the model's
#: columns they see none), which a reference fit's parameter error mimics on every test flight, so the error is a
#: between-flight scale error ``s`` of the coefficients, ``b = s V / 2`` m/s: against JSBSim's truth the re-fit's
#: RMS error grows with the trim airspeed (0.3-0.9 m/s at 41 m/s, 3-6.5 m/s on the 130-m/s transports;
#: ``docs/benchmarks.md``, "Forty-seventh session, lead"). On (0.005) since the forty-seventh session, by a rule
#: written before its fresh runs (clean seeds 46-50: 122 -> 123 of 125, c684 s47; effect seed 7's 50
#: ``bias:airspeed`` cases: top 24 -> 24; ALFA 9 of 9, 5 of 5). The flat 0.45 m/s, measured first, lost 1 m/s biases
#: on the light GA.
REFIT_SYSTEMATIC_REL = 0.005
#: |fused change| / its standard error for the wind triangle and the coefficients together to name a
#: pitot bias (:func:`fuse_pitot_evidence`).
MIN_T_FUSED = 3.0
#: The cheap screen before the pipeline is re-run with the pitot corrected (:func:`_unit_delta_rereduced`):
#: the wind triangle and the closed-form coefficient fit agree and their fused |t| reaches this, or (added
#: 2026-11-22, branch i9-top90) the wind triangle's change since the reference flight alone reaches it.
MIN_T_SCREEN = 2.0
#: The screen's wind-triangle-alone route (added 2026-11-22 15:55 UTC, branch i9-pitot; before: MIN_T_SCREEN). The
#: screen only decides whether the exact re-fit is spent; naming stays with MIN_T_FUSED on both measurements. The
#: closed-form route is biased low by the aided angles (0.16, -0.08, 0.08 m/s for 1 m/s on pa28 s3, j3cub s1,
#: c182 s1), so a triangle of 1.6-1.9 standard errors stopped three 1 m/s biases before the measurement that
#: decides; on 76 recorded tuning flights without a pitot change the triangle's t lies in [-1.27, +0.30]
#: (``docs/benchmarks.md``, *Ninth session, i9-pitot*).
MIN_T_SCREEN_TRIANGLE = 1.5
#: Largest coloured standard error (m/s) of one coefficient's estimate of the bias for it to take part in
#: the coefficients' median (:func:`_fit_unit_delta`).
MAX_SE_COEF_MPS = 0.5
#: The exact re-fit's coefficient estimates are changes since the reference flight(s) re-fitted the same way
#: (:func:`_rereduced_baseline`), not minus the closed-form fit's reference value (added 2026-11-22, branch
#: i9-scale; freeze time in ``docs/benchmarks.md``).
DIFFERENTIAL_REREDUCED = True
#: The wind-triangle pitot finding's gain is the largest over the quantities the bias acts on: each coefficient (as
#: before) *and the pitot's own airspeed*, on the wind triangle's residual in m/s over the same untouched rows
#: (:func:`gcs_sysid.diagnose.wind_triangle.triangle_gain`), as every other data-compatibility sensor cause's gain is
#: in its own units (:mod:`gcs_sysid.diagnose.compat`). Read by the naming check ``gain_on_untouched_rows`` and by
#: the reported ``gain``. Why (eleventh session, branch i9-b747, ``docs/benchmarks.md``): on the JSBSim b747 at 134
#: m/s even the *exact* effect of the bias (the same flight logged with the pitot 1 m/s apart) gains at most 12-17 %
#: of a coefficient's held-out residual at 2 m/s and 5-7.5 % at 1 m/s, so a coefficient gain measures the flight's
#: turbulence floor, not the finding; on the wind triangle the same biases gain 81-86 % and 60-73 % (residual
#: 0.29-0.36 m/s). False: coefficients only (the tenth session's rule).
#: Switched off at the eleventh session's merge: the project's own simulated flights named a pitot bias that is not
#: there (``tests/diagnose/test_diagnose_e2e.py``: the clean flight and three single-effect flights, triangle gains
#: 37-45 %; ``test_physical.py``'s IMU turn-on biases). **On again since the twelfth session (branch i9-pitot)**, with
#: the cause found and two changes (``docs/diagnose.md``, "What offset the triangle on the project's own flights"):
#: what offset the residual there is the simulated autopilot's wind wandering (0.3 m/s, 20-s Gauss-Markov), traded by
#: the triangle's *fitted* constant wind correction against the bias over the two headings and the turn between them
#: (clean flight: bias +0.50 +- 0.13 m/s with a correction of (0.78, 0.54) m/s; the pitot against GPS minus the logged
#: wind has a level of -0.004 m/s; the density, EAS -> TAS and the pitot itself are exact to 0.004 m/s). So (1) the
#: gain is taken on the residual against the autopilot's wind *as logged* (a pitot bias is a constant offset of that
#: residual whatever the heading; an offset made by a fitted correction is not in it), and (2) before = the reference
#: flight(s)' level of that same residual. The triangle that sizes the finding still uses every valid row, the gain rows
#: (a sixth of the flight) included: fitted off them, it read 2.59 m/s for the 2 m/s bias of ``test_physical.py``
#: (the wander trades differently on fewer rows), outside the 25 % the test allows.
SENSOR_GAIN = True
#: The coefficients must *confirm* a wind-triangle finding, not merely not contradict it (added 2026-11-23, branch
#: i9-heave2; ``docs/diagnose.md``, "Both measurements must see it"): the coefficients' own change since the
#: reference (the exact re-fit's median, its standard error with :data:`REFIT_SYSTEMATIC_MPS` in quadrature) must lie
#: at least this many of its standard errors from 0 on the fused estimate's side. Agreement (3 combined standard
#: errors) and the fused t (:data:`MIN_T_FUSED`) alone let the triangle carry the finding by itself when the
#: coefficients read nothing; the triangle's standard error on one flight omits the autopilot wind's wander (the
#: project's simulated trainer, seed 13, no bias: triangle +0.50 +- 0.13 m/s, coefficients -0.14 +- 0.41, fused t 3.7,
#: then accepted on a coefficient gain made of constant CY/Cl/Cn offsets once the gust projector was off). Accepted real
#: biases in the archived JSBSim records (old turbulence levels, ten aircraft) read 1.5-10.5 of these standard errors
#: but one (b747 1 m/s, seed 7: 0.9, lost); at the new levels (rascal, t6, c172x; band off and on) 2.0-9.9.
MIN_T_COEF_CONFIRM = 1.0
#: The coefficients confirm a wind-triangle finding only where they can (added 2026-11-26, forty-first session; None:
#: they must always confirm, the rule before). Where the exact re-fit's coefficient estimate of the bias has a standard
#: error (with :data:`REFIT_SYSTEMATIC_MPS`) above this, m/s, the coefficients are no witness of a bias the size of the
#: ones that matter (1 m/s is 3-10 % of qbar at 20-60 m/s), so :data:`MIN_T_COEF_CONFIRM` is not asked of them; the
#: fused change must still reach :data:`MIN_T_FUSED`, the coefficients can still veto by disagreeing
#: (``measurements_agree``) and the gain check stays (:func:`_acceptance_checks`). The
#: project's simulated trainer, whose false pitot the confirm rule was made for, has a coefficient standard error of
#: 0.41 m/s and keeps the rule. See ``docs/diagnose.md``, "Both measurements must see it", and ``docs/benchmarks.md``,
#: "Forty-first session, lead".
COEF_WITNESS_MAX_SE_MPS: float | None = 1.0
#: The wind triangle must *confirm* a fused finding too (on since the forty-eighth session, by a rule written before
#: its fresh runs; None: not asked, the rule before): its own change since the reference flight(s) must lie at least
#: this many of its standard errors from 0 on the fused estimate's side, as :data:`MIN_T_COEF_CONFIRM` asks of the
#: coefficients. Without it the coefficients carry the finding alone when the triangle reads nothing, and their exact
#: re-fit's stated error is the weaker of the two (against JSBSim's truth the robust SD of its standardised error is
#: 1.15 after the median over the coefficients and about 5 per coefficient: ``docs/benchmarks.md``, "Forty-seventh
#: session, lead" and "Forty-eighth session, lead"). Two of the three false fused findings of the forty-seventh
#: session's fresh clean flights read the triangle at 0.35 and 0.48 of its standard errors (c684 s38, navion s50); of
#: the 101 real biases accepted in the records and on seeds 6 and 7, all read it at 1 or more but one (c172p 1 m/s,
#: seed 6: 0.78). On fresh flights (effect seed 8's 50 biases, clean seeds 51-55) it changed no decision: no clean
#: flight was named there, and the 22 accepted biases read the triangle at 2.2 or more. See ``docs/benchmarks.md``,
#: "Forty-eighth session, lead".
MIN_T_TRIANGLE_CONFIRM: float | None = 1.0
#: The signature path (a pitot cause named on the coefficients' signature when the wind-triangle path names nothing)
#: must agree with the wind triangle's change since the reference flight(s), by the three combined standard errors of
#: :func:`fuse_pitot_evidence` (:func:`signature_agrees_with_triangle`; on since the forty-fifth session, by a rule
#: written before its fresh runs: ``docs/benchmarks.md``, "Forty-fifth session, lead"). Before, only
#: the flight's own wind shift was asked of it, within 3 standard errors plus 25 %: the b737's clean s23 (seed 3)
#: was named -1.59 +- 0.28 m/s where the triangle read +0.53 +- 0.51.
SIGNATURE_TRIANGLE_AGREE = True
#: The signature path's significance (:data:`MIN_T`) counts :data:`COEF_SYSTEMATIC_MPS` in quadrature with the fit's
#: coloured standard error, as the wind-triangle path does for the same coefficient fit (on since the forty-fifth
#: session, with :data:`SIGNATURE_TRIANGLE_AGREE`). Before, the coloured error alone: the ultrastick's clean s26
#: (seed 4) was named -0.26 +- 0.033 m/s (t 8; with the term 1.3).
SIGNATURE_SYSTEMATIC = True
#: True: an accepted pitot finding takes its place among the findings by its held-out gain, like the catalogue's and
#: the search's causes (:func:`with_pitot`; tried 2026-11-23, branch i9-heave2). False (kept): first, as
#: :func:`gcs_sysid.diagnose.sparse.merge_findings` keeps every data-compatibility cause first. Measured with True at
#: the new turbulence levels (rascal, t6, c172x, the heave band off and on): the pitot lost the top on 6 of the 17
#: flights where it was named (``scale:CY`` first, 62-84 %), one of them otherwise found; with
#: :data:`MIN_T_COEF_CONFIRM` the false pitot it guarded against is no longer accepted (``docs/benchmarks.md``,
#: *Fifteenth session, i9-heave2*).
RANK_BY_GAIN = False
#: The share of the wind triangle's variance (of the change since the reference flight(s)) above which
#: :func:`pitot_resolution` names a component as what limits the flight: the autopilot wind's error (advice: a heading
#: reversal or a cloverleaf) or the scatter of the pitot against GPS in gusts (advice: longer steady legs). A report
#: figure; no decision reads it.
LIMITING_SHARE = 0.5


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
    if not ctx.has("wn", "we", "phi", "theta", "psi"):
        return None
    w_ap = autopilot_wind(flight, ctx.t)
    if w_ap is None:
        return None
    ap = (w_ap[:, 0], w_ap[:, 1])
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
                   model=None, min_score: float = 30.0, min_gain_pct: float = 10.0,
                   angle_fits: dict | None = None) -> dict:
    """Fit and judge ``bias:airspeed`` and ``scale:airspeed`` on the coefficients (see the module doc).

    Args:
        ctx: the context (``train`` the selection rows, ``test`` the held-out rows, split here into
            acceptance and untouched gain rows by :func:`~gcs_sysid.diagnose.physical.split_held_out`).
        R: (T, 6) residual against the model under test. proj: the gust projector or None.
        flight: the decoded flight (for the wind check) or None.
        references: :class:`~gcs_sysid.diagnose.differential.Reference` flights (same model).
        airframe, model: for the reference contexts.
        min_score, min_gain_pct: the usual acceptance on the acceptance rows.
        angle_fits: the flight's ``FlightStates.angle_fits``: its re-reduction with the pitot corrected aids the
            sideslip with the same side-force estimator (:func:`_unit_delta_rereduced`); None: its own choice.

    Returns:
        ``{"candidates": [...], "finding": dict | None, "calibration": [str], "delta"}``; ``delta`` (T, 6)
        the accepted cause's correction (``R + delta`` the residual after it; not JSON, for
        :func:`gcs_sysid.diagnose.core._differential_gains`); each candidate
        ``{"cause", "estimate", "std_error", "t_statistic", "score", "gain_percent", "checks": {...},
        "accepted"}``; ``finding`` the accepted one as a diagnosis finding (evidence domain
        ``"physical signature"``), ``gain`` on the untouched rows.
    """
    acc, gain_rows = split_held_out(ctx.t, ctx.test)
    ctx_a = with_test(ctx, acc)
    wind = wind_shift(ctx, flight)
    out = {"candidates": [], "finding": None, "calibration": []}
    best, passed = None, []
    for cause in PITOT_CAUSES:
        f = _fit(ctx_a, np.nan_to_num(R), proj, cause)
        if f is None:
            continue
        null = _null(cause)
        # the between-flight systematic of a bias fitted on the coefficients, in the cause's own units
        sys_se = COEF_SYSTEMATIC_MPS / _mps_per_unit(ctx, cause) if SIGNATURE_SYSTEMATIC else 0.0
        tstat = (f.estimate - null) / float(np.hypot(f.std_error, sys_se))
        checks = {"significant": bool(abs(tstat) >= MIN_T),
                  "accepted_on_acceptance_rows": bool(f.score >= min_score and f.gain_percent >= min_gain_pct)}
        cand = {"cause": cause, "estimate": float(f.estimate), "std_error": float(f.std_error),
                "t_statistic": float(tstat), "score": float(f.score), "gain_percent": float(f.gain_percent),
                "checks": checks}
        out["candidates"].append(cand)
        if cause == "bias:airspeed":
            cand["references"] = _reference_values(references, airframe, model, cause)
        if not all(checks.values()):
            cand["accepted"] = False
            continue
        # the autopilot's own wind estimate independently confirms a pitot error along the heading: then the
        # coefficient offsets the bias makes are part of its evidence, not a between-flight allowance
        b_est = f.estimate if cause == "bias:airspeed" else (f.estimate - 1.0) * _median_airspeed(ctx)
        confirmed = wind is not None and abs(wind["bias_mps"]) >= MIN_T_WIND * wind["std_error"] and \
            abs(wind["bias_mps"] - b_est) <= 3.0 * np.hypot(wind["std_error"], f.std_error) + 0.25 * abs(b_est)
        gate = physical_gate(ctx, np.nan_to_num(R), f.delta, 1, proj, acc, gain_rows,
                             offsets_allowed=False if confirmed else None)
        cand["confirmed_by_wind_estimate"] = bool(confirmed)
        checks["signature"] = gate["signature"]["holds"]
        checks["beats_terms"] = bool(gate["versus_terms"]["beats"])
        cand["gate"] = gate
        if wind is not None:
            b = f.estimate if cause == "bias:airspeed" else (f.estimate - 1.0) * _median_airspeed(ctx)
            checks["wind_shift"] = bool(abs(wind["bias_mps"] - b) <= 3.0 * np.hypot(wind["std_error"], f.std_error)
                                        + 0.25 * abs(b))
            cand["wind_shift"] = wind
        refs = cand["references"] if "references" in cand else _reference_values(references, airframe, model, cause)
        cand["references"] = refs
        same = [r for r in refs if abs(f.estimate - r["estimate"]) < 3.0 * np.hypot(f.std_error, r["std_error"])]
        checks["changed_since_reference"] = not (refs and len(same) == len(refs))
        if refs and len(same) == len(refs):
            vals = ", ".join(f"{r['estimate']:.3g}" for r in refs)
            out["calibration"].append(f"{cause} = {f.estimate:.3g} +- {f.std_error:.2g}, the same in the reference "
                                      f"flight(s) ({vals}): a calibration to correct, not a change")
        cand["accepted"] = all(checks.values())
        cand["gain_untouched"] = gate["versus_terms"].get("gain_cause", {})
        if cand["accepted"]:
            passed.append((f, cand, gate))
    fused = _fused_candidate(ctx, R, proj, flight, references, airframe, model, out["candidates"], gain_rows,
                             min_gain_pct, angle_fits)
    for f, cand, gate in passed:
        if SIGNATURE_TRIANGLE_AGREE and fused is not None and fused.get("change") is not None:
            k, null = _mps_per_unit(ctx, f.cause), _null(f.cause)
            ref_mean, ref_se = _references_mean(cand["references"])
            ref = ((ref_mean - null) * k, ref_se * k) if cand["references"] else (0.0, 0.0)
            agree = signature_agrees_with_triangle(fused["change"], (f.estimate - null) * k, ref, f.std_error * k)
            cand["checks"]["triangle_agrees"] = agree
            cand["accepted"] = bool(cand["accepted"] and agree)
        if cand["accepted"] and (best is None or f.score > best[0].score):
            best = (f, cand, gate)
    out["wind_triangle"] = fused
    if fused is not None:
        fused["resolution"] = pitot_resolution(fused)
    delta = fused.pop("_delta", None) if fused is not None else None
    if fused is not None and fused["accepted"]:
        out["finding"] = fused.pop("finding")
        out["delta"] = delta
        return out
    if fused is not None:
        fused.pop("finding", None)
    if best is not None:
        f, cand, gate = best
        out["delta"], out["delta_offsets_removed"] = f.delta, bool(gate.get("offsets_allowed"))
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


def _references_mean(refs: list[dict]) -> tuple[float, float]:
    """Inverse-variance mean of the references' fits of one cause (:func:`_reference_values`) and its standard error,
    in the cause's units; ``(0, 0)`` without any."""
    if not refs:
        return 0.0, 0.0
    w = np.array([1.0 / max(r["std_error"], 1e-9) ** 2 for r in refs])
    return float(np.sum(w * [r["estimate"] for r in refs]) / w.sum()), float(1.0 / np.sqrt(w.sum()))


def _median_airspeed(ctx: DiagContext) -> float:
    """The flight's median airspeed over its valid rows, m/s."""
    return float(np.median(ctx.x("V")[ctx.valid]))


def _mps_per_unit(ctx: DiagContext, cause: str) -> float:
    """m/s of airspeed per unit of a pitot cause: 1 for a bias, the flight's median V for a scale (``(s - 1) V``)."""
    return _median_airspeed(ctx) if cause == "scale:airspeed" else 1.0


def signature_agrees_with_triangle(change: dict, estimate_mps: float, reference: tuple[float, float],
                                   std_error: float) -> bool:
    """Does a pitot cause fitted on the coefficients' signature agree with the wind triangle's change?

    The test of :func:`fuse_pitot_evidence` applied to the signature path's finding: the coefficients' change since
    the reference flight(s) (``estimate_mps`` less the references' fit of the same cause, its standard error
    ``std_error`` with theirs and :data:`COEF_SYSTEMATIC_MPS` in quadrature) and the triangle's change
    (``change``, :func:`gcs_sysid.diagnose.wind_triangle.change_since_references`) must differ by at most three
    combined standard errors. Read when :data:`SIGNATURE_TRIANGLE_AGREE` is on.

    Args:
        change: ``{"change_mps", "std_error"}`` (m/s). estimate_mps: the flight's fit, m/s of airspeed.
        reference: ``(mean, se)`` of the references' fit, m/s. std_error: the flight's fit's, m/s.

    Returns:
        True when they agree (or either standard error is not positive and finite: nothing to test).
    """
    coef_change = estimate_mps - reference[0]
    coef_se = float(np.sqrt(std_error ** 2 + reference[1] ** 2 + COEF_SYSTEMATIC_MPS ** 2))
    fused = fuse_pitot_evidence(change, coef_change, coef_se)
    return True if fused is None else bool(fused["agree"])


def fuse_pitot_evidence(triangle: dict | None, coef_change: float, coef_se: float) -> dict | None:
    """Two independent measurements of one pitot bias change, combined when they agree.

    The wind triangle (:func:`gcs_sysid.diagnose.wind_triangle.change_since_references`: the pitot
    against GPS minus the wind, flight minus reference) and the coefficients' qbar signature (the
    bias fitted on the coefficient residual, flight minus reference, its standard error with
    :data:`COEF_SYSTEMATIC_MPS` in quadrature) see the same change through unrelated errors (the wind
    estimate's wander; the model's between-flight inadequacy). They *agree* when they differ by at most
    3 combined standard errors; then the inverse-variance mean is the estimate.

    Args:
        triangle: ``{"change_mps", "std_error"}`` or None. coef_change, coef_se: m/s.

    Returns:
        None without a usable triangle, else ``{"agree", "estimate", "std_error", "t_statistic",
        "triangle_mps", "triangle_se", "coefficients_mps", "coefficients_se"}``.
    """
    if triangle is None or not (triangle["std_error"] > 0) or not (coef_se > 0) or not np.isfinite(coef_change):
        return None
    a, sa = triangle["change_mps"], triangle["std_error"]
    wa, wc = 1.0 / sa ** 2, 1.0 / coef_se ** 2
    est = (wa * a + wc * coef_change) / (wa + wc)
    se = 1.0 / np.sqrt(wa + wc)
    agree = abs(a - coef_change) <= 3.0 * np.hypot(sa, coef_se)
    return {"agree": bool(agree), "estimate": float(est), "std_error": float(se), "t_statistic": float(est / se),
            "triangle_mps": float(a), "triangle_se": float(sa), "coefficients_mps": float(coef_change),
            "coefficients_se": float(coef_se)}


def coefficients_confirm(fused: dict) -> bool:
    """Do the coefficients on their own see the bias the fused estimate names (:data:`MIN_T_COEF_CONFIRM`)?

    Args:
        fused: :func:`fuse_pitot_evidence` (``estimate``, ``coefficients_mps``, ``coefficients_se``, m/s).

    Returns:
        True when ``sign(estimate) * coefficients_mps / coefficients_se >= MIN_T_COEF_CONFIRM``.
    """
    return _sees_it(fused, "coefficients", MIN_T_COEF_CONFIRM)


def _sees_it(fused: dict, which: str, min_t: float) -> bool:
    """One measurement's own change (``which``: ``"coefficients"`` or ``"triangle"``) lies at least ``min_t`` of its
    standard errors from 0 on the fused estimate's side; False without a finite change and a positive error."""
    se = fused[f"{which}_se"]
    if not (se > 0) or not np.isfinite(fused[f"{which}_mps"]):
        return False
    return bool(np.sign(fused["estimate"]) * fused[f"{which}_mps"] / se >= min_t)


def triangle_confirms(fused: dict) -> bool:
    """Does the wind triangle on its own see the bias the fused estimate names (:data:`MIN_T_TRIANGLE_CONFIRM`)?

    Args:
        fused: :func:`fuse_pitot_evidence` (``estimate``, ``triangle_mps``, ``triangle_se``, m/s).

    Returns:
        True when ``sign(estimate) * triangle_mps / triangle_se >= MIN_T_TRIANGLE_CONFIRM`` (always True while it is
        None).
    """
    return MIN_T_TRIANGLE_CONFIRM is None or _sees_it(fused, "triangle", MIN_T_TRIANGLE_CONFIRM)


def _scatter_se(tri: dict) -> float:
    """A :func:`~gcs_sysid.diagnose.wind_triangle.wind_triangle`'s bias standard error with the wind known: its
    residual's RMS over the square root of its effective samples (m/s; NaN without them)."""
    n_eff, rms = tri.get("n_eff"), tri.get("residual_rms_mps")
    if not n_eff or rms is None or not n_eff > 0:
        return float("nan")
    return float(rms / np.sqrt(n_eff))


def pitot_resolution(wt: dict) -> dict | None:
    """What a flight resolves of a pitot bias change, what limits it, and what would resolve more (a report figure;
    no decision reads it).

    The smallest change since the reference flight(s) the diagnosis could name is :data:`MIN_T_FUSED` standard errors
    of the measurement that names it: the wind triangle's change fused with the coefficients' exact re-fit where the
    re-fit ran (:func:`_fused_candidate`), else the triangle's change alone (the closed-form screen does not name;
    its stated error is too small, ``docs/diagnose.md``). The other checks (agreement, both measurements confirming,
    the gain) can only raise it. The triangle's variance (this flight's and the references' mean, as
    :func:`~gcs_sysid.diagnose.wind_triangle.change_since_references` adds them) is split into its *scatter*, the
    pitot against GPS in gusts the wind estimate cannot follow (``residual_rms_mps^2 / n_eff`` per flight: it falls
    as one over the steady flight time), and the rest, the *wind estimate's* error (along a steady track the wind
    and a pitot bias are one unknown, told apart only by the autopilot's wind, prior :data:`WIND_SYSTEMATIC_MPS` per
    component: a heading reversal or a cloverleaf removes it; USNTPS FTM 108, ch. 9; Lewis, "A Flight Test
    Technique Using GPS for Position Error Correction Testing", SETP Cockpit, 2003). A share of at least
    :data:`LIMITING_SHARE` names what limits the flight and what to fly.

    Args:
        wt: ``data["pitot"]["wind_triangle"]`` (:func:`_fused_candidate`'s document): ``flight`` and ``references``
            (:func:`~gcs_sysid.diagnose.wind_triangle.wind_triangle` each), ``change``
            (:func:`~gcs_sysid.diagnose.wind_triangle.change_since_references`), ``fused`` (or None) and
            ``coefficients_rereduced`` (present where the exact re-fit ran).

    Returns:
        None without the flight's triangle change; else ``{"min_named_mps", "std_error_mps", "by",
        "triangle_std_error_mps", "wind_share", "scatter_share", "limited_by" ("wind estimate" | "scatter" | None),
        "heading_span_deg", "reference_heading_span_deg" (list), "summary", "advice"}`` (m/s, deg, shares 0-1;
        shares None where a flight's scatter is not known; ``advice`` None when neither share reaches
        :data:`LIMITING_SHARE`).
    """
    change, tri = wt.get("change"), wt.get("flight")
    if not change or not tri or not change.get("std_error", 0) > 0:
        return None
    fused = wt.get("fused") if wt.get("coefficients_rereduced") else None
    by = ("the wind triangle and the coefficients' exact re-fit, fused" if fused
          else "the wind triangle alone (the coefficients' exact re-fit runs only past the screen)")
    se = float(fused["std_error"]) if fused else float(change["std_error"])
    refs = [r for r in (wt.get("references") or []) if r and r.get("std_error", 0) > 0]
    flights = [("this flight", tri)] + [(r.get("label", "reference"), r) for r in refs]
    # the change's variance: this flight's plus the references' inverse-variance mean's, each split in two
    w = np.array([1.0 / r["std_error"] ** 2 for r in refs])
    parts = [(1.0, tri)] + [(float(wi / w.sum()), r) for wi, r in zip(w, refs)]
    total = float(sum(a * a * c["std_error"] ** 2 for a, c in parts))
    scatter = float(sum(a * a * min(_scatter_se(c), c["std_error"]) ** 2 for a, c in parts))
    shares = (1.0 - scatter / total, scatter / total) if np.isfinite(scatter) and total > 0 else (None, None)
    limited = None
    if shares[0] is not None and shares[0] >= LIMITING_SHARE:
        limited = "wind estimate"
    elif shares[1] is not None and shares[1] >= LIMITING_SHARE:
        limited = "scatter"
    span = tri.get("heading_span_deg")
    out = {"min_named_mps": float(MIN_T_FUSED * se), "std_error_mps": se, "by": by,
           "triangle_std_error_mps": float(change["std_error"]), "wind_share": shares[0], "scatter_share": shares[1],
           "limited_by": limited, "heading_span_deg": span,
           "reference_heading_span_deg": [r.get("heading_span_deg") for r in refs]}
    since = "since the reference flight(s)" if refs else "(no reference flight, so against zero)"
    out["summary"] = (f"the pitot's bias change {since} is measured to +- {se:.2g} m/s (stated standard error) by "
                      f"{by}: a change smaller than about {MIN_T_FUSED * se:.2g} m/s ({MIN_T_FUSED:g} standard "
                      "errors) is not named on this flight")
    if shares[0] is not None:
        out["summary"] += (f"; of the wind triangle's variance {100 * shares[0]:.0f} % is the autopilot wind "
                           f"estimate's error, {100 * shares[1]:.0f} % the pitot's scatter against GPS in gusts")
    where = "on the reference flight and on this one" if refs else "in the next flight"
    spans = ", ".join(f"{lbl} {c['heading_span_deg']:.0f} deg" for lbl, c in flights
                      if c.get("heading_span_deg") is not None)
    out["advice"] = {
        "wind estimate": (f"limited by the wind estimate (heading spans: {spans}): along a steady track the wind and a "
                          f"pitot bias are one unknown, told apart only by the autopilot's wind (taken as good to "
                          f"{WIND_SYSTEMATIC_MPS:g} m/s per component). To resolve a smaller bias, fly a heading "
                          f"reversal or a cloverleaf (three steady legs about 120 deg apart) {where}: the wind is "
                          "then solved from the flight itself (USNTPS FTM 108, ch. 9; Lewis 2003)"),
        "scatter": ("limited by the pitot's scatter against GPS in gusts the wind estimate cannot follow: its "
                    "variance falls as one over the steady flight time (four times the time halves its standard "
                    f"error); fly longer steady legs, or in calmer air, {where}"),
        None: None}[limited]
    return out


def _acceptance_checks(fused: dict) -> tuple[dict, dict]:
    """The agreement, significance and confirmation checks of a fused pitot finding (the gain is added by the caller).

    ``significant``: the fused change's ``|t| >= MIN_T_FUSED``; ``coefficients_confirm``: :func:`coefficients_confirm`,
    waived (True, said in the second return value) where :data:`COEF_WITNESS_MAX_SE_MPS` is set and the coefficients'
    standard error is above it: there they are no witness, and the inverse-variance fusion already gives them the little
    weight they carry. ``triangle_confirms`` (only while :data:`MIN_T_TRIANGLE_CONFIRM` is set):
    :func:`triangle_confirms`.

    Args:
        fused: :func:`fuse_pitot_evidence`.

    Returns:
        ``(checks, witness)``: ``{"measurements_agree", "significant", "coefficients_confirm"[, "triangle_confirms"]}``
        (bools) and ``{"witness": bool, "coefficients_se", "max_se", "why"}``.
    """
    se_c = float(fused["coefficients_se"])
    cap = COEF_WITNESS_MAX_SE_MPS
    witness = cap is None or not se_c > float(cap)
    checks = {"measurements_agree": bool(fused["agree"]),
              "significant": bool(abs(fused["t_statistic"]) >= MIN_T_FUSED),
              "coefficients_confirm": coefficients_confirm(fused) if witness else True}
    if MIN_T_TRIANGLE_CONFIRM is not None:
        checks["triangle_confirms"] = triangle_confirms(fused)
    why = None if witness else (f"the coefficients' estimate of the bias has a standard error of {se_c:.2f} m/s (above "
                                f"{float(cap):g}): no witness of a bias this size, so they are not asked to confirm "
                                "it (they still must agree, and the fused change must be significant)")
    return checks, {"witness": bool(witness), "coefficients_se": se_c, "max_se": cap, "why": why}


def screen(fused: dict, change: dict) -> dict:
    """The cheap screen before the exact re-fit of a pitot bias (:func:`_unit_delta_rereduced`).

    It passes when the wind triangle and the closed-form coefficient fit agree and their fused change
    is at least :data:`MIN_T_SCREEN` standard errors, *or* when the wind triangle's change since the
    reference flight(s) alone is at least :data:`MIN_T_SCREEN_TRIANGLE`: the closed-form fit misses the aided angles'
    response to the airspeed, so on some aircraft it comes out too low to agree, and it must not keep the exact re-fit
    (which decides, with the same agreement test) from being reached.

    Args:
        fused: :func:`fuse_pitot_evidence` of the triangle and the closed-form fit.
        change: :func:`gcs_sysid.diagnose.wind_triangle.change_since_references`.

    Returns:
        ``{"passes", "fused", "triangle_alone", "linearise_at_mps"}``: the two routes and the bias at
        which the re-fit is linearised (the fused estimate, else the triangle's change), m/s.
    """
    by_fused = bool(fused["agree"] and abs(fused["t_statistic"]) >= MIN_T_SCREEN)
    by_triangle = bool(change["std_error"] > 0 and abs(change["t_statistic"]) >= MIN_T_SCREEN_TRIANGLE)
    return {"passes": by_fused or by_triangle, "fused": by_fused, "triangle_alone": by_triangle,
            "linearise_at_mps": float(fused["estimate"] if by_fused else change["change_mps"])}


def _fused_candidate(ctx, R, proj, flight, references, airframe, model, candidates, gain_rows, min_gain_pct,
                     angle_fits=None):
    """``bias:airspeed`` by the wind triangle and the coefficients together (:func:`fuse_pitot_evidence`).

    Accepted when both measurements agree, their combined change since the reference flight(s) is at
    least :data:`MIN_T_FUSED` standard errors from 0, the coefficients on their own see it (at least
    :data:`MIN_T_COEF_CONFIRM` of their standard errors on the fused estimate's side,
    :func:`coefficients_confirm`) and the correction at that size gains at least ``min_gain_pct`` on a
    coefficient's untouched rows (never used by either fit) or on the pitot's own reading
    (:data:`SENSOR_GAIN`). The offsets the bias makes count as its evidence in that gain (the triangle
    measures the bias without the coefficients), which is why the coefficients must confirm it first.
    ``angle_fits``: as :func:`airspeed_cause`.
    """
    from .wind_triangle import change_since_references, triangle_gain, wind_triangle

    cand = next((c for c in candidates if c["cause"] == "bias:airspeed"), None)
    if cand is None:
        return None
    tri = wind_triangle(ctx.t, ctx.states, ctx.valid, flight)
    ref_tri = _reference_triangles(references, airframe, model)
    change = change_since_references(tri, ref_tri)
    refs = cand.get("references") or []
    ref_b, ref_se = _references_mean(refs)
    coef_change = cand["estimate"] - ref_b
    coef_se = float(np.sqrt(cand["std_error"] ** 2 + ref_se ** 2 + COEF_SYSTEMATIC_MPS ** 2))
    fused = fuse_pitot_evidence(change, coef_change, coef_se)
    out = {"flight": tri, "references": ref_tri, "change": change, "fused": fused, "accepted": False}
    if fused is None:
        out["why"] = "no wind triangle (no pitot, ground velocity or autopilot wind on this flight)"
        return out
    # the screen passed: the pipeline re-run on the flight with the pitot corrected gives the bias's
    # exact effect on every regressor and coefficient (the estimation layer's aided angles move with the
    # airspeed in ways the closed-form transform does not model); the coefficient fit is then redone with it
    # the screen: the two agree and their fused change is significant, or the wind triangle alone is
    # (then the closed-form coefficient fit, which the aided angles' response to the airspeed biases,
    # must not keep the exact re-fit from being reached; the re-fit is then linearised at the triangle's value)
    out["screen"] = screen(fused, change)
    if not out["screen"]["passes"]:
        out["why"] = "the screen (wind triangle and closed-form coefficient fit) did not pass"
        out["checks"] = {"measurements_agree": fused["agree"], "significant": False}
        return out
    D1 = _unit_delta_rereduced(ctx, flight, out["screen"]["linearise_at_mps"], angle_fits)
    if D1 is not None:
        # the same exact re-fit on the reference flight(s), coefficient by coefficient: the differential
        # baseline of each coefficient's estimate (_rereduced_baseline); without one, the closed-form
        # reference value as before
        base = _rereduced_baseline(references, airframe, model, out["screen"]["linearise_at_mps"]) \
            if DIFFERENTIAL_REREDUCED else None
        b_c, se_c, per_coef = _fit_unit_delta(ctx, R, D1, base)
        coef_change = b_c - (0.0 if base else ref_b)
        v_med = _median_airspeed(ctx) if REFIT_SYSTEMATIC_REL and np.isfinite(b_c) else 0.0
        coef_se = float(np.sqrt(se_c ** 2 + (0.0 if base else ref_se ** 2) + REFIT_SYSTEMATIC_MPS ** 2
                                + (REFIT_SYSTEMATIC_REL * v_med) ** 2))
        fused = fuse_pitot_evidence(change, coef_change, coef_se)
        out["fused"] = fused
        out["coefficients_rereduced"] = {"estimate": float(b_c), "std_error": float(se_c), "by_coefficient": per_coef,
                                         "baseline": "re-reduced reference flight(s), per coefficient" if base
                                         else "closed-form reference value"}
        if fused is None:
            # reached on the wind triangle alone (screen), the re-fit found no coefficient that carries
            # the bias (no finite estimate): nothing to confirm it with, so no finding
            out["why"] = "the exact re-fit gave no finite coefficient estimate of the bias to confirm the wind triangle"
            out["checks"] = {"measurements_agree": False, "significant": False}
            return out
        b = fused["estimate"]
        delta = b * D1
    else:
        b = fused["estimate"]
        delta = next(c for c in transforms(ctx) if c.cause == "bias:airspeed").delta(ctx, [b])
    sc = Scorer(with_test(ctx, gain_rows), np.nan_to_num(R), proj)
    score, gains = sc.score(np.nan_to_num(delta), 1)
    gain_pct = {k: v["percent"] for k, v in gains.items()}
    if SENSOR_GAIN:
        # the bias acts first on the pitot's own reading: its gain there, in m/s on the wind triangle's
        # residual over the same untouched rows (wind_triangle.triangle_gain), is one of the quantities
        # the largest gain is taken over, as each coefficient is
        # "before" is the reference flight(s)' level against their logged wind (the same residual), 0 without one
        ref_b = _reference_level(ref_tri)
        g_v = triangle_gain(ctx.t, ctx.states, gain_rows & ctx.valid, flight, ref_b, ref_b + float(b))
        if g_v is not None:
            out["gain_sensor"] = g_v
            gain_pct["V"] = g_v["percent"]
    main = max(gain_pct, key=gain_pct.get) if gain_pct else ""
    checks, witness = _acceptance_checks(fused)
    checks["gain_on_untouched_rows"] = bool(main and gain_pct[main] >= min_gain_pct)
    out.update(checks=checks, coefficients_witness=witness, gain_untouched=gain_pct, score_untouched=float(score),
               accepted=all(checks.values()), _delta=np.nan_to_num(delta))
    if not out["accepted"]:
        out["why"] = ", ".join(k for k, v in checks.items() if not v) + " failed"
        return out
    ref_txt = (f"reference flight(s) {change['reference_mps']:+.2f} m/s" if change["reference_mps"] is not None
               else "no reference flight")
    out["finding"] = {
        "cause": "bias:airspeed", "coefficient": main, "estimate": float(b), "std_error": float(fused["std_error"]),
        "gain": {"percent": float(gain_pct[main]), "rows": "untouched (held out from selection and acceptance)"},
        "evidence": {"domain": "data compatibility", "method": "wind triangle + coefficient signature",
                     "score": float(score), "t_statistic": fused["t_statistic"], "checks": checks,
                     "wind_triangle": {"flight": tri, "references": ref_tri, "change": change},
                     "coefficients": {"estimate": cand["estimate"], "std_error": cand["std_error"],
                                      "references": refs, "systematic_mps": COEF_SYSTEMATIC_MPS},
                     "fused": fused, "coefficients_witness": witness, "gain_untouched_by_coefficient": gain_pct,
                     "gain_sensor": out.get("gain_sensor"),
                     "differential": {"verdict": "changed" if change["reference_mps"] is not None
                                      else "no reference flight", "references": refs},
                     "signature": {"implied": [c for c, g in gain_pct.items() if g > 0 and c != "V"]},
                     "separable": True, "rivals": [],
                     "summary": f"the pitot reads {b:+.2f} +- {fused['std_error']:.2f} m/s more than before: "
                                f"the wind triangle (pitot against GPS minus the autopilot's wind) "
                                f"{change['flight_mps']:+.2f} m/s on this flight, {ref_txt}; the coefficients' "
                                f"qbar signature {coef_change:+.2f} m/s"}}
    return out


def _unit_delta_rereduced(ctx: DiagContext, flight, b0: float, angle_fits: dict | None = None) -> np.ndarray | None:
    """Change of the residual (T, 6) per m/s of pitot bias, from the pipeline re-run with the pitot reading
    ``b0`` m/s (TAS) less (estimation and coefficients as :func:`gcs_sysid.diagnose.run.load_measurements`
    computes them); None when the flight cannot be re-reduced (no pitot stream, another grid, ``b0`` ~ 0).
    ``angle_fits``: the flight's own ``FlightStates.angle_fits``; its beta fit is given to the re-run so that the
    side-force slopes are fitted by the same estimator (with :data:`gcs_sysid.estimation.airangles.INSTRUMENTED_BETA`
    2SLS or least squares; a re-run that chose the other would put the estimators' difference into the per-m/s
    effect: the JSBSim t6's 2-m/s bias read 2.37 against 1.88 m/s, ``docs/benchmarks.md``, "Seventeenth session,
    i9-ivdiag"). None: the re-run chooses its own.
    """
    import dataclasses

    from ..aero import compute_coefficients
    from ..estimation import estimate_states
    from ..telemetry.types import Stream
    from .run import BETA_GLS, BETA_PROFILE      # the sideslip's estimator load_measurements used

    if flight is None or abs(b0) < 1e-3 or not ctx.has("rho"):
        return None
    streams = dict(flight.streams)
    changed = False
    for name, key in (("airspeed", "eas"), ("vfr_hud", "airspeed")):
        if name in streams and key in streams[name].fields:
            st = streams[name]
            rho = np.interp(st.t, ctx.t, ctx.states["rho"])
            f = dict(st.fields)
            f[key] = np.asarray(st[key], float) - b0 * np.sqrt(rho / 1.225)      # TAS bias -> EAS
            streams[name] = Stream(st.name, st.source, st.t, f)
            changed = True
    if not changed:
        return None
    try:
        beta_fit = (angle_fits or {}).get("beta")
        states = estimate_states(dataclasses.replace(flight, streams=streams), ctx.airframe,
                                 turbulence_state=False, profile_beta=BETA_PROFILE, gls_beta=BETA_GLS,  # as loaded
                                 angle_models={"beta": beta_fit} if beta_fit is not None else None)
        table = compute_coefficients(states, ctx.airframe)
    except (ValueError, ArithmeticError, np.linalg.LinAlgError, KeyError):
        return None
    X, Y = np.array(table.X, float), np.asarray(table.Y, float)
    if X.shape != ctx.X.shape or not np.allclose(np.asarray(table.t, float), ctx.t):
        return None
    if SHIFT_KEY in ctx.states:
        X = _realigned_alpha(ctx, table, X, Y)
    D = (Y - ctx.model_values(X)) - (ctx.Y - ctx.model_values())
    return np.where(np.isfinite(D), D, 0.0) / b0


def _realigned_alpha(ctx: DiagContext, table, X: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """The re-reduced flight's regressors (T, 10) in the common alpha frame of :mod:`gcs_sysid.diagnose.alpha_level`.

    A flight diagnosed with the alpha level on (``ctx.states[SHIFT_KEY]``, the shift applied to it) was moved
    into one frame with its reference and the model, which ``ctx.model`` already is; its re-reduction with the
    pitot corrected comes back in the log's own frame. Its offset is found again against ``ctx.model`` (the
    shifted model: the offset ``d`` found is ``-(shift)`` of the corrected flight) and removed, as the
    alignment did for the flight as logged. Re-found rather than the recorded shift reused: a pitot bias scales
    the measured ``CZ`` and so moved the offset the alignment found; the per-m/s effect of the bias must
    include that move, or the coefficients read the frame's change as the bias's (JSBSim c172p, ``bias:airspeed
    = 2`` seed 1, pooled level: CZ read -10.0 m/s, the fused estimate 1.36 m/s with the coefficients
    0.64 +- 1.51, no finding; twenty-third session, branch i9-level2). Where no offset is found the recorded
    shift is applied.
    """
    from ..aero.table import REGRESSORS
    from .alpha_level import level_offset

    ia = REGRESSORS.index("alpha")
    off = level_offset(np.asarray(table.t, float), X, Y, np.asarray(table.valid, bool), ctx.model)["offset_rad"]
    X[:, ia] += -off if np.isfinite(off) else np.asarray(ctx.states[SHIFT_KEY], float)
    return X


def _fit_unit_delta(ctx: DiagContext, R: np.ndarray, D1: np.ndarray,
                    baseline: dict | None = None) -> tuple[float, float, dict]:
    """Pitot bias from the coefficients with its exact per-m/s effect ``D1`` (T, 6): one estimate per
    coefficient, combined by their median.

    With ``baseline`` (``{coef: {"estimate", "std_error"}}``, the same fit on the reference flight(s),
    :func:`_rereduced_baseline`) each coefficient's estimate is its *change* since the reference: the
    reference's value is subtracted and its standard error added in quadrature before the median, and
    a coefficient takes part only when it resolves the bias on both flights.

    Each coefficient ``j`` gives ``b_j`` from ``R_j + b_j D1_j ~ 0`` on the selection rows with both
    sides' means removed (the between-flight offset allowance of :mod:`gcs_sysid.diagnose.physical`: the
    bias counts here only for what it explains beyond a constant per coefficient; the wind triangle
    measures its level) and a coloured standard error. A coefficient takes part when it resolves the bias
    (``se_j <= MAX_SE_COEF_MPS``). One bias acts on every coefficient, so their estimates agree where the
    model is adequate; the median is robust to the minority where the model's own between-flight error
    correlates with the bias's effect, and its standard error is the larger of the coefficients' scatter
    (``1.2533 * 1.4826 * MAD / sqrt(k)``) and the smallest coloured error.

    Returns:
        ``(b, std_error, {coef: {"estimate", "std_error", "used"}})``; NaN when no coefficient resolves it.
    """
    from ..aero.table import COEFFICIENTS
    from .regression import colored_covariance

    tr = ctx.train & ctx.valid
    per, est, ses = {}, [], []
    for j, c in enumerate(COEFFICIENTS):
        if not ctx.active[j]:
            continue
        r, d = np.nan_to_num(R[tr, j]), np.nan_to_num(D1[tr, j])
        r, d = r - r.mean(), d - d.mean()
        dd = float(d @ d)
        if dd <= 0 or len(d) < 50:
            continue
        b = -float(r @ d) / dd
        se = float(np.sqrt(max(colored_covariance(d[:, None], r + b * d)[0, 0], 0.0)))
        used = bool(np.isfinite(b) and 0 < se <= MAX_SE_COEF_MPS)
        per[c] = {"estimate": b, "std_error": se, "used": used}
        if baseline is not None:
            ref = baseline.get(c)
            used = bool(used and ref is not None and ref["used"])
            if ref is not None and np.isfinite(ref["estimate"]):
                b, se = b - ref["estimate"], float(np.hypot(se, ref["std_error"]))
            per[c] = {"estimate": b, "std_error": se, "used": used, "flight": per[c]["estimate"],
                      "reference": None if ref is None else ref["estimate"]}
        if used:
            est.append(b)
            ses.append(se)
    if not est:
        return float("nan"), float("nan"), per
    est = np.asarray(est)
    b = float(np.median(est))
    mad = float(np.median(np.abs(est - b)))
    se = max(1.2533 * 1.4826 * mad / np.sqrt(len(est)), float(np.min(ses)))
    return b, float(se), per


def _rereduced_baseline(references, airframe, model, b0: float) -> dict | None:
    """Each coefficient's exact re-fit of the pitot bias (:func:`_fit_unit_delta`) on the reference flight(s).

    Why: the re-fit removes each coefficient's mean (the between-flight offset allowance), and what is left
    of the model's own inadequacy correlates with the bias's per-m/s effect (which scales every coefficient by
    ``(V / (V + b))^2``, so it follows the speed sweep). On the C182 the re-fit reads -0.18 m/s on the
    clean reference and -0.23 on a clean test flight, and a 1 m/s bias read 0.66, then 0.65 after fusion
    with the wind triangle, because the baseline subtracted was the closed-form fit's (+0.01), a different
    estimator. The change of the *same* estimator since the reference, coefficient by coefficient, is
    the differential measurement (as ``b - b_ref`` is for the wind triangle). Costs one more re-reduction
    of each reference flight, only when the screen passed.

    Args:
        references: :class:`~gcs_sysid.diagnose.differential.Reference` flights (decoded flight and states).
        airframe, model: those of the diagnosis. b0: the bias (m/s) the flight's re-fit is linearised at.

    Returns:
        ``{coef: {"estimate", "std_error", "used"}}`` (inverse-variance mean over the references of the
        coefficients each resolves), or None when no reference can be re-reduced.
    """
    acc: dict[str, list] = {}
    for ref in references or ():
        if getattr(ref, "flight", None) is None or getattr(ref, "states", None) is None:
            continue
        try:
            rctx = DiagContext.build(ref.table, airframe, model, ref.states, None, None)
            D1 = _unit_delta_rereduced(rctx, ref.flight, b0, getattr(ref.states, "angle_fits", None))
            if D1 is None:
                continue
            _, _, per = _fit_unit_delta(rctx, np.nan_to_num(rctx.Y - rctx.model_values()), D1)
        except (ValueError, ArithmeticError, np.linalg.LinAlgError):
            continue
        for c, v in per.items():
            acc.setdefault(c, []).append(v)
    if not acc:
        return None
    out = {}
    for c, vs in acc.items():
        ok = [v for v in vs if np.isfinite(v["estimate"]) and v["std_error"] > 0]
        if not ok:
            continue
        w = np.array([1.0 / v["std_error"] ** 2 for v in ok])
        out[c] = {"estimate": float(np.sum(w * [v["estimate"] for v in ok]) / w.sum()),
                  "std_error": float(1.0 / np.sqrt(w.sum())), "used": all(v["used"] for v in ok)}
    return out or None


def _reference_triangles(references, airframe, model) -> list[dict]:
    """:func:`~gcs_sysid.diagnose.wind_triangle.wind_triangle` of each reference flight with a decoded log."""
    from .wind_triangle import triangle_gain, wind_triangle

    out = []
    for ref in references or ():
        if getattr(ref, "flight", None) is None or getattr(ref, "states", None) is None:
            continue
        try:
            rctx = DiagContext.build(ref.table, airframe, model, ref.states, None, None)
            c = wind_triangle(rctx.t, rctx.states, rctx.valid, ref.flight)
        except (ValueError, ArithmeticError, np.linalg.LinAlgError):
            c = None
        if c is not None:
            lv = triangle_gain(rctx.t, rctx.states, rctx.valid, ref.flight, 0.0, 0.0)
            out.append(c | {"label": getattr(ref, "label", "reference"),
                            "level_logged_wind_mps": None if lv is None else lv["level"]})
    return out


def _reference_level(ref_tri: list[dict]) -> float:
    """The reference flight(s)' pitot level against their logged wind, m/s (inverse-variance mean over the
    references' :func:`~gcs_sysid.diagnose.wind_triangle.wind_triangle` standard errors; 0 without one): the
    "before" of :func:`~gcs_sysid.diagnose.wind_triangle.triangle_gain`."""
    ok = [c for c in ref_tri if c.get("level_logged_wind_mps") is not None and c["std_error"] > 0]
    if not ok:
        return 0.0
    w = np.array([1.0 / c["std_error"] ** 2 for c in ok])
    return float(np.sum(w * [c["level_logged_wind_mps"] for c in ok]) / w.sum())


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
    """Findings with an accepted pitot cause first after the faults (with :data:`RANK_BY_GAIN`: placed by its held-out
    gain, before the first remaining non-fault finding whose gain is not larger); the aero terms of its
    implied coefficients are its symptoms (``evidence.explains``) and leave the list. Writes ``data["pitot"]`` (the
    candidates and their checks) and appends its calibration notes to ``data["calibration"]``.

    Args:
        findings: the diagnosis' findings. pitot: from :func:`airspeed_cause`. data: ``Diagnosis.data``.

    Returns:
        the new findings list.
    """
    data["pitot"] = {"candidates": [{k: (v if k != "gate" else {"why": v["why"], "signature": v["signature"],
                                                                  "versus_terms": v["versus_terms"]})
                                     for k, v in c.items()} for c in pitot["candidates"]]}
    if pitot.get("wind_triangle") is not None:
        data["pitot"]["wind_triangle"] = pitot["wind_triangle"]
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
    faults = [g for g in findings if g.get("kind") == "fault"]
    rest = [g for g in findings if g.get("kind") != "fault" and g not in symptoms]
    k = 0
    if RANK_BY_GAIN:      # before the first remaining finding it out-gains, as the others are ranked
        g_f = f["gain"].get("percent", 0.0)
        while k < len(rest) and rest[k]["gain"].get("percent", 0.0) > g_f:
            k += 1
    return faults + rest[:k] + [f] + rest[k:]
