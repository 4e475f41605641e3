"""TEST HELPER: a synthetic flight with known truth, turned into noisy telemetry streams.

Body rates are sums of sinusoids (analytic derivatives), the Euler angles are
integrated from them on a 1 kHz grid; airspeed, alpha and beta are analytic; a
constant wind gives the ground velocity; the specific force follows from the
rigid-body kinematics ``f = v_dot_b + omega x v_b - C' g``. Sensors sample the
truth at their own rates with seeded noise and biases. Production code never
imports this module.
"""

from __future__ import annotations

import math

from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from gcs_sysid.estimation.ekf import G0, dcm
from gcs_sysid.telemetry.types import Flight, Stream

RHO0 = 1.225

# (amplitude rad/s, frequency Hz, phase) per axis; plus a constant yaw rate so the heading turns
_RATES = {
    "p": [(0.5, 0.4, 0.0), (0.3, 1.3, 1.0), (0.15, 2.7, 2.0)],
    "q": [(0.3, 0.6, 0.5), (0.2, 1.7, 0.2), (0.1, 3.1, 1.2)],
    "r": [(0.2, 0.3, 0.1), (0.1, 1.1, 2.5)],
}
_R_MEAN = 0.12


@dataclass
class Truth:
    t: np.ndarray
    data: dict[str, np.ndarray] = field(default_factory=dict)

    def at(self, key: str, t: np.ndarray) -> np.ndarray:
        if key == "psi":
            return np.angle(np.interp(t, self.t, np.cos(self.data[key]))
                            + 1j * np.interp(t, self.t, np.sin(self.data[key])))
        return np.interp(t, self.t, self.data[key])


def _rate(axis, t):
    w = np.full_like(t, _R_MEAN if axis == "r" else 0.0)
    wd = np.zeros_like(t)
    for a, f, ph in _RATES[axis]:
        om = 2 * np.pi * f
        w += a * np.sin(om * t + ph)
        wd += a * om * np.cos(om * t + ph)
    return w, wd


def truth(duration: float = 120.0, wind=(4.0, -3.0, 0.0), alt0: float = 300.0, lever=(0.0, 0.0, 0.0)) -> Truth:
    """Truth trajectory on a 1 kHz grid."""
    dt = 1e-3
    t = np.arange(0.0, duration + dt / 2, dt)
    tr = Truth(t)
    for ax in "pqr":
        tr.data[ax], tr.data[ax + "_dot"] = _rate(ax, t)
    p, q, r = tr.data["p"], tr.data["q"], tr.data["r"]
    eul = np.zeros((len(t), 3))
    eul[0] = [0.0, 0.05, 0.3]

    def erates(e, w):
        ph, th = e[0], e[1]
        return np.array([w[0] + np.tan(th) * (np.sin(ph) * w[1] + np.cos(ph) * w[2]),
                         np.cos(ph) * w[1] - np.sin(ph) * w[2],
                         (np.sin(ph) * w[1] + np.cos(ph) * w[2]) / np.cos(th)])

    W = np.stack([p, q, r], 1)

    def rhs(tt, e):
        w = [(_R_MEAN if ax == "r" else 0.0) + sum(a * math.sin(2 * math.pi * f * tt + ph) for a, f, ph in _RATES[ax])
             for ax in "pqr"]
        sf, cf, th = math.sin(e[0]), math.cos(e[0]), e[1]
        a = sf * w[1] + cf * w[2]
        return [w[0] + math.tan(th) * a, cf * w[1] - sf * w[2], a / math.cos(th)]

    sol = solve_ivp(rhs, (t[0], t[-1]), eul[0], method="DOP853", t_eval=t, rtol=1e-10, atol=1e-12)
    eul = sol.y.T
    tr.data["phi"], tr.data["theta"] = eul[:, 0], eul[:, 1]
    tr.data["psi"] = np.mod(eul[:, 2] + np.pi, 2 * np.pi) - np.pi
    V = 20.0 + 2.0 * np.sin(2 * np.pi * 0.05 * t) + 0.5 * np.sin(2 * np.pi * 0.7 * t)
    alpha = 0.06 + 0.03 * np.sin(2 * np.pi * 0.6 * t + 0.3) + 0.01 * np.sin(2 * np.pi * 1.9 * t)
    beta = 0.02 * np.sin(2 * np.pi * 0.4 * t + 1.0) + 0.01 * np.sin(2 * np.pi * 1.3 * t)
    vb = np.stack([V * np.cos(alpha) * np.cos(beta), V * np.sin(beta), V * np.sin(alpha) * np.cos(beta)], 1)
    C = dcm(eul[:, 0], eul[:, 1], eul[:, 2])
    w_ned = np.asarray(wind, float)
    v_ned = np.einsum("tij,tj->ti", C, vb) + w_ned
    vb_dot = np.gradient(vb, dt, axis=0)
    f = vb_dot + np.cross(W, vb) - np.einsum("tji,j->ti", C, np.array([0.0, 0.0, G0]))
    Wd = np.stack([tr.data["p_dot"], tr.data["q_dot"], tr.data["r_dot"]], 1)
    rl = np.asarray(lever, float)
    f_imu = f + np.cross(Wd, rl) + np.cross(W, np.cross(W, rl))
    alt = alt0 - np.cumsum(v_ned[:, 2]) * dt
    for i, k in enumerate(("u", "v", "w")):
        tr.data[k] = vb[:, i] + (np.einsum("tji,j->ti", C, w_ned)[:, i])  # ground-relative body velocity
    for i, k in enumerate(("vn", "ve", "vd")):
        tr.data[k] = v_ned[:, i]
    for i, k in enumerate(("ax", "ay", "az")):
        tr.data[k] = f[:, i]
        tr.data[k + "_imu"] = f_imu[:, i]
    tr.data.update(V=V, alpha=alpha, beta=beta, alt=alt)
    tr.data["wn"], tr.data["we"], tr.data["wd"] = (np.full_like(t, w) for w in w_ned)
    return tr


def _times(t0, t1, rate, rng, jitter=0.1):
    n = int((t1 - t0) * rate)
    tt = t0 + (np.arange(n) + 0.5) / rate
    tt = tt + rng.uniform(-jitter, jitter, n) / rate
    return np.sort(tt)


def flight_from_truth(tr: Truth, seed: int = 0, imu_hz=50.0, att_hz=50.0, gps_hz=10.0, arsp_hz=20.0,
                      servo_hz=25.0, gyro_noise=0.003, gyro_bias=(0.01, -0.02, 0.015), acc_noise=0.05,
                      acc_bias=(0.05, -0.04, 0.08), att_noise=0.002, vel_noise=0.08, eas_noise=0.3,
                      temp_k=288.15 - 0.0065 * 300.0, omit=(), ap_wind_error=(1.0, 1.0, 0.0)) -> Flight:
    """Noisy telemetry streams sampled from a truth trajectory (canonical streams, SI)."""
    rng = np.random.default_rng(seed)
    t0, t1 = tr.t[0], tr.t[-1]
    streams = {}

    def S(name, source, rate, fields):
        tt = _times(t0, t1, rate, rng)
        streams[name] = Stream(name, source, tt, {k: fn(tt) for k, fn in fields.items()})

    gb, ab = np.asarray(gyro_bias), np.asarray(acc_bias)
    S("imu", "RAW_IMU", imu_hz, {
        **{f"{a}": (lambda tt, a=a, i=i: tr.at(a, tt) + gb[i] + rng.normal(0, gyro_noise, len(tt)))
           for i, a in enumerate("pqr")},
        **{f"a{c}": (lambda tt, c=c, i=i: tr.at(f"a{c}_imu", tt) + ab[i] + rng.normal(0, acc_noise, len(tt)))
           for i, c in enumerate("xyz")}})
    S("attitude", "ATTITUDE", att_hz, {
        "roll": lambda tt: tr.at("phi", tt) + rng.normal(0, att_noise, len(tt)),
        "pitch": lambda tt: tr.at("theta", tt) + rng.normal(0, att_noise, len(tt)),
        "yaw": lambda tt: np.mod(tr.at("psi", tt) + rng.normal(0, att_noise, len(tt)) + np.pi, 2 * np.pi) - np.pi})
    S("gps", "GLOBAL_POSITION_INT", gps_hz, {
        "vn": lambda tt: tr.at("vn", tt) + rng.normal(0, vel_noise, len(tt)),
        "ve": lambda tt: tr.at("ve", tt) + rng.normal(0, vel_noise, len(tt)),
        "vd": lambda tt: tr.at("vd", tt) + rng.normal(0, vel_noise, len(tt)),
        "alt": lambda tt: tr.at("alt", tt)})
    p0 = 101325.0 * (1 - 2.25577e-5 * 300.0) ** 5.25588

    def rho_at(tt):
        return p0 / (287.05287 * temp_k) * np.ones_like(tt)

    S("airspeed", "SCALED_PRESSURE", arsp_hz, {
        "eas": lambda tt: tr.at("V", tt) * np.sqrt(rho_at(tt) / RHO0) + rng.normal(0, eas_noise, len(tt))})
    S("pressure", "SCALED_PRESSURE", arsp_hz, {"press_abs": lambda tt: p0 + 0 * tt,
                                                "temperature": lambda tt: temp_k + 0 * tt})
    # servo steps: a square wave on each surface channel, throttle constant
    S("servo", "SERVO_OUTPUT_RAW", servo_hz, {
        "pwm1": lambda tt: 1500 + 100 * np.sign(np.sin(2 * np.pi * 0.25 * tt)),
        "pwm2": lambda tt: 1500 + 80 * np.sign(np.sin(2 * np.pi * 0.2 * tt + 1)),
        "pwm3": lambda tt: 1600 + 0 * tt,
        "pwm4": lambda tt: 1500 + 60 * np.sign(np.sin(2 * np.pi * 0.15 * tt + 2))})
    we = np.asarray(ap_wind_error)
    S("wind", "WIND", 2.0, {k: (lambda tt, k=k, i=i: tr.at(k, tt) + we[i]) for i, k in enumerate(("wn", "we", "wd"))})
    S("aoa_ssa", "AOA_SSA", 10.0, {"alpha": lambda tt: tr.at("alpha", tt - 0.3),
                                   "beta": lambda tt: 0 * tt})
    S("vfr_hud", "VFR_HUD", 4.0, {"airspeed": lambda tt: tr.at("V", tt) * np.sqrt(rho_at(tt) / RHO0),
                                  "alt": lambda tt: tr.at("alt", tt), "throttle": lambda tt: 0.6 + 0 * tt})
    for name in omit:
        streams.pop(name, None)
    return Flight("synthetic", "synthetic", streams)
