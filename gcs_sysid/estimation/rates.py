"""Body rates and angular accelerations that jump where the controls step.

With ideal or fast actuators a control step changes the control moment within
one grid step, so the angular acceleration *jumps* while the rate only kinks.
A smoother whose model has a continuous acceleration (white snap) smears that
jump over its memory (about 0.2 s at 6 Hz): the measured Cl Cm Cn are wrong
exactly where the control derivatives are identified, and those come out
attenuated in regression. Here the control commands, which are known inputs,
enter the model.

Model, per axis, on the uniform grid (``k`` = grid step, ``dt``)::

    w_dot(t) = a~(t) + sum_c sum_j b_cj g_cj(t),    [w, a~, a~_dot] nominal (white snap)
    z_k = w(t_k) + v_k                              (gyro minus bias)

For every control ``c`` (delayed by ``l_c`` grid steps) the input shapes
``g_cj`` are a step ``qbar (delta_c - delta_c(0))`` (``j = 0``) and decaying
transients started by each change ``qbar Delta delta_c`` (``exp(-lambda_j t)``,
``lambda_j`` in :data:`DECAYS`), see :func:`control_columns`: the acceleration
jumps by ``sum_j b_cj qbar Delta delta`` at the step and its slope (the jerk)
jumps too. The coefficients ``b`` (per axis, control and shape) are unknown and
estimated with the states: ``x = x~ + X b`` where ``X`` is the deterministic
response to the controls (acceleration ``A b`` and its exact integral ``W b``),
and ``x~`` follows the nominal
time-invariant model. Because everything is linear this is a *regression
effect* in a state-space model (Harvey 1989, sec. 3.4; Durbin and Koopman
2012, sec. 6.2; de Jong 1991): the innovations of ``z - W b`` are those of ``z``
minus the innovations of the columns of ``W``, so ``b`` is the generalised
least-squares solution of the innovations on the column innovations (diffuse
prior), then ``z - W b`` is smoothed with the nominal steady-state gains and
``W b`` (rate) and ``A b`` (acceleration) are added back. The result is the
mean of the Kalman filter + RTS smoother of the augmented model (``b`` as
constant states with a diffuse prior; the tests check it against a dense
generalised least-squares reference), but every pass is a compiled LTI filter
(``scipy.signal.lfilter``): about 1 s for three axes, four controls and a
10-minute 50 Hz flight.

The jump sits exactly at the grid step of the (delayed) control change; the smoother
stays zero phase. Where the controls do not move the model is the nominal one.
Smooth inputs (multisines) sampled and held at the grid rate are staircases
too; their many small steps carry the same ``b``.

How a logged control moves between its samples is chosen by the same
likelihood (:data:`HOLDS`): ``"zoh"`` holds it (ideal actuators fed the logged
commands: the acceleration jumps at the sample, as in the project's simulation),
``"foh"`` moves it linearly to the next sample (logged surface positions of real
servos, or servos slower than the log rate: JSBSim's flights). Taken as steps, a
smooth surface motion made the smoother overshoot JSBSim's angular accelerations
(regression slope 1.08, Cl Cm 11-14 % off); with the linear hold the slope is
1.00 and Cl Cm Cn 4-9 %. Steps are chosen only with decisive evidence
(:data:`ZOH_EVIDENCE` per sample; they gain 0.43 per sample on the simulation).
With the linear hold, measured signals ``aux`` may enter the acceleration too
(one coefficient per axis that takes them, linear between samples, no delay): the
replay passes the measured normal specific force (:func:`normal_force_input`) to
the pitch axis only, where it shows
the gust-driven angle of attack, and so ``Cm_alpha alpha``, at the instant it
acts (Morelli and Klein 2016, ch. 5: measured accelerations as regressors).

Each control enters the axes its moment equation gives it (:data:`CONTROL_AXES`: the elevator pitch,
the aileron and rudder roll and yaw, the throttle all three; Morelli and Klein 2016, ch. 3): a free
column on another axis only carries the gyro's noise there, in a shape that follows the controls. A
slower transient per control (:data:`SLOW_DECAYS`) is added on an axis only where both the
likelihood-ratio statistic and a Wald statistic with coloured innovations (a Bartlett long-run covariance
of the scores, Newey and West 1987) beat the BIC penalty (a large aircraft's yaw damping): with white
innovations the two agree, and where the innovations stay correlated over the transient's second (model
error, gusts) the second asks for more.

The bandwidth of the nominal model is chosen per axis by the diffuse profile
likelihood (de Jong 1991) over a ladder of candidates, with ``b`` re-estimated
for each candidate; then the delay ``l_c`` of each control (a servo or output
delay, 0 ... ``max_delay_s``) by the same likelihood summed over the axes
(coordinate ascent; a change must beat the BIC penalty of one parameter).

One bandwidth per axis cannot follow what neither the inputs nor the nominal
model explain (gust-driven moments at 2-5 Hz): it stays in the residual, gyro
minus smoothed rate. :func:`smooth_rates` then adds the Wiener estimate of that
residual's signal where its spectrum stands significantly above the gyro's
white-noise floor (:mod:`.wiener`), zero phase, per axis and gap-free piece; a
white residual is left alone.
:func:`smooth_specific_force` does the same with the accelerometer's residual on x and y
(gust-driven forces above its bandwidth). On z (the lift's answer to vertical gusts, with the Dryden ``1/f^2``
tail up to the Nyquist frequency in moderate turbulence) the turbulence is a state of the model instead: a
first-order Gauss-Markov gust added to the measured force, its level chosen by the likelihood and kept only
past a BIC penalty (:data:`GUST_HZ`, :func:`_nominal_model`; the filter-error method's process noise,
Jategaonkar 2015 ch. 5).

References:
    Harvey, *Forecasting, Structural Time Series Models and the Kalman Filter*,
    CUP 1989, sec. 3.4 (explanatory variables and interventions), ch. 3
    (concentrated likelihood).
    Durbin and Koopman, *Time Series Analysis by State Space Methods*, 2nd ed.,
    OUP 2012, sec. 6.2 (regression effects, augmented filter and smoother).
    de Jong, "The diffuse Kalman filter", Annals of Statistics 19(2), 1991,
    doi:10.1214/aos/1176348139 (diffuse likelihood).
    Bar-Shalom, Li and Kirubarajan (2001) ch. 6 (white-noise kinematic models);
    Klein and Morelli, *Aircraft System Identification*, AIAA 2006, ch. 10.
    Franklin, Powell and Workman, *Digital Control of Dynamic Systems*, 3rd ed.,
    1998, sec. 6.3 (zero- and first-order hold equivalents).
    Morelli and Klein, *Aircraft System Identification*, 2nd ed., 2016, ch. 5
    (equation error with measured accelerations), ch. 11 (data smoothing).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from filterpy.common import Q_continuous_white_noise
from scipy.signal import lfilter, ss2tf

from .inputs import aux_columns, control_columns, lagged, normal_force_input, prepare_inputs, shift
from .kalman import SteadyState, lti_response, steady_state, steady_state_smoother
from .nodes import segments
from .wiener import residual_wiener

__all__ = ["AILERON_YAW_TIE", "BANDWIDTHS_HZ", "CONTROL_AXES", "COUPLED", "DECAYS", "SLOW_DECAYS", "HOLDS",
           "ZOH_EVIDENCE", "RESIDUAL_FORCE_AXES", "RateEstimate", "normal_force_input", "smooth_rates",
           "smooth_specific_force", "control_columns"]

#: Candidate bandwidths (Hz) of the rate smoother; those above 0.35 x grid rate are dropped.
BANDWIDTHS_HZ = (0.5, 1.0, 1.5, 2.5, 4.0, 6.0, 9.0, 13.0)
#: Decay rates (1/s) of the control transients: a basis for the response shape after a step (the roll,
#: pitch and yaw damping of small aircraft lie within it); measured on the simulation in docs/estimation.md.
DECAYS = (2.0, 5.0, 12.0, 30.0)
#: Slower transients (1/s) taken per axis only where the data carry them (the likelihood-ratio statistic and
#: a Wald statistic with coloured innovations, :func:`_coloured_wald`, both above the BIC penalty ``k log n``
#: for the axis' ``k`` extra columns;
#: the plain likelihood-ratio test took them on the project's own simulation's yaw axis, where the
#: innovations stay correlated for seconds, and cost its Cn 2.66 -> 3.21 %): the
#: B747's yaw response (its own yaw damper in the loop) decays at about 1/s, slower than :data:`DECAYS` spans;
#: where the extra columns would only carry the gyro's noise (a fixed 1/s transient on every axis cost the
#: light aircraft up to a point of q_dot / r_dot error), the test leaves them out (docs/estimation.md,
#: "Slow transients and the control terms").
SLOW_DECAYS = (1.0,)
#: The axes (0 p, 1 q, 2 r) each control may accelerate, for delta_e delta_a delta_r delta_t: the moment
#: equations' control terms of a laterally symmetric aircraft (Morelli and Klein 2016, ch. 3; Etkin 1972,
#: ch. 5): the symmetric elevator moves Cm alone, the antisymmetric aileron and rudder Cl and Cn alone (and
#: through Ixz both p_dot and r_dot); the throttle all three (engine torque, slipstream, thrust line).
#: A free elevator column on the yaw axis only carried the gyro's noise onto r_dot, where it followed q and
#: appeared as a Cn_q_hat in the fits (docs/estimation.md, "Slow transients and the control terms").
CONTROL_AXES = {"delta_e": (1,), "delta_a": (0, 2), "delta_r": (0, 2), "delta_t": None}
#: Controls whose response on a second axis is tied to their response on the first (primary, secondary axis).
#: The aileron: ``I_z r_dot = N + I_xz p_dot``, so its yaw response is its fitted roll response times
#: ``I_xz / I_z``, a part shaped like the roll rate it starts (``N_p p``) and its own step (``N_da``): three
#: coefficients instead of its five or six free columns on the yaw axis, kept unless those beat them by the BIC
#: penalty (:func:`_coupled_axis`; docs/estimation.md, "The aileron's yaw response").
AILERON_YAW_TIE = {"delta_a": (0, 2)}
#: The ties the pipeline applies: none by default (thirteenth session, i8-cnda, decided at the merge). The
#: aileron tie above mends the b747's apparent ``Cn_delta_a`` (GP better than LS 10 -> 12 of 18) but over nine
#: aircraft the count stays 134 of 162 (t6 17 -> 15 on two 0.02-point ties, f16 16 -> 15 on a gate flip), and
#: the diagnosis was not evaluated with it. Opt in with ``COUPLED.update(AILERON_YAW_TIE)`` or
#: ``smooth_rates(coupled=...)`` (docs/estimation.md, "The aileron's yaw response").
COUPLED: dict[str, tuple[int, int]] = {}
#: How a logged control may move between its samples; the likelihood picks one per record (module docstring).
HOLDS = ("zoh", "foh")
#: Log-likelihood gain per sample that steps ("zoh") must show over linear motion ("foh") to be chosen.
ZOH_EVIDENCE = 0.01
#: Axes of the specific force that get the residual's Wiener correction: x and y. On z the measured CZ is
#: already 0.4-1.4 % off the truth in light turbulence (JSBSim), and there the correction (1.4 -> 1.1 % on
#: the c172x) narrowed the GP's CZ band with noise to 62-77 % coverage of the truth on the sgs (88-94 % without).
RESIDUAL_FORCE_AXES = (0, 1)
#: Levels of the turbulence state offered to the specific-force smoother (Hz: where the gust's ``1/f^2``
#: spectrum meets the accelerometer's white noise), by the likelihood with a BIC penalty (:func:`_nominal_model`).
GUST_HZ = (2.0, 4.0, 8.0, 16.0, 32.0, 64.0)
#: Correlation time of the turbulence state, s (its spectrum is flat below ``1/(2 pi tau)``, where the nominal
#: part already follows the signal; 0.5 and 2 s gave the same CZ on the f16, 0.66 / 0.67 %).
GUST_TAU_S = 2.0
#: Axes of the specific force that are offered the turbulence state: y and z. A vertical gust changes the angle of
#: attack and the lift at once (``CZ_alpha w_g / V``), a lateral gust the sideslip and the side force
#: (``CY_beta v_g / V``); both Dryden spectra fall as ``1/f^2`` above ``V / L`` (MIL-F-8785C sec. 3.7.2), up to the
#: Nyquist frequency in MIL-F-8785C light turbulence. Until the fifteenth session only z was offered it (on y the
#: likelihood took it and CY went 7.8 -> 9.0 % on the f16 in the then "moderate", JSBSim severity 3); with the
#: turbulence relabelled (light = severity 3) the plain y smoother took the gust-driven side force for noise (t6:
#: 0.11 m/s^2 against the sensor's 0.05) and CY sat at twice the accelerometer's Wiener floor; offered the state,
#: the measured held-out CY in light turbulence (eval_jsbsim, seeds 1-3) went t6 8.0-10.2 -> 4.5-6.3, rascal
#: 14.8-16.0 -> 6.5-8.1, sgs126 10.9-14.7 -> 6.3-8.6, c172x 10.0-13.3 -> 9.8-12.8 %; the smoother alone on the f16's
#: light flights 6.2-7.4 -> 6.7-8.6 % (the one loss; docs/estimation.md, section 5, "The measured coefficients in
#: MIL-F-8785C light turbulence").
#: x keeps the residual's Wiener correction alone by default; ``(0, 1, 2)`` (``estimate_states(gust_force_axes=)``,
#: ``eval_jsbsim --gust-force-axes xyz``) offers x the state too, opt-in: held-out CX sgs126 14.4 -> 12.3, us25e
#: 3.5 -> 2.7 %, GP band-edge flips elsewhere (docs/estimation.md, "The measured coefficients against their noise
#: floors"; twenty-fifth session, i8-meas). Read at each :func:`~.estimate.estimate_states` call.
GUST_FORCE_AXES = (1, 2)
#: Window of the rate smoother's local bandwidth choice, s (:func:`_local_blend`): the motion's strength changes
#: along a flight (manoeuvres and quiet legs; turbulence with altitude, MIL-F-8785C sec. 3.7, and in patches), a
#: whole-record bandwidth cannot follow it; only the whole-record choice and narrower candidates are offered
#: (offered wider ones too, it cost the f4n's held-out q_dot 7.60 -> 8.00 %, docs/estimation.md). Opt-in
#: (``smooth_rates(local_window_s=LOCAL_WINDOW_S)``); the pipeline does not use it (docs/benchmarks.md).
LOCAL_WINDOW_S = 5.0


@dataclass
class RateEstimate:
    """Smoothed body rates and angular accelerations.

    Attributes:
        rate, rate_sigma: (T, 3) p q r and 1-sigma, rad/s (NaN where no gyro).
        accel, accel_sigma: (T, 3) p_dot q_dot r_dot and 1-sigma, rad/s^2.
        bandwidth_hz: (3,) smoother bandwidth chosen per axis (maximum likelihood).
        noise_std: (3,) gyro white-noise standard deviation (maximum likelihood), rad/s.
        effectiveness: (3, m) acceleration jump per unit scaled control step (rad/s^2 per unit
            of ``scale * control``: the step and transient coefficients summed over the lags;
            with ``scale`` = qbar in Pa and the controls in rad, times ``I / (S b)`` it is a
            control derivative), per control given; NaN for a control that never moves, 0 on an
            axis the control is not given (``control_axes``).
        effectiveness_sigma: (3, m) 1-sigma of ``effectiveness``.
        input_lag: (m,) delay of each given control's effect, grid steps (maximum likelihood
            or as given); NaN for a control that never moves.
        hold: how the logged controls move between their samples, chosen by the likelihood
            (:data:`HOLDS`): ``"zoh"`` steps at the samples (ideal or fast servos fed the logged
            commands), ``"foh"`` linear between them (logged surface positions, or servos slower
            than the log rate).
        correction_band_hz: (3, 2) per axis the lowest and highest frequency (Hz) where the residual
            correction (:mod:`.wiener`) found signal over the gyro's noise floor and added it; NaN
            where it found none (or was switched off).
        slow_transient: (3,) per axis whether the slow transients (:data:`SLOW_DECAYS`) were taken
            (likelihood-ratio and coloured Wald tests); all False when none were offered.
        local_bandwidth_hz: (3, 2) per axis the lowest and highest local (weighted-mean) bandwidth, Hz, where
            the bandwidth was let change along the record (:func:`_local_blend`), NaN on an axis where it was not
            (its whole-record choice the narrowest candidate); None where on no axis.
    """

    rate: np.ndarray
    rate_sigma: np.ndarray
    accel: np.ndarray
    accel_sigma: np.ndarray
    bandwidth_hz: np.ndarray
    noise_std: np.ndarray
    effectiveness: np.ndarray
    effectiveness_sigma: np.ndarray
    input_lag: np.ndarray
    hold: str = "zoh"
    correction_band_hz: np.ndarray | None = None
    slow_transient: np.ndarray | None = None
    local_bandwidth_hz: np.ndarray | None = None


def _nominal_model(dt: float, bandwidth_hz: float, gust_hz: float = 0.0,
                   gust_tau_s: float = 2.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(F, Q, H)`` of the nominal model for unit measurement noise.

    ``[s, s_dot, s_ddot]`` with white snap, ``q = dt omega_c^6`` (``omega_c = 2 pi bandwidth_hz``). With
    ``gust_hz > 0`` a fourth state ``g``, first-order Gauss-Markov (``g_{k+1} = exp(-dt/tau) g_k + w_k``), is
    added to the measurement (``z = s + g + v``): the turbulence-driven part of the signal, whose spectrum
    falls as ``1/f^2`` above ``1/(2 pi tau)`` (the Dryden form's high-frequency tail, MIL-F-8785C sec.
    3.7.2) where the white-snap part falls as ``1/f^6``. ``var(w) = (2 pi gust_hz dt)^2``: above ``1/tau``
    the gust's spectrum equals the white noise's at ``gust_hz``. Jategaonkar, *Flight Vehicle System
    Identification*, 2nd ed., AIAA 2015, ch. 5 (process noise for turbulence, the filter-error model).
    """
    F = np.array([[1.0, dt, 0.5 * dt * dt], [0.0, 1.0, dt], [0.0, 0.0, 1.0]])
    Q = dt * (2 * np.pi * bandwidth_hz) ** 6 * Q_continuous_white_noise(dim=3, dt=dt, spectral_density=1.0)
    H = np.array([[1.0, 0.0, 0.0]])
    if gust_hz <= 0:
        return F, Q, H
    F4, Q4 = np.zeros((4, 4)), np.zeros((4, 4))
    F4[:3, :3], Q4[:3, :3] = F, Q
    F4[3, 3], Q4[3, 3] = math.exp(-dt / gust_tau_s), (2 * np.pi * gust_hz * dt) ** 2
    return F4, Q4, np.array([[1.0, 0.0, 0.0, 1.0]])


class _Lazy(dict):
    """``lazy[c]`` computes ``fn(c)`` once, on first use (the candidates a search never visits cost nothing)."""

    def __init__(self, fn):
        super().__init__()
        self.fn = fn

    def __missing__(self, c):
        self[c] = v = self.fn(c)
        return v


def _x0(z0: float, nx: int) -> np.ndarray:
    """Prior mean of the nominal state: the first measurement as the signal, rates and gust 0."""
    x = np.zeros(nx)
    x[0] = z0
    return x


def _innovation_filter(F: np.ndarray, g: SteadyState, H: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Transfer function (num, den) from measurements to innovations of the constant-gain filter.

    State ``s_k = x_{k-1}``: ``s_{k+1} = (I - K H) F s_k + K z_k``, innovation ``y_k = z_k - H F s_k``.
    """
    A = (np.eye(len(F)) - g.K @ H) @ F
    num, den = ss2tf(A, g.K, -H @ F, np.eye(1))
    return num[0], den


def _solve(GG: np.ndarray, Ge: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """GLS solution, inverse Gram and log-determinant of a (possibly rank-poor) Gram matrix."""
    m = len(Ge)
    if m == 0:
        return np.zeros(0), np.zeros((0, 0)), 0.0
    ridge = 1e-10 * max(float(np.trace(GG)) / m, 1e-300)
    M = GG + ridge * np.eye(m)
    L = np.linalg.cholesky(M)
    Minv = np.linalg.inv(L).T @ np.linalg.inv(L)       # m is at most a few dozen
    return Minv @ Ge, Minv, 2.0 * float(np.log(np.diag(L)).sum())


def _smooth_columns(F: np.ndarray, g: SteadyState, H: np.ndarray, Z: np.ndarray,
                    states: tuple[int, ...] | None = None) -> np.ndarray:
    """Constant-gain RTS smoother of many scalar records at once, from a zero prior mean.

    The same passes as :func:`~gcs_sysid.estimation.kalman.steady_state_smoother` (with
    ``x0 = 0``) for each column of ``Z`` (n, m), vectorised over the columns. The passes run on
    time-contiguous copies (``(state, column, time)``): each input is transposed once, not once per
    filter, and the sums build up contiguously; every value is that of the same ``lfilter`` calls
    on the same inputs, added in the same order.

    Args:
        F, g, H: the nominal model and its steady-state gains.
        Z: (n, m) records.
        states: the smoothed states wanted (None: all); the others are returned as 0 (the backward
            pass filters ``len(states)`` of them instead of ``Nx``).

    Returns:
        Smoothed states (n, Nx, m).
    """
    n, m = Z.shape
    nx = F.shape[0]
    want = tuple(range(nx)) if states is None else tuple(states)
    A = (np.eye(nx) - g.K @ H) @ F
    Zt = np.ascontiguousarray(Z.T)
    xt = np.empty((nx, m, n))
    for j in range(nx):      # forward: x_k = A x_{k-1} + K z_k, zero initial state
        num, den = ss2tf(A, g.K, A[j:j + 1], g.K[j:j + 1])
        xt[j] = lfilter(num[0], den, Zt, axis=-1)
    Cg = g.C
    M = np.eye(nx) - Cg @ F
    xst = np.zeros((nx, m, n))      # time reversed
    for i in range(nx):      # backward: xs_k = C xs_{k+1} + M x_k, from xs_T = F x_{T-1}
        xri = np.ascontiguousarray(xt[i, :, ::-1])
        for j in want:
            num, den = ss2tf(Cg, M[:, i:i + 1], Cg[j:j + 1], M[j:j + 1, i:i + 1])
            xst[j] += lfilter(num[0], den, xri, axis=-1)
    v = F @ np.ascontiguousarray(xt[:, :, -1])   # zero-input response of the end condition, until it has decayed
    del xt, Zt                                   # (freed before the result's copy: the worker's peak memory)
    scale = max(float(np.abs(v).max()), 1e-300)
    # the powers C^(k+1) until they have decayed (small matrices), then all rows at once
    pw, Ck = [], Cg.copy()
    norm_c = max(float(np.abs(Cg).max()), 1e-300)
    v_max, floor = float(np.abs(v).max()), 1e-15 * scale * min(norm_c, 1.0)
    for _ in range(n):
        if not np.abs(Ck).max() * v_max > floor:
            break
        pw.append(Ck)
        Ck = Cg @ Ck
    if pw:
        tail = np.einsum("kij,jm->kim", np.array(pw), v)
        for j in want:
            xst[j, :, :len(pw)] += tail[:, j].T
    return np.ascontiguousarray(xst.transpose(2, 0, 1))[::-1]


def _long_run_cov(S: np.ndarray, max_lag: int) -> np.ndarray:
    """Bartlett-weighted long-run covariance ``(k, k)`` of the rows of ``S (n, k)`` (a time series of scores):
    ``sum_{|j| <= L} (1 - |j| / (L + 1)) sum_t s_t s_(t-j)^T`` (Newey and West 1987), positive semi-definite."""
    out = S.T @ S
    for j in range(1, min(int(max_lag), len(S) - 1) + 1):
        g = S[j:].T @ S[:-j]
        out += (1.0 - j / (max_lag + 1.0)) * (g + g.T)
    return out


def _coloured_wald(inn: list[tuple[np.ndarray, np.ndarray]], GG: np.ndarray, Ge: np.ndarray,
                   sel: np.ndarray, opt: np.ndarray) -> float:
    """Wald statistic of the columns ``opt`` added to ``sel`` with coloured innovations.

    ``inn``: per gap-free segment the (lagged, standardised) column innovations ``G (n_s, m)`` and the
    measurement's innovations ``e (n_s,)``; ``GG = sum G^T G``, ``Ge = sum G^T e``. The columns ``opt``
    are partialled on ``sel`` (Frisch-Waugh), ``A = G~^T G~``, ``b`` their coefficients in the joint fit,
    and the scores ``G~_t r_t`` (``r`` the joint fit's innovations) give a Bartlett long-run covariance
    ``S`` per segment (lag window ``min(n - 1, 250, max(10, 4 n^(1/3)))``, as
    ``gcs_sysid.diagnose.regression.colored_covariance``): ``W = b^T A S^{-1} A b``. With white innovations
    ``W`` is the likelihood-ratio statistic ``n log(RSS_0 / RSS_1)`` to first order; when the innovations
    stay correlated over the transients' time scale (model error, gusts) it is smaller by their long-run
    variance ratio, and larger where the scores are anti-correlated (Newey and West 1987; Morelli and
    Klein 2016, sec. 5.3). Returns 0 when ``S`` is singular.
    """
    sel1 = np.union1d(sel, opt)
    b1 = _solve(GG[np.ix_(sel1, sel1)], Ge[sel1])[0]
    P = _solve(GG[np.ix_(sel, sel)], GG[np.ix_(sel, opt)])[0] if len(sel) else np.zeros((0, len(opt)))
    A = GG[np.ix_(opt, opt)] - GG[np.ix_(opt, sel)] @ P
    b = b1[np.searchsorted(sel1, opt)]
    n = sum(len(e) for _, e in inn)
    L = int(min(n - 1, 250, max(10, 4 * n ** (1 / 3))))
    S = np.zeros((len(opt), len(opt)))
    for G, e in inn:
        r = e - G[:, sel1] @ b1
        S += _long_run_cov((G[:, opt] - G[:, sel] @ P) * r[:, None], L)
    Ab = A @ b
    try:
        return float(Ab @ np.linalg.solve(S, Ab))
    except np.linalg.LinAlgError:
        return 0.0


def _segkey(segs: list[slice]) -> tuple:
    return tuple((sg.start, sg.stop) for sg in segs)


def _profile(GG, Ge, ee, n, m, S, noise_floor, sel=None):
    """GLS fit and diffuse profile log-likelihood (de Jong 1991) of the innovations on the columns
    (only the columns ``sel`` when given: the others get coefficient 0 and no variance)."""
    if sel is not None and len(sel) < m:
        b, Mi, logdet = _solve(GG[np.ix_(sel, sel)], Ge[sel])
        beta, Minv = np.zeros(m), np.zeros((m, m))
        beta[sel], Minv[np.ix_(sel, sel)] = b, Mi
        m = len(sel)
    else:
        beta, Minv, logdet = _solve(GG, Ge)
    rss = max(ee - float(Ge @ beta), 0.0)
    s2 = max(rss / max(n - m, 1), noise_floor**2)      # profiled measurement-noise variance
    return -0.5 * ((n - m) * np.log(s2) + n * np.log(S) + logdet), beta, Minv, s2


def _smooth_with_inputs(dt: float, Z: np.ndarray, U: np.ndarray, s: np.ndarray, lag: np.ndarray | None,
                        max_lag: int, decays: tuple[float, ...], noise_floor: float,
                        bandwidths_hz: tuple[float, ...], order: int,
                        hold: tuple[str, ...] = ("zoh", "foh"), aux: np.ndarray | None = None,
                        aux_axes: tuple[int, ...] | None = None,
                        slow_decays: tuple[float, ...] = (),
                        control_axes: list[tuple[int, ...] | None] | None = None,
                        gust_hz: tuple[float, ...] = (), gust_tau_s: float = 2.0,
                        gust_axes: tuple[int, ...] | None = None,
                        local_window_s: float | None = None) -> dict[str, np.ndarray]:
    """The shared engine of :func:`smooth_rates` (``order`` 1) and :func:`smooth_specific_force` (``order`` 0).

    ``order`` is the derivative of the measured signal that the control columns
    enter: 1 for rates (the acceleration jumps), 0 for forces (the measured
    specific force itself jumps). ``lag``: input delay per control in grid steps
    (None: 0), the start of a search over 0 ... ``max_lag`` (none if 0) by the
    likelihood summed over the axes, coordinate ascent over the controls at each
    axis' bandwidth; a change must raise the log-likelihood by more than the BIC
    penalty of one parameter, ``0.5 log(n)``, so a control with little effect
    keeps its delay.

    ``slow_decays``: further transient decay rates whose columns are left out of the bandwidth and
    delay choices and then taken per axis only if the likelihood-ratio statistic ``n log(RSS_0 / RSS_1)``
    and the Wald statistic with coloured innovations (:func:`_coloured_wald`) both beat the BIC penalty
    ``k log n`` (``k`` the axis' extra columns).
    ``control_axes``: per control of ``U`` the axes whose signal it may move (None: all); its columns
    are left out on the others.
    ``gust_hz``, ``gust_tau_s``, ``gust_axes``: the turbulence state (:func:`_nominal_model`) offered on the
    axes ``gust_axes`` (None: none) at the levels ``gust_hz``: after the nominal bandwidths, coordinate ascent
    over the level and the bandwidth; taken only if the log-likelihood gains more than ``0.5 log n`` over the
    nominal model's best. The smoothed signal is then the nominal part plus the gust; ``xd`` stays the nominal
    part's derivative (order 0 only: the forces need no derivative). ``out["gust"]``: the level taken per axis
    (0: none).
    ``local_window_s``: where given, the nominal bandwidth may narrow along the record (:func:`_local_blend`):
    per window of about this length the posterior weight of the whole-record choice and of each narrower nominal
    candidate from its innovations (the input coefficients and the noise level of the whole-record fit), the
    smoothed means blended with the weights interpolated between window centres. Not on an axis that took the
    turbulence state or whose choice is the narrowest. ``out["local_bw"]``: per axis the lowest and highest
    weighted-mean bandwidth over the record, Hz (NaN where not used).
    """
    T, d = Z.shape
    bw_ok = np.array([f for f in bandwidths_hz if f < 0.35 / dt] or [min(bandwidths_hz)])
    # candidates (bandwidth, gust level): the nominal model alone (gust 0) and, for each level in
    # gust_hz, with the turbulence-driven part as a Gauss-Markov state of the measured signal
    cands = [(f, 0.0) for f in bw_ok] + [(f, fg) for fg in gust_hz if fg > 0 for f in bw_ok]
    models = [_nominal_model(dt, f, fg, gust_tau_s) for f, fg in cands]
    Fs, Hs = [mo[0] for mo in models], [mo[2] for mo in models]
    gains = _Lazy(lambda c: steady_state(*models[c], np.eye(1)))
    tfs = _Lazy(lambda c: _innovation_filter(Fs[c], gains[c], Hs[c]))
    S = _Lazy(lambda c: gains[c].S[0, 0])
    bws = np.array([c[0] for c in cands])
    n_nominal = len(bw_ok)          # the first n_nominal candidates have no gust state
    aux = np.zeros((T, 0)) if aux is None else np.asarray(aux, float).reshape(T, -1)
    ok_u = np.isfinite(U).all(axis=1) & np.isfinite(aux).all(axis=1)
    all_decays = (0.0,) + tuple(decays) + tuple(slow_decays)
    nd, nc = len(all_decays), U.shape[1]
    # each control's axes (control_axes); the optional slow transients' columns are out of the bandwidth and
    # delay choices and tested per axis at the end
    ctl_axes = [None] * nc if control_axes is None else list(control_axes)
    on = lambda c, i: ctl_axes[c] is None or i in ctl_axes[c]       # noqa: E731
    n_base = nd - len(slow_decays)

    def opt_of(i):
        """The optional slow transients' columns of axis ``i``."""
        return np.array([c * nd + j for c in range(nc) if on(c, i) for j in range(n_base, nd)], int)
    lag = np.zeros(nc, int) if lag is None else np.asarray(lag, int)
    out = {k: np.full((T, d), np.nan) for k in ("x", "xs", "xd", "xds")}
    out.update(bw=np.full(d, np.nan), sig=np.full(d, np.nan), gust=np.full(d, np.nan), lag=lag)
    holds = tuple(hold) if nc else ("foh",)
    # the measured signals (aux) only with smooth controls: low-passed, they would smear the jumps that
    # ideal actuators (zoh) make in them (the project's simulation: q_dot 2.7 -> 5.0 % with them)
    m_of = {h: nc * nd + (aux.shape[1] if h == "foh" else 0) for h in holds}

    def sel_of(i, m):
        """Columns of axis ``i`` (None: all): its controls' (without the optional slow transients), and
        the measured signals' if the axis takes them."""
        cols = [c * nd + j for c in range(nc) if on(c, i) for j in range(n_base)]
        if m > nc * nd and (aux_axes is None or i in aux_axes):
            cols += list(range(nc * nd, m))
        return None if len(cols) == m else np.array(cols, int)
    per_hold = {h: [] for h in holds}   # per hold, per axis: segments, columns, innovations at its bandwidth
    ll_hold = dict.fromkeys(holds, 0.0)
    colcache: dict = {}
    bw_index = {f: j for j, f in enumerate(bw_ok)}

    def candidates_of(i, ll_of):
        """Candidates to evaluate on axis ``i`` and the best: every nominal bandwidth; on a gust axis then
        coordinate ascent over the gust level (at the best bandwidth) and the bandwidth (at the best level)."""
        lls = {c: ll_of(c) for c in range(n_nominal)}
        c0 = max(lls, key=lls.get)
        if gust_axes is None or i not in gust_axes or len(cands) == n_nominal:
            return c0, lls
        levels = [0.0] + [fg for fg in gust_hz if fg > 0]
        idx = lambda f, fg: bw_index[f] + (0 if fg == 0 else n_nominal * levels.index(fg))   # noqa: E731

        def visit(cs):
            """Evaluate the candidates ``cs`` not yet seen; the best so far."""
            for c in cs:
                if c not in lls:
                    lls[c] = ll_of(c)
            return max(lls, key=lls.get)
        best = c0
        for _ in range(3):      # levels at the best bandwidth, then bandwidths at the best level
            before = best
            best = visit([idx(cands[best][0], fg) for fg in levels])
            best = visit([idx(f, cands[best][1]) for f in bw_ok])
            if best == before:
                break
        # the gust state is one more parameter: taken only if it beats the nominal model's best by the
        # BIC penalty 0.5 log n (Schwarz 1978); else the nominal choice, exactly as without it
        n_i = ll_of.n
        return (best if lls[best] - lls[c0] > 0.5 * math.log(max(n_i, 2)) else c0), lls

    for i in range(d):
        segs = segments(np.isfinite(Z[:, i]) & ok_u, 10)
        if not segs:
            continue
        ezc: dict = {}      # the measurement's innovations per candidate and segment (the same for every hold)

        def ez_of(c, segs=segs, i=i, ezc=ezc):
            if c not in ezc:
                F_, H_, g = Fs[c], Hs[c], gains[c]
                # innovations only: one transfer function, not the filter's states as well
                ezc[c] = [lti_response((np.eye(len(F_)) - g.K @ H_) @ F_, g.K, -H_ @ F_, np.eye(1),
                                       Z[sg, i][:, None], _x0(Z[sg.start, i], len(F_)))[:, 0] / math.sqrt(S[c])
                          for sg in segs]
            return ezc[c]
        n = sum(sg.stop - sg.start for sg in segs)
        for h in holds:
            key = (_segkey(segs), h)
            m = m_of[h]
            if key not in colcache:     # the columns and their Gram matrices are the same for every axis
                cols = []               # with the same segments (the usual case): filtered once, not per axis
                for sg in segs:
                    A, W = control_columns(dt, U[sg], s[sg], (0,), all_decays, h)
                    if m > nc * nd:             # measured signals: continuous, linear between samples
                        Ax, Wx = aux_columns(dt, aux[sg])
                        A, W = np.concatenate([A, Ax], 1), np.concatenate([W, Wx], 1)
                    # measured part, and the parts of the signal and of its derivative (undelayed)
                    cols.append((W, W, A) if order == 1 else (A, A, np.gradient(A, dt, axis=0)))
                # the measured part's columns transposed once (time contiguous) for every candidate's filter
                colcache[key] = (cols, {}, {}, [np.ascontiguousarray(X[0].T) for X in cols] if m else None)
            cols, Gs, GG, cols_t = colcache[key]

            def gram(c, cols=cols, Gs=Gs, GG=GG, m=m, cols_t=cols_t):
                """Per segment the column innovations of candidate ``c`` and their lagged Gram matrix
                (computed once per candidate, shared by the axes)."""
                if c not in Gs:
                    num, den = tfs[c]
                    # lfilter down the rows of X[0], run on its time-contiguous copy made once (each column
                    # streams through memory; the same values as axis=0 on the row-major array)
                    Gs[c] = [(lfilter(num, den, Xt, axis=-1).T if m else X[0]) / math.sqrt(S[c])
                             for X, Xt in zip(cols, cols_t or [None] * len(cols))]
                    GG[c] = sum(lagged(G, nd, lag).T @ lagged(G, nd, lag) for G in Gs[c]) if Gs[c] else \
                        np.zeros((m, m))
                return Gs[c], GG[c]

            def ll_of(c, i=i, m=m):
                Gc, GGc = gram(c)
                es = ez_of(c)
                Ge = sum(lagged(G, nd, lag).T @ e for G, e in zip(Gc, es))
                ee = sum(float(e @ e) for e in es)
                return _profile(GGc, Ge, ee, n, m, S[c], noise_floor, sel_of(i, m))[0]
            ll_of.n = n
            c, lls = candidates_of(i, ll_of)
            ll_hold[h] += lls[c]
            per_hold[h].append((i, segs, cols, list(zip(gram(c)[0], ez_of(c))), c, n))
    # the same hold for every axis (it is how the servos move). Steps need decisive evidence: no servo
    # moves within one sample, so "zoh" (ideal actuators fed the logged commands, as in the project's own
    # simulation, where it gains about 0.4 per sample) is taken only when it beats "foh" by more than
    # ZOH_EVIDENCE per sample (and a BIC penalty, 0.5 log n) on every axis together; on JSBSim's servos
    # the two lie within +-0.005 per sample, foh giving the better accelerations throughout (docs/estimation.md)
    best_hold = holds[0]
    if len(holds) > 1:
        pen = {h: sum(max(0.5 * math.log(max(a[-1], 2)), ZOH_EVIDENCE * a[-1]) for a in per_hold[h])
               if h == "zoh" else 0.0 for h in holds}
        best_hold = max(holds, key=lambda h: ll_hold[h] - pen[h])
    axes = per_hold[best_hold]
    out["hold"] = best_hold
    m = m_of[best_hold]
    out.update(beta=np.full((d, m), np.nan), cov=np.full((d, m, m), np.nan), slow=np.zeros(d, bool))

    def grams(lagv):
        """Per axis: the lagged column innovations per segment and their Gram matrices (the Gram
        matrix shared by axes with the same segments and bandwidth)."""
        st, memo = [], {}
        for i, segs, cols, inn, c, n in axes:
            kk = (_segkey(segs), c)
            if kk not in memo:
                Gls = [lagged(G, nd, lagv) for G, _ in inn]
                memo[kk] = (Gls, sum(G.T @ G for G in Gls))
            Gls, GG = memo[kk]
            st.append([Gls, GG, sum(G.T @ e for G, (_, e) in zip(Gls, inn)), sum(float(e @ e) for _, e in inn)])
        return st

    if nc and max_lag > 0 and axes:
        cur = grams(lag)
        best = sum(_profile(GG, Ge, ee, ax[-1], m, S[ax[4]], noise_floor, sel_of(ax[0], m))[0]
                   for ax, (_, GG, Ge, ee) in zip(axes, cur))
        penalty = 0.5 * math.log(sum(a[-1] for a in axes))
        for _ in range(2):                       # coordinate ascent over the controls' delays
            before = lag.copy()
            for k in range(nc):
                kb = slice(k * nd, (k + 1) * nd)
                for cand in range(max_lag + 1):
                    if cand == lag[k]:
                        continue
                    ll = 0.0
                    memo = {}
                    for ax, (Gls, GG, Ge, ee), (i, segs, _, inn, c, n) in zip(axes, cur, axes):
                        # only the block of control k changes: its rows and columns of the Gram matrix
                        # (the same for axes with the same segments and bandwidth: computed once)
                        kk = (_segkey(segs), c)
                        if kk not in memo:
                            Gk = [shift(G[:, kb], cand) for G, _ in inn]
                            GG2 = GG.copy()
                            cross = sum(g.T @ G for g, G in zip(Gk, Gls))
                            GG2[kb, :] = cross
                            GG2[:, kb] = cross.T
                            GG2[kb, kb] = sum(g.T @ g for g in Gk)
                            memo[kk] = (Gk, GG2)
                        Gk, GG2 = memo[kk]
                        Ge2 = Ge.copy()
                        Ge2[kb] = sum(g.T @ e for g, (_, e) in zip(Gk, inn))
                        ll += _profile(GG2, Ge2, ee, n, m, S[c], noise_floor, sel_of(i, m))[0]
                    if ll > best + penalty:
                        best = ll
                        lag = lag.copy()
                        lag[k] = cand
                        cur = grams(lag)
            if np.array_equal(before, lag):
                break
        out["lag"] = lag
    xjcache: dict = {}
    for i, segs, cols, inn, c, n in axes:
        GG, Ge, ee = np.zeros((m, m)), np.zeros(m), 0.0
        for G, e in inn:
            Gl = lagged(G, nd, lag)
            GG += Gl.T @ Gl
            Ge += Gl.T @ e
            ee += float(e @ e)
        sel = sel_of(i, m)
        opt = opt_of(i)
        # the slow transients: taken on this axis only if the white and the coloured test both ask for them
        if len(opt):
            sel1 = np.union1d(sel, opt)
            rss = [max(ee - float(Ge[q] @ _solve(GG[np.ix_(q, q)], Ge[q])[0]), 1e-300) for q in (sel, sel1)]
            wald = _coloured_wald([(lagged(G, nd, lag), e) for G, e in inn], GG, Ge, sel, opt)
            # kept for diagnosis: rows, extra columns, the white likelihood-ratio statistic, the Wald statistic
            out.setdefault("slow_test", {})[i] = (n, len(opt), n * float(math.log(rss[0] / rss[1])), wald)
            # stricter than the white test, never looser: anti-correlated innovations (a long-run variance
            # below the white one) do not lower the bar (as gcs_sysid.gp.colored.variance_inflation, >= 1)
            if min(wald, n * math.log(rss[0] / rss[1])) > len(opt) * math.log(n):
                sel = None if len(sel1) == m else sel1
                out["slow"][i] = True
        _, beta, Minv, s2 = _profile(GG, Ge, ee, n, m, S[c], noise_floor, sel)
        out["bw"][i], out["sig"][i], out["gust"][i] = bws[c], math.sqrt(s2), cands[c][1]
        out["beta"][i], out["cov"][i] = beta, s2 * Minv
        g, F, H = gains[c], Fs[c], Hs[c]
        local = local_window_s is not None and cands[c][1] == 0 and 0 < c < n_nominal
        for sg, (Mz, X0, X1) in zip(segs, cols):
            Mz, X0, X1 = (lagged(X, nd, lag) for X in (Mz, X0, X1))
            z = Z[sg, i][:, None] - (Mz @ beta)[:, None]
            if local:
                js = list(range(c + 1))      # the whole-record choice and the narrower candidates
                x0n, x1n, var0, var1, bw_t = _local_blend(
                    z[:, 0], [(Fs[j], gains[j], Hs[j]) for j in js], js.index(c), s2,
                    max(int(round(local_window_s / dt)), 10))
                bw_mean = bws[js] @ bw_t
                lo_hi = out.setdefault("local_bw", np.full((d, 2), np.nan))
                lo_hi[i] = np.fmin(lo_hi[i, 0], bw_mean.min()), np.fmax(lo_hi[i, 1], bw_mean.max())
            else:
                xs, _ = steady_state_smoother(F, g, H, z, _x0(z[0, 0], len(F)))
                x0n, x1n = xs @ H[0], xs[:, 1]
                var0 = np.full(len(z), s2 * float(H[0] @ g.Ps @ H[0]))
                var1 = np.full(len(z), s2 * g.Ps[1, 1])
            # the signal is what the sensor measures without its noise: the nominal part plus the gust
            out["x"][sg, i] = x0n + X0 @ beta
            out["xd"][sg, i] = x1n + X1 @ beta
            if m:
                # the coefficients' own uncertainty: x = x~(z - Mz b) + X b, so an error db moves the
                # states by (X - smoother(Mz)) db
                kk = (sg.start, sg.stop, c)   # the same for axes with the same segment and bandwidth
                if kk not in xjcache:
                    # only the states read below: the signal (H) and its derivative (1)
                    xjcache[kk] = _smooth_columns(F, g, H, Mz, tuple(sorted({1, *np.flatnonzero(H[0])})))
                xj = xjcache[kk]
                D0, D1 = X0 - np.einsum("j,njm->nm", H[0], xj), X1 - xj[:, 1]
                C = s2 * Minv
                var0 += ((D0 @ C) * D0).sum(axis=1)
                var1 += ((D1 @ C) * D1).sum(axis=1)
            out["xs"][sg, i] = np.sqrt(var0)
            out["xds"][sg, i] = np.sqrt(var1)
    return out


def _local_blend(z: np.ndarray, models: list, c0: int, s2: float, window: int
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The nominal part smoothed with a bandwidth that may change along the record (a multiple-model smoother).

    One bandwidth per axis is a compromise over the whole record, set where the signal is strongest
    (manoeuvres, turbulence; its strength varies with altitude, MIL-F-8785C sec. 3.7, and comes in patches);
    where the motion is weaker it lets more of the sensor's noise through than the signal needs. Each candidate
    ``j`` (a nominal model, unit measurement noise; the caller passes the whole-record choice and the narrower
    ones) runs its constant-gain filter and smoother over ``z`` (the measurement less the input columns of the
    whole-record fit); per window of ``window`` samples its log-likelihood is the Gaussian density of its own
    innovations with the whole-record noise variance ``s2`` (the prediction-error decomposition: the
    innovations' density given the past, as a multiple-model filter weighs its modes; Bar-Shalom, Li and
    Kirubarajan, *Estimation with Applications to Tracking and Navigation*, Wiley 2001, ch. 11, the
    multiple-model approach), with prior 1/2 on the whole-record choice ``c0`` and the rest shared by the others.
    The posterior weights at the window centres are interpolated linearly in time and the smoothed means
    blended with them (model averaging, zero phase as each smoother). On a record of one window or less the
    weights are those of the whole record.

    Args:
        z: (n,) measurement less the input columns' part, finite.
        models: per candidate ``(F, SteadyState, H)`` of the nominal model (:func:`_nominal_model`), the
            bandwidth ladder's order.
        c0: index of the whole-record choice.
        s2: measurement-noise variance of the whole-record fit.
        window: window length, samples.

    Returns:
        ``(x, x_dot, var_x, var_x_dot, w)``: the blended signal and derivative (n,), their variances (n,)
        (each candidate's steady-state smoothed variance and the candidates' spread, weighted), and the
        weights ``w`` (K, n).
    """
    n, K = len(z), len(models)
    xs, xd, v0, v1, ll = np.empty((K, n)), np.empty((K, n)), np.empty(K), np.empty(K), []
    nw = max(int(round(n / window)), 1)
    edges = np.linspace(0, n, nw + 1).round().astype(int)
    for j, (F, g, H) in enumerate(models):
        x, inn = steady_state_smoother(F, g, H, z[:, None], _x0(z[0], len(F)))
        xs[j], xd[j] = x @ H[0], x[:, 1]
        v0[j], v1[j] = s2 * float(H[0] @ g.Ps @ H[0]), s2 * g.Ps[1, 1]
        S = s2 * float(g.S[0, 0])
        nll = 0.5 * (math.log(2 * math.pi * S) + inn[:, 0] ** 2 / S)
        ll.append([-float(nll[a:b].sum()) for a, b in zip(edges[:-1], edges[1:])])
    logp = np.array(ll) + np.log(np.where(np.arange(K) == c0, 0.5, 0.5 / max(K - 1, 1)))[:, None]
    wc = np.exp(logp - logp.max(axis=0))
    wc /= wc.sum(axis=0)
    centres = 0.5 * (edges[:-1] + edges[1:])
    k = np.arange(n)
    w = np.array([np.interp(k, centres, wc[j]) for j in range(K)])
    w /= w.sum(axis=0)
    xm, xdm = (w * xs).sum(axis=0), (w * xd).sum(axis=0)
    var0 = (w * (v0[:, None] + (xs - xm) ** 2)).sum(axis=0)
    var1 = (w * (v1[:, None] + (xd - xdm) ** 2)).sum(axis=0)
    return xm, xdm, var0, var1, w


def _coupled_axis(dt: float, Z: np.ndarray, U: np.ndarray, s: np.ndarray, o: dict, k: int, pa: int, sa: int,
                  decays: tuple[float, ...], slow_decays: tuple[float, ...], noise_floor: float,
                  bandwidths_hz: tuple[float, ...], control_axes: list[tuple[int, ...] | None] | None
                  ) -> tuple[int, int, float, float] | None:
    """Re-smooth axis ``sa`` of ``o`` (in place) with control ``k``'s response tied to axis ``pa``'s.

    From ``J w_dot = M`` with the product of inertia ``I_xz``: ``I_z r_dot = N + I_xz p_dot``. The aileron's
    part of ``r_dot`` is then its part of ``p_dot`` (the rolling moment ``L_da`` and the roll damping that
    follows, as the roll axis' control columns fitted them) times ``I_xz / I_z``, plus the yawing moment it
    brings: ``N_da`` at once (a step) and, through the roll it starts, a part shaped like that roll rate
    (``N_p p``, and the sideslip the roll makes) (Etkin, *Dynamics of Atmospheric Flight*, 1972, ch. 5;
    Morelli and Klein 2016, ch. 3). So on axis ``sa`` the control's free step and transients (five or six
    columns) are replaced by three inputs with one coefficient each: the primary axis' fitted response to
    the control (acceleration ``A b``, and its rate ``W b`` taken as an acceleration) and the control's
    step. The free columns fitted the secondary axis' gyro noise in a shape that follows the control: on
    the JSBSim B747 an apparent ``Cn_delta_a`` with ``t`` 2-6 in the measured Cn, which its aerodynamics
    does not have (docs/estimation.md, "The aileron's yaw response").

    The three enter as measured signals (linear between samples, :func:`~.inputs.aux_columns`) on axis
    ``sa`` alone, with the other controls' columns, lags and the slow transients' test as in ``o`` (linear
    hold only). The tied form is kept unless the free columns lower the axis' profiled noise variance by
    more than the BIC penalty of their extra parameters, ``n log(s2_tied / s2_free) > (m_free - 3) log n``
    (Schwarz 1978; as the slow transients' test); then ``o`` is left as it was and None is returned.

    Returns:
        ``(pa, sa, effectiveness, sigma)``: control ``k``'s acceleration jump on ``sa`` (the tied
        acceleration's coefficient times the primary axis' jump, plus the step's) and its 1-sigma; or None.
    """
    nc = U.shape[1]
    all_decays = (0.0,) + tuple(decays) + tuple(slow_decays)
    nd = len(all_decays)
    lag = np.asarray(o["lag"], int)
    kb = slice(k * nd, (k + 1) * nd)
    b = o["beta"][pa, kb]
    T = len(Z)
    acc, rate, step = np.full(T, np.nan), np.full(T, np.nan), np.full(T, np.nan)
    ok = np.isfinite(U).all(axis=1) & np.isfinite(Z[:, pa])
    for sg in segments(ok, 10):
        A, W = control_columns(dt, U[sg][:, [k]], s[sg], (0,), all_decays, "foh")
        A, W = shift(A, int(lag[k])), shift(W, int(lag[k]))
        acc[sg], rate[sg], step[sg] = A @ b, W @ b, A[:, 0]
    aux = np.column_stack([acc, rate, step])
    ax = [() if c == k else ((0,) if control_axes is None or control_axes[c] is None or sa in control_axes[c]
                              else ()) for c in range(nc)]
    o2 = _smooth_with_inputs(dt, Z[:, [sa]], U, s, lag, 0, decays, noise_floor, bandwidths_hz, order=1,
                             hold=("foh",), aux=aux, aux_axes=None, slow_decays=slow_decays, control_axes=ax)
    # BIC between the free columns (pass 1) and the tied inputs on this axis
    n = int(np.isfinite(o2["x"][:, 0]).sum())
    m_free = int(np.count_nonzero(o["cov"][sa, kb, kb].diagonal()))
    if not (np.isfinite(o2["sig"][0]) and np.isfinite(o["sig"][sa])) or n < 2 or \
            2 * n * math.log(o2["sig"][0] / o["sig"][sa]) > (m_free - 3) * math.log(n):
        return None
    for key in ("x", "xs", "xd", "xds"):
        o[key][:, sa] = o2[key][:, 0]
    for key in ("bw", "sig", "gust", "slow"):
        o[key][sa] = o2[key][0]
    j = nc * nd
    o["beta"][sa], o["cov"][sa] = 0.0, 0.0
    o["beta"][sa, :j] = o2["beta"][0, :j]
    o["cov"][sa, :j, :j] = o2["cov"][0, :j, :j]
    if "slow_test" in o2:
        o.setdefault("slow_test", {})[sa] = o2["slow_test"][0]
    g = np.array([float(b.sum()), 0.0, 1.0])
    o.setdefault("coupled", {})[k] = o2["beta"][0, j:j + 3]
    var = float(g @ o2["cov"][0, j:j + 3, j:j + 3] @ g)
    return pa, sa, float(g @ o2["beta"][0, j:j + 3]), math.sqrt(max(var, 0.0))


def smooth_rates(dt: float, rates: np.ndarray, noise_floor: float = 2e-4,
                 bandwidths_hz: tuple[float, ...] = BANDWIDTHS_HZ, controls: np.ndarray | None = None,
                 scale: np.ndarray | None = None, max_delay_s: float = 0.2,
                 input_lag: np.ndarray | None = None, decays: tuple[float, ...] = DECAYS,
                 holds: tuple[str, ...] = HOLDS, aux: np.ndarray | None = None,
                 aux_axes: tuple[int, ...] | None = None, residual_correction: bool = True,
                 slow_decays: tuple[float, ...] = SLOW_DECAYS,
                 control_axes: list[tuple[int, ...] | None] | None = None,
                 local_window_s: float | None = None,
                 coupled: dict[int, tuple[int, int]] | None = None) -> RateEstimate:
    """Body rates and their derivatives from bias-corrected gyro samples and the control commands.

    Per axis the nominal state is ``[w, w_dot, w_ddot]`` with white snap of
    spectral density ``q``, measured by ``w`` with white noise ``sigma^2``; the
    controls add acceleration steps and decaying transients of estimated size
    (module docstring, :func:`control_columns`). Each candidate bandwidth
    ``omega_c = (q / (sigma^2 dt))^(1/6)`` fixes the ratio ``q / sigma^2``; the
    scale ``sigma^2`` and the input coefficients are profiled out of the diffuse
    likelihood and the best bandwidth per axis is smoothed. Records are split at
    gaps (NaN in the gyro or the controls); the input coefficients are shared by
    the pieces.

    Args:
        dt: grid step, s.
        rates: (T, 3) gyro minus bias, rad/s, NaN where missing.
        noise_floor: smallest gyro noise assumed, rad/s (quantisation).
        bandwidths_hz: candidate bandwidths, Hz.
        controls: optional (T, m) control commands held over each grid step (rad), e.g.
            delta_e delta_a delta_r delta_t; columns that never change are not used.
        scale: optional (T,) effectiveness scale, e.g. the dynamic pressure from the
            pitot (Pa); default 1. NaN is filled by interpolation.
        max_delay_s: longest input delay searched per control, s (a servo or output delay;
            maximum likelihood over whole grid steps 0 ... max_delay_s).
        input_lag: optional delay per given control, grid steps: fixed if ``max_delay_s`` is 0,
            else the start of the search.
        decays: decay rates of the control transients, 1/s.
        slow_decays: slower transient decay rates, 1/s, taken per axis only where the likelihood-ratio
            and the coloured-innovation Wald statistics both beat the BIC penalty (:data:`SLOW_DECAYS`;
            ``()``: none offered).
        control_axes: optional, per column of ``controls``, the axes (0 p, 1 q, 2 r) that control may
            accelerate (None: all; :data:`CONTROL_AXES` for delta_e delta_a delta_r delta_t, the
            moment equations' control terms); its columns are left out on the other axes.
        coupled: optional ``{control column: (primary axis, secondary axis)}``: on the secondary axis that
            control's free columns are replaced by three (:func:`_coupled_axis`): the primary axis' fitted
            response to it (acceleration, and rate taken as an acceleration) and its step, unless the free
            columns beat them by the BIC penalty. For the aileron ``(0, 2)`` (:data:`AILERON_YAW_TIE`): its yaw
            response is its roll response times ``I_xz / I_z`` plus ``N_p p`` and ``N_da`` (Etkin 1972,
            ch. 5). Only with the linear hold (``"foh"``); with steps the free columns stay.
        holds: the candidate motions of the controls between their samples (:data:`HOLDS`), one
            chosen for all axes by the likelihood (steps only with decisive evidence,
            :data:`ZOH_EVIDENCE`).
        aux: optional (T, k) measured signals that enter the angular accelerations linearly and at
            once, linear between samples, one coefficient per axis and signal, not delayed and not
            scaled (e.g. :func:`normal_force_input`); NaN rows are left out like gyro gaps.
        aux_axes: the axes (0 p, 1 q, 2 r) that take ``aux``; None: all.
        residual_correction: add what the smoother left in the gyro where the residual's spectrum
            shows signal over the white-noise floor (:func:`~.wiener.residual_wiener`, per axis and
            gap-free piece, zero phase); False: the smoother alone.
        local_window_s: let the nominal bandwidth narrow along the record where the motion is weaker, chosen
            per window of about this length by the candidates' innovations (:func:`_local_blend`; e.g.
            :data:`LOCAL_WINDOW_S`); None (the default, and what :func:`~.estimate.estimate_states` uses): one
            bandwidth per axis for the whole record. Opt-in: on the JSBSim flights it improved the measured Cn
            but cost the GP's held-out Cl on pa28 light s3 (9.37 -> 10.82 %) and two GP-vs-LS ties on the t6
            (docs/benchmarks.md, "Thirteenth session, i8-meas").

    Returns:
        :class:`RateEstimate`.

    Raises:
        ValueError: ``controls`` or ``scale`` of the wrong length, or ``control_axes`` not one entry per
            column of ``controls``.

    Source: module docstring; Harvey (1989) sec. 3.4; de Jong (1991); the control terms: Morelli and
    Klein (2016) ch. 3; the slow transients' test: Schwarz, "Estimating the dimension of a model", Annals
    of Statistics 6(2), 1978 (BIC); Newey and West, "A simple, positive semi-definite,
    heteroskedasticity and autocorrelation consistent covariance matrix", Econometrica 55(3), 1987.
    """
    T = len(rates)
    U, moving, s = prepare_inputs(T, controls, scale)
    if control_axes is not None and len(control_axes) != len(moving):
        raise ValueError(f"control_axes has {len(control_axes)} entries, controls {len(moving)} columns")
    lag = None if input_lag is None else np.nan_to_num(np.asarray(input_lag, float)[moving]).astype(int)
    o = _smooth_with_inputs(dt, np.asarray(rates, float), U, s, lag, int(round(max_delay_s / dt)),
                            tuple(decays), noise_floor, bandwidths_hz, order=1, hold=tuple(holds),
                            aux=aux, aux_axes=aux_axes, slow_decays=tuple(slow_decays),
                            control_axes=None if control_axes is None else
                            [a for a, mv in zip(control_axes, moving) if mv], local_window_s=local_window_s)
    tied = {}
    if coupled and o.get("hold") == "foh":
        idx = np.cumsum(moving) - 1           # column of ``controls`` -> column of the moving ones
        for ctl, (pa, sa) in coupled.items():
            if 0 <= ctl < len(moving) and moving[ctl] and (control_axes is None or control_axes[ctl] is None
                                                            or {pa, sa} <= set(control_axes[ctl])):
                tied[ctl] = _coupled_axis(dt, np.asarray(rates, float), U, s, o, int(idx[ctl]), pa, sa,
                                          tuple(decays), tuple(slow_decays), noise_floor, bandwidths_hz,
                                          None if control_axes is None else
                                          [a for a, mv in zip(control_axes, moving) if mv])
    nctl = len(moving)
    eff = np.full((3, nctl), np.nan)
    eff_sig = np.full((3, nctl), np.nan)
    lags = np.full(nctl, np.nan)
    nd = 1 + len(decays) + len(slow_decays)
    for k, ctl in enumerate(np.nonzero(moving)[0]):   # the jump: step + transients at the (delayed) step
        sel = np.arange(k * nd, (k + 1) * nd)
        eff[:, ctl] = o["beta"][:, sel].sum(axis=1)
        eff_sig[:, ctl] = np.sqrt(np.maximum(o["cov"][:, sel][:, :, sel].sum(axis=(1, 2)), 0.0))
        lags[ctl] = o["lag"][k]
    for ctl, res in tied.items():
        if res is not None:
            eff[res[1], ctl], eff_sig[res[1], ctl] = res[2], res[3]
    band = np.full((3, 2), np.nan)
    if residual_correction:
        band = _correct_residual(dt, np.asarray(rates, float), o)
    return RateEstimate(o["x"], o["xs"], o["xd"], o["xds"], o["bw"], o["sig"], eff, eff_sig, lags,
                        o.get("hold", "zoh"), band, o["slow"], o.get("local_bw"))


def _correct_residual(dt: float, Z: np.ndarray, o: dict, order: int = 1,
                      axes: tuple[int, ...] | None = None) -> np.ndarray:
    """Add the Wiener estimate of the residual's signal to the smoothed signal in ``o`` (in place, per
    axis and gap-free piece) and its error variance to the sigmas; returns the corrected band per axis
    (d, 2), Hz, NaN where none (and for axes not in ``axes``; None: all).

    ``order`` 1 (rates): ``o["x"]`` is the rate, ``o["xd"]`` its derivative; the correction adds to both and
    the derivative's sigma grows by the Wiener error ``sum G N (2 pi f)^2 df``. ``order`` 0 (specific
    force): ``o["x"]`` is the signal itself; its sigma grows by ``sum G N df``.
    """
    band = np.full((Z.shape[1], 2), np.nan)
    for i in (range(Z.shape[1]) if axes is None else axes):
        res = Z[:, i] - o["x"][:, i]
        lo, hi = np.inf, -np.inf
        for sg in segments(np.isfinite(res), 10):
            c = residual_wiener(dt, res[sg])
            if c is None or not (c.gain > 0).any():
                continue
            o["x"][sg, i] += c.rate
            if order == 1:
                o["xd"][sg, i] += c.accel
                o["xds"][sg, i] = np.sqrt(o["xds"][sg, i] ** 2 + c.accel_var)
            else:
                var = float(np.sum(c.gain * c.noise_psd) * (c.freq[1] - c.freq[0]))
                o["xs"][sg, i] = np.sqrt(o["xs"][sg, i] ** 2 + var)
            b = c.band_hz
            lo, hi = min(lo, b[0]), max(hi, b[1])
        if np.isfinite(lo):
            band[i] = lo, hi
    return band


def smooth_specific_force(dt: float, f: np.ndarray, noise_floor: float = 1e-3,
                          bandwidths_hz: tuple[float, ...] = BANDWIDTHS_HZ, controls: np.ndarray | None = None,
                          scale: np.ndarray | None = None, max_delay_s: float = 0.2,
                          input_lag: np.ndarray | None = None, decays: tuple[float, ...] = DECAYS,
                          holds: tuple[str, ...] = HOLDS, residual_correction: bool = True,
                          residual_axes: tuple[int, ...] = RESIDUAL_FORCE_AXES,
                          gust_hz: tuple[float, ...] = GUST_HZ, gust_axes: tuple[int, ...] = GUST_FORCE_AXES
                          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Zero-phase smoothing of the specific force, jumping where the controls step.

    The same model as :func:`smooth_rates` one derivative lower: the measured
    specific force is a smooth part (``[f, f_dot, f_ddot]``, white snap) plus
    steps and decaying transients at the control changes (a control *force*,
    e.g. ``CZ_delta_e``, appears at once), measured with white noise (the
    accelerometer noise and vibration). Bandwidth per axis by the diffuse
    likelihood, as there; then, as there, the residual's Wiener correction
    (:func:`~.wiener.residual_wiener`): what the one bandwidth left of the force
    where the residual's spectrum stands significantly above the accelerometer's
    white-noise floor is added back, zero phase (gust-driven forces above the
    smoother's bandwidth; on JSBSim's moderate turbulence CY 15.8 -> 12.1 % on the
    c172x, ``docs/estimation.md``).

    Args:
        dt: grid step, s.
        f: (T, 3) specific force, m/s^2, NaN where missing.
        noise_floor: smallest accelerometer noise assumed, m/s^2.
        bandwidths_hz, controls, scale, max_delay_s, input_lag, decays, holds: as :func:`smooth_rates`
            (pass the rates' ``input_lag`` as the start: the same servo delays unless the
            forces clearly say otherwise, e.g. for the throttle, which hardly moves the rates; and
            the rates' ``hold`` as the only one: how the servos move is clearest in the rates, where
            steps gain 0.4 log-likelihood per sample on the project's simulation, the forces 0.01).
        residual_correction: add what the smoother left in the specific force where the residual's
            spectrum shows signal over the white-noise floor (per axis and gap-free piece, zero
            phase; its error variance ``sum G N df`` goes into ``f_sigma``); False: the smoother alone.
        residual_axes: the axes (0 x, 1 y, 2 z) corrected (:data:`RESIDUAL_FORCE_AXES`).
        gust_hz: levels of the turbulence state (Hz where its ``1/f^2`` spectrum meets the white noise) offered
            by the likelihood (:data:`GUST_HZ`; ``()``: none, the plain smoother).
        gust_axes: the axes offered it (:data:`GUST_FORCE_AXES`, y and z: the gust-driven side force and lift);
            the state is a first-order Gauss-Markov gust added to the measured force (:func:`_nominal_model`),
            taken on an axis only if it gains more than the BIC penalty over the plain smoother's best bandwidth.

    Returns:
        ``(f_smooth, f_sigma, noise_std)``: (T, 3), (T, 3) in m/s^2 and (3,) the
        accelerometer white noise (maximum likelihood), m/s^2.

    Raises:
        ValueError: ``controls`` or ``scale`` of the wrong length.

    Source: module docstring; Klein and Morelli (2006) ch. 10; Morelli and Klein (2016) sec. 11.1
    (smoothing from the measured signal and noise spectra); the turbulence state: Jategaonkar, *Flight Vehicle
    System Identification*, 2nd ed., AIAA 2015, ch. 5 and 7 (process noise, the filter-error method);
    MIL-F-8785C sec. 3.7.2 (the Dryden spectra); Schwarz (1978) (the BIC penalty).
    """
    U, moving, s = prepare_inputs(len(f), controls, scale)
    lag = None if input_lag is None else np.nan_to_num(np.asarray(input_lag, float)[moving]).astype(int)
    f = np.asarray(f, float)
    o = _smooth_with_inputs(dt, f, U, s, lag, int(round(max_delay_s / dt)),
                            tuple(decays), noise_floor, bandwidths_hz, order=0, hold=tuple(holds),
                            gust_hz=tuple(gust_hz), gust_tau_s=GUST_TAU_S, gust_axes=tuple(gust_axes))
    if residual_correction:
        _correct_residual(dt, f, o, order=0, axes=tuple(residual_axes))
    return o["x"], o["xs"], o["sig"]
