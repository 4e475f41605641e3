"""Checks of a flown JSBSim flight's exact truth and log shared by the harness tests: least-squares derivatives
(:func:`derivative_slopes`, :func:`closure_slopes`), the rigid body (:func:`rigid_body_residual`,
:func:`assert_rigid_body_glide`), the decoded log (:func:`assert_servos_map_back`, :func:`assert_airspeed_bias_in_log`)
and the evaluation's flights and envelope (:data:`EVALUATION_FLIGHTS`, :func:`evaluation_envelope`,
:func:`assert_in_envelope`).

The checks of JSBSim's own properties at the harness's initial condition, nothing flown (FCS, static stability and
control, the hidden effects), are in ``static_checks.py``; those of an aircraft's harness entry (its names, checked-in
model, derivation and summary labels) in ``model_checks.py`` (twenty-ninth session: split from this module, every
helper moved unchanged).
"""

import numpy as np

from benchmarks.jsbsim_harness.truth import truth_coefficients, truth_regressors

__all__ = ["LB", "assert_rigid_body_glide", "assert_servos_map_back", "derivative_slopes", "closure_slopes",
           "servo_against_truth", "rigid_body_residual", "LOG_STREAMS", "decoded_servo_errors", "non_aero_residual",
           "EVALUATION_FLIGHTS", "ENVELOPE_FLIGHTS", "assert_airspeed_bias_in_log", "evaluation_envelope",
           "assert_in_envelope", "flown_flight"]

LB = 0.45359237          # kg per lb


def flown_flight(cfg, folder):
    """Fly ``cfg`` (a harness ``FlightConfig``) into ``folder`` and return ``(decoded log, airframe, truth npz)``."""
    from benchmarks.jsbsim_harness.logfile import make_flight
    from gcs_sysid.airframe import load_airframe
    from gcs_sysid.telemetry import read_log

    files = make_flight(cfg, folder)
    return read_log(files.tlog), load_airframe(files.airframe), np.load(files.truth)


def assert_rigid_body_glide(files, mass_lb: float) -> None:
    """A harness flight's truth is a rigid body with the checked-in airframe file, gliding.

    JSBSim's aerodynamic moments equal ``J w_dot + w x J w`` with the airframe file's J to 2e-3 of
    their RMS (:func:`rigid_body_residual`), every non-gravity force and moment is aerodynamic
    (:func:`non_aero_residual` under 1e-9: engines stopped), and the airframe file's mass is
    JSBSim's, ``mass_lb`` lb.

    Raises:
        AssertionError: one of these fails.
    """
    import pytest

    from gcs_sysid.airframe import load_airframe

    tr, af, const = files.recording.truth, load_airframe(files.airframe), files.recording.constants
    rel = rigid_body_residual(tr, af.inertia)
    assert (rel < 2e-3).all(), rel
    assert non_aero_residual(tr) < 1e-9
    assert af.mass == pytest.approx(const["mass"], rel=1e-5) and const["mass"] == pytest.approx(mass_lb * LB, rel=1e-6)


def assert_servos_map_back(files) -> None:
    """The pipeline decodes every stream of a harness flight's .tlog, and its SERVO_OUTPUT_RAW maps
    back through the airframe file to JSBSim's deflections within 0.1 deg, each surface moving
    (standard deviation over 0.5 deg; :func:`decoded_servo_errors`).

    Raises:
        AssertionError: a stream is missing or a surface does not map back.
    """
    empty, errors = decoded_servo_errors(files)
    assert empty == [], empty
    for k, (err, std) in errors.items():
        assert err < np.radians(0.1) and std > np.radians(0.5), k      # maps back; every surface moves


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


def closure_slopes(rec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Slopes of the exact Cm, Cl, Cn on the regressors JSBSim's terms read (intercept fitted, not returned):
    the body rates relative to the turbulent air (``p_aero q_aero r_aero``, what ``Clp Cmq Cnr`` read) made
    dimensionless, and JSBSim's ``aero/alphadot-rad_sec`` rebuilt from the truth as JSBSim's
    ``FGAuxiliary`` computes it: ``(u_a w_dot - w_a u_dot) / (u_a^2 + w_a^2)`` with the air-relative
    ``u_a w_a`` and the time derivatives of the body velocity over the ground (so without the gusts' own
    rate). :func:`derivative_slopes` uses the inertial rates and no alpha-dot; in light turbulence at
    3000 ft the sgs126's alpha-dot term (Cmadot -12, larger than its Cmq -9) and the gusts' rotation turn
    the sign of its Cm_alpha and halve its Cl_beta on a 30-s flight, while this fit closes on JSBSim's
    numbers (Cl and Cn to 1e-6).

    Args:
        rec: a harness ``Recording``.

    Returns:
        ``(cm, cl, cn)``: Cm on (alpha, q_aero_hat, delta_e, alpha_dot_hat); Cl and Cn each on (beta,
        p_aero_hat, r_aero_hat, delta_a, delta_r); 1/rad.
    """
    tr, c, b = rec.truth, rec.constants["c"], rec.constants["b"]
    V, al, be = tr["V"], tr["alpha"], tr["beta"]
    ua, wa = V * np.cos(al) * np.cos(be), V * np.sin(al) * np.cos(be)
    adot = (ua * np.gradient(tr["w"], rec.t) - wa * np.gradient(tr["u"], rec.t)) / (ua**2 + wa**2)
    Y = truth_coefficients(rec)

    def slopes(y, *cols):
        return np.linalg.lstsq(np.column_stack((np.ones(len(y)),) + cols), y, rcond=None)[0][1:]

    lat = (be, tr["p_aero"] * b / (2 * V), tr["r_aero"] * b / (2 * V), tr["delta_a"], tr["delta_r"])
    return (slopes(Y[:, 4], al, tr["q_aero"] * c / (2 * V), tr["delta_e"], adot * c / (2 * V)),
            slopes(Y[:, 3], *lat), slopes(Y[:, 5], *lat))


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


#: The evaluation flights an untouched aircraft's envelope test flies: :data:`EVALUATION_FLIGHTS`
#: and the evaluation's pair of effects.
ENVELOPE_FLIGHTS = EVALUATION_FLIGHTS + [(1, "light", "sweep", [("Cm:alpha^2", -8.0), ("Cn:delta_a", -0.06)])]


def assert_airspeed_bias_in_log(files, out_dir, bias: float = 2.0) -> None:
    """``bias:airspeed`` = ``bias`` m/s of TAS written into a second log of a harness flight.

    Args:
        files: the harness ``FlightFiles`` of a flight flown here (``recording`` set).
        out_dir: folder for the biased .tlog.

    Raises:
        AssertionError: the decoded airspeed (EAS, from SCALED_PRESSURE) of the biased log minus
            the clean log's (same seed, same sensor noise) differs from ``bias sqrt(rho / rho0)``
            by more than 0.01 m/s at a sample.
    """
    from pathlib import Path

    from benchmarks.jsbsim_harness import write_log
    from benchmarks.jsbsim_harness.effects import RHO0, _bias_airspeed
    from benchmarks.jsbsim_harness.sensors import make_sensors
    from gcs_sysid.telemetry import read_log

    rec, biased = files.recording, Path(out_dir) / "biased.tlog"
    write_log(rec, biased, sensors=_bias_airspeed(make_sensors(rec, "ahrs"), rec, bias))
    a, b = (read_log(p).streams["airspeed"] for p in (files.tlog, biased))
    want = bias * np.sqrt(np.interp(a.t, rec.t, rec.truth["rho"]) / RHO0)
    np.testing.assert_allclose(b.fields["eas"] - a.fields["eas"], want, atol=0.01)


def evaluation_envelope(name: str, seed: int, turbulence: str, plan: str, effects, out_dir) -> dict:
    """Fly one of the :data:`EVALUATION_FLIGHTS` (120 s) of aircraft ``name`` into ``out_dir``.

    Returns:
        ``flight_envelope`` of its truth file plus ``wild`` (True when ``Cl:alpha*beta`` is
        injected: the effect that reverses the dihedral effect), ``alt_min`` (lowest altitude
        above sea level, m) and ``sink_air_mps`` (mean sink through the air, m/s: the mean of the
        truth's ``vd - wd``, the ground's down velocity less the air's).
    """
    from benchmarks.jsbsim_harness import FlightConfig, make_flight
    from benchmarks.jsbsim_harness.effects import Effect, make_effect_flight
    from benchmarks.jsbsim_harness.envelope import flight_envelope

    cfg = FlightConfig(name, duration_s=120.0, turbulence=turbulence, seed=seed, plan=plan)
    files = (make_effect_flight(cfg, [Effect(n, v) for n, v in effects], out_dir) if effects
             else make_flight(cfg, out_dir))
    with np.load(files.truth) as z:
        alt_min = float(z["alt"].min())
        sink_air = float(np.mean(z["vd"] - z["wd"]))
    return flight_envelope(files.truth) | {"wild": any(n == "Cl:alpha*beta" for n, _ in effects), "alt_min": alt_min,
                                           "sink_air_mps": sink_air}


def assert_in_envelope(e: dict, alpha, beta, bank, speed, rate_std: float, rate_std_held: float,
                       alt_min: float = 0.0, sink_min: float = 3.0,
                       surface_std_min: tuple[float, float, float] = (1.0, 1.0, 1.0)) -> None:
    """An :func:`evaluation_envelope` inside the aircraft's limits, with every axis excited.

    Args:
        alpha: (lowest, highest) alpha, deg. beta, bank: (clean, ``wild``) largest abs(beta) and
            bank, deg. speed: (lowest, highest) TAS, m/s. rate_std, rate_std_held: least standard
            deviation of each body rate on the whole flight and the held-out last 20 %, deg/s.
        alt_min: lowest altitude above sea level, m.
        sink_min: the glide sinks through the air (``sink_air_mps``) more than this, m/s (3 unless
            the aircraft glides flatter: the rascal sinks 1.6-2.2 m/s at 20 m/s). Through the air, not
            over the ground (``sink_mps``), since the fifteenth session: the mean vertical gust of
            MIL-F-8785C light turbulence over a 120-s flight is about 1-1.6 m/s (the rascal's seed-1
            flights sank 0.31-0.36 m/s over the ground, 1.9-2.1 through the air; the sgs126's rose by
            0.06-0.12 m/s and sank 1.0-1.3 through the air); in the old light turbulence the two agreed.
        surface_std_min: least standard deviation of (delta_e, delta_a, delta_r), deg: 1 deg each for every
            aircraft but the us25e, whose rudder is set from its yaw-moment power (twenty-second session: its
            Cn_delta_r -0.18 per rad is 2.5 times its Cn_beta, so 1 deg of rudder standard deviation costs
            sideslips beyond 10 deg and knock-it-offs; docs/jsbsim.md, "The us25e").

    Raises:
        AssertionError: a knock-it-off was flown, or a limit is exceeded; every surface moves by
            more than ``surface_std_min`` (standard deviation; 1 deg) and the glide sinks more than ``sink_min``.
    """
    w = int(e["wild"])
    assert e["aborts"] == [], e["aborts"]
    assert alpha[0] < e["alpha"][0] and e["alpha"][1] < alpha[1], e["alpha"]
    assert max(map(abs, e["beta"])) < beta[w] and e["bank_max"] < bank[w], e
    assert speed[0] < e["V"][0] and e["V"][1] < speed[1], e["V"]
    assert min(e["rate_std"]) > rate_std and min(e["rate_std_held"]) > rate_std_held, e      # deg/s
    assert all(s > m for s, m in zip(e["surface_std"], surface_std_min)), e
    assert e["sink_air_mps"] > sink_min and e["alt_min"] > alt_min, e
