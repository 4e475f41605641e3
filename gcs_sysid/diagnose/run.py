"""The ``fit`` and ``diagnose`` jobs: log -> states -> coefficients -> model file / diagnosis directory."""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..airframe import Airframe, load_airframe
from ..errors import DataError, InputError
from ..outdir import StagedDir, StagedFiles

#: What ``diagnose`` writes into its output folder.
DIAGNOSE_OUTPUTS = ("diagnosis.json", "model_extended.toml", "report.html")
#: Logs at least this large (a 10-minute 50 Hz flight is ~7 MB) are decoded with the spare worker process.
SPLIT_MIN_BYTES = 4 << 20

__all__ = ["Measurements", "load_measurements", "run_fit", "air_rate_target", "check_fit_air_pitch", "run_diagnose"]


@dataclass
class Measurements:
    """A log taken through the replay front end: the flight, airframe, states and coefficients.

    ``air_roll``: what :func:`load_measurements`' ``air_roll`` did (the info of
    :func:`gcs_sysid.diagnose.air_roll.air_roll_table` / :func:`~gcs_sysid.diagnose.air_roll.air_roll_cl_table`:
    ``applied``, ``note``, ``g_sd``, ``Cl_p``), or None where it moved nothing."""

    flight: object
    airframe: Airframe
    states: object
    table: object
    timings: dict
    air_roll: dict | None = None


def _check_airframe_matches(flight, airframe: Airframe, log: str) -> None:
    """The servo channels the airframe names must be in the log."""
    if not flight.has("servo"):
        raise DataError(f"{log}: no servo outputs (SERVO_OUTPUT_RAW / RCOU): cannot tell the control inputs")
    srv = flight["servo"]
    missing = []
    for s in airframe.servos:
        key = f"pwm{s.channel}"
        if key not in srv.fields or not np.any(np.asarray(srv[key]) > 0):
            missing.append(f"{s.name} (channel {s.channel})")
    if missing:
        raise InputError(f"{log}: airframe '{airframe.name}' does not match the log: servo channel(s) "
                         f"{', '.join(missing)} carry no PWM; check the [[servo]] channels in "
                         f"{airframe.source or 'the airframe file'}")


#: Aid the flight's alpha with the first reference flight's CZ slopes, so that the two flights' alpha share
#: one scale (``estimate_states(angle_models=...)``, docs/estimation.md). Off: on the JSBSim ``Cm:alpha^2``
#: cases it moved one J3Cub and one c182 estimate into 25 % and lost one c182 top finding, and on the
#: project's own sim it turned the CLI test's delay into ``Cm:delta_e`` (docs/benchmarks.md, "Eighth
#: session, i8-alpha").
SHARE_ALPHA_MODEL = False


#: The alpha level (:mod:`gcs_sysid.diagnose.alpha_level`): None (off, the default), ``"reference"`` (the flight
#: under test moved into the alpha frame of the reference flight the model was fitted on) or ``"pooled"`` (every
#: flight and the model moved into the frame of the reference flights' mean level). Off: see docs/diagnose.md,
#: "The alpha level", and docs/benchmarks.md, "Twenty-second session, i9-level".
ALPHA_LEVEL: str | None = None

#: The roll rate the diagnosis reads (:mod:`gcs_sysid.diagnose.air_roll`; twenty-fifth session, branch i9-airroll):
#: ``"off"`` (the gyro's ``p_hat`` everywhere; the default until the fiftieth session), ``"reference"`` (the
#: reference flight, the one ``fit`` fits the model on and the differential diagnosis and search compare with, at
#: ``p_hat`` less its own smoothed rolling gust; the flight under test at the gyro's) or ``"both"`` (the flight under
#: test at its own air-relative rate too; measured to take up a hidden rolling moment, docs/diagnose.md); ``"fit"``:
#: only the model's fit (the diagnosis compares both flights at the gyro's rate). Off: the ka350 wins (whole eval
#: 30/26/22/19 -> 31/29/24/22), the b737 loses a clean flight, the c172p a bias:airspeed estimate and gain, the s23 a
#: Cn:delta_a top (rule 8(a)). Measured in docs/benchmarks.md, "Twenty-fifth session, i9-airroll".
#: ``"reference:Cl"`` (forty-ninth session): the reference flight's Cl *target*
#: at its air-relative rate and every ``p_hat`` the gyro's (:func:`gcs_sysid.diagnose.air_roll.air_roll_cl_table`), so
#: that Cn and CY are not moved with Cl; the default since the fiftieth session, by the rule written before its fresh
#: test (effect seed 9 and clean seeds 56-60, paired with ``"off"``: top +8/-3, all three +6/-2, clean not worse;
#: docs/benchmarks.md, "Fiftieth session, lead"). A coefficient whose target moved on one flight only witnesses no air
#: angle's scale (:func:`gcs_sysid.diagnose.air_roll.moved_targets`).
AIR_ROLL_RATE = "reference:Cl"

#: The sideslip aiding's ``CY_beta`` estimator for every flight the diagnosis and ``fit`` load
#: (:func:`load_measurements`, and the pitot-bias re-run of :mod:`gcs_sysid.diagnose.pitot`): False, least squares
#: (the estimator issue 9's roster counts were measured with); True, the gust model's likelihood with the slope held
#: (:data:`gcs_sysid.estimation.airangles.BETA_PROFILE` and ``BETA_PROFILE_HOLD``, the replay's default in the
#: thirty-second session only, opt-in again since the thirty-third). Off here: the diagnosis compares flights through
#: their aided sideslips, issue 9's counts with the profile are not measured, and the twenty-fifth session's run of the
#: profile alone lost the s23's ``CY:scale`` (docs/benchmarks.md, "Twenty-fifth session, i8-beta" and "Thirty-second
#: session, lead").
BETA_PROFILE = False
#: The sideslip aiding's side-force slopes for every flight the diagnosis and ``fit`` load (:func:`load_measurements`,
#: and the pitot-bias re-run of :mod:`gcs_sysid.diagnose.pitot`): True, generalised least squares under the gust model
#: (:data:`gcs_sysid.estimation.airangles.BETA_GLS`); False, least squares (the default: the estimator issue 9's records
#: were measured with; docs/estimation.md, "The side-force model by generalised least squares").
BETA_GLS = False


#: What :func:`load_measurements`' ``air_roll`` moves to the air-relative roll rate: ``"off"`` nothing, ``"p_hat"`` the
#: ``p_hat`` regressor (:func:`gcs_sysid.diagnose.air_roll.air_roll_table`), ``"Cl"`` Cl's target only
#: (:func:`gcs_sysid.diagnose.air_roll.air_roll_cl_table`).
AIR_ROLL_KINDS = ("off", "p_hat", "Cl")


def air_roll_kind(role: str, mode: str | None = None) -> str:
    """What a flight of ``role`` is loaded with under ``mode`` (None: :data:`AIR_ROLL_RATE`): one of
    :data:`AIR_ROLL_KINDS`, for :func:`load_measurements`' ``air_roll``.

    Roles: ``"fit"`` (the reference flight as ``fit`` loads it to fit the model), ``"reference"`` (the reference
    flight as the diagnosis compares with it) and ``"flight"`` (the flight under test). ``"fit"`` mode moves only the
    model's fit; ``"reference"`` the fit and the reference; ``"both"`` all three; each by its ``p_hat`` regressor.
    ``"reference:Cl"`` moves the fit and the reference by Cl's target.

    Raises:
        ValueError: an unknown ``role`` or ``mode`` (:data:`gcs_sysid.diagnose.air_roll.AIR_ROLL_MODES`).
    """
    from .air_roll import AIR_ROLL_MODES

    mode = AIR_ROLL_RATE if mode is None else mode
    if mode not in AIR_ROLL_MODES:
        raise ValueError(f"air roll rate: mode must be one of {AIR_ROLL_MODES}, got {mode!r}")
    if role not in ("fit", "reference", "flight"):
        raise ValueError(f"air roll rate: role must be 'fit', 'reference' or 'flight', got {role!r}")
    moved = {"off": (), "fit": ("fit",), "reference": ("fit", "reference"), "both": ("fit", "reference", "flight"),
             "reference:Cl": ("fit", "reference")}
    if role not in moved[mode]:
        return "off"
    return "Cl" if mode == "reference:Cl" else "p_hat"


def air_roll_for(role: str, mode: str | None = None) -> bool:
    """Whether a flight of ``role`` is moved to the air-relative roll rate at all under ``mode`` (None:
    :data:`AIR_ROLL_RATE`): :func:`air_roll_kind` is not ``"off"``.

    Raises:
        ValueError: an unknown ``role`` or ``mode``.
    """
    return air_roll_kind(role, mode) != "off"


def shared_angle_models(fits: dict | None) -> dict | None:
    """The reference flight's air-angle fits that the flight under test is aided with.

    The sideslip's always: with :data:`gcs_sysid.estimation.airangles.INSTRUMENTED_BETA` the reference flight decides
    between two-stage and ordinary least squares for the side-force slopes and the flight under test uses the same
    estimator (its slopes still its own), so that the two aided sideslips carry the same errors in variables
    (``docs/benchmarks.md``, "Seventeenth session, i9-ivdiag"); without it the given beta fit changes nothing. The
    angle of attack's slopes only with :data:`SHARE_ALPHA_MODEL`.

    Args:
        fits: the reference's ``FlightStates.angle_fits`` (``{"alpha": AxisFit, "beta": AxisFit}``) or None.

    Returns:
        the ``angle_models`` for :func:`load_measurements`, or None.
    """
    out = {k: v for k, v in (fits or {}).items() if k == "beta" or (k == "alpha" and SHARE_ALPHA_MODEL)}
    return out or None


def load_measurements(log, airframe_path, t_from: float | None = None, t_to: float | None = None,
                      progress=None, notify=None, gust_rates: str | None = None,
                      angle_models: dict | None = None, air_roll: str = "off",
                      profile_beta: bool | None = None, gls_beta: bool | None = None) -> Measurements:
    """Decode a log and compute its coefficient table (the replay pipeline's first stages).

    Args:
        log: .tlog or DataFlash .bin path.
        airframe_path: airframe TOML.
        t_from, t_to: vehicle-time window, s (None = open).
        notify: called with one line per damage found in the log (None: not shown).
        angle_models: a reference flight's ``states.angle_fits`` (:func:`shared_angle_models`): this flight's alpha
            is aided with its force model (one alpha scale for both) and its sideslip with its side-force estimator
            (:func:`gcs_sysid.estimation.estimate_states`). None: own.
        air_roll: one of :data:`AIR_ROLL_KINDS` (:func:`air_roll_kind` says which for a role under the diagnosis's
            mode): ``"off"`` as measured; ``"p_hat"`` the table's ``p_hat`` less the flight's own smoothed rolling
            gust (:func:`gcs_sysid.diagnose.air_roll.air_roll_table`); ``"Cl"`` Cl's target at the air-relative rate,
            every regressor the gyro's (:func:`~gcs_sysid.diagnose.air_roll.air_roll_cl_table`).
        profile_beta: the sideslip aiding's ``CY_beta`` estimator (``estimate_states(profile_beta=)``); None:
            :data:`BETA_PROFILE` as it stands at the call (least squares).
        gls_beta: the side-force model's slopes by GLS under the gust model (``estimate_states(gls_beta=)``); None:
            :data:`BETA_GLS` as it stands at the call (least squares).

    Raises:
        InputError, DataError: from the stages, or an airframe whose servo channels
            are absent from the log, or a window outside the log.
        ValueError: ``air_roll`` not one of :data:`AIR_ROLL_KINDS` (checked before the log is read).
    """
    from ..aero import compute_coefficients
    from ..estimation import estimate_states
    from ..options import check_window
    from ..parallel import Helper
    from ..telemetry import cut_window, read_log

    if isinstance(air_roll, bool) or air_roll not in AIR_ROLL_KINDS:
        raise ValueError(f"load_measurements: air_roll must be one of {AIR_ROLL_KINDS} (air_roll_kind), "
                         f"got {air_roll!r}")
    tm: dict[str, float] = {}
    t0 = time.perf_counter()
    check_window(t_from, t_to)
    airframe = load_airframe(airframe_path)
    try:
        big = Path(log).stat().st_size >= SPLIT_MIN_BYTES
    except OSError:
        big = False   # read_log says what is wrong with the path
    # a long log is decoded in two parts at once and the specific force smoothed beside the other
    # filters, as the replay does (gcs_sysid.parallel; the same results with and without the worker)
    with Helper(enabled=None if big else False, warm=("gcs_sysid.telemetry.tlog_scan",)) as helper:
        flight = read_log(log, helper=helper)
        tm["decode_s"] = time.perf_counter() - t0
        if notify is not None:
            for note in flight.damage:
                notify(f"damaged log: {note}")
        flight = cut_window(flight, t_from, t_to)
        _check_airframe_matches(flight, airframe, str(log))
        t1 = time.perf_counter()
        helper.preload(["gcs_sysid.estimation.rates"])
        # the plain force smoother (no turbulence state): the diagnosis compares flights in the manoeuvre
        # band, and the gust-driven CZ above it named a zero-size elevator delay on a clean JSBSim c172x
        # flight (tests/jsbsim/test_effects_diagnose.py; docs/estimation.md, "Moderate turbulence")
        states = estimate_states(flight, airframe, progress=(lambda f: progress(f"estimation {f:.0%}"))
                                 if progress is not None else None, helper=helper, angle_models=angle_models,
                                 turbulence_state=False,
                                 profile_beta=BETA_PROFILE if profile_beta is None else bool(profile_beta),
                                 gls_beta=BETA_GLS if gls_beta is None else bool(gls_beta))
        tm["estimate_s"] = time.perf_counter() - t1
    t2 = time.perf_counter()
    table = compute_coefficients(states, airframe, gust_rates=gust_rates)
    if air_roll != "off":
        from .air_roll import air_roll_cl_table, air_roll_table

        table, air_info = (air_roll_cl_table if air_roll == "Cl" else air_roll_table)(table, states, airframe)
    else:
        air_info = None
    tm["coefficients_s"] = time.perf_counter() - t2
    return Measurements(flight, airframe, states, table, tm, air_info)


def run_fit(log, airframe_path, out_path, t_from: float | None = None, t_to: float | None = None,
            progress=None, notify=None, gust_rates: str | None = None, air_roll_train: bool | None = None,
            profile_beta: bool | None = None, gls_beta: bool | None = None, air_pitch: bool = False):
    """``gcs-sysid fit``: stepwise equation-error model from a log, written as a model file.

    Also writes ``<out>.fit.json`` with the per-coefficient statistics (and the damage found in the
    log, ``log_damage``). Both files are written under temporary names and renamed into place at
    the end (:class:`gcs_sysid.outdir.StagedFiles`); ``--out`` is checked before the log is decoded.

    Args:
        air_roll_train: True: Cl fitted on the replay's air-rate target (``--air-roll on``): the measured Cl less
            the window's smoothed rolling-gust moment, from the replay's one roll fit with its checks
            (:func:`air_rate_target`), so the model's ``Cl`` terms read the air-relative roll rate; every other
            coefficient as measured. Refused (the measured Cl) where the roll fit is refused; ``<out>.fit.json``'s
            ``air_roll`` and the model file's header say which and why. False (``--air-roll off``): the measured Cl
            (a mode of :data:`AIR_ROLL_RATE` that moves the fit's ``p_hat`` regressor still moves it). None (the
            default): as the diagnosis loads its reference flight, :data:`AIR_ROLL_RATE` (``"reference:Cl"``
            since the fiftieth session: Cl's air-rate target, :func:`gcs_sysid.diagnose.air_roll.air_roll_cl_table`;
            the diagnosis's reference models are fitted through here).
        profile_beta: the sideslip's ``CY_beta`` by the gust model's likelihood, held (the thirty-second session's
            replay estimator, ``--beta-profile on``), or by least squares (False); None: :data:`BETA_PROFILE` (least
            squares: the diagnosis's reference models are fitted through here).
        gls_beta: the side-force model's slopes by GLS (True) or least squares (False); None: :data:`BETA_GLS`
            (least squares, as the diagnosis loads its flights).
        air_pitch: ``q_hat`` at the air-relative estimate where the window's own fit shows the pitch gust's share
            (``--air-pitch on``; :func:`gcs_sysid.aero.airpitch.apply_air_pitch` on every valid row of the window,
            as the replay's default does on its training rows), so the model's ``q_hat`` terms read the air's rate;
            the note goes into the model's header and ``<out>.fit.json``'s ``air_pitch``. False (the default): the
            gyro's ``q_hat``, as the diagnosis reads its flights.

    Returns:
        (model, report) as :func:`gcs_sysid.diagnose.fit.fit_model`.

    Raises:
        InputError: ``air_roll_train`` True with :data:`AIR_ROLL_RATE` moving the fit's ``p_hat`` regressor already
            (the gust would be taken out twice); ``air_pitch`` with a ``gust_rates`` frame that moves ``q_hat``
            already (``"path"``, ``"mean-wind"``); from the stages.
    """
    from ..sim.model_file import save_model
    from .fit import fit_model

    kind = air_roll_kind("fit")
    if air_roll_train and kind == "p_hat":
        raise InputError(f"fit --air-roll on: not with the diagnosis's air roll rate {AIR_ROLL_RATE!r} (the fit's "
                         "table is at the air rate already)")
    # explicit on/off: the replay's pair or the measured Cl (a p_hat mode still moves the regressor); None: the
    # diagnosis's own mode, as load_measurements loads its reference flight (air_roll_kind)
    load_kind = "off" if air_roll_train is not None and kind == "Cl" else kind
    check_fit_air_pitch(air_pitch, gust_rates)
    out = Path(out_path)
    with StagedFiles(out, out.with_suffix(".fit.json"), option="--out") as stage:
        meas = load_measurements(log, airframe_path, t_from, t_to, progress, notify, gust_rates=gust_rates,
                                 air_roll=load_kind, profile_beta=profile_beta, gls_beta=gls_beta)
        table, air = meas.table, None
        if air_roll_train:
            table, air = air_rate_target(meas)
        elif load_kind == "Cl":                 # Cl's target moved by load_measurements: recorded
            info = meas.air_roll
            air = {"target": "air" if info["applied"] else "gyro", "applied": bool(info["applied"]),
                   "Cl_p": float(info["Cl_p"]) if info["applied"] else None,
                   "note": f"{info['note']} (the diagnosis's air roll rate {AIR_ROLL_RATE!r}; --air-roll off: "
                           "the measured Cl)"}
        pitch = None
        if air_pitch:
            from ..aero.airpitch import apply_air_pitch

            table, fit, note = apply_air_pitch(table, meas.states, meas.airframe, np.asarray(table.valid, bool))
            pitch = {"applied": bool(fit is not None and fit["applied"]),
                     "kappa": None if fit is None else float(fit["kappa"]),
                     "t": None if fit is None else float(fit["t"]), "note": note}
        model, report = fit_model(table, name=Path(out_path).stem)
        if air is not None:
            report.notes.append(air["note"])
        if pitch is not None:
            report.notes.append(pitch["note"])
        model = type(model)(model.terms, model.name, f"fitted from {Path(str(log)).name} by gcs-sysid fit", "")
        header = report.header() + ("" if air is None else "\n" + air["note"]) + \
            ("" if pitch is None else "\n" + pitch["note"])
        save_model(model, stage.path(out), header=header)
        doc = report.to_json()
        if isinstance(doc, dict):                 # which flight: diagnose finds it again (differential diagnosis)
            from .differential import fit_record

            doc["reference_flights"] = [fit_record(log, t_from, t_to)]
            off = {"target": "gyro", "applied": False, "Cl_p": None, "note": "off (--air-roll off)"}
            doc["air_roll"] = off if air is None else {k: air[k] for k in ("target", "applied", "Cl_p", "note")}
            doc["air_pitch"] = pitch if pitch is not None else {"applied": False, "kappa": None, "t": None,
                                                                 "note": "off (--air-pitch off)"}
        if meas.flight.damage and isinstance(doc, dict):
            doc["log_damage"] = list(meas.flight.damage)
        stage.path(out.with_suffix(".fit.json")).write_text(json.dumps(doc, indent=1, default=float))
    return model, report


def check_fit_air_pitch(air_pitch: bool, gust_rates: str | None) -> None:
    """``gcs-sysid fit --air-pitch on`` refused with a ``--gust-rates`` frame whose ``q_hat`` is relative to the air
    already (:data:`gcs_sysid.estimation.gustrates.PITCH_FRAMES`); run by :func:`run_fit` and by the CLI before any
    work.

    Raises:
        InputError: ``air_pitch`` with such a frame.
    """
    from ..estimation.gustrates import PITCH_FRAMES

    if air_pitch and gust_rates in PITCH_FRAMES:
        raise InputError(f"--air-pitch on: not with --gust-rates {gust_rates} (its q_hat is relative to the air "
                         "already)")


def air_rate_target(meas: Measurements):
    """The fit's table with Cl at the air-relative roll rate: the replay's air-rate pair, training half, on every valid
    row of the window (``gcs-sysid fit`` holds nothing out).

    The one roll fit of the pair (:func:`gcs_sysid.aero.gustfilter.air_roll_fit`: the ``"rollgp"`` filter-error fit
    with the Dryden check and the instruments' check of :data:`~gcs_sysid.aero.gustfilter.ROLL_MAX_IV_RATIO`) and
    the target it gives (:func:`~gcs_sysid.aero.gustfilter.air_roll_target`: ``Cl + Cl_p p_hat_g``, the measured Cl
    less the smoothed gust moment); Jategaonkar, *Flight Vehicle System Identification*, 2nd ed., AIAA 2015, ch. 5
    (the filter-error method). The regressors are not changed (the gyro's ``p_hat``): a model fitted on this target
    is a model of Cl at the air-relative rate.

    Args:
        meas: :func:`load_measurements`' flight (table at the gyro's rate, states, airframe).

    Returns:
        ``(table, info)``: a new table (Cl's column moved; ``meas.table`` itself where the fit was refused) and a dict
        (``target`` ``"air"`` or ``"gyro"``, ``applied`` bool, ``Cl_p`` (None when refused), ``note``: what was done
        or why it was refused).
    """
    from dataclasses import replace

    from ..aero.gustfilter import air_roll_fit, air_roll_target

    table = meas.table
    rows = np.asarray(table.valid, bool)
    fit = air_roll_fit(table, meas.states, meas.airframe, rows) if len(table.t) >= 3 else \
        "gust filter not run: fewer than 3 rows"
    Y, info = air_roll_target(table, meas.states, meas.airframe, rows, fit=fit)
    applied = not isinstance(fit, str)
    out = {"target": "air" if applied else "gyro", "applied": applied,
           "Cl_p": float(info["Cl_p"]) if applied else None, "note": info["note"]}
    return (replace(table, Y=Y) if applied else table), out


def run_diagnose(log, airframe_path, model_path, out_dir, t_from: float | None = None,
                 t_to: float | None = None, progress=None, output_error: bool = True, notify=None,
                 references=None, alpha_level: str | None = None, **kw):
    """``gcs-sysid diagnose``: hold the model against the log; write diagnosis.json, model_extended.toml, report.html.

    Args:
        log, airframe_path, model_path: inputs. out_dir: directory (created).
        t_from, t_to: vehicle-time window, s.
        output_error: also run the output-error comparison (needs ``gcs_sysid.sim.propagate``).
        notify: called with one line per damage found in the log (None: not shown).
        references: reference flight logs for the differential diagnosis (``--reference``); None: the
            flight(s) recorded in ``<model>.fit.json`` by ``gcs-sysid fit``, when found; ``[]``: none.
        alpha_level: ``"reference"`` or ``"pooled"`` (:func:`gcs_sysid.diagnose.alpha_level.align_alpha_levels`;
            pooled over every reference flight given); None: :data:`ALPHA_LEVEL` (off by default).
        **kw: passed to :func:`gcs_sysid.diagnose.core.diagnose`.

    Returns:
        the :class:`~gcs_sysid.diagnose.core.Diagnosis`.
    """
    from ..sim.model_file import load_model
    from .core import diagnose

    t0 = time.perf_counter()
    model = load_model(model_path)
    with StagedDir(out_dir, "diagnose", DIAGNOSE_OUTPUTS) as stage:
        kw = {**kw, **_references(model_path, airframe_path, references, progress)}
        refs = kw.get("references") or []
        meas = load_measurements(log, airframe_path, t_from, t_to, progress, notify, angle_models=shared_angle_models(
            getattr(refs[0].states, "angle_fits", None)) if refs else None, air_roll=air_roll_kind("flight"))
        level = alpha_level if alpha_level is not None else ALPHA_LEVEL
        level_info = None
        if level and refs:
            model, meas, kw, level_info = aligned_alpha(level, model, meas, kw)
        kw = {**kw, "alpha_level_info": level_info} if level_info is not None else kw
        diag = _diagnose_into(stage.path, diagnose, meas, model, log, airframe_path, model_path, t_from, t_to,
                              output_error, progress, t0, kw)
    return diag


def aligned_alpha(mode: str, model, meas: Measurements, kw: dict, level_tables=()):
    """The model, the flight under test and its reference flights (``kw["references"]``) in one alpha frame.

    :func:`gcs_sysid.diagnose.alpha_level.align_alpha_levels` with the first reference as the flight the model was
    fitted on; with ``mode="pooled"`` the other references (and ``level_tables``) pool the level.

    Returns:
        ``(model', meas', kw', info)``: ``model'`` an :class:`~gcs_sysid.sim.model_file.AeroModel`, ``meas'`` a new
        :class:`Measurements` (the inputs are not changed), ``info`` for ``data["alpha_level"]``.
    """
    from dataclasses import replace

    from ..sim.model_file import AeroModel
    from .alpha_level import align_alpha_levels

    refs = list(kw.get("references") or [])
    extra = [r.table for r in refs[1:]] + list(level_tables)
    m1, tab, st, refs1, info = align_alpha_levels(mode, model, meas.table, meas.states, refs[:1], extra)
    refs1 = refs1 + refs[1:]
    model1 = AeroModel(m1, getattr(model, "name", "model") or "model",
                       (getattr(model, "notes", "") or "")
                       + f"; alpha frame moved by {info.get('level_deg', 0.0):.3g} deg "
                       f"({mode} level)", getattr(model, "source", "") or "")
    kw1 = dict(kw, references=refs1)
    if kw.get("search_reference") is not None and refs1:
        kw1["search_reference"] = (refs1[0].table, refs1[0].states)
    return model1, replace(meas, table=tab, states=st), kw1, info


def _references(model_path, airframe_path, given, progress) -> dict:
    """``diagnose`` keyword arguments for the reference flights (loaded through the same front end)."""
    from .differential import Reference, reference_logs

    logs, notes = reference_logs(model_path, given)
    refs = []
    for r in logs:
        m = load_measurements(r["log"], airframe_path, *r["window_s"], progress, air_roll=air_roll_kind("reference"))
        refs.append(Reference(m.table, m.states, m.flight, label=Path(r["log"]).name))
    return {"references": refs, "reference_notes": notes} if (refs or notes) else {}


def _diagnose_into(out, diagnose, meas, model, log, airframe_path, model_path, t_from, t_to, output_error,
                   progress, t0, kw):
    """Run the diagnosis and write its files into ``out`` (the staging folder)."""
    from ..sim.model_file import AeroModel, save_model
    from .report import write_report

    notes = kw.pop("reference_notes", [])
    level_info = kw.pop("alpha_level_info", None)
    diag = diagnose(meas.table, meas.airframe, model, meas.states, output_error=output_error,
                    flight=meas.flight, progress=progress, **kw)
    if level_info is not None:
        diag.data["alpha_level"] = level_info
    if notes:
        diag.data["reference_notes"] = notes
    diag.data.update({"log": str(log), "airframe": str(airframe_path), "model": str(model_path),
                      "window_s": [t_from, t_to]})
    diag.data["timings"].update(meas.timings)
    diag.data["timings"]["total_s"] = time.perf_counter() - t0
    diag.data["estimation_notes"] = list(getattr(meas.states, "notes", [])) + \
        list(getattr(meas.states, "missing", []))
    diag.data["log_damage"] = list(meas.flight.damage)
    ext = AeroModel(diag.model_extended, (model.name or "model") + "-extended",
                    "extended by gcs-sysid diagnose: " + (", ".join(f["cause"] for f in diag.findings) or "no change"))
    header = "Model extended by gcs-sysid diagnose.\n" + "\n".join(
        f"{f['cause']}: estimate {f['estimate']:.4g} +- {f['std_error']:.2g}, held-out gain "
        f"{f['gain'].get('percent', 0):.0f} %" for f in diag.findings)
    save_model(ext, out / "model_extended.toml", header=header)
    (out / "diagnosis.json").write_text(json.dumps(diag.to_json(), indent=1, default=_json_default))
    write_report(diag, out / "report.html")
    return diag


def _json_default(o):
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, np.bool_):
        return bool(o)
    raise TypeError(f"not JSON-able: {type(o).__name__}")
