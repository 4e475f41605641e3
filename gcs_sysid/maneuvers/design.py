"""Design of one candidate maneuver: safe flight condition, waveform, amplitude within the limits,
expected response and the regressor trajectory it would produce.

- Flight condition: 1-g trim at an airspeed inside [V_min, V_max] whose trim alpha leaves room for
  the maneuver below alpha_max; a region whose centre lies outside is *out of reach* and the nearest
  safe condition is flown instead (said in the suggestion).
- Pulse width from the mode frequency (Jategaonkar, *Flight Vehicle System Identification*, 2006,
  sec. 2.5: doublet ``dt = 2.3 / w_n``, 3-2-1-1 ``dt = 1.6 / w_n``); multisine band around the modes,
  each input its own harmonics (Morelli, "Multiple input design for real-time parameter estimation
  in the frequency domain", IFAC SYSID 2003; Morelli and Klein 2016, ch. 9).
- Amplitude: sized for a near-linear response (target alpha/q, p, beta excursions, bank), raised to
  reach the region where the surface allows, then scaled down (the model is linear in the input)
  until the expected peaks respect every limit: alpha_max and n_max / n_min with 30 % of the headroom
  kept in reserve, throw (less a trim margin), surface rate
  (a pulse edge may take at most 20 % of the pulse at the rate limit). A candidate whose smallest
  useful amplitude cannot be flown within the limits is dropped.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import signals
from ..aero.table import REGRESSORS
from ..airframe import CONTROLS, Airframe
from ..envelope import EnvelopeMap, FlaggedRegion
from .limits import EffectiveLimits, check_peaks
from .linear import G, linear_models, mode_omega, response

__all__ = ["ManeuverConfig", "Context", "flight_condition", "design", "RATE_OF"]

#: Normalised rate each control excites most.
RATE_OF = {"delta_e": "q_hat", "delta_a": "p_hat", "delta_r": "r_hat"}


@dataclass(frozen=True)
class ManeuverConfig:
    """Settings of :func:`gcs_sysid.maneuvers.suggest_maneuvers` (angles in deg, rates in deg/s where named so).

    Attributes:
        target_alpha_deg, target_q_deg_s: elevator inputs sized for these peak excursions.
        target_p_deg_s, target_beta_deg: aileron / rudder inputs sized for these.
        max_bank_deg: lateral inputs also keep the bank excursion below this.
        min_amplitude_deg: smallest useful amplitude; a candidate that cannot reach it within the limits
            is dropped.
        alpha_room_deg: the trim alpha of a condition stays this far below alpha_max.
        V_margin: test points stay this fraction of the airspeed range inside [V_min, V_max] (the
            trim at the edge is an extrapolation of the identified model).
        trim_margin_deg: surface travel kept free beyond the estimated trim deflection (its error).
        edge_fraction: a pulse edge may last at most this fraction of the pulse at the surface rate limit.
        max_regions: regions (most uncertain, weakest coefficients first) turned into candidates.
        sample_hz: rate at which the response is simulated (x5 internally).
        n_extra: the trajectory given to the model is this many evenly spaced samples of the maneuver.
        query_bucket: query arrays are padded to a multiple of this length (few distinct JAX shapes).
        lead_s, settle_s: trim time before and free response after the input.
        min_pulse_s, max_pulse_s: pulse width limits.
        max_band_hz: highest multisine frequency (servo bandwidth, pilot or autopilot injection).
        targets: coefficients to target (None: all, moments first by ``force_weight``).
        force_weight: ranking weight of a force coefficient relative to a moment coefficient (Cl Cm Cn
            lead by default: they are what the method exists for).
        gate_pct: a coefficient whose held-out error exceeds this (%) is not ranked (quality gate).
        headroom: fraction of the alpha and load-factor headroom a design may use (the linear model and
            the autopilot's own commands make the flown peaks larger than the designed ones).
        min_reduction, min_relative_reduction: a candidate whose expected variance reduction (mean over
            its targets) is below ``max(min_reduction, min_relative_reduction x the best candidate's)``
            teaches the model next to nothing and is not suggested.
    """

    target_alpha_deg: float = 3.0
    target_q_deg_s: float = 20.0
    target_p_deg_s: float = 45.0
    target_beta_deg: float = 4.0
    max_bank_deg: float = 30.0
    min_amplitude_deg: float = 1.0
    alpha_room_deg: float = 4.0
    V_margin: float = 0.1
    trim_margin_deg: float = 5.0
    edge_fraction: float = 0.2
    max_regions: int = 24
    sample_hz: float = 10.0
    n_extra: int = 64
    query_bucket: int = 256
    lead_s: float = 1.0
    settle_s: float = 3.0
    min_pulse_s: float = 0.15
    max_pulse_s: float = 3.0
    max_band_hz: float = 2.5
    targets: tuple[str, ...] | None = None
    force_weight: float = 0.35
    gate_pct: float = 50.0
    min_reduction: float = 1e-4
    min_relative_reduction: float = 0.1
    headroom: float = 0.7


@dataclass
class Context:
    """What every candidate of one call shares (derivatives, limits, reference condition)."""

    model: Any
    env: EnvelopeMap
    airframe: Airframe
    cfg: ManeuverConfig
    d: dict
    at_ref: dict
    assumed: list
    ref: dict
    rho: float
    limits: EffectiveLimits
    weight: dict
    dt_data: float


def _cz(ctx: Context, alpha: float) -> float:
    return ctx.at_ref["CZ"] + ctx.d[("CZ", "alpha")] * (alpha - ctx.ref["alpha"])


def _lift0(ctx: Context) -> float:
    """CZ V^2 of 1-g flight, anchored on the reference (median) condition taken as trimmed (insensitive
    to mass and thrust errors); from the weight when the reference CZ is not negative."""
    V0 = max(ctx.ref["V"], 1.0)
    cz0 = _cz(ctx, ctx.ref["alpha"])
    return cz0 * V0**2 if cz0 < 0 else -ctx.airframe.mass * G / (0.5 * ctx.rho * ctx.airframe.S)


def trim_alpha(ctx: Context, V: float) -> float:
    """1-g trim alpha (rad) at airspeed V (m/s) from the identified CZ_alpha."""
    return float(ctx.ref["alpha"]
                 + (_lift0(ctx) / max(V, 1.0) ** 2 - _cz(ctx, ctx.ref["alpha"])) / ctx.d[("CZ", "alpha")])


def flight_condition(ctx: Context, center: dict[str, float], axes: tuple[str, ...]) -> tuple[dict[str, Any], str]:
    """1-g trim condition for a region's centre, moved to the nearest safe one when outside the limits.

    Returns:
        (condition, out_of_reach): the condition (``V`` m/s, ``alpha`` rad, ``alpha_deg``,
        ``load_factor`` 1, ``delta_e_trim`` rad, ``rho``, ``density_altitude_m``, ``altitude_band_m``)
        and "" or one line saying why the region as such is out of reach.
    """
    lim, cfg = ctx.limits, ctx.cfg
    V = float(center.get("V", ctx.ref["V"])) if "V" in axes else float(ctx.ref["V"])
    want_alpha = float(center["alpha"]) if "alpha" in axes else None
    if want_alpha is not None and "V" not in axes and _cz(ctx, want_alpha) < 0:
        V = float(np.sqrt(_lift0(ctx) / _cz(ctx, want_alpha)))
    why = []
    alpha_cap = lim.alpha_max - math.radians(cfg.alpha_room_deg)
    if want_alpha is not None and want_alpha > alpha_cap:
        why.append(f"alpha {math.degrees(want_alpha):.1f} deg needs more than alpha_max "
                   f"{math.degrees(lim.alpha_max):.1f} deg less {cfg.alpha_room_deg:g} deg of maneuver room")
    if V < lim.V_min:
        why.append(f"V {V:.1f} m/s is below V_min {lim.V_min:.1f} m/s")
    if V > lim.V_max:
        why.append(f"V {V:.1f} m/s is above V_max {lim.V_max:.1f} m/s")
    m = cfg.V_margin * (lim.V_max - lim.V_min)
    if lim.V_min <= V < lim.V_min + m or lim.V_max - m < V <= lim.V_max:
        why.append(f"V {V:.1f} m/s is within {100 * cfg.V_margin:.0f} % of the airspeed range of a limit")
    V = float(np.clip(V, lim.V_min + m, lim.V_max - m))
    if trim_alpha(ctx, V) > alpha_cap and _cz(ctx, alpha_cap) < 0:   # speed up until trim alpha leaves room
        V_safe = float(np.sqrt(_lift0(ctx) / _cz(ctx, alpha_cap)))
        if V_safe > V:
            why.append(f"trim alpha at {V:.1f} m/s leaves less than {cfg.alpha_room_deg:g} deg to alpha_max")
            V = min(V_safe, lim.V_max - m)
    alpha = trim_alpha(ctx, V)
    d, ref = ctx.d, ctx.ref
    de = ref["delta_e"] - (ctx.at_ref["Cm"] + d[("Cm", "alpha")] * (alpha - ref["alpha"])) / d[("Cm", "delta_e")]
    h = float(44330.8 * (1 - (ctx.rho / 1.225) ** (1 / 4.2559)))
    fc = {"V": V, "alpha": alpha, "alpha_deg": math.degrees(alpha), "load_factor": 1.0, "delta_e_trim": float(de),
          "rho": ctx.rho, "density_altitude_m": h, "altitude_band_m": [round(h - 100.0), round(h + 100.0)]}
    out = ""
    if why:
        out = ("out of reach as flagged (" + "; ".join(why) + f"): nearest safe condition V {V:.1f} m/s, "
               f"alpha {math.degrees(alpha):.1f} deg at 1 g")
    return fc, out


def _pulse(kind: str, omega: float, cfg: ManeuverConfig, dt_data: float) -> float:
    k = 2.3 if kind == "doublet" else 1.6   # Jategaonkar (2006) sec. 2.5
    return float(np.clip(k / max(omega, 1e-3), max(cfg.min_pulse_s, 2 * dt_data), cfg.max_pulse_s))


def _band(omega: dict[str, float], cfg: ManeuverConfig, dt_data: float, n_inputs: int) -> tuple[float, float, float]:
    """(f_lo, f_hi, period) of a multisine covering the modes, with at least 2 harmonics per input."""
    f = np.array([w / (2 * np.pi) for w in omega.values()])
    lo = max(0.1, 0.4 * f.min())
    hi = min(1.6 * f.max(), 0.4 / max(dt_data, 1e-3), cfg.max_band_hz)
    T = float(np.clip(2.0 / lo, 8.0, 20.0))
    hi = max(hi, lo + (2 * n_inputs + 0.5) / T)
    return lo, hi, T


def _peaks(ctx: Context, resp: dict, u: dict[str, np.ndarray], base: dict[str, float], fc: dict, dt: float
           ) -> dict[str, float]:
    """Expected peaks (deg, deg/s, g) of a response to inputs ``u`` around condition ``fc``."""
    V, c = fc["V"], ctx.airframe.c
    k = 0.5 * fc["rho"] * V**2 * ctx.airframe.S / (ctx.airframe.mass * G)
    z = np.zeros(len(resp["alpha"]))
    dn = -k * (ctx.d[("CZ", "alpha")] * resp["alpha"] + ctx.d[("CZ", "q_hat")] * resp["q"] * c / (2 * V)
               + ctx.d[("CZ", "delta_e")] * u.get("delta_e", z))
    out = {"V_mps": V, "p_max_dps": math.degrees(np.max(np.abs(resp["p"]))),
           "q_max_dps": math.degrees(np.max(np.abs(resp["q"]))), "r_max_dps": math.degrees(np.max(np.abs(resp["r"]))),
           "alpha_max_deg": math.degrees(fc["alpha"] + np.max(resp["alpha"])),
           "alpha_min_deg": math.degrees(fc["alpha"] + np.min(resp["alpha"])),
           "beta_max_deg": math.degrees(np.max(np.abs(resp["beta"]))),
           "bank_max_deg": math.degrees(np.max(np.abs(resp["phi"]))),
           "n_max": float(1.0 + np.max(dn)), "n_min": float(1.0 + np.min(dn))}
    for ctl, v in u.items():
        out[f"deflection_max_deg.{ctl}"] = math.degrees(np.max(np.abs(base[ctl] + v)))
        out[f"surface_rate_max_dps.{ctl}"] = _surface_rate(v, dt)
    return out


def _surface_rate(v: np.ndarray, dt: float) -> float:
    """Largest surface rate (deg/s) the input asks for. A step (doublet, 3211) is flown at the servo's
    limited rate, so it counts as its height over the edge time allowed (see :func:`design`)."""
    d = np.abs(np.diff(v))
    return math.degrees(float(d.max() / dt)) if d.size else 0.0


def design(ctx: Context, kind: str, controls: tuple[str, ...], region: FlaggedRegion) -> tuple[dict, np.ndarray] | None:
    """Waveform, amplitudes, expected peaks and the regressor trajectory of one candidate.

    Args:
        ctx: shared context. kind: ``doublet``, ``3211`` or ``multisine``. controls: surfaces excited.
        region: the region the candidate aims at (its centre sets the condition).

    Returns:
        (design dict, X (n_extra, 10) regressor trajectory) or None when the linear model diverges or
        the smallest useful amplitude cannot be flown within the limits.
    """
    cfg, lim = ctx.cfg, ctx.limits
    fc, out_of_reach = flight_condition(ctx, region.center, region.axes)
    V = fc["V"]
    models = linear_models(ctx.d, ctx.airframe, V, ctx.rho, fc["alpha"])
    omega = {c: mode_omega(models, c) for c in controls}
    dt = 1.0 / cfg.sample_hz / 5.0
    if kind == "multisine":
        lo, hi, T_in = _band(omega, cfg, ctx.dt_data, len(controls))
        band = (lo, hi)
        pulse = 1.0 / (2 * hi)
    else:
        pulse = _pulse(kind, min(omega.values()), cfg, ctx.dt_data)
        T_in, band = signals.duration_of(kind, pulse), None
    total = cfg.lead_s + T_in + cfg.settle_s
    t = np.arange(0.0, total, dt)
    base = {"delta_e": fc["delta_e_trim"], "delta_a": ctx.ref["delta_a"], "delta_r": ctx.ref["delta_r"]}
    unit = {c: signals.waveform(kind, t, cfg.lead_s, 1.0, pulse_width=pulse, duration=T_in, band=band,
                                n_inputs=len(controls), index=i) for i, c in enumerate(controls)}
    amps, notes = {}, []
    for c in controls:
        resp = response(models, {c: unit[c]}, t)
        if resp is None:
            return None
        pk = {k: np.nanmax(np.abs(v)) + 1e-12 for k, v in resp.items()}
        if c == "delta_e":
            lin = min(math.radians(cfg.target_alpha_deg) / pk["alpha"], math.radians(cfg.target_q_deg_s) / pk["q"])
        elif c == "delta_a":
            lin = min(math.radians(cfg.target_p_deg_s) / pk["p"], math.radians(cfg.max_bank_deg) / pk["phi"])
        else:
            lin = min(math.radians(cfg.target_beta_deg) / pk["beta"], math.radians(cfg.max_bank_deg) / pk["phi"])
        reach = abs(region.center[c] - base[c]) if c in region.axes else 0.0
        rate = RATE_OF[c]
        if rate in region.axes:
            key = {"q_hat": "q", "p_hat": "p", "r_hat": "r"}[rate]
            scale = (ctx.airframe.c if rate == "q_hat" else ctx.airframe.b) / (2 * V)
            reach = max(reach, abs(region.center[rate]) / (pk[key] * scale))
        if reach > lin:
            notes.append(f"{_name(c)} amplitude raised above the linear-response target to reach the region")
        amps[c] = max(lin, reach)
    # the limits: throw and surface rate per control, then alpha and load factor for all together
    for c in controls:
        room = lim.throw.get(c, 0.0) - abs(base[c]) - math.radians(cfg.trim_margin_deg)
        if kind == "multisine":
            slope = max(np.max(np.abs(np.diff(unit[c]))) / dt, 1e-9)
            rate_cap = lim.rate.get(c, np.inf) / slope
        else:
            rate_cap = lim.rate.get(c, np.inf) * cfg.edge_fraction * pulse / 2.0
        cap = min(room, rate_cap)
        if amps[c] > cap:
            which = "throw" if room <= rate_cap else "surface rate"
            notes.append(f"{_name(c)} amplitude cut from {math.degrees(amps[c]):.1f} to "
                         f"{math.degrees(max(cap, 0)):.1f} deg by the {which} limit")
            amps[c] = cap
    u = {c: amps[c] * unit[c] for c in controls}
    resp = response(models, u, t)
    if resp is None:
        return None
    pk = _peaks(ctx, resp, u, base, fc, dt)
    k, h = 1.0, cfg.headroom
    a_up = h * (math.degrees(lim.alpha_max) - fc["alpha_deg"])
    if pk["alpha_max_deg"] - fc["alpha_deg"] > a_up:
        k = min(k, a_up / (pk["alpha_max_deg"] - fc["alpha_deg"]))
    if pk["n_max"] - 1.0 > h * (lim.n_max - 1.0):
        k = min(k, h * (lim.n_max - 1.0) / (pk["n_max"] - 1.0))
    if 1.0 - pk["n_min"] > h * (1.0 - lim.n_min):
        k = min(k, h * (1.0 - lim.n_min) / (1.0 - pk["n_min"]))
    if k < 1.0:
        notes.append(f"amplitudes scaled by {k:.2f} to keep alpha and load factor inside the limits")
        amps = {c: a * k for c, a in amps.items()}
        u = {c: amps[c] * unit[c] for c in controls}
        resp = response(models, u, t)
        pk = _peaks(ctx, resp, u, base, fc, dt)
    if min(amps.values()) < math.radians(cfg.min_amplitude_deg) - 1e-9:
        return None
    if kind != "multisine":   # steps are flown at the rate limit: the rate asked for is the limit itself
        for c in controls:
            pk[f"surface_rate_max_dps.{c}"] = min(pk[f"surface_rate_max_dps.{c}"],
                                                  2 * math.degrees(amps[c]) / (cfg.edge_fraction * pulse))
    broken = check_peaks(pk, lim)
    if broken:   # cannot happen after the scaling above; kept as the guarantee the report states
        return None
    X = np.tile(np.array([ctx.ref[r] for r in REGRESSORS]), (len(t), 1))
    col = REGRESSORS.index
    X[:, col("V")] = V
    X[:, col("alpha")] = fc["alpha"] + resp["alpha"]
    X[:, col("beta")] = resp["beta"] + ctx.ref["beta"]
    X[:, col("q_hat")] = resp["q"] * ctx.airframe.c / (2 * V)
    X[:, col("p_hat")] = resp["p"] * ctx.airframe.b / (2 * V)
    X[:, col("r_hat")] = resp["r"] * ctx.airframe.b / (2 * V)
    for c in CONTROLS:
        X[:, col(c)] = base[c] + u.get(c, 0.0)
    idx = np.linspace(0, len(t) - 1, cfg.n_extra).round().astype(int)
    out = {"fc": fc, "amps": amps, "pulse": pulse, "duration": total, "input_s": T_in, "band": band, "t": t[::2],
           "u": {c: v[::2] for c, v in u.items()}, "mode_hz": {c: w / (2 * np.pi) for c, w in omega.items()},
           "notes": notes, "expected": pk, "out_of_reach": out_of_reach}
    return out, X[idx]


def _name(c: str) -> str:
    return {"delta_e": "elevator", "delta_a": "aileron", "delta_r": "rudder"}[c]
