"""Sensor models: what a small autopilot (MPU-class IMU, MS5611 baro, MS4525 pitot, u-blox GPS) would log.

Each stream is sampled on a decimation of the plan's tick grid (rates in
:data:`STREAM_RATES_HZ`) from the truth, with white noise of the standard
deviations in :class:`SensorConfig` and the sensor effects of
:class:`gcs_sysid.sim.effects.Effects` (biases, airspeed scale, CG offset moving
the IMU lever arm). The IMU measures the specific force at its own position::

    f_imu = f_cg + omega_dot x l + omega x (omega x l),   l = lever arm from the true CG

(Stevens, Lewis and Johnson, 3rd ed., sec. 1.9). AOA_SSA is the autopilot's
*estimate* (first-order lag of 0.1 s on the truth, plus bias and noise; beta
noisier), not a vane; WIND is an EKF-like slowly wandering estimate of the
steady wind; GPS-derived GLOBAL_POSITION_INT is emitted at the EKF output rate.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import Mapping

import numpy as np
from scipy.signal import lfilter

from ..errors import InputError
from .dynamics import dcm, quat_from_euler
from .effects import Effects
from .environment import RHO0, isa

__all__ = ["SensorConfig", "STREAM_RATES_HZ", "decimation", "make_sensors"]

#: Nominal output rate of each stream (Hz); the real rate is the plan rate divided by a whole number.
STREAM_RATES_HZ = {"imu": 50.0, "attitude": 50.0, "servo": 50.0, "gps": 25.0, "pressure": 25.0,
                   "vfr_hud": 10.0, "rc": 10.0, "aoa_ssa": 10.0, "wind": 2.0, "heartbeat": 1.0}


@dataclass(frozen=True)
class SensorConfig:
    """1-sigma white noise per sample (SI) and estimate time constants (s); ``[sensors]`` of the plan."""

    gyro: float = 0.005            # rad/s
    accel: float = 0.05            # m/s^2
    mag: float = 0.005             # gauss
    attitude: float = 0.003        # rad (AHRS attitude)
    attitude_rate: float = 0.002   # rad/s (AHRS rates)
    gps_vel: float = 0.07          # m/s
    gps_pos: float = 0.3           # m (slow random walk amplitude)
    baro: float = 3.0              # Pa
    airspeed: float = 0.2          # m/s (EAS)
    aoa: float = 0.005             # rad
    ssa: float = 0.02              # rad
    aoa_tau: float = 0.1           # s, lag of the AOA_SSA estimate
    wind: float = 0.3              # m/s, wander of the WIND estimate

    @staticmethod
    def from_dict(d: Mapping[str, float], source: str = "<plan>") -> "SensorConfig":
        """Overrides from the plan's ``[sensors]`` table.

        Raises:
            InputError: unknown key or a negative / non-numeric value.
        """
        names = {f.name for f in fields(SensorConfig)}
        for k, v in d.items():
            if k not in names:
                raise InputError(f"{source}: [sensors] unknown key '{k}' (expected {', '.join(sorted(names))})")
            if isinstance(v, bool) or not isinstance(v, (int, float)) or v < 0:
                raise InputError(f"{source}: [sensors] '{k}' must be a number >= 0, got {v!r}")
        return replace(SensorConfig(), **{k: float(v) for k, v in d.items()})


def decimation(rate_hz: float, stream: str) -> int:
    """Plan ticks per sample of ``stream`` (>= 1)."""
    return max(1, int(round(rate_hz / STREAM_RATES_HZ[stream])))


def _lowpass(x: np.ndarray, dt: float, tau: float) -> np.ndarray:
    if tau <= 0:
        return x
    a = np.exp(-dt / tau)
    y, _ = lfilter([1 - a], [1, -a], x, zi=[a * x[0]])
    return y


def _walk(rng: np.random.Generator, n: int, dt: float, sigma: float, tau: float = 5.0) -> np.ndarray:
    """First-order Gauss-Markov noise of stationary std ``sigma`` and correlation time ``tau``."""
    a = np.exp(-dt / tau)
    e = rng.normal(0.0, sigma * np.sqrt(1 - a * a), n)
    y, _ = lfilter([1.0], [1, -a], e, zi=[a * rng.normal(0.0, sigma)])
    return y


def make_sensors(t: np.ndarray, truth: Mapping[str, np.ndarray], lever_arm: np.ndarray, effects: Effects,
                 cfg: SensorConfig, rng: np.random.Generator, rate_hz: float,
                 home: tuple[float, float, float], steady_wind=(0.0, 0.0, 0.0)) -> dict[str, dict[str, np.ndarray]]:
    """Simulated sensor streams.

    Args:
        t: vehicle time of the ticks, s, shape (T,).
        truth: truth arrays (T,) (keys of ``SimResult.truth``).
        lever_arm: nominal IMU position from the nominal CG, m, (3,).
        effects: biases, airspeed scale and CG offset.
        cfg: noise levels. rng: seeded generator. rate_hz: tick rate.
        home: (lat rad, lon rad, ground altitude m AMSL) of the NED origin.
        steady_wind: the steady wind (NED, m/s) the WIND estimate wanders around.

    Returns:
        stream -> {"t": (N,), field: (N,)}, SI units: ``imu`` (ax ay az m/s^2, p q r rad/s,
        mx my mz gauss), ``attitude`` (roll pitch yaw rad, p q r rad/s), ``gps`` (lat lon rad,
        alt m AMSL, relative_alt m, vn ve vd m/s), ``local_position`` (x y z vx vy vz),
        ``pressure`` (press_abs Pa, temperature K, diff_pressure Pa), ``airspeed`` (eas m/s),
        ``aoa_ssa`` (alpha beta rad), ``wind`` (wn we wd m/s).
    """
    T = len(t)
    dt = 1.0 / rate_hz
    tr = truth

    def sub(stream):
        return slice(0, T, decimation(rate_hz, stream))

    def noise(sigma, n):
        return rng.normal(0.0, sigma, n) if sigma > 0 else np.zeros(n)

    out: dict[str, dict[str, np.ndarray]] = {}
    # IMU at its lever arm from the true CG
    arm = np.asarray(lever_arm, float) - np.asarray(effects.cg_offset, float)
    w = np.stack([tr["p"], tr["q"], tr["r"]], 1)
    wd = np.stack([tr["p_dot"], tr["q_dot"], tr["r_dot"]], 1)
    f_cg = np.stack([tr["ax"], tr["ay"], tr["az"]], 1)
    f_imu = f_cg + np.cross(wd, arm) + np.cross(w, np.cross(w, arm))
    s = sub("imu")
    n = len(t[s])
    imu = {"t": t[s]}
    for i, a in enumerate("xyz"):
        imu[f"a{a}"] = f_imu[s, i] + effects.accel_bias[i] + noise(cfg.accel, n)
    for i, k in enumerate("pqr"):
        imu[k] = w[s, i] + effects.gyro_bias[i] + noise(cfg.gyro, n)
    # earth field (gauss, NED, mid-latitude) rotated into body axes with the truth attitude
    C = dcm(quat_from_euler(tr["phi"][s], tr["theta"][s], tr["psi"][s]))
    m_b = np.einsum("nji,j->ni", C, np.array([0.21, 0.0, 0.43]))
    for i, a in enumerate("xyz"):
        imu[f"m{a}"] = m_b[:, i] + noise(cfg.mag, n)
    out["imu"] = imu
    s = sub("attitude")
    n = len(t[s])
    out["attitude"] = {"t": t[s], "roll": tr["phi"][s] + noise(cfg.attitude, n),
                       "pitch": tr["theta"][s] + noise(cfg.attitude, n),
                       "yaw": tr["psi"][s] + noise(cfg.attitude, n),
                       "p": tr["p"][s] + noise(cfg.attitude_rate, n), "q": tr["q"][s] + noise(cfg.attitude_rate, n),
                       "r": tr["r"][s] + noise(cfg.attitude_rate, n)}
    # GPS / EKF position and velocity
    s = sub("gps")
    n = len(t[s])
    dts = dt * decimation(rate_hz, "gps")
    pn = tr["pn"][s] + _walk(rng, n, dts, cfg.gps_pos)
    pe = tr["pe"][s] + _walk(rng, n, dts, cfg.gps_pos)
    alt = tr["alt"][s] + _walk(rng, n, dts, cfg.gps_pos)
    vel = [tr[k][s] + noise(cfg.gps_vel, n) for k in ("vn", "ve", "vd")]
    lat0, lon0, h0 = home
    R = 6378137.0
    out["gps"] = {"t": t[s], "lat": lat0 + pn / R, "lon": lon0 + pe / (R * np.cos(lat0)), "alt": alt,
                  "relative_alt": alt - h0, "vn": vel[0], "ve": vel[1], "vd": vel[2]}
    out["local_position"] = {"t": t[s], "x": pn, "y": pe, "z": -(alt - h0), "vx": vel[0], "vy": vel[1], "vz": vel[2]}
    # air data: baro and pitot (EAS with scale and bias)
    s = sub("pressure")
    n = len(t[s])
    p_abs, temp, _ = isa(tr["alt"][s])
    eas_true = tr["V"] * np.sqrt(tr["rho"] / RHO0)
    eas_meas = effects.airspeed_scale * eas_true + effects.airspeed_bias + noise(cfg.airspeed, T)
    eas_meas = np.maximum(eas_meas, 0.0)
    out["pressure"] = {"t": t[s], "press_abs": p_abs + noise(cfg.baro, n), "temperature": temp + 10.0,
                       "diff_pressure": 0.5 * RHO0 * eas_meas[s] ** 2}
    out["airspeed"] = {"t": t, "eas": eas_meas}
    # autopilot's alpha / beta estimate
    s = sub("aoa_ssa")
    n = len(t[s])
    a_est = _lowpass(tr["alpha"], dt, cfg.aoa_tau)[s] + effects.alpha_bias + noise(cfg.aoa, n)
    b_est = _lowpass(tr["beta"], dt, cfg.aoa_tau)[s] + effects.beta_bias + noise(cfg.ssa, n)
    out["aoa_ssa"] = {"t": t[s], "alpha": a_est, "beta": b_est}
    # EKF wind estimate: the steady wind plus a slow wander
    s = sub("wind")
    n = len(t[s])
    dtw = dt * decimation(rate_hz, "wind")
    steady = [np.full(n, float(v)) for v in steady_wind]
    out["wind"] = {"t": t[s], "wn": steady[0] + _walk(rng, n, dtw, cfg.wind, 20.0),
                   "we": steady[1] + _walk(rng, n, dtw, cfg.wind, 20.0), "wd": steady[2]}
    return out
