"""Least-squares derivatives of a JSBSim flight's exact truth, shared by the harness tests."""

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
