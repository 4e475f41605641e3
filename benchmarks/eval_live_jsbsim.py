"""Score the live learner's GP against JSBSim's exact truth, per GP noise and GP seed (issue 8's counts).

For each JSBSim flight (``benchmarks.jsbsim_harness``, as ``eval_jsbsim.py``; flown or reused in ``--work``):

1. the flight's tlog is streamed through :class:`gcs_sysid.live.Learner` (the live session's schedule:
   ``LearnOptions()``, 30 s windows every 10 s, 3 s lag) once, recording what each step hands to the GP
   (the window's coefficient table, its new rows, its identifiability);
2. for every ``--gp-noise`` x ``--gp-seeds`` a fresh learner's own ``_learn`` is fed those steps with the rows
   after the replay's held-out cut removed (the last 20 % of the valid flight time,
   :func:`gcs_sysid.pipeline.held_out_mask`): the model a live session stopped at the cut ends with (first fit on
   ``min_rows`` rows, then ``model.update``; light hyperparameter refreshes every ``hyper_every`` rows);
3. it is scored on the held-out rows of the whole-flight table (``estimate_states`` + ``compute_coefficients``,
   the replay's estimation) as ``eval_jsbsim`` scores the replay: ``gp`` (at the estimated regressors, % of the
   truth's RMS), ``true_air`` (at the true regressors with the rates JSBSim's aerodynamics reads), ``cov_gp``
   (the coefficient's band at the estimated regressors, without the white noise), ``cov_true_air``, ``max_corr``
   (the largest learned output correlation, ``model.output_correlation()``) and ``ls`` (``run_fit`` on the
   training window, once per flight); ``gp_win`` (sixty-sixth session) asks the model at the held-out rows as the
   learner's own windows estimated them (:func:`held_rows_of_windows`; ``n_heldout_win`` rows): each window is
   estimated on its own, so ``gp`` at the whole-flight table's regressors mixes the two estimators' levels.

``--air-roll off on`` runs each noise x GP seed without and with the learner's air-rate pair (``LearnOptions.air_roll``;
thirty-first session, live-pair31; the learner's default and this script's since the sixty-sixth session): rows with
the pair add the learner's ``air_roll`` status, ``gp_air_cl`` (the held-out Cl
asked at ``p_hat - p_hat_g``, ``heldout_air_roll`` ``"predicted:Cl"`` with the learner's own roll fit: the replay's
question, post hoc), ``ls_air_cl`` (least squares asked there too) and ``cov_gp_air_cl`` (Cl's band there).

``--lift-line off on`` (sixty-seventh session) records the windows twice, without and with the lift line carried
across them (``LearnOptions.lift_line``: it changes the windows' estimates), and the learner with it plays the session's
end (:meth:`Learner.relevel`); rows add ``lift_line``, ``lift_line_status`` and ``alpha_levels_deg`` (each window's
mean alpha error against JSBSim's, :func:`window_levels`).

Counts (:func:`counts`; thresholds as issue 8: held-out / true-air within 5 % forces, 10 % moments; GP better than
LS; bands 90-98 %, the band at exact conditions also per coefficient, ``cov_true_air_c``; a learned output correlation
above 0.5) and flips of each variant (:func:`variant`: the noise, ``+air-roll``, ``-unstated``) against ``--base``
(``independent``) at the same seed are printed by ``--summarize`` (``--heldout-cl air``: the pair's Cl at the air-rate
question).

Usage::

    python benchmarks/eval_live_jsbsim.py --aircraft c172x sgs --seeds 1 --work DIR --json live.jsonl
    python benchmarks/eval_live_jsbsim.py --summarize live.jsonl
    python benchmarks/eval_live_jsbsim.py --aircraft c172x --gp-noise learned --air-roll off on --json pair.jsonl
    python benchmarks/eval_live_jsbsim.py --summarize pair.jsonl --base learned --heldout-cl gyro
    python benchmarks/eval_live_jsbsim.py --seeds 13 14 15 --duration 120 --gp-noise learned --stated-errors off on
    python benchmarks/eval_live_jsbsim.py --summarize stated.jsonl --base learned-unstated   # after --json stated.jsonl
    python benchmarks/eval_live_jsbsim.py --seeds 22 --duration 120 --gp-noise learned --lift-line off on --json l.jsonl
    python benchmarks/eval_live_jsbsim.py --summarize l.jsonl --base learned+air-roll --heldout-cl gyro
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.eval_common import (append_jsonl, false_couplings, pair_correlations,  # noqa: E402
                                    truth_residual_correlation)
from benchmarks.eval_jsbsim import _coverage, _errs, aero_reads_air_rates  # noqa: E402
from benchmarks.jsbsim_harness import UNTOUCHED_AIRCRAFT, FlightConfig, load_truth, make_flight  # noqa: E402
from benchmarks.jsbsim_harness.aircraft import aircraft_argument  # noqa: E402
from gcs_sysid.aero.table import COEFFICIENTS, REGRESSORS  # noqa: E402

FORCES = ("CX", "CY", "CZ")


def _pair_states(states):
    """The part of a window's states the air-rate pair, the stated errors' pool and the lift line's pool read
    (:data:`gcs_sysid.aero.gustfilter.AIR_ROLL_STATE_KEYS`, :data:`gcs_sysid.aero.errorpool.POOL_STATE_KEYS`;
    ``ax`` and alpha's aiding fit, :class:`gcs_sysid.aero.liftline.LiftLinePool`)."""
    from gcs_sysid.aero.errorpool import POOL_STATE_KEYS
    from gcs_sysid.aero.gustfilter import AIR_ROLL_STATE_KEYS
    from gcs_sysid.estimation.states import FlightStates

    if states is None:
        return None
    data = set(AIR_ROLL_STATE_KEYS["data"]) | set(POOL_STATE_KEYS["data"]) | {"ax"}
    sigma = set(AIR_ROLL_STATE_KEYS["sigma"]) | set(POOL_STATE_KEYS["sigma"])
    return FlightStates(states.t, states.rate_hz, {k: states.data[k] for k in sorted(data) if k in states.data},
                        {k: states.sigma[k] for k in sorted(sigma) if k in states.sigma},
                        angle_fits={k: v for k, v in states.angle_fits.items() if k == "alpha"})


def record_steps(tlog: Path, airframe, lift_line: bool = False, status: dict | None = None,
                 alpha_profile: tuple[str, ...] | None = None, air_pitch: bool = True,
                 pitch_status: dict | None = None) -> list[tuple]:
    """Stream ``tlog`` through a live :class:`Learner`; the ``(identifiable, table, rows, states, pitch)`` of every GP
    step (``states``: the part the air-rate pair reads; ``pitch``: the window's pitch gust rate ``g`` (T,) as a hat
    and the share its ``q_hat`` was moved with, and the pooled fit after it, for :meth:`Learner.pitch_relearn`; None
    with ``air_pitch`` off). ``lift_line``: the learner's carried lift line
    (``LearnOptions.lift_line``: it changes the windows' estimates, so it is recorded here, not in :func:`learn`);
    ``status``: a dict updated with the recorder's ``lift_line`` status at the end; ``alpha_profile``:
    ``LearnOptions.alpha_profile`` (the windows' estimates too); ``air_pitch``: ``LearnOptions.air_pitch`` (the windows'
    ``q_hat``), with the recorder's ``air_pitch`` status put into ``pitch_status``."""
    from gcs_sysid.live.learner import Learner, LearnOptions, iter_tlog_records

    steps: list[tuple] = []
    rec = Learner(airframe, LearnOptions(air_roll=False, lift_line=lift_line,   # records each step; learns nothing
                                         alpha_profile=alpha_profile, air_pitch=air_pitch))
    rec._learn = lambda table, rows, states=None: steps.append((dict(rec.identifiable), table, rows.copy(),
                                                                _pair_states(states), _pitch_of(rec)))   # no GP here
    for stamp, packet in iter_tlog_records(tlog):
        rec.feed(stamp, packet)
    rec.finish()
    if status is not None:
        status.update(rec.lift_line)
    if pitch_status is not None:
        pitch_status.update(rec.air_pitch)
    return steps


def _pitch_of(rec) -> dict | None:
    """The recorder's current window's pitch gust rate, the share applied to it and the pooled fit after it."""
    if rec._pitch_pool is None or rec._pitch_window is None:
        return None
    g, kappa = rec._pitch_window
    fit = rec._pitch_pool.fit()
    return {"g": g, "kappa": kappa,
            "fit": {"applied": bool(fit["applied"]), "kappa": float(fit["kappa"]), "windows": int(fit["windows"])}}


def held_rows_of_windows(steps: list[tuple], t_cut: float) -> tuple[np.ndarray, np.ndarray]:
    """The held-out rows (vehicle time at or after ``t_cut``, s) as the live learner's windows estimated them: each
    step's new valid rows with finite regressors, ``(X (N, 10), t (N,))`` in time order (each row is new in one step).
    The model asked there is asked at its own estimator's regressors, as a live session would ask it of the rows it
    has not learned yet; the whole-flight table's ``gp`` asks it at the replay's."""
    Xs, ts = [], []
    for _, table, rows, _, _ in steps:
        sel = rows & np.asarray(table.valid, bool) & (table.t >= t_cut) & np.all(np.isfinite(table.X), axis=1)
        Xs.append(table.X[sel])
        ts.append(table.t[sel])
    if not Xs:
        return np.zeros((0, len(REGRESSORS))), np.zeros(0)
    X, t = np.concatenate(Xs), np.concatenate(ts)
    order = np.argsort(t, kind="stable")
    return X[order], t[order]


def learn(steps: list[tuple], airframe, t_cut: float, gp_noise: str, gp_seed: int, air_roll: bool = True,
          stated_errors: bool = True, lift_line: bool = False, pitch_relearn: bool = False):
    """The learner fed ``steps`` up to vehicle time ``t_cut`` (s) and its CPU s (its ``model``, ``outputs``,
    ``n_learned``, ``air_roll``, ``errors``, ``lift_line``, ``air_pitch``). With ``lift_line`` (steps recorded with
    it, :func:`record_steps`) the session's end is played too: its rows moved onto the windows' line and learned
    again (:meth:`Learner.relevel`, what the final step of a session does). With ``pitch_relearn`` (steps recorded
    with ``air_pitch``) the end first moves the rows to the pooled pitch gust share as it stood after the last
    window with training rows and learns again (:meth:`Learner.pitch_relearn`)."""
    from gcs_sysid.live.learner import Learner, LearnOptions

    lr = Learner(airframe, LearnOptions(gp_noise=gp_noise, gp_seed=gp_seed, air_roll=air_roll,
                                        stated_errors=stated_errors, lift_line=lift_line,
                                        air_pitch_relearn=pitch_relearn))
    t0 = time.process_time()
    last_fit = None
    for k, (ident, table, rows, states, pitch) in enumerate(steps):
        lr.steps, lr.identifiable = k + 1, ident
        train = rows & (table.t < t_cut)
        lr._pitch_window = None if pitch is None or pitch["g"] is None else (pitch["g"], pitch["kappa"])
        if pitch is not None and train.any():
            last_fit = pitch["fit"]
        lr._window_in(table, train, states)
        lr._learn(table, train, states)
    if pitch_relearn:
        if last_fit is None:
            raise SystemExit("--pitch-relearn on needs steps recorded with --air-pitch on")
        lr.pitch_relearn(last_fit)
    if lift_line:
        lr.relevel()
    return lr, time.process_time() - t0


def window_levels(steps: list[tuple], truth) -> list[float]:
    """Each step's mean alpha error against JSBSim's over the rows it hands over, deg (NaN-free steps only): the
    window's alpha level (the carried lift line's question)."""
    out = []
    for _, table, rows, _, _ in steps:
        sel = rows & np.asarray(table.valid, bool) & np.isfinite(table.X[:, 0])
        if sel.any():
            e = table.X[sel, 0] - truth.at(table.t[sel])[0][:, 0]
            if np.isfinite(e).any():
                out.append(float(np.degrees(np.nanmean(e))))
    return out


def evaluate(aircraft: str, seed: int, turbulence: str, duration: float, work: Path, noises, gp_seeds,
             air_rolls=(True,), stated=(True,), lift_lines=(False,), alpha_profile: bool = False,
             air_pitch: bool = True, pitch_relearns=(False,)) -> list[dict]:
    """One flight's rows (one per noise x GP seed x air-rate pair off/on x stated errors off/on x lift line off/on),
    JSON-able.

    ``lift_lines``: ``LearnOptions.lift_line`` values (the windows' lift line carried across them; each value records
    its own steps, :func:`record_steps`); each row says its own in ``lift_line`` with the learner's status in
    ``lift_line_status`` and its windows' alpha levels against the truth in ``alpha_levels_deg``
    (:func:`window_levels`). ``alpha_profile``: the learner's windows with ``LearnOptions.alpha_profile =
    ("delta_e",)`` (the whole-flight estimate and the LS reference keep least squares); rows say it in
    ``alpha_profile``. ``air_pitch``: the learner's windows with ``LearnOptions.air_pitch`` (each window's ``q_hat`` at
    the air-relative estimate where the windows' pooled fit shows the pitch gust's share; the learner's default since
    the sixty-ninth session) and the whole-flight table's too (the
    replay's ``air_pitch`` on its training rows: the held-out question ``gp`` asks at the same kind of ``q_hat``; the
    least-squares line is fitted at that kind too since the sixty-ninth session, ``run_fit(air_pitch=)``, at the
    gyro's before); rows say it in ``air_pitch`` with the recorder's status in ``air_pitch_status``.

    ``stated``: ``LearnOptions.stated_errors`` values to run (the windows' pooled regressor errors in the model's
    band at exact conditions, ``cov_true_air``); each row says its own in ``stated_errors``.

    With the pair on (``LearnOptions.air_roll``) the row also has ``gp_air_cl``: ``gp`` with Cl asked at the
    held-out rows' ``p_hat - p_hat_g`` (``heldout_air_roll`` ``"predicted:Cl"`` with the learner's own roll fit: the
    replay's held-out question; a post hoc line, the live learner asks nowhere at the air rate), and
    ``air_roll`` the learner's status."""
    from gcs_sysid.aero import compute_coefficients
    from gcs_sysid.airframe import load_airframe
    from gcs_sysid.diagnose import run_fit
    from gcs_sysid.estimation import airangles, estimate_states
    from gcs_sysid.pipeline import held_out_mask
    from gcs_sysid.telemetry import read_log

    if aircraft in UNTOUCHED_AIRCRAFT:
        raise SystemExit(f"{aircraft} is the untouched aircraft")
    files = make_flight(FlightConfig(aircraft, duration_s=duration, turbulence=turbulence, seed=seed), work,
                        reuse=True)
    truth = load_truth(files.truth)
    af = load_airframe(files.airframe)
    states_all = estimate_states(read_log(files.tlog), af)
    tab = compute_coefficients(states_all, af)
    held = held_out_mask(tab.t, tab.valid, 0.2)
    t_cut = float(tab.t[held][0])
    if air_pitch:                 # the whole-flight table as the replay's --air-pitch makes it
        from gcs_sysid.aero.airpitch import apply_air_pitch

        tab = apply_air_pitch(tab, states_all, af, tab.valid & ~held)[0]
    Xt, Yt = truth.at(tab.t)
    Xt_air = Xt.copy()
    cst = truth.meta["constants"]
    for j, (ax, ref) in enumerate(zip("pqr", ("b", "c", "b"))):
        if aero_reads_air_rates(aircraft)[ax]:
            Xt_air[:, 2 + j] = np.interp(tab.t, truth.t, truth.fields[f"{ax}_aero"]) * cst[ref] / (2 * Xt[:, 9])
    h = held & tab.valid & np.isfinite(Yt).all(1) & np.all(np.isfinite(tab.X), axis=1)
    truth_corr = truth_residual_correlation(Xt_air, Yt, tab.valid & ~held)
    ls_model, _ = run_fit(files.tlog, files.airframe, work / f"{files.tlog.stem}-livefit.toml", t_to=t_cut,
                          profile_beta=airangles.BETA_PROFILE,      # the learner's sideslip estimator
                          air_roll_train=False,     # the measured Cl (not the diagnosis's reference target)
                          air_pitch=air_pitch)      # the whole-flight table's kind of q_hat (sixty-ninth session)
    ls = _errs(ls_model.evaluate(tab.X[h]), Yt[h])
    out = []
    for ll in lift_lines:
        out += _evaluate_steps(aircraft, seed, turbulence, duration, files, truth, af, states_all, tab, held, t_cut,
                               Xt_air, h, ls_model, ls, noises, gp_seeds, air_rolls, stated, ll, alpha_profile,
                               air_pitch, truth_corr, pitch_relearns)
    return out


def _evaluate_steps(aircraft, seed, turbulence, duration, files, truth, af, states_all, tab, held, t_cut, Xt_air, h,
                    ls_model, ls, noises, gp_seeds, air_rolls, stated, ll, alpha_profile=False,
                    air_pitch=True, truth_corr=None, pitch_relearns=(False,)) -> list[dict]:
    """:func:`evaluate`'s rows of one ``lift_line`` value ``ll``."""
    Yt = truth.at(tab.t)[1]
    t0 = time.perf_counter()
    status: dict = {}
    pitch_status: dict = {}
    steps = record_steps(files.tlog, af, lift_line=ll, status=status,
                         alpha_profile=("delta_e",) if alpha_profile else None, air_pitch=air_pitch,
                         pitch_status=pitch_status)
    t_rec = time.perf_counter() - t0
    levels = window_levels(steps, truth)
    Xw, tw = held_rows_of_windows(steps, t_cut)
    Ytw = truth.at(tw)[1]
    okw = np.isfinite(Ytw).all(1)
    Xw, Ytw = Xw[okw], Ytw[okw]
    out = []
    for noise, gs, pair, se, pr in ((n, g, p, s, r) for n in noises for g in gp_seeds for p in air_rolls
                                    for s in stated for r in pitch_relearns):
        lr, cpu = learn(steps, af, t_cut, noise, gs, pair, se, ll, pr)
        model, outputs, n_learned = lr.model, lr.outputs, lr.n_learned
        cols = [COEFFICIENTS.index(c) for c in outputs]
        mean = np.full((int(h.sum()), 6), np.nan)
        sig, mta, sta = mean.copy(), mean.copy(), mean.copy()
        xv = None if tab.x_var is None else tab.x_var[h]
        m, v = model.predict(tab.X[h], x_var=xv)
        white = model.noise_var(white_noise=True) - model.noise_var(white_noise=False)
        mean[:, cols] = np.asarray(m)
        sig[:, cols] = np.sqrt(np.maximum(np.asarray(v) - white[None, :], 0.0))
        mean_w = np.full(Ytw.shape, np.nan)
        if len(Xw):
            mean_w[:, cols] = np.asarray(model.predict(Xw)[0])
        ma, va = model.predict(Xt_air[h], include_noise=False, input_noise=False)
        mta[:, cols], sta[:, cols] = np.asarray(ma), np.sqrt(np.asarray(va))
        C = np.abs(np.asarray(model.output_correlation(), float))
        np.fill_diagonal(C, 0.0)
        row = {"aircraft": aircraft, "seed": seed, "turbulence": turbulence, "duration_s": duration,
               "gp_noise": noise, "gp_seed": gs, "outputs": list(outputs), "n_learned": int(n_learned),
               "n_heldout": int(h.sum()), "t_record_s": round(t_rec, 1),
               "cpu_learn_s": round(cpu, 2), "noise_correlation": bool(model.config.noise_correlation),
               "gp": _errs(mean, Yt[h]), "true_air": _errs(mta, Yt[h]), "ls": ls,
               "gp_win": _errs(mean_w, Ytw) if len(Xw) else None, "n_heldout_win": int(len(Xw)),
               "cov_gp_each": [_coverage(mean[:, i], sig[:, i], Yt[h, i]) for i in range(6)],
               "cov_true_air_each": [_coverage(mta[:, i], sta[:, i], Yt[h, i]) for i in range(6)],
               "max_corr": float(np.nanmax(C)) if C.size else 0.0, "notes": list(model.notes)[-3:],
               "air_roll": dict(lr.air_roll) if pair else None, "stated_errors": bool(se),
               "errors_note": lr.errors.get("note", ""), "lift_line": bool(ll),
               "lift_line_status": {**status, **{k: v for k, v in lr.lift_line.items() if k != "note"}},
               "alpha_levels_deg": [round(x, 3) for x in levels], "alpha_profile": bool(alpha_profile),
               "air_pitch": bool(air_pitch), "air_pitch_status": {k: v for k, v in pitch_status.items() if k != "note"},
               "pitch_relearn": bool(pr), "pitch_relearn_info": lr.air_pitch.get("relearn"),
               "corr_pairs": pair_correlations(C, outputs),
               "truth_resid_corr": truth_corr}
        if pair:
            row["gp_air_cl"], row["ls_air_cl"] = dict(row["gp"]), dict(ls)
            if lr._roll_fit is not None and "Cl" in outputs:   # Cl asked at the held-out air rate, post hoc
                from gcs_sysid.aero.gustfilter import heldout_air_roll

                train = tab.valid & (tab.t < t_cut)
                tab_air, info = heldout_air_roll(tab, states_all, af, train, held, mode="predicted:Cl",
                                                 fit=lr._roll_fit)
                if info is not None:
                    xva = None if tab_air.x_var is None else tab_air.x_var[h]
                    mc, vc = model.predict(tab_air.X[h], x_var=xva)
                    i, k = COEFFICIENTS.index("Cl"), outputs.index("Cl")
                    mean_a = mean.copy()
                    mean_a[:, i] = np.asarray(mc)[:, k]
                    row["gp_air_cl"] = _errs(mean_a, Yt[h])
                    row["cov_gp_air_cl"] = _coverage(mean_a[:, i], np.sqrt(np.maximum(np.asarray(vc)[:, k] - white[k],
                                                                                      0.0)), Yt[h, i])
                    ls_a = np.array(ls_model.evaluate(tab.X[h]), float)
                    ls_a[:, i] = ls_model.evaluate(tab_air.X[h])[:, i]      # LS asked at the same held-out rate
                    row["ls_air_cl"] = _errs(ls_a, Yt[h])
        row["cov_gp"] = float(np.nanmean(row["cov_gp_each"]))
        row["cov_true_air"] = float(np.nanmean(row["cov_true_air_each"]))
        out.append(row)
        print(f"{aircraft} {turbulence} s{seed} {noise} gs{gs} pair {'on' if pair else 'off'} "
              f"stated {'on' if se else 'off'} line {'on' if ll else 'off'} relearn {'on' if pr else 'off'}: gp " +
              " ".join(f"{c} {row['gp'][c]:.1f}" for c in COEFFICIENTS) +
              f" | cov {row['cov_gp']:.1f} / {row['cov_true_air']:.1f} corr {row['max_corr']:.2f} "
              f"cpu {cpu:.1f} s" + (f" | pair {lr.air_roll['state']}, Cl at the air rate "
                                     f"{row['gp_air_cl']['Cl']:.1f}" if pair else ""), flush=True)
    return out


def variant(row: dict) -> str:
    """A row's learner variant: its GP noise, ``+air-roll`` with the air-rate pair on, ``-unstated`` without the
    stated regressor errors (``LearnOptions.stated_errors`` False; rows written before the sixty-fifth session had
    none and carry no such field), ``+lift-line`` with the windows' lift line carried (``LearnOptions.lift_line``),
    ``+alpha-profile`` with ``LearnOptions.alpha_profile``, ``+air-pitch`` with ``LearnOptions.air_pitch``."""
    return (row["gp_noise"] + ("+air-roll" if row.get("air_roll") else "")
            + ("-unstated" if row.get("stated_errors") is False else "")
            + ("+lift-line" if row.get("lift_line") else "") + ("+alpha-profile" if row.get("alpha_profile") else "")
            + ("+air-pitch" if row.get("air_pitch") else "") + ("+pitch-relearn" if row.get("pitch_relearn") else ""))


def counts(row: dict, heldout_cl: str = "gyro") -> dict[str, int]:
    """Issue 8's counts of one row: coefficients within / better than LS, bands in 90-98 %, correlation flags.

    ``no_corr``: no learned output correlation above 0.5; ``no_false_corr``: none above 0.5 where JSBSim's residual
    correlation is below 0.3 (issue 8's line as written, :func:`benchmarks.eval_common.false_couplings`; a row
    written before ``corr_pairs`` existed reads ``no_corr``). :func:`summarize` tables both and counts flips on
    ``no_false_corr`` only (since the sixty-ninth session), as ``issue8_counts.py`` does.

    ``heldout_cl="air"``: a row with the air-rate pair on has its held-out Cl asked at the reconstructed air rate
    (``gp_air_cl``), as the replay asks it, and so has its LS line (``ls_air_cl``: least squares on the measured Cl
    asked at the same held-out rate); ``"gyro"``: at the gyro's rate, as the learner's model is asked."""
    if heldout_cl == "air" and row.get("gp_air_cl") is not None:
        row = {**row, "gp": row["gp_air_cl"], "ls": row.get("ls_air_cl", row["ls"])}
        if row.get("cov_gp_air_cl") is not None:        # Cl's band at the same question
            each = list(row["cov_gp_each"])
            each[COEFFICIENTS.index("Cl")] = row["cov_gp_air_cl"]
            row["cov_gp"] = float(np.nanmean(each))
    th = {c: 5.0 if c in FORCES else 10.0 for c in COEFFICIENTS}
    fc = false_couplings(row.get("corr_pairs"), row.get("truth_resid_corr"))
    fin = lambda d, c: d.get(c) is not None and np.isfinite(d[c])  # noqa: E731
    return {"gp_within": sum(fin(row["gp"], c) and row["gp"][c] <= th[c] for c in COEFFICIENTS),
            "true_within": sum(fin(row["true_air"], c) and row["true_air"][c] <= th[c] for c in COEFFICIENTS),
            "gp_lt_ls": sum(fin(row["gp"], c) and fin(row["ls"], c) and row["gp"][c] < row["ls"][c]
                            for c in COEFFICIENTS),
            "cov_gp": int(90.0 <= row["cov_gp"] <= 98.0),
            "cov_true_air": int(90.0 <= row["cov_true_air"] <= 98.0),
            "cov_true_air_c": sum(int(90.0 <= x <= 98.0) for x in row["cov_true_air_each"]
                                  if x is not None and np.isfinite(x)),
            "no_corr": int(row["max_corr"] <= 0.5),
            "no_false_corr": int(not fc) if fc is not None else int(row["max_corr"] <= 0.5)}


def summarize(paths: list[str], base: str = "independent", heldout_cl: str = "gyro") -> str:
    """Totals per variant (:func:`variant`) and GP seed, flips against ``base`` at the same seed, aircraft losing a
    count (:func:`counts` with ``heldout_cl``)."""
    rows = [json.loads(line) for p in paths for line in Path(p).read_text().splitlines() if line.strip()]
    key = lambda r: (r["aircraft"], r["turbulence"], r["seed"])  # noqa: E731
    by = {(key(r), variant(r), r["gp_seed"]): r for r in rows}
    cnt = lambda r: counts(r, heldout_cl)  # noqa: E731
    noises = sorted({variant(r) for r in rows})
    gseeds = sorted({r["gp_seed"] for r in rows})
    flights = sorted({key(r) for r in rows})
    lines = [f"{len(flights)} flights; noises {noises}; GP seeds {gseeds}", ""]
    items = list(cnt(rows[0]))
    judged = [i for i in items if i != "no_corr"]        # tabled, not flipped: no_false_corr reads the issue's line
    lines.append("| noise, GP seed | " + " | ".join(items) + " | median gp F / M % | median cpu s |")
    lines.append("|---" * (len(items) + 3) + "|")
    for n in noises:
        for s in gseeds:
            rs = [by[(f, n, s)] for f in flights if (f, n, s) in by]
            tot = {i: sum(cnt(r)[i] for r in rs) for i in items}
            gf = np.nanmedian([r["gp"][c] for r in rs for c in FORCES])
            gm = np.nanmedian([r["gp"][c] for r in rs for c in COEFFICIENTS if c not in FORCES])
            cpu = np.median([r["cpu_learn_s"] for r in rs])
            lines.append(f"| {n}, {s} | " + " | ".join(str(tot[i]) for i in items)
                         + f" | {gf:.2f} / {gm:.2f} | {cpu:.1f} |")
    lines += ["", "The band at exact conditions per coefficient: pooled coverage % (flights below 90 / within 90-98 / "
              "above 98 %)", "", "| noise, GP seed | " + " | ".join(COEFFICIENTS) + " |",
              "|---" * (len(COEFFICIENTS) + 1) + "|"]
    for n in noises:
        for s in gseeds:
            rs = [by[(f, n, s)] for f in flights if (f, n, s) in by]
            cells = []
            for i in range(len(COEFFICIENTS)):
                v = [(r["cov_true_air_each"][i], r["n_heldout"]) for r in rs
                     if r["cov_true_air_each"][i] is not None and np.isfinite(r["cov_true_air_each"][i])]
                pooled = sum(c * w for c, w in v) / max(sum(w for _, w in v), 1)
                cells.append(f"{pooled:.1f} ({sum(c < 90 for c, _ in v)}/{sum(90 <= c <= 98 for c, _ in v)}/"
                             f"{sum(c > 98 for c, _ in v)})")
            lines.append(f"| {n}, {s} | " + " | ".join(cells) + " |")
    lines.append("")
    lose_any: dict[str, dict[int, set]] = {}
    for n in noises:
        if n == base:
            continue
        for s in gseeds:
            win = loss = 0
            lost: dict[str, list[str]] = {}
            for f in flights:
                if (f, n, s) not in by or (f, base, s) not in by:
                    continue
                a, b = cnt(by[(f, n, s)]), cnt(by[(f, base, s)])
                for i in judged:
                    win += max(a[i] - b[i], 0)
                    loss += max(b[i] - a[i], 0)
                    if a[i] < b[i]:
                        lost.setdefault(f[0], []).append(f"{f[1]} s{f[2]} {i} {b[i]}->{a[i]}")
            lose_any.setdefault(n, {})[s] = set(lost)
            lines.append(f"{n} vs {base} at GP seed {s}: flips +{win} / -{loss}; aircraft losing a count: "
                         f"{len(lost)} ({'; '.join(f'{k}: ' + ', '.join(v) for k, v in sorted(lost.items()))})")
        if len(gseeds) >= 2:
            both = set.intersection(*(lose_any[n][s] for s in gseeds))
            lines.append(f"{n}: aircraft losing a count at every GP seed: {len(both)} {sorted(both)}")
    if len(gseeds) >= 2:   # the yardstick: the base merely reseeded
        s0, s1 = gseeds[:2]
        win = loss = 0
        lost = set()
        for f in flights:
            if (f, base, s0) in by and (f, base, s1) in by:
                a, b = cnt(by[(f, base, s1)]), cnt(by[(f, base, s0)])
                for i in judged:
                    win += max(a[i] - b[i], 0)
                    loss += max(b[i] - a[i], 0)
                    if a[i] < b[i]:
                        lost.add(f[0])
        lines.append(f"{base} reseeded ({s0} -> {s1}): flips +{win} / -{loss}; aircraft losing a count: {len(lost)} "
                     f"{sorted(lost)}")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--aircraft", nargs="+", default=["c172x", "sgs"], type=aircraft_argument)
    ap.add_argument("--seeds", nargs="+", type=int, default=[1])
    ap.add_argument("--turbulence", nargs="+", default=["light"])
    ap.add_argument("--duration", type=float, default=90.0)
    ap.add_argument("--gp-noise", nargs="+", default=["independent", "learned"])
    ap.add_argument("--gp-seeds", nargs="+", type=int, default=[0, 1])
    ap.add_argument("--air-roll", nargs="+", default=["on"], choices=("off", "on"),
                    help="the learner's air-rate pair (LearnOptions.air_roll, on by default since the sixty-sixth "
                         "session) off and/or on")
    ap.add_argument("--stated-errors", nargs="+", default=["on"], choices=("off", "on"),
                    help="the learner's pooled regressor errors (LearnOptions.stated_errors) off and/or on")
    ap.add_argument("--lift-line", nargs="+", default=["off"], choices=("off", "on"),
                    help="the learner's lift line carried across its windows (LearnOptions.lift_line) off and/or on")
    ap.add_argument("--alpha-profile", default="off", choices=("off", "on"),
                    help="the learner's windows with the elevator's slope by the gust likelihood (LearnOptions."
                         "alpha_profile)")
    ap.add_argument("--air-pitch", default="on", choices=("off", "on"),
                    help="the learner's windows (and the whole-flight table) with q_hat at the air-relative estimate "
                         "(LearnOptions.air_pitch; default on, as the learner's since the sixty-ninth session)")
    ap.add_argument("--pitch-relearn", nargs="+", default=["off"], choices=("off", "on"),
                    help="the learner's end with the rows moved to the final pooled pitch gust share and learned again "
                         "(LearnOptions.air_pitch_relearn) off and/or on, on the same recording")
    ap.add_argument("--base", default="independent", help="--summarize: the variant flips are counted against")
    ap.add_argument("--heldout-cl", default="gyro", choices=("gyro", "air"),
                    help="--summarize: the pair's held-out Cl at the gyro's rate or at the reconstructed air rate")
    ap.add_argument("--work", default=None)
    ap.add_argument("--json", default=None, help="append one JSON line per flight x noise x GP seed")
    ap.add_argument("--summarize", nargs="+", default=None, metavar="JSONL")
    a = ap.parse_args(argv)
    if a.summarize:
        print(summarize(a.summarize, a.base, a.heldout_cl))
        return 0
    import tempfile

    work = Path(a.work) if a.work else Path(tempfile.mkdtemp(prefix="eval-live-"))
    work.mkdir(parents=True, exist_ok=True)
    for ac in a.aircraft:
        for turb in a.turbulence:
            for seed in a.seeds:
                rows = evaluate(ac, seed, turb, a.duration, work, a.gp_noise, a.gp_seeds,
                                tuple(x == "on" for x in a.air_roll), tuple(x == "on" for x in a.stated_errors),
                                tuple(x == "on" for x in a.lift_line), a.alpha_profile == "on",
                                air_pitch=a.air_pitch == "on",
                                pitch_relearns=tuple(x == "on" for x in a.pitch_relearn))
                append_jsonl(a.json, rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
