"""The live edge: a causal (filtering, not smoothing) estimate of the newest state, sample by sample.

What the learner learns comes from the smoother over a lagging window; the console and the alerts
need the state *now*. :class:`LiveEdge` takes each decoded sample (:func:`gcs_sysid.telemetry.live.
sample_of`, the telemetry layer's own conversion) and keeps:

* body rates and angular accelerations from a forward Kalman filter per axis with a
  constant-angular-acceleration model, state ``[w, w_dot]`` (rad/s, rad/s^2), driven by the gyro
  (RAW_IMU / SCALED_IMU / HIGHRES_IMU, else ATTITUDE rates); filterpy's ``KalmanFilter``:

      F = [[1, dt], [0, 1]],  Q = q_j [[dt^3/3, dt^2/2], [dt^2/2, dt]],  H = [1, 0],  R = sigma_gyro^2

  (white-noise jerk, Bar-Shalom, Li and Kirubarajan, *Estimation with Applications to Tracking and
  Navigation*, 2001, sec. 6.3.3; the same process model as the offline rate smoother);
* the latest attitude (rad), equivalent airspeed (m/s), throttle, and the autopilot's AOA_SSA
  estimate of alpha/beta (rad; a lagged estimate, not a vane).
"""

from __future__ import annotations

import numpy as np

__all__ = ["LiveEdge", "SIGMA_GYRO", "JERK_PSD"]

SIGMA_GYRO = 0.01    #: gyro noise, rad/s (1 sigma) for the filter's R
JERK_PSD = 3.0       #: white angular-jerk spectral density q_j, (rad/s^3)^2/Hz (best of 1..400 on a 0.8 Hz, 0.3 rad/s
#: oscillation with 0.01 rad/s gyro noise at 50 Hz: w_dot within 23 % RMS, the causal lag; tests/live)

_IMU = ("RAW_IMU", "SCALED_IMU", "HIGHRES_IMU")


class LiveEdge:
    """Forward filter of the body rates and the latest air data (see the module docstring).

    Attributes:
        values: name -> latest value (SI): ``p q r`` and ``p_dot q_dot r_dot`` (filtered), ``roll
            pitch yaw``, ``eas``, ``throttle``, ``alpha_ap beta_ap`` (autopilot estimate), ``t`` vehicle
            time of the last gyro sample, s.
        updates: gyro samples filtered.
    """

    def __init__(self, sigma_gyro: float = SIGMA_GYRO, jerk_psd: float = JERK_PSD):
        from filterpy.kalman import KalmanFilter

        self._kf = []
        for _ in range(3):
            kf = KalmanFilter(dim_x=2, dim_z=1)
            kf.H = np.array([[1.0, 0.0]])
            kf.R = np.array([[sigma_gyro ** 2]])
            kf.P = np.diag([1.0, 100.0])
            self._kf.append(kf)
        self._q = jerk_psd
        self._t: float | None = None
        self._gyro_src: str | None = None
        self.values: dict[str, float] = {}
        self.updates = 0

    def feed(self, name: str, sample: dict[str, float], t: float | None) -> None:
        """One decoded sample of message ``name`` (SI fields) at vehicle time ``t`` (s, or None)."""
        if name in _IMU or (name == "ATTITUDE" and self._gyro_src in (None, "ATTITUDE")):
            if self._gyro_src is None or name in _IMU:
                self._gyro_src = name
            if name == self._gyro_src and t is not None:
                self._gyro(t, np.array([sample["p"], sample["q"], sample["r"]]))
        if name == "ATTITUDE":
            self.values.update(roll=sample["roll"], pitch=sample["pitch"], yaw=sample["yaw"])
        elif name == "VFR_HUD":
            self.values.update(eas=sample["airspeed"], throttle=sample["throttle"])
        elif name == "AOA_SSA":
            self.values.update(alpha_ap=sample["alpha"], beta_ap=sample["beta"])

    def _gyro(self, t: float, w: np.ndarray) -> None:
        if self._t is not None:
            dt = t - self._t
            if not 0 < dt < 1.0:        # a repeat, a reordered sample or a gap (reboot): restart the filter
                self._t = t
                for kf, z in zip(self._kf, w):
                    kf.x = np.array([[z], [0.0]])
                    kf.P = np.diag([1.0, 100.0])
                return
            F = np.array([[1.0, dt], [0.0, 1.0]])
            Q = self._q * np.array([[dt ** 3 / 3, dt ** 2 / 2], [dt ** 2 / 2, dt]])
            for kf, z in zip(self._kf, w):
                kf.predict(F=F, Q=Q)
                kf.update(np.array([[z]]))
        else:
            for kf, z in zip(self._kf, w):
                kf.x = np.array([[z], [0.0]])
        self._t = t
        self.updates += 1
        for axis, kf in zip("pqr", self._kf):
            self.values[axis] = float(kf.x[0, 0])
            self.values[f"{axis}_dot"] = float(kf.x[1, 0])
        self.values["t"] = t
