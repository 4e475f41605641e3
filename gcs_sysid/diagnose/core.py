"""Diagnose a simulation model against measured coefficients: name the cause, extend, measure the gain.

The model under test ("the simulation") is held against the measured
coefficient table. Candidate causes from the catalogue compete on held-out data
(see :mod:`gcs_sysid.diagnose.candidates`); the best is accepted when its
held-out score beats the complexity penalty by a margin and it removes a
meaningful share of the residual, then the search repeats on what is left.
Accepted aero terms are re-estimated jointly and written into the extended
model; what no cause explains is reported as ``unexplained`` with its size and
where in the envelope and in time it lives. Nothing is ever named without
held-out support. A physical cause (cg_offset, inertia, mass, the pitot) must also show its
signature in every coefficient it implies and beat term-level explanations on rows neither the
fit nor the acceptance saw (:mod:`gcs_sysid.diagnose.physical`, :mod:`gcs_sysid.diagnose.pitot`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..aero.table import COEFFICIENTS, CoefficientTable
from ..airframe import Airframe
from ..errors import DataError
from .candidates import Fitted, Scorer, fit_aero_terms, fit_delays, fit_sensor_causes, fit_stuck
from .context import DiagContext, ModelDict, model_as_dict
from .evidence import maneuver_for, unexplained_report
from .fault_merge import merge_faults, set_aside_answering
from .physical import first_passing
from .faults import FaultThresholds, detect_faults
from .regression import ols
from .residual_gp import residual_structure
from .turbulence import gust_projector
from .terms import term_matrix

__all__ = ["Diagnosis", "diagnose"]


@dataclass
class Diagnosis:
    """Result of :func:`diagnose` (plain data; ``to_json`` gives the diagnosis.json document).

    Attributes:
        findings: accepted causes, dicts with ``cause coefficient estimate std_error evidence gain``
            (and ``onset_s``), ordered by gain.
        unexplained: per-coefficient residual left after the findings (size, where, above_threshold).
        data: facts on the data, the split, equation- and output-error gains, separation advice.
        model: the model under test; model_extended: with the accepted aero terms (re-estimated).
        t, X, residual_before, residual_after, train, test: arrays for the report ((T,), (T,10), (T,6)).
        fitted: the accepted :class:`Fitted` objects; rivals: the best of the others in the last round.
    """

    findings: list[dict]
    unexplained: list[dict]
    data: dict
    model: ModelDict
    model_extended: ModelDict
    t: np.ndarray = field(repr=False)
    X: np.ndarray = field(repr=False)
    residual_before: np.ndarray = field(repr=False)
    residual_after: np.ndarray = field(repr=False)
    train: np.ndarray = field(repr=False)
    test: np.ndarray = field(repr=False)
    fitted: list[Fitted] = field(default_factory=list, repr=False)
    output_error: dict | None = None
    model_inadequacy: list[dict] | None = None

    def to_json(self) -> dict:
        """The ``diagnosis.json`` document (schema in docs/diagnose.md)."""
        doc = {"findings": self.findings, "unexplained": self.unexplained, "data": self.data}
        if self.model_inadequacy is not None:                 # only with reference flights
            doc["model_inadequacy"] = self.model_inadequacy
        return doc


def _eq_error(R0, R1, test) -> dict:
    out = {}
    for j, c in enumerate(COEFFICIENTS):
        b = float(np.sqrt(np.mean(R0[test, j] ** 2)))
        a = float(np.sqrt(np.mean(R1[test, j] ** 2)))
        out[c] = {"rms_before": b, "rms_after": a, "percent": float(100 * (1 - a / b)) if b > 0 else 0.0}
    return out


def _reestimate(ctx: DiagContext, R_final: np.ndarray, accepted: list[Fitted], proj=None) -> None:
    """Re-estimate the accepted aero terms of each coefficient jointly (coloured std errors).

    With a gust projector the fit is on the projected, weighted residuals of all six
    coefficients (the same space the candidates were scored in).
    """
    P = proj if proj is not None else (lambda D: D)
    sw = np.sqrt(ctx.weight)
    tr = ctx.train
    by_coef: dict[str, list[Fitted]] = {}
    for f in accepted:
        if f.kind == "aero":
            by_coef.setdefault(f.cause.split(":")[0], []).append(f)
    for coef, fs in by_coef.items():
        j = COEFFICIENTS.index(coef)
        terms = [f.labels[0] for f in fs]
        Phi = term_matrix(ctx.X, terms)
        base = R_final + sum(-f.delta for f in fs)      # residual without these corrections
        cols = []
        for i in range(len(terms)):
            D = np.zeros_like(base)
            D[:, j] = Phi[:, i]
            cols.append((P(D)[tr] * sw).T.ravel())
        z = (P(base)[tr] * sw).T.ravel()
        A = np.column_stack(cols)
        keep = np.any(A != 0, axis=1)
        res = ols(A[keep], z[keep], terms=[f"x{i}" for i in range(len(terms))])
        for i, f in enumerate(fs):
            th = float(res.theta[i])
            old = f.evidence["model_value"]
            f.params = np.array([th])
            f.estimate, f.std_error = old + th, float(res.std_error[i])
            f.evidence["correction"] = th
            f.model_update = {coef: {terms[i]: th}}
            new_delta = np.zeros_like(f.delta)
            new_delta[:, j] = -th * Phi[:, i]
            R_final += new_delta - f.delta
            f.delta = new_delta


#: With a reference flight and the search, every coefficient-domain finding's reported held-out gain is
#: measured on the *differential* residual: the residual against the model minus the reference flight's own
#: inadequacy predicted on this flight (the search's ridge, :func:`gcs_sysid.diagnose.sparse.sparse_search`),
#: the residual on which the search's own terms have always been measured. Added 2026-11-22, branch i9-pitot;
#: ``docs/diagnose.md`` step 7. Naming is unchanged (every threshold is judged as before).
DIFFERENTIAL_GAIN = True


def _differential_gains(ctx: DiagContext, R0: np.ndarray, proj, inadequacy: np.ndarray, accepted: list[Fitted],
                        pitot: dict | None, findings: list[dict]) -> None:
    """Measure the held-out gain of the catalogue and pitot findings on the change since the reference flight.

    The catalogue's causes and the pitot were scored on the residual against the model, ``R0`` (T, 6),
    which also holds what the model never captured: present in the reference flight too, that part is no
    change and no cause can take it up (on the JSBSim T-37 the reference's inadequacy is 0.0096 of CZ's
    0.0148 held-out RMS, the 2-m/s pitot bias's exact effect 0.0106). The differential diagnosis names
    changes, and the search's terms are measured on ``R0 - inadequacy``; so is every other finding here,
    with its own rows and correction: a catalogue cause on ``ctx.test`` after the causes accepted before it,
    the pitot on its untouched rows (offsets removed where its gate removed them). Each such finding's
    ``gain`` is replaced by the largest per-coefficient gain there (``gain.coefficient``, ``gain.residual``
    = ``"differential"``), the former one kept as ``evidence.gain_against_model``. Sensor causes judged by
    data compatibility (gains in the sensor's own units), telemetry faults and the search's terms keep theirs.

    Args:
        ctx: the context. R0: (T, 6) residual against the model. proj: the gust projector or None.
        inadequacy: (T, 6) the reference's inadequacy on this flight (``sparse_search``'s
            ``inadequacy_prediction``). accepted: the catalogue's accepted causes, in order.
        pitot: :func:`gcs_sysid.diagnose.pitot.airspeed_cause` or None. findings: edited in place.
    """
    from .physical import remove_offsets, split_held_out, with_test

    Rb = np.nan_to_num(R0) - np.nan_to_num(inadequacy)

    def gain_of(c, R, delta, k):
        _, g = Scorer(c, R, proj).score(np.nan_to_num(delta), k)
        if not g:
            return None
        main = max(g, key=lambda m: g[m]["percent"])
        return dict(g[main], coefficient=main, residual="differential (against the model minus the reference "
                                                          "flight's inadequacy)")

    new = {}
    R = Rb.copy()
    for f in accepted:
        new[f.cause] = gain_of(ctx, R, f.delta, len(f.params))
        R = R + f.delta
    pf = pitot.get("finding") if pitot is not None else None
    if pf is not None and pitot.get("delta") is not None:
        _, gain_rows = split_held_out(ctx.t, ctx.test)
        Rp, dp = Rb, pitot["delta"]
        if pitot.get("delta_offsets_removed"):
            Rp, dp = remove_offsets(ctx, Rp), remove_offsets(ctx, dp)
        g = gain_of(with_test(ctx, gain_rows), Rp, dp, 1)
        # the wind-triangle finding's gain in the pitot's own units (pitot.SENSOR_GAIN) needs no reference
        # inadequacy: it stays one of the quantities the largest gain is taken over
        gs = pf.get("evidence", {}).get("gain_sensor")
        if g is not None and gs is not None and gs["percent"] > g["percent"]:
            g = dict(gs, coefficient="V", residual="the pitot's airspeed against the wind triangle (m/s)")
        if g is not None:
            pf.setdefault("evidence", {})["gain_against_model"] = dict(pf.get("gain", {}))
            pf["gain"] = dict(g, rows=pf.get("gain", {}).get("rows", "untouched"))
            if gs is not None:             # the finding's quantity is the one its reported gain is on
                pf["coefficient"] = g["coefficient"]
    for fd in findings:
        if fd is pf or fd.get("source") == "sparse search" or fd.get("kind") == "fault" \
                or str(fd.get("evidence", {}).get("domain", "")).startswith(
                    ("data compatibility", "physical signature", "output error", "telemetry", "sparse search")) \
                or new.get(fd["cause"]) is None:
            continue
        fd.setdefault("evidence", {})["gain_against_model"] = dict(fd.get("gain", {}))
        fd["gain"] = dict(new[fd["cause"]], rows=fd.get("gain", {}).get("rows", "held out"))


def _angle_sigma(states, t: np.ndarray) -> dict | None:
    """The estimator's stated per-sample 1-sigma of alpha and beta (``FlightStates.sigma``, rad) on the grid ``t``
    (T,), ``{"alpha": (T,), "beta": (T,)}`` (NaN where not stated); None without states or sigma. Read by the sparse
    search's errors-in-variables correction (``sparse.THRESHOLDS["errors_in_variables"]``)."""
    sig = getattr(states, "sigma", None) if states is not None else None
    if not sig or not any(k in sig for k in ("alpha", "beta")):
        return None
    st = np.asarray(states.t, float)
    return {k: np.interp(t, st, np.asarray(sig[k], float)) for k in ("alpha", "beta") if k in sig}


def _finding(f: Fitted, rivals: list[Fitted]) -> dict:
    main = f.coefficient
    ev = {"score": float(f.score), "t_statistic": float(f.estimate / f.std_error) if f.std_error > 0 else None,
          "parameters": {k: float(v) for k, v in zip(f.labels, f.params)},
          "gain_by_coefficient": f.gains, **f.evidence}
    close = [r for r in rivals if r.cause != f.cause and r.score > 0.9 * f.score]
    ev["rivals"] = [{"cause": r.cause, "score": float(r.score), "gain_percent": float(r.gain_percent)}
                    for r in rivals[:4] if r.cause != f.cause]
    ev["separable"] = not close
    if close:
        ev["separate_by"] = [maneuver_for(f.cause)] + [maneuver_for(r.cause) for r in close[:2]]
    out = {"cause": f.cause, "coefficient": main, "estimate": float(f.estimate), "std_error": float(f.std_error),
           "evidence": ev, "gain": dict(f.gains.get(main, {"rms_before": 0.0, "rms_after": 0.0, "percent": 0.0}))}
    if f.onset_s is not None:
        out["onset_s"] = float(f.onset_s)
    return out


def diagnose(table: CoefficientTable, airframe: Airframe, model, states=None, *, train=None, test=None,
             max_findings: int = 3, min_score: float = 30.0, min_gain_pct: float = 10.0,
             min_rows: int = 500, unexplained_threshold_pct: float = 20.0, output_error: bool = True,
             min_gain_oe_pct: float = 45.0, project_gusts: bool = True, flight=None,
             fault_thresholds: FaultThresholds | None = None, search: bool = False,
             references=None, search_reference=None, sparse_thresholds: dict | None = None,
             progress=None) -> Diagnosis:
    """Hold a model against measured coefficients, name the cause(s), extend the model.

    Args:
        table: measured coefficients and regressors (T rows).
        airframe: the airframe the coefficients were computed with.
        model: the model under test (``AeroModel`` or ``{coef: {term: value}}``).
        states: the :class:`~gcs_sysid.estimation.states.FlightStates` behind the table
            (needed for wind, inertia and CG causes and for output error); optional.
        train, test: (T,) masks; default interleaved 8-s blocks, every third held out.
        max_findings: most causes accepted (greedy, best first).
        min_score: held-out penalised log-likelihood ratio a cause must exceed.
        min_gain_pct: held-out RMS reduction (percent) it must bring to its main coefficient.
        min_gain_oe_pct: the same for a cause seen in output error (``wind``): open-loop errors are
            dominated by turbulence, whose mean over a minute is itself a small "wind", so the bar is higher.
        min_rows: fewest valid rows accepted.
        unexplained_threshold_pct: share of the remaining held-out residual that must be
            predictable from the regressors for ``unexplained`` to be flagged above threshold.
        output_error: with ``states``, test the ``wind`` cause and measure the output-error gain by
            simulating short windows (:mod:`gcs_sysid.diagnose.output_error`; needs ``gcs_sysid.sim``).
        project_gusts: profile out the angle errors of the reconstruction (turbulence) before
            scoring (:mod:`gcs_sysid.diagnose.turbulence`; only when the data show them).
        flight: the decoded flight behind ``states``; with it the sensor causes (air data, pitot,
            gyro, accelerometer) are judged by data compatibility (:mod:`gcs_sysid.diagnose.compat`)
            instead of in the coefficients, and actuator / engine faults are read from the servo
            outputs against the autopilot's demand (:mod:`gcs_sysid.diagnose.faults`; findings with
            ``kind = "fault"``, listed first). With it the pitot is also judged on the coefficients
            (:func:`gcs_sysid.diagnose.pitot.airspeed_cause`; ``data["pitot"]``), and sensor offsets the
            reference flights had too go to ``data["calibration"]``, not to the findings.
        fault_thresholds: thresholds of the fault detection (default: the frozen ones).
        search: also search a wide candidate library for what each coefficient's residual still needs
            (:mod:`gcs_sysid.diagnose.search`: forward stepwise by block PRESS on the training rows, gain
            measured once on the held-out rows; reported in ``data["search"]``, never as a named cause),
            and run the sparse search of :mod:`gcs_sysid.diagnose.sparse` (``data["sparse"]``), whose
            named terms lead the findings (:func:`~gcs_sysid.diagnose.sparse.merge_findings`).
        references: reference flights (:class:`~gcs_sysid.diagnose.differential.Reference`; the flight(s)
            the model was fitted on): differential diagnosis (:mod:`gcs_sysid.diagnose.differential`):
            findings also present there move to ``model_inadequacy``, the rest are changes (with onset
            where the data show one); ``data["differential"]`` holds the comparison.
        search_reference: ``(table, states)`` of the flight the model was fitted on, for the
            differential sparse search (None: the first of ``references`` when given, else not
            differential).
        sparse_thresholds: overrides of :data:`gcs_sysid.diagnose.sparse.THRESHOLDS` for this call (keys of that
            mapping): the sparse search and the differential step both read the thresholds with these on top
            (:func:`~gcs_sysid.diagnose.sparse.sparse_search` ``thresholds``,
            :meth:`~gcs_sysid.diagnose.differential.DifferentialOptions.from_thresholds`). None: the frozen ones.
        progress: optional callable ``progress(message)``.

    Returns:
        :class:`Diagnosis`.

    Raises:
        DataError: too few valid rows, or no held-out rows (with ``flight``, a partial diagnosis with
            the telemetry faults only is returned instead, ``data["coefficient_diagnosis"]`` saying why).
    """
    t0 = time.perf_counter()
    say = progress or (lambda msg: None)
    ctx = DiagContext.build(table, airframe, model, states, train, test)
    if ctx.valid.sum() < min_rows or ctx.train.sum() < min_rows // 2 or ctx.test.sum() < min_rows // 4:
        if flight is not None:                # the telemetry faults need no coefficients: a partial result
            return _faults_only(ctx, model, flight, airframe, fault_thresholds, min_rows, t0)
        raise DataError(f"diagnose: {int(ctx.valid.sum())} valid rows ({int(ctx.train.sum())} training, "
                        f"{int(ctx.test.sum())} held out); need at least {min_rows} (about "
                        f"{min_rows / 50:.0f} s at 50 Hz of flight with excitation)")
    model0 = {c: dict(v) for c, v in ctx.model.items()}
    R0 = ctx.Y - ctx.model_values()
    proj = gust_projector(ctx, R0) if project_gusts else None
    if proj is not None and proj.active:
        ctx.weight = np.where(ctx.active, 1.0 / proj.sigma**2, 0.0)
    else:
        proj = None
    R = R0.copy()
    accepted: list[Fitted] = []
    last_rivals: list[Fitted] = []
    rounds = []
    for rnd in range(max_findings):
        say(f"diagnose: round {rnd + 1}, fitting candidate causes")
        scorer = Scorer(ctx, R, proj)
        cands = fit_aero_terms(ctx, R, scorer) + fit_delays(ctx, R, scorer) + fit_stuck(ctx, R, scorer) \
            + fit_sensor_causes(ctx, R, scorer, exclude=SENSOR_CAUSES if flight is not None else ())
        cands = [c for c in cands if np.isfinite(c.score) and c.cause not in {a.cause for a in accepted}]
        for c in cands:                      # a quadratic aero term must beat a simpler one by 10 %
            if c.kind == "aero" and ("*" in c.labels[0] or "^2" in c.labels[0]) and c.score > 0:
                c.score *= 0.9
        cands.sort(key=lambda c: c.score, reverse=True)
        rounds.append([{"cause": c.cause, "score": float(c.score), "gain_percent": float(c.gain_percent)}
                       for c in cands[:8]])
        if not cands:
            break
        best = first_passing(ctx, R, proj, cands, min_score, min_gain_pct, rounds[-1])
        if best is None:
            break
        last_rivals = [c for c in cands if c is not best]
        best.evidence["rivals_at_acceptance"] = rounds[-1][1:5]
        accepted.append(best)
        R = R + best.delta
        if best.model_update:
            for coef, upd in best.model_update.items():
                for term, d in upd.items():
                    ctx.model[coef][term] = ctx.model[coef].get(term, 0.0) + d
    ext = {c: dict(v) for c, v in model0.items()}
    if accepted:
        _reestimate(ctx, R, accepted, proj)
        for f in accepted:
            for coef, upd in (f.model_update or {}).items():
                for term, d in upd.items():
                    ext[coef][term] = ext[coef].get(term, 0.0) + d
    findings = [_finding(f, [r for r in last_rivals] if i == 0 else []) for i, f in enumerate(accepted)]
    oe_states = states if (output_error and states is not None and hasattr(states, "t")) else None
    wind_info = None
    if oe_states is not None and "wind" not in {f["cause"] for f in findings}:
        say("diagnose: output error, wind")
        wind_info = _wind_finding(ctx, oe_states, airframe, min_score, min_gain_oe_pct)
        if wind_info and wind_info.get("accepted"):
            findings.append(wind_info["finding"])
    compat, pitot, calibration = [], None, []
    if flight is not None and states is not None and hasattr(states, "t"):
        say("diagnose: sensor data compatibility")
        gust = None
        if proj is not None:
            e = proj.angles(np.nan_to_num(R0))
            e = np.where(ctx.valid[:, None], e - e[ctx.train].mean(axis=0), 0.0)
            gust = {n: e[:, i] for i, n in enumerate(proj.names)}
        compat = _compat_findings(ctx, flight, states, airframe, min_score, min_gain_pct, gust, references)
        findings += [c for c in compat if c["accepted"]]
        calibration = [c["evidence"]["calibration_note"] for c in compat if "calibration_note" in c["evidence"]]
        say("diagnose: pitot causes on their whole signature")
        from .pitot import airspeed_cause, with_pitot

        pitot = airspeed_cause(ctx, R0, proj, flight, references, airframe, model0, min_score, min_gain_pct,
                               angle_fits=getattr(states, "angle_fits", None))
    fault_summary = None
    if flight is not None:
        say("diagnose: actuator and engine faults in the telemetry")
        faults, fault_summary = detect_faults(flight, airframe, fault_thresholds)
        findings, rejected = set_aside_answering(ctx, findings, faults)
        if rejected:
            fault_summary["coefficient_stuck_rejected"] = rejected
        findings = merge_faults(findings, faults)
    for f in findings:
        f.pop("accepted", None)
    # faults seen in the telemetry first (by onset), then the causes by held-out gain
    findings.sort(key=lambda d: (d.get("kind") != "fault", d.get("onset_s", 0.0) if d.get("kind") == "fault"
                                 else -d["gain"].get("percent", 0.0)))
    P = proj if proj is not None else (lambda D: D)
    unexplained = unexplained_report(ctx, P(R), threshold_pct=unexplained_threshold_pct)
    say("diagnose: residual GP (where structure remains)")
    t_gp = time.perf_counter()
    residual_gp = residual_structure(ctx, P(R), threshold_pct=unexplained_threshold_pct)
    for u in unexplained:
        if u["coefficient"] in residual_gp:
            u["gp"] = residual_gp[u["coefficient"]]
    gp_s = time.perf_counter() - t_gp
    separation = []
    for fd in findings:
        if not fd["evidence"]["separable"]:
            separation.append(f"{fd['cause']} cannot be told apart from "
                              + ", ".join(r["cause"] for r in fd["evidence"]["rivals"][:2])
                              + " on these data; fly: " + "; ".join(fd["evidence"]["separate_by"]))
    for u in ("delta_e", "delta_a", "delta_r"):
        if np.std(ctx.x(u)[ctx.valid]) < np.radians(0.5):
            separation.append(f"{u} barely moves (std below 0.5 deg): causes that act through it (its derivatives, "
                              f"delay:{u}, stuck:{u}) cannot be seen; fly: {maneuver_for('delay:' + u)}")
    if not findings and any(u["above_threshold"] or u.get("gp", {}).get("structured") for u in unexplained):
        separation.append("the residual is structured but no single catalogue cause explains it on held-out "
                          "data; see 'unexplained' for where it lives")
    data = {
        "n_rows": int(len(ctx.t)), "n_valid": int(ctx.valid.sum()), "n_train": int(ctx.train.sum()),
        "n_held_out": int(ctx.test.sum()),
        "t_range_s": [float(ctx.t[ctx.valid][0]), float(ctx.t[ctx.valid][-1])],
        "rate_hz": float(1.0 / np.median(np.diff(ctx.t))),
        "held_out": "interleaved blocks" if train is None else "given",
        "equation_error": _eq_error(P(R0), P(R), ctx.test),
        "equation_error_raw": _eq_error(R0, R, ctx.test),
        "turbulence": proj.summary() if proj is not None else {"active": False},
        "candidate_rounds": rounds,
        "thresholds": {"min_score": min_score, "min_gain_pct": min_gain_pct, "min_gain_oe_pct": min_gain_oe_pct,
                       "unexplained_threshold_pct": unexplained_threshold_pct},
        "separation": separation,
        "notes": list(ctx.notes) + list(getattr(table, "notes", [])),
        "timings": {"diagnose_s": float(time.perf_counter() - t0), "residual_gp_s": float(gp_s)},
    }
    if fault_summary is not None:
        data["faults"] = fault_summary
    from .sparse import THRESHOLDS as _SPARSE_TH

    th = dict(_SPARSE_TH, **(sparse_thresholds or {}))   # the search's and the differential step's, this call
    search_residual = None
    if search:
        from .search import search_residual as _search_wide

        say("diagnose: searching the wide candidate library")
        t1 = time.perf_counter()
        data["search"] = _search_wide(ctx, R)
        from .sparse import merge_findings, reference_context, sparse_search

        if search_reference is None and references:   # the first reference flight makes the search differential
            search_reference = (references[0].table, references[0].states)
        keep_rd = bool(th["allowance_on_search_residual"]) or bool(th["angle_error_beside_named"])
        from .uncertainty import air_data_uncertainty

        data["sparse"] = sparse_search(ctx, R0, reference_context(search_reference, airframe, model0),
                                       thresholds=th, keep_residual=keep_rd,
                                       angle_uncertainty=air_data_uncertainty(
                                           getattr(states, "angle_fits", None),
                                           getattr(search_reference[1], "angle_fits", None)
                                           if isinstance(search_reference, tuple) else None,
                                           pair_scale=str(th["coverage_scale_pair"])),
                                       model=model0, angle_sigma=_angle_sigma(states, ctx.t))
        search_residual = data["sparse"].pop("residual", None) if data["sparse"].get("differential") else None
        data["sparse"].pop("residual", None)
        data["sparse"].pop("rows", None)
        data["sparse"].pop("scale_columns", None)     # an array kept with the residual (not JSON)
        inadequacy = data["sparse"].pop("inadequacy_prediction", None)
        findings[:] = merge_findings(findings, data["sparse"])
        data["timings"]["search_s"] = float(time.perf_counter() - t1)
    else:
        inadequacy = None
    if calibration:
        data["calibration"] = calibration
    if pitot is not None:
        findings[:] = with_pitot(findings, pitot, data)
    if inadequacy is not None and DIFFERENTIAL_GAIN:
        _differential_gains(ctx, R0, proj, inadequacy, accepted, pitot, findings)
    if compat:
        data["sensor_candidates"] = [{"cause": c["cause"], "estimate": c["estimate"], "score": c["score"],
                                      "gain_percent": c["gain"]["percent"]} for c in compat]
    if wind_info is not None:
        data["wind_candidate"] = {k: v for k, v in wind_info.items() if k != "finding"}
    diag = Diagnosis(findings, unexplained, data, model0, ext, ctx.t, ctx.X, R0, R, ctx.train, ctx.test, accepted)
    if oe_states is not None:
        from .output_error import output_error_gain

        say("diagnose: output error before / after")
        t1 = time.perf_counter()
        diag.output_error = output_error_gain(diag, oe_states, airframe)
        data["output_error"] = {k: v for k, v in diag.output_error.items() if k != "windows_plot"}
        data["timings"]["output_error_s"] = float(time.perf_counter() - t1)
    if references:
        from .air_roll import unlike_targets
        from .differential import DifferentialOptions, differential

        # a coefficient whose target was moved on one side only witnesses no air angle's scale (air_roll.moved_targets)
        unlike = unlike_targets(table, references)

        say("diagnose: differential against the reference flight(s)")
        t1 = time.perf_counter()
        data["differential"] = differential(diag, list(references), airframe,
                                            threshold_pct=unexplained_threshold_pct,
                                            search_residual=search_residual, angle_witness_exclude=unlike,
                                            options=DifferentialOptions.from_thresholds(th))
        diag.model_inadequacy = data["differential"]["model_inadequacy"]
        data["timings"]["differential_s"] = float(time.perf_counter() - t1)
    data["timings"]["diagnose_s"] = float(time.perf_counter() - t0)
    return diag


def _faults_only(ctx: DiagContext, model, flight, airframe, thresholds, min_rows: int, t0: float) -> Diagnosis:
    """Partial diagnosis when the coefficient table is too short: the telemetry faults only."""
    faults, summary = detect_faults(flight, airframe, thresholds)
    why = (f"not run: {int(ctx.valid.sum())} valid rows ({int(ctx.train.sum())} training, {int(ctx.test.sum())} "
           f"held out); need at least {min_rows} (about {min_rows / 50:.0f} s at 50 Hz of flight with excitation)")
    tv = ctx.t[ctx.valid] if ctx.valid.any() else ctx.t
    data = {"n_rows": int(len(ctx.t)), "n_valid": int(ctx.valid.sum()), "n_train": int(ctx.train.sum()),
            "n_held_out": int(ctx.test.sum()), "t_range_s": [float(tv[0]), float(tv[-1])] if len(tv) else [0.0, 0.0],
            "rate_hz": float(1.0 / np.median(np.diff(ctx.t))) if len(ctx.t) > 1 else 0.0,
            "coefficient_diagnosis": why, "faults": summary, "separation": [], "notes": list(ctx.notes),
            "timings": {"diagnose_s": float(time.perf_counter() - t0)}}
    m0 = {c: dict(v) for c, v in model_as_dict(model).items()}
    z = np.zeros((0, 6))
    return Diagnosis(faults, [], data, m0, {c: dict(v) for c, v in m0.items()}, ctx.t[:0], ctx.X[:0], z, z,
                     ctx.train[:0], ctx.test[:0])


SENSOR_CAUSES = ("bias:airspeed", "scale:airspeed", "bias:alpha", "bias:beta", "bias:gyro_x", "bias:gyro_y",
                 "bias:gyro_z", "bias:accel_x", "bias:accel_y", "bias:accel_z")


def _compat_findings(ctx: DiagContext, flight, states, airframe, min_score: float, min_gain_pct: float,
                     gust=None, references=None) -> list[dict]:
    """Sensor causes by data compatibility, each marked ``accepted`` when it passes the gates of
    :func:`gcs_sysid.diagnose.compat.judge` (three-way split, honest standard errors, differential
    against the reference flights that carry their decoded flight)."""
    from .compat import compatibility_candidates, judge
    from .physical import split_held_out

    acc, gain = split_held_out(ctx.t, ctx.test)
    t = np.asarray(states.t, float)
    if len(t) == len(ctx.t) and np.allclose(t, ctx.t):
        tr, te, g = ctx.train, acc, gain
    else:
        tr, te, g = (np.interp(t, ctx.t, m.astype(float)) > 0.5 for m in (ctx.train, acc, gain))
        gust = {k: np.interp(t, ctx.t, v) for k, v in gust.items()} if gust else None
    cands = compatibility_candidates(flight, states, airframe, tr, te, gust, gain_rows=g)
    ref_cands = []
    for ref in references or ():
        if getattr(ref, "flight", None) is None or getattr(ref, "states", None) is None:
            continue
        allr = np.isfinite(np.asarray(ref.states.t, float))
        ref_cands.append((ref.label, compatibility_candidates(ref.flight, ref.states, airframe, allr, allr,
                                                              floors=False)))
    judge(cands, ref_cands, min_score, min_gain_pct)
    for c in cands:
        if not c["evidence"]["separable"]:
            c["evidence"]["separate_by"] = [maneuver_for(c["cause"])]
    return cands


def _wind_finding(ctx: DiagContext, states, airframe, min_score: float, min_gain_pct: float) -> dict | None:
    """Score the output-error ``wind`` cause; a finding dict when it passes the same tests as the others."""
    from types import SimpleNamespace

    from ..sim.model_file import AeroModel
    from .output_error import wind_candidate

    if not all(k in states for k in ("wn", "we", "u", "v", "w", "alt")):
        return None
    wc = wind_candidate(SimpleNamespace(t=ctx.t, train=ctx.train, test=ctx.test), states, airframe,
                        AeroModel(ctx.model, "model"))
    if wc is None:
        return None
    main = max(wc["gains"], key=lambda k: wc["gains"][k]["percent"])
    ok = (wc["score"] >= min_score and wc["gains"][main]["percent"] >= min_gain_pct
          and wc["estimate"] > max(3 * wc["std_error"], 0.5))
    wc["accepted"] = bool(ok)
    if ok:
        wc["finding"] = {"cause": "wind", "coefficient": main, "estimate": wc["estimate"], "std_error": wc["std_error"],
                         "evidence": {"domain": "output error (simulation without wind vs measured states)",
                                      "score": wc["score"], "wind_ned_mps": wc["wind_ned"], "wind_ned": wc["wind_ned"],
                                      "from_deg": wc["from_deg"], "gain_by_state": wc["gains"],
                                      "separable": True, "rivals": []},
                         "gain": dict(wc["gains"][main])}
    return wc

