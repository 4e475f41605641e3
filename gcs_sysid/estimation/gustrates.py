"""Rotational gust components (gust rates) from the reconstructed gust velocities.

The aerodynamic moments depend on the body's rotation relative to the air, ``p - p_g``,
``q - q_g``, ``r - r_g``; a gyro measures ``p q r``. A turbulent air mass whose vertical gust
``w_g`` changes along the flight path pitches the air relative to the aircraft, one whose lateral
gust ``v_g`` changes along the path yaws it (Etkin, *Dynamics of Atmospheric Flight*, Wiley 1972,
ch. 13, gust gradients: ``q_g = -dw_g/dx``, ``r_g = dv_g/dx``, ``p_g = dw_g/dy``). With Taylor's frozen-field
hypothesis the along-path derivative is the time derivative over the airspeed, ``d/dx = (d/dt) / V``.
MIL-F-8785C sec. 3.7.2 (Dryden form) gives the rates' spectra as those of filtered gust
velocities, which this module applies to the reconstructed gusts::

    q_g = s_q * (s / V) / (1 + (4 b / (pi V)) s) * w_g          (MIL-F-8785C eq. for q_g)
    r_g = s_r * (s / V) / (1 + (3 b / (pi V)) s) * v_g          (MIL-F-8785C eq. for r_g)

The standard leaves the signs open (``q_g = +-``, ``r_g = -+``); the first-order lag stands for the
gradient averaged over the span and tail length. Three frames are offered (:data:`FRAMES`):

* ``"path"`` (physical; Etkin): body axes, ``w_g`` and ``v_g`` the gust's body z and y components,
  the derivative taken of the NED gust and rotated into body axes (a steady wind seen from a
  rotating body is no gradient), ``s_q = -1``, ``s_r = +1``.
* ``"path-yaw"``: ``"path"`` on the yaw axis only, ``q_g = p_g = 0``. The yaw axis is the one where
  the physical relation (Etkin: ``r_g = +dv_g/dx``) and JSBSim's turbulence model (``FGWinds::Turbulence``,
  ``ttMilspec``, its eq. 35: ``xi_r`` the ``3b`` filter of ``+d xi_v/dt / V``) agree in sign; on the pitch
  axis JSBSim steps ``xi_q`` with ``+d xi_w/dt / V`` (its eq. 34, ``xi_w`` the gust down), the opposite
  of Etkin's ``q_g = -dw_g/dx``, and the estimate from the reconstructed vertical gust (a derivative of
  an alpha-limited ``w_g``) carries as much error as signal on the rascal's JSBSim flights (0.96-2.45
  of it even with JSBSim's sign; ``docs/benchmarks.md``, "Fourteenth session, i8-rotgust").
* ``"mean-wind"``: the low-altitude model's axes (MIL-F-8785C sec. 3.7.2 and MIL-HDBK-1797
  below 1000 ft: turbulence axes aligned with the mean wind), the form JSBSim's ``ttMilspec``
  source describes (``FGWinds::Turbulence``, eqs. 34-35 of its Yeager 1998 formulation; the rates
  measured from JSBSim 1.3.3 follow its filters and signs but not these axes, ``docs/benchmarks.md``,
  "Gust rates"; JSBSim turns its turbulence by the mirror of the wind azimuth, ``xi_u`` along ``-psiw``,
  ``docs/benchmarks.md``, "Fourteenth session, i8-rotgust"): ``w_g`` the
  vertical gust and ``v_g`` the gust across the mean wind, ``s_q = s_r = +1``, the rate vector
  ``(0, q_g, r_g)`` in the wind frame rotated to NED by the mean wind's azimuth and to body axes
  (a mean wind under :data:`MIN_MEAN_WIND` has no direction: north is taken, as JSBSim keeps its
  wind azimuth at 0 without a steady wind).

``p_g`` (the span-wise gradient ``dw_g/dy``, MIL-F-8785C's own filtered noise with
``sigma_p = 1.9 sigma_w / sqrt(L_w b)``) is not observable from one point's air data: it is left at 0
and said so. In a filter-error method (Jategaonkar, *Flight Vehicle System Identification*, 2nd ed.,
AIAA 2015, ch. 5 and 7) it would be process noise of the roll equation, estimated through the measured
roll moment itself.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["FRAMES", "MIN_MEAN_WIND", "DRYDEN_L", "DRYDEN_RATE_FACTORS", "GustRates", "gust_rates", "lag_filter",
           "gust_intensity", "dryden_rate_sigma", "states_gust_rates", "states_gust_hat", "PITCH_FRAMES"]

FRAMES = ("path", "path-yaw", "mean-wind")   #: frames of :func:`gust_rates`
#: the frames whose rates include the pitch gust rate ``q_g`` (``"path-yaw"`` sets it to 0): a ``q_hat`` relative to
#: the air made with one of them must not be moved again by :mod:`gcs_sysid.aero.airpitch`
PITCH_FRAMES = ("path", "mean-wind")
MIN_MEAN_WIND = 1.0              #: m/s; below it the mean wind has no direction and ``"mean-wind"`` takes north
#: m; the Dryden scale length of MIL-F-8785C's medium/high-altitude model (1750 ft above 2000 ft, sec. 3.7.2; the
#: transverse spectrum ``sigma^2 L/pi (1 + 3 L^2 W^2)/(1 + L^2 W^2)^2``), the one JSBSim's ``ttMilspec`` flies there
DRYDEN_L = 1750.0 * 0.3048
#: ``sigma_(p,q,r) = k sigma_w / sqrt(L_w b)``: ``p`` MIL-F-8785C's own ``1.9``; ``q`` and ``r`` the Dryden
#: ``w``/``v`` spectra's high-frequency level through the standard's gradient filters (:func:`dryden_rate_sigma`)
DRYDEN_RATE_FACTORS = (1.9, float(np.sqrt(3.0 * np.pi / 8.0)), float(np.sqrt(np.pi / 2.0)))


@dataclass(frozen=True)
class GustRates:
    """Estimated rotational gust components in body axes.

    Attributes:
        rates: ``(T, 3)`` ``p_g q_g r_g`` in rad/s (``p_g`` is 0: not observable); NaN where the
            inputs are not finite.
        frame: one of :data:`FRAMES`.
        mean_wind: ``(2,)`` the mean horizontal wind (N, E) in m/s used by ``"mean-wind"``.
        notes: one-line statements of what was done and what is missing.
    """

    rates: np.ndarray
    frame: str
    mean_wind: np.ndarray
    notes: tuple[str, ...]


def lag_filter(dt: float, x: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """First-order lag ``y = x / (1 + tau s)``, discretised exactly for a sample-and-hold input.

    Args:
        dt: sample interval, s.
        x: input of shape ``(T,)``; non-finite samples are held at the last finite value.
        tau: time constant of shape ``(T,)`` or scalar, s (> 0).

    Returns:
        ``(T,)`` output, started at ``x[0]`` (no start-up transient).

    Source: zero-order-hold discretisation of ``tau y' + y = x`` (Franklin, Powell and Workman,
    *Digital Control of Dynamic Systems*, 3rd ed., sec. 4.3).
    """
    x = np.asarray(x, float)
    a = np.exp(-dt / np.broadcast_to(np.asarray(tau, float), x.shape)).tolist()
    fin = np.isfinite(x)
    xs = np.where(fin, x, np.nan).tolist()           # Python floats: the recursion runs about 5x faster than on
    prev = float(x[np.argmax(fin)]) if fin.any() else 0.0     # numpy scalars, with the same IEEE arithmetic
    y = [0.0] * len(xs)
    for k, xk in enumerate(xs):
        if xk != xk:                                  # not finite: the output holds
            xk = prev
        if k:
            ak = a[k]
            prev = ak * prev + (1.0 - ak) * xk
        else:
            prev = xk
        y[k] = prev
    return np.array(y, float)


def _ddt(dt: float, x: np.ndarray) -> np.ndarray:
    """Central difference along axis 0 (one-sided at the ends), per s."""
    return np.gradient(x, dt, axis=0)


def gust_rates(dt: float, C: np.ndarray, wind_ned: np.ndarray, V: np.ndarray, b: float,
               frame: str = "path") -> GustRates:
    """Rotational gust components ``p_g q_g r_g`` from the reconstructed wind (mean + gusts).

    Args:
        dt: grid interval, s.
        C: body-to-NED direction cosines of shape ``(T, 3, 3)``.
        wind_ned: the air's velocity over the ground of shape ``(T, 3)``, m/s, gusts included
            (``FlightStates`` ``wn we wd`` after the specific-force aiding).
        V: true airspeed of shape ``(T,)``, m/s.
        b: wing span, m (the lag's time constants ``4b/(pi V)``, ``3b/(pi V)``).
        frame: ``"path"``, ``"path-yaw"`` (``r_g`` alone) or ``"mean-wind"`` (module docstring).

    Returns:
        :class:`GustRates`.

    Raises:
        ValueError: unknown ``frame``, shapes that disagree, or ``b <= 0``.

    Source: Etkin (1972) ch. 13; MIL-F-8785C sec. 3.7.2 (Dryden form, low-altitude axes); MIL-HDBK-1797 (its turbulence
    models).
    """
    if frame not in FRAMES:
        raise ValueError(f"gust-rate frame must be one of {', '.join(FRAMES)}, got '{frame}'")
    wind_ned, V, C = np.asarray(wind_ned, float), np.asarray(V, float), np.asarray(C, float)
    T = len(V)
    if wind_ned.shape != (T, 3) or C.shape != (T, 3, 3):
        raise ValueError(f"gust_rates: wind_ned (T, 3) and C (T, 3, 3) with T = {T} expected, got "
                         f"{wind_ned.shape} and {C.shape}")
    if not b > 0:
        raise ValueError(f"gust_rates: the wing span must be positive, got {b}")
    good = np.isfinite(wind_ned).all(1) & np.isfinite(V) & (V > 1.0) & np.isfinite(C).all((1, 2))
    Vs = np.where(good, V, np.nanmedian(V[good]) if good.any() else 1.0)
    w = np.where(good[:, None], wind_ned, np.nan)
    for i in range(3):                       # fill gaps so the derivative does not spread NaN
        ok = np.isfinite(w[:, i])
        w[:, i] = np.interp(np.arange(T), np.nonzero(ok)[0], w[ok, i]) if ok.any() else 0.0
    mean = w[good, :2].mean(0) if good.any() else np.zeros(2)
    wdot = _ddt(dt, w)                       # NED gust derivative, m/s^2 (the steady wind drops out)
    tau_q, tau_r = 4.0 * b / (np.pi * Vs), 3.0 * b / (np.pi * Vs)
    notes = ["p_g = 0: the span-wise gust gradient is not observable from one point's air data "
             "(a filter-error method would estimate it from the roll moment)"]
    rates = np.zeros((T, 3))
    if frame in ("path", "path-yaw"):
        # d/dx of the gust, body axes
        db = np.einsum("tji,tj->ti", np.where(np.isfinite(C), C, 0.0), wdot) / Vs[:, None]
        rates[:, 2] = lag_filter(dt, db[:, 1], tau_r)        # r_g = +dv_g/dx
        if frame == "path":
            rates[:, 1] = -lag_filter(dt, db[:, 2], tau_q)   # q_g = -dw_g/dx
            notes.append("q_g = -(s/V)/(1+4b s/(pi V)) w_g, r_g = +(s/V)/(1+3b s/(pi V)) v_g in body axes "
                         "(MIL-F-8785C Dryden form, Etkin's signs)")
        else:
            notes.append("q_g = 0: the pitch gust rate is not removed (its sign differs between Etkin and "
                         "JSBSim, and the vertical gust's derivative, from alpha, is as noisy as its signal on a "
                         "slow UAV)")
            notes.append("r_g = +(s/V)/(1+3b s/(pi V)) v_g in body axes (MIL-F-8785C Dryden form; Etkin's "
                         "sign, which JSBSim's shares)")
    else:
        psiw = float(np.arctan2(mean[1], mean[0])) if np.hypot(*mean) >= MIN_MEAN_WIND else 0.0
        cw, sw = np.cos(psiw), np.sin(psiw)
        v_across = (-sw * wdot[:, 0] + cw * wdot[:, 1]) / Vs          # d/dt of the gust across the mean wind / V
        q_w = lag_filter(dt, wdot[:, 2] / Vs, tau_q)
        r_w = lag_filter(dt, v_across, tau_r)
        ned = np.stack([-sw * q_w, cw * q_w, r_w], axis=1)            # (0, q_w, r_w) rotated by psiw to NED
        rates = np.einsum("tji,tj->ti", np.where(np.isfinite(C), C, 0.0), ned)
        notes.append(f"q_g, r_g in the mean wind's axes (towards {np.degrees(psiw) % 360:.0f} deg): "
                     "+(s/V)/(1+4b s/(pi V)) w_g, +(s/V)/(1+3b s/(pi V)) v_g, rotated to body axes "
                     "(MIL-F-8785C low-altitude axes, JSBSim's ttMilspec form)")
    rates[~good] = np.nan
    return GustRates(rates, frame, mean, tuple(notes))


def states_gust_rates(states, V: np.ndarray, b: float, frame: str) -> GustRates | str:
    """:func:`gust_rates` of smoothed states: their attitude ``phi theta psi`` (rad) and reconstructed wind ``wn we wd``
    (m/s, NED) on their grid ``t`` (s), with the airspeed ``V`` ``(T,)`` m/s and the span ``b`` m.

    Returns:
        the :class:`GustRates`, or a one-line reason (``"no ... in the states"``) when a field is missing or the grid
        has fewer than 3 samples.
    """
    from .ekf import dcm      # filterpy: not at import (check_replay reads FRAMES before the log is decoded)

    d = states.data
    need = [k for k in ("phi", "theta", "psi", "wn", "we", "wd") if k not in d]
    if need or len(states.t) < 3:
        return f"no {' '.join(need) or 'grid'} in the states"
    return gust_rates(float(np.median(np.diff(states.t))), dcm(d["phi"], d["theta"], d["psi"]),
                      np.stack([d["wn"], d["we"], d["wd"]], axis=1), V, b, frame)


def states_gust_hat(states, b: float, frame: str, axis: str, length: float) -> tuple[np.ndarray | None, str]:
    """One gust rate of :func:`states_gust_rates` as a hat, ``rate * length / (2 V)`` with the states' airspeed ``V``.

    Args:
        states: smoothed states with ``phi theta psi`` (rad), ``wn we wd`` (m/s, NED) and ``V`` (m/s) on a uniform
            grid ``t`` (s).
        b: wing span, m (the Dryden lags).
        frame: one of :data:`FRAMES`.
        axis: ``"p"``, ``"q"`` or ``"r"``.
        length: the hat's reference length, m (``b`` for ``p`` and ``r``, the chord ``c`` for ``q``).

    Returns:
        ``((T,) hat, the rates' notes joined)``; ``(None, why)`` when a field is missing or the grid is shorter than 3
        samples.
    """
    if "V" not in states.data:
        return None, "no gust rate: no V in the states"
    V = np.asarray(states.data["V"], float)
    G = states_gust_rates(states, V, b, frame)
    if isinstance(G, str):
        return None, f"no gust rate: {G}"
    with np.errstate(invalid="ignore", divide="ignore"):
        hat = G.rates[:, "pqr".index(axis)] * length / (2.0 * V)
    return hat, "; ".join(G.notes)


def _dryden_transverse_rho(x):
    """Dryden transverse correlation ``(1 - x/2) exp(-x)`` at separation ``x = xi / L`` (MIL-F-8785C)."""
    return (1.0 - 0.5 * x) * np.exp(-x)


def gust_intensity(dt: float, wind_ned: np.ndarray, V: np.ndarray, lag_s: float = 1.0,
                   L: float = DRYDEN_L) -> float:
    """Turbulence intensity ``sigma`` (m/s) from the reconstructed horizontal gusts' structure function.

    The rotational gust rates depend on the gust spectrum's high-frequency level, ``sigma^2 / L``, which the
    mean square increment over a short flight distance ``xi = V lag`` measures without the slow part a 90-s
    record samples poorly: for the Dryden transverse correlation ``rho(xi) = (1 - xi/(2L)) exp(-xi/L)``,
    ``E[(v(t + lag) - v(t))^2] = 2 sigma^2 (1 - rho(xi))``, and ``-> 3 sigma^2 xi / L`` for ``xi << L``, so
    the rates below (which need only ``sigma^2 / L``) hardly depend on the ``L`` assumed. The north and east
    gusts are averaged (transverse and longitudinal mixed: the approximation of an isotropic field,
    MIL-F-8785C above 2000 ft, ``sigma_u = sigma_v = sigma_w``).

    Args:
        dt: grid interval, s.
        wind_ned: ``(T, 3)`` the air's velocity over the ground, m/s, gusts included (``FlightStates``
            ``wn we wd``; only ``wn we`` are read: the vertical gust comes from alpha, the poorer angle).
        V: ``(T,)`` true airspeed, m/s.
        lag_s: the increment's lag, s (> ``dt``).
        L: the scale length assumed, m (default :data:`DRYDEN_L`).

    Returns:
        ``sigma`` in m/s; NaN with fewer than 10 finite increments.

    Raises:
        ValueError: shapes that disagree, or ``lag_s``, ``L`` or ``dt`` not positive.

    Source: MIL-F-8785C sec. 3.7.2 (Dryden form); structure function: Pope, *Turbulent Flows*, CUP 2000, sec. 6.2.
    """
    wind_ned, V = np.asarray(wind_ned, float), np.asarray(V, float)
    if wind_ned.ndim != 2 or wind_ned.shape[1] < 2 or wind_ned.shape[0] != len(V):
        raise ValueError(f"gust_intensity: wind_ned (T, 3) and V (T,) expected, got {wind_ned.shape} and {V.shape}")
    if not (dt > 0 and lag_s > 0 and L > 0):
        raise ValueError(f"gust_intensity: dt, lag_s and L must be positive, got {dt}, {lag_s}, {L}")
    k = max(int(round(lag_s / dt)), 1)
    inc = wind_ned[k:, :2] - wind_ned[:-k, :2]
    ok = np.isfinite(inc).all(1) & np.isfinite(V[k:]) & np.isfinite(V[:-k]) & (V[k:] > 1.0)
    if ok.sum() < 10:
        return float("nan")
    xi = 0.5 * (V[k:] + V[:-k])[ok] * k * dt
    D = np.mean(inc[ok] ** 2)                        # per component (mean of north and east)
    return float(np.sqrt(D / np.mean(2.0 * (1.0 - _dryden_transverse_rho(xi / L)))))


def dryden_rate_sigma(sigma: float, b: float, L: float = DRYDEN_L) -> np.ndarray:
    """Standard deviations of the rotational gust rates ``p_g q_g r_g`` (rad/s) of MIL-F-8785C's Dryden model.

    ``sigma_p = 1.9 sigma_w / sqrt(L_w b)`` is the standard's own (sec. 3.7.2). ``q_g`` and ``r_g`` are the
    standard's gradient filters ``(s/V)/(1 + 4b s/(pi V))`` on ``w_g`` and ``(s/V)/(1 + 3b s/(pi V))`` on
    ``v_g`` (module docstring). With ``b << L`` the filters pass only the spectra's high-frequency tail,
    ``Phi(Omega) -> 3 sigma^2 / (pi L Omega^2)`` (one-sided, per rad/m), so
    ``sigma_q^2 = 3 sigma^2 / (pi L) int dOmega / (1 + (4b Omega/pi)^2) = (3 pi / 8) sigma^2 / (L b)`` and
    ``sigma_r^2 = (pi / 2) sigma^2 / (L b)`` (:data:`DRYDEN_RATE_FACTORS`). All three are independent of the
    airspeed and need only ``sigma^2 / L`` (:func:`gust_intensity`). Measured against JSBSim's own
    rotational turbulence (``p - p_aero`` of the truth files, severity 3 and 4, twelve aircraft, with ``sigma``
    from the truth's wind): ratio 0.91-1.24 on ``p``, 0.67-1.07 on ``q``, 0.80-0.95 on ``r``
    (``benchmarks/rate_floor.py``; ``docs/benchmarks.md``, "Fifteenth session, i8-rotgust2").

    Args:
        sigma: turbulence intensity, m/s (NaN gives NaN).
        b: wing span, m (> 0).
        L: scale length, m (> 0; default :data:`DRYDEN_L`).

    Returns:
        ``(3,)`` ``sigma_p sigma_q sigma_r`` in rad/s.

    Raises:
        ValueError: ``b`` or ``L`` not positive.

    Source: MIL-F-8785C sec. 3.7.2 (Dryden form, the rates' filters); MIL-HDBK-1797 (the same model).
    """
    if not (b > 0 and L > 0):
        raise ValueError(f"dryden_rate_sigma: span and scale length must be positive, got b={b}, L={L}")
    return np.asarray(DRYDEN_RATE_FACTORS) * float(sigma) / np.sqrt(L * b)
