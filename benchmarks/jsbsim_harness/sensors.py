"""What an ArduPilot autopilot would log from a JSBSim flight: noisy sensors and its AOA_SSA.

Streams follow :func:`gcs_sysid.sim.sensors.make_sensors` (same names, fields and units, so that
:func:`gcs_sysid.sim.tlog.write_tlog` writes them), sampled from the JSBSim truth:

* ``imu`` 50 Hz: specific force at the IMU, ``F_non-gravity / m`` from JSBSim's total body forces
  (JSBSim's accelerometer-equivalent output at the CG: with the WGS-84 gravity, Coriolis and transport
  rate it closes JSBSim's own NED velocity equation to 2e-5 m/s^2 across the track,
  ``tests/jsbsim/test_jsbsim_earth.py``) plus, for an IMU away from the CG (``imu_offset``, which
  the airframe file's ``imu_lever_arm`` must then state), ``omega_dot x r + omega x (omega x r)``
  with JSBSim's inertial body rates and their derivatives; by default the IMU sits at the CG, as the
  checked-in airframe files say (``imu_lever_arm = [0, 0, 0]``). Gyro = inertial body rates; white
  noise and a constant bias per seed; magnetometer from the attitude.
* ``attitude`` 50 Hz (AHRS: truth + small noise), ``gps`` / ``local_position`` 25 Hz (position
  random walk, velocity white noise), ``pressure`` 25 Hz (static pressure from JSBSim's
  atmosphere; ``diff_pressure`` = pitot dynamic pressure ``0.5 rho0 EAS^2`` with EAS noise),
  ``airspeed`` (EAS) at 50 Hz, sent in VFR_HUD at 10 Hz as ArduPilot does.
* ``wind`` 2 Hz: an EKF-like wind estimate, the true (steady + turbulent) wind low-passed with a
  10 s time constant plus a slow 0.3 m/s wander: the EKF cannot follow gusts.
* ``aoa_ssa`` 50 Hz, two variants:
  ``"ahrs"``: as ArduPilot's ``AP_AHRS::update_AOA_SSA`` computes it: the EKF ground velocity minus
  the EKF wind estimate, rotated into body axes with the AHRS attitude, ``alpha = atan2(w, u)``,
  ``beta = asin(v / |v|)``, then a 0.1 s lag and noise. It misses the gusts by construction.
  ``"vane"``: the exact JSBSim ``aero/alpha-rad``, ``aero/beta-rad`` plus 0.1 deg noise (an air-data
  boom with vanes).

References:
    ArduPilot, ``libraries/AP_AHRS/AP_AHRS.cpp``, ``update_AOA_SSA`` (github.com/ArduPilot/ardupilot).
"""

from __future__ import annotations

import zlib

import numpy as np
from scipy.signal import lfilter

from .flight import Recording

__all__ = ["SENSOR_RATES_HZ", "AOA_VARIANTS", "make_sensors", "body_from_ned"]

#: Stream rates (Hz) of the harness's logs: ArduPlane with SR0_RAW_SENS / SR0_EXTRA1 at 50 Hz and
#: AOA_SSA streamed at 50 Hz for system identification.
SENSOR_RATES_HZ = {"imu": 50.0, "attitude": 50.0, "servo": 50.0, "aoa_ssa": 50.0, "gps": 25.0,
                   "pressure": 25.0, "vfr_hud": 10.0, "rc": 10.0, "wind": 2.0, "heartbeat": 1.0}
AOA_VARIANTS = ("ahrs", "vane")
RHO0 = 1.225


def body_from_ned(phi: np.ndarray, theta: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """Rotation matrices NED -> body (3-2-1 Euler angles, rad), shape (T, 3, 3)."""
    cf, sf, ct, st, cp, sp = np.cos(phi), np.sin(phi), np.cos(theta), np.sin(theta), np.cos(psi), np.sin(psi)
    R = np.empty(phi.shape + (3, 3))
    R[..., 0, :] = np.stack([ct * cp, ct * sp, -st], -1)
    R[..., 1, :] = np.stack([sf * st * cp - cf * sp, sf * st * sp + cf * cp, sf * ct], -1)
    R[..., 2, :] = np.stack([cf * st * cp + sf * sp, cf * st * sp - sf * cp, cf * ct], -1)
    return R


def _lowpass(x: np.ndarray, dt: float, tau: float) -> np.ndarray:
    a = np.exp(-dt / tau)
    y, _ = lfilter([1 - a], [1, -a], x, zi=[a * x[0]])
    return y


def _walk(rng: np.random.Generator, n: int, dt: float, sigma: float, tau: float) -> np.ndarray:
    a = np.exp(-dt / tau)
    y, _ = lfilter([1.0], [1, -a], rng.normal(0.0, sigma * np.sqrt(1 - a * a), n), zi=[a * rng.normal(0.0, sigma)])
    return y


def make_sensors(rec: Recording, aoa: str = "ahrs", seed: int | None = None,
                 imu_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> dict[str, dict[str, np.ndarray]]:
    """Sensor streams of a recorded flight (same layout as :func:`gcs_sysid.sim.sensors.make_sensors`).

    Args:
        rec: the flight (truth at ``rec.config.log_rate_hz``, which must be 50 Hz).
        aoa: ``"ahrs"`` (ArduPilot's estimate) or ``"vane"`` (exact angles + noise).
        seed: noise seed (default ``rec.config.seed``); the noise does not depend on ``imu_offset``.
            With ``rec.config.sensor_draw == "per_aircraft"`` the aircraft's name is mixed into it
            (CRC-32), so that each aircraft draws its own noise for the same seed.
        imu_offset: IMU position from the CG, body axes, m: the accelerometers measure
            ``f_cg + omega_dot x r + omega x (omega x r)`` (rigid body; Stevens, Lewis and Johnson
            2016, sec. 1.9). A log written with an offset needs an airframe file whose
            ``imu_lever_arm`` says so.

    Returns:
        stream -> {"t": (N,), field: (N,)}, SI (see the module docstring).

    Raises:
        ValueError: unknown ``aoa`` variant or a log rate other than 50 Hz.
    """
    if aoa not in AOA_VARIANTS:
        raise ValueError(f"aoa must be one of {AOA_VARIANTS}, got '{aoa}'")
    rate = rec.config.log_rate_hz
    if abs(rate - 50.0) > 1e-9:
        raise ValueError(f"the harness logs at 50 Hz, got {rate}")
    base = 1000 + (rec.config.seed if seed is None else seed)
    # "per_aircraft": the aircraft's name enters the seed, so that flights of one seed on different
    # aircraft draw independent noise (FlightConfig.sensor_draw); "shared" keeps the older draws
    per_aircraft = rec.config.sensor_draw == "per_aircraft"
    rng = np.random.default_rng([base, zlib.crc32(rec.config.aircraft.encode())] if per_aircraft else base)
    tr, t = rec.truth, rec.t
    T, dt = len(t), 1.0 / rate
    m = rec.constants["mass"]

    def sub(stream: str) -> slice:
        return slice(0, T, max(1, int(round(rate / SENSOR_RATES_HZ[stream]))))

    def noise(sigma: float, n: int) -> np.ndarray:
        return rng.normal(0.0, sigma, n)

    out: dict[str, dict[str, np.ndarray]] = {}
    s = sub("imu")
    n = len(t[s])
    R = body_from_ned(tr["phi"], tr["theta"], tr["psi"])
    imu = {"t": t[s]}
    r_imu = np.asarray(imu_offset, float)
    w = np.stack([tr[k] for k in "pqr"], 1)[s]
    wd = np.stack([tr[k + "_dot"] for k in "pqr"], 1)[s]
    arm = np.cross(wd, r_imu) + np.cross(w, np.cross(w, r_imu))     # zero at the CG
    for i, (a, F) in enumerate(zip("xyz", ("Fx_total", "Fy_total", "Fz_total"))):
        imu[f"a{a}"] = tr[F][s] / m + arm[:, i] + rng.normal(0.0, 0.03) + noise(0.05, n)
    for k in "pqr":
        imu[k] = tr[k][s] + rng.normal(0.0, 0.001) + noise(0.005, n)
    mag = np.einsum("nij,j->ni", R[s], np.array([0.21, 0.0, 0.43]))
    for i, a in enumerate("xyz"):
        imu[f"m{a}"] = mag[:, i] + noise(0.005, n)
    out["imu"] = imu
    s = sub("attitude")
    n = len(t[s])
    out["attitude"] = {"t": t[s], **{k: tr[src][s] + noise(0.003, n) for k, src in
                                      (("roll", "phi"), ("pitch", "theta"), ("yaw", "psi"))},
                       **{k: tr[k][s] + noise(0.002, n) for k in "pqr"}}
    s = sub("gps")
    n = len(t[s])
    dts = dt * (s.step or 1)
    Re = 6378137.0
    lat = tr["lat"][s] + _walk(rng, n, dts, 0.3, 5.0) / Re
    lon = tr["lon"][s] + _walk(rng, n, dts, 0.3, 5.0) / (Re * np.cos(tr["lat"][0]))
    alt = tr["alt"][s] + _walk(rng, n, dts, 0.3, 5.0)
    vel = [tr[k][s] + noise(0.07, n) for k in ("vn", "ve", "vd")]
    home_alt = rec.constants["home_alt"]
    out["gps"] = {"t": t[s], "lat": lat, "lon": lon, "alt": alt, "relative_alt": alt - home_alt,
                  "vn": vel[0], "ve": vel[1], "vd": vel[2]}
    pn = (lat - rec.constants["home_lat"]) * Re
    pe = (lon - rec.constants["home_lon"]) * Re * np.cos(rec.constants["home_lat"])
    out["local_position"] = {"t": t[s], "x": pn, "y": pe, "z": -(alt - home_alt), "vx": vel[0], "vy": vel[1],
                             "vz": vel[2]}
    s = sub("pressure")
    n = len(t[s])
    eas = np.maximum(tr["V"] * np.sqrt(tr["rho"] / RHO0) + noise(0.2, T), 0.0)
    out["pressure"] = {"t": t[s], "press_abs": tr["press_abs"][s] + noise(3.0, n),
                       "temperature": tr["temperature"][s] + 10.0, "diff_pressure": 0.5 * RHO0 * eas[s] ** 2}
    out["airspeed"] = {"t": t, "eas": eas}
    # the EKF's wind estimate (50 Hz internally; WIND is sent at 2 Hz)
    w_est = np.stack([_lowpass(tr[k], dt, 10.0) + _walk(rng, T, dt, 0.3, 20.0) for k in ("wn", "we")]
                     + [np.zeros(T)], 1)
    s = sub("wind")
    out["wind"] = {"t": t[s], "wn": w_est[s, 0], "we": w_est[s, 1], "wd": w_est[s, 2]}
    s = sub("aoa_ssa")
    n = len(t[s])
    if aoa == "ahrs":
        v_ekf = np.stack([tr[k] + noise(0.05, T) for k in ("vn", "ve", "vd")], 1)
        R_ahrs = body_from_ned(out["attitude"]["roll"], out["attitude"]["pitch"], out["attitude"]["yaw"]) \
            if len(out["attitude"]["t"]) == T else R
        vb = np.einsum("nij,nj->ni", R_ahrs, v_ekf - w_est)
        a_est = np.arctan2(vb[:, 2], vb[:, 0])
        b_est = np.arcsin(np.clip(vb[:, 1] / np.linalg.norm(vb, axis=1), -1, 1))
        a_est = _lowpass(a_est, dt, 0.1)[s] + noise(0.002, n)
        b_est = _lowpass(b_est, dt, 0.1)[s] + noise(0.002, n)
    else:
        a_est = tr["alpha"][s] + noise(np.radians(0.1), n)
        b_est = tr["beta"][s] + noise(np.radians(0.1), n)
    out["aoa_ssa"] = {"t": t[s], "alpha": a_est, "beta": b_est}
    return out
