"""One campaign flight: its plan (standard doublets, validation multisines, the suggestions), flying
it in the simulation, the noisy identification data, fitting and mapping the model, flown-limit check."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..aero.table import COEFFICIENTS, REGRESSORS, CoefficientTable
from ..airframe import Airframe
from ..errors import InputError
from .config import COEF_NOISE, CampaignConfig

__all__ = ["standard_doc", "validation_doc", "fly", "fit", "suggest", "fit_plan", "errors", "sigma_in", "flown_check",
           "Flight"]

#: Standard doublets per control: amplitude deg, pulse s (as in data/plans/sysid-trainer.toml).
_STD = {"delta_e": (5.0, 0.5), "delta_a": (8.0, 0.4), "delta_r": (10.0, 0.6)}

@dataclass
class Flight:
    X: np.ndarray
    Y: np.ndarray
    peaks: dict[str, float] = field(default_factory=dict)


def _plan(doc: dict, source: str):
    from ..sim import plan_from_dict

    return plan_from_dict(doc, source)


def _base_doc(name: str, V0: float, duration: float, seed: int, w20: float) -> dict:
    return {"name": name, "duration_s": duration, "rate_hz": 50.0, "internal_rate_hz": 200.0, "start_time_s": 30.0,
            "seed": int(seed), "initial": {"airspeed_mps": round(V0, 2), "altitude_m": 150.0, "heading_deg": 90.0},
            "home": {"lat_deg": 47.3977, "lon_deg": 8.5456, "alt_m": 50.0},
            "wind": {"speed_mps": 3.0, "from_deg": 250.0}, "turbulence": {"w20_mps": w20}}


def standard_doc(V0: float, cfg: CampaignConfig, seed: int, throw: dict[str, float], budget_s: float | None,
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


def validation_doc(lim, throw: dict[str, float], name: str, duration_s: float = 90.0) -> dict:
    """Multisines on all surfaces at three airspeeds across the limits (no turbulence), in a flight of
    ``duration_s`` (>= 82 s; the campaign's flight length, so the simulation compiles once)."""
    Vs = [lim.V_min + 0.15 * (lim.V_max - lim.V_min), 0.5 * (lim.V_min + lim.V_max),
          lim.V_max - 0.15 * (lim.V_max - lim.V_min)]
    ctl = [c for c in ("delta_e", "delta_a", "delta_r") if c in throw]
    amp = {"delta_e": 3.0, "delta_a": 6.0, "delta_r": 8.0}
    doc = _base_doc(name, Vs[0], max(duration_s, 3 * 26.0 + 4.0), 777, 0.0)
    doc["setpoint"], doc["maneuver"] = [], []
    for i, V in enumerate(Vs):
        t0 = 30.0 + i * 26.0
        if i:
            doc["setpoint"].append({"start_s": t0, "airspeed_mps": round(V, 2)})
        doc["maneuver"].append({"kind": "multisine", "controls": ctl, "start_s": t0 + 8.0, "duration_s": 15.0,
                                "band_hz": [0.2, 2.0], "amplitude_deg": [min(amp[c], 0.8 * math.degrees(throw[c]))
                                                                         for c in ctl]})
    return doc


def fly(airframe: Airframe, truth, doc: dict, rate_hz: float, rng: np.random.Generator, noise: bool = True) -> Flight:
    from ..sim import simulate

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
    return Flight(X, Y, peaks)


def table(X: np.ndarray, Y: np.ndarray, rate_hz: float) -> CoefficientTable:
    t = np.arange(len(X)) / rate_hz
    V = X[:, REGRESSORS.index("V")]
    return CoefficientTable(t, X, Y, np.ones(len(X), bool), 0.5 * 1.2 * V**2, [])


def errors(model, X_test: np.ndarray, Y_test: np.ndarray) -> dict[str, float]:
    from ..pipeline import error_pct

    mean, _ = model.predict(X_test)
    return {c: error_pct(np.asarray(mean)[:, j], Y_test[:, j]) for j, c in enumerate(COEFFICIENTS)}


def sigma_in(model, regions: dict[str, np.ndarray]) -> dict[str, float]:
    out = {}
    for c, P in regions.items():
        _, var = model.predict(P, include_noise=False)
        out[c] = float(np.sqrt(np.mean(np.asarray(var)[:, COEFFICIENTS.index(c)])))
    return out


def suggest(model, X: np.ndarray, Y: np.ndarray, airframe: Airframe, cfg: CampaignConfig, lim):
    from ..envelope import EnvelopeConfig, confidence_map
    from ..maneuvers import ManeuverConfig, suggest_maneuvers

    tab = table(X, Y, cfg.rate_hz)
    env_cfg = EnvelopeConfig(n_grid=14,
                             limits={"V": (lim.V_min, lim.V_max), "alpha": (math.radians(-2.0), lim.alpha_max)})
    env = confidence_map(model, tab, tab.valid, env_cfg)
    sug = suggest_maneuvers(env, model, tab, airframe, max_suggestions=cfg.max_suggestions,
                            config=ManeuverConfig(targets=cfg.targets, max_regions=12))
    return env, sug


def fit(X: np.ndarray, Y: np.ndarray, cfg: CampaignConfig, seed: int):
    """The campaign's GP on ``X (N, 10)``, ``Y (N, 6)`` (SI, coefficients), noise ``cfg.gp_noise``
    (:func:`gcs_sysid.pipeline.gp_noise_fields`), ``GPConfig.seed = seed``; a :class:`~gcs_sysid.gp.LocalGlobalGP`."""
    from ..gp import GPConfig, fit_gp
    from ..pipeline import gp_noise_fields

    gcfg = GPConfig(n_inducing=cfg.n_inducing, n_inducing_hyper=24, n_train_max=600, steps=cfg.gp_steps,
                    mi_pool=400, local=cfg.local, local_steps=20, batch_size=1024, seed=seed,
                    **gp_noise_fields(cfg.gp_noise))
    model, _ = fit_gp(X, Y, gcfg)
    return model


def fit_plan(sug: list, airframe: Airframe, cfg: CampaignConfig, seed: int) -> tuple[dict, list]:
    """The largest prefix of the ranked suggestions that fits one flight; (plan, flown suggestions)."""
    from ..maneuvers import plan_document

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



def flown_check(peaks: dict[str, float], lim) -> list[str]:
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
            out.append(f"{c} reached {peaks[f'defl_max_deg.{c}']:.1f} deg (autopilot + input), "
                       f"throw {math.degrees(th):.1f}")
    return out

