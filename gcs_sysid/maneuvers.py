"""Excitation maneuvers that would shrink the model's uncertainty where the confidence map flags it.

For each flagged region (``gcs_sysid.envelope``) a maneuver is designed on the surface that drives
the weak coefficient (elevator for CX CZ Cm, aileron for Cl, rudder for CY Cn; an orthogonal
multisine on several surfaces when several axes are weak there):

1. Derivative estimates by ordinary least squares on the training rows (equation error, Morelli
   and Klein, *Aircraft System Identification*, 2nd ed., 2016, ch. 5); a derivative with the wrong
   sign or |t| < 2 is replaced by a typical small-UAV value (Beard and McLain, *Small Unmanned
   Aircraft*, 2012, app. E, Aerosonde), and the text says so.
2. Flight condition from the region's centre: V and alpha, one from the other through 1-g trim
   (-CZ qbar S = m g), elevator trim from Cm = 0.
3. Linear response around that condition: short-period model (alpha, q) for the elevator, and
   the lateral-directional model (beta, p, r, phi, with Ixz) for aileron and rudder (Etkin and
   Reid, *Dynamics of Flight*, 3rd ed., 1996, ch. 6 and 9), discretised exactly (zero-order hold).
   Mode frequencies from its eigenvalues: short period and Dutch roll natural frequencies, roll
   subsidence inverse time constant.
4. Pulse width from the mode frequency (Jategaonkar, *Flight Vehicle System Identification*, 2006,
   sec. 2.5: doublet ``dt = 2.3 / w_n``, 3-2-1-1 ``dt = 1.6 / w_n``); multisine band around the
   modes (Morelli 2003). Amplitude so the response stays linear (target alpha/q, p, beta
   excursions and bank angle), raised to reach the region's deflection or rate if needed, capped
   by a fraction of the surface authority left at trim.
5. Ranking: the regressor trajectory the maneuver would produce is passed to the model, which
   returns the predictive variance at the region's points after observing it
   (``model.global_variance_after_many`` for the package's GP: all candidates in one batched,
   closed-form update of the global layer; ``model.variance_after`` for any other model); the
   relative reduction of the variance at the region's points, weighted towards the weakest
   coefficients (lowest confidence score), is the priority (active learning by variance
   reduction: MacKay, "Information-based objective functions for active data selection",
   Neural Computation 4(4), 1992).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.linalg import expm

from . import signals
from .aero.table import COEFFICIENTS, MOMENT_COEFFICIENTS, REGRESSORS, CoefficientTable
from .airframe import CONTROLS, Airframe
from .envelope import EnvelopeMap, FlaggedRegion, model_variance
from .errors import InputError

__all__ = ["ManeuverConfig", "Suggestion", "suggest_maneuvers", "derivative_estimates", "linear_models",
           "SURFACE_OF", "SURFACE_NAMES"]

G = 9.80665
#: Surface that drives each coefficient.
SURFACE_OF = {"CX": "delta_e", "CZ": "delta_e", "Cm": "delta_e", "Cl": "delta_a", "CY": "delta_r", "Cn": "delta_r"}
SURFACE_NAMES = {"delta_e": "elevator", "delta_a": "aileron", "delta_r": "rudder"}
_MODE_OF = {"delta_e": "short period", "delta_a": "roll subsidence", "delta_r": "Dutch roll"}
_RATE_OF = {"delta_e": "q_hat", "delta_a": "p_hat", "delta_r": "r_hat"}
#: Typical values (Beard and McLain 2012, app. E, Aerosonde), signs per docs/conventions.md.
_PRIOR = {("CZ", "alpha"): -5.6, ("CZ", "q_hat"): -7.9, ("CZ", "delta_e"): -0.13, ("Cm", "alpha"): -2.7,
          ("Cm", "q_hat"): -38.0, ("Cm", "delta_e"): -0.99, ("CY", "beta"): -0.98, ("CY", "delta_r"): 0.17,
          ("Cl", "beta"): -0.12, ("Cl", "p_hat"): -0.51, ("Cl", "r_hat"): 0.25, ("Cl", "delta_a"): -0.17,
          ("Cn", "beta"): 0.073, ("Cn", "p_hat"): -0.069, ("Cn", "r_hat"): -0.095, ("Cn", "delta_r"): -0.069}
_LIN = ("alpha", "beta", "p_hat", "q_hat", "r_hat", "delta_e", "delta_a", "delta_r", "delta_t")


@dataclass(frozen=True)
class ManeuverConfig:
    """Settings of :func:`suggest_maneuvers` (angles in deg, rates in deg/s where named so).

    Attributes:
        target_alpha_deg, target_q_deg_s: elevator inputs sized for these peak excursions.
        target_p_deg_s, target_beta_deg: aileron / rudder inputs sized for these.
        max_bank_deg: lateral inputs also keep the bank excursion below this.
        authority_fraction: at most this fraction of the surface travel left at trim.
        min_amplitude_deg: smallest amplitude suggested.
        max_regions: regions (most uncertain, weakest coefficients first) turned into candidates.
        sample_hz: rate at which the response is simulated (x5 internally).
        n_extra: the trajectory given to ``variance_after`` is this many evenly spaced samples of
            the maneuver (one information budget per maneuver, and one array shape so a JAX model
            compiles once).
        query_bucket: query arrays are padded (last row repeated) to a multiple of this length,
            again so a JAX model sees few distinct shapes.
        lead_s, settle_s: trim time before and free response after the input.
        min_pulse_s, max_pulse_s: pulse width limits.
        max_band_hz: highest multisine frequency (servo bandwidth, pilot or autopilot injection).
    """

    target_alpha_deg: float = 3.0
    target_q_deg_s: float = 20.0
    target_p_deg_s: float = 45.0
    target_beta_deg: float = 4.0
    max_bank_deg: float = 30.0
    authority_fraction: float = 0.6
    min_amplitude_deg: float = 1.0
    max_regions: int = 24
    sample_hz: float = 10.0
    n_extra: int = 64
    query_bucket: int = 256
    lead_s: float = 1.0
    settle_s: float = 3.0
    min_pulse_s: float = 0.15
    max_pulse_s: float = 3.0
    max_band_hz: float = 2.5


@dataclass
class Suggestion:
    """One maneuver to fly next.

    Attributes:
        rank: 1 = fly first.
        coefficients: targeted coefficients, weakest first.
        kind: ``"doublet"``, ``"3211"`` or ``"multisine"`` (:data:`gcs_sysid.signals.KINDS`).
        controls: controls excited, e.g. ``("delta_e",)``.
        amplitude_rad, amplitude_deg: peak input of the first control.
        amplitudes_rad: control -> peak input, rad.
        pulse_width_s: unit pulse width (doublet, 3211); for a multisine its shortest half period.
        duration_s: the whole maneuver including trim lead-in and settling, s.
        flight_condition: ``V`` m/s, ``alpha`` rad, ``alpha_deg``, ``load_factor``, ``delta_e_trim``
            rad, ``rho`` kg/m^3, ``density_altitude_m``, ``beta`` rad when a steady sideslip is asked.
        expected_reduction: mean relative reduction of predictive variance at the region's points
            over the targeted coefficients, 0..1.
        reductions: coefficient -> relative reduction.
        priority: ranking key (reduction weighted towards the weakest coefficients).
        reason: why, naming coefficient, region and sigma.
        region: the (weakest coefficient's) region: ``axes``, ``bounds``, ``center``, ``mean_rel_sigma``.
        mode_hz: natural frequency (Hz) of the excited mode(s), control -> Hz.
        band_hz: multisine band (lo, hi) in Hz, else None.
        t: waveform time, s, shape (K,). u: control -> input deviation from trim, rad, shape (K,).
        assumed: derivatives taken from typical values rather than these data.
    """

    rank: int
    coefficients: tuple[str, ...]
    kind: str
    controls: tuple[str, ...]
    amplitude_rad: float
    amplitude_deg: float
    amplitudes_rad: dict[str, float]
    pulse_width_s: float
    duration_s: float
    flight_condition: dict[str, float]
    expected_reduction: float
    reductions: dict[str, float]
    priority: float
    reason: str
    region: dict[str, Any]
    mode_hz: dict[str, float] = field(default_factory=dict)
    band_hz: tuple[float, float] | None = None
    t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    u: dict[str, np.ndarray] = field(default_factory=dict)
    assumed: list[str] = field(default_factory=list)

    @property
    def control(self) -> str:
        """The first (main) control."""
        return self.controls[0]

    def to_dict(self) -> dict[str, Any]:
        """JSON-able dict (waveform as lists)."""
        r = lambda x: round(float(x), 6)  # noqa: E731
        return {
            "rank": self.rank, "coefficients": list(self.coefficients), "kind": self.kind,
            "controls": list(self.controls), "surfaces": [SURFACE_NAMES[c] for c in self.controls],
            "amplitude_rad": r(self.amplitude_rad), "amplitude_deg": r(self.amplitude_deg),
            "amplitudes_rad": {k: r(v) for k, v in self.amplitudes_rad.items()},
            "pulse_width_s": r(self.pulse_width_s), "duration_s": r(self.duration_s),
            "flight_condition": {k: r(v) for k, v in self.flight_condition.items()},
            "expected_reduction": r(self.expected_reduction), "reductions": {k: r(v) for k, v in self.reductions.items()},
            "priority": r(self.priority), "reason": self.reason, "region": self.region,
            "mode_hz": {k: r(v) for k, v in self.mode_hz.items()},
            "band_hz": None if self.band_hz is None else [r(x) for x in self.band_hz],
            "waveform": {"t": np.round(self.t, 4).tolist(), **{k: np.round(v, 6).tolist() for k, v in self.u.items()}},
            "assumed": list(self.assumed),
        }

    @staticmethod
    def from_dict(d: dict[str, Any]) -> "Suggestion":
        """Inverse of :meth:`to_dict`."""
        wf = dict(d.get("waveform", {}))
        t = np.asarray(wf.pop("t", []), float)
        return Suggestion(int(d["rank"]), tuple(d["coefficients"]), d["kind"], tuple(d["controls"]),
                          float(d["amplitude_rad"]), float(d["amplitude_deg"]), dict(d["amplitudes_rad"]),
                          float(d["pulse_width_s"]), float(d["duration_s"]), dict(d["flight_condition"]),
                          float(d["expected_reduction"]), dict(d["reductions"]), float(d["priority"]), d["reason"],
                          dict(d["region"]), dict(d.get("mode_hz", {})),
                          None if d.get("band_hz") is None else tuple(d["band_hz"]), t,
                          {k: np.asarray(v, float) for k, v in wf.items()}, list(d.get("assumed", [])))


# ----------------------------------------------------------------------------- derivatives, models


def derivative_estimates(table: CoefficientTable, mask: np.ndarray) -> tuple[dict[tuple[str, str], float],
                                                                              dict[str, float], list[str]]:
    """Equation-error least squares of each coefficient on the linear regressors.

    Args:
        table: coefficient table (T rows). mask: (T,) bool rows to use.

    Returns:
        (derivs, at_ref, assumed): ``derivs[(coef, regressor)]`` (per rad, or per unit of the
        normalised rate); ``at_ref[coef]`` the fitted coefficient at the median regressors;
        ``assumed`` names like ``"Cm_q"`` replaced by typical values (wrong sign, |t| < 2 or no data).

    Source: Morelli and Klein (2016), ch. 5 (ordinary least squares, parameter standard errors).
    """
    rows = mask & np.all(np.isfinite(table.X), axis=1)
    cols = [REGRESSORS.index(r) for r in _LIN]
    X = table.X[rows][:, cols]
    ref = np.median(X, axis=0) if len(X) else np.zeros(len(cols))
    derivs: dict[tuple[str, str], float] = {}
    at_ref: dict[str, float] = {}
    assumed: list[str] = []
    for j, c in enumerate(COEFFICIENTS):
        y = table.Y[rows, j]
        ok = np.isfinite(y)
        theta = np.full(len(cols), np.nan)
        tstat = np.zeros(len(cols))
        if ok.sum() > len(cols) + 2:
            A = np.column_stack([np.ones(ok.sum()), X[ok] - ref])
            sd = A.std(0)
            live = np.r_[True, sd[1:] > 1e-9]
            As = A[:, live] / np.where(sd[live] > 0, sd[live], 1.0)
            th, *_ = np.linalg.lstsq(As, y[ok], rcond=None)
            res = y[ok] - As @ th
            s2 = float(res @ res) / max(1, len(res) - As.shape[1])
            cov = s2 * np.linalg.pinv(As.T @ As)
            th_full = np.zeros(A.shape[1])
            se_full = np.full(A.shape[1], np.inf)
            th_full[live] = th / np.where(sd[live] > 0, sd[live], 1.0)
            se_full[live] = np.sqrt(np.maximum(np.diag(cov), 0)) / np.where(sd[live] > 0, sd[live], 1.0)
            at_ref[c] = float(th_full[0])
            theta = th_full[1:]
            tstat = np.abs(theta) / np.where(se_full[1:] > 0, se_full[1:], np.inf)
            theta[~live[1:]] = np.nan
        else:
            at_ref[c] = 0.0
        for k, r in enumerate(_LIN):
            v = theta[k]
            prior = _PRIOR.get((c, r))
            if prior is not None and (not np.isfinite(v) or np.sign(v) != np.sign(prior) or tstat[k] < 2.0):
                derivs[(c, r)] = prior
                assumed.append(f"{c}_{r.replace('_hat', '')}")
            else:
                derivs[(c, r)] = float(v) if np.isfinite(v) else 0.0
    return derivs, at_ref, assumed


def linear_models(d: dict[tuple[str, str], float], airframe: Airframe, V: float, rho: float,
                  alpha0: float) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Continuous linear models around a flight condition.

    Args:
        d: derivatives from :func:`derivative_estimates`. airframe: mass, inertia, geometry.
        V: airspeed m/s. rho: air density kg/m^3. alpha0: trim alpha, rad (= pitch in level flight).

    Returns:
        ``{"lon": (A (2,2), B (2,1)), "lat": (A (4,4), B (4,2))}``: longitudinal states
        (alpha, q) with input delta_e; lateral states (beta, p, r, phi) with inputs (delta_a, delta_r).

    Source: Etkin and Reid (1996) sec. 6.2 (short period), sec. 6.7-6.8 and 9 (lateral, Ixz via the
    inverse inertia).
    """
    qS = 0.5 * rho * V**2 * airframe.S
    m, b, c = airframe.mass, airframe.b, airframe.c
    Za, Zq, Zde = qS * d[("CZ", "alpha")] / m, qS * d[("CZ", "q_hat")] * c / (2 * V) / m, qS * d[("CZ", "delta_e")] / m
    Ma = qS * c * d[("Cm", "alpha")] / airframe.Iyy
    Mq = qS * c * d[("Cm", "q_hat")] * c / (2 * V) / airframe.Iyy
    Mde = qS * c * d[("Cm", "delta_e")] / airframe.Iyy
    A_lon = np.array([[Za / V, 1.0 + Zq / V], [Ma, Mq]])
    B_lon = np.array([[Zde / V], [Mde]])
    Iinv = np.linalg.inv(np.array([[airframe.Ixx, -airframe.Ixz], [-airframe.Ixz, airframe.Izz]]))
    row = lambda coef: np.array([d[(coef, "beta")], d[(coef, "p_hat")] * b / (2 * V),  # noqa: E731
                                 d[(coef, "r_hat")] * b / (2 * V), d[(coef, "delta_a")], d[(coef, "delta_r")]])
    LN = Iinv @ (qS * b * np.vstack([row("Cl"), row("Cn")]))          # (2, 5): beta p r da dr
    Y = qS / m * row("CY")
    th = alpha0
    A_lat = np.array([
        [Y[0] / V, Y[1] / V + np.sin(alpha0), Y[2] / V - np.cos(alpha0), G * np.cos(th) / V],
        [LN[0, 0], LN[0, 1], LN[0, 2], 0.0],
        [LN[1, 0], LN[1, 1], LN[1, 2], 0.0],
        [0.0, 1.0, np.tan(th), 0.0],
    ])
    B_lat = np.array([[Y[3] / V, Y[4] / V], [LN[0, 3], LN[0, 4]], [LN[1, 3], LN[1, 4]], [0.0, 0.0]])
    return {"lon": (A_lon, B_lon), "lat": (A_lat, B_lat)}


def _mode_omega(models: dict, control: str) -> float:
    """Natural frequency (rad/s) of the mode a control excites, from the model's eigenvalues."""
    if control == "delta_e":
        ev = np.linalg.eigvals(models["lon"][0])
        return float(np.max(np.abs(ev)))
    ev = np.linalg.eigvals(models["lat"][0])
    if control == "delta_a":  # roll subsidence: the fastest real eigenvalue
        real = ev[np.abs(ev.imag) < 1e-9]
        return float(np.max(np.abs(real))) if real.size else float(np.max(np.abs(ev)))
    cplx = ev[np.abs(ev.imag) > 1e-9]
    return float(np.max(np.abs(cplx))) if cplx.size else float(np.median(np.abs(ev)))


def _simulate(A: np.ndarray, B: np.ndarray, U: np.ndarray, dt: float) -> np.ndarray:
    """Zero-order-hold response x (K, n) to inputs U (K, m) from x = 0."""
    n, m = B.shape
    M = expm(np.block([[A, B], [np.zeros((m, n + m))]]) * dt)
    Ad, Bd = M[:n, :n], M[:n, n:]
    x = np.zeros((len(U), n))
    for k in range(1, len(U)):
        x[k] = Ad @ x[k - 1] + Bd @ U[k - 1]
        if not np.all(np.abs(x[k]) < 1e6):
            x[k:] = np.nan
            break
    return x


# ----------------------------------------------------------------------------- design


@dataclass
class _Context:
    model: Any
    env: EnvelopeMap
    airframe: Airframe
    cfg: ManeuverConfig
    d: dict
    at_ref: dict
    assumed: list
    ref: dict
    rho: float
    authority: dict
    weight: dict
    dt_data: float


def _authority(airframe: Airframe) -> dict[str, float]:
    """Control travel (rad) each effective control can reach with its servos' limits."""
    out = {}
    for cn in CONTROLS:
        out[cn] = float(sum(abs(s.mix.get(cn, 0.0)) * min(abs(s.limit_min), abs(s.limit_max)) for s in airframe.servos))
    return out


def _flight_condition(ctx: _Context, center: dict[str, float], axes: tuple[str, ...]) -> dict[str, float]:
    """V, alpha and trims for a region's centre: one of V / alpha from the other via 1-g trim."""
    a, d, ref = ctx.airframe, ctx.d, ctx.ref
    CZa = d[("CZ", "alpha")]
    CZ = lambda al: ctx.at_ref["CZ"] + CZa * (al - ref["alpha"])  # noqa: E731
    # lift needed in level flight: anchored on the reference (median) flight condition, taken as
    # 1-g trim, so CZ V^2 = const (insensitive to mass and thrust errors); weight-based otherwise
    V0 = max(ref["V"], 1.0)
    lift0 = CZ(ref["alpha"]) * V0**2 if CZ(ref["alpha"]) < 0 else -a.mass * G / (0.5 * ctx.rho * a.S)
    V, alpha = center.get("V", ref["V"]), center.get("alpha", ref["alpha"])
    if "V" in axes and "alpha" not in axes:
        alpha = ref["alpha"] + (lift0 / max(V, 1.0) ** 2 - CZ(ref["alpha"])) / CZa
    elif "alpha" in axes and "V" not in axes and CZ(alpha) < 0:
        V = float(np.sqrt(lift0 / CZ(alpha)))
    V = float(max(V, 1.0))
    n = float(CZ(alpha) * V**2 / lift0)
    de = ref["delta_e"] - (ctx.at_ref["Cm"] + d[("Cm", "alpha")] * (alpha - ref["alpha"])) / d[("Cm", "delta_e")]
    fc = {"V": V, "alpha": float(alpha), "alpha_deg": float(np.degrees(alpha)), "load_factor": n,
          "delta_e_trim": float(de), "rho": ctx.rho,
          "density_altitude_m": float(44330.8 * (1 - (ctx.rho / 1.225) ** (1 / 4.2559)))}
    if "beta" in axes:
        beta = center["beta"]
        fc["beta"] = float(beta)
        fc["delta_r_sideslip"] = float(ref["delta_r"] - d[("Cn", "beta")] * (beta - ref["beta"]) / d[("Cn", "delta_r")])
    return fc


def _pulse(kind: str, omega: float, cfg: ManeuverConfig, dt_data: float) -> float:
    k = 2.3 if kind == "doublet" else 1.6   # Jategaonkar (2006) sec. 2.5
    return float(np.clip(k / max(omega, 1e-3), max(cfg.min_pulse_s, 2 * dt_data), cfg.max_pulse_s))


def _design(ctx: _Context, kind: str, controls: tuple[str, ...], coefs: tuple[str, ...],
            region: FlaggedRegion) -> tuple[dict, np.ndarray] | None:
    """Waveform, amplitudes and the regressor trajectory (K, 10) of one candidate."""
    cfg = ctx.cfg
    fc = _flight_condition(ctx, region.center, region.axes)
    V = fc["V"]
    models = linear_models(ctx.d, ctx.airframe, V, ctx.rho, fc["alpha"])
    omega = {c: _mode_omega(models, c) for c in controls}
    dt = 1.0 / cfg.sample_hz / 5.0
    if kind == "multisine":
        f = np.array([w / (2 * np.pi) for w in omega.values()])
        lo = max(0.1, 0.3 * f.min())
        hi = max(min(2.0 * f.max(), 0.4 / max(ctx.dt_data, 1e-3), cfg.max_band_hz), 2 * lo)
        T_in = float(np.clip(2.0 / lo, 8.0, 20.0))
        band = (lo, hi)
        pulse = 1.0 / (2 * hi)
    else:
        pulse = _pulse(kind, min(omega.values()), cfg, ctx.dt_data)
        T_in, band = signals.duration_of(kind, pulse), None
    total = cfg.lead_s + T_in + cfg.settle_s
    t = np.arange(0.0, total, dt)
    base = {"delta_e": fc["delta_e_trim"], "delta_a": ctx.ref["delta_a"],
            "delta_r": fc.get("delta_r_sideslip", ctx.ref["delta_r"])}
    unit = {}
    for i, c in enumerate(controls):
        unit[c] = signals.waveform(kind, t, cfg.lead_s, 1.0, pulse_width=pulse, duration=T_in, band=band,
                                   n_inputs=len(controls), index=i)
    amps, notes = {}, []
    for c in controls:
        resp = _response(models, {c: unit[c]}, t, V, ctx.airframe)
        if resp is None:
            return None
        peaks = {k: np.nanmax(np.abs(v)) + 1e-12 for k, v in resp.items()}
        if c == "delta_e":
            lin = min(np.radians(cfg.target_alpha_deg) / peaks["alpha"], np.radians(cfg.target_q_deg_s) / peaks["q"])
        elif c == "delta_a":
            lin = min(np.radians(cfg.target_p_deg_s) / peaks["p"], np.radians(cfg.max_bank_deg) / peaks["phi"])
        else:
            lin = min(np.radians(cfg.target_beta_deg) / peaks["beta"], np.radians(cfg.max_bank_deg) / peaks["phi"])
        reach = 0.0
        if c in region.axes:
            reach = abs(region.center[c] - base[c])
        rate = _RATE_OF[c]
        if rate in region.axes:
            key = {"q_hat": "q", "p_hat": "p", "r_hat": "r"}[rate]
            scale = (ctx.airframe.c if rate == "q_hat" else ctx.airframe.b) / (2 * V)
            reach = max(reach, abs(region.center[rate]) / (peaks[key] * scale))
        amp = max(lin, reach)
        room = ctx.cfg.authority_fraction * max(ctx.authority[c] - abs(base[c]), 0.0)
        if reach > lin and amp <= room:
            notes.append(f"{SURFACE_NAMES[c]} amplitude raised above the linear-response target to reach the region")
        amps[c] = float(np.clip(amp, np.radians(cfg.min_amplitude_deg), max(room, np.radians(cfg.min_amplitude_deg))))
    u = {c: amps[c] * unit[c] for c in controls}
    resp = _response(models, u, t, V, ctx.airframe)
    if resp is None:
        return None
    X = np.tile(np.array([ctx.ref[r] for r in REGRESSORS]), (len(t), 1))
    col = lambda name: REGRESSORS.index(name)  # noqa: E731
    X[:, col("V")] = V
    X[:, col("alpha")] = fc["alpha"] + resp["alpha"]
    X[:, col("beta")] = fc.get("beta", ctx.ref["beta"]) + resp["beta"]
    X[:, col("q_hat")] = resp["q"] * ctx.airframe.c / (2 * V)
    X[:, col("p_hat")] = resp["p"] * ctx.airframe.b / (2 * V)
    X[:, col("r_hat")] = resp["r"] * ctx.airframe.b / (2 * V)
    for c in CONTROLS:
        X[:, col(c)] = base[c] + u.get(c, 0.0)
    idx = np.linspace(0, len(t) - 1, cfg.n_extra).round().astype(int)
    design = {"fc": fc, "amps": amps, "pulse": pulse, "duration": total, "band": band, "t": t[::2],
              "u": {c: v[::2] for c, v in u.items()}, "mode_hz": {c: w / (2 * np.pi) for c, w in omega.items()},
              "notes": notes}
    return design, X[idx]


def _response(models: dict, u: dict[str, np.ndarray], t: np.ndarray, V: float, af: Airframe) -> dict | None:
    """Deviations alpha, q, beta, p, r, phi (rad, rad/s) for control deviations u (rad)."""
    dt = t[1] - t[0]
    z = np.zeros(len(t))
    A, B = models["lon"]
    lon = _simulate(A, B, u.get("delta_e", z)[:, None], dt)
    A, B = models["lat"]
    lat = _simulate(A, B, np.column_stack([u.get("delta_a", z), u.get("delta_r", z)]), dt)
    if not (np.isfinite(lon).all() and np.isfinite(lat).all()):
        return None
    return {"alpha": lon[:, 0], "q": lon[:, 1], "beta": lat[:, 0], "p": lat[:, 1], "r": lat[:, 2], "phi": lat[:, 3]}


def _pad(X: np.ndarray, bucket: int) -> np.ndarray:
    """Rows of X padded to a multiple of ``bucket`` by repeating the last row (Q, D) -> (Q', D)."""
    n = len(X)
    m = int(np.ceil(n / bucket) * bucket) if bucket > 0 else n
    return np.vstack([X, np.repeat(X[-1:], m - n, axis=0)]) if m > n else X


def _surface_for(coef: str, authority: dict[str, float]) -> str | None:
    c = SURFACE_OF[coef]
    if authority.get(c, 0.0) > 0:
        return c
    alt = {"delta_r": "delta_a", "delta_a": "delta_r"}.get(c)   # no rudder: aileron yaws too (adverse yaw)
    return alt if alt and authority.get(alt, 0.0) > 0 else None


def _describe(region: FlaggedRegion) -> str:
    def unit(k: str, v: float) -> str:
        if k in ("alpha", "beta", "delta_e", "delta_a", "delta_r"):
            return f"{np.degrees(v) + 0.0:.1f} deg".replace("-0.0 ", "0.0 ")
        return f"{v:.1f} m/s" if k == "V" else f"{v + 0.0:.3f}".replace("-0.000", "0.000")

    return ", ".join(f"{k} {unit(k, lo)}..{unit(k, hi)}" for k, (lo, hi) in region.bounds.items())


def _group(regions: list[FlaggedRegion]) -> list[list[FlaggedRegion]]:
    """Regions of one slice whose centres lie in each other's boxes form a group (one location)."""
    groups: list[list[FlaggedRegion]] = []
    inside = lambda c, b: all(b[k][0] <= c[k] <= b[k][1] for k in b)  # noqa: E731
    for r in regions:
        for g in groups:
            if g[0].axes == r.axes and (inside(r.center, g[0].bounds) or inside(g[0].center, r.bounds)):
                g.append(r)
                break
        else:
            groups.append([r])
    return groups


def suggest_maneuvers(envelope: EnvelopeMap, model: Any, table: CoefficientTable, airframe: Airframe,
                      max_suggestions: int = 10, config: ManeuverConfig | None = None) -> list[Suggestion]:
    """Design and rank maneuvers that excite the flagged regions of the confidence map.

    Args:
        envelope: the confidence map (its ``outputs`` name the model's output columns).
        model: ``predict(X) -> (mean, var)`` and ``variance_after(X_extra, X_query) -> var (Q, P)``.
        table: the coefficient table (valid rows give the derivative estimates and air density).
        airframe: mass, inertia, geometry and surface limits.
        max_suggestions: at most this many, best first.
        config: design settings (:class:`ManeuverConfig`).

    Returns:
        Suggestions ranked by priority (expected variance reduction weighted towards the weakest
        coefficients), ``rank`` 1 first; empty when nothing is flagged.

    Raises:
        InputError: ``max_suggestions`` < 1.

    Source: module docstring (Morelli and Klein 2016 ch. 9; Jategaonkar 2006 sec. 2.5; MacKay 1992).
    """
    if max_suggestions < 1:
        raise InputError(f"max_suggestions must be >= 1, got {max_suggestions}")
    cfg = config or ManeuverConfig()
    outs = list(envelope.outputs)
    regions = [r for r in envelope.regions if r.coefficient in outs and len(r.points)]
    if not regions:
        return []
    rows = table.valid & np.all(np.isfinite(table.X), axis=1)
    d, at_ref, assumed = derivative_estimates(table, rows)
    qv = 2 * table.qbar[rows] / np.maximum(table.x("V")[rows], 1.0) ** 2
    qv = qv[np.isfinite(qv) & (qv > 0.3) & (qv < 1.6)]
    rho = float(np.median(qv)) if qv.size else 1.225
    weak = {c: 1.0 - (envelope.scores.get(c) if np.isfinite(envelope.scores.get(c, np.nan)) else 0.0) for c in outs}
    wmax = max(weak.values()) or 1.0
    weight = {c: max(v, 1e-3) / wmax for c, v in weak.items()}
    dts = np.diff(table.t)
    ctx = _Context(model, envelope, airframe, cfg, d, at_ref, assumed, dict(envelope.reference), rho,
                   _authority(airframe), weight, float(np.median(dts)) if dts.size else 0.02)
    regions.sort(key=lambda r: -r.mean_rel_sigma * weight[r.coefficient])
    designs = []      # (gi, kind, controls, targets, lead, design, X_extra, query index)
    queries = []      # per group: (Xq padded, coefficient -> row slice)
    for gi, grp in enumerate(_group(regions[:cfg.max_regions])):
        coefs = sorted({r.coefficient for r in grp}, key=lambda c: (-weight[c], c not in MOMENT_COEFFICIENTS, c))
        pts = {c: np.vstack([r.points for r in grp if r.coefficient == c]) for c in coefs}
        sl = {}
        k0 = 0
        for c in coefs:
            sl[c] = slice(k0, k0 + len(pts[c]))
            k0 += len(pts[c])
        queries.append((_pad(np.vstack([pts[c] for c in coefs]), cfg.query_bucket), sl))
        by_surface: dict[str, list[str]] = {}
        for c in coefs:
            s = _surface_for(c, ctx.authority)
            if s is not None:
                by_surface.setdefault(s, []).append(c)
        plans = [(k, (s,), tuple(cs)) for s, cs in by_surface.items() for k in ("doublet", "3211")]
        if len(by_surface) > 1:
            plans.append(("multisine", tuple(sorted(by_surface, key=CONTROLS.index)), tuple(coefs)))
        for kind, controls, targets in plans:
            lead = next(r for r in grp if r.coefficient == targets[0])
            out = _design(ctx, kind, controls, targets, lead)
            if out is not None:
                designs.append((gi, kind, controls, targets, lead, out[0], out[1]))
    candidates = []
    for (gi, kind, controls, targets, lead, design, _), (var0, var1) in zip(designs, _variances(model, designs, queries)):
        sl = queries[gi][1]
        red = {}
        for c in targets:
            j = outs.index(c)
            v0 = float(np.mean(var0[sl[c], j]))
            red[c] = float(np.clip(1.0 - np.mean(var1[sl[c], j]) / v0, 0.0, 1.0)) if v0 > 0 else 0.0
        prio = sum(weight[c] * red[c] for c in targets) / np.sqrt(len(targets))
        candidates.append((prio, gi, kind, controls, targets, lead, design, red))
    candidates.sort(key=lambda x: -x[0])
    chosen, seen = [], set()
    for prio, gi, kind, controls, targets, lead, design, red in candidates:
        fc = design["fc"]
        same = (kind, controls, round(fc["V"]), round(fc["alpha_deg"]), round(np.degrees(fc.get("beta", 0.0))),
                tuple(round(float(np.degrees(a)), 0) for a in design["amps"].values()))
        if (gi, controls) in seen or same in seen:   # one per location and surface; no repeats
            continue
        seen.update({(gi, controls), same})
        chosen.append(_suggestion(len(chosen) + 1, ctx, prio, kind, controls, targets, lead, design, red))
        if len(chosen) >= max_suggestions:
            break
    return chosen


def _variances(model: Any, designs: list, queries: list) -> list[tuple[np.ndarray, np.ndarray]]:
    """(variance before, variance after) at each candidate's query points, latent where possible.

    A model with ``global_variance_after_many`` (:class:`gcs_sysid.gp.LocalGlobalGP`) ranks all
    candidates in one batched call on its global layer (closed-form Woodbury update; the
    nearest-neighbour local layer is left out of both numbers); any other model is asked
    ``predict`` once per query set and ``variance_after`` once per candidate.
    """
    if not designs:
        return []
    batched = getattr(model, "global_variance_after_many", None)
    if batched is not None:
        return [tuple(np.asarray(v, float) for v in pair)
                for pair in batched([d[6] for d in designs], [queries[d[0]][0] for d in designs])]
    before: dict[int, np.ndarray] = {}
    out = []
    for d in designs:
        gi = d[0]
        if gi not in before:
            before[gi] = model_variance(model.predict, queries[gi][0])
        out.append((before[gi], model_variance(model.variance_after, d[6], queries[gi][0])))
    return out


def _suggestion(rank: int, ctx: _Context, prio: float, kind: str, controls: tuple[str, ...],
                targets: tuple[str, ...], region: FlaggedRegion, design: dict, red: dict) -> Suggestion:
    fc = design["fc"]
    amps = design["amps"]
    main = controls[0]
    mean_red = float(np.mean([red[c] for c in targets]))
    surf = " + ".join(SURFACE_NAMES[c] for c in controls)
    modes = ", ".join(f"{_MODE_OF[c]} {design['mode_hz'][c]:.2f} Hz" for c in controls)
    relevant = {"delta_e": ("CZ", "Cm"), "delta_a": ("Cl",), "delta_r": ("CY", "Cn")}
    used = [a for a in ctx.assumed if a.split("_")[0] in {x for c in controls for x in relevant[c]}]
    amp_txt = ", ".join(f"{SURFACE_NAMES[c]} {np.degrees(a):.1f} deg" for c, a in amps.items())
    shape = (f"{kind} ({design['band'][0]:.2f}-{design['band'][1]:.2f} Hz, {design['duration'] - ctx.cfg.lead_s - ctx.cfg.settle_s:.0f} s)"
             if kind == "multisine" else f"{kind} (pulse {design['pulse']:.2f} s)")
    known = region.mean_rel_sigma <= ctx.env.thresholds.get(region.coefficient, np.inf)
    reason = (f"{', '.join(targets)} {'not flown' if known else 'poorly known'} at {_describe(region)} "
              f"(mean predictive sigma "
              f"{region.mean_rel_sigma:.2f} x the coefficient's spread, {region.n_points} samples there): "
              f"fly {'an' if surf[0] in 'aeiou' else 'a'} {surf} {shape}, amplitude {amp_txt}, at V {fc['V']:.1f} m/s, alpha {fc['alpha_deg']:.1f} deg"
              + (f", sideslip {np.degrees(fc['beta']):.1f} deg" if "beta" in fc else "")
              + (f" ({fc['load_factor']:.2f} g: {'pull-up or turn' if fc['load_factor'] > 1 else 'push-over'})"
                 if abs(fc["load_factor"] - 1.0) > 0.15 else "")
              + f"; excites the {modes}; expected variance reduction {100 * mean_red:.0f} %")
    if design["notes"]:
        reason += "; " + "; ".join(design["notes"])
    if used:
        reason += f"; typical values assumed for {', '.join(used)}"
    reg = {"coefficient": region.coefficient, "axes": list(region.axes),
           "bounds": {k: [float(a), float(b)] for k, (a, b) in region.bounds.items()},
           "center": {k: float(region.center[k]) for k in region.axes},
           "mean_rel_sigma": float(region.mean_rel_sigma), "n_points": int(region.n_points)}
    return Suggestion(rank, targets, kind, controls, amps[main], float(np.degrees(amps[main])), dict(amps),
                      float(design["pulse"]), float(design["duration"]), fc, mean_red, dict(red), float(prio), reason,
                      reg, dict(design["mode_hz"]), design["band"], design["t"], design["u"], used)
