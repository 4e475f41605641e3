"""The GP alone against JSBSim's exact truth: variants, joint vs six independent GPs, vs least squares.

``benchmarks/eval_jsbsim.py`` scores the whole replay; this script isolates the GP. It first caches,
per flight, what the replay estimated (the coefficient table: regressors ``X``, measured coefficients
``Y``, the training rows and the held-out last 20 %), the truth on the same grid and the project's
stepwise least-squares model (``gcs-sysid fit`` on the training window) evaluated on it (``--make``;
one ``.npz`` per flight under ``--cache``). Then it fits GP variants on the training rows of each
cached table (``fit_gp``, the replay's settings unless a variant says otherwise) and scores them on
the held-out rows against the truth:

  err     100 * RMS(model - truth) / RMS(truth) per coefficient, model at the measured regressors
  cov     share of the truth inside the model's 95 % band (sigma without observation noise: the truth
          has none), per coefficient, and the median over the six; ``cov_noise``: with the noise (the
          band the replay reports)
  corr    the largest |learned output correlation| of the global layer (``output_correlation``)
  true    ``err_true``, ``cov_true``: the model at the true regressors (``predict(..., include_noise=False,
          input_noise=False)``, as ``gcs-sysid predict`` at exact conditions: with the model's error there,
          ``docs/gp.md``), against the truth; ``cov_true_latent``: the latent band alone
          (``model_error=False``, the band before that term); ``cov_true_noise``: with the noise
          (``<C>_sigma_obs``); ``discrepancy_std``, ``offset_std_deg``: the term's parts

Variants (``--variants``): ``diag`` the GP with one noise variance per output (before issue 8),
``full`` with the full 6 x 6 noise covariance in the likelihood (``GPConfig.noise_correlation``),
``nigp`` = ``full`` + the input-noise variance (``docs/gp.md``, "Noisy inputs"; the shipped
default is the input noise without ``full``, for the replay's speed; with the coupling gate, on by default since
the sixteenth session), ``nigp0`` = ``nigp`` without the coupling gate (the default before), ``global`` = ``nigp``
without the local layer, ``lsres`` = ``nigp`` fitted to the residual
of the least-squares model (LS as the prior mean), ``indep`` six
independent one-output GPs (same settings, each its own hyperparameters), ``lmc`` = ``nigp`` with a
linear model of coregionalisation of two latent kernels (``GPConfig.latent_kernels = 2``: per-output
length-scales), ``lmc3`` with three, ``nigpc`` = ``nigp`` with the coloured-residual variance factor
(``GPConfig.residual_correlation``), ``dec`` = ``nigp`` with its cross-output coupling removed after the
fit (``gp.joint.decoupled``: ``B`` and the noise covariance made diagonal, every other
hyperparameter kept: what the coupling contributes to the mean), ``sel`` = per output ``nigp`` or
that output's ``indep`` GP, whichever has the lower blocked cross-validation error on the training
rows (``gp.joint.select_outputs``), ``nigpv`` = ``nigp`` with the coupling kept only for the outputs
whose blocked cross-validation error it lowers (``GPConfig.coupling_validation``), ``nigpa`` = ``nigp``
with each shared factor of ``B`` on the longitudinal or the lateral outputs only
(``GPConfig(output_groups="axes")``), ``nigpk`` = ``nigp`` with one latent kernel (own length-scales) per
axis (``GPConfig(output_groups="kernels")``), ``nigpf`` = the same with free loadings
(``"kernels-free"``), ``nigpo`` = one kernel per output (``"output-kernels"``), ``nigpr`` = ``nigp`` with
``B`` and the noise covariance learned again on every training row (``GPConfig.coupling_rows = "all"``,
twentieth session), ``nigpt`` = ``nigp`` with the signal coupling kept only for the outputs whose coupling
the bound on every training row supports by a deflated likelihood-ratio test (``GPConfig.coupling_test = "lr"``,
twenty-first session; since the twenty-second ``GPConfig``'s default, so ``nigp`` is the same), ``nigpu`` = ``nigp``
with ``B``'s couplings as learned, untested (``coupling_test = "none"``, the default until the twenty-second
session), and ``ls`` (cached).

For the joint variants each line also carries the output correlations (issue 8, "no learned
output correlation above 0.5 where the truth has none"): ``corr_learned`` (``output_correlation``),
``latent_std`` (sqrt of ``B``'s diagonal, data units), ``noise_corr`` (``noise_correlation``),
``corr_model_nl`` (the model's global mean over the training rows, its part not linear in the
regressors, correlated across outputs), ``corr_model_quad`` (the truth's statistic applied to the model's
predictions: the nonlinear part of a quadratic response surface of the global mean on the measured regressors;
the prediction correlation comparable with ``truth["signal_corr"]``; ``std_model_quad`` its std per output,
data units) and the truth's counterparts ``truth`` from
``gp.joint.truth_correlation`` on the exact regressors and coefficients of the training rows
(``signal_corr``: the nonlinear part of a quadratic response surface; ``rest_corr``: what it
leaves, the part no function of the regressors explains); matrices flattened row-major. ``flags``
lists the pairs with a learned correlation above 0.5 where the truth's is below 0.2 (``TRUTH_NONE``),
``flags_carrying`` those of them where both outputs' latent std is at least 0.1 of their noise std
(``CARRIES``). ``--diagnose`` prints, per
flight, least squares per output against seemingly-unrelated-regressions GLS (Zellner 1962).

The replay's air-rate pair (``--air-roll``, on by default since the thirtieth session, as ``gcs-sysid replay``): every
variant's Cl is trained on the replay's target (the measured Cl less the training rows' smoothed rolling-gust moment,
:func:`gcs_sysid.aero.gustfilter.air_roll_target`) and asked at the held-out rows' air-relative roll rate
(``HELDOUT_AIR_ROLL = "predicted:Cl"``), from the one roll fit ``air_roll_fit`` with its calm-air guard (refused: the
measured Cl and the gyro's rate, as the replay); ``ls`` is then ``eval_jsbsim``'s fair line ``ls_airtrain`` (Cl by the
stepwise fit on the replay's table and the same target, asked at the same rate); ``err_true`` asks Cl at JSBSim's
air-relative rates (``eval_jsbsim``'s ``true_air``, :func:`true_air_regressors`), the other outputs at the truth's
body rates as before. ``--make`` caches the pair's arrays (:func:`air_rate_arrays`); ``--air-roll off`` gives the
tables before (``aoa`` tagged ``/gyro-Cl``). The
``--missing`` models, ``--diagnose`` and ``eval_gp_joint.py`` (its own scoring) stay on the measured Cl.

Missing outputs (heterotopic data, ``--missing PATTERN ...``; issue 8 item 3, the case where the
coupling of the outputs can move the predictions): the moment coefficients (Cl Cm Cn) of a share of
the training rows are removed (NaN) by a pattern fixed before any run (:data:`MISSING_PATTERNS`):

  rates   the rows whose largest standardised |p_hat|, |q_hat|, |r_hat| (distance from the training
          median over the training std) is above its 70th percentile on the training rows: the
          angular-acceleration estimate rejected in the fastest 30 % of the maneuvers
  block   the rows in the 35-65 % stretch of the training time: a 30 % gyro dropout

and four models are scored on the held-out rows against the truth (same ``GPConfig()``, the replay's
settings): ``hjoint`` one joint GP on every training row, moments missing where removed (the
per-output statistics, ``docs/gp.md``); ``hindep`` six independent GPs, each on the rows that carry
its output; ``hdrop`` one joint GP on the complete rows only (what the pipeline did before: rows with
a missing output dropped); ``hdec`` ``hjoint`` with its cross-output coupling removed after the fit
(``gp.joint.decoupled_model``: what the coupling contributes); ``hjointv`` ``hjoint`` with the
coupling gate (``GPConfig.coupling_validation``: the coupling kept only for the outputs whose
blocked cross-validation error it lowers, on the rows that carry them). Each line carries ``err`` (all held-out
rows) and ``err_region`` (for ``rates``: the held-out rows beyond the same threshold, where the
training moments were missing; ``block``: all held-out rows again) and ``err_gap`` (the training rows
whose moments were removed, against the truth: the gap the replay fills, where the joint model has
the forces of the same rows). ``--summarize`` prints the pairs.

Usage::

    python benchmarks/eval_gp_jsbsim.py --make --aircraft c172x sgs --seeds 1 2 --turbulence light moderate
    python benchmarks/eval_gp_jsbsim.py --variants diag full nigp indep ls --json /tmp/gp.jsonl
    python benchmarks/eval_gp_jsbsim.py --summarize /tmp/gp.jsonl

``pa28``, ``j3cub`` (``J3Cub``), ``c182``, ``t37``, ``t6`` (``t6texan2``), ``b747`` (``B747``), ``f16``
(``f16_direct``), ``f4n`` (``F4N_fcs``), ``rascal`` (``Rascal110_glide``), ``sgs126``, ``asw20`` (``asw20_glide``) and
``iar80`` (``IAR80_glide``), ``c684`` (``C684_glide``), ``ultrastick`` (``UltraStick120_glide``), ``b737`` (``737``) and
``c172p``, ``eternity`` (``Eternity_glide``), ``us25e`` (``UltraStick25e_glide``), ``ka350``
(``KingAir350_glide``, a JSBSim Beechcraft King Air 350 twin turboprop from a FlightGear package, without its engines)
``s23`` (``ShortS23_glide``, JSBSim's Short S.23 flying boat, without its engines), ``dr1`` (``Dr1_glide``,
JSBSim's Fokker Dr.I triplane, without its rotary engine) and ``navion`` (``Navion_glide``, JSBSim's Ryan Navion, the
wheel's ``L17``, without its engine) were held out in earlier sessions and have been evaluated: they count as used.
``fokker50`` (JSBSim's Fokker 50, ``Fokker50_glide``, without its engines, propwash terms or yaw damper) is the
held-out, untouched one: never in the defaults, made and scored only in the final evaluation.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.eval_common import AIRCRAFT_HELP, append_jsonl  # noqa: E402
from benchmarks.jsbsim_harness.aircraft import aircraft_argument, summary_label  # noqa: E402
from gcs_sysid.aero.table import COEFFICIENTS  # noqa: E402
from gcs_sysid.gp import GPConfig, fit_gp  # noqa: E402
from gcs_sysid.jaxconfig import limit_blas_threads  # noqa: E402
from gcs_sysid.gp.joint import (correlation, decoupled_model, nonlinear_part, select_outputs,  # noqa: E402
                                truth_correlation)

VARIANTS = ("diag", "full", "nigp", "nigp0", "nigpd", "nigpnf", "global", "lsres", "indep", "lmc", "lmc3", "nigpc",
            "dec", "sel", "nigpv", "nigpa", "nigpk", "nigpf", "nigpo", "nigpr", "nigpt", "nigpu", "ls")

#: |truth correlation| below which the truth "has none" (the flags of the joint variants)
TRUTH_NONE = 0.2
#: an output's latent GP "carries a signal" when its prior std is at least this share of its noise std
#: (a correlation with a latent part of ~zero variance is scale-free but says nothing)
CARRIES = 0.1


def make(aircraft: str, seed: int, turbulence: str, aoa: str, duration: float, cache: Path) -> Path:
    """Fly, replay and fit least squares once; save the table, truth and LS predictions (``.npz``)."""
    from benchmarks.jsbsim_harness import FlightConfig, load_truth, make_flight
    from gcs_sysid.airframe import load_airframe
    from gcs_sysid.diagnose import run_fit
    from gcs_sysid.estimation import airangles
    from gcs_sysid.pipeline import ReplayOptions, replay_gust_rates, run_replay

    name = f"{aircraft}-{seed}-{turbulence}-{aoa}"
    work = cache / ("work-" + name)
    work.mkdir(parents=True, exist_ok=True)
    # a flight already in ``work`` from the same harness and configuration is reused (make_flight's stamp)
    files = make_flight(FlightConfig(aircraft, duration_s=duration, turbulence=turbulence, seed=seed), work, aoa=aoa,
                        reuse=True)
    truth = load_truth(files.truth)
    res = run_replay(files.tlog, files.airframe, work / "rep", ReplayOptions(progress=False))
    tab, held = res.table, res.held_out
    Xt, Yt = truth.at(tab.t)
    t_cut = float(tab.t[held & tab.valid][0])
    ls_model, _ = run_fit(files.tlog, files.airframe, work / "fit.toml", t_to=t_cut,
                          gust_rates=replay_gust_rates(ReplayOptions()),   # the replay's rates (eval_jsbsim's line)
                          profile_beta=airangles.BETA_PROFILE,      # the replay's sideslip estimator
                          air_roll_train=False)     # the measured Cl (the air-rate line is air_rate_arrays')
    air = air_rate_arrays(res, load_airframe(files.airframe), ls_model)
    air["Xt_air"] = true_air_regressors(aircraft, truth, tab.t, Xt)
    out = cache / f"{name}.npz"
    np.savez(out, t=tab.t, X=tab.X, Y=tab.Y, valid=tab.valid, held=held, train=res.train, Xt=Xt, Yt=Yt,
             gp_mean=res.pred_mean, gp_sigma=res.pred_sigma, ls=ls_model.evaluate(tab.X),
             x_offset_cov=np.full((tab.X.shape[1],) * 2, np.nan) if tab.x_offset_cov is None else tab.x_offset_cov,
             **air)
    return out


def true_air_regressors(aircraft: str, truth, t: np.ndarray, Xt: np.ndarray) -> np.ndarray:
    """The true regressors ``Xt`` ``(T, 10)`` with the rate hats JSBSim's aerodynamics reads: ``p_aero q_aero r_aero``
    on the axes whose XML reads them (:func:`benchmarks.eval_jsbsim.aero_reads_air_rates`), as ``eval_jsbsim``'s
    ``true_air`` line; the others as ``Xt``. ``t``: ``(T,)`` s; ``truth``:
    :func:`~benchmarks.jsbsim_harness.load_truth`."""
    from benchmarks.eval_jsbsim import aero_reads_air_rates

    out = np.array(Xt, float, copy=True)
    cst = truth.meta["constants"]
    axes = aero_reads_air_rates(aircraft)
    for j, (ax, ref) in enumerate(zip("pqr", ("b", "c", "b"))):
        if axes[ax]:
            out[:, 2 + j] = np.interp(t, truth.t, truth.fields[f"{ax}_aero"], left=np.nan, right=np.nan) * cst[ref] \
                / (2 * Xt[:, 9])
    return out


def air_rate_arrays(res, airframe, ls_model) -> dict:
    """The replay's air-rate pair on one replay's table, for :func:`score` (arrays for the cache ``.npz``).

    The one roll fit of the pair (:func:`gcs_sysid.aero.gustfilter.air_roll_fit` on the replay's training rows, with
    its Dryden and instruments' checks), the GP's Cl training target it gives
    (:func:`~gcs_sysid.aero.gustfilter.air_roll_target`: the measured Cl less the training rows' smoothed gust
    moment) and the held-out rows at the air-relative roll rate of
    :data:`~gcs_sysid.aero.gustfilter.HELDOUT_AIR_ROLL` (:func:`~gcs_sysid.aero.gustfilter.heldout_air_roll`), as
    ``run_replay`` makes them with ``AIR_ROLL_TRAIN``; and the fair least-squares line of ``eval_jsbsim``
    (``ls_airtrain``, :func:`benchmarks.eval_jsbsim.ls_air_target_scores`): Cl by ``gcs-sysid fit``'s stepwise
    regression (:func:`gcs_sysid.diagnose.fit.fit_model`) on the replay's training rows and that target, asked at the
    same held-out air rate; the other coefficients ``ls_model``'s.

    Args:
        res: :class:`gcs_sysid.pipeline.ReplayResult` (its table at the gyro's ``p_hat``, states, rows).
        airframe: the flight's :class:`~gcs_sysid.airframe.Airframe`.
        ls_model: ``gcs-sysid fit``'s model on the training window (``evaluate(X) -> (T, 6)``).

    Returns:
        ``Y_air`` ``(T, 6)`` (the measured coefficients with Cl's training rows moved; equal to ``Y`` where the roll
        fit was refused), ``X_air`` ``(T, 10)`` (``X`` with the held-out rows' ``p_hat`` less the gust; equal to
        ``X`` where refused or ``HELDOUT_AIR_ROLL`` is ``"off"``), ``ls_air`` ``(T, 6)``, ``air_applied`` (bool:
        the roll fit was accepted), ``air_note`` (the target's note: what was done, or why not).
    """
    from benchmarks.eval_jsbsim import air_rate_pair, ls_cl_on
    from gcs_sysid.aero.gustfilter import HELDOUT_AIR_ROLL

    X_air, Y_air, info = air_rate_pair(res, airframe, HELDOUT_AIR_ROLL)
    ls_air = np.array(ls_model.evaluate(res.table.X), float)
    ls_air[:, COEFFICIENTS.index("Cl")] = ls_cl_on(res, Y_air, X_air)
    return dict(Y_air=Y_air, X_air=X_air, ls_air=ls_air, air_applied="Cl_p" in info, air_note=info["note"])


def errors(est: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """``100 RMS(est - ref) / RMS(ref)`` per column ``(P,)`` (the project's error metric)."""
    return 100.0 * np.sqrt(np.mean((est - ref) ** 2, 0)) / np.sqrt(np.mean(ref**2, 0))


def coverage(mean: np.ndarray, sigma: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """Share (%) of ``ref`` inside ``mean +- 1.96 sigma``, per column ``(P,)`` (NaN without a sigma)."""
    out = 100.0 * np.mean(np.abs(mean - ref) <= 1.96 * sigma, 0)
    return np.where(np.all(np.isnan(sigma), 0), np.nan, out)


def _config(variant: str, base: GPConfig) -> GPConfig:
    if variant == "diag":
        return replace(base, noise_correlation=False, input_noise=False)
    if variant in ("full", "indep"):
        return replace(base, noise_correlation=variant == "full", input_noise=False)
    if variant in ("nigp", "dec", "sel"):
        return replace(base, noise_correlation=True, input_noise=True)
    if variant == "nigp0":        # nigp without the coupling gate (the default before the sixteenth session)
        return replace(base, noise_correlation=True, input_noise=True, coupling_validation=False)
    if variant == "nigpd":        # nigp with one noise variance per output (the replay's GPConfig())
        return replace(base, noise_correlation=False, input_noise=True)
    if variant == "nigpnf":       # nigp with the shared error started in the noise (GPConfig.noise_start)
        return replace(base, noise_correlation=True, input_noise=True, noise_start="noise")
    if variant == "nigpv":
        return replace(base, noise_correlation=True, input_noise=True, coupling_validation=True)
    # the longitudinal and lateral outputs' factors of B kept apart (GPConfig.output_groups)
    if variant == "nigpa":
        return replace(base, noise_correlation=True, input_noise=True, output_groups="axes")
    if variant == "nigpk":        # one latent kernel per output group (GPConfig.output_groups="kernels")
        return replace(base, noise_correlation=True, input_noise=True, output_groups="kernels")
    if variant == "nigpf":        # the same kernels, loadings free (GPConfig.output_groups="kernels-free")
        return replace(base, noise_correlation=True, input_noise=True, output_groups="kernels-free")
    if variant == "nigpo":        # one kernel per output, loading on its axis (GPConfig.output_groups="output-kernels")
        return replace(base, noise_correlation=True, input_noise=True, output_groups="output-kernels")
    # nigp with B and the noise covariance learned again on every row (GPConfig.coupling_rows)
    if variant == "nigpr":
        return replace(base, noise_correlation=True, input_noise=True, coupling_rows="all")
    if variant == "nigpt":        # nigp, coupling kept where the every-row bound supports it (GPConfig.coupling_test;
        return replace(base, noise_correlation=True, input_noise=True, coupling_test="lr")   # the default since s22)
    # nigp with B's couplings as learned, untested (the default until the twenty-second session)
    if variant == "nigpu":
        return replace(base, noise_correlation=True, input_noise=True, coupling_test="none")
    if variant == "nigpc":
        return replace(base, noise_correlation=True, input_noise=True, residual_correlation=True)
    if variant == "lsres":
        return replace(base, noise_correlation=True, input_noise=True)
    if variant in ("lmc", "lmc3"):
        return replace(base, noise_correlation=True, input_noise=True, latent_kernels=2 if variant == "lmc" else 3)
    if variant == "global":
        return replace(base, noise_correlation=True, input_noise=True, local=False)
    raise ValueError(variant)


def score(path: Path, variants, base: GPConfig = GPConfig(), thin: int | None = None, air_roll: bool = True):
    """Every variant on one cached flight; yields one JSON-able dict per variant.

    ``thin``: fit on every ``thin``-th training row only (few samples over the whole flown envelope:
    where pooling the outputs in one joint model should matter most); None: all of them.
    ``air_roll``: the replay's air-rate pair (:func:`air_rate_arrays`, cached by ``--make``): every variant's Cl
    trained on the air-rate target and asked at the held-out rows' air roll rate (the other outputs at the gyro's
    rate, as the replay's ``"predicted:Cl"``), and ``ls`` the fair least-squares line on the same target; where the
    roll fit was refused the target and rates are the measured ones. False: Cl trained on the measured Cl at the
    gyro's rate (the tables before the thirtieth session; the lines' ``aoa`` gets ``/gyro-Cl``).

    Raises:
        ValueError: ``air_roll`` on a cache made before the air-rate arrays (remake it with ``--make``).
    """
    from gcs_sysid.gp.discrepancy import with_offset_covariance

    d = np.load(path)
    X, Y, Xt, Yt = d["X"], d["Y"], d["Xt"], d["Yt"]
    if air_roll and "Y_air" not in d.files:
        raise ValueError(f"{path}: cached without the air-rate pair's arrays; remake it with --make, or score it "
                         "with --air-roll off")
    Ym = Y                                  # the measured coefficients (meas); Y: the training target
    Y, Xa = (d["Y_air"], d["X_air"]) if air_roll else (Y, X)
    ls_line = d["ls_air"] if air_roll else d["ls"]
    ci = COEFFICIENTS.index("Cl")

    # the true regressors Cl is asked at (err_true): JSBSim's air-relative rates for a model of Cl at the air rate
    Xt_cl = d["Xt_air"] if air_roll and "Xt_air" in d.files else Xt

    def held(predict, at=None, at_cl=None, **kw):
        """``predict(Xq, **kw) -> (mean, var)`` on the held-out rows of ``at`` (``X``), Cl's column at ``at_cl``
        (the air rate ``Xa``)."""
        at, at_cl = (X, Xa) if at is None else (at, at_cl)
        m, v = (np.array(a, float) for a in predict(at[h], **kw))
        if at_cl is not at:
            ma, va = predict(at_cl[h], **kw)
            m[:, ci], v[:, ci] = np.asarray(ma)[:, ci], np.asarray(va)[:, ci]
        return m, v
    # the estimator's flight-common regressor offset (tables cached before it was carried have none)
    off = d["x_offset_cov"] if "x_offset_cov" in d.files and np.isfinite(d["x_offset_cov"]).all() else None
    ok = d["valid"] & np.isfinite(Yt).all(1) & np.isfinite(X).all(1)
    tr = d["train"] & np.isfinite(Y).all(1) & np.isfinite(X).all(1)
    if thin is not None:
        tr &= (np.cumsum(tr) - 1) % int(thin) == 0
    h = d["held"] & ok
    meta = dict(zip(("aircraft", "seed", "turbulence", "aoa"), path.stem.split("-")))
    if thin is not None:
        meta["aoa"] += f"/thin{int(thin)}"            # a separate group in --summarize
    if not air_roll:
        meta["aoa"] += "/gyro-Cl"
    meta["air_roll"] = bool(air_roll) and bool(d["air_applied"])   # the pair applied (not refused) on this flight
    memo: dict = {}

    def joint_fit():          # nigp, shared by nigp, dec and sel (fitted once per flight)
        if "joint" not in memo:
            model, hist = fit_gp(X[tr], Y[tr], _config("nigp", base))
            memo["joint"] = with_offset_covariance(model, off), hist
        return memo["joint"]

    def indep_fit():          # six one-output GPs, shared by indep and sel
        if "indep" not in memo:
            cfg = _config("indep", base)
            memo["indep"] = [with_offset_covariance(fit_gp(X[tr], Y[tr][:, [p]], cfg,
                                                           output_names=[COEFFICIENTS[p]])[0], off)
                             for p in range(Y.shape[1])]
        return memo["indep"]

    for v in variants:
        t0 = time.perf_counter()
        corr = float("nan")
        true = None
        validation = {}
        true_latent = true_noise = None
        extra: dict = {}
        if v == "ls":
            mean, sig = ls_line[h], np.full((int(h.sum()), Y.shape[1]), np.nan)
            sig_n = sig_g = sig
        elif v == "sel":
            sel = select_outputs(joint_fit()[0], indep_fit(), X[tr], Y[tr])
            m, var = held(sel.predict, include_noise=False)
            mean, sig = m, np.sqrt(var)
            sig_n = np.sqrt(held(sel.predict)[1])
            sig_g = sig * np.nan
            mt, vt = held(sel.predict, Xt, Xt_cl, include_noise=False, input_noise=False)
            true = mt, np.sqrt(vt)
            extra = {"use_joint": sel.use_joint.tolist(), "cv_joint": sel.err_joint.tolist(),
                     "cv_indep": sel.err_indep.tolist()}
        elif v == "indep":
            models = indep_fit()
            Xq = [Xa[h] if p == ci else X[h] for p in range(len(models))]
            parts = [m.predict(x, False) for m, x in zip(models, Xq)]
            mean = np.column_stack([m for m, _ in parts])
            sig = np.sqrt(np.column_stack([s for _, s in parts]))
            tp = [m.predict((Xt_cl if p == ci else Xt)[h], include_noise=False, input_noise=False)
                  for p, m in enumerate(models)]
            true = np.column_stack([m for m, _ in tp]), np.sqrt(np.column_stack([s for _, s in tp]))
            sig_n = sig_g = sig * np.nan
        else:
            prior = ls_line if v == "lsres" else np.zeros_like(Y)      # lsres: the GP on the residual of LS
            if v in ("nigp", "dec"):
                model, hist = joint_fit()
                if v == "dec":
                    model = decoupled_model(model)
                extra = _correlations(model, X[tr], Xt[tr], Yt[tr])
            else:
                model, hist = fit_gp(X[tr], (Y - prior)[tr], _config(v, base))
                model = with_offset_covariance(model, off)
                if v in ("nigp0", "nigpd", "nigpnf", "nigpv", "nigpa", "nigpk", "nigpf", "nigpo", "nigpr", "nigpt",
                         "nigpu"):
                    extra = _correlations(model, X[tr], Xt[tr], Yt[tr])
            validation = hist.validation
            m, var = held(model.predict, include_noise=False)
            mean, sig = m + prior[h], np.sqrt(var)
            sig_n = np.sqrt(held(model.predict)[1])         # with the observation noise (the replay's band)
            # with the global layer's noise variance sigma_p^2 (the likelihood's) instead of the local nugget
            sig_g = np.sqrt(var + np.asarray(model.params.noise)[None, :] * model.scaler.y_std**2)
            c = model.output_correlation()
            corr = float(np.max(np.abs(c - np.diag(np.diag(c)))))
            mt, vt = held(model.predict, Xt, Xt_cl, include_noise=False, input_noise=False)     # exact regressors
            true = mt + prior[h], np.sqrt(vt)
            # before the model-error term (docs/gp.md, "The band at exact conditions"): latent alone, and
            # the latent band widened by the offset term alone / the discrepancy alone
            _, vl = held(model.predict, Xt, Xt_cl, include_noise=False, input_noise=False, model_error=False)
            true_latent = coverage(mt + prior[h], np.sqrt(vl), Yt[h])
            true_noise = coverage(mt + prior[h], np.sqrt(held(model.predict, Xt, Xt_cl, input_noise=False)[1]), Yt[h])
        e, cv, cvn = errors(mean, Yt[h]), coverage(mean, sig, Yt[h]), coverage(mean, sig_n, Yt[h])
        yield (dict(meta, variant=v, err=dict(zip(COEFFICIENTS, e.round(2).tolist())),
                         cov=dict(zip(COEFFICIENTS, cv.round(1).tolist())),
                         cov_noise=dict(zip(COEFFICIENTS, cvn.round(1).tolist())),
                         cov_gnoise=dict(zip(COEFFICIENTS, coverage(mean, sig_g, Yt[h]).round(1).tolist())),
                         max_corr=corr, validation=validation,
                         meas=dict(zip(COEFFICIENTS, errors(Ym[h], Yt[h]).round(2).tolist())),
                         **({} if true is None else {
                             "err_true": dict(zip(COEFFICIENTS, errors(true[0], Yt[h]).round(2).tolist())),
                             "cov_true": dict(zip(COEFFICIENTS, coverage(*true, Yt[h]).round(1).tolist()))}),
                         **({} if true_latent is None else {
                             "cov_true_latent": dict(zip(COEFFICIENTS, true_latent.round(1).tolist())),
                             "cov_true_noise": dict(zip(COEFFICIENTS, true_noise.round(1).tolist())),
                             "discrepancy_std": None if model.discrepancy is None else dict(zip(
                                 COEFFICIENTS, (np.sqrt(model.discrepancy[0]) * model.scaler.y_std).tolist())),
                             "offset_std_deg": None if off is None else float(np.degrees(np.sqrt(off[0, 0])))}),
                         **extra, t_fit_s=round(time.perf_counter() - t0, 2)))


#: Missing-output patterns of ``--missing`` (module docstring); the moments are removed.
MISSING_PATTERNS = ("rates", "block")
#: Share of the training rows whose moments a pattern removes.
MISSING_SHARE = 0.3
#: Columns of the moment coefficients (Cl Cm Cn) in ``COEFFICIENTS``; of the rate regressors in ``X``.
MOMENTS, RATES = (3, 4, 5), (2, 3, 4)


def missing_rows(pattern: str, X: np.ndarray, tr: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows whose moments ``pattern`` removes ``(N,)`` (within ``tr``) and the rows of its region ``(N,)``
    (``rates``: every row beyond the training threshold; ``block``: all rows)."""
    if pattern == "rates":
        med, sd = np.median(X[tr][:, RATES], 0), X[tr][:, RATES].std(0)
        score = np.max(np.abs(X[:, RATES] - med) / np.where(sd > 0, sd, 1.0), 1)
        thr = np.quantile(score[tr], 1.0 - MISSING_SHARE)
        return tr & (score > thr), score > thr
    if pattern == "block":
        k = np.flatnonzero(tr)
        lo, hi = k[int(round(0.35 * len(k)))], k[int(round(0.65 * len(k)))]
        idx = np.arange(len(X))
        return tr & (idx >= lo) & (idx < hi), np.ones(len(X), bool)
    raise ValueError(pattern)


MISSING_MODELS = ("hjoint", "hindep", "hdrop", "hdec", "hjointv")


def score_missing(path: Path, patterns, base: GPConfig = GPConfig(), which=MISSING_MODELS):
    """``hjoint``, ``hindep``, ``hdrop``, ``hdec`` on one cached flight for each missing-output pattern
    (module docstring); yields one JSON-able dict per pattern and model. The independent GPs of the
    forces see the same rows under every pattern and are fitted once."""
    from gcs_sysid.gp.joint import decoupled_model

    d = np.load(path)
    X, Y, Xt, Yt = d["X"], d["Y"], d["Xt"], d["Yt"]
    ok = d["valid"] & np.isfinite(Yt).all(1) & np.isfinite(X).all(1)
    tr = d["train"] & np.isfinite(Y).all(1) & np.isfinite(X).all(1)
    h = d["held"] & ok
    meta = dict(zip(("aircraft", "seed", "turbulence", "aoa"), path.stem.split("-")))
    force_fits: dict = {}
    P = Y.shape[1]
    for pattern in patterns:
        gone, region = missing_rows(pattern, X, tr)
        Ym = Y.copy()
        Ym[np.ix_(gone, MOMENTS)] = np.nan
        hr = h & region
        models, times, indep = {}, {}, []
        if "hjoint" in which or "hdec" in which:
            t0 = time.perf_counter()
            models["hjoint"] = fit_gp(X[tr], Ym[tr], base)[0]
            models["hdec"] = decoupled_model(models["hjoint"])
            times.update(hjoint=time.perf_counter() - t0, hdec=0.0)
        if "hjointv" in which:
            t0 = time.perf_counter()
            models["hjointv"] = fit_gp(X[tr], Ym[tr], replace(base, coupling_validation=True))[0]
            times["hjointv"] = time.perf_counter() - t0
        if "hdrop" in which:
            t0 = time.perf_counter()
            keep = tr & ~gone
            models["hdrop"] = fit_gp(X[keep], Y[keep], base)[0]
            times["hdrop"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        for p in range(P if "hindep" in which else 0):
            rows = tr & np.isfinite(Ym[:, p])
            if p not in MOMENTS:
                if p not in force_fits:
                    force_fits[p] = fit_gp(X[rows], Y[rows][:, [p]], base, output_names=[COEFFICIENTS[p]])[0]
                indep.append(force_fits[p])
            else:
                indep.append(fit_gp(X[rows], Y[rows][:, [p]], base, output_names=[COEFFICIENTS[p]])[0])
        times["hindep"] = time.perf_counter() - t0
        for v in [m for m in MISSING_MODELS if m in which]:
            if v == "hindep":
                parts = [m.predict(X[h], include_noise=False) for m in indep]
                mean, var = np.column_stack([a for a, _ in parts]), np.column_stack([b for _, b in parts])
                gap = np.column_stack([m.predict(X[gone], include_noise=False)[0] for m in indep])
                corr = float("nan")
            else:
                mean, var = models[v].predict(X[h], include_noise=False)
                gap = models[v].predict(X[gone], include_noise=False)[0]
                c = models[v].output_correlation()
                corr = float(np.max(np.abs(c - np.diag(np.diag(c)))))
            sig = np.sqrt(var)
            in_region = region[h]
            yield dict(meta, aoa=meta["aoa"] + f"/miss-{pattern}", variant=v, pattern=pattern,
                       n_train=int(tr.sum()), n_missing=int(gone.sum()), n_held=int(h.sum()), n_region=int(hr.sum()),
                       err=dict(zip(COEFFICIENTS, errors(mean, Yt[h]).round(2).tolist())),
                       err_region=dict(zip(COEFFICIENTS, errors(mean[in_region], Yt[hr]).round(2).tolist())),
                       err_gap=dict(zip(COEFFICIENTS, errors(gap, Yt[gone]).round(2).tolist())),
                       cov=dict(zip(COEFFICIENTS, coverage(mean, sig, Yt[h]).round(1).tolist())),
                       max_corr=corr, t_fit_s=round(times[v], 2),
                       notes=[] if v == "hindep" else [n for n in models[v].notes if "miss" in n])


def summarize_missing(rows: list[dict]) -> str:
    """Pairs of the ``--missing`` models per pattern: all six coefficients and the moments alone, on all
    held-out rows and in the pattern's region (better / worse by more than 0.05 points / within)."""
    out = []
    by: dict = {}
    for r in rows:
        by.setdefault((r.get("pattern"), r["aircraft"], r["seed"], r["turbulence"]), {})[r["variant"]] = r
    models = [m for m in MISSING_MODELS if any(m in f for f in by.values())]
    mom = [COEFFICIENTS[i] for i in MOMENTS]
    for key, what in (("err", "held-out rows"), ("err_gap", "training rows whose moments were removed")):
        out.append(f"\n{key}: Cl Cm Cn %, {what}\n\n| pattern | flight | " + " | ".join(models) + " |")
        out.append("|" + "---|" * (len(models) + 2))
        for (pt, ac, seed, turb), f in sorted(by.items()):
            out.append(f"| {pt} | {ac} {turb} s{seed} | " + " | ".join(
                " ".join(f"{f[m][key][c]:.1f}" for c in mom) if m in f else "" for m in models) + " |")
    out.append("")
    for a, b in (("hjoint", "hindep"), ("hjoint", "hdrop"), ("hjoint", "hdec"), ("hindep", "hdrop"),
                 ("hjointv", "hindep"), ("hjointv", "hjoint")):
        for pattern in MISSING_PATTERNS:
            for key in ("err", "err_region", "err_gap"):
                for what, cols in (("all", COEFFICIENTS), ("moments", [COEFFICIENTS[i] for i in MOMENTS])):
                    pairs = [(f[a][key][c], f[b][key][c]) for (pt, *_), f in by.items() if pt == pattern
                             and a in f and b in f for c in cols]
                    if not pairs:
                        continue
                    better = sum(x < y - 0.05 for x, y in pairs)
                    worse = sum(x > y + 0.05 for x, y in pairs)
                    out.append(f"{pattern:6s} {key:10s} {what:7s} {a} vs {b}: {better} better / {worse} worse / "
                               f"{len(pairs) - better - worse} within 0.05 of {len(pairs)} (median "
                               f"{np.median([x for x, _ in pairs]):.2f} vs {np.median([y for _, y in pairs]):.2f} %)")
    return "\n".join(out)


def _correlations(model, X, Xt, Yt) -> dict:
    """Learned output correlations of ``model`` and the truth's on the training rows (JSON-able)."""
    B = np.asarray(model.params.B)
    gm, _ = model.predict_global(X, include_noise=False)
    model_nl, _ = correlation(nonlinear_part(X, gm))
    truth = truth_correlation(Xt, Yt)
    quad = truth_correlation(X, gm)       # the truth's statistic on the model's predictions (measured regressors)
    learned = model.output_correlation()
    P = learned.shape[0]
    flags = [(i, j) for i in range(P) for j in range(i + 1, P)
             if abs(learned[i, j]) > 0.5 and abs(truth["signal_corr"][i, j]) < TRUTH_NONE]
    latent, noise = np.sqrt(np.diag(B)), np.sqrt(np.asarray(model.params.noise))     # standardised
    carries = latent >= CARRIES * noise         # outputs whose latent GP carries a signal at all
    name = lambda i, j: f"{COEFFICIENTS[i]}-{COEFFICIENTS[j]}"  # noqa: E731
    r = lambda a: [float(f"{x:.4g}") for x in np.ravel(a)]  # noqa: E731   (flattened, 4 significant digits)
    return {"corr_learned": r(learned), "latent_std": r(latent * model.scaler.y_std),
            "noise_corr": r(model.noise_correlation()), "noise_std": r(noise * model.scaler.y_std),
            "corr_model_nl": r(model_nl), "corr_model_quad": r(quad["signal_corr"]),
            "std_model_quad": r(quad["signal_std"]),
            "truth": {k: r(v) for k, v in truth.items()},
            "flags": [name(i, j) for i, j in flags],
            "flags_carrying": [name(i, j) for i, j in flags if carries[i] and carries[j]]}


def diagnose(path: Path) -> str:
    """Least squares per output against SUR/GLS on one cached flight (Zellner 1962), held-out error %.

    ``ols``: each coefficient on all ten regressors; ``gls_all``: GLS with the residuals' 6 x 6
    covariance and the same regressors for every output (equal to ``ols`` by Zellner's theorem);
    ``ols_sub``/``sur_sub``: each coefficient on its own axis's regressors only (longitudinal CX CZ
    Cm: alpha q_hat delta_e delta_t V; lateral CY Cl Cn: beta p_hat r_hat delta_a delta_r), least
    squares and GLS: where the regressor sets differ, correlated noise can help a joint estimate.
    """
    d = np.load(path)
    X, Y, Yt = d["X"], d["Y"], d["Yt"]
    ok = d["valid"] & np.isfinite(Yt).all(1) & np.isfinite(X).all(1)
    tr = d["train"] & np.isfinite(Y).all(1) & np.isfinite(X).all(1)
    h = d["held"] & ok
    sd = X[tr].std(0)
    A = np.column_stack([np.ones(len(X)), (X - X[tr].mean(0)) / np.where(sd > 0, sd, 1.0)])
    lon, lat = [1, 4, 6, 9, 10], [2, 3, 5, 7, 8]          # columns of A (1 + regressor index)
    out = []
    for name, cols in (("all", [list(range(11))] * 6),
                       ("sub", [[0] + (lon if p in (0, 2, 4) else lat) for p in range(6)])):
        Wo = [np.linalg.lstsq(A[tr][:, c], Y[tr][:, p], rcond=None)[0] for p, c in enumerate(cols)]
        res = np.column_stack([Y[tr][:, p] - A[tr][:, c] @ w for p, (c, w) in enumerate(zip(cols, Wo))])
        Si = np.linalg.inv(np.cov(res.T))
        off = np.cumsum([0] + [len(c) for c in cols])
        G, g = np.zeros((off[-1], off[-1])), np.zeros(off[-1])
        for p, cp in enumerate(cols):
            for q, cq in enumerate(cols):
                G[off[p]:off[p + 1], off[q]:off[q + 1]] = Si[p, q] * A[tr][:, cp].T @ A[tr][:, cq]
            g[off[p]:off[p + 1]] = A[tr][:, cp].T @ (Y[tr] @ Si[p])
        b = np.linalg.lstsq(G, g, rcond=None)[0]
        ols = np.column_stack([A[h][:, c] @ w for c, w in zip(cols, Wo)])
        gls = np.column_stack([A[h][:, c] @ b[off[p]:off[p + 1]] for p, c in enumerate(cols)])
        rc, _ = correlation(res)
        big = max(abs(rc[i, j]) for i in range(6) for j in range(i + 1, 6))
        out.append(f"{path.stem:26s} ols_{name} " + " ".join(f"{e:6.2f}" for e in errors(ols, Yt[h]))
                   + f"   gls_{name} " + " ".join(f"{e:6.2f}" for e in errors(gls, Yt[h]))
                   + f"   largest |residual corr| {big:.2f}")
    return "\n".join(out)


def summarize(paths) -> str:
    """Markdown table (medians over seeds) of ``--json`` lines."""
    rows = [json.loads(line) for p in paths for line in open(p) if line.strip()]
    missing = [r for r in rows if "pattern" in r]
    if missing:
        return summarize_missing(missing)
    last = {(r["aircraft"], r["seed"], r["turbulence"], r["aoa"], r["variant"]): r for r in rows}   # a rerun replaces
    rows = list(last.values())
    groups: dict[tuple, list[dict]] = {}
    for r in rows:
        groups.setdefault((r["aircraft"], r["turbulence"], r["aoa"], r["variant"]), []).append(r)
    head = ("| aircraft | turb. | AOA_SSA | model | seeds | " + " | ".join(COEFFICIENTS)
            + " | cov95 % latent (min-max) | with local noise | with global noise | at true regressors | max corr |")
    out = [head, "|" + "---|" * (head.count("|") - 1)]
    for (ac, turb, aoa, v), rs in sorted(groups.items()):
        med = lambda k, c: float(np.nanmedian([r[k][c] for r in rs]))   # noqa: E731
        def cov(key):
            vals = [x for r in rs if r["variant"] != "ls" for x in r.get(key, {}).values()
                    if x is not None and np.isfinite(x)]
            return f"{np.median(vals):.0f} ({min(vals):.0f}-{max(vals):.0f})" if vals else ""
        corr = float(np.nanmedian([r["max_corr"] for r in rs]))
        name = summary_label(ac)
        out.append(f"| {name} | {turb} | {aoa} | {v} | {len(rs)} | "
                   + " | ".join(f"{med('err', c):.1f}" for c in COEFFICIENTS)
                   + f" | {cov('cov')} | {cov('cov_noise')} | {cov('cov_gnoise')} | {cov('cov_true')} | "
                   + f"{'' if np.isnan(corr) else f'{corr:.2f}'} |")
    # pairwise: joint (full) vs independent, GP vs least squares, per flight and coefficient
    by = {}
    for r in rows:
        by.setdefault((r["aircraft"], r["seed"], r["turbulence"], r["aoa"]), {})[r["variant"]] = r
    for a, b in (("full", "indep"), ("nigp", "indep"), ("nigp0", "indep"), ("nigp", "nigp0"), ("nigp0", "ls"),
                 ("nigpd", "indep"), ("nigpnf", "indep"), ("nigp", "nigpd"), ("nigpnf", "nigpd"), ("nigpnf", "nigp"),
                 ("nigpd", "ls"), ("nigpnf", "ls"), ("dec", "nigp"), ("dec", "indep"), ("sel", "indep"),
                 ("sel", "nigp"), ("nigpv", "nigp"), ("nigpv", "indep"), ("nigpa", "nigp"), ("nigpa", "indep"),
                 ("nigpa", "ls"), ("nigpk", "nigp"), ("nigpk", "indep"), ("nigpk", "ls"), ("nigpf", "nigp"),
                 ("nigpf", "indep"), ("nigpf", "ls"), ("nigpo", "nigp"), ("nigpo", "indep"), ("nigpo", "ls"),
                 ("nigpr", "nigp"), ("nigpr", "indep"), ("nigpr", "ls"), ("nigpt", "nigp"), ("nigpt", "indep"),
                 ("nigpt", "ls"), ("nigp", "nigpu"), ("nigpu", "indep"), ("lmc", "indep"), ("lmc3", "indep"),
                 ("lmc", "nigp"),
                 ("lmc3", "nigp"), ("full", "ls"), ("nigp", "ls"), ("lmc", "ls"), ("lmc3", "ls"), ("full", "diag"),
                 ("nigp", "diag"), ("diag", "ls")):
        pairs = [(f[a]["err"][c], f[b]["err"][c]) for f in by.values() if a in f and b in f for c in COEFFICIENTS]
        if pairs:
            wins = sum(x < y for x, y in pairs)
            out.append(f"\n{a} better than {b}: {wins} of {len(pairs)} flight x coefficient pairs "
                       f"(median error {np.median([x for x, _ in pairs]):.1f} vs "
                       f"{np.median([y for _, y in pairs]):.1f} %)")
    return "\n".join(out)


def add_flight_args(ap: argparse.ArgumentParser, aircraft: list[str],
                    make_help: str = "fly, replay and cache the flights first") -> None:
    """Add the options that pick the cached flights (``--cache --make --aircraft --seeds --turbulence``)
    to ``ap``; shared by this script and ``eval_gp_joint.py``.

    Args:
        ap: the script's parser (changed in place).
        aircraft: the default of ``--aircraft`` (harness names).
        make_help: the help of ``--make`` (what the script does with missing flights).
    """
    ap.add_argument("--cache", default="/tmp/gcs-sysid-gp-eval", help="folder of the cached flights (.npz)")
    ap.add_argument("--make", action="store_true", help=make_help)
    ap.add_argument("--aircraft", nargs="+", default=aircraft, type=aircraft_argument,
                    help=AIRCRAFT_HELP)
    ap.add_argument("--seeds", nargs="+", type=int, default=[1])
    ap.add_argument("--turbulence", nargs="+", default=["light"])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_flight_args(ap, ["c172x", "sgs"])
    ap.add_argument("--aoa", nargs="+", default=["ahrs"], choices=("ahrs", "vane"))
    ap.add_argument("--duration", type=float, default=90.0)
    ap.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=VARIANTS)
    ap.add_argument("--json", default=None, help="append one JSON line per flight and variant")
    ap.add_argument("--summarize", nargs="+", default=None, metavar="JSONL")
    ap.add_argument("--thin", type=int, default=None,
                    help="fit on every N-th training row only (joint vs independent with few samples)")
    ap.add_argument("--missing", nargs="+", default=None, choices=MISSING_PATTERNS,
                    help="remove the moments of part of the training rows by these patterns and score hjoint, "
                         "hindep, hdrop, hdec, hjointv instead of --variants")
    ap.add_argument("--missing-models", nargs="+", default=list(MISSING_MODELS), choices=MISSING_MODELS)
    ap.add_argument("--air-roll", choices=("on", "off"), default="on",
                    help="Cl trained on the replay's air-rate target and asked at the held-out air roll rate, the "
                         "LS line on the same target (the replay's air-rate pair, AIR_ROLL_TRAIN; default on); "
                         "'off': the measured Cl at the gyro's rate (the tables before the thirtieth session)")
    ap.add_argument("--diagnose", action="store_true",
                    help="print least squares vs SUR/GLS per cached flight instead of fitting GPs")
    a = ap.parse_args(argv)
    if a.summarize:
        print(summarize(a.summarize))
        return 0
    # the replay's BLAS setting (one thread, pipeline._load_stages), before any fit: a flight made by this process
    # set it through its replay, a cached one did not, and the fit's hyperparameters (and so the latent band) moved
    # with the threading: Cl's latent coverage 21.7 against 19.1 % on fokker50 s1 light (thirty-third session, lead)
    limit_blas_threads(1)
    cache = Path(a.cache)
    cache.mkdir(parents=True, exist_ok=True)
    for ac in a.aircraft:
        for turb in a.turbulence:
            for aoa in a.aoa:
                for seed in a.seeds:
                    path = cache / f"{ac}-{seed}-{turb}-{aoa}.npz"
                    if a.make or not path.is_file():
                        path = make(ac, seed, turb, aoa, a.duration, cache)
                    if a.diagnose:
                        print(diagnose(path), flush=True)
                        continue
                    if a.missing:
                        for r in score_missing(path, a.missing, which=a.missing_models):
                            print(f"{path.stem:26s} {r['pattern']:5s} {r['variant']:6s} err "
                                  + " ".join(f"{r['err'][c]:6.2f}" for c in COEFFICIENTS) + "  region "
                                  + " ".join(f"{r['err_region'][c]:6.2f}" for c in COEFFICIENTS) + "  gap "
                                  + " ".join(f"{r['err_gap'][c]:6.2f}" for i, c in enumerate(COEFFICIENTS)
                                             if i in MOMENTS)
                                  + f"  ({r['n_missing']} of {r['n_train']} missing, {r['n_region']} held-out "
                                  f"rows in region)  {r['t_fit_s']:.1f} s", flush=True)
                            append_jsonl(a.json, [r])
                        continue
                    for r in score(path, a.variants, thin=a.thin, air_roll=a.air_roll == "on"):
                        print(f"{path.stem:26s} {r['variant']:6s} err "
                              + " ".join(f"{r['err'][c]:6.1f}" for c in COEFFICIENTS)
                              + "  cov " + " ".join(f"{r['cov'][c]:5.1f}" for c in COEFFICIENTS)
                              + f"  corr {r['max_corr']:.2f}  {r['t_fit_s']:.1f} s", flush=True)
                        for k in ("err_true", "cov_true", "cov_true_latent", "cov_true_noise", "cov_noise"):
                            if r.get(k):
                                print(f"{'':33s} {k:15s} " + " ".join(f"{r[k][c]:6.1f}" for c in COEFFICIENTS)
                                      + f"   mean {np.nanmean(list(r[k].values())):5.1f}", flush=True)
                        append_jsonl(a.json, [r])
    return 0


if __name__ == "__main__":
    sys.exit(main())
