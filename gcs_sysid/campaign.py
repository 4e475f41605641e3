"""Closed-loop test campaign in the project's simulation: fly, identify, suggest, fly the suggestions, repeat.

``gcs-sysid campaign --airframe A --model TRUE --flights N --out DIR`` runs, per seed:

1. a validation flight (orthogonal multisines on all surfaces at three airspeeds across the limits,
   no turbulence): its true regressors and the truth model's coefficients are the held-out test set;
2. flight 1: standard doublets on each axis at cruise; identify (:func:`gcs_sysid.gp.fit_gp`);
3. two arms from that model, flights 2..N each:
   *suggested*: map the confidence, :func:`gcs_sysid.maneuvers.suggest_maneuvers`, fly the top
   suggestions (as many as fit the flight) with :func:`gcs_sysid.sim.simulate`;
   *standard*: a standard doublet set with the same input-time and amplitude budget;
   after each flight the model is updated incrementally (``model.update``, hyperparameters kept);
4. per flight and arm: held-out error of each coefficient against the truth
   (``100 RMS(model - truth) / RMS(truth)``) and the mean latent predictive sigma in the regions
   flagged after flight 1; whether every suggestion respected the limits (designed peaks and the
   peaks the simulation actually flew).

Identification shortcut (said in the output): the coefficients are the simulation's true ones plus
white noise of the size the estimation chain leaves (``COEF_NOISE``), at 10 Hz; the regressors are
the true ones (turbulence included). The EKF/RTS chain itself is checked by the replay round trip
tests, and running it here would multiply the campaign's time by ten.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .aero.table import COEFFICIENTS, MOMENT_COEFFICIENTS, REGRESSORS, CoefficientTable
from .airframe import Airframe, load_airframe
from .errors import InputError

__all__ = ["CampaignConfig", "run_campaign", "run_campaign_cli", "COEF_NOISE", "campaign_figure", "campaign_markdown"]

#: 1-sigma white noise added to the true coefficients (CX CY CZ Cl Cm Cn): the size of the
#: estimation error the replay leaves on the sample flight (held-out residuals of a well-fitted model).
COEF_NOISE = np.array([0.004, 0.003, 0.01, 0.0006, 0.0015, 0.0004])
_STD = {"delta_e": (5.0, 0.5), "delta_a": (8.0, 0.4), "delta_r": (10.0, 0.6)}   # standard doublets: deg, s


@dataclass(frozen=True)
class CampaignConfig:
    """Settings of :func:`run_campaign`.

    Attributes:
        flights: flights per arm including the first (>= 2).
        seeds: one campaign per seed (turbulence, noise, GP subsets).
        flight_s: length of every flight, s (one compiled simulation).
        w20_mps: turbulence at 20 ft, m/s (MIL-HDBK-1797 light is 7.7; calm sysid air ~1.5).
        max_suggestions: suggestions flown per flight, at most.
        rate_hz: rate of the identification data.
        n_inducing: inducing points of the GP.
        gp_steps: Adam steps of the GP fit.
        local: the GP's local layer.
        targets: coefficients to target (None: all, moments first).
        refit: re-learn the GP (hyperparameters, inducing points) on all data after each flight
            instead of the incremental update (for comparison; the product updates incrementally).
    """

    flights: int = 4
    seeds: tuple[int, ...] = (1,)
    flight_s: float = 90.0
    w20_mps: float = 1.5
    max_suggestions: int = 4
    rate_hz: float = 10.0
    n_inducing: int = 48
    gp_steps: int = 80
    local: bool = True
    targets: tuple[str, ...] | None = None
    refit: bool = False

    def __post_init__(self):
        if self.flights < 2:
            raise InputError(f"--flights must be at least 2 (one standard, then suggested), got {self.flights}")
        if not self.seeds:
            raise InputError("at least one seed is needed")
        if not self.flight_s >= 30.0:
            raise InputError(f"flight length must be at least 30 s, got {self.flight_s}")


@dataclass
class _Flight:
    X: np.ndarray
    Y: np.ndarray
    peaks: dict[str, float] = field(default_factory=dict)


def _plan(doc: dict, source: str):
    from .sim import plan_from_dict

    return plan_from_dict(doc, source)


def _base_doc(name: str, V0: float, duration: float, seed: int, w20: float) -> dict:
    return {"name": name, "duration_s": duration, "rate_hz": 50.0, "internal_rate_hz": 200.0, "start_time_s": 30.0,
            "seed": int(seed), "initial": {"airspeed_mps": round(V0, 2), "altitude_m": 150.0, "heading_deg": 90.0},
            "home": {"lat_deg": 47.3977, "lon_deg": 8.5456, "alt_m": 50.0},
            "wind": {"speed_mps": 3.0, "from_deg": 250.0}, "turbulence": {"w20_mps": w20}}


def _standard_doc(V0: float, cfg: CampaignConfig, seed: int, throw: dict[str, float], budget_s: float | None,
                  amps: dict[str, float] | None, name: str) -> tuple[dict, float]:
    """Standard doublets (elevator, aileron, rudder, repeated) at V0; (plan, input seconds)."""
    mans, t, used = [], 35.0, 0.0
    while True:
        for c in ("delta_e", "delta_a", "delta_r"):
            if c not in throw:
                continue
            a_deg, pulse = _STD[c]
            a_deg = min((amps or {}).get(c, a_deg), math.degrees(throw[c]) * 0.999)
            if t + 2 * pulse + 4.0 > 30.0 + cfg.flight_s - 3.0:
                return {**_base_doc(name, V0, cfg.flight_s, seed, cfg.w20_mps), "maneuver": mans}, used
            mans.append({"kind": "doublet", "control": c, "start_s": round(t, 3), "amplitude_deg": round(a_deg, 3),
                         "pulse_s": pulse, "mode": "open", "settle_s": 1.0})
            t += 2 * pulse + 4.0
            used += 2 * pulse
            if budget_s is not None and used >= budget_s - 1e-9:
                return {**_base_doc(name, V0, cfg.flight_s, seed, cfg.w20_mps), "maneuver": mans}, used


def _validation_doc(lim, throw: dict[str, float], name: str) -> dict:
    """Multisines on all surfaces at three airspeeds across the limits (no turbulence)."""
    Vs = [lim.V_min + 0.15 * (lim.V_max - lim.V_min), 0.5 * (lim.V_min + lim.V_max), lim.V_max - 0.15 * (lim.V_max - lim.V_min)]
    ctl = [c for c in ("delta_e", "delta_a", "delta_r") if c in throw]
    amp = {"delta_e": 3.0, "delta_a": 6.0, "delta_r": 8.0}
    doc = _base_doc(name, Vs[0], 3 * 26.0 + 4.0, 777, 0.0)
    doc["setpoint"], doc["maneuver"] = [], []
    for i, V in enumerate(Vs):
        t0 = 30.0 + i * 26.0
        if i:
            doc["setpoint"].append({"start_s": t0, "airspeed_mps": round(V, 2)})
        doc["maneuver"].append({"kind": "multisine", "controls": ctl, "start_s": t0 + 8.0, "duration_s": 15.0,
                                "band_hz": [0.2, 2.0], "amplitude_deg": [min(amp[c], 0.8 * math.degrees(throw[c]))
                                                                         for c in ctl]})
    return doc


def _fly(airframe: Airframe, truth, doc: dict, rate_hz: float, rng: np.random.Generator, noise: bool = True) -> _Flight:
    from .sim import simulate

    res = simulate(airframe, truth, _plan(doc, doc["name"]))
    step = max(1, int(round(res.rate_hz / rate_hz)))
    X, Y = res.X[::step], res.Y[::step].copy()
    if noise:
        Y += rng.normal(size=Y.shape) * COEF_NOISE
    tr = res.truth
    peaks = {"V_min": float(tr["V"].min()), "V_max": float(tr["V"].max()),
             "alpha_max_deg": float(np.degrees(tr["alpha"].max())),
             "n_max": float((-tr["az"] / 9.80665).max()), "n_min": float((-tr["az"] / 9.80665).min()),
             **{f"defl_max_deg.{c}": float(np.degrees(np.abs(tr[c]).max())) for c in ("delta_e", "delta_a", "delta_r")}}
    return _Flight(X, Y, peaks)


def _table(X: np.ndarray, Y: np.ndarray, rate_hz: float) -> CoefficientTable:
    t = np.arange(len(X)) / rate_hz
    V = X[:, REGRESSORS.index("V")]
    return CoefficientTable(t, X, Y, np.ones(len(X), bool), 0.5 * 1.2 * V**2, [])


def _errors(model, X_test: np.ndarray, Y_test: np.ndarray) -> dict[str, float]:
    from .pipeline import error_pct

    mean, _ = model.predict(X_test)
    return {c: error_pct(np.asarray(mean)[:, j], Y_test[:, j]) for j, c in enumerate(COEFFICIENTS)}


def _sigma_in(model, regions: dict[str, np.ndarray]) -> dict[str, float]:
    out = {}
    for c, P in regions.items():
        _, var = model.predict(P, include_noise=False)
        out[c] = float(np.sqrt(np.mean(np.asarray(var)[:, COEFFICIENTS.index(c)])))
    return out


def _suggest(model, X: np.ndarray, Y: np.ndarray, airframe: Airframe, cfg: CampaignConfig, lim):
    from .envelope import EnvelopeConfig, confidence_map
    from .maneuvers import ManeuverConfig, suggest_maneuvers

    tab = _table(X, Y, cfg.rate_hz)
    env_cfg = EnvelopeConfig(n_grid=14, limits={"V": (lim.V_min, lim.V_max), "alpha": (math.radians(-2.0), lim.alpha_max)})
    env = confidence_map(model, tab, tab.valid, env_cfg)
    sug = suggest_maneuvers(env, model, tab, airframe, max_suggestions=cfg.max_suggestions,
                            config=ManeuverConfig(targets=cfg.targets, max_regions=12))
    return env, sug


def _fit(X: np.ndarray, Y: np.ndarray, cfg: CampaignConfig, seed: int):
    from .gp import GPConfig, fit_gp

    gcfg = GPConfig(n_inducing=cfg.n_inducing, n_inducing_hyper=24, n_train_max=600, steps=cfg.gp_steps,
                    mi_pool=400, local=cfg.local, local_steps=20, batch_size=1024, seed=seed)
    model, _ = fit_gp(X, Y, gcfg)
    return model


def _fit_plan(sug: list, airframe: Airframe, cfg: CampaignConfig, seed: int) -> tuple[dict, list]:
    """The largest prefix of the ranked suggestions that fits one flight; (plan, flown suggestions)."""
    from .maneuvers import plan_document

    best = None
    for k in range(1, len(sug) + 1):
        try:
            doc = plan_document(sug[:k], name="suggested", seed=seed, w20_mps=cfg.w20_mps, wind_mps=3.0,
                                duration_s=cfg.flight_s)
        except InputError:
            break
        best = (doc, list(sug[:k]))
    if best is None:
        raise InputError(f"the top suggestion does not fit a {cfg.flight_s:g} s flight")
    best[0]["wind"]["from_deg"] = 250.0
    return best


def run_campaign(airframe_path: str | Path, model_path: str | Path, out_dir: str | Path | None,
                 config: CampaignConfig = CampaignConfig(), progress=print) -> dict[str, Any]:
    """Run the closed-loop campaign (module docstring) and write ``campaign.json``, ``campaign.md``, ``campaign.png``.

    Args:
        airframe_path: airframe TOML (its ``[limits]`` bound every suggestion).
        model_path: truth aero model TOML (``docs/model-file.md``).
        out_dir: output directory (created), or None to write nothing.
        config: :class:`CampaignConfig`.
        progress: callable taking one line of text (``print``), or None.

    Returns:
        the result document (also ``campaign.json``): ``runs`` (per seed: ``flights`` rows per arm with
        ``errors_pct`` and ``sigma`` per coefficient), ``acceptance`` (the three checks per seed and overall).

    Raises:
        InputError: bad files or settings; an airframe whose limits cannot be defaulted.
    """
    from .jaxconfig import enable_x64
    from .maneuvers import check_peaks, effective_limits
    from .sim import load_model

    enable_x64()
    say = progress or (lambda s: None)
    airframe = load_airframe(airframe_path)
    truth = load_model(model_path)
    if airframe.limits is None:
        raise InputError(f"{airframe_path}: campaign needs a [limits] table (there is no flown envelope to default "
                         f"it from before the first flight)")
    lim = effective_limits(airframe)
    throw = dict(lim.throw)
    V0 = round(lim.V_min + 0.45 * (lim.V_max - lim.V_min), 1)
    runs = []
    for seed in config.seeds:
        rng = np.random.default_rng(seed)
        val = _fly(airframe, truth, _validation_doc(lim, throw, "validation"), config.rate_hz, rng, noise=False)
        X_test, Y_test = val.X, val.Y
        f1 = _fly(airframe, truth, _standard_doc(V0, config, seed, throw, None, None, "standard-1")[0],
                  config.rate_hz, rng)
        model1 = _fit(f1.X, f1.Y, config, seed)
        env1, sug1 = _suggest(model1, f1.X, f1.Y, airframe, config, lim)
        regions = {}
        for c in MOMENT_COEFFICIENTS:
            pts = [r.points for r in env1.regions_of(c)]
            if pts:
                regions[c] = np.vstack(pts)
        top = sug1[0] if sug1 else None
        target_pts = None
        if top is not None:
            for r in env1.regions:
                if r.coefficient == top.region["coefficient"] and list(r.axes) == top.region["axes"] and \
                        all(abs(r.bounds[k][0] - v[0]) < 1e-12 for k, v in top.region["bounds"].items()):
                    target_pts = r.points
                    break
        row1 = {"flight": 1, "kind": "standard", "errors_pct": _errors(model1, X_test, Y_test),
                "sigma": _sigma_in(model1, regions), "peaks": f1.peaks}
        if target_pts is not None:
            row1["target_sigma"] = _sigma_in(model1, {top.coefficients[0]: target_pts})[top.coefficients[0]]
        say(f"seed {seed}: flight 1 (standard) errors " + " ".join(f"{c} {e:.0f}%" for c, e in row1["errors_pct"].items()))
        arms: dict[str, list[dict]] = {"suggested": [row1], "standard": [row1]}
        violations: list[str] = []
        flown_bad: list[str] = []
        for arm in ("suggested", "standard"):
            model, X, Y, sug = model1, f1.X, f1.Y, sug1
            for k in range(2, config.flights + 1):
                if arm == "suggested":
                    if not sug:
                        say(f"seed {seed}: no suggestion before flight {k}; flying a standard set")
                        doc, used = _standard_doc(V0, config, seed * 100 + k, throw, None, None, f"s{k}")
                        flown = []
                    else:
                        doc, flown = _fit_plan(list(sug), airframe, config, seed * 100 + k)
                    for s in flown:
                        bad = check_peaks(s.expected, lim)
                        violations += [f"seed {seed} flight {k} #{s.rank}: {b}" for b in bad]
                    budget = sum(s.input_s for s in flown)
                    amps = {}
                    for s in flown:
                        for c, a in s.amplitudes_rad.items():
                            amps[c] = max(amps.get(c, 0.0), math.degrees(a))
                    arms.setdefault("_budget", []).append({"flight": k, "input_s": budget, "amps": amps})
                else:
                    b = arms["_budget"][k - 2]
                    doc, used = _standard_doc(V0, config, seed * 100 + k, throw, b["input_s"] or None,
                                              b["amps"] or None, f"std{k}")
                    flown = []
                fl = _fly(airframe, truth, doc, config.rate_hz, rng)
                if arm == "suggested" and flown:
                    flown_bad += [f"seed {seed} flight {k}: {b}" for b in _flown_check(fl.peaks, lim)]
                X, Y = np.vstack([X, fl.X]), np.vstack([Y, fl.Y])
                model = _fit(X, Y, config, seed) if config.refit else model.update(fl.X, fl.Y)
                row = {"flight": k, "kind": arm, "errors_pct": _errors(model, X_test, Y_test),
                       "sigma": _sigma_in(model, regions), "peaks": fl.peaks,
                       "flown": [{"rank": s.rank, "kind": s.kind, "controls": list(s.controls),
                                  "coefficients": list(s.coefficients), "V": s.flight_condition["V"]} for s in flown]}
                if target_pts is not None:
                    row["target_sigma"] = _sigma_in(model, {top.coefficients[0]: target_pts})[top.coefficients[0]]
                arms[arm].append(row)
                say(f"seed {seed}: flight {k} ({arm}) errors " + " ".join(f"{c} {e:.0f}%" for c, e in row["errors_pct"].items()))
                if arm == "suggested" and k < config.flights:
                    _, sug = _suggest(model, X, Y, airframe, config, lim)
        budget = arms.pop("_budget", [])
        runs.append({"seed": seed, "arms": arms, "budget": budget, "violations": violations, "flown_outside": flown_bad,
                     "target": None if top is None else {"coefficient": top.coefficients[0], "region": top.region,
                                                         "fix": top.fix}})
    doc = {"airframe": str(airframe_path), "truth_model": str(model_path), "config": _cfg_dict(config),
           "limits": lim.to_dict(), "identification": "true regressors + coefficient noise COEF_NOISE "
                                                      f"{COEF_NOISE.tolist()} at {config.rate_hz:g} Hz",
           "runs": runs, "acceptance": _acceptance(runs, lim)}
    if out_dir is not None:
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        from .report.store import jsonable

        (out / "campaign.json").write_text(json.dumps(jsonable(doc), indent=1, allow_nan=False))
        (out / "campaign.md").write_text(campaign_markdown(doc), encoding="utf-8")
        (out / "campaign.png").write_bytes(campaign_figure(doc))
    return doc


def _flown_check(peaks: dict[str, float], lim) -> list[str]:
    """What the simulation actually flew beyond the limits during a suggested flight (autopilot included)."""
    out = []
    if peaks["V_min"] < lim.V_min - 0.5:
        out.append(f"flew {peaks['V_min']:.1f} m/s, below V_min {lim.V_min:.1f}")
    if peaks["V_max"] > lim.V_max + 0.5:
        out.append(f"flew {peaks['V_max']:.1f} m/s, above V_max {lim.V_max:.1f}")
    if peaks["alpha_max_deg"] > math.degrees(lim.alpha_max) + 0.5:
        out.append(f"flew alpha {peaks['alpha_max_deg']:.1f} deg, above {math.degrees(lim.alpha_max):.1f}")
    if peaks["n_max"] > lim.n_max or peaks["n_min"] < lim.n_min:
        out.append(f"flew {peaks['n_min']:.2f} to {peaks['n_max']:.2f} g, outside {lim.n_min:.2f} to {lim.n_max:.2f}")
    for c, th in lim.throw.items():
        if peaks[f"defl_max_deg.{c}"] > math.degrees(th) + 0.5:
            out.append(f"{c} reached {peaks[f'defl_max_deg.{c}']:.1f} deg (autopilot + input), throw {math.degrees(th):.1f}")
    return out


def _cfg_dict(c: CampaignConfig) -> dict:
    return {k: (list(v) if isinstance(v, tuple) else v) for k, v in c.__dict__.items()}


def _acceptance(runs: list[dict], lim) -> dict[str, Any]:
    per = []
    for run in runs:
        s, b = run["arms"]["suggested"], run["arms"]["standard"]
        r: dict[str, Any] = {"seed": run["seed"]}
        if "target_sigma" in s[0] and len(s) > 1:
            d_s = s[0]["target_sigma"] - s[1]["target_sigma"]
            d_b = s[0]["target_sigma"] - b[1]["target_sigma"]
            r["sigma_drop_suggested"], r["sigma_drop_standard"] = d_s, d_b
            r["sigma_drop_ratio"] = d_s / d_b if d_b > 0 else float("inf")
            r["sigma_2x"] = bool(d_s >= 2.0 * max(d_b, 0.0) and d_s > 0)
        n = min(len(s), len(b), 4) - 1
        if n >= 1:
            r["after_flights"] = n + 1
            r["moment_errors_suggested"] = {c: s[n]["errors_pct"][c] for c in MOMENT_COEFFICIENTS}
            r["moment_errors_standard"] = {c: b[n]["errors_pct"][c] for c in MOMENT_COEFFICIENTS}
            r["moments_better"] = bool(all(s[n]["errors_pct"][c] < b[n]["errors_pct"][c] for c in MOMENT_COEFFICIENTS))
        r["inside_limits"] = not run["violations"]
        r["flown_inside_limits"] = not run.get("flown_outside")
        per.append(r)
    return {"per_seed": per,
            "sigma_2x_all": all(p.get("sigma_2x", False) for p in per),
            "moments_better_all": all(p.get("moments_better", False) for p in per),
            "inside_limits_all": all(p["inside_limits"] for p in per),
            "flown_inside_limits_all": all(p["flown_inside_limits"] for p in per)}


def campaign_markdown(doc: dict) -> str:
    """campaign.md: per seed, a table per arm of held-out error vs truth and sigma in the flagged regions."""
    L = ["# gcs-sysid campaign", "", f"- airframe: {doc['airframe']}", f"- truth model: {doc['truth_model']}",
         f"- identification: {doc['identification']}", ""]
    acc = doc["acceptance"]
    L += ["## Acceptance", "", "| seed | target sigma drop: suggested / standard | 2x | moment errors after "
          "flight N: suggested vs standard (%) | lower | inside limits |", "|---|---|---|---|---|---|"]
    for p in acc["per_seed"]:
        me = ", ".join(f"{c} {p['moment_errors_suggested'][c]:.1f} vs {p['moment_errors_standard'][c]:.1f}"
                       for c in MOMENT_COEFFICIENTS) if "moment_errors_suggested" in p else "-"
        drop = (f"{p['sigma_drop_suggested']:.2e} / {p['sigma_drop_standard']:.2e}" if "sigma_drop_suggested" in p else "-")
        L.append(f"| {p['seed']} | {drop} | {p.get('sigma_2x', '-')} | {me} | {p.get('moments_better', '-')} | "
                 f"{p['inside_limits']} |")
    L += ["", f"All seeds: sigma 2x {acc['sigma_2x_all']}, moments lower {acc['moments_better_all']}, designed inside "
              f"limits {acc['inside_limits_all']}, flown inside limits {acc['flown_inside_limits_all']}.", ""]
    for run in doc["runs"]:
        L += [f"## Seed {run['seed']}", ""]
        if run["target"]:
            L += [f"Target of the first suggestion: {run['target']['coefficient']} ({run['target']['fix']}; "
                  f"{run['target']['region'].get('description', '')}).", ""]
        for arm in ("suggested", "standard"):
            L += [f"### {arm}", "", "| flight | " + " | ".join(f"{c} err %" for c in COEFFICIENTS) + " | "
                  + " | ".join(f"{c} sigma" for c in MOMENT_COEFFICIENTS) + " | flown |",
                  "|" + "---|" * (len(COEFFICIENTS) + len(MOMENT_COEFFICIENTS) + 2)]
            for row in run["arms"][arm]:
                fl = "; ".join(f"#{f['rank']} {f['kind']} {'+'.join(f['controls'])} @ {f['V']:.0f} m/s"
                               for f in row.get("flown", [])) or row["kind"]
                L.append(f"| {row['flight']} | " + " | ".join(f"{row['errors_pct'][c]:.1f}" for c in COEFFICIENTS)
                         + " | " + " | ".join(f"{row['sigma'].get(c, float('nan')):.2e}" for c in MOMENT_COEFFICIENTS)
                         + f" | {fl} |")
            L.append("")
        if run["violations"]:
            L += ["Designed peaks outside the limits:", ""] + [f"- {v}" for v in run["violations"]] + [""]
        if run.get("flown_outside"):
            L += ["Flown (simulated, autopilot included) outside the limits:", ""] + [f"- {v}" for v in run["flown_outside"]] + [""]
    return "\n".join(L) + "\n"


def campaign_figure(doc: dict) -> bytes:
    """PNG: held-out error vs truth (top) and mean sigma in the flagged regions (bottom) of Cl Cm Cn per flight."""
    import io

    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 5.5))
    axes = fig.subplots(2, 3, sharex=True)
    for j, c in enumerate(MOMENT_COEFFICIENTS):
        for run in doc["runs"]:
            for arm, style in (("suggested", "-o"), ("standard", "--s")):
                rows = run["arms"][arm]
                x = [r["flight"] for r in rows]
                axes[0, j].plot(x, [r["errors_pct"][c] for r in rows], style, ms=3, lw=1,
                                color="C0" if arm == "suggested" else "C1", label=arm if run is doc["runs"][0] else None)
                axes[1, j].plot(x, [r["sigma"].get(c, np.nan) for r in rows], style, ms=3, lw=1,
                                color="C0" if arm == "suggested" else "C1")
        axes[0, j].set_title(c, fontsize=10)
        axes[1, j].set_xlabel("flight")
        for a in axes[:, j]:
            a.grid(alpha=0.3)
    axes[0, 0].set_ylabel("held-out error vs truth (%)")
    axes[1, 0].set_ylabel("mean sigma, flagged regions")
    axes[0, 0].legend(fontsize=8)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    return buf.getvalue()


def run_campaign_cli(airframe: str, model: str, flights: int, seeds: str, out: str) -> int:
    """``gcs-sysid campaign``: parse the seeds, run, print the acceptance lines; returns the exit code.

    Raises:
        InputError: seeds that are not comma-separated non-negative integers, or see :func:`run_campaign`.
    """
    try:
        seed_list = tuple(int(x) for x in seeds.split(",") if x.strip())
    except ValueError:
        raise InputError(f"--seeds must be comma-separated integers, got {seeds!r}") from None
    if not seed_list or min(seed_list) < 0:
        raise InputError(f"--seeds must be comma-separated non-negative integers, got {seeds!r}")
    doc = run_campaign(airframe, model, out, CampaignConfig(flights=flights, seeds=seed_list))
    acc = doc["acceptance"]
    print(f"wrote {Path(out) / 'campaign.md'}: sigma drop >= 2x standard: {acc['sigma_2x_all']}; "
          f"Cl Cm Cn error below standard: {acc['moments_better_all']}; inside limits: {acc['inside_limits_all']}")
    return 0
