"""Score gcs-sysid against JSBSim's exact truth: aircraft x seeds x turbulence levels.

For each flight (``benchmarks.jsbsim_harness``: a stock JSBSim aircraft gliding through 3-2-1-1s,
doublets and multisines on all axes in Milspec turbulence, logged as an ArduPilot .tlog) it runs the
real replay (``run_replay``: decode, EKF/RTS, coefficients, GP on the first 80 %, held-out last 20 %)
and the project's stepwise least-squares fit (``run_fit`` on the training window), and prints,
against the truth (``100 * RMS(est - truth) / RMS(truth)`` per coefficient, on the held-out segment):

  meas   the measured coefficients themselves (``meas_all`` in the JSON: on all valid rows;
         ``meas_true_accel``: on all rows with JSBSim's angular accelerations put in, a diagnosis;
         ``meas_offset``: the mean of the held-out error, % of the truth's RMS, the part of ``meas``
         an offset explains; ``meas_flat``: held-out, re-estimated with a flat non-rotating Earth,
         ``estimate_states(earth="flat")``, what the velocity filter's Earth model changes)
  gp     the replay's model predictions at the measured regressors
  true   the saved model (``gcs-sysid predict``'s path) at the TRUE regressors
  tair   the same with the rates the aircraft's JSBSim aerodynamics reads in ``p_hat q_hat r_hat``
         (c172x, sgs, c182, t37, t6, b747: air-relative ``p-aero q-aero r-aero``; pa28: its XML reads the body rates,
         so ``tair`` = ``true``; ``true`` has the inertial rates a gyro measures)
  ls     the stepwise least-squares model (``gcs-sysid fit``) at the measured regressors (with ``air_roll_train``
         also ``ls_airtrain`` in the JSON: Cl trained on the GP's air-rate target, :func:`ls_air_target_scores`)
  cov    share of the truth inside the model's 95 % band, averaged over the six coefficients
         (``cov_gp_each`` etc. in the JSON: per coefficient). The truth is noise-free, so both scored bands
         are bands for the coefficient itself (``docs/gp.md``, "Two bands"; ``docs/jsbsim.md``, "What the
         coverage criterion scores"): gp: the replay's ``<C>_sigma`` at the flight's estimated
         regressors, without the white measurement noise (since the eleventh session; before, the band
         with it, now ``cov_gp_obs``: the replay's ``<C>_sigma_obs``, a band for a new measurement);
         true: the model's sigma without noise at exact conditions, with the model's error there
         (``cov_true_latent`` in the JSON: the latent band alone)
  terms  (JSON only, ``band_terms``) each variance term of the two bands per coefficient, as the RMS of
         its sigma in % of the truth's RMS (:func:`band_terms`; read against ``gp`` and ``true``)
  air    alpha and beta RMS errors of the reconstructed air data, deg (all valid rows)
  cy_diag  (JSON only) where the model's CY error at the true conditions (``tair``) comes from
         (:func:`cy_diagnosis`: the aided sideslip's scale against JSBSim's, the model's and JSBSim's local CY
         slopes on the true regressors, the error split into bias / linear / rest); ``--iv-beta`` picks the
         side-force slopes' estimator (``docs/estimation.md``, "Weak-instrument treatments")

Usage::

    python benchmarks/eval_jsbsim.py                        # small grid (2 tuning aircraft + held-out, 1 seed)
    python benchmarks/eval_jsbsim.py --aircraft c172x sgs pa28 --seeds 1 2 3 --turbulence light moderate
    python benchmarks/eval_jsbsim.py --aoa vane             # AOA_SSA = exact vane angles
    python benchmarks/eval_jsbsim.py --summarize results.jsonl   # markdown table of --json results
    python benchmarks/eval_jsbsim.py --aircraft eternity --work DIR --fly-only   # fly (or reuse) only

``pa28`` (held out since 2026-11-21), ``j3cub`` (the J-3 Cub, ``J3Cub`` also accepted; the
sixth session's untouched aircraft), ``c182`` (the seventh session's) and ``t37`` (the eighth
session's) and ``t6`` (the T-6A Texan II, ``t6texan2`` also accepted; the ninth session's) have been
evaluated and their results read: they count as used, as does ``b747`` (the Boeing 747, ``B747``; the
tenth session's) and ``f16`` (the F-16 with direct surfaces, ``f16_direct`` also accepted; the eleventh
session's) and ``f4n`` (the F-4N Phantom II with its own yaw damper, ``F4N`` also accepted; the twelfth
session's) and ``rascal`` (ArduPilot's SITL Rascal 110 without its propeller, ``Rascal110_glide`` also
accepted; the thirteenth session's) and ``sgs126`` (JSBSim's Schweizer SGS 1-26 glider at 3000 ft; the
fourteenth session's) and ``asw20`` (FlightGear's ASW 20 sailplane at 3000 ft, ``asw20_glide`` also accepted; the
fifteenth session's) and ``iar80`` (FlightGear's JSBSim IAR-80 fighter without its propeller at 10000 ft,
``IAR80_glide`` also accepted; the sixteenth session's) and ``c684`` (FlightGear's JSBSim Caudron C.684 racer without
its propeller at 6000 ft, ``C684_glide`` also accepted; the seventeenth session's) and ``ultrastick`` (the University of
Minnesota UAS Lab's JSBSim Ultra Stick 120 UAV without propulsion at 10000 ft, ``UltraStick120_glide`` also
accepted; the eighteenth session's) and ``b737`` (JSBSim's stock Boeing 737, engines shut down, its own yaw damper in
the loop, at 12000 ft; ``737`` also accepted; the nineteenth session's) and ``c172p`` (JSBSim's stock Cessna 172P,
engine shut down, at 4000 ft; the twentieth session's) and ``eternity`` (ENAC's Eternity UAV from Paparazzi's JSBSim
models without its motor, at 10000 ft; ``Eternity_glide`` also accepted; the twenty-first session's) and ``us25e``
(the University of Minnesota UAS Lab's Ultra Stick 25e with its OpenFlight aerodynamics, without propulsion;
``UltraStick25e_glide`` also accepted; the twenty-second session's) and ``ka350`` (a JSBSim Beechcraft King Air 350
twin turboprop from a FlightGear package, engines removed, gear up, at 8000 ft; ``KingAir350_glide`` also accepted;
the twenty-third session's) and ``s23`` (JSBSim's Short S.23 flying boat, engines removed, at 6000 ft;
``ShortS23_glide`` also accepted; the twenty-fourth session's) and ``dr1`` (JSBSim's Fokker Dr.I triplane, rotary
engine removed, at 8000 ft; ``Dr1_glide`` also accepted; the twenty-fifth session's) and ``navion`` (JSBSim's Ryan
Navion, the wheel's ``L17``, engine removed, gear up, at 10000 ft; ``Navion_glide`` also accepted; the twenty-sixth
session's). ``fokker50`` (JSBSim's Fokker 50 twin-turboprop airliner, engines, propwash terms and yaw damper
removed, gear up, at 10000 ft; ``Fokker50_glide`` also accepted) is the held-out, untouched one: never in the default
list, evaluated once after the thresholds are frozen.
A flight already in ``--work``, flown by the same harness with the same configuration, is reused
(``make_flight(reuse=True)``: ``<stem>-flight.json`` records the configuration and the harness fingerprint);
``--fly-only`` flies (or finds) the flights there and stops. Results are appended as JSON lines to ``--json`` when
given.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.eval_common import (AIRCRAFT_HELP, append_jsonl, pair_correlations,  # noqa: E402
                                    truth_residual_correlation)
from benchmarks.jsbsim_harness import (UNTOUCHED_AIRCRAFT, FlightConfig, coefficient_errors,  # noqa: E402
                                       load_truth, make_flight)
from benchmarks.jsbsim_harness.aircraft import aircraft_argument, summary_label  # noqa: E402
from gcs_sysid.aero.table import COEFFICIENTS  # noqa: E402
from gcs_sysid.pipeline import (ReplayOptions, replay_air_pitch, replay_beta_gls, replay_gust_rates,  # noqa: E402
                               run_replay)
import gcs_sysid.pipeline as _pipeline  # noqa: E402

THESIS_FORCES, THESIS_MOMENTS = 19.8, 23.8


def _errs(est: np.ndarray, ref: np.ndarray) -> dict[str, float]:
    return coefficient_errors(est, ref)


def _coverage(mean, sigma, ref) -> float:
    m = np.isfinite(mean) & np.isfinite(sigma) & np.isfinite(ref)
    return float(100.0 * np.mean(np.abs(mean[m] - ref[m]) <= 1.96 * sigma[m])) if m.any() else float("nan")


def _pct(ref):
    """``var (N, 6) -> [6 floats]``: the RMS over the rows of a term's sigma, % of the truth's RMS per coefficient."""
    scale = 100.0 / np.sqrt(np.mean(np.asarray(ref) ** 2, axis=0))
    return lambda v: (scale * np.sqrt(np.nanmean(np.broadcast_to(v, np.shape(ref)), axis=0))).round(3).tolist()


def exact_band_terms(model, X_true, ref) -> dict[str, list[float]]:
    """The band at exact conditions ``X_true`` taken apart (:func:`band_terms`' ``true`` entry): ``latent``,
    ``offset`` (``v_off``), ``scale`` (``v_scale``, inputs without a map), ``map`` (``v_map``, the stated linear errors
    of the aided angles and, since the sixty-fourth session, the yaw rate), ``discrepancy`` (``d``) and ``sigma``
    (their sum), % of the truth's RMS per coefficient (``X_true`` ``(N, D)`` finite, ``ref`` ``(N, 6)``)."""
    from dataclasses import replace

    from gcs_sysid.gp.discrepancy import exact_condition_variance

    ys2 = model.scaler.y_std ** 2
    pct = _pct(ref)
    Xts = model.scaler.x(np.asarray(X_true))
    _, lat_t = model.predict(X_true, include_noise=False, input_noise=False, model_error=False)
    # each term alone, by the model's own formula (gcs_sysid.gp.discrepancy.exact_condition_variance)
    Mc = model.map_cov
    mapped = np.zeros(model.n_inputs, bool) if Mc is None else np.any(np.asarray(Mc) != 0, axis=(1, 2))
    sv = None if model.scale_var is None else np.where(mapped, 0.0, np.asarray(model.scale_var))   # the map holds those
    bare = replace(model, offset_cov=None, scale_var=None, map_cov=None, discrepancy=None)
    alone = lambda **kw: exact_condition_variance(replace(bare, **kw), Xts) * ys2                 # noqa: E731
    off, vsc, vmap = alone(offset_cov=model.offset_cov), alone(scale_var=sv), alone(map_cov=Mc)
    d = np.zeros(model.n_outputs) if model.discrepancy is None else np.asarray(model.discrepancy)[0] * ys2
    return {"latent": pct(lat_t), "offset": pct(off), "scale": pct(vsc), "map": pct(vmap), "discrepancy": pct(d),
            "sigma": pct(lat_t + off + vsc + vmap + d[None, :])}


def band_terms(model, X, X_true, x_var, ref) -> dict[str, dict[str, list[float]]]:
    """The two scored bands taken apart: each variance term's size per coefficient (a diagnosis).

    ``gp`` (the replay's ``<C>_sigma`` at the flight's estimated regressors ``X``, ``docs/gp.md``, "Two
    bands"): ``latent`` (what more data can reduce), ``input_learned`` (NIGP's learned input noise through
    the slope, McHutchon and Rasmussen 2011, eq. 4), ``input`` (the term as used: per row and regressor the
    larger of the learned and the estimator's stated variance ``x_var``), ``coloured`` (the observation noise
    less its white part, ``noise_var(white_noise=False)``), ``white`` (the white part, left out of the band)
    and ``sigma`` (the band: ``latent + input + coloured``). ``true`` (the band at exact conditions
    ``X_true``, ``docs/gp.md``, "The band at exact conditions"): :func:`exact_band_terms`. Each entry is the RMS
    over the rows of the term's standard deviation, ``100 sqrt(mean(var)) / RMS(ref)``: the coefficient errors' unit
    (``row["gp"]``, ``row["true"]``), so a band whose ``sigma`` is well above the error over-covers.

    Args:
        model: the replay's saved :class:`gcs_sysid.gp.LocalGlobalGP` (six outputs).
        X, X_true: ``(N, D)`` the estimated and the true regressors of the scored rows (finite; ``D`` the model's
            inputs: 11 with ``alpha_dot_hat``).
        x_var: ``(N, 10)`` the estimator's stated per-row regressor variances (``CoefficientTable.x_var``) or None.
        ref: ``(N, 6)`` the true coefficients.

    Returns:
        ``{"gp": {term: [6 floats]}, "true": {term: [6 floats]}}``, % of the truth's RMS per coefficient.
    """
    ys2 = model.scaler.y_std ** 2
    pct = _pct(ref)
    Xs = model.scaler.x(np.asarray(X))
    if x_var is not None and model.n_mean_only:          # nothing stated for the mean-only inputs
        x_var = model.full_inputs(x_var, "x_var", np.nan)
    xv_s = None if x_var is None else np.where(model.scaler.active, np.asarray(x_var) / model.scaler.x_std ** 2, np.nan)
    _, lat = model.predict(X, include_noise=False, input_noise=False, model_error=False)
    learned = model.input_variance_s(Xs) * ys2
    inp = model.input_variance_s(Xs, xv_s) * ys2
    col = model.noise_var(white_noise=False)
    gp = {"latent": pct(lat), "input_learned": pct(learned), "input": pct(inp), "coloured": pct(col),
          "white": pct(model.noise_var() - col), "sigma": pct(lat + inp + col[None, :])}
    return {"gp": gp, "true": exact_band_terms(model, X_true, ref)}


def true_alpha_dot(truth) -> np.ndarray:
    """JSBSim's ``aero/alphadot-rad_sec`` rebuilt from the truth file, ``(T,)`` rad/s on ``truth.t``:
    ``(u_a w_dot - w_a u_dot) / (u_a^2 + w_a^2)`` with ``u_dot w_dot`` the time derivative of the body-axis
    ground velocity (``velocities/u-fps``, ``w-fps``; FGAuxiliary's ``vUVWdot``) and ``u_a w_a`` from the
    true airspeed and air angles (central differences at the truth's rate)."""
    f = truth.fields
    ud, wd = np.gradient(f["u"], truth.t), np.gradient(f["w"], truth.t)
    ua = f["V"] * np.cos(f["alpha"]) * np.cos(f["beta"])
    wa = f["V"] * np.sin(f["alpha"]) * np.cos(f["beta"])
    return (ua * wd - wa * ud) / (ua**2 + wa**2)


def aero_reads_air_rates(aircraft: str) -> dict[str, bool]:
    """Per body axis ``p q r``: does the stock model's XML read the air-relative rate
    (``velocities/p-aero-rad_sec``...)? c172x and SGS do; pa28 reads ``velocities/p-rad_sec`` (the
    body rates over the Earth; the truth's inertial rates differ from them by the Earth rate only)."""
    from benchmarks.jsbsim_harness import aircraft as spec_of
    from benchmarks.jsbsim_harness.effects import stock_model_dir

    spec = spec_of(aircraft)
    xml = (stock_model_dir(spec) / f"{spec.model}.xml").read_text()
    return {ax: f"velocities/{ax}-aero-rad_sec" in xml for ax in "pqr"}


#: ``--stated-lift-slope``: ``{aircraft: (CL_alpha, CL_q)}`` written into a copy of the airframe file that the replay
#: and the least-squares fit read (:func:`stated_airframe`); empty: the harness's airframe file as it is
STATED_AERO: dict[str, tuple[float, float | None]] = {}
#: ``--stated-lift-level``: ``{aircraft: {"CL_alpha", "CL_q", "CL_delta_e", "CL0", "CL0_sigma"}}`` written into the same
#: copy (:func:`stated_airframe`; ``CL_alpha`` and ``CL_q`` from :data:`STATED_AERO` where both are given)
STATED_LINE: dict[str, dict[str, float]] = {}


def parse_stated_line(items: list[str]) -> dict[str, dict[str, float]]:
    """``--stated-lift-level`` items ``AC:CL_ALPHA:CL_Q:CL_DE:CL0[:CL0_SIGMA]`` -> :data:`STATED_LINE` entries.

    Raises:
        SystemExit: an item without the four numbers after the aircraft, or with a number that does not parse.
    """
    out = {}
    keys = ("CL_alpha", "CL_q", "CL_delta_e", "CL0", "CL0_sigma")
    for item in items:
        ac_, *vals = item.split(":")
        if not 4 <= len(vals) <= 5:
            raise SystemExit(f"--stated-lift-level {item!r}: needs AC:CL_ALPHA:CL_Q:CL_DE:CL0[:CL0_SIGMA]")
        try:
            out[ac_] = {k: float(v) for k, v in zip(keys, vals)}
        except ValueError as exc:
            raise SystemExit(f"--stated-lift-level {item!r}: {exc}") from None
    return out


def apply_aiding_options(a: argparse.Namespace) -> None:
    """Set the air-angle aiding's module switches from the options this script and ``eval_jsbsim_diagnose.py`` share
    (each only where given; the package's defaults otherwise).

    Args:
        a: the parsed command line: ``stated_lift_slope`` (items ``AC:CL_ALPHA[:CL_Q]``: :data:`STATED_AERO` and
            ``airangles.STATED_LIFT_SLOPE`` on), ``stated_lift_level`` (:func:`parse_stated_line` items:
            :data:`STATED_LINE` and ``airangles.STATED_LIFT_LEVEL`` on), ``alpha_profile`` (column names:
            ``airangles.ALPHA_PROFILE_COLUMNS``), ``beta_profile_min_lr`` where the script has it
            (``airangles.BETA_PROFILE_MIN_LR``) and the ``on``/``off`` switches ``beta_profile``, and where the
            script has them ``kinematic_mean`` and ``floor_drops_curvature`` (``airangles.BETA_PROFILE``,
            ``KINEMATIC_MEAN``, ``FLOOR_DROPS_CURVATURE``), ``beta_gls`` (``airangles.BETA_GLS``), ``wind_window`` (s:
            ``estimate.WIND_WINDOW_S``) and the ``on``/``off`` switch ``wind_residual_scale``
            (``estimate.WIND_RESIDUAL_SCALE``).

    Raises:
        SystemExit: a ``--stated-lift-level`` item does not parse. ValueError: a ``--stated-lift-slope`` value is
            not a number.
    """
    from gcs_sysid.estimation import airangles as _aa

    if a.stated_lift_slope is not None:
        _aa.STATED_LIFT_SLOPE = True
        for item in a.stated_lift_slope:
            ac_, *vals = item.split(":")
            STATED_AERO[ac_] = (float(vals[0]), float(vals[1]) if len(vals) > 1 else None)
    if a.stated_lift_level is not None:
        _aa.STATED_LIFT_LEVEL = True
        STATED_LINE.update(parse_stated_line(a.stated_lift_level))
    if a.alpha_profile is not None:
        _aa.ALPHA_PROFILE_COLUMNS = tuple(a.alpha_profile)
    for option, flag in (("kinematic_mean", "KINEMATIC_MEAN"), ("floor_drops_curvature", "FLOOR_DROPS_CURVATURE"),
                         ("beta_profile", "BETA_PROFILE"), ("beta_gls", "BETA_GLS")):
        if getattr(a, option, None) is not None:
            setattr(_aa, flag, getattr(a, option) == "on")
    if getattr(a, "beta_profile_min_lr", None) is not None:
        _aa.BETA_PROFILE_MIN_LR = a.beta_profile_min_lr
    if getattr(a, "wind_window", None) is not None:
        from gcs_sysid.estimation import estimate as _est

        _est.WIND_WINDOW_S = float(a.wind_window)
    if getattr(a, "wind_residual_scale", None) is not None:
        from gcs_sysid.estimation import estimate as _est

        _est.WIND_RESIDUAL_SCALE = a.wind_residual_scale == "on"


def stated_airframe(path: Path, work: Path, stem: str) -> Path:
    """The airframe file the replay reads: ``path`` itself, or with ``--stated-lift-slope`` a copy
    ``work/<stem>-airframe-stated.toml`` with ``[aero] CL_alpha`` (and ``CL_q``) appended (the flight's fingerprint
    reads the harness's own file, so the flights are reused; ``docs/estimation.md``, "The lift-slope floor as a fixed
    point")."""
    name = Path(path).stem.removeprefix("jsbsim-")
    if name not in STATED_AERO and name not in STATED_LINE:
        return path
    vals = dict(STATED_LINE.get(name, {}))
    if name in STATED_AERO:
        vals["CL_alpha"], clq = STATED_AERO[name]
        vals.pop("CL_q", None)
        if clq is not None:
            vals["CL_q"] = clq
    out = Path(work) / f"{stem}-airframe-stated.toml"
    out.write_text(Path(path).read_text() + "\n[aero]\n" + "".join(f"{k} = {v!r}\n" for k, v in vals.items()))
    return out


def evaluate(aircraft: str, seed: int, turbulence: str, aoa: str, duration: float, work: Path,
             gust_rates: str | None = None, gust_filter: bool | str | None = None,
             heldout_air_roll: str | None = None, airp_lines: tuple[str, ...] = (),
             air_roll_train: bool | None = None, gp_seed: int = 0, beta_gls: bool | None = None,
             air_yaw: bool | None = None, rate_errors: bool | None = None, air_pitch: bool | None = None) -> dict:
    """One flight scored (see the module docstring); returns a JSON-able dict. ``gust_rates``: the
    replay's and the fit's ``p_hat q_hat r_hat`` relative to the air (``ReplayOptions.gust_rates``; None: the
    replay's default, :data:`gcs_sysid.pipeline.REPLAY_GUST_RATES`, given to the fit too, so that both models are
    learned on the same rates). ``beta_gls``: ``ReplayOptions.beta_gls`` (None: the aiding's module switch,
    ``airangles.BETA_GLS``), given to the fit too (``run_fit(gls_beta=)``: both models on the replay's sideslip, which
    they are scored at). ``air_yaw``: ``ReplayOptions.air_yaw`` (None: the default, off). ``rate_errors``:
    ``ReplayOptions.rate_errors`` (None: the default; the band at exact conditions only). ``air_pitch``:
    ``ReplayOptions.air_pitch`` (None: the default, :data:`gcs_sysid.aero.airpitch.AIR_PITCH`); the least-squares line
    (``run_fit(air_pitch=)``) is fitted at the same kind of ``q_hat`` as the replay's (since the sixty-ninth session;
    before, at the gyro's either way) and scored at the replay's held-out regressors; rows say it in ``ls_air_pitch``.
    ``true`` scores the model at the true regressors with the inertial rates (as the truth file
    keeps them), ``true_air`` with the rates the aircraft's JSBSim aerodynamics reads (air-relative
    ``p_aero q_aero r_aero`` on the axes where its XML reads ``p-aero`` etc., :func:`aero_reads_air_rates`;
    what a simulator using the model would give it). ``gust_filter``: ``ReplayOptions.gust_filter`` (None: the
    default). ``heldout_air_roll``: ``ReplayOptions.heldout_air_roll`` (None: the default). ``air_roll_train``:
    ``ReplayOptions.air_roll_train`` (None: the default). ``gp_seed``: ``ReplayOptions.gp_seed`` (the GP fit's
    ``GPConfig.seed``; 0, the default, as before the option existed). ``airp_lines``: modes of
    :func:`gcs_sysid.aero.gustfilter.heldout_air_roll` scored post hoc on the same replay's model (rows
    ``gp_airp_MODE``, ``ls_airp_MODE``, ``cov_gp_airp_MODE`` and ``airp_MODE`` with the estimated gust against
    JSBSim's ``p - p_aero``; a diagnosis: the replay's table must not be gust-filtered)."""
    from gcs_sysid.aero import rateerrors as _rateerrors
    from gcs_sysid.diagnose import run_fit
    from gcs_sysid.gp import load_gp

    t0 = time.perf_counter()
    files = make_flight(FlightConfig(aircraft, duration_s=duration, turbulence=turbulence, seed=seed), work, aoa=aoa,
                        reuse=True)     # a flight already in ``work`` from the same harness and configuration
    t_fly = time.perf_counter() - t0
    truth = load_truth(files.truth)
    out = work / f"{files.tlog.stem}-replay"
    af_path = stated_airframe(files.airframe, work, files.tlog.stem)     # files.airframe unless --stated-lift-slope
    opts = ReplayOptions(progress=False, gust_rates=gust_rates, beta_gls=beta_gls, air_yaw=air_yaw,
                         rate_errors=rate_errors, air_pitch=air_pitch,
                         gust_filter=gust_filter, heldout_air_roll=heldout_air_roll, air_roll_train=air_roll_train,
                         gp_seed=gp_seed)
    gust_rates = replay_gust_rates(opts)      # the frame the replay used (None: the gyro's rates), for the fit too
    res = run_replay(files.tlog, af_path, out, opts)
    t_replay = time.perf_counter() - t0 - t_fly
    tab, held = res.table, res.held_out
    Xt, Yt = truth.at(tab.t)
    Xt_air = Xt.copy()            # the true regressors with the rates JSBSim's aerodynamics reads
    cst = truth.meta["constants"]
    ip = lambda k: np.interp(tab.t, truth.t, truth.fields[k], left=np.nan, right=np.nan)  # noqa: E731
    air_axes = aero_reads_air_rates(aircraft)
    for j, (ax, ref) in enumerate(zip("pqr", ("b", "c", "b"))):
        if air_axes[ax]:
            Xt_air[:, 2 + j] = ip(f"{ax}_aero") * cst[ref] / (2 * Xt[:, 9])
    ok = tab.valid & np.isfinite(Yt).all(1)
    h = held & ok
    row: dict = {"aircraft": aircraft, "seed": seed, "turbulence": turbulence, "aoa": aoa, "duration_s": duration,
                 "gust_rates": gust_rates, "beta_gls": replay_beta_gls(opts), "air_yaw": air_yaw,
                 "rate_errors": _rateerrors.RATE_ERRORS if rate_errors is None else rate_errors,
                 "air_pitch": replay_air_pitch(opts),
                 "air_pitch_note": next((n for n in res.table.notes if "pitch gust" in n), None),
                 "gust_filter": gust_filter,
                 "heldout_air_roll": heldout_air_roll, "air_roll_train": air_roll_train, "gp_seed": gp_seed,
                 "cy_rate_prior": _pipeline.SIDE_FORCE_RATE_PRIOR_STD,
                 "n_heldout": int(h.sum()), "t_fly_s": round(t_fly, 1), "t_replay_s": round(t_replay, 1)}
    row["meas"] = _errs(tab.Y[h], Yt[h])
    row["meas_all"] = _errs(tab.Y[ok], Yt[ok])
    # diagnosis: the measured coefficients again with JSBSim's angular accelerations in the states
    from gcs_sysid.aero import compute_coefficients
    from gcs_sysid.airframe import load_airframe

    st = res.states
    saved = {k: st.data[k] for k in ("p_dot", "q_dot", "r_dot")}
    for k in saved:
        st.data[k] = np.interp(st.t, truth.t, truth.fields[k])
    tab_acc = compute_coefficients(st, load_airframe(files.airframe))
    st.data.update(saved)
    row["meas_true_accel"] = _errs(tab_acc.Y[ok], Yt[ok])
    rms = np.sqrt(np.mean(Yt[h] ** 2, axis=0))
    row["meas_offset"] = {c: float(100.0 * np.mean(tab.Y[h, i] - Yt[h, i]) / rms[i])
                          for i, c in enumerate(COEFFICIENTS)}
    from gcs_sysid.estimation import estimate_states
    from gcs_sysid.telemetry import read_log

    af = load_airframe(files.airframe)
    tab_flat = compute_coefficients(estimate_states(read_log(files.tlog), af, earth="flat"), af)
    row["meas_flat"] = _errs(tab_flat.Y[h], Yt[h])
    row["gp"] = _errs(res.pred_mean[h], Yt[h])
    # the coefficient's band (no white measurement noise; the truth carries none) and a measurement's band
    row["cov_gp"] = float(np.nanmean([_coverage(res.pred_mean[h, i], res.pred_sigma[h, i], Yt[h, i])
                                      for i in range(6)]))
    row["cov_gp_obs"] = float(np.nanmean([_coverage(res.pred_mean[h, i], res.pred_sigma_obs[h, i], Yt[h, i])
                                          for i in range(6)]))
    row["cov_gp_obs_each"] = [_coverage(res.pred_mean[h, i], res.pred_sigma_obs[h, i], Yt[h, i]) for i in range(6)]
    model = load_gp(Path(res.model_path))
    if hasattr(model, "output_correlation"):
        # the largest learned correlation between two outputs' latent parts (issue 8: none above 0.5 where the
        # truth has none); gcs_sysid.pipeline.GP_COUPLING_TEST "lr" (the default) drops B's couplings the data
        # do not support
        C = np.abs(np.asarray(model.output_correlation(), float))
        np.fill_diagonal(C, 0.0)
        row["max_corr"] = float(np.nanmax(C)) if C.size else 0.0
        # the pairs, and the truth's own coupling beyond a linear model (issue 8's "where the truth has none")
        row["corr_pairs"] = pair_correlations(C, model.output_names)
        row["truth_resid_corr"] = truth_residual_correlation(Xt_air, Yt, res.train & ok)
        row["gp_coupling_test"] = _pipeline.GP_COUPLING_TEST
        row["gp_noise_correlation"] = _pipeline.GP_NOISE_CORRELATION
        row["gp_noise_posterior"] = _pipeline.GP_NOISE_POSTERIOR
        row["gp_noise_start"] = _pipeline.GP_NOISE_START
    if model.discrepancy is not None and model.n_outputs == 6:
        # a diagnosis, not a criterion: the coefficient band with its coloured noise share floored at the
        # blocked validation's discrepancy d (as at exact conditions)
        d = np.asarray(model.discrepancy)[0] * model.scaler.y_std**2
        col = model.noise_var(white_noise=False)
        sd = np.sqrt(res.pred_sigma[h] ** 2 + np.maximum(d - col, 0.0)[None, :])
        row["cov_gp_dfloor"] = float(np.nanmean([_coverage(res.pred_mean[h, i], sd[:, i], Yt[h, i]) for i in range(6)]))
    Xg = tab.X
    if model.n_mean_only:      # alpha_dot_hat, a mean-only input of Cm: the truth's own and the estimate
        adt = np.interp(tab.t, truth.t, true_alpha_dot(truth)) * cst["c"] / (2 * Xt[:, 9])
        Xt, Xt_air = np.c_[Xt, adt], np.c_[Xt_air, adt]
        ade = np.nan_to_num(np.asarray(tab.alpha_dot_hat, float))
        Xg = np.c_[tab.X, ade]
        ok_a = ok & np.isfinite(adt)
        row["alpha_dot_hat"] = {"rms": float(np.std(adt[ok_a])),
                                "err_pct": float(100 * np.sqrt(np.mean((ade[ok_a] - adt[ok_a]) ** 2))
                                                 / np.std(adt[ok_a])),
                                "corr": float(np.corrcoef(ade[ok_a], adt[ok_a])[0, 1])}
    mt, vt = model.predict(Xt[h], include_noise=False, input_noise=False)   # exact regressors
    row["true"] = _errs(np.asarray(mt), Yt[h])
    ma, va = model.predict(Xt_air[h], include_noise=False, input_noise=False)
    row["true_air"] = _errs(np.asarray(ma), Yt[h])
    row["cov_true_air"] = float(np.nanmean([_coverage(np.asarray(ma)[:, i], np.sqrt(np.asarray(va)[:, i]), Yt[h, i])
                                            for i in range(6)]))
    row["cov_true_air_each"] = [_coverage(np.asarray(ma)[:, i], np.sqrt(np.asarray(va)[:, i]), Yt[h, i])
                                for i in range(6)]
    row["cov_true"] = float(np.nanmean([_coverage(np.asarray(mt)[:, i], np.sqrt(np.asarray(vt)[:, i]), Yt[h, i])
                                        for i in range(6)]))
    row["cov_true_each"] = [_coverage(np.asarray(mt)[:, i], np.sqrt(np.asarray(vt)[:, i]), Yt[h, i]) for i in range(6)]
    # the latent band alone (before the model-error term, docs/gp.md "The band at exact conditions")
    _, vl = model.predict(Xt[h], include_noise=False, input_noise=False, model_error=False)
    row["cov_true_latent"] = float(np.nanmean([_coverage(np.asarray(mt)[:, i], np.sqrt(np.asarray(vl)[:, i]), Yt[h, i])
                                               for i in range(6)]))
    row["cov_gp_each"] = [_coverage(res.pred_mean[h, i], res.pred_sigma[h, i], Yt[h, i]) for i in range(6)]
    if model.n_outputs == 6:      # the bands' variance terms per coefficient (a diagnosis, docs/gp.md)
        row["band_terms"] = band_terms(model, Xg[h], Xt[h], None if tab.x_var is None else tab.x_var[h], Yt[h])
        # the band at exact conditions with the aerodynamics' rates (``tair``, ``cov_true_air``), term by term
        row["band_terms_air"] = exact_band_terms(model, Xt_air[h], Yt[h])
    t_cut = float(tab.t[h][0])
    # the LS line on the replay's own sideslip estimator (the two models are scored at the replay's regressors;
    # `gcs-sysid fit` alone keeps least squares' CY_beta by default, gcs_sysid.diagnose.run.BETA_PROFILE)
    from gcs_sysid.estimation import airangles as _aa

    row["ls_air_pitch"] = replay_air_pitch(opts)     # the replay's kind of q_hat: the same data as the GP
    ls_model, _ = run_fit(files.tlog, af_path, work / f"{files.tlog.stem}-fit.toml", t_to=t_cut,
                          gust_rates=gust_rates, profile_beta=_aa.BETA_PROFILE, gls_beta=replay_beta_gls(opts),
                          air_roll_train=False,     # the measured Cl, as issue 8's records were (not the diagnosis's)
                          air_pitch=row["ls_air_pitch"])
    row["ls"] = _errs(ls_model.evaluate(tab.X[h]), Yt[h])
    from gcs_sysid.aero.gustfilter import AIR_ROLL_TRAIN, HELDOUT_AIR_ROLL

    if (AIR_ROLL_TRAIN and not gust_filter) if air_roll_train is None else air_roll_train:
        row.update(ls_air_target_scores(res, af, h, Yt, ls_model,
                                        HELDOUT_AIR_ROLL if heldout_air_roll is None else heldout_air_roll))
    row["alpha_deg"] = float(np.degrees(np.sqrt(np.mean((tab.X[ok, 0] - Xt[ok, 0]) ** 2))))
    row["beta_deg"] = float(np.degrees(np.sqrt(np.mean((tab.X[ok, 1] - Xt[ok, 1]) ** 2))))
    row["alpha_rms_deg"] = float(np.degrees(np.std(Xt[ok, 0])))
    row["beta_rms_deg"] = float(np.degrees(np.sqrt(np.mean(Xt[ok, 1] ** 2))))
    row["cy_diag"] = cy_diagnosis(tab.X[h], Xt_air[h], np.asarray(ma)[:, 1], Yt[h, 1])
    if airp_lines:
        g_true = (ip("p") - ip("p_aero")) * cst["b"] / (2 * Xt[:, 9])
        row.update(airp_scores(res, model, af, h, Yt, g_true, ls_model, airp_lines))
    return row


def ls_air_target_scores(res, airframe, h: np.ndarray, Yt: np.ndarray, ls_model, mode: str) -> dict:
    """The least-squares line with Cl trained on the target the replay's GP was given with ``air_roll_train``
    (:func:`gcs_sysid.aero.gustfilter.air_roll_target`: the measured Cl less the training rows' smoothed gust
    moment) and asked, as the GP's Cl is, at the held-out rows' air-relative roll rate of ``mode``
    (:func:`gcs_sysid.aero.gustfilter.heldout_air_roll`; ``"off"``: the gyro's). A fair GP < LS for Cl: the
    ``ls`` line (``gcs-sysid fit``) is trained on the measured Cl at the gyro's rate, whose gust moment the GP's
    target no longer holds. The stepwise fit is :func:`gcs_sysid.diagnose.fit.fit_model` (``gcs-sysid fit``'s pool
    and thresholds) on the replay's own table and training rows; the other coefficients keep ``ls_model``'s.

    Returns:
        ``ls_airtrain`` (the fair line) and ``ls_airtab`` (the same fit on the measured Cl, asked at the same rate:
        what the replay's table rather than ``gcs-sysid fit``'s own changes), % errors per coefficient on ``h``;
        ``ls_airtrain_applied`` False when the roll fit was refused (the target is then the measured Cl).
    """
    tab, i = res.table, COEFFICIENTS.index("Cl")
    X_air, Y2, tinfo = air_rate_pair(res, airframe, mode)
    base = ls_model.evaluate(tab.X[h])
    out: dict = {"ls_airtrain_applied": "Cl_p" in tinfo}
    for key, Y in (("ls_airtrain", Y2), ("ls_airtab", tab.Y)):
        est = base.copy()
        est[:, i] = ls_cl_on(res, Y, X_air[h])
        out[key] = _errs(est, Yt[h])
    return out


def air_rate_pair(res, airframe, mode: str):
    """The replay's air-rate pair on one replay's table, as ``run_replay`` makes it with ``air_roll_train``: the one
    roll fit (:func:`gcs_sysid.aero.gustfilter.air_roll_fit` on the training rows, with its Dryden and instruments'
    checks), the held-out rows at the air-relative roll rate of ``mode``
    (:func:`~gcs_sysid.aero.gustfilter.heldout_air_roll`; ``"off"``: the gyro's) and the Cl training target
    (:func:`~gcs_sysid.aero.gustfilter.air_roll_target`: the measured Cl less the training rows' smoothed gust
    moment).

    Args:
        res: :class:`gcs_sysid.pipeline.ReplayResult` (table at the gyro's ``p_hat``, states, rows).
        airframe: the flight's airframe (``Ixx``, ``S``, ``b`` ...). mode: a ``HELDOUT_AIR_ROLL`` value.

    Returns:
        ``(X_air (T, 10), Y_air (T, 6), info)``: ``X_air`` and ``Y_air`` equal the table's where the fit was refused;
        ``info`` is ``air_roll_target``'s (``"Cl_p"`` in it when the fit was applied, ``"note"``).
    """
    from gcs_sysid.aero.gustfilter import air_roll_fit, air_roll_mode, air_roll_target, heldout_air_roll

    tab = res.table
    fit = air_roll_fit(tab, res.states, airframe, res.train)
    X_air = tab.X
    if air_roll_mode(mode)[0] != "off":
        X_air = heldout_air_roll(tab, res.states, airframe, res.train, res.held_out, mode=mode, fit=fit)[0].X
    Y_air, info = air_roll_target(tab, res.states, airframe, res.train, fit=fit)
    return X_air, Y_air, info


def ls_cl_on(res, Y: np.ndarray, Xq: np.ndarray) -> np.ndarray:
    """Cl ``(Q,)`` at ``Xq`` ``(Q, 10)`` from ``gcs-sysid fit``'s stepwise regression
    (:func:`gcs_sysid.diagnose.fit.fit_model`, its pool and thresholds) on the replay's table with the coefficients
    ``Y`` ``(T, 6)`` and its training rows."""
    from dataclasses import replace

    from gcs_sysid.diagnose.fit import fit_model

    m, _ = fit_model(replace(res.table, Y=Y), mask=res.train)
    return m.evaluate(Xq)[:, COEFFICIENTS.index("Cl")]


def airp_scores(res, model, airframe, h: np.ndarray, Yt: np.ndarray, g_true: np.ndarray, ls_model,
                modes: tuple[str, ...]) -> dict:
    """The held-out lines with the rows' ``p_hat`` less the rolling gust estimated there
    (:func:`gcs_sysid.aero.gustfilter.heldout_air_roll`), from one replay's table and model: ``gp_airp_MODE``,
    ``ls_airp_MODE`` (% errors per coefficient), ``cov_gp_airp_MODE`` (``_each``: per coefficient) and ``airp_MODE``
    (``corr`` and ``err_pct``, the RMS error of the estimated ``p_hat_g`` in % of JSBSim's ``(p - p_aero) b/(2V)``, on
    the held-out rows; ``sd`` the estimate's SD over the true one's; ``applied`` False when the fit or its Dryden check
    refused). Mode ``"off"`` reproduces the replay's own ``gp`` line (a check). ``gp_airp_oracle`` / ``ls_airp_oracle``:
    the same with JSBSim's own ``p_g`` taken out of the held-out rows' ``p_hat`` (reads the truth: what a perfect gust
    estimate would give; below it, the estimate is taking up the model's own error from the measured moment).

    Args:
        res: the replay's result (its table not gust-filtered). model: its GP. airframe: the loaded airframe.
        h: ``(T,)`` bool scored held-out rows. Yt: ``(T, 6)`` JSBSim's coefficients. g_true: ``(T,)``.
        ls_model: the stepwise least-squares model (``evaluate(X)``). modes: entries of
            :data:`gcs_sysid.aero.gustfilter.AIR_ROLL_MODES` (``"predicted:Cl"``: Cl at the air rate, the other
            outputs' lines at the gyro's, as the replay's per-output mode asks them).
    """
    from dataclasses import replace

    from gcs_sysid.aero.gustfilter import air_roll_mode, heldout_air_roll
    from gcs_sysid.pipeline import gp_inputs

    out: dict = {}
    tab = res.table
    fit_cols = [i for i in range(6) if np.isfinite(res.pred_mean[:, i]).any()]
    use_adot = model.n_inputs == tab.X.shape[1] + 1
    white = model.noise_var(white_noise=True) - model.noise_var(white_noise=False)
    def at(t2):
        rows = h & np.all(np.isfinite(t2.X), axis=1)
        Xq, xv = gp_inputs(t2, rows, use_adot)
        mean, var = model.predict(Xq, x_var=xv)
        pm = np.full(Yt.shape, np.nan)
        ps = np.full(Yt.shape, np.nan)
        pm[np.ix_(rows, fit_cols)] = np.asarray(mean)
        ps[np.ix_(rows, fit_cols)] = np.sqrt(np.maximum(np.asarray(var) - white[None, :], 0.0))
        return rows, pm, ps, ls_model.evaluate(t2.X[h])

    for mode in modes:
        t2, info = heldout_air_roll(tab, res.states, airframe, res.train, res.held_out, mode=mode)
        rows, pm, ps, pl = at(t2)
        outs = air_roll_mode(mode)[1]
        if outs is not None:    # per output ("MODE:Cl"): the others at the gyro's p_hat, as the replay asks them
            keep = [i for i, c in enumerate(COEFFICIENTS) if c not in outs]
            _, pm0, ps0, pl0 = at(tab)
            pm[:, keep], ps[:, keep], pl[:, keep] = pm0[:, keep], ps0[:, keep], pl0[:, keep]
        out[f"gp_airp_{mode}"] = _errs(pm[h], Yt[h])
        out[f"cov_gp_airp_{mode}_each"] = [_coverage(pm[h, i], ps[h, i], Yt[h, i]) for i in range(6)]
        out[f"cov_gp_airp_{mode}"] = float(np.nanmean(out[f"cov_gp_airp_{mode}_each"]))
        out[f"ls_airp_{mode}"] = _errs(pl, Yt[h])
        if mode != "off":
            g = np.zeros(len(h)) if info is None else info["g"]
            if mode == modes[-1] or "oracle" not in out:   # once: the model at JSBSim's own p_g (reads the truth)
                Xo = tab.X.copy()
                Xo[:, 2] -= np.where(h, np.nan_to_num(g_true), 0.0)
                to = replace(tab, X=Xo)
                mo = np.full(Yt.shape, np.nan)
                mo[np.ix_(rows, fit_cols)] = np.asarray(model.predict(gp_inputs(to, rows, use_adot)[0],
                                                                      x_var=gp_inputs(to, rows, use_adot)[1])[0])
                out["gp_airp_oracle"] = _errs(mo[h], Yt[h])
                out["ls_airp_oracle"] = _errs(ls_model.evaluate(Xo[h]), Yt[h])
            m = h & np.isfinite(g_true)
            gt, ge = g_true[m], g[m]
            out[f"airp_{mode}"] = {"applied": info is not None,
                                   "corr": float(np.corrcoef(ge, gt)[0, 1]) if np.std(ge) > 0 else 0.0,
                                   "err_pct": float(100 * np.sqrt(np.mean((ge - gt) ** 2)) / np.std(gt)),
                                   "sd": float(np.std(ge) / np.std(gt))}
    return out


#: the side-force regressors of :func:`cy_diagnosis`'s local linear fits (a diagnosis only)
CY_DIAG_COLUMNS = ("beta", "p_hat", "r_hat", "delta_a", "delta_r")


def cy_diagnosis(X_est: np.ndarray, X_true: np.ndarray, cy_model: np.ndarray, cy_true: np.ndarray) -> dict:
    """Where the model's CY error at the true conditions comes from (a diagnosis: reads the truth, scores only).

    Args:
        X_est: (N, 10) the pipeline's regressors (:data:`gcs_sysid.aero.table.REGRESSORS` order) on the held-out rows.
        X_true: (N, 10) JSBSim's regressors there (the rates its aerodynamics reads). cy_model: (N,) the model's CY
            at ``X_true``. cy_true: (N,) JSBSim's CY.

    Returns:
        ``beta_scale``, ``beta_offset_deg``, ``beta_resid_deg``: the reconstructed sideslip regressed on the true one
        (errors in variables: a scale below 1 with an error that correlates with the truth); ``CY_beta_model`` /
        ``CY_beta_true`` (1/rad) and the same for the other :data:`CY_DIAG_COLUMNS`: least-squares slopes of the
        model's and of JSBSim's CY on the true regressors (with a constant); ``err_pct``: the model's RMS error, % of
        the truth's RMS, split into ``bias_pct`` (its mean), ``linear_pct`` (what is linear in the true regressors
        beyond the mean: the slopes' errors) and ``rest_pct`` (the remainder: shape), in quadrature.
    """
    from gcs_sysid.aero.table import REGRESSORS

    idx = [REGRESSORS.index(k) for k in CY_DIAG_COLUMNS]
    ok = np.isfinite(X_est[:, 1]) & np.isfinite(X_true[:, idx]).all(1) & np.isfinite(cy_model) & np.isfinite(cy_true)
    b_e, b_t = X_est[ok, 1], X_true[ok, 1]
    G = np.c_[np.ones(ok.sum()), b_t]
    sb, *_ = np.linalg.lstsq(G, b_e, rcond=None)
    A = np.c_[np.ones(ok.sum()), X_true[ok][:, idx]]
    cm, *_ = np.linalg.lstsq(A, cy_model[ok], rcond=None)
    ct, *_ = np.linalg.lstsq(A, cy_true[ok], rcond=None)
    e = cy_model[ok] - cy_true[ok]
    rms = float(np.sqrt(np.mean(cy_true[ok] ** 2)))
    ce, *_ = np.linalg.lstsq(A, e, rcond=None)
    lin = A @ ce - np.mean(e)
    rest = e - A @ ce
    out = {"beta_scale": float(sb[1]), "beta_offset_deg": float(np.degrees(sb[0])),
           "beta_resid_deg": float(np.degrees(np.std(b_e - G @ sb))),
           "err_pct": float(100 * np.sqrt(np.mean(e ** 2)) / rms), "bias_pct": float(100 * abs(np.mean(e)) / rms),
           "linear_pct": float(100 * np.sqrt(np.mean(lin ** 2)) / rms),
           "rest_pct": float(100 * np.sqrt(np.mean(rest ** 2)) / rms)}
    for j, k in enumerate(CY_DIAG_COLUMNS):
        out[f"CY_{k}_model"], out[f"CY_{k}_true"] = float(cm[j + 1]), float(ct[j + 1])
    return out


def _fmt(d: dict) -> str:
    return " ".join(f"{d[c]:6.1f}" for c in COEFFICIENTS)


def summarize(paths: list[str]) -> str:
    """Markdown table of JSON lines written by ``--json``: per aircraft, turbulence and AOA variant,
    the median over seeds of each score (coefficient errors in %, coverage in %, air data in deg)."""
    rows = [json.loads(line) for p in paths for line in open(p) if line.strip()]
    groups: dict[tuple, list[dict]] = {}
    for r in rows:
        groups.setdefault((r["aircraft"], r["turbulence"], r["aoa"]), []).append(r)
    head = ("| aircraft | turb. | AOA_SSA | seeds | score | " + " | ".join(COEFFICIENTS)
            + " | cov95 % | alpha / beta err deg (signal) |")
    out = [head, "|" + "---|" * (head.count("|") - 1)]
    for (ac, turb, aoa), rs in groups.items():
        med = lambda k, c=None: float(np.nanmedian([r[k][c] if c else r[k] for r in rs]))   # noqa: E731
        scores = (("meas", "measured"), ("gp", "GP held-out"), ("true", "GP at true regressors"),
                  ("true_air", "GP at true regressors, aero rates"), ("ls", "stepwise LS"))
        for k, label in scores:
            if not all(k in r for r in rs):      # rows written before the score existed
                continue
            obs = f" (measurement {med('cov_gp_obs'):.0f})" if all("cov_gp_obs" in r for r in rs) else ""
            cov = {"gp": f"{med('cov_gp'):.0f}{obs}", "true": f"{med('cov_true'):.0f}",
                   "true_air": f"{med('cov_true_air'):.0f}" if all("cov_true_air" in r for r in rs) else ""}.get(k, "")
            air = (f"{med('alpha_deg'):.2f} / {med('beta_deg'):.2f} ({med('alpha_rms_deg'):.2f} / "
                   f"{med('beta_rms_deg'):.2f})") if k == "meas" else ""
            name = summary_label(ac)
            out.append(f"| {name} | {turb} | {aoa} | {len(rs)} | {label} | "
                       + " | ".join(f"{med(k, c):.1f}" for c in COEFFICIENTS) + f" | {cov} | {air} |")
    for turb in sorted({r["turbulence"] for r in rows}):
        for k, label in (("meas", "measured"), ("gp", "GP held-out"), ("true", "GP at true regressors"),
                         ("true_air", "GP at true regressors, aero rates"), ("ls", "stepwise LS")):
            rs = [r for r in rows if r["turbulence"] == turb]
            if not all(k in r for r in rs):
                continue
            f = np.nanmedian([r[k][c] for r in rs for c in COEFFICIENTS[:3]])
            m = np.nanmedian([r[k][c] for r in rs for c in COEFFICIENTS[3:]])
            out.append(f"\n{turb}, {label}: median over all flights and coefficients: forces {f:.1f} %, "
                       f"moments {m:.1f} % (thesis real flights: {THESIS_FORCES} %, {THESIS_MOMENTS} %)")
    return "\n".join(out)


def _band_output(pipeline, spec: str) -> None:
    """Set one output's stated-band regime from ``C=SPEC`` (``--band-output``); SystemExit on a bad spec."""
    name, _, how = spec.partition("=")
    if name not in COEFFICIENTS or how not in ("+1", "1", "0", "-1", "d", "white", "white-learned"):
        raise SystemExit(f"--band-output {spec!r}: expected C=SPEC with C one of {', '.join(COEFFICIENTS)} and SPEC "
                         "+1, 0, -1, d, white or white-learned")
    signs = dict(pipeline.STATED_BAND_SIGN)
    less = [c for c in pipeline.STATED_BAND_LESS_WHITE if c != name]
    learned = [c for c in pipeline.WHITE_BAND_NO_STATED_INPUT if c != name]
    signs.pop(name, None)
    if how == "white-learned":
        learned.append(name)
    elif how != "white":
        signs[name] = 0.0 if how == "d" else float(how)
        if how == "d":
            less.append(name)
    pipeline.STATED_BAND_SIGN = signs
    pipeline.STATED_BAND_LESS_WHITE = tuple(less)
    pipeline.WHITE_BAND_NO_STATED_INPUT = tuple(learned)


def main(argv=None) -> int:
    from gcs_sysid.aero.gustfilter import AIR_ROLL_MODES

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--aircraft", nargs="+", default=["c172x", "sgs", "pa28"], type=aircraft_argument,
                    help=AIRCRAFT_HELP)
    ap.add_argument("--seeds", nargs="+", type=int, default=[1])
    ap.add_argument("--turbulence", nargs="+", default=["light", "moderate"])
    ap.add_argument("--aoa", default="ahrs", choices=("ahrs", "vane"))
    ap.add_argument("--duration", type=float, default=120.0, help="logged flight time per flight, s")
    ap.add_argument("--gust-filter", default=None, choices=("on", "off", "roll", "rollgp"),
                    help="train the GP on p_hat less the filter-error p_g (ReplayOptions.gust_filter; 'on': the "
                         "measured Cl as output, 2SLS slopes; 'roll': p_g a state of the roll dynamics, "
                         "gcs_sysid.aero.rollgust; 'rollgp': the same with the moment's stated noise and the GP "
                         "given the fit's Cl slopes; default: the replay's default, "
                         "gcs_sysid.aero.gustfilter.GUST_FILTER)")
    ap.add_argument("--heldout-air-roll", default=None, choices=AIR_ROLL_MODES,
                    help="the held-out rows' p_hat less the rolling gust estimated there from their own measured roll "
                         "moment with the training rows' roll fit (ReplayOptions.heldout_air_roll, "
                         "gcs_sysid.aero.gustfilter.heldout_air_roll; default: the replay's, HELDOUT_AIR_ROLL)")
    ap.add_argument("--heldout-gust-var", default=None, choices=("fit", "moment", "rts", "nis", "innov"),
                    help="the variance under which the held-out rows' air roll rate states its error (the held-out "
                         "band of Cl; gcs_sysid.aero.gustfilter.HELDOUT_GUST_VAR; default: the package's)")
    ap.add_argument("--heldout-gust-cutoff", default=None, choices=("on", "off"),
                    help="the held-out air roll rate's stated error also carries the rolling gust's moment the rate "
                         "smoother cut off the measured Cl (gcs_sysid.aero.gustfilter.HELDOUT_GUST_CUTOFF, "
                         "gcs_sysid.aero.rollgust.gust_cutoff_variance; default: the package's)")
    ap.add_argument("--coefficient-band", default=None, choices=_pipeline.COEFFICIENT_BANDS,
                    help="the coefficient's band at the flight's own regressors (gcs_sysid.pipeline.COEFFICIENT_BAND; "
                         "'stated': gcs_sysid.gp.coefband; default: the package's)")
    ap.add_argument("--band-output", action="append", default=[], metavar="C=SPEC",
                    help="with the stated band, one output's regime (edits gcs_sysid.pipeline.STATED_BAND_SIGN and "
                         "STATED_BAND_LESS_WHITE for this run): SPEC +1, 0 or -1 (the sign of the stated error), d "
                         "(the discrepancy: the residual less its white nugget), white (the white band) or "
                         "white-learned (the white band without the stated regressor variances); repeatable")
    ap.add_argument("--air-roll-train", default=None, choices=("on", "off"),
                    help="train the GP's Cl on the measured Cl less the roll fit's rolling-gust moment, Cl at the "
                         "air-relative roll rate (ReplayOptions.air_roll_train, gcs_sysid.aero.gustfilter."
                         "air_roll_target; pair with --heldout-air-roll predicted:Cl; default: the replay's, "
                         "AIR_ROLL_TRAIN)")
    ap.add_argument("--airp-lines", nargs="*", default=(), choices=AIR_ROLL_MODES,
                    help="also score these heldout_air_roll modes post hoc on the same replay's model (rows "
                         "gp_airp_MODE, ls_airp_MODE, cov_gp_airp_MODE, airp_MODE; a diagnosis)")
    ap.add_argument("--gust-rates", default=None, choices=("path", "path-yaw", "mean-wind", "inertial"),
                    help="p_hat q_hat r_hat relative to the air with this gust-rate frame, or the gyro's ('inertial'), "
                         "for the replay and the fit (default: the replay's, gcs_sysid.pipeline.REPLAY_GUST_RATES)")
    ap.add_argument("--gp-fit", default=None, choices=("default", "decorrelated", "untested"),
                    help="the replay's GP settings: 'decorrelated' sets gcs_sysid.pipeline.USE_DECORRELATED_GP "
                         "(hyperparameters on rows a decorrelation time apart, coupling off; docs/gp.md); "
                         "'untested' sets gcs_sysid.pipeline.GP_COUPLING_TEST = 'none' (B's couplings kept as "
                         "learned, without the every-row likelihood-ratio test: the default until the twenty-second "
                         "session)")
    ap.add_argument("--gp-noise", default=_pipeline.GP_NOISE, choices=tuple(_pipeline.GP_NOISE_MODES),
                    help="the replay GP's noise (gcs_sysid.pipeline.GP_NOISE_MODES; sets GP_NOISE_CORRELATION, "
                         "GP_NOISE_POSTERIOR, GP_NOISE_START): 'learned' (the default since the twenty-fifth session) "
                         "a P x P noise covariance learned with the hyperparameters, only its diagonal in the "
                         "posterior; "
                         "'independent' one variance per output (the default until the twenty-fifth session; "
                         "'diagonal' is its older name); 'full' the learned covariance in the posterior too "
                         "(eval_gp_jsbsim's nigp); 'full-nstart' full with the shared error started in the noise; "
                         "default %(default)s")
    ap.add_argument("--cy-rate-prior", default=None, metavar="STD|off",
                    help="a zero-mean prior of this std (0: the slopes fixed at 0) on CY's p_hat and r_hat slopes, by "
                         "mixed estimation on the GP's target (gcs_sysid.pipeline.SIDE_FORCE_RATE_PRIOR_STD); 'off': "
                         "none; default: the package's default")
    ap.add_argument("--gp-seed", type=int, default=0,
                    help="the replay GP's seed (ReplayOptions.gp_seed, GPConfig.seed: the hyperparameters' row subset "
                         "and the inducing points); issue 8's counts are judged at seeds 0 and 1 "
                         "(benchmarks/issue8_counts.py); default %(default)s")
    ap.add_argument("--json", default=None, help="append one JSON line per flight to this file")
    ap.add_argument("--work", default=None, help="keep the flights and replays here (default: a temp dir)")
    ap.add_argument("--summarize", nargs="+", default=None, metavar="JSONL",
                    help="only print the markdown table of earlier --json results (medians over seeds)")
    ap.add_argument("--iv-beta", default=None, choices=("off", "r2", "f", "fuller"),
                    help="the side-force slopes: least squares (off), 2SLS with the first-stage R2 floor (r2: "
                         "INSTRUMENTED_BETA), or 2SLS where the effective-sample first-stage F passes (f: "
                         "BETA_WEAK_TEST='f'), or Fuller's k-class on every flight (fuller); default: the package's "
                         "defaults")
    ap.add_argument("--beta-profile", default=None, choices=("on", "off"),
                    help="CY_beta of the replay's sideslip aiding by the gust model's likelihood, held in the later "
                         "passes (gcs_sysid.estimation.airangles.BETA_PROFILE; default: the package's, off since the "
                         "thirty-third session; the LS line is fitted with the same estimator)")
    ap.add_argument("--beta-profile-min-lr", default=None, type=float, metavar="LR",
                    help="take the profiled CY_beta only where its likelihood-ratio statistic against least squares' "
                         "slope reaches LR (3.84: the chi-squared 95 %% point; gcs_sysid.estimation.airangles."
                         "BETA_PROFILE_MIN_LR; default: the package's, no test)")
    ap.add_argument("--beta-gls", default=None, choices=("on", "off"),
                    help="the side-force model's slopes of the sideslip aiding by generalised least squares under the "
                         "gust model, held in the later passes (the replay's ReplayOptions.beta_gls and "
                         "gcs_sysid.estimation.airangles.BETA_GLS, and the least-squares line's fit; default: the "
                         "package's, off)")
    ap.add_argument("--air-yaw", default=None, choices=("on", "off"),
                    help="AIR_YAW_OUTPUTS (Cn) trained at the air-relative yaw rate (ReplayOptions.air_yaw, "
                         "gcs_sysid.aero.airyaw; default: the replay's, off)")
    ap.add_argument("--air-yaw-outputs", nargs="+", default=None, choices=("Cl", "Cn"),
                    help="with --air-yaw on: the outputs trained and asked at the air-relative yaw rate "
                         "(gcs_sysid.aero.airyaw.AIR_YAW_OUTPUTS; default: the package's, Cn)")
    ap.add_argument("--rate-errors", default=None, choices=("on", "off"),
                    help="the gyro rates' errors in the band at exact conditions (ReplayOptions.rate_errors, "
                         "gcs_sysid.aero.rateerrors; default: the replay's)")
    ap.add_argument("--air-pitch", default=None, choices=("on", "off"),
                    help="q_hat at the air-relative estimate, less the pitch gust rate with its fitted share "
                         "(ReplayOptions.air_pitch, gcs_sysid.aero.airpitch; default: the replay's, on)")
    ap.add_argument("--fly-only", action="store_true", help="only fly (or find) the flights in --work; no scoring")
    ap.add_argument("--wind-window", default=None, type=float, metavar="S",
                    help="the wind fit's window length, s (default: the package's estimate.WIND_WINDOW_S)")
    ap.add_argument("--wind-residual-scale", default=None, choices=("on", "off"),
                    help="weight the wind fit's airspeed residuals with their own RMS (gcs_sysid.estimation.estimate."
                         "WIND_RESIDUAL_SCALE; default: the package's, on since the fortieth session)")
    ap.add_argument("--kinematic-mean", default=None, choices=("on", "off"),
                    help="keep the aided alpha's flight mean at the kinematic one (gcs_sysid.estimation.airangles."
                         "KINEMATIC_MEAN; default: the package's default, off)")
    ap.add_argument("--floor-drops-curvature", default=None, choices=("on", "off"),
                    help="leave alpha's curvature out of the floored first pass (gcs_sysid.estimation.airangles."
                         "FLOOR_DROPS_CURVATURE; default: the package's default, off)")
    ap.add_argument("--alpha-profile", nargs="*", default=None, metavar="COLUMN",
                    help="the alpha aiding's columns whose slopes the gust model's likelihood chooses (gcs_sysid."
                         "estimation.airangles.ALPHA_PROFILE_COLUMNS, e.g. delta_e; default: the package's, none)")
    ap.add_argument("--stated-lift-slope", nargs="+", default=None, metavar="AC:CL_ALPHA[:CL_Q]",
                    help="give the aiding a stated whole-aircraft lift slope (1/rad) and pitch-rate lift (per q_hat) "
                         "per aircraft, e.g. s23:5.5:7.1 (the airframe's [aero] table; gcs_sysid.estimation.airangles."
                         "STATED_LIFT_SLOPE on; default: off, the wing's floor)")
    ap.add_argument("--stated-lift-level", nargs="+", default=None, metavar="AC:CL_ALPHA:CL_Q:CL_DE:CL0[:SIGMA]",
                    help="give the aiding a stated lift line per aircraft (slope 1/rad, per q_hat, per rad of "
                         "elevator, CL at zero, its 1-sigma), e.g. dr1:3.57:1.05:0.16:0.252:0.01: alpha's flight "
                         "mean is set on it (gcs_sysid.estimation.airangles.STATED_LIFT_LEVEL on; default: off)")
    ap.add_argument("--gust-force-axes", default=None, choices=("yz", "xyz"),
                    help="the specific-force axes offered the turbulence state (gcs_sysid.estimation.rates."
                         "GUST_FORCE_AXES; default: the package's, y and z; xyz adds x)")
    a = ap.parse_args(argv)
    if a.gust_force_axes is not None:
        from gcs_sysid.estimation import rates as _rates

        _rates.GUST_FORCE_AXES = tuple("xyz".index(c) for c in a.gust_force_axes)
    apply_aiding_options(a)
    if a.iv_beta is not None:
        from gcs_sysid.estimation import airangles

        airangles.INSTRUMENTED_BETA = a.iv_beta != "off"
        airangles.BETA_WEAK_TEST = a.iv_beta if a.iv_beta in ("f", "fuller") else None
    if a.summarize:
        print(summarize(a.summarize))
        return 0
    for ac in sorted(set(a.aircraft) & set(UNTOUCHED_AIRCRAFT)):
        print(f"note: {ac} is the untouched aircraft (docs/jsbsim.md): score it only in the final evaluation",
              file=sys.stderr)
    if a.fly_only:
        if not a.work:
            ap.error("--fly-only needs --work DIR")
        for ac in a.aircraft:
            for turb in a.turbulence:
                for seed in a.seeds:
                    t0 = time.perf_counter()
                    files = make_flight(FlightConfig(ac, duration_s=a.duration, turbulence=turb, seed=seed),
                                        Path(a.work), aoa=a.aoa, reuse=True)
                    print(f"{files.tlog}  {'reused' if files.recording is None else 'flown'} "
                          f"[{time.perf_counter() - t0:.1f} s]", flush=True)
        return 0
    if a.gp_fit is not None:
        import gcs_sysid.pipeline as pipeline

        pipeline.USE_DECORRELATED_GP = a.gp_fit == "decorrelated"
        pipeline.GP_COUPLING_TEST = "none" if a.gp_fit == "untested" else "lr"
    if a.gp_noise is not None:
        import gcs_sysid.pipeline as pipeline

        (pipeline.GP_NOISE_CORRELATION, pipeline.GP_NOISE_POSTERIOR,
         pipeline.GP_NOISE_START) = pipeline.GP_NOISE_MODES[a.gp_noise]
    if a.cy_rate_prior is not None:
        import gcs_sysid.pipeline as pipeline

        pipeline.SIDE_FORCE_RATE_PRIOR_STD = None if a.cy_rate_prior == "off" else float(a.cy_rate_prior)
    from gcs_sysid.aero import gustfilter as _gustfilter

    if a.heldout_gust_var is not None:
        _gustfilter.HELDOUT_GUST_VAR = a.heldout_gust_var
    if a.heldout_gust_cutoff is not None:
        _gustfilter.HELDOUT_GUST_CUTOFF = a.heldout_gust_cutoff == "on"
    if a.coefficient_band is not None:
        _pipeline.COEFFICIENT_BAND = a.coefficient_band
    for spec in a.band_output:
        _band_output(_pipeline, spec)
    if a.air_yaw_outputs is not None:
        from gcs_sysid.aero import airyaw

        airyaw.AIR_YAW_OUTPUTS = tuple(a.air_yaw_outputs)
    work = Path(a.work) if a.work else Path(tempfile.mkdtemp(prefix="eval-jsbsim-"))
    rows = []
    print(f"{'flight':32s} {'':5s} " + " ".join(f"{c:>6s}" for c in COEFFICIENTS) + "   cov95  alpha/beta err deg")
    for ac in a.aircraft:
        for turb in a.turbulence:
            for seed in a.seeds:
                row = evaluate(ac, seed, turb, a.aoa, a.duration, work, a.gust_rates,
                               None if a.gust_filter is None else
                               {"on": True, "off": False, "roll": "roll", "rollgp": "rollgp"}[a.gust_filter],
                               a.heldout_air_roll, tuple(a.airp_lines),
                               None if a.air_roll_train is None else a.air_roll_train == "on", a.gp_seed,
                               beta_gls=None if a.beta_gls is None else a.beta_gls == "on",
                               air_yaw=None if a.air_yaw is None else a.air_yaw == "on",
                               rate_errors=None if a.rate_errors is None else a.rate_errors == "on",
                               air_pitch=None if a.air_pitch is None else a.air_pitch == "on")
                row["gp_fit"] = a.gp_fit
                row["heldout_gust_var"] = _gustfilter.HELDOUT_GUST_VAR
                row["heldout_gust_cutoff"] = _gustfilter.HELDOUT_GUST_CUTOFF
                row["coefficient_band"] = _pipeline.COEFFICIENT_BAND
                row["band_outputs"] = {c: ("d" if c in _pipeline.STATED_BAND_LESS_WHITE else v)
                                       for c, v in _pipeline.STATED_BAND_SIGN.items()}
                row["band_outputs"].update({c: "white-learned" for c in _pipeline.WHITE_BAND_NO_STATED_INPUT})
                rows.append(row)
                name = f"{ac} {turb} s{seed} {a.aoa}"
                print(f"{name:32s} meas  {_fmt(row['meas'])}")
                print(f"{'':32s} flat  {_fmt(row['meas_flat'])}   (measured, flat-Earth velocity filter)")
                print(f"{'':32s} gp    {_fmt(row['gp'])}   {row['cov_gp']:5.1f}  "
                      f"{row['alpha_deg']:.2f}/{row['beta_deg']:.2f} (signal {row['alpha_rms_deg']:.2f}/"
                      f"{row['beta_rms_deg']:.2f}); band for a measurement {row['cov_gp_obs']:.1f}")
                print(f"{'':32s} true  {_fmt(row['true'])}   {row['cov_true']:5.1f}  (latent alone "
                      f"{row['cov_true_latent']:.1f}; per coefficient "
                      + " ".join(f"{c:.0f}" for c in row["cov_true_each"])
                      + ")")
                print(f"{'':32s} tair  {_fmt(row['true_air'])}   {row['cov_true_air']:5.1f}  (at the true regressors "
                      "with the rates JSBSim's aerodynamics reads)")
                print(f"{'':32s} ls    {_fmt(row['ls'])}", flush=True)
                for m in a.airp_lines:
                    extra = "" if m == "off" else (f"  p_g corr {row['airp_' + m]['corr']:.2f} "
                                                   f"err {row['airp_' + m]['err_pct']:.0f} %")
                    print(f"{'':32s} {m[:5]:5s} {_fmt(row['gp_airp_' + m])}   {row['cov_gp_airp_' + m]:5.1f}  "
                          f"(ls {_fmt(row['ls_airp_' + m])}){extra}", flush=True)
                append_jsonl(a.json, [row])
    forces = [r[k][c] for r in rows for k in ("gp",) for c in COEFFICIENTS[:3]]
    moments = [r[k][c] for r in rows for k in ("gp",) for c in COEFFICIENTS[3:]]
    print(f"median held-out model error: forces {np.nanmedian(forces):.1f} % (thesis real flight {THESIS_FORCES}), "
          f"moments {np.nanmedian(moments):.1f} % (thesis {THESIS_MOMENTS})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
