"""Checks of a JSBSim flight's exact truth shared by the harness tests: least-squares derivatives,
the rigid body, the decoded log, the hidden effects in JSBSim's own properties, the evaluation's flights."""

import numpy as np

from benchmarks.jsbsim_harness.truth import truth_coefficients, truth_regressors


def derivative_slopes(rec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Slopes of the exact Cm, Cl, Cn on their leading regressors (intercept fitted, not returned).

    Args:
        rec: a harness ``Recording``.

    Returns:
        ``(cm, cl, cn)``: Cm on (alpha, q_hat, delta_e); Cl and Cn each on (beta, p_hat, r_hat,
        delta_a, delta_r); 1/rad.
    """
    X, Y = truth_regressors(rec), truth_coefficients(rec)

    def slopes(y, cols):
        A = np.c_[np.ones(len(y)), X[:, cols]]
        return np.linalg.lstsq(A, y, rcond=None)[0][1:]

    return (slopes(Y[:, 4], [0, 3, 5]), slopes(Y[:, 3], [1, 2, 4, 6, 7]), slopes(Y[:, 5], [1, 2, 4, 6, 7]))


def servo_against_truth(flight, files) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The logged servo PWM mapped back to deflections, next to the truth's, per surface.

    Args:
        flight: the decoded log (``read_log``); files: the harness ``FlightFiles`` (airframe, truth).

    Returns:
        ``{"delta_e" | "delta_a" | "delta_r": (from_pwm, truth)}``, each (T,) rad on the servo times.
    """
    from gcs_sysid.airframe import load_airframe
    from benchmarks.jsbsim_harness import load_truth

    af = load_airframe(files.airframe)
    servo = flight.streams["servo"]
    ctl = af.controls_from_pwm({c: servo.fields[f"pwm{c}"] for c in af.channels})
    truth = load_truth(files.truth)
    return {k: (ctl[k], np.interp(servo.t, truth.t, truth.X[:, i]))
            for k, i in (("delta_e", 5), ("delta_a", 6), ("delta_r", 7))}


def rigid_body_residual(truth: dict, inertia: np.ndarray) -> np.ndarray:
    """How far JSBSim's aerodynamic moments are from the rigid body with the airframe file's inertia.

    Args:
        truth: a recording's truth arrays (``p q r`` rad/s, ``p_dot q_dot r_dot`` rad/s^2,
            ``L_aero M_aero N_aero`` N m; each (T,)).
        inertia: (3, 3) inertia tensor of the airframe file, kg m^2 (project convention).

    Returns:
        (3,) RMS of ``J w_dot + w x J w - M`` over the RMS of ``M``, per body axis (Euler's
        equations about the CG, e.g. Stevens, Lewis and Johnson, *Aircraft Control and
        Simulation*, 3rd ed., 2016, eq. 1.7-2).
    """
    w = np.stack([truth["p"], truth["q"], truth["r"]], 1)
    wd = np.stack([truth["p_dot"], truth["q_dot"], truth["r_dot"]], 1)
    M = np.stack([truth["L_aero"], truth["M_aero"], truth["N_aero"]], 1)
    rhs = wd @ inertia.T + np.cross(w, w @ inertia.T)
    return np.sqrt(np.mean((rhs - M) ** 2, 0)) / np.sqrt(np.mean(M ** 2, 0))


def effect_state(spec, effects, cmds=(0.3, -0.4, 0.2), n=40, alpha_deg=None):
    """JSBSim (``FGFDMExec``) at the harness's initial condition with 4 deg of sideslip (and
    ``alpha_deg`` of alpha when given) and the fixed normalised commands ``cmds`` (elevator,
    aileron, rudder), after ``n`` frames at 200 Hz, with ``effects`` edited into a copy of the
    model's XML (none: the stock model). ``n = 0``: the initial condition itself, where
    ``run_ic`` has evaluated the models but nothing has been integrated, so that two models'
    forces and moments there are at the same state (JSBSim integrates first in each later frame,
    with the accelerations of the frame before)."""
    import tempfile
    from pathlib import Path

    from benchmarks.jsbsim_harness import FlightConfig
    from benchmarks.jsbsim_harness.effects import _write_model
    from benchmarks.jsbsim_harness.flight import _set_ic, load_model

    with tempfile.TemporaryDirectory() as tmp:
        fdm = load_model(spec, 1 / 200, 0, _write_model(spec, effects, Path(tmp)) if effects else None)
        _set_ic(fdm, spec, FlightConfig(spec.name, turbulence="none"))
        fdm["ic/beta-deg"] = 4.0
        if alpha_deg is not None:
            fdm["ic/alpha-deg"] = alpha_deg
        fdm["fcs/elevator-cmd-norm"], fdm["fcs/aileron-cmd-norm"], fdm["fcs/rudder-cmd-norm"] = cmds
        fdm.run_ic()
        for _ in range(n):
            fdm.run()
        return fdm


#: The injected moment effects: effect name -> (JSBSim function, moment property, reference length).
MOMENT_EFFECTS = {"Cm:alpha^2": ("injected_Cm_alpha2", "moments/m-aero-lbsft", "metrics/cbarw-ft"),
                  "Cl:alpha*beta": ("injected_Cl_alpha_beta", "moments/l-aero-lbsft", "metrics/bw-ft"),
                  "Cn:delta_a": ("injected_Cn_delta_a", "moments/n-aero-lbsft", "metrics/bw-ft")}


def injected_moment(spec, name, k, n=40, alpha_deg=None) -> tuple[float, float, float]:
    """One moment effect of ``effects.py`` as JSBSim computes it (:func:`effect_state`).

    Returns:
        ``(function, specified, change)``, lbf ft: the injected function's value
        (``aero/coefficient/injected_*``); ``k`` times its regressor (alpha^2, alpha beta, or the
        harness's delta_a) times ``qbar S`` and c or b, from JSBSim's own state; and the change of
        JSBSim's total aerodynamic moment on that axis against the stock model after the same
        frames (equal to the function only while both states are the same: ``n = 0``).
    """
    from benchmarks.jsbsim_harness.effects import Effect
    from benchmarks.jsbsim_harness.flight import _deflections

    func, moment, ref = MOMENT_EFFECTS[name]
    fdm, stock = effect_state(spec, [Effect(name, k)], n=n, alpha_deg=alpha_deg), \
        effect_state(spec, [], n=n, alpha_deg=alpha_deg)
    a, b, da = fdm["aero/alpha-rad"], fdm["aero/beta-rad"], _deflections(fdm, spec)[1]
    x = {"Cm:alpha^2": a * a, "Cl:alpha*beta": a * b, "Cn:delta_a": da}[name]
    want = k * x * fdm["aero/qbar-psf"] * fdm["metrics/Sw-sqft"] * fdm[ref]
    return fdm[f"aero/coefficient/{func}"], want, fdm[moment] - stock[moment]


def delay_trace(spec, delay_s: float, cmd: float = 0.5, n: int = 40) -> tuple[np.ndarray, np.ndarray]:
    """The elevator and the delayed elevator the aerodynamics read with ``delay:delta_e`` = ``delay_s``,
    frame by frame (200 Hz) after a step of the normalised elevator command to ``cmd``.

    Returns:
        ``(position, delayed)``, each (n,) rad (``fcs/elevator-pos-rad``,
        ``fcs/elevator-pos-delayed-rad``).
    """
    import tempfile
    from pathlib import Path

    from benchmarks.jsbsim_harness import FlightConfig
    from benchmarks.jsbsim_harness.effects import Effect, _write_model
    from benchmarks.jsbsim_harness.flight import _set_ic, load_model

    with tempfile.TemporaryDirectory() as tmp:
        fdm = load_model(spec, 1 / 200, 0, _write_model(spec, [Effect("delay:delta_e", delay_s)], Path(tmp)))
        _set_ic(fdm, spec, FlightConfig(spec.name, turbulence="none"))
        fdm.run()
        fdm["fcs/elevator-cmd-norm"] = cmd
        pos, delayed = [], []
        for _ in range(n):
            fdm.run()
            pos.append(fdm["fcs/elevator-pos-rad"])
            delayed.append(fdm["fcs/elevator-pos-delayed-rad"])
    return np.array(pos), np.array(delayed)


#: The streams every harness .tlog carries (``docs/jsbsim.md``, "The log").
LOG_STREAMS = ("imu", "attitude", "servo", "aoa_ssa", "gps", "airspeed", "wind")


def decoded_servo_errors(files) -> tuple[list[str], dict[str, tuple[float, float]]]:
    """Decode a harness flight's .tlog with the pipeline's reader and map its servos back.

    Args:
        files: the harness ``FlightFiles`` (tlog, airframe, truth).

    Returns:
        ``(empty, errors)``: the :data:`LOG_STREAMS` the log lacks or holds no sample of, and per
        surface (``delta_e delta_a delta_r``) the largest absolute difference between the
        deflection from SERVO_OUTPUT_RAW through the airframe file and JSBSim's, and the standard
        deviation of JSBSim's, both rad (:func:`servo_against_truth`).
    """
    from gcs_sysid.telemetry import read_log

    flight = read_log(files.tlog)
    empty = [n for n in LOG_STREAMS if n not in flight.streams or flight.streams[n].t.size == 0]
    return empty, {k: (float(np.max(np.abs(a - b))), float(np.std(b)))
                   for k, (a, b) in servo_against_truth(flight, files).items()}


def non_aero_residual(truth: dict) -> float:
    """Largest absolute difference between JSBSim's total non-gravity forces and moments and the
    aerodynamic ones (N, N m) over a recording's truth: zero in a glide with the engine stopped."""
    return max(float(np.max(np.abs(truth[f"{k}_total"] - truth[f"{k}_aero"])))
               for k in ("Fx", "Fy", "Fz", "L", "M", "N"))


#: Flights of the final evaluation that a harness aircraft must fly inside its envelope:
#: (seed, turbulence, plan, [(effect, size), ...]).
EVALUATION_FLIGHTS = [
    (100, "light", "sweep", []),                                 # the diagnosis's reference flight
    (11, "light", "sweep", []),                                  # a clean diagnosis flight
    (1, "light", "sweep", [("Cl:alpha*beta", 3.0)]),             # the effect most likely to depart
    (1, "light", "sweep", [("delay:delta_e", 0.12)]),
    (2, "moderate", "standard", []),                             # eval_jsbsim, moderate turbulence
]
