"""Hidden effects injected into JSBSim flights: does ``diagnose`` name them? (issue 9, items 2 and 5)

For each aircraft: ``gcs-sysid fit`` (the library's :func:`run_fit`) on a clean 120-s reference
flight (seed 100), then ``diagnose --search`` (differential against the reference flight, no
output error) on 120-s flights with one effect of :mod:`benchmarks.jsbsim_harness.effects`
injected, over seeds x sizes x effects, plus clean flights and two effects at once. The truth
(``-effects.json``) is read only here, after the diagnosis.

Score per case:
  * ``top``: the injected cause is the top finding (for two effects: both among the findings);
  * ``est``: the estimate within 25 % of the injected value (aero terms: estimate minus the
    reference model's value of the term, i.e. the change; ``CY:scale``, named ``scale:CY``: the
    estimated factor minus 1 against the injected ``k - 1``: the harness scales JSBSim's wind-axis
    side force by ``k``, and the diagnosis's ``scale:CY`` candidate is the model's wind-axis side force
    (:func:`gcs_sysid.diagnose.sparse.scale_columns`, since 2026-11-22, branch i9-scale). From branch
    i9-clean until then it was scored against the body-axis equivalent of a single factor on the
    model's body-axis CY, :func:`side_force_scale_truth` (0.74-0.93 (k - 1)), which is not what the
    search's estimate is: the search fitted the factor with the drag's part beside it as a ``beta``
    term whenever it selected one (``docs/jsbsim.md``); that value is kept as ``body_axis_value``);
  * ``gain``: held-out gain of that finding >= 50 %;
  * ``cover``: |estimate - truth| <= 2 standard errors (coverage of the reported standard errors; a term the
    sparse search names reports its combined standard uncertainty since the ninth session, branch i9-se);
    ``cover_decision``: the same with ``evidence.std_error_decision``, the standard error the diagnosis's
    decisions read (the reported one before; the summary shows it in brackets);
  * clean flights: ``ok`` when no cause is named.

Since the tenth session (branch i9-alias) every score is also given *with aliases* (``top_alias``,
``est_alias``, ``gain_alias``, ``ok_alias``; the strict ones above are kept and reported beside them): the
top finding also counts when the injected cause is one of the candidates the diagnosis reports it cannot
be told apart from on this flight (``aliases``: partial-column condition index >= 30,
:mod:`gcs_sysid.diagnose.aliases`), and the estimate and gain are then that alias's own (its fit in place
of the named term; ``scale:CY`` reads ``factor - 1``, a term ``estimate - model_value``). With two effects,
each injected cause must be named or an alias of some finding. Why: when two candidates are one regressor
on the flight (the t6's ``scale:CY`` and ``CY:beta``, partial correlation 0.99997), no data from that
flight can rank them, and the diagnosis reports both readings; scoring only the first would score a coin
the data never tossed. A clean flight is still ``ok`` only when nothing is named (aliases name nothing).
Since the twenty-second session (decided before its freeze) an injected ``CY:scale`` is also read, in the
with-aliases scores only, by a ``CY:beta`` finding when the flown model's side force reads beta alone
(:func:`side_axis_variables`; nine roster aircraft, among them the eternity, t6 and b737): a factor on a side force
of beta alone is that factor on ``CY_beta``, one hypothesis of the aircraft whatever the flight shows, scored as
``estimate / model_value - 1`` against ``body_axis_value`` (:func:`_one_term_alias`).

Usage::

    python -m benchmarks.eval_jsbsim_diagnose --aircraft c172x sgs --seeds 1 2 3 --out benchmarks/out/diag
    python -m benchmarks.eval_jsbsim_diagnose --aircraft pa28 --seeds 1 --out benchmarks/out/diag-pa28
    python -m benchmarks.eval_jsbsim_diagnose --aircraft fokker50 --out DIR --fly-only   # flights only

``--aircraft`` takes the harness names (c172x sgs pa28 j3cub c182 t37 t6 b747 f16 f4n rascal sgs126 asw20 iar80 c684
ultrastick b737 c172p eternity us25e ka350 s23 dr1 navion fokker50) or JSBSim's model names (J3Cub, T37, t6texan2, B747,
f16_direct, F4N_fcs, Rascal110_glide, asw20_glide, IAR80_glide, C684_glide, UltraStick120_glide, 737, Eternity_glide,
UltraStick25e_glide, KingAir350_glide, ShortS23_glide, Dr1_glide, Navion_glide, Fokker50_glide); no aircraft is
untouched now (``j3cub``, ``c182``, ``t37``, ``t6``, ``b747``, ``f16``, ``f4n``, ``rascal``, ``sgs126``, ``asw20``,
``iar80``, ``c684``, ``ultrastick``, ``b737``, ``c172p``, ``eternity``, ``us25e``, ``ka350``, ``s23``, ``dr1``,
``navion`` and ``fokker50``, untouched until the sixth to twenty-seventh sessions' final evaluations, count as used;
none of them is in the defaults; docs/jsbsim.md, "No untouched aircraft"). The flights of ``--out`` are reused when they
were flown by the same harness (``-effects.json`` records its fingerprint) with the same duration, plan and draws;
``--fly-only`` flies (or finds) the reference and every case and stops, without fitting or diagnosing anything.
``--sensor-draw`` is ``per_aircraft`` by default since the thirty-fourth session (each aircraft its own sensor noise;
the records before drew ``shared``), ``--turbulence-draw`` is ``per_aircraft`` since the thirty-fifth (each aircraft its
own JSBSim turbulence), and ``--plan sweep_turn`` flies the sweep in a steady turn
(``benchmarks/jsbsim_harness/flight.py``).

Prints a table and writes one JSON line per case to ``<out>/results.jsonl``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from benchmarks.jsbsim_harness import FlightConfig  # noqa: E402
from benchmarks.jsbsim_harness.aircraft import summary_label  # noqa: E402
from benchmarks.jsbsim_harness.effects import EFFECTS, SIZES, Effect, case_stem, make_effect_flight  # noqa: E402

__all__ = ["reference_model", "level_flights", "diagnose_case", "score_case", "side_force_scale_truth",
           "side_axis_variables", "scoring_truth", "rescore", "summarize", "clean_scatter", "coverage_with_scatter",
           "main"]

DURATION_S = 120.0
REF_SEED = 100
#: Flight plan of every flight, reference and test alike (``benchmarks/jsbsim_harness/flight.py``:
#: ``"sweep"`` spans alpha with a speed sweep and steady-heading sideslips; ``"standard"`` was the
#: plan of the 2026-11-21 runs).
PLAN = "sweep"
#: Sensor noise draws of every flight (``FlightConfig.sensor_draw``) for the library's functions
#: (:func:`reference_model`, :func:`diagnose_case` ...): ``"shared"`` (every aircraft's flight of one seed
#: carries the same noise: the records until the thirty-fourth session, and the tests written on them).
#: The script's runs draw ``"per_aircraft"`` by default since the thirty-fourth session (``--sensor-draw``;
#: decided before its data: with shared draws a roster's ``bias:airspeed`` counts rest on one wind-wander
#: draw per seed).
SENSOR_DRAW = "shared"
#: JSBSim's turbulence draws of every flight (``FlightConfig.turbulence_draw``) for the library's functions:
#: ``"shared"`` (every aircraft's flight of one seed flies the same random sequence: the records until the
#: thirty-fifth session). The script's runs draw ``"per_aircraft"`` by default since the thirty-fifth session
#: (``--turbulence-draw``; decided before its data, for the reason of ``SENSOR_DRAW``'s default).
TURBULENCE_DRAW = "shared"


def _draws() -> dict[str, str]:
    """The draws of every flight, as :class:`FlightConfig` keyword arguments."""
    return {"sensor_draw": SENSOR_DRAW, "turbulence_draw": TURBULENCE_DRAW}


def _draw_suffix(sensor_draw: str, turbulence_draw: str = "shared") -> str:
    """The file-name suffix of the draws: ``-pa`` for per-aircraft sensor noise, ``-pt`` for per-aircraft
    turbulence, none for shared ones."""
    return ("-pa" if sensor_draw == "per_aircraft" else "") + ("-pt" if turbulence_draw == "per_aircraft" else "")


def _stem_suffix(plan: str, sensor_draw: str, turbulence_draw: str = "shared") -> str:
    """The file-name suffix of a flight's plan and draws (none for the standard plan's shared draws)."""
    return (f"-{plan}" if plan != "standard" else "") + _draw_suffix(sensor_draw, turbulence_draw)


def _flight(config: FlightConfig, effects: list[Effect], out: Path, stem: str | None = None):
    """:func:`make_effect_flight`, or the files already in ``out`` from an earlier run of the same case."""
    from benchmarks.jsbsim_harness.aircraft import aircraft
    from benchmarks.jsbsim_harness.logfile import FlightFiles, harness_fingerprint

    stem = stem or case_stem(config.aircraft, config.seed, [(e.name, e.value) for e in effects])
    stem += _stem_suffix(config.plan, config.sensor_draw, config.turbulence_draw)
    tlog = out / f"{stem}.tlog"
    done = tlog.with_name(stem + "-effects.json")
    if tlog.exists() and done.exists():
        doc = json.loads(done.read_text())
        # files written before the fingerprint was recorded (2026-11-22) carry none and are reused as before
        if doc["config"]["duration_s"] == config.duration_s and doc["config"].get("plan", "standard") == config.plan \
                and doc["config"].get("sensor_draw", "shared") == config.sensor_draw \
                and doc["config"].get("turbulence_draw", "shared") == config.turbulence_draw \
                and doc.get("harness", harness_fingerprint(config.aircraft)) == harness_fingerprint(config.aircraft):
            return _stated(FlightFiles(tlog, out / f"{stem}-truth.npz", aircraft(config.aircraft).airframe_path, None),
                           out, stem)
    return _stated(make_effect_flight(config, effects, out, stem=stem), out, stem)


def _stated(files, out: Path, stem: str):
    """``files`` with the airframe the pipeline reads replaced by its copy with ``[aero]`` where
    ``--stated-lift-slope`` or ``--stated-lift-level`` names the aircraft
    (:func:`benchmarks.eval_jsbsim.stated_airframe`)."""
    from dataclasses import replace

    from benchmarks.eval_jsbsim import STATED_AERO, STATED_LINE, stated_airframe

    if not STATED_AERO and not STATED_LINE:         # the options not given: the flight's files exactly as before
        return files
    path = stated_airframe(files.airframe, out, stem)
    return files if path == files.airframe else replace(files, airframe=path)


def _fly_only(aircraft_names, seeds, clean_seeds, pairs, effects, out: Path, plan: str = PLAN) -> int:
    """Fly (or find in ``out``) the reference flight and every case :func:`main` would diagnose, and
    nothing else: a flight cache for a later run with the same ``--out``. Prints one line per flight
    (flown / reused / left the envelope); returns 0."""
    done = set()
    for ac, seed, effs in _cases(aircraft_names, seeds, clean_seeds, pairs):
        if effects and effs and not all(e.name in effects for e in effs):
            continue
        jobs = [] if ac in done else [(FlightConfig(ac, duration_s=DURATION_S, seed=REF_SEED, plan=plan,
                                                    **_draws()), [], f"{ac}-ref")]
        done.add(ac)
        jobs.append((FlightConfig(ac, duration_s=DURATION_S, seed=seed, plan=plan, **_draws()), effs, None))
        for cfg, es, stem in jobs:
            t0 = time.perf_counter()
            tag = "+".join(f"{e.name}={e.value:g}" for e in es) or ("reference" if stem else "clean")
            try:
                files = _flight(cfg, es, out, stem=stem)
                how = "reused" if files.recording is None else "flown"
            except RuntimeError as exc:       # the aircraft left the envelope with that effect
                how = f"FAILED: {exc}"
            print(f"{cfg.aircraft:6s} s{cfg.seed:<3d} {tag:36s} {how} [{time.perf_counter() - t0:.1f} s]", flush=True)
    return 0


def reference_model(ac: str, out: Path, duration_s: float = DURATION_S, plan: str = PLAN,
                    turbulence: str = "light"):
    """Fly the clean reference flight, fit the model; returns (files, model path, measurements).
    ``turbulence``: the harness level (the evaluation flies "light"; tests of a mechanism pass "calm")."""
    from gcs_sysid.diagnose import run_fit
    from gcs_sysid.diagnose.run import air_roll_kind, load_measurements

    files = _flight(FlightConfig(ac, duration_s=duration_s, seed=REF_SEED, plan=plan, **_draws(),
                                 turbulence=turbulence), [], out,
                    stem=f"{ac}-ref")
    model_path = out / f"{ac}-ref-{plan}{_draw_suffix(SENSOR_DRAW, TURBULENCE_DRAW)}-model.toml"
    run_fit(files.tlog, files.airframe, model_path)
    return files, model_path, load_measurements(files.tlog, files.airframe, air_roll=air_roll_kind("reference"))


def _alpha_error_deg(table, tlog: Path) -> dict:
    """The table's alpha against JSBSim's (the ``-truth.npz`` beside ``tlog``) on its valid rows: mean and RMS, deg
    ({} without a truth file)."""
    from benchmarks.jsbsim_harness.truth import load_truth

    npz = tlog.with_name(tlog.stem + "-truth.npz")
    if not npz.exists():
        return {}
    Xt, _ = load_truth(npz).at(table.t)
    e = np.asarray(table.X, float)[:, 0] - Xt[:, 0]
    ok = np.asarray(table.valid, bool) & np.isfinite(e)
    return {"mean_deg": float(np.degrees(e[ok].mean())), "rms_deg": float(np.degrees(np.sqrt(np.mean(e[ok] ** 2)))),
            "sd_deg": float(np.degrees(e[ok].std()))}


def level_flights(ac: str, seeds, out: Path, ref_meas, duration_s: float = DURATION_S, plan: str = PLAN,
                  turbulence: str = "light") -> list:
    """Clean flights flown like the reference (``<ac>-level-s<seed>``), loaded as the test flights are (aided with
    the reference's sideslip estimator): the flights the ``pooled`` alpha level averages over beside the reference.
    They are never diagnosed."""
    from gcs_sysid.diagnose.run import load_measurements, shared_angle_models

    out_m = []
    for s in seeds:
        files = _flight(FlightConfig(ac, duration_s=duration_s, seed=s, plan=plan, **_draws(),
                                     turbulence=turbulence), [], out,
                        stem=f"{ac}-level-s{s}")
        out_m.append(load_measurements(files.tlog, files.airframe,
                                       angle_models=shared_angle_models(ref_meas.states.angle_fits)))
    return out_m


def diagnose_case(ac: str, seed: int, effects: list[Effect], out: Path, model_path: Path, ref_meas,
                  duration_s: float = DURATION_S, plan: str = PLAN,
                  turbulence: str = "light", level_meas=None) -> tuple[list[dict], dict, float]:
    """Fly one case and diagnose it; returns (findings, injected truth doc, seconds of diagnosis).
    ``turbulence`` as in :func:`reference_model`; ``level_meas``: :func:`level_flights` (pooled alpha level)."""
    from gcs_sysid.diagnose import diagnose
    from gcs_sysid.diagnose.run import air_roll_kind, load_measurements
    from gcs_sysid.sim.model_file import load_model

    _LAST_PITOT.clear()
    _LAST_NOT_NAMED.clear()
    _LAST_FLOOR.clear()
    _LAST_FIRST.clear()
    _LAST_LEVEL.clear()
    files = _flight(FlightConfig(ac, duration_s=duration_s, seed=seed, plan=plan, **_draws(),
                                 turbulence=turbulence), effects, out)
    truth = scoring_truth(json.loads(files.tlog.with_name(files.tlog.stem + "-effects.json").read_text()),
                          files.tlog.with_name(files.tlog.stem + "-truth.npz"))
    t0 = time.perf_counter()
    # as run_diagnose does: the test flight's sideslip is aided with the reference's side-force estimator, and with
    # SHARE_ALPHA_MODEL its alpha with the reference's force model (one alpha scale for both)
    from gcs_sysid.diagnose.run import shared_angle_models

    meas = load_measurements(files.tlog, files.airframe, angle_models=shared_angle_models(ref_meas.states.angle_fits),
                             air_roll=air_roll_kind("flight"))
    from gcs_sysid.diagnose import run as diagnose_run
    from gcs_sysid.diagnose.differential import Reference

    # as the CLI does with the flight recorded in <model>.fit.json: the reference carries its decoded
    # flight, so sensor causes are compared with it too (a bias it had is a calibration note)
    model = load_model(model_path)
    kw = {"search_reference": (ref_meas.table, ref_meas.states),
          "references": [Reference(ref_meas.table, ref_meas.states, ref_meas.flight, label=f"{ac}-ref")]}
    if diagnose_run.ALPHA_LEVEL:
        # the alpha level (gcs_sysid.diagnose.alpha_level): this flight, the reference and the model in one frame,
        # pooled with the level flights' tables (--level-seeds) in "pooled" mode; scored against JSBSim's alpha
        a_before = _alpha_error_deg(meas.table, files.tlog)
        model, meas, kw, info = diagnose_run.aligned_alpha(diagnose_run.ALPHA_LEVEL, model, meas, kw,
                                                           level_tables=[m.table for m in level_meas or ()])
        _LAST_LEVEL.update(info, alpha_error_before=a_before,
                           alpha_error_after=_alpha_error_deg(meas.table, files.tlog))
    else:
        _LAST_LEVEL.update(alpha_error_before=_alpha_error_deg(meas.table, files.tlog))
    diag = diagnose(meas.table, meas.airframe, model, meas.states, output_error=False,
                    flight=meas.flight, search=True, **kw)
    _LAST_PITOT.update(_pitot_summary(diag.data))
    _LAST_NOT_NAMED[:] = list((diag.data.get("sparse") or {}).get("not_named") or [])
    entries = [e for e in (diag.data.get("sparse") or {}).get("coefficients") or [] if "coefficient" in e]
    _LAST_FLOOR.update({e["coefficient"]: e.get("naming_floor") for e in entries})
    _LAST_FIRST.update({e["coefficient"]: first_term_gates(e) for e in entries})
    return diag.findings, truth, time.perf_counter() - t0


def first_term_gates(entry: dict) -> dict | None:
    """What the sparse search's naming gates read of one coefficient's first selected term (round 0 of
    :func:`gcs_sysid.diagnose.sparse.sparse_search`): the term and its estimate, ``t`` (the estimate over its
    Bartlett standard error, against ``min_abs_t``), ``score`` (its PRESS drop, against ``min_press_drop``), the
    untouched segment's gain (percent, against ``min_gain_pct``) and its confirmation slope and t. None where the
    search selected no term. Recorded per case so that a gate's trade-off can be read from the records."""
    terms = entry.get("terms") or []
    if not terms:
        return None
    t0, held = terms[0], entry.get("held_out") or {}
    se = float(t0.get("std_error_naming") or 0.0)
    conf = held.get("confirmation") or {}
    return {"term": t0["term"], "estimate": float(t0["estimate"]),
            "t": abs(float(t0["estimate"])) / se if se > 0 else None, "score": float(entry.get("score", 0.0)),
            "gain_pct": held.get("percent"), "confirm_slope": conf.get("slope"),
            "confirm_t": conf.get("t_statistic"), "entered_with": entry.get("entered_with")}


#: the last diagnosed case's alpha level (``data["alpha_level"]``) and its alpha against JSBSim's before / after
_LAST_LEVEL: dict = {}
#: the last diagnosed case's pitot evidence (:func:`_pitot_summary`), recorded with it in ``results.jsonl``
_LAST_PITOT: dict = {}
#: the terms the last case's sparse search did not name because their change lay within their expanded uncertainty
#: (``sparse.beyond_expanded_uncertainty``; sixteenth session), recorded as ``not_named``
_LAST_NOT_NAMED: list = []
#: the last case's sparse-search naming floor per coefficient (``sparse.naming_floor``: the smallest term the share
#: gates let it name), recorded as ``naming_floor``
_LAST_FLOOR: dict = {}
#: the last case's first selected term per coefficient with what the naming gates read of it (:func:`first_term_gates`),
#: recorded as ``first_terms``
_LAST_FIRST: dict = {}


def _pitot_summary(data: dict) -> dict:
    """The wind triangle's and the coefficients' pitot-bias changes, fused, and why it was or was not named
    (``data["pitot"]["wind_triangle"]``), for the record of a case; {} when the pitot was not judged."""
    wt = (data.get("pitot") or {}).get("wind_triangle") or {}
    if not wt:
        return {}
    fused = wt.get("fused") or {}
    ch = wt.get("change") or {}
    re = wt.get("coefficients_rereduced") or {}
    flt = wt.get("flight") or {}
    # the wind triangle on this flight and on the reference (absolute, m/s): the reference's own error enters every
    # case's change alike (sixteenth session, branch i9-asw: the asw20's reference read +0.39 +- 0.38 m/s, 0.53 above
    # its eight no-bias flights' mean); the exact re-fit's estimate by coefficient (change since the reference, m/s)
    by = {c: {k: v.get(k) for k in ("estimate", "std_error", "used")}
          for c, v in ((re.get("by_coefficient") or {}).items())}
    return {"triangle_mps": ch.get("change_mps"), "triangle_se": ch.get("std_error"),
            "triangle_flight_mps": ch.get("flight_mps"), "triangle_reference_mps": ch.get("reference_mps"),
            "triangle_heading_span_deg": flt.get("heading_span_deg"), "rereduced_by_coefficient": by or None,
            "coefficients_mps": fused.get("coefficients_mps"), "coefficients_se": fused.get("coefficients_se"),
            "fused_mps": fused.get("estimate"), "fused_t": fused.get("t_statistic"), "agree": fused.get("agree"),
            "screen": (wt.get("screen") or {}).get("passes"), "rereduced_mps": re.get("estimate"),
            "checks": wt.get("checks"), "why": wt.get("why"),
            "gain_untouched": wt.get("gain_untouched"), "gain_sensor": wt.get("gain_sensor"),
            "coefficients_witness": wt.get("coefficients_witness"), "resolution": wt.get("resolution")}


def side_force_scale_truth(truth_npz, k: float) -> float:
    """The body-axis equivalent ``f - 1`` of a wind-axis side-force scale ``k``, from a flight's exact truth.

    Not the scored truth since 2026-11-22 (branch i9-scale; :func:`scoring_truth` scores ``k - 1``): it is
    what a *single* factor on the body-axis CY reads, kept as ``body_axis_value`` for comparison.

    JSBSim sums its SIDE axis in wind axes; the effect multiplies that side force ``Y_w`` by ``k``. The
    body-axis side force is ``Y_b = cos(beta) Y_w - sin(beta) D`` (JSBSim's ``Tw2b``: body from wind,
    forces ``(-D, Y_w, -L)``; Stevens, Lewis and Johnson, *Aircraft Control and Simulation*, 3rd ed.,
    sec. 2.3), so the effect adds ``(k - 1) cos(beta) Y_w`` to it and leaves the drag's part alone. Here
    ``Y_w`` is taken from the flight's exact body-axis coefficients (``C_Yw = -cos(alpha) sin(beta) CX +
    cos(beta) CY - sin(alpha) sin(beta) CZ``, already scaled by ``k``), the unscaled body-axis CY is
    rebuilt (``CY - (k - 1)/k cos(beta) C_Yw``), and the change is regressed on it with a free constant,
    as the diagnosis fits ``scale:CY`` on the model's CY. Exact to the truth file's precision; no
    estimated quantity enters.

    Args:
        truth_npz: the flight's ``-truth.npz`` (``X`` (T, 10) with alpha, beta in rad, ``Y`` (T, 6)).
        k: the injected wind-axis factor.

    Returns:
        ``f - 1`` (dimensionless): what a correct ``scale:CY`` estimates minus 1.
    """
    z = np.load(truth_npz)
    X, Y = np.asarray(z["X"], float), np.asarray(z["Y"], float)
    if X.shape[0] == 10 and X.shape[1] != 10:
        X, Y = X.T, Y.T
    a, b = X[:, 0], X[:, 1]
    c_yw = -np.cos(a) * np.sin(b) * Y[:, 0] + np.cos(b) * Y[:, 1] - np.sin(a) * np.sin(b) * Y[:, 2]
    clean = Y[:, 1] - (k - 1.0) / k * np.cos(b) * c_yw
    d = Y[:, 1] - clean
    ok = np.isfinite(d) & np.isfinite(clean)
    return float(np.linalg.lstsq(np.column_stack([np.ones(ok.sum()), clean[ok]]), d[ok], rcond=None)[0][1])


def scoring_truth(truth: dict, truth_npz) -> dict:
    """The injected truth as scored: ``scale:CY`` against the injected wind-axis ``k - 1`` (the
    diagnosis's candidate is the model's wind-axis side force, :func:`gcs_sysid.diagnose.sparse.scale_columns`);
    its body-axis single-factor equivalent (:func:`side_force_scale_truth`) is added as ``body_axis_value``
    for comparison, never scored. Before 2026-11-22 (branch i9-scale) the body-axis value was scored."""
    out = dict(truth, injected=[dict(e) for e in truth["injected"]])
    for e in out["injected"]:
        if e["cause"] == "scale:CY":
            k = e.get("scale", 1.0 + e.get("wind_axis_value", e["value"]))
            e["value"] = e["wind_axis_value"] = k - 1.0
            if "body_axis_value" not in e:
                e["body_axis_value"] = side_force_scale_truth(truth_npz, k)
            if "side_variables" not in e and truth.get("aircraft"):
                e["side_variables"] = side_axis_variables(truth["aircraft"])
    return out


def side_axis_variables(ac: str) -> list[str]:
    """The properties aircraft ``ac``'s flown (stock or derived) JSBSim model reads on its SIDE axis, less the
    scaling ones (``aero/qbar-*``, ``metrics/*``), sorted; read from its XML in the wheel's aircraft folder (every
    ``<property>`` and table ``<independentVar>`` of the axis); [] when the model cannot be read.

    Used by :func:`score_case`'s one-term alias (twenty-second session): where the side force reads beta alone
    (``["aero/beta-rad"]``: the eternity, t6, b737, b747, f4n, rascal, sgs126, iar80 and c684 of the roster), a scale
    of the whole side force *is* a change of its beta derivative, so a ``CY:beta`` finding reads the injected
    ``CY:scale``. A side force summed elsewhere (OpenFlight's ``aero/coefficient/CY``: the ultrastick, us25e) or
    reading rates and surfaces is not one term."""
    import xml.etree.ElementTree as ET

    from benchmarks.jsbsim_harness.aircraft import aircraft
    from benchmarks.jsbsim_harness.effects import stock_model_dir

    try:
        spec = aircraft(ac)
        root = ET.parse(stock_model_dir(spec) / f"{spec.model}.xml").getroot()
    except (KeyError, ValueError, OSError, ET.ParseError):
        return []
    for ax in root.iter("axis"):
        if ax.get("name") == "SIDE":
            names = {(e.text or "").strip() for e in ax.iter() if e.tag in ("property", "independentVar")}
            return sorted(n for n in names if n and not n.startswith(("aero/qbar", "metrics/")))
    return []


#: the side-axis properties that are beta (:func:`side_axis_variables`, :func:`_one_term_alias`)
BETA_PROPERTIES = frozenset({"aero/beta-rad", "aero/beta-deg"})

def rescore(path: str) -> list[dict]:
    """The records of a ``results.jsonl`` scored again by :func:`score_case` against :func:`scoring_truth`
    (the flights' ``-effects.json`` and ``-truth.npz`` read from the file's folder)."""
    out = []
    folder = Path(path).parent
    for ln in Path(path).read_text().splitlines():
        if not ln.strip():
            continue
        r = json.loads(ln)
        if r["effects"] and "error" not in r["score"]:
            stem = case_stem(r["aircraft"], r["seed"], r["effects"]) + _stem_suffix(
                r.get("plan", PLAN), r.get("sensor_draw", "shared"), r.get("turbulence_draw", "shared"))
            truth = json.loads((folder / f"{stem}-effects.json").read_text())
            findings = [dict(f, gain={"percent": f.get("gain_pct") or 0.0}) for f in r["findings"]]
            r["score"] = score_case(findings, scoring_truth(truth, folder / f"{stem}-truth.npz"))
        out.append(r)
    return out


def _estimate_scores(f: dict, e: dict) -> dict:
    """Estimate, gain and coverage of finding (or alias) ``f`` against injected effect ``e``."""
    est = f["estimate"] - (f.get("model_value", 0.0) if ":" in e["cause"] and not
                           e["cause"].startswith(("delay:", "bias:")) else 0.0)
    se = float(f.get("std_error") or 0.0)
    # the standard error the diagnosis's decisions read (before the ninth session's combined
    # uncertainty, sparse._with_uncertainty, it was the reported one)
    se_d = float(f.get("std_error_decision") or f.get("evidence", {}).get("std_error_decision") or se)
    gain = float((f.get("gain") or {}).get("percent", f.get("gain_pct")) or 0.0)
    return dict(estimate=est, std_error=se, est=abs(est - e["value"]) <= 0.25 * abs(e["value"]),
                gain_pct=gain, gain=gain >= 50.0, cover=se > 0 and abs(est - e["value"]) <= 2 * se,
                std_error_decision=se_d, cover_decision=se_d > 0 and abs(est - e["value"]) <= 2 * se_d)


def _g3(x) -> str:
    """``x`` to 3 significant figures, or "?" when it is None (an alias without an estimate)."""
    return "?" if x is None else f"{x:.3g}"


def _with_alias(findings: list[dict], cause: str) -> tuple[dict | None, dict | None]:
    """``(finding, alias)``: the first finding whose reported aliases include ``cause`` and that alias."""
    for f in findings:
        for a in f.get("aliases") or []:
            if a["cause"] == cause:
                return f, a
    return None, None


def _one_term_alias(findings: list[dict], e: dict) -> dict | None:
    """The with-aliases score of an injected ``scale:CY`` read by a ``CY:beta`` finding, when the flown model's side
    force reads beta alone (``e["side_variables"]`` within :data:`BETA_PROPERTIES`, :func:`side_axis_variables`);
    None otherwise.

    A factor ``k`` on a side force ``CY_beta beta`` is the factor ``k`` on ``CY_beta``: the two causes are one
    hypothesis of the aircraft, whatever the data (decided in the twenty-second session, before its freeze, after
    the eternity's six ``CY:scale`` cases were all named ``CY:beta``). The estimate is the finding's relative
    change of the body-axis derivative, ``estimate / model_value - 1``, scored against the body-axis equivalent
    of the injected factor (``body_axis_value``, :func:`side_force_scale_truth`: the drag's part of the body-axis
    ``CY_beta`` is not scaled); a finding without a reference value (``model_value`` missing or 0) gets no
    estimate score. The gain is the finding's own."""
    if e["cause"] != "scale:CY" or not e.get("side_variables") or not set(e["side_variables"]) <= BETA_PROPERTIES:
        return None
    f = next((f for f in findings if f["cause"] == "CY:beta"), None)
    if f is None:
        return None
    gain = float((f.get("gain") or {}).get("percent", f.get("gain_pct")) or 0.0)
    mv = f.get("model_value")
    target = float(e.get("body_axis_value", e["value"]))
    est = float(f["estimate"]) / float(mv) - 1.0 if mv else None
    se = float(f.get("std_error") or 0.0) / abs(float(mv)) if mv else 0.0
    return {"via_alias": "CY:beta (one-term side force)", "estimate_alias": est, "gain_pct_alias": gain,
            "est_alias": est is not None and abs(est - target) <= 0.25 * abs(target), "gain_alias": gain >= 50.0,
            "cover_alias": est is not None and se > 0 and abs(est - target) <= 2 * se}


def score_case(findings: list[dict], truth: dict) -> dict:
    """Scores of one case against its injected truth (see the module docstring).

    Strict (``top``, ``est``, ``gain``, ``ok``): the injected cause is the finding's named cause, as before the
    tenth session. With aliases (``top_alias``, ``est_alias``, ``gain_alias``, ``ok_alias``; branch i9-alias): a
    finding also counts when the injected cause is one of the candidates it reports it cannot be told apart from
    on this flight (``aliases``, :mod:`gcs_sysid.diagnose.aliases`), scored on that alias's own estimate and
    held-out gain; ``via_alias`` names the finding it came through. A named cause is always tried first.
    """
    inj = truth["injected"]
    causes = [f["cause"] for f in findings]
    if not inj:
        return {"ok": not causes, "ok_alias": not causes, "named": causes}
    rows = []
    for k, e in enumerate(inj):
        f = next((f for f in findings if f["cause"] == e["cause"]), None)
        row = {"cause": e["cause"], "value": e["value"], "found": f is not None,
               "top": (causes[:1] == [e["cause"]]) if len(inj) == 1 else f is not None}
        if f is not None:
            row.update(_estimate_scores(f, e))
        # with aliases: the named cause first, else an alias of the top finding (one effect) or of any finding (two)
        g, a = (None, None) if row["top"] else _with_alias(findings[:1] if len(inj) == 1 else findings, e["cause"])
        if row["top"]:
            row.update(top_alias=True, est_alias=row.get("est"), gain_alias=row.get("gain"))
        elif a is not None:
            sa = _estimate_scores(a, e)
            row.update(top_alias=True, via_alias=g["cause"], estimate_alias=sa["estimate"],
                       gain_pct_alias=sa["gain_pct"], est_alias=sa["est"], gain_alias=sa["gain"],
                       cover_alias=sa["cover"])
        elif (t := _one_term_alias(findings[:1] if len(inj) == 1 else findings, e)) is not None:
            row.update(top_alias=True, **t)
        else:
            row.update(top_alias=False, est_alias=False, gain_alias=False)
        rows.append(row)
    return {"ok": all(r["top"] and r.get("est") and r.get("gain") for r in rows),
            "ok_alias": all(r["top_alias"] and r.get("est_alias") and r.get("gain_alias") for r in rows),
            "effects": rows, "named": causes}


#: the library term each injected aero cause is fitted as, by coefficient (``clean_scatter``)
_FORCED = {"Cm:alpha^2": ("Cm", "alpha^2"), "Cl:alpha*beta": ("Cl", "alpha*beta"), "Cn:delta_a": ("Cn", "delta_a"),
           "scale:CY": ("CY", "scale:CY")}


def clean_scatter(ac: str, out: Path, clean_seeds, ref_meas, model_path: Path, plan: str = PLAN) -> dict:
    """Flight-to-flight scatter of each injected term's estimate, from the clean flights.

    On every clean flight the sparse search's residual (after the reference's inadequacy and the angle
    nuisance, ``keep_residual``) is fitted with the constant and the one term each effect is named by
    (``_FORCED``; ``scale:CY`` as the search's own candidate, the model's wind-axis side force), on the training rows.
    Nothing was injected, so the spread of these estimates over the clean flights is what a flight changes a term by
    when nothing changed: the between-flight error the test flight's coloured standard error does not hold.

    Returns:
        ``{cause: {"sd": float, "estimates": [...]}}`` (sample standard deviation over the clean flights;
        ``delay:delta_e`` and ``bias:airspeed`` are not library terms and are left out).
    """
    from gcs_sysid.aero.table import COEFFICIENTS
    from gcs_sysid.diagnose.context import DiagContext, model_as_dict
    from gcs_sysid.diagnose.run import air_roll_kind, load_measurements
    from gcs_sysid.diagnose.run import shared_angle_models
    from gcs_sysid.diagnose.sparse import _library, alpha_quantile_knots, reference_context, sparse_search
    from gcs_sysid.sim.model_file import load_model

    model = model_as_dict(load_model(model_path))
    reference = reference_context((ref_meas.table, ref_meas.states), ref_meas.airframe, model)
    knots = alpha_quantile_knots(reference[0])
    est: dict[str, list[float]] = {c: [] for c in _FORCED}
    for cs in clean_seeds:
        files = _flight(FlightConfig(ac, duration_s=DURATION_S, seed=cs, plan=plan, **_draws()), [], out)
        m = load_measurements(files.tlog, files.airframe, angle_models=shared_angle_models(ref_meas.states.angle_fits),
                              air_roll=air_roll_kind("flight"))
        ctx = DiagContext.build(m.table, m.airframe, model, m.states)
        res = sparse_search(ctx, ctx.Y - ctx.model_values(), reference, keep_residual=True)
        names, Phi = _library(ctx, knots)
        tr = res["rows"]["train"]
        M = res["scale_columns"]          # the candidates the search fits scale:<coef> with
        for cause, (coef, term) in _FORCED.items():
            j = COEFFICIENTS.index(coef)
            x = M[:, j] if term.startswith("scale:") else Phi[:, names.index(term)]
            A = np.c_[np.ones(tr.size), np.nan_to_num(x[tr])]
            est[cause].append(float(np.linalg.lstsq(A, res["residual"][tr, j], rcond=None)[0][1]))
    return {c: {"sd": float(np.std(v, ddof=1)) if len(v) > 1 else float("nan"), "estimates": v} for c, v in est.items()}


def _cases(aircraft, seeds, clean_seeds, pairs):
    """Large sizes of the first seed, the clean flights and the pairs, then the small sizes, then the
    other seeds (a run cut short stays balanced over effects)."""
    for ac in aircraft:
        for k, seed in enumerate(seeds):
            for i in (1, 0):
                for name in EFFECTS:
                    yield ac, seed, [Effect(name, SIZES[name][i])]
                if k == 0 and i == 1:
                    for cs in clean_seeds:
                        yield ac, cs, []
                    for (a, b) in pairs:
                        yield ac, seed, [Effect(a, SIZES[a][1]), Effect(b, SIZES[b][1])]


def summarize(paths: list[str]) -> str:
    """A markdown table of ``results.jsonl`` files: per aircraft and effect, cases passing each score."""
    recs = [json.loads(ln) for p in paths for ln in Path(p).read_text().splitlines() if ln.strip()]
    groups: dict[tuple[str, str], list[dict]] = {}
    for r in recs:
        key = "clean" if not r["effects"] else " + ".join(e[0] for e in r["effects"])
        groups.setdefault((r["aircraft"], key), []).append(r)
    out = ["| aircraft | injected | cases | top | estimate within 25 % | gain >= 50 % | all three "
           "| with aliases: top, estimate, gain, all three | 2-se coverage "
           "| what was named (estimate - model, truth) |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for (ac, key), rs in sorted(groups.items(), key=lambda kv: (kv[0][0], kv[0][1] == "clean", kv[0][1])):
        if key == "clean":
            ok = sum(r["score"]["ok"] for r in rs)
            named = sorted({c for r in rs for c in r["score"].get("named", [])})
            out.append(f"| {summary_label(ac)} | clean | {len(rs)} | | | | no named cause {ok}/{len(rs)} | | | "
                       f"{', '.join(named) or '-'} |")
            continue
        rows = [e for r in rs for e in r["score"].get("effects", [])]
        n = len(rows)
        found = [e for e in rows if e["found"]]
        desc = "; ".join(
            f"s{r['seed']} " + ", ".join(
                f"{e['cause']} {e['estimate']:.3g} ({e['value']:.3g})" if e["found"] else
                f"[{e['via_alias']} ~ {e['cause']} {_g3(e.get('estimate_alias'))}] ({e['value']:.3g})"
                if e.get("via_alias") else
                f"[{', '.join(r['score'].get('named', [])[:2]) or 'nothing'}] ({e['value']:.3g})"
                for e in r["score"].get("effects", []))
            for r in rs)
        out.append(f"| {summary_label(ac)} | {key} | {len(rs)} | {sum(e['top'] for e in rows)}/{n} | "
                   f"{sum(bool(e.get('est')) for e in rows)}/{n} | {sum(bool(e.get('gain')) for e in rows)}/{n} | "
                   f"{sum(bool(r['score']['ok']) for r in rs)}/{len(rs)} | "
                   + (f"{sum(bool(e.get('top_alias')) for e in rows)}/{n}, "
                      f"{sum(bool(e.get('est_alias')) for e in rows)}/{n}, "
                      f"{sum(bool(e.get('gain_alias')) for e in rows)}/{n}, "
                      f"{sum(bool(r['score'].get('ok_alias')) for r in rs)}/{len(rs)} | "
                      if any('top_alias' in e for e in rows) else "| ")
                   + f"{sum(bool(e.get('cover')) for e in found)}/{len(found)}"
                   + (f" ({sum(bool(e.get('cover_decision')) for e in found)}/{len(found)} with the decision se)"
                      if any('cover_decision' in e for e in found) else "") + f" | {desc} |")
    return "\n".join(out)


def coverage_with_scatter(results: list[str], scatter: list[str]) -> str:
    """2-se coverage per injected cause, with the standard error alone and with the clean flights'
    flight-to-flight scatter (:func:`clean_scatter`) added in quadrature.

    Args:
        results: ``results.jsonl`` files. scatter: ``scatter-<ac>.json`` files (the aircraft from the name).

    Returns:
        a markdown table: aircraft, cause, found, covered by 2 se, covered by 2 sqrt(se^2 + sd^2), sd.
    """
    sd = {Path(p).stem.split("-", 1)[1]: json.loads(Path(p).read_text()) for p in scatter}
    rows: dict[tuple[str, str], list[int]] = {}
    for p in results:
        for ln in Path(p).read_text().splitlines():
            r = json.loads(ln) if ln.strip() else None
            if not r or not r["effects"]:
                continue
            for e in r["score"].get("effects", []):
                if not e["found"]:
                    continue
                s = sd.get(r["aircraft"], {}).get(e["cause"], {}).get("sd", 0.0)
                err = abs(e["estimate"] - e["value"])
                k = rows.setdefault((r["aircraft"], e["cause"]), [0, 0, 0])
                k[0] += 1
                k[1] += bool(e.get("cover"))
                k[2] += bool(err <= 2 * np.hypot(e.get("std_error") or 0.0, s))
    out = ["| aircraft | injected | found | 2 se | 2 sqrt(se^2 + sd_clean^2) | sd_clean |", "|---|---|---|---|---|---|"]
    for (ac, c), (n, c1, c2) in sorted(rows.items()):
        s = sd.get(ac, {}).get(c, {}).get("sd")
        out.append(f"| {ac} | {c} | {n} | {c1}/{n} | {c2}/{n} | {'-' if s is None else f'{s:.3g}'} |")
    return "\n".join(out)


def main(argv=None) -> int:
    global SENSOR_DRAW, TURBULENCE_DRAW
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--aircraft", nargs="+", default=["c172x", "sgs"])
    p.add_argument("--seeds", nargs="*", type=int, default=[1, 2, 3],
                   help="seeds of the effect flights (none with --scatter: only the clean flights' scatter)")
    p.add_argument("--clean-seeds", nargs="*", type=int, default=[11, 12, 13, 14, 15])
    p.add_argument("--effects", nargs="+", default=None, help="subset of effects (default all)")
    p.add_argument("--pairs", nargs="*", default=["Cm:alpha^2,Cn:delta_a", "Cl:alpha*beta,delay:delta_e"])
    p.add_argument("--fly-only", action="store_true",
                   help="only fly (or find in --out) the reference and every case; no fit, no diagnosis")
    p.add_argument("--out", default=str(REPO / "benchmarks" / "out" / "diag-effects"))
    p.add_argument("--plan", default=PLAN, choices=("standard", "sweep", "sweep_turn"),
                   help="flight plan of every flight (default %(default)s; sweep_turn: the sweep in a steady turn)")
    p.add_argument("--sensor-draw", default="per_aircraft", choices=("shared", "per_aircraft"),
                   help="sensor noise seeded by the seed and the aircraft, or by the seed alone as every record before "
                        "the thirty-fourth session (default %(default)s)")
    p.add_argument("--turbulence-draw", default="per_aircraft", choices=("shared", "per_aircraft"),
                   help="JSBSim's turbulence seeded by the seed and the aircraft, or by the seed alone as every record "
                        "before the thirty-fifth session (default %(default)s)")
    p.add_argument("--summary", nargs="+", metavar="JSONL", help="only print the markdown table of these results")
    p.add_argument("--rescore", action="store_true",
                   help="with --summary: score the records again against today's scoring truth (scoring_truth: "
                        "scale:CY against the injected wind-axis k - 1), flights read from each file's folder")
    p.add_argument("--scatter-json", nargs="+", metavar="JSON",
                   help="with --summary: also the 2-se coverage with these scatter-<ac>.json files")
    p.add_argument("--scatter", action="store_true",
                   help="also fit each effect's term on the clean flights (flight-to-flight scatter, "
                        "scatter-<ac>.json)")
    p.add_argument("--sparse-thresholds", default="{}", metavar="JSON",
                   help="overrides of gcs_sysid.diagnose.sparse.THRESHOLDS for this run (a variant, not the "
                        "frozen set)")
    p.add_argument("--share-alpha-model", action="store_true",
                   help="aid each flight's alpha with the reference flight's CZ slopes "
                        "(gcs_sysid.diagnose.run.SHARE_ALPHA_MODEL; off by default)")
    p.add_argument("--alpha-profile", nargs="*", default=None, metavar="COLUMN",
                    help="the alpha aiding's columns whose slopes the gust model's likelihood chooses (gcs_sysid."
                         "estimation.airangles.ALPHA_PROFILE_COLUMNS, e.g. delta_e; default: the package's, none)")
    p.add_argument("--alpha-level", default=None, choices=("reference", "pooled"),
                   help="move each test flight, the reference and the model into one alpha frame (gcs_sysid.diagnose."
                        "alpha_level; default off): the reference flight's, or pooled with --level-seeds")
    p.add_argument("--level-seeds", nargs="*", type=int, default=[101, 102, 103, 104],
                   help="seeds of the clean level flights pooled with the reference (--alpha-level pooled)")
    p.add_argument("--stated-lift-slope", nargs="+", default=None, metavar="AC:CL_ALPHA[:CL_Q]",
                   help="the aiding's stated lift-slope floor per aircraft, e.g. s23:5.5:7.1 (the airframe's [aero]; "
                        "gcs_sysid.estimation.airangles.STATED_LIFT_SLOPE on; as eval_jsbsim's option; default off)")
    p.add_argument("--stated-lift-level", nargs="+", default=None, metavar="AC:CL_ALPHA:CL_Q:CL_DE:CL0[:SIGMA]",
                   help="the aiding's stated lift line per aircraft, alpha's flight mean set on it "
                        "(gcs_sysid.estimation.airangles.STATED_LIFT_LEVEL on; as eval_jsbsim's option; default off)")
    p.add_argument("--air-roll-rate", default=None, choices=("off", "fit", "reference", "both", "reference:Cl"),
                   help="the reference flight (and with 'both' the flight under test; with 'fit' only the model's "
                        "fit) at p_hat less its own smoothed rolling gust; 'reference:Cl': the reference's Cl target "
                        "only (gcs_sysid.diagnose.run.AIR_ROLL_RATE; default: the package's, reference:Cl)")
    p.add_argument("--wind-window", default=None, type=float, metavar="S",
                   help="the wind fit's window length, s (default: the package's estimate.WIND_WINDOW_S)")
    p.add_argument("--wind-residual-scale", default=None, choices=("on", "off"),
                   help="weight the wind fit's airspeed residuals with their own RMS (gcs_sysid.estimation.estimate."
                        "WIND_RESIDUAL_SCALE; default: the package's, on since the fortieth session)")
    p.add_argument("--beta-profile", default=None, choices=("on", "off"),
                   help="CY_beta of the sideslip aiding's first pass by the gust model's likelihood, held in the "
                        "later passes, for the flights the diagnosis loads (gcs_sysid.diagnose.run.BETA_PROFILE; "
                        "default: the package's, off, as the replay's since the thirty-third session)")
    p.add_argument("--beta-gls", default=None, choices=("on", "off"),
                   help="the side-force model's slopes of the sideslip aiding by generalised least squares under the "
                        "gust model, for every flight the diagnosis loads (gcs_sysid.diagnose.run.BETA_GLS and "
                        "gcs_sysid.estimation.airangles.BETA_GLS; default: the package's, off)")
    p.add_argument("--pitot-witness-max-se", default=None, metavar="MPS|off", type=_number_or_off,
                   help="the coefficients confirm a wind-triangle pitot bias only where their standard error is "
                        "at most this, m/s; 'off': always (gcs_sysid.diagnose.pitot.COEF_WITNESS_MAX_SE_MPS; "
                        "default: the package's)")
    p.add_argument("--pitot-refit-systematic", default=None, type=float, metavar="MPS",
                   help="the exact pitot re-fit's between-flight systematic error, m/s, in quadrature with its "
                        "standard error (gcs_sysid.diagnose.pitot.REFIT_SYSTEMATIC_MPS; default: the package's)")
    p.add_argument("--pitot-refit-relative", default=None, type=float, metavar="FRACTION",
                   help="the exact pitot re-fit's systematic error relative to the median airspeed, in quadrature "
                        "(gcs_sysid.diagnose.pitot.REFIT_SYSTEMATIC_REL; default: the package's, 0.005 since the "
                        "forty-seventh session; 0 to compare with the committed records)")
    p.add_argument("--pitot-triangle-confirm", default=None, metavar="T|off", type=_number_or_off,
                   help="the wind triangle must see a fused pitot bias on its own, at least T of its standard "
                        "errors on the estimate's side; 'off': not asked "
                        "(gcs_sysid.diagnose.pitot.MIN_T_TRIANGLE_CONFIRM; default: the package's, 1.0 since the "
                        "forty-eighth session)")
    p.add_argument("--pitot-signature-triangle", default=None, choices=("on", "off"),
                   help="a pitot cause named on the coefficients' signature must agree with the wind triangle's change "
                        "(gcs_sysid.diagnose.pitot.SIGNATURE_TRIANGLE_AGREE; default: the package's)")
    p.add_argument("--pitot-signature-systematic", default=None, choices=("on", "off"),
                   help="the signature path's pitot significance counts the coefficient fit's between-flight "
                        "systematic (gcs_sysid.diagnose.pitot.SIGNATURE_SYSTEMATIC; default: the package's)")
    p.add_argument("--library-control-trim", default=None, choices=("on", "off"),
                   help="the sparse search's monomials with the surfaces measured about the reference flight's trim "
                        "(gcs_sysid.diagnose.sparse.THRESHOLDS['library_control_trim']; default: the package's, off)")
    a = p.parse_args(argv)
    prev = SENSOR_DRAW, TURBULENCE_DRAW
    SENSOR_DRAW, TURBULENCE_DRAW = a.sensor_draw, a.turbulence_draw
    try:
        return _run(p, a)
    finally:                    # the library's functions keep their own defaults after a run
        SENSOR_DRAW, TURBULENCE_DRAW = prev


def _number_or_off(v: str) -> float | str:
    """An option's value: ``"off"`` as it is, anything else as a float (argparse reports a ValueError)."""
    return v if v == "off" else float(v)


def _run(p: argparse.ArgumentParser, a: argparse.Namespace) -> int:
    """:func:`main` after its arguments are parsed (``SENSOR_DRAW`` and ``TURBULENCE_DRAW`` set from
    ``--sensor-draw`` and ``--turbulence-draw``)."""
    if a.library_control_trim is not None:
        from gcs_sysid.diagnose import sparse as _sp

        _sp.THRESHOLDS["library_control_trim"] = a.library_control_trim == "on"
    from gcs_sysid.diagnose import pitot as _pt

    for name, value in (("SIGNATURE_TRIANGLE_AGREE", a.pitot_signature_triangle),
                        ("SIGNATURE_SYSTEMATIC", a.pitot_signature_systematic),
                        ("REFIT_SYSTEMATIC_MPS", a.pitot_refit_systematic),
                        ("REFIT_SYSTEMATIC_REL", a.pitot_refit_relative)):
        if value is not None:                    # given: "on"/"off" switches, numbers as they are
            setattr(_pt, name, value == "on" if isinstance(value, str) else value)
    for name, value in (("COEF_WITNESS_MAX_SE_MPS", a.pitot_witness_max_se),
                        ("MIN_T_TRIANGLE_CONFIRM", a.pitot_triangle_confirm)):
        if value is not None:                    # given: a number, or "off" (None: the check not asked)
            setattr(_pt, name, None if value == "off" else value)
    if a.air_roll_rate is not None:
        from gcs_sysid.diagnose import run as _dr

        _dr.AIR_ROLL_RATE = a.air_roll_rate
    from benchmarks.eval_jsbsim import apply_aiding_options

    # --beta-profile, --stated-lift-slope, --stated-lift-level, --alpha-profile, --wind-window,
    # --wind-residual-scale, --beta-gls
    apply_aiding_options(a)
    if a.beta_profile is not None:      # the diagnosis loads its flights with its own switch (load_measurements)
        from gcs_sysid.diagnose import run as _dr

        _dr.BETA_PROFILE = a.beta_profile == "on"
    if a.beta_gls is not None:          # as --beta-profile: the diagnosis's own switch as well as the aiding's
        from gcs_sysid.diagnose import run as _dr

        _dr.BETA_GLS = a.beta_gls == "on"
    if a.alpha_level is not None:
        from gcs_sysid.diagnose import run as _dr

        _dr.ALPHA_LEVEL = a.alpha_level
    if a.share_alpha_model:
        from gcs_sysid.diagnose import run as diagnose_run

        diagnose_run.SHARE_ALPHA_MODEL = True
    if json.loads(a.sparse_thresholds):
        from gcs_sysid.diagnose import sparse

        sparse.THRESHOLDS.update(json.loads(a.sparse_thresholds))
    if a.summary:
        if a.rescore:
            import tempfile

            tmp = Path(tempfile.mkdtemp(prefix="rescored-"))
            paths = []
            for i, pth in enumerate(a.summary):
                q = tmp / f"{i}-{Path(pth).name}"
                q.write_text("".join(json.dumps(r, default=float) + "\n" for r in rescore(pth)))
                paths.append(str(q))
            a.summary = paths
        print(summarize(a.summary))
        if a.scatter_json:
            print()
            print(coverage_with_scatter(a.summary, a.scatter_json))
        return 0
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    pairs = [tuple(x.split(",")) for x in a.pairs]
    from benchmarks.jsbsim_harness.aircraft import UNTOUCHED_AIRCRAFT, canonical_name

    try:
        a.aircraft = [canonical_name(x) for x in a.aircraft]    # harness or JSBSim model names (J3Cub)
    except KeyError as exc:
        p.error(f"argument --aircraft: {exc.args[0]}")
    for ac in sorted(set(a.aircraft) & set(UNTOUCHED_AIRCRAFT)):
        print(f"note: {ac} is the untouched aircraft (docs/jsbsim.md): diagnose it only in the final evaluation",
              file=sys.stderr)
    if a.fly_only:
        return _fly_only(a.aircraft, a.seeds, a.clean_seeds, pairs, a.effects, out, a.plan)
    refs, levels = {}, {}
    lines = []
    with open(out / "results.jsonl", "a") as fh:
        for ac, seed, effects in _cases(a.aircraft, a.seeds, a.clean_seeds, pairs):
            if a.effects and effects and not all(e.name in a.effects for e in effects):
                continue
            if ac not in refs:
                refs[ac] = reference_model(ac, out, plan=a.plan)
                if a.alpha_level == "pooled":
                    levels[ac] = level_flights(ac, a.level_seeds, out, refs[ac][2], plan=a.plan)
            _, model_path, ref_meas = refs[ac]
            try:
                findings, truth, secs = diagnose_case(ac, seed, effects, out, model_path, ref_meas, plan=a.plan,
                                                      level_meas=levels.get(ac))
                sc = score_case(findings, truth)
            except RuntimeError as exc:       # the aircraft left the envelope with that effect
                sc, findings, secs = {"ok": False, "error": str(exc)}, [], 0.0
            rec = {"aircraft": ac, "seed": seed, "plan": a.plan, "sensor_draw": SENSOR_DRAW,
                   "turbulence_draw": TURBULENCE_DRAW,
                   "effects": [[e.name, e.value] for e in effects],
                   "score": sc, "diagnose_s": secs, "pitot": dict(_LAST_PITOT), "not_named": list(_LAST_NOT_NAMED),
                   "naming_floor": dict(_LAST_FLOOR), "first_terms": dict(_LAST_FIRST),
                   "alpha_level": dict(_LAST_LEVEL),
                   "findings": [{k: f.get(k) for k in ("cause", "estimate", "std_error", "model_value")}
                                | {"gain_pct": f.get("gain", {}).get("percent"),
                                   "std_error_decision": f.get("evidence", {}).get("std_error_decision"),
                                   "uncertainty": f.get("evidence", {}).get("uncertainty"),
                                   # the gain on the residual against the model, where diagnose now reports the
                                   # differential one (core.DIFFERENTIAL_GAIN; None where nothing was replaced)
                                   "gain_against_model_pct": f.get("evidence", {}).get("gain_against_model",
                                                                                       {}).get("percent"),
                                   "source": f.get("source") or f.get("evidence", {}).get("domain"),
                                   # the candidates this finding cannot be told apart from on this flight
                                   # (gcs_sysid.diagnose.aliases), each with its own estimate and gain
                                   "aliases": [{k: a.get(k) for k in ("cause", "estimate", "std_error", "model_value",
                                                                       "partial_correlation", "condition_index",
                                                                       "per_unit_of_named", "cannot_tell_apart",
                                                                       "separate_with")}
                                               | {"gain_pct": a.get("gain", {}).get("percent")}
                                               for a in f.get("aliases") or []]}
                                for f in findings]}
            fh.write(json.dumps(rec, default=float) + "\n")
            fh.flush()
            lines.append(rec)
            tag = "+".join(f"{e.name}={e.value:g}" for e in effects) or "clean"
            ests = "; ".join(f"{r['cause']} est {r.get('estimate', float('nan')):.4g} (truth {r['value']:.4g}, "
                             f"se {r.get('std_error', float('nan')):.2g}) gain {r.get('gain_pct', float('nan')):.0f}%"
                             for r in sc.get("effects", []))
            print(f"{ac:6s} s{seed:<3d} {tag:36s} {'PASS' if sc['ok'] else 'fail'}  named={sc.get('named')} {ests}"
                  f"  [{secs:.0f} s]", flush=True)
    eff = [r for r in lines if r["effects"]]
    clean = [r for r in lines if not r["effects"]]
    rows = [e for r in eff for e in r["score"].get("effects", [])]
    if rows:
        n = len(rows)
        print(f"\neffect cases {len(eff)}: top {sum(r['top'] for r in rows)}/{n}, est within 25 % "
              f"{sum(bool(r.get('est')) for r in rows)}/{n}, "
              f"gain >= 50 % {sum(bool(r.get('gain')) for r in rows)}/{n}, "
              f"all three {sum(bool(r['ok']) for r in (x['score'] for x in eff))}/{len(eff)}; with aliases: top "
              f"{sum(bool(r.get('top_alias')) for r in rows)}/{n}, "
              f"est {sum(bool(r.get('est_alias')) for r in rows)}/{n}, "
              f"gain {sum(bool(r.get('gain_alias')) for r in rows)}/{n}, "
              f"all three {sum(bool(r.get('ok_alias')) for r in (x['score'] for x in eff))}/{len(eff)}; "
              f"2-sigma coverage {sum(bool(r.get('cover')) for r in rows if r['found'])}/"
              f"{sum(r['found'] for r in rows)}")
    if clean:
        print(f"clean flights: no named cause {sum(r['score']['ok'] for r in clean)}/{len(clean)}")
    if a.scatter and len(a.clean_seeds) > 1:
        for ac in a.aircraft:
            if ac not in refs:
                refs[ac] = reference_model(ac, out, plan=a.plan)
            _, model_path, ref_meas = refs[ac]
            sc = clean_scatter(ac, out, a.clean_seeds, ref_meas, model_path, plan=a.plan)
            (out / f"scatter-{ac}.json").write_text(json.dumps(sc, indent=1))
            print(f"{ac} flight-to-flight scatter on the clean flights: "
                  + ", ".join(f"{c} {v['sd']:.3g}" for c, v in sc.items()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
