"""The estimation stage: from a decoded :class:`Flight` to smoothed :class:`FlightStates`.

Order of work (``docs/estimation.md``): align on a grid -> attitude and gyro
bias (EKF + RTS) -> rates and angular accelerations (RTS) -> lever-arm
correction of the accelerometers -> ground velocity and accel bias (KF + RTS)
-> density, airspeed, wind, alpha, beta, qbar -> controls from servo PWM ->
validity and identifiability flags. Whatever is missing is listed in
``missing`` with why; only a log with neither IMU nor attitude raises.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..airframe import Airframe
from ..errors import DataError
from ..parallel import Helper
from ..telemetry.types import Flight
from . import airangles
from . import rates as _rates
from .airangles import aided_air_angles, describe
from .airdata import air_angles, density, estimate_wind, isa, pressure_altitude, tas_from_eas
from .align import Aligned, align_flight, events
from .alpharate import kinematic_alpha_rate
from .ekf import dcm, smooth_attitude
from .rates import CONTROL_AXES, COUPLED, GUST_HZ, HOLDS, normal_force_input, smooth_rates
from .smoothers import normal_gravity, smooth_level, smooth_velocity
from .kalman import noise_std
from .measured import surface_controls
from .states import FlightStates

__all__ = ["estimate_states", "V_FLOOR", "RATE_OK_HZ", "RATE_MIN_HZ"]

V_FLOOR = 8.0        #: airspeed (m/s) above which the aircraft counts as flying (or half its typical speed if lower)
#: Whether the wind fit also estimates a pitot scale ``k`` on a turning track (``estimate_wind(min_turn=0.5)``).
#: Off since the thirty-fourth session: with a free wind per 30-s window, the windows absorb most of a scale and
#: the gusts set the rest; on JSBSim flights in light turbulence flown in a steady turn (``"sweep_turn"``) ``k``
#: came out 0.91-1.06 with 1-sigma 0.005 (true 1; 0.82 with 15-s windows), moving V by up to 7 %, while ``k = 1``
#: gave V within 0.03 m/s on average (docs/estimation.md, "Wind"). The pitot's calibration is the diagnosis's (the
#: wind triangle and the data-compatibility check, one steady wind and coloured standard errors).
PITOT_SCALE_FROM_TURNS = False
#: Length (s) of the wind fit's windows (``estimate_wind(window_s=...)``): one horizontal wind per window, linearly
#: interpolated between the window centres. 15 s was measured in the thirty-seventh session and not adopted: closer
#: to JSBSim's wind and 5 more tops on issue 9's roster, but 2 fewer clean flights naming nothing and issue 8's rule
#: 8(b) failed (docs/benchmarks.md, "Thirty-seventh session, lead").
WIND_WINDOW_S = 30.0
#: Whether the wind fit weights its airspeed residuals with their own RMS (at least the pitot's 0.5 m/s) rather than
#: with the pitot's noise alone (``estimate_wind(residual_scale=...)``; thirty-eighth session; **on** since the
#: fortieth). In turbulence the airspeed residual holds the vertical wind and the gust within a window (0.75-2.4 m/s
#: RMS on JSBSim's light turbulence), and weighted as pitot noise it outweighs the sideslip residuals: the Navion's
#: reference fits a crosswind 9-23 m/s off in a dive. On, the wind's error against JSBSim's halves (150 flights). The
#: thirty-eighth session's rule 8(b) failed on it (least squares improved more than the GP); the rule written before
#: fresh data (issue 8's seeds 4-6 at GP seeds 0 and 1, issue 9's seed 3 and clean seeds 21-25, ALFA) passed in the
#: fortieth (docs/benchmarks.md, "Fortieth session, lead"). Where the residuals are within the pitot's noise (the
#: project's own simulation) it changes nothing.
WIND_RESIDUAL_SCALE = True
RATE_OK_HZ = 20.0    #: gyro rate from which angular accelerations are trusted
RATE_MIN_HZ = 10.0   #: below this rate they are not identifiable at all
_STREAM_ADVICE = ("raise the telemetry stream rates to 50 Hz (ArduPilot SRx_RAW_SENS for RAW_IMU, SRx_EXTRA1 for "
                  "ATTITUDE, SRx_RC_CHAN for SERVO_OUTPUT_RAW, SRx_POSITION, SRx_EXTRA2) or use the DataFlash log")


def _stack(al: Aligned, stream: str, fields: tuple[str, ...]) -> np.ndarray | None:
    if not al.has(stream) or not all(f in al.values[stream] for f in fields):
        return None
    x = np.stack([al.values[stream][f] for f in fields], axis=1)
    return x if np.isfinite(x).all(axis=1).sum() >= 10 else None


def _take_vanes(vanes, sources: dict, ident: dict, notes: list) -> tuple[np.ndarray, np.ndarray]:
    """Use the vane angles of :func:`_vane_angles` as alpha and beta; records their source and note.

    Returns:
        alpha, beta in rad, each of shape (T,).
    """
    alpha, beta, note = vanes
    for k in ("alpha", "beta"):
        sources[k] = "vanes (AOA_SSA/AOA; airframe [air_data] angles = \"vane\"), linear interpolation"
        ident[k] = (True, "measured by vanes")
    notes.append(note)
    return alpha, beta


def _vane_angles(flight: Flight, airframe: Airframe, al):
    """``(alpha, beta, note)`` on the grid from the vanes when the airframe says AOA_SSA/AOA are vane
    measurements (``[air_data] angles = "vane"``) and the log has them; else None.

    The vanes are taken as at the CG (no boom lever-arm or upwash correction) and as fast enough that
    linear interpolation of their samples is the angle (a vane's own lag is not removed).
    """
    if getattr(airframe, "air_angles", "estimate") != "vane" or not flight.has("aoa_ssa"):
        return None
    alpha, beta = al.get("aoa_ssa", "alpha"), al.get("aoa_ssa", "beta")
    if not (np.isfinite(alpha).any() and np.isfinite(beta).any()):
        return None
    n = len(flight["aoa_ssa"].t)
    span = float(flight["aoa_ssa"].t[-1] - flight["aoa_ssa"].t[0]) if n > 1 else 0.0
    rate = (n - 1) / span if span > 0 else float("nan")
    return alpha, beta, (f"alpha and beta from the vanes (AOA_SSA/AOA at {rate:.0f} Hz; airframe "
                         f"[air_data] angles = \"vane\"); V and the wind still from GPS, attitude and pitot")


def _aid_angles(dt, alpha, beta, V, rho, f_cg, abias, W, data, airframe, fly, C, v_ned, sources, sigma, notes,
                Wd=None, offsets=None, models=None, fits=None, profile_beta=None, gls_beta=None, lift_line=None,
                alpha_profile=None):
    """The kinematic alpha, beta aided by the specific force (:mod:`.airangles`) where the log allows;
    records sources, sigma, notes and the flight-common offsets' 1-sigma (``offsets``, rad; and the
    gusts in the wind) and the axes' fits (``fits``); ``models``: another flight's fits to take the alpha
    model's slopes from; ``profile_beta``, ``gls_beta``, ``lift_line``, ``alpha_profile``: as :func:`estimate_states`;
    returns ``(alpha, beta)``."""
    if f_cg is None or W is None or fly is None or not all(k in data for k in ("delta_e", "delta_a", "delta_r")):
        notes.append("alpha, beta: kinematic only (specific-force aiding needs accelerometers, gyro, pitot and "
                     "control outputs)")
        return alpha, beta
    ctrl = {k: data[k] for k in ("delta_e", "delta_a", "delta_r", "delta_t") if k in data}
    Ai = aided_air_angles(dt, alpha, beta, V, 0.5 * rho * V**2, f_cg - abias, W, ctrl, airframe.mass, airframe.S,
                          airframe.b, airframe.c, fly & np.isfinite(V), rate_dot=Wd, inertia=airframe.inertia,
                          models=models, profile_beta=profile_beta, gls_beta=gls_beta, alpha_profile=alpha_profile,
                          stated_slopes=((getattr(airframe, "CL_alpha", None), getattr(airframe, "CL_q", None))
                                         if airangles.STATED_LIFT_SLOPE else None),
                          stated_level=(dict(lift_line) if lift_line is not None else
                                        {k: getattr(airframe, k, None) for k in ("CL0", "CL_alpha", "CL_q",
                                                                                 "CL_delta_e", "CL0_sigma")}
                                        if airangles.STATED_LIFT_LEVEL and getattr(airframe, "CL0", None) is not None
                                        else None))
    notes.extend(describe(Ai))
    if fits is not None:
        fits.update({ax.name: ax for ax in Ai.axes})
    src = ("; gusts from the specific force: {c} model fitted on this flight, gust angle a Gauss-Markov state, "
           "Kalman + RTS smoother")
    for ax, k in zip(Ai.axes, ("alpha", "beta")):
        if ax.used:
            sources[k] += src.format(c="CZ(alpha, q_hat, delta_e)" if k == "alpha" else
                                     "CY(beta, p_hat, r_hat, delta_a, delta_r)")
            sigma[k] = Ai.alpha_sigma if k == "alpha" else Ai.beta_sigma     # NaN where not aided
            if offsets is not None and np.isfinite(ax.bias_sigma):
                offsets[k] = float(ax.bias_sigma)      # common to the flight: the GP's exact-condition band
        else:
            # a fallback after the moment cross-check keeps the kinematic angle and states its error: the gust
            # the rejected aiding found (airangles.kinematic_sigma); NaN (nothing stated) otherwise
            s = Ai.alpha_sigma if k == "alpha" else Ai.beta_sigma
            if np.isfinite(s).any():
                sigma[k] = s
                sources[k] += "; 1-sigma: the gust angle the rejected specific-force aiding found"
    if any(ax.used for ax in Ai.axes):      # the gusts found belong to the wind: w = v_ground - C v_air
        ca, sa, cb, sb = np.cos(Ai.alpha), np.sin(Ai.alpha), np.cos(Ai.beta), np.sin(Ai.beta)
        vb = V[:, None] * np.stack([ca * cb, sb, sa * cb], axis=1)
        w = v_ned - np.einsum("tij,tj->ti", C, vb)
        good = np.isfinite(w).all(axis=1)
        for i, k in enumerate(("wn", "we", "wd")):
            if k in data:
                data[k] = np.where(good, w[:, i], data[k])
        sources["wind"] = sources.get("wind", "") + "; plus the gusts found by the specific-force aiding"
    return Ai.alpha, Ai.beta


def estimate_states(flight: Flight, airframe: Airframe, rate_hz: float = 50.0,
                    progress: Callable[[float], None] | None = None, helper: Helper | None = None,
                    aid_air_angles: bool = True, earth: str = "wgs84", angle_models: dict | None = None,
                    turbulence_state: bool = True,
                    gust_force_axes: tuple[int, ...] | None = None,
                    meanwhile: Callable[[], None] | None = None,
                    profile_beta: bool | None = None, gls_beta: bool | None = None,
                    lift_line: dict[str, float] | None = None,
                    alpha_profile: tuple[str, ...] | None = None) -> FlightStates:
    """Smooth the states of a flight on a uniform grid.

    Args:
        flight: decoded flight with canonical streams (``docs/architecture.md``).
        airframe: mass properties, servo maps and IMU lever arm.
        rate_hz: grid rate, Hz (capped at the IMU rate).
        progress: optional ``callable(fraction)`` called as stages finish.
        helper: a :class:`~gcs_sysid.parallel.Helper` whose worker smooths the specific force while
            this process runs the velocity filter and the air data (None: all here; same results).
        aid_air_angles: aid the kinematic alpha and beta with the specific force
            (:mod:`gcs_sysid.estimation.airangles`; False: kinematic only, for comparisons).
        earth: the velocity filter's Earth: ``"wgs84"`` (WGS-84 normal gravity, Coriolis and transport
            rate at the GPS latitude and height; a flat Earth where the log has no GPS latitude) or
            ``"flat"`` (non-rotating, standard gravity: the project's own simulation's world).
        angle_models: another flight's :attr:`FlightStates.angle_fits` (the same aircraft, e.g. the reference
            of a differential diagnosis): the alpha aiding then uses that flight's CZ slopes, so that both
            flights' alpha share one scale (:func:`gcs_sysid.estimation.airangles.aided_air_angles`, ``models``).
            None: fitted on this flight.
        turbulence_state: offer the specific-force smoother's y and z axes the turbulence state
            (:data:`gcs_sysid.estimation.rates.GUST_HZ`; the replay's default). False: the plain smoother, as the
            diagnosis and ``fit`` load their flights (:func:`gcs_sysid.diagnose.run.load_measurements`: on a
            clean JSBSim c172x flight the retained high-frequency CZ was named a zero-size elevator delay).
        gust_force_axes: the specific-force axes (0 x, 1 y, 2 z) offered that state; None:
            :data:`gcs_sysid.estimation.rates.GUST_FORCE_AXES` as it stands at the call (y and z; ``(0, 1, 2)``
            adds x, opt-in, ``eval_jsbsim --gust-force-axes xyz``; docs/estimation.md).
        meanwhile: optional callable run once, in this process, after the velocity filter and the air data and
            before the specific-force smoother's result is collected: the caller's own preparation (the replay's
            later imports) overlaps the worker's smoother instead of waiting for it. Not run when the flight has
            no accelerometer (no smoother to wait for). It must not change what this function computes.
        profile_beta: the sideslip aiding's ``CY_beta`` by the gust model's likelihood (True) or by least squares
            (False); None: :data:`gcs_sysid.estimation.airangles.BETA_PROFILE` as it stands at the call (off since the
            thirty-third session; the diagnosis and ``fit`` pass :data:`gcs_sysid.diagnose.run.BETA_PROFILE`, off).
        gls_beta: the side-force model's first-pass slopes by generalised least squares under the gust model (True) or
            by least squares (False); None: :data:`gcs_sysid.estimation.airangles.BETA_GLS` as it stands at the call
            (off; the diagnosis and ``fit`` pass :data:`gcs_sysid.diagnose.run.BETA_GLS`, off).
        lift_line: a lift line to set the aided alpha's level on, ``{"CL0", "CL_alpha", "CL_q", "CL_delta_e",
            "CL0_sigma"}`` (:func:`gcs_sysid.estimation.airangles.aided_air_angles`, ``stated_level``; the live
            learner's line carried across its windows, :class:`gcs_sysid.aero.liftline.LiftLinePool`). It takes the
            place of the airframe's stated line (:data:`~gcs_sysid.estimation.airangles.STATED_LIFT_LEVEL`). None:
            the airframe's where that opt-in is on, else none.
        alpha_profile: the alpha aiding's columns whose slopes are chosen by the gust model's likelihood
            (``("delta_e",)``: the elevator's, which least squares loads with the gust's normal force in closed loop);
            None: :data:`gcs_sysid.estimation.airangles.ALPHA_PROFILE_COLUMNS` as it stands at the call (``()``).

    Returns:
        :class:`FlightStates`; keys that could not be estimated are absent from
        ``data`` and listed in ``missing``.

    Raises:
        DataError: neither an IMU nor an attitude stream, or fewer than 10 grid points.
        ValueError: ``earth`` not ``"wgs84"`` or ``"flat"``.
    """
    if earth not in ("wgs84", "flat"):
        raise ValueError(f"earth must be 'wgs84' or 'flat', got '{earth}'")
    prog = progress or (lambda f: None)
    src = flight.path
    if not (flight.has("imu") or flight.has("attitude")):
        raise DataError(f"{src}: no IMU (RAW_IMU, SCALED_IMU*, HIGHRES_IMU or DataFlash IMU) and no attitude "
                        "(ATTITUDE or ATT) stream: no states can be estimated")
    al = align_flight(flight, rate_hz)
    t, rate = al.t, al.rate_hz
    dt = 1.0 / rate
    T = len(t)
    if T < 10:
        raise DataError(f"{src}: only {T} grid points at {rate:.1f} Hz; the log is too short to estimate states")
    data: dict[str, np.ndarray] = {}
    sigma: dict[str, np.ndarray] = {}
    offsets: dict[str, float] = {}
    fits: dict = {}
    sources: dict[str, str] = {}
    missing: list[str] = []
    notes: list[str] = []
    ident: dict[str, tuple[bool, str]] = {}
    prog(0.1)

    # --- gyro and attitude ------------------------------------------------------------------
    gyro = _stack(al, "imu", ("p", "q", "r"))
    gyro_src, gyro_rate = "imu", al.rates.get("imu", 0.0)
    if gyro is None:
        gyro = _stack(al, "attitude", ("p", "q", "r"))
        gyro_src, gyro_rate = "attitude", al.rates.get("attitude", 0.0)
        if gyro is not None:
            notes.append("no IMU gyro: body rates from ATTITUDE rollspeed/pitchspeed/yawspeed (already "
                         "bias-corrected by the autopilot)")
    att_stream = "attitude" if flight.has("attitude") else ("ekf" if flight.has("ekf") else None)
    att = None
    if att_stream is not None and all(f in flight[att_stream] for f in ("roll", "pitch", "yaw")):
        att = events(flight[att_stream], ("roll", "pitch", "yaw"), t, angles=("roll", "pitch", "yaw"))
        if not np.isfinite(att).all(axis=1).any():
            att = None
    bias = np.zeros((T, 3))
    euler = None
    if gyro is not None:
        sg = float(np.median([noise_std(gyro[:, i], 2e-4) for i in range(3)]))
    if att is not None and gyro is not None:
        A = smooth_attitude(dt, gyro, att, sg)
        euler, esig = A.euler, A.euler_sigma
        if gyro_src == "imu":
            bias = A.gyro_bias
            notes.append("gyro bias (EKF, mean) p q r = " + ", ".join(f"{b:+.4f}" for b in bias.mean(0)) + " rad/s")
        src_att = f"EKF (filterpy) + RTS: {gyro_src} gyro integrated, updated by {att_stream.upper()} attitude"
    elif att is not None:
        euler = np.stack([al.get(att_stream, f) for f in ("roll", "pitch", "yaw")], axis=1)
        esig = np.full((T, 3), np.nan)
        src_att = f"{att_stream.upper()} attitude interpolated (no gyro to smooth it)"
    if euler is not None:
        for i, k in enumerate(("phi", "theta", "psi")):
            data[k], sigma[k], sources[k] = euler[:, i], esig[:, i], src_att
    else:
        missing.append("phi theta psi: no attitude stream (ATTITUDE / ATT / EKF); the IMU alone cannot level")
    prog(0.35)

    # --- controls -------------------------------------------------------------------------------
    servo_rate = al.rates.get("servo", 0.0)
    if al.has("servo") or airframe.can_actuators:   # measured surface positions (DroneCAN) beat PWM
        pwm = {ch: al.values["servo"][f"pwm{ch}"] for ch in airframe.channels
               if al.has("servo") and f"pwm{ch}" in al.values["servo"]}
        ctrl, csrc, cnotes = surface_controls(al, airframe, pwm)
        for k in ("delta_e", "delta_a", "delta_r", "delta_t"):
            if k in ctrl:
                data[k], sources[k] = ctrl[k], csrc[k]
        notes.extend(cnotes)
    mix = airframe.mixing
    for i, k in enumerate(("delta_e", "delta_a", "delta_r")):
        if k in data:
            continue
        if not np.any(mix[i] != 0.0):  # the aircraft has no such surface (a flying wing has no rudder)
            data[k], sources[k] = np.zeros(T), f"0: the {airframe.name} airframe has no servo driving {k}"
            notes.append(f"{k} = 0: the airframe has no servo mixed into it")
        else:
            missing.append(f"{k}: no servo output (SERVO_OUTPUT_RAW / RCOU) for its channel(s)")
    if "delta_t" not in data:
        thr = al.get("vfr_hud", "throttle")
        if airframe.throttle is None:
            data["delta_t"], sources["delta_t"] = np.zeros(T), "0: the airframe has no throttle (glider)"
        elif np.isfinite(thr).any():
            data["delta_t"], sources["delta_t"] = thr, "VFR_HUD throttle (no throttle servo output)"
        else:
            missing.append("delta_t: no throttle servo output and no VFR_HUD throttle")
    if servo_rate and servo_rate < 0.95 * RATE_MIN_HZ:
        ident["controls"] = (False, f"servo outputs at {servo_rate:.1f} Hz: control steps are smeared; "
                                    f"{_STREAM_ADVICE}")
        notes.append(ident["controls"][1])
    else:
        ident["controls"] = (al.has("servo"), f"servo outputs at {servo_rate:.0f} Hz" if servo_rate else "no servo")

    # --- rates and angular accelerations ------------------------------------------------------
    W = Wd = None
    in_lag = None
    # control commands as known inputs: angular accelerations and forces jump where they step; their
    # effectiveness scales with the dynamic pressure, here from the pitot's EAS (0.5 rho0 EAS^2)
    cnames = [k for k in ("delta_e", "delta_a", "delta_r", "delta_t")
              if k in data and ident["controls"][0] and sources[k].startswith("servo")]
    U = np.stack([data[k] for k in cnames], axis=1) if cnames else None
    eas_q = al.get("airspeed", "eas")
    if not np.isfinite(eas_q).any():
        eas_q = al.get("vfr_hud", "airspeed")
    qbar_eas = 0.5 * 1.225 * eas_q**2 if np.isfinite(eas_q).sum() >= 10 else None
    if gyro is not None:
        acc0 = _stack(al, "imu", ("ax", "ay", "az"))   # the gust-driven pitching moment shows in az at once
        Rr = smooth_rates(dt, gyro - bias, controls=U, scale=qbar_eas,
                          aux=None if acc0 is None else normal_force_input(dt, acc0[:, 2]), aux_axes=(1,),
                          control_axes=[CONTROL_AXES[k] for k in cnames] if cnames else None,
                          coupled={cnames.index(k): v for k, v in COUPLED.items() if k in cnames})
        in_lag = Rr.input_lag if cnames else None
        W, Wd = Rr.rate, Rr.accel
        for i, k in enumerate(("p", "q", "r")):
            data[k], sigma[k] = W[:, i], Rr.rate_sigma[:, i]
            data[k + "_dot"], sigma[k + "_dot"] = Wd[:, i], Rr.accel_sigma[:, i]
            inputs = f", jumps at steps of {' '.join(cnames)}" if cnames else ""
            sources[k] = f"{gyro_src} gyro minus EKF bias, RTS-smoothed (rate/acceleration/jerk model{inputs})"
            sources[k + "_dot"] = (f"RTS-smoothed derivative of the {gyro_src} gyro, bandwidth "
                                   f"{Rr.bandwidth_hz[i]:g} Hz (maximum likelihood){inputs}")
        notes.append("rate smoother bandwidth p q r = " + ", ".join(f"{b:g}" for b in Rr.bandwidth_hz)
                     + " Hz; gyro noise = " + ", ".join(f"{s:.4f}" for s in Rr.noise_std) + " rad/s; signal "
                     "above it recovered from the residual's spectrum (Wiener) p q r: " + ", ".join(
                         "none" if not np.isfinite(b[0]) else f"{b[0]:.1f}-{b[1]:.1f} Hz"
                         for b in Rr.correction_band_hz))
        if cnames:
            unit = "rad/s^2 per Pa rad" if qbar_eas is not None else "rad/s^2 per rad"
            notes.append("control steps taken as known inputs (" + ", ".join(cnames) + "); step effectiveness "
                         f"({unit}) p q r: " + "; ".join(
                             ", ".join(f"{e:+.3g}" for e in row) for row in Rr.effectiveness)
                         + "; delay of their effect (maximum likelihood) = "
                         + ", ".join(f"{lg * dt:.2f}" for lg in Rr.input_lag) + " s; between samples the controls "
                         + ("step (ideal servos)" if Rr.hold == "zoh" else "move linearly (servo motion)")
                         + " (likelihood); slow transients (1/s, likelihood-ratio and coloured Wald tests) on "
                         + (" ".join(a for a, on in zip("pqr", Rr.slow_transient) if on) or "no axis"))
    else:
        missing.append("p q r p_dot q_dot r_dot: no gyro (IMU) and no rates in ATTITUDE")
    if gyro_rate < 0.95 * RATE_MIN_HZ:  # 5 % margin: a nominal 10 Hz stream logs 9.9-10.1 Hz
        reason = (f"gyro at {gyro_rate:.1f} Hz: p_dot q_dot r_dot (and so Cl Cm Cn) are not identifiable at this "
                  f"rate; {_STREAM_ADVICE}")
        ident["rate_derivatives"] = (False, reason)
        notes.append(reason)
    elif gyro_rate < RATE_OK_HZ:
        reason = (f"gyro at {gyro_rate:.1f} Hz: angular accelerations are band-limited to about "
                  f"{0.35 * min(gyro_rate, rate):.1f} Hz, moment coefficients marginal; {_STREAM_ADVICE}")
        ident["rate_derivatives"] = (True, reason)
        notes.append(reason)
    else:
        ident["rate_derivatives"] = (True, f"gyro at {gyro_rate:.0f} Hz")
    prog(0.55)

    # --- specific force at the CG, velocity, accel bias ------------------------------------------
    acc = _stack(al, "imu", ("ax", "ay", "az"))
    f_cg = None
    if acc is not None:
        r_arm = np.asarray(airframe.imu_lever_arm, float)
        f_cg = acc.copy()
        if W is not None and np.any(r_arm != 0):
            # a_cg = a_imu - omega_dot x r - omega x (omega x r)
            f_cg = acc - np.cross(Wd, r_arm) - np.cross(W, np.cross(W, r_arm))
            notes.append("accelerometers moved to the CG (lever arm " + ", ".join(f"{x:g}" for x in r_arm) + " m)")
    else:
        missing.append("ax ay az: no accelerometer (IMU) stream")
    if f_cg is not None:   # needs nothing from the velocity filter and the air data below: in the helper's
        # worker (when there is one) while this process runs them; collected at the end
        sf_job = (helper or Helper(enabled=False)).submit("gcs_sysid.estimation.rates:smooth_specific_force", dt,
                                                          f_cg, controls=U, scale=qbar_eas, input_lag=in_lag,
                                                          holds=(Rr.hold,) if in_lag is not None else HOLDS,
                                                          gust_hz=GUST_HZ if turbulence_state else (),
                                                          gust_axes=tuple(_rates.GUST_FORCE_AXES if gust_force_axes
                                                                          is None else gust_force_axes))
    vsrc = "gps" if _stack(al, "gps", ("vn", "ve", "vd")) is not None else (
        "local_position" if _stack(al, "local_position", ("vx", "vy", "vz")) is not None else None)
    vfields = ("vn", "ve", "vd") if vsrc == "gps" else ("vx", "vy", "vz")
    v_ned = None
    C = dcm(*euler.T) if euler is not None else None
    abias = np.zeros((T, 3))
    if vsrc is not None:
        if vsrc == "local_position":
            notes.append("no GPS velocity: using LOCAL_POSITION_NED (the autopilot's EKF velocity)")
        vmeas = events(flight[vsrc], vfields, t)
        if f_cg is not None and C is not None:
            sa = float(np.median([noise_std(f_cg[:, i], 1e-3) for i in range(3)]))
            lat = al.get("gps", "lat") if earth == "wgs84" else np.full(T, np.nan)
            round_earth = bool(np.isfinite(lat).any())
            Vel = smooth_velocity(dt, C, f_cg, vmeas, sa, lat=lat if round_earth else None,
                                  alt=al.get("gps", "alt"))
            v_ned, vsig, abias = Vel.v_ned, Vel.v_sigma, Vel.accel_bias
            vs = f"KF + RTS: accelerometers (attitude-rotated) integrated, updated by {vsrc} velocity"
            if round_earth:
                la = float(np.degrees(np.nanmedian(lat)))
                h_gps = al.get("gps", "alt")
                h_med = float(np.nanmedian(h_gps)) if np.isfinite(h_gps).any() else 0.0
                g = float(normal_gravity(np.radians(la), h_med))
                vs += f"; WGS-84 gravity ({g:.4f} m/s^2), Coriolis and transport rate at latitude {la:.2f} deg"
            else:
                vs += "; flat non-rotating Earth, standard gravity"
                notes.append("velocity filter: flat non-rotating Earth with standard gravity (" + (
                    "no GPS latitude" if earth == "wgs84" else "earth=\"flat\"") + "): the Coriolis "
                    "acceleration (about 1e-4 s^-1 x the ground speed) goes into the accelerometer bias and "
                    "from there into the force coefficients")
            notes.append("accelerometer bias (KF, mean) x y z = " + ", ".join(f"{b:+.3f}" for b in abias.mean(0))
                         + " m/s^2")
        else:
            v_ned = np.stack([al.get(vsrc, f) for f in vfields], axis=1)
            vsig = np.full((T, 3), 0.2)
            vs = f"{vsrc} velocity interpolated (no accelerometer/attitude to smooth it)"
        for i, k in enumerate(("vn", "ve", "vd")):
            data[k], sigma[k], sources[k] = v_ned[:, i], vsig[:, i], vs
        if C is not None:
            vb = np.einsum("tji,tj->ti", C, v_ned)
            for i, k in enumerate(("u", "v", "w")):
                data[k], sources[k] = vb[:, i], "C' (v_ned) with the smoothed attitude"
        else:
            missing.append("u v w: no attitude to rotate the ground velocity into body axes")
    else:
        missing.append("vn ve vd u v w: no GPS (GLOBAL_POSITION_INT / GPS) or LOCAL_POSITION_NED velocity")
    prog(0.75)

    # --- air data -------------------------------------------------------------------------------
    alt = al.get("gps", "alt")
    alt_src = "GPS altitude AMSL"
    if not np.isfinite(alt).any():
        alt, alt_src = al.get("vfr_hud", "alt"), "VFR_HUD altitude"
    press = al.get("pressure", "press_abs")
    if not np.isfinite(alt).any() and np.isfinite(press).any():
        alt, alt_src = pressure_altitude(press), "pressure altitude (ISA)"
    if np.isfinite(alt).any():
        data["alt"], sources["alt"] = alt, alt_src
    else:
        missing.append("alt: no GPS, VFR_HUD or pressure altitude")
    # The logged baro temperature is the sensor's own (board) temperature, typically 5-15 K above the
    # outside air: static pressure is used with the ISA temperature at the pressure altitude instead.
    rho = density(press)
    rho_isa = isa(np.nan_to_num(alt, nan=0.0))[2]
    have_p = np.isfinite(rho)
    rho = np.where(have_p, rho, rho_isa)
    sources["rho"] = ("p/(R T) from SCALED_PRESSURE/BARO press_abs with the ISA temperature at the pressure "
                      "altitude" if have_p.any() else "ISA at the " + alt_src)
    temp = al.get("pressure", "temperature")
    if have_p.any() and np.isfinite(temp).any():
        dT = float(np.nanmedian(temp) - np.nanmedian(isa(pressure_altitude(press[have_p]))[1]))
        notes.append(f"baro temperature is {dT:+.1f} K from the ISA at the pressure altitude; not used for "
                     "density (it is the sensor's board temperature)")
    if not have_p.all() and have_p.any():
        sources["rho"] += "; ISA where no pressure sample"
    data["rho"] = rho
    eas = al.get("airspeed", "eas")
    eas_src, eas_stream = "airspeed (SCALED_PRESSURE press_diff / ARSP) EAS", ("airspeed", "eas")
    if not np.isfinite(eas).any():
        eas, eas_src = al.get("vfr_hud", "airspeed"), "VFR_HUD airspeed (ArduPilot: EAS)"
        eas_stream = ("vfr_hud", "airspeed")
    gs = np.linalg.norm(v_ned[:, :2], axis=1) if v_ned is not None else np.full(T, np.nan)
    if np.isfinite(eas).any() and np.nanmax(eas) < 1.0 and np.nanmax(gs) > 5.0:
        eas = np.full(T, np.nan)
        notes.append("airspeed reads 0 throughout while the aircraft moves: pitot ignored")
    tas = tas_from_eas(eas, rho)
    have_tas = np.isfinite(tas).sum() >= 10
    wind_ap = _stack(al, "wind", ("wn", "we", "wd"))
    wind = None
    k_pitot = None
    if v_ned is not None:
        fly = have_tas & np.isfinite(tas) & (np.nan_to_num(tas) > min(V_FLOOR, 0.5 * np.nanpercentile(tas, 90)))\
            if have_tas else None
        if fly is not None and fly.sum() >= 10:
            try:
                We = estimate_wind(t, v_ned, tas, fly, prior=wind_ap, C=C, window_s=WIND_WINDOW_S,
                                   min_turn=0.5 if PITOT_SCALE_FROM_TURNS else 0.0,
                                   residual_scale=WIND_RESIDUAL_SCALE)
                wind, wsig = We.wind, We.sigma
                sources["wind"] = (f"least squares over {WIND_WINDOW_S:g} s windows: |v_gps - w| = k V_tas" +
                                   ("" if PITOT_SCALE_FROM_TURNS else " (k = 1)") + ", beta ~ 0 on average" +
                                   (" (autopilot WIND/XKF2 only as a weak prior)" if wind_ap is not None else ""))
                if not PITOT_SCALE_FROM_TURNS:
                    kn = ("pitot scale taken as 1 (the pitot is trusted; its calibration is the diagnosis's wind "
                          "triangle)")
                elif np.isfinite(We.scale_sigma):
                    kn = f"pitot scale k = {We.scale:.3f} +- {We.scale_sigma:.3f}"
                else:
                    kn = "pitot scale kept at 1 (too few turns to separate it from the wind)"
                notes.append(f"{kn}; mean wind N E = {wind[:, 0].mean():+.2f}, {wind[:, 1].mean():+.2f} m/s" +
                             (f"; airspeed residuals weighted with their own RMS, {We.sigma_airspeed:.2f} m/s "
                              "(turbulence)"
                              if We.fits > 1 else ""))
                k_pitot = We.scale
            except ValueError:
                wind = None
        if wind is None and wind_ap is not None:
            wind = np.stack([np.interp(t, t[np.isfinite(wind_ap[:, i])], wind_ap[np.isfinite(wind_ap[:, i]), i])
                             for i in range(3)], axis=1)
            wsig = np.full((T, 3), 1.0)
            sources["wind"] = "autopilot's wind estimate (WIND / XKF2), no usable airspeed to estimate our own"
            notes.append("wind taken from the autopilot's estimate (no usable airspeed): V, alpha, beta inherit "
                         "its errors")
        if wind is None:
            wind, wsig = np.zeros((T, 3)), np.full((T, 3), 5.0)
            sources["wind"] = "assumed calm: no airspeed and no autopilot wind estimate"
            notes.append("no airspeed and no wind estimate: calm air assumed, V alpha beta are ground-relative")
        for i, k in enumerate(("wn", "we", "wd")):
            data[k], sigma[k] = wind[:, i], wsig[:, i]
    V = alpha = beta = None
    if v_ned is not None and C is not None:
        vb, V, alpha, beta = air_angles(C, v_ned, wind)
        sources["V"] = "|C'(v_gps - wind)| (smoothed GPS velocity minus wind; the pitot calibrates the wind)"
        if k_pitot is not None:
            # gusts along the flight path: what the pitot sees beyond the windowed wind, smoothed (zero phase)
            # on the pitot's own samples (interpolated samples would have correlated noise)
            ev = events(flight[eas_stream[0]], (eas_stream[1],), t)[:, 0]
            j = np.nonzero(np.isfinite(ev) & fly)[0]
            d = np.zeros(T)
            if len(j) >= 10:
                dj = smooth_level(float(np.median(np.diff(t[j]))), k_pitot * tas_from_eas(ev[j], rho[j]) - V[j])
                d = np.interp(t, t[j], np.nan_to_num(dj))
            vb[:, 0] += d
            V = np.linalg.norm(vb, axis=1)
            alpha = np.arctan2(vb[:, 2], vb[:, 0])
            beta = np.arcsin(np.clip(vb[:, 1] / np.maximum(V, 1e-9), -1.0, 1.0))
            sources["V"] += " + the smoothed pitot excess (longitudinal gusts)"
        sources["alpha"] = "atan2(w_a, u_a) of the air-relative body velocity"
        sources["beta"] = "asin(v_a / V) of the air-relative body velocity"
        ident["alpha"] = (True, "reconstructed from GPS velocity, attitude and wind")
        ident["beta"] = (True, "reconstructed from GPS velocity, attitude and wind")
        vanes = _vane_angles(flight, airframe, al)
        if vanes is not None:
            alpha, beta = _take_vanes(vanes, sources, ident, notes)
        elif aid_air_angles:
            alpha, beta = _aid_angles(dt, alpha, beta, V, rho, f_cg, abias, W, data, airframe,
                                      fly, C, v_ned, sources, sigma, notes, Wd, offsets, angle_models, fits,
                                      profile_beta, gls_beta, lift_line, alpha_profile)
    else:
        if have_tas:
            V = tas
            sources["V"] = eas_src + " -> TAS with " + sources["rho"].split(" (")[0]
        vanes = _vane_angles(flight, airframe, al)
        if vanes is not None:
            alpha, beta = _take_vanes(vanes, sources, ident, notes)
        elif flight.has("aoa_ssa"):
            alpha, beta = al.get("aoa_ssa", "alpha"), al.get("aoa_ssa", "beta")
            for k in ("alpha", "beta"):
                sources[k] = "AOA_SSA/AOA: the autopilot's own lagged estimate (fallback, not a vane)"
            ident["alpha"] = (True, "autopilot's AOA estimate (lagged), fallback")
            ident["beta"] = (False, "autopilot's sideslip estimate only: poor, not a measurement")
            notes.append("alpha and beta from AOA_SSA/AOA, the autopilot's lagged estimate: fallback only")
        else:
            missing.append("alpha beta: no GPS velocity with attitude and no AOA_SSA")
            ident["alpha"] = ident["beta"] = (False, "no GPS velocity with attitude and no AOA_SSA")
    if V is not None:
        data["V"] = V
        data["qbar"] = 0.5 * rho * V**2
        sources["qbar"] = "0.5 rho V^2"
    else:
        missing.append("V qbar: no airspeed and no GPS velocity with attitude")
    if alpha is not None:
        data["alpha"], data["beta"] = alpha, beta
    if f_cg is not None:
        # the velocity filter needs the raw samples (white noise); the coefficients get the smoothed ones
        if meanwhile is not None:
            meanwhile()
        f_s, f_sig, f_noise = sf_job.result()
        f_corr = f_s - abias
        for i, k in enumerate(("ax", "ay", "az")):
            data[k] = f_corr[:, i]
            sigma[k] = f_sig[:, i]
            sources[k] = "IMU specific force at the CG (lever arm removed), RTS-smoothed" + (
                " with jumps at control steps" if cnames else "") + (
                ", minus the KF accelerometer bias" if v_ned is not None and C is not None else "")
        notes.append("accelerometer noise (maximum likelihood) x y z = " + ", ".join(f"{x:.3f}" for x in f_noise)
                     + " m/s^2")
        if alpha is not None and V is not None and W is not None and C is not None and v_ned is not None:
            # from the force equations, not by differentiating alpha (module .alpharate): the alpha_dot that
            # simulators' CL_alpha_dot and Cm_alpha_dot terms read; not a regressor of the GP (docs/estimation.md)
            data["alpha_dot"] = kinematic_alpha_rate(C, v_ned, f_corr, W, V, alpha, beta)
            sources["alpha_dot"] = ("force equations: (u_a w_dot - w_a u_dot) / (u_a^2 + w_a^2) with the smoothed "
                                    "specific force, rates, attitude and GPS velocity (not differentiated)")
    prog(0.9)

    # --- validity --------------------------------------------------------------------------------
    # rows need the regressors and the force inputs; the rate derivatives are not required, so that
    # a log too slow for them (4 Hz telemetry) still yields the force coefficients
    need = ("p", "q", "r", "ax", "ay", "az", "V", "alpha", "beta", "qbar",
            "delta_e", "delta_a", "delta_r", "delta_t")
    valid = np.ones(T, bool)
    for k in need:
        valid &= np.isfinite(data[k]) if k in data else False
    if V is not None and np.isfinite(V).any():
        floor = min(V_FLOOR, 0.5 * float(np.nanpercentile(V, 90)))
        valid &= np.nan_to_num(V) > floor
        notes.append(f"airborne where V > {floor:.1f} m/s: {valid.mean() * 100:.0f} % of the grid valid")
    ident["force_coefficients"] = (f_cg is not None and V is not None,
                                   "accelerometers and airspeed present" if f_cg is not None and V is not None
                                   else "no accelerometer or no airspeed")
    # moment coefficients need the angular accelerations AND control outputs fast enough to resolve the
    # control derivatives that dominate Cl Cm Cn (3 Hz servo telemetry smears every step)
    if gyro is None:
        ident["moment_coefficients"] = (False, "no gyro")
    elif not ident["rate_derivatives"][0]:
        ident["moment_coefficients"] = ident["rate_derivatives"]
    elif not ident["controls"][0] and servo_rate:
        ident["moment_coefficients"] = (False, ident["controls"][1])
    else:
        ident["moment_coefficients"] = (V is not None, ident["rate_derivatives"][1] if V is not None else "no airspeed")
    for c in ("CX", "CY", "CZ"):          # per coefficient, as the pipeline reads them
        ident[c] = ident["force_coefficients"]
    for c in ("Cl", "Cm", "Cn"):
        ident[c] = ident["moment_coefficients"]
    prog(1.0)
    return FlightStates(t, rate, data, sigma, valid, sources, missing, notes, ident, offsets, fits,
                        rate_bandwidth_hz=None if gyro is None else np.asarray(Rr.bandwidth_hz, float))
