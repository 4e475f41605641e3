"""Air angles aided by the specific force: the gusts that kinematics cannot see.

The kinematic air angles (:func:`gcs_sysid.estimation.airdata.air_angles`: GPS velocity minus a
slowly varying wind, rotated into body axes) miss the turbulence across and normal to the flight
path. The accelerometers do not: the side force measures beta through ``CY_beta`` and the normal
force measures alpha through ``CZ_alpha``. Here the two are fused, per axis, in a state-space
model in which the gust is a *state*, not noise (the filter-error idea, Jategaonkar 2015 ch. 5
and 7; Morelli and Klein 2016 ch. 6-7):

    state        g_k = alpha_true - alpha_kin   (resp. beta),  g_{k+1} = phi g_k + w_k
                 (first-order Gauss-Markov, the Dryden spectrum's low-order form:
                 phi = exp(-dt / tau), stationary variance s_g^2)
    measurement  z_k = (CZ_meas_k - CZ_rest_k) / CZ_alpha - alpha_kin_k = g_k + v_k
                 CZ_meas = m a_z / (qbar S), CZ_rest = the linear model without its alpha term
                 (resp. CY with beta, p_hat, r_hat, delta_a, delta_r)

The aerodynamic model is identified from the same flight by linear least squares: a first pass
regresses the measured coefficients on the kinematic angles, the smoother gives new angles, and a
second pass regresses on those (the kinematic angles' gust errors attenuate ``CY_beta``; the second
pass removes most of that). The correlation time ``tau`` and the ratio ``s_g^2 / var(v)`` are
chosen per axis by maximum likelihood over a small grid (the noise scale profiled out, as in
:func:`gcs_sysid.estimation.smoothers.smooth_level`); the linear model is time-invariant, so the
steady-state Kalman filter and RTS smoother (:func:`gcs_sysid.estimation.kalman.steady_state_smoother`,
checked against filterpy's ``KalmanFilter`` + ``rts_smoother`` in the tests) give the exact
smoothed means in compiled code. Low frequencies stay with the kinematics (the Gauss-Markov state
reverts to zero), so a constant force-model bias (accelerometer bias, asymmetry) does not move the
angles; the gusts come from the accelerometers.

Circularity: the angles are then partly built from the same force measurements that the model
learns ``CY(beta)`` and ``CZ(alpha)`` from. Judge it on held-out truth (``docs/benchmarks.md``),
not on the angle error alone.

In turbulence the kinematic alpha's gust error can exceed the manoeuvre's alpha many times over (MIL-F-8785C light
turbulence, slow aircraft: 3-9 times), and the least-squares ``CZ_alpha`` is then a fraction of the lift slope or not
identified. Errors in variables only attenuate it, and an aircraft's lift slope is not below its wing's, so the
first pass holds ``|CZ_alpha|`` at least at the wing's slope from its aspect ratio (:data:`SLOPE_FLOOR`,
:func:`lift_slope`; ``docs/estimation.md``, "The lift-slope floor").

The side force has the same errors in variables with another sign pattern: the aircraft weathercocks into the lateral
gust (the kinematic sideslip takes the gust the aircraft turns into with the opposite sign) and rolls and yaws with it,
so least squares on the kinematic sideslip gives ``CY_beta`` and the rate terms the gust's share. The controls move the
sideslip and the rates and do not see the air: the side-force model's slopes are fitted by two-stage least squares with
the rudder, the aileron and their delays as instruments of ``beta``, ``p_hat`` and ``r_hat`` (opt-in,
:data:`INSTRUMENTED_BETA`, off by default: the t6 diagnosis got worse with it on; Söderström and Stoica, *Instrumental
variable methods for system identification*, Springer 1983; Morelli and Klein 2016 sec. 5.4), falling back to least
squares where they are weak (:data:`BETA_MIN_FIRST_STAGE_R2`).

Two errors stay (:mod:`gcs_sysid.estimation.angleerrors`): the least-squares ``CZ_alpha`` is attenuated
because the aircraft heaves with the gust the kinematic angle misses (``instrument_slopes``: the
elevator as instrument, two-stage least squares), and the flight-mean vertical wind puts an offset
``mean(w_d) / V`` on alpha that no channel of the log sees (its 1-sigma, ``AxisFit.bias_sigma``, is
added to alpha's sigma: an error common to the whole flight).

References:
    Jategaonkar, *Flight Vehicle System Identification*, 2nd ed., AIAA 2015, ch. 5 (filter error
    method, process noise for turbulence) and ch. 7 (flight path reconstruction).
    Morelli and Klein, *Aircraft System Identification*, 2nd ed., 2016, ch. 6 (equation error) and
    ch. 7 (output error; turbulence).
    MIL-F-8785C (1980) sec. 3.7 (Dryden turbulence model; gust correlation time L / V).
    Harvey, *Forecasting, Structural Time Series Models and the Kalman Filter*, CUP 1989 ch. 3
    (concentrated likelihood).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.signal import butter, lfilter, sosfiltfilt

from ..jackknife import block_jackknife_cov, block_jackknife_vars, slope_second_moment
from .angleerrors import MIN_FIRST_STAGE_R2, effective_n, first_stage_f, iv_lstsq, lagged_instruments, mean_wind_sigma
from .kalman import steady_state, steady_state_smoother
from .nodes import segments

__all__ = ["TAUS_S", "RATIOS", "AxisFit", "AidedAngles", "aided_air_angles", "describe", "lift_level"]

TAUS_S = (0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0)     #: candidate gust correlation times, s
RATIOS = (0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0)   #: candidate gust / measurement variance ratios
MIN_T_STAT = 8.0      #: |CY_beta|, |CZ_alpha| must exceed this many standard errors
MIN_SEGMENT_S = 5.0   #: shortest contiguous record that is aided, s
#: block length of the first pass's delete-a-block jackknife (:attr:`AxisFit.slope_jackknife`), s: the diagnosis's
#: (:data:`gcs_sysid.diagnose.uncertainty.BLOCK_S`), longer than the gusts' correlation times
SLOPE_JACKKNIFE_S = 15.0
MIN_VALID_S = 20.0    #: least aided flight time for the model fit, s
MIN_RATE_HZ = 20.0    #: slowest grid (IMU) rate at which the angles are aided, Hz
HIGHPASS_HZ = 0.3     #: the model's slopes are fitted above this frequency, Hz (at least; see HEAVE_EDGE)
#: alpha's slopes are fitted above ``max(HIGHPASS_HZ, HEAVE_EDGE x f_heave)``, ``f_heave = qbar S CL_alpha /
#: (2 pi m V)`` (``CL_alpha`` the wing's, :func:`lift_slope`) the heave (plunge) mode's corner, below which the aircraft
#: rides the vertical gust and the kinematic alpha's gust error correlates with the kinematic alpha (errors in
#: variables; ``docs/estimation.md``, "The slopes' band and the heave mode"). None (the default): the fixed
#: :data:`HIGHPASS_HZ`. Opt-in (1.0: the corner itself): measured better on the rascal (aided alpha's error SD 0.11-0.14
#: -> 0.035-0.046 deg in light turbulence; issue 9's ``Cm:alpha^2`` named 0/6 -> 4/6), but on the project's sim trainer
#: (corner 1.5 Hz) the diagnosis then names ``bias:airspeed`` before ``wind`` in tests/diagnose/test_diagnose_e2e.py:
#: its ranking was set with the old alpha (as for :data:`INSTRUMENTED_SLOPES`).
HEAVE_EDGE: float | None = None
MAX_EDGE_HZ = 2.0     #: the heave edge is capped here (the manoeuvres' band, 0.1-1.5 Hz, must stay in reach), Hz
SIGMA_CY0 = 0.003     #: prior 1-sigma of a symmetric airframe's CY at zero sideslip (asymmetry, accel bias)
SIGMA_BETA_MEAN = np.radians(1.0)   #: prior 1-sigma of the kinematic sideslip's mean error, rad
MEAN_BLOCK_S = 5.0    #: block length for the standard error of the CY constant (correlated residuals), s
#: gust correlation times in the moving window of :func:`kinematic_sigma`'s local gust variance (5: the variance
#: of a Gauss-Markov gust averaged over 5 tau has a relative standard error of about sqrt(2 / 5) ~ 0.6 in
#: variance, 0.3 in sigma, and follows a turbulent stretch of a flight that is calm elsewhere)
MOMENT_WINDOW_TAUS = 5.0
#: the moment cross-check drops the aiding only when, beside the larger residual, the moments follow the kinematic
#: angle by more than this many block-jackknife standard errors (``lambda + MOMENT_Z se < 0.5``, :func:`moment_lambda`;
#: thirty-sixth session). None: the older rule (a larger residual alone drops it), which fell back on a knife edge on
#: the JSBSim gliders' flights (sgs126: 41.7 against 41.5 %) and kept a kinematic alpha 20-50 times further from the
#: true one
MOMENT_Z: float | None = 2.0
MOMENT_BLOCK_S = 15.0  #: block length of :func:`moment_lambda`'s jackknife, s (the gusts are slow; as the scale check)
#: Default of ``aided_air_angles(instrument_slopes=None)``: fit CZ_alpha by two-stage least squares with the
#: elevator as instrument (:mod:`.angleerrors`). Off by default for now: measured better on JSBSim (c172x
#: light: alpha scale error 8 -> 5 %, 7 -> 3 %) and on the project's sim trainer (alpha RMS 0.114 -> 0.047
#: deg, CZ_alpha -4.3 -> -4.89 against -4.8), but with the sharper alpha the diagnosis finds small
#: ``wind`` / ``CZ:V`` / ``Cm:V`` effects on clean sim flights (tests/diagnose), whose floors were set
#: with the old alpha; switch on once those are re-measured (docs/estimation.md).
INSTRUMENTED_SLOPES = False
#: Default of ``aided_air_angles(instrument_beta=None)``: fit the side-force model's slopes by two-stage least squares
#: with the rudder and the aileron and their delayed copies (:data:`.angleerrors.INSTRUMENT_LAGS_S`) as instruments of
#: the sideslip and of the rates that answer the lateral gust (:data:`BETA_ENDOGENOUS`); least squares in every pass
#: where the instruments are weaker than :data:`BETA_MIN_FIRST_STAGE_R2` in any pass (opt-in: off by default). The
#: aircraft weathercocks into the lateral gust the kinematic sideslip misses, so least squares flattens ``CY_beta`` and
#: gives the yaw rate the gust's side force (MIL-F-8785C light turbulence: rascal -0.61..-0.71 against JSBSim's -1.03,
#: ``CY_r_hat`` -1.9 against 0), and the aided sideslip inherits the fit: the GP's side-force map is then wrong at the
#: true sideslip, where the truth's sideslip in the training regressors makes it right (``docs/estimation.md``,
#: "Instrumented side-force slopes"; ``docs/benchmarks.md``, "Sixteenth session, i8-iv").
INSTRUMENTED_BETA = False   # opt-in: with it on the diagnosis lost CY:scale (t6: estimators differing between flights,
#   fixed by the shared estimator; rascal 2/6 -> 0/6 even with it: docs/benchmarks.md, i8-iv and i9-ivdiag)
BETA_INSTRUMENTS = ("delta_r", "delta_a")   #: the controls that instrument the side-force model (with their delays)
#: columns of the side-force model instrumented with the sideslip: the aircraft rolls and yaws with the lateral gust,
#: so their least-squares slopes take the gust's side force the kinematic sideslip misses
BETA_ENDOGENOUS = ("p_hat", "r_hat")
#: the least first-stage partial R^2 of the beta instruments in every pass (:func:`.angleerrors.iv_lstsq`, the smallest
#: over the instrumented columns). On the JSBSim flights (rascal, t6, asw20; 90 s, manoeuvres in every axis) it is
#: 0.11-0.17 in light turbulence and 0.03-0.10 in moderate; the flights with a pass below 0.1 (t6 light s2: 0.12 then
#: 0.07) had 2SLS slopes 25-65 % off JSBSim's (weak instruments: Staiger and Stock, Econometrica 65, 1997)
BETA_MIN_FIRST_STAGE_R2 = 0.1
#: The weak-instrument test of the beta instruments (with :data:`INSTRUMENTED_BETA`): None: the first-stage R^2 floor
#: :data:`BETA_MIN_FIRST_STAGE_R2`; ``"f"``: the first-stage F statistic on the effective sample size
#: (:func:`.angleerrors.first_stage_f`) against :data:`BETA_MIN_FIRST_STAGE_F` (opt-in); ``"fuller"``: Fuller's k-class
#: (:func:`.angleerrors.iv_lstsq`, ``fuller_n``: the effective sample) on every flight, no fallback (opt-in)
BETA_WEAK_TEST: str | None = None
#: Staiger and Stock's (1997) rule of thumb (Stock and Yogo 2005: critical values near 10)
BETA_MIN_FIRST_STAGE_F = 10.0
WEAK_F_MAX_LAG_S = 2.0          #: the autocorrelation lags summed for the effective sample size, s
#: Hold ``|CZ_alpha|`` at least at the wing's lift slope (:func:`lift_slope`, Helmbold's formula, from ``b^2 / S``) in
#: the first pass where the fitted one is flatter (or not identified), and leave :data:`FLOOR_DROPS` out of that pass
#: (``docs/estimation.md``, "The lift-slope floor"). In MIL-F-8785C light turbulence the kinematic alpha's gust error
#: is 1-7 deg against a 0.6-1.1 deg signal on the slow aircraft, the fitted slope a fifth of the lift slope or not
#: identified, and the aiding fell back (sgs126 6/6 flights): with the floor every flight is aided and the aided
#: alpha's error less its mean is 0.1-0.4 deg (``docs/benchmarks.md``, "Fifteenth session, i8-aiding").
SLOPE_FLOOR = True
#: the floor holds only where the lateral gust found by the beta axis predicts at least this share of the kinematic
#: alpha's in-band variance as gust error (:func:`gust_share`: errors in variables to explain a flat slope); below it,
#: or with beta not aided, the fitted slope and the identification check stand as before
FLOOR_MIN_GUST_SHARE = 0.1
FLOOR_DROPS = ("q_hat",)   #: columns left out of the first pass when the slope floor holds
#: Opt-in (default False; twenty-fourth session, lift-floor): the pipeline (:mod:`.estimate`) gives the aiding the
#: airframe's *stated* whole-aircraft lift derivatives (``[aero] CL_alpha``, ``CL_q`` in the airframe file:
#: :class:`gcs_sysid.airframe.Airframe`; a wind-tunnel or DATCOM number), :func:`aided_air_angles` ``stated_slopes``.
#: The floor is then ``CL_alpha`` instead of the wing's Helmbold slope, and where it holds ``q_hat`` is held at
#: ``-CL_q`` instead of left out. The later passes refit on the angle the floored pass made, so whatever the first
#: pass holds is where they end (a fixed point: ``docs/estimation.md``, "The lift-slope floor as a fixed point"):
#: the wing-only floor leaves the whole aircraft's lift slope (the tail's ~10 %) and ``CZ_q`` out (s23: alpha read
#: 12-13 % too wide). An airframe file without ``[aero]`` changes nothing.
STATED_LIFT_SLOPE = False
#: Opt-in (default False; eighteenth session, i8-alpha): keep the aided alpha's flight mean at the kinematic alpha's
#: (the gust state's mean over the aided rows is removed after every pass). The flight-mean vertical wind is not
#: observable (it goes into CZ0), so the aiding has no information on alpha's mean; but its force-derived angle,
#: linearised at the kinematic angle with the local slope ``CZ_alpha + 2 CZ_alpha2 (alpha - alpha0)``, divides a
#: residual that correlates with the kinematic angle's gust error by a slope that moves with that same error, and its
#: mean moves away from the kinematic one by 0.3-1.0 deg on the slow aircraft (rascal, sgs126, asw20 in MIL-F-8785C
#: light turbulence; ``docs/benchmarks.md``, "Eighteenth session, i8-alpha").
KINEMATIC_MEAN = False
#: Opt-in (default False; twenty-sixth session, i8-cl0): the aided alpha's flight mean from the airframe's *stated*
#: lift line (``[aero] CL0``, ``CL_alpha``, ``CL_q``, ``CL_delta_e`` in the airframe file, :class:`gcs_sysid.airframe.
#: Airframe`; :func:`lift_level`). A constant vertical wind is not observable from one flight's kinematics and goes into
#: the fitted ``CZ0``; a *stated* zero-lift level is what makes it observable (the level is to alpha's mean what the
#: stated ``CL_alpha`` is to its scale). The measured lift's flight mean, read through the stated line, gives the true
#: alpha's mean; it is combined with the aided alpha's mean by their two 1-sigmas (the flight-mean wind's,
#: ``AxisFit.bias_sigma``, and the stated line's, ``CL0_sigma / CL_alpha`` with the measured lift's block standard
#: error), and the smaller combined 1-sigma replaces ``bias_sigma``. An airframe without ``CL0`` changes nothing.
STATED_LIFT_LEVEL = False
#: the 1-sigma of a stated ``CL0`` when the airframe gives no ``[aero] CL0_sigma`` (a judgement: DATCOM-class estimates
#: of a conventional aircraft's zero-lift angle are good to about 0.5 deg, 0.02-0.05 in CL; a wind tunnel's to 0.005)
STATED_CL0_SIGMA = 0.02
#: block length of the measured lift's flight-mean standard error (:func:`lift_level`: the gusts' lift is correlated), s
LEVEL_BLOCK_S = 10.0
#: Opt-in (default False; eighteenth session, i8-alpha): where the lift-slope floor holds, leave the curvature
#: ``(alpha - alpha0)^2`` out of the first pass too (as :data:`FLOOR_DROPS`); the later passes fit it on the aided
#: angle. Fitted on the kinematic angle it is that angle's gust error squared (rascal, sgs126, asw20 light: -16..+11 per
#: rad^2 against JSBSim's -0.1..0.3), and it moves the aided alpha's mean (``docs/benchmarks.md``, "Eighteenth session,
#: i8-alpha").
FLOOR_DROPS_CURVATURE = False
#: Opt-in (default (); twenty-first session, i8-aid): the columns of the alpha model whose slopes are chosen by the
#: *gust model's likelihood* instead of least squares (``"delta_e"``; the curvature as ``"(alpha - alpha0)^2"``), see
#: :func:`_profile_columns`. In turbulence the kinematic alpha carries the vertical gust, the stabilising autopilot
#: moves the elevator against the gust's pitch, and least squares gives ``CZ_delta_e`` the gust's normal force (c172p
#: light: +0.6..+1.2 against JSBSim's -0.39; the aided alpha then carries ``-CZ_delta_e / CZ_alpha`` of the elevator).
ALPHA_PROFILE_COLUMNS: tuple[str, ...] = ()
#: refit the other free columns for each candidate (a profile likelihood; measured: c172p light CZ_delta_e
#: -0.8..-2.0 with q_hat -10..-18, the pair slides along their collinearity); False: held at least squares
PROFILE_REFIT = False
#: the profiled slope is searched within +- this (per unit of its regressor) of least squares'
PROFILE_HALF_WIDTH = 2.0
#: Opt-in again since the thirty-third session (twenty-fifth session, i8-beta; the replay's, ``predict``'s and
#: ``listen``'s default in the thirty-second session only): ``CY_beta`` by the gust model's likelihood, the
#: filter-error estimate (:func:`_profile_angle_slope`): the change of variables' Jacobian ``-N log|CY_beta|`` included,
#: the other side-force slopes refitted by least squares for each candidate, in the first pass (the later passes refit
#: on the aided angle by least squares, a fixed point). Least squares above 0.3 Hz makes ``CY_beta`` 15-18 % steep on
#: the s23 (above the directional mode the kinematic sideslip's gust error correlates positively with it); the
#: likelihood lands within a few per cent of JSBSim's slope there (docs/estimation.md, "The side-force slope by the
#: gust model's likelihood"). With :data:`BETA_PROFILE_HOLD`, on the 75 light flights of the 25 JSBSim tuning aircraft
#: issue 8's counts went +11/-2 (GP seed 0) and +15/-3 (seed 1), only the s23 losing a count at both seeds, and the
#: median error of the model at JSBSim's true regressors fell for CY 24.7 -> 21.2 % and Cn 21.4 -> 18.6 % (rule 8(b);
#: ``docs/benchmarks.md``, "Thirty-first session, lead" and "Thirty-second session, lead"). The diagnosis and
#: ``gcs-sysid fit`` load their flights with least squares instead (:data:`gcs_sysid.diagnose.run.BETA_PROFILE`):
#: issue 9's counts with the profile are not measured, and the twenty-fifth session's run of the profile alone lost a
#: count there (the s23's ``CY:scale``). :func:`aided_air_angles` ``profile_beta`` and
#: :func:`gcs_sysid.estimation.estimate_states` ``profile_beta`` choose per call.
#: **Why it is off again** (thirty-third session, lead; ``docs/benchmarks.md``, "Thirty-third session, lead"): those
#: counts left out the bands and the correlation. With all of issue 8's counts (``benchmarks/issue8_counts.py``) the
#: same 90-s flights give +13/-10 and +14/-6; 120-s flights of the same aircraft +12/-9 and +15/-9; and a third set
#: fixed in advance (seeds 4-6, 90 s) **+6/-11** and **+8/-14**, net negative at both GP seeds, which the session's
#: pre-registered rule made the end of the default. The medians at the true regressors still favour it on CY and Cn on
#: every set.
BETA_PROFILE = False
#: On (thirty-first session, i8-truereg; it acts only with the profile, :data:`BETA_PROFILE` or ``profile_beta=True``,
#: so the profile, when asked for, comes with its hold): the later passes keep the
#: first pass's profiled ``CY_beta`` (the other side-force slopes refitted by least squares with it held) instead of
#: refitting it by least squares on the aided sideslip. That refit is circular: the aided sideslip is built from the
#: measured side force with the last pass's slope, so least squares on it returns about that slope plus the share of
#: the gust the aided angle still misses, and the passes drift back towards least squares' steep slope (fokker50 light
#: s1: profiled -0.480, least squares -0.538, after the passes -0.496; JSBSim's -0.445). A model learned on a sideslip
#: read ``k`` times the true one has ``CY_beta`` and ``Cn_beta`` ``1 / k`` times JSBSim's and misses at the true
#: sideslip (``docs/benchmarks.md``, "Thirty-first session, i8-truereg").
BETA_PROFILE_HOLD = True
#: ``CY_beta`` is searched between these multiples of least squares' slope; an optimum at either end keeps least
#: squares. Only flatter (upper end 1): where the likelihood steepened least squares it was wrong on the roster (the
#: jets, whose gust is fast against the manoeuvre: b737 -1.07..-1.13 -> -1.33..-1.43 against JSBSim's -1.03; with 1.5
#: the error SD rose on 14 of 60 light roster flights, with 1 on 2 of 66, s23 and ka350 included; chosen after that
#: measurement). The lower end: with 0.5 the sgs126 s1 went to 0.53 x (error SD 0.32 -> 1.85 deg).
BETA_PROFILE_RANGE = (2.0 / 3.0, 1.0)
#: the force-derived departure is high-passed here before its likelihood, Hz: below it the kinematic angle's error is
#: the 30-s wind estimate's drift, which a first-order gust state describes badly (full band: s23 s2, s3 -0.43, -0.31
#: against JSBSim's -0.55; with 0.1 Hz -0.52, -0.56)
BETA_PROFILE_EDGE_HZ = 0.1
#: Opt-in (thirty-third session, i8-counts33; None: off, the default): the profiled ``CY_beta`` is taken only where
#: the gust model's likelihood prefers it to least squares' significantly, i.e. the likelihood-ratio statistic
#: ``2 (nll(least squares) - nll(profiled))`` (:func:`_angle_profile_objective`) reaches this value; below it least
#: squares' slope is kept (and nothing is held). The statistic is chi-squared with one degree of freedom under least
#: squares' slope (Wilks 1938; Pawitan, *In All Likelihood*, 2001, sec. 9.3): 3.84 is the 95 % level
#: (:data:`BETA_PROFILE_LR_95`). On the s23's light flights the profile moved the slope by 0.6-1.5 curvature standard
#: errors with a ratio of 0.3-2.1, and the model's Cl and Cn at the true regressors got worse. At 3.84 on the 75 light
#: roster flights it refused the profile on 23 of the 41 it moves (12 aircraft) and lost rule 8(b) on issue 8's
#: counts (+4/-5 at GP seed 0, +4/-9 at seed 1; ``docs/benchmarks.md``, "Thirty-third session, i8-counts33";
#: ``docs/estimation.md``, "Why the s23 loses counts with it").
BETA_PROFILE_MIN_LR: float | None = None
#: Opt-in (sixty-second session; default False): the side-force model's slopes of the first pass by generalised least
#: squares under the gust model (:func:`_gls_gust_fit`): every slope, ``CY_beta`` and the rate and control terms, fitted
#: on the innovations of the Gauss-Markov gust plus white noise (a regression with ARMA(1, 1) errors, the correlation
#: time and variance ratio by the concentrated likelihood), then held in the later passes. Least squares on the
#: kinematic sideslip gives the rate and control columns the gust's side force wherever the aircraft or its autopilot
#: answers the gust (JSBSim C.684, whose side force is ``-1.04 beta`` alone: ``CY_r_hat`` -1.35, ``CY_delta_r`` -0.11),
#: and the aided sideslip then under-reads the slow sideslip those columns move with (``docs/estimation.md``, "The
#: side-force model by generalised least squares").
BETA_GLS = False
#: physical signs of the side-force model's columns in :data:`BETA_GLS`'s fit: a slope of the wrong sign is held at zero
#: and the others fitted again. A conventional fin gives ``CY_r_hat > 0`` (the yaw rate's sideslip at the fin) and a
#: rudder deflected trailing edge left (``delta_r > 0``) a side force to the right (``CY_delta_r > 0``): least squares
#: on the kinematic sideslip gives both the wrong sign where the aircraft or its autopilot answers the gust (JSBSim t6,
#: iar80, f4n, c684; the 25 JSBSim aircraft's exact side force has each at zero, within 0.005, or positive)
BETA_GLS_SIGNS: dict[str, float] = {"r_hat": 1.0, "delta_r": 1.0}
#: the first pass's columns are high-passed here before :func:`_gls_gust_fit`, Hz (None: the full band): below it the
#: kinematic sideslip's error is the wind estimate's drift, no first-order gust
BETA_GLS_EDGE_HZ: float | None = 0.1
#: the gust correlation times :func:`_gls_gust_fit` chooses from, s: :data:`TAUS_S` less 0.5 s, where the whitening
#: is nearly a first difference and the kinematic sideslip's own share of the gust (the aircraft drifting with it)
#: flattens ``CY_beta`` (screened on 25 JSBSim reference flights: the c684, rascal and s23 chose 0.5 s, and came out
#: 0.72, 0.57 and 0.86 of JSBSim's slope, against 0.92, 0.69 and 0.99 from 1 s)
BETA_GLS_TAUS = (1.0, 2.0, 4.0, 8.0, 16.0, 32.0)
#: the chi-squared 95 % point with one degree of freedom (``scipy.stats.chi2.ppf(0.95, 1)``)
BETA_PROFILE_LR_95 = 3.841458820694124


@dataclass
class AxisFit:
    """One axis of :func:`aided_air_angles` (alpha from CZ, or beta from CY).

    Attributes:
        name: ``"alpha"`` or ``"beta"``.
        used: whether the specific force aided this axis (False: kinematic angle kept).
        reason: why not, or a summary of the fit.
        columns: regressor names of the linear model, the first is the constant.
        coef: (P,) model coefficients of the last pass; coef[1] is CZ_alpha or CY_beta (1/rad).
        coef_sigma: (P,) their standard errors.
        tau_s: gust correlation time, s (maximum likelihood).
        gust_sigma: stationary 1-sigma of the gust angle, rad.
        noise_sigma: 1-sigma of the force-derived angle per sample, rad.
        ratio: the chosen gust / noise variance ratio (one of :data:`RATIOS`).
        r2: share of the measured coefficient's variance above :data:`HIGHPASS_HZ` that the model explains.
        mean_shift: constant added to the angle, rad (beta: the kinematic angle's mean error, from CY0 ~ 0; alpha: the
            move onto the stated lift line's level, :data:`STATED_LIFT_LEVEL`, else 0).
        shift_note: why the angle's mean was or was not moved (beta; alpha only with a stated lift line, else empty).
        moment_rss: (kinematic, aided) residual variance of the moment cross-check, each as a share of
            the moment coefficients' variance (NaN: no moments given).
        moment_lambda: (lambda, its standard error) of the cross-check's encompassing regression
            (:func:`_moment_check`: 1, the moments follow the aided angle; 0, the kinematic one); NaN where not
            needed (the aided residual the smaller) or with fewer than 3 blocks.
        slope_method: how the slopes were fitted: ``"2SLS"`` (alpha: the elevator and its delayed copies
            instrument the angle, :func:`gcs_sysid.estimation.angleerrors.iv_lstsq`), ``"OLS"`` or ``"given"``
            (another flight's slopes, :func:`aided_air_angles` ``models``), followed by a note when a model was given,
            and (alpha) when the first pass held ``CZ_alpha`` at the wing's lift slope (:data:`SLOPE_FLOOR`).
        first_stage_r2: the instruments' first-stage partial R^2 (NaN: no instruments).
        scale_sigma: standard uncertainty of the aided angle's relative scale: the aided and the kinematic
            angle's disagreement in scale, ``sqrt(d^2 + se_d^2)`` with ``d`` the slope of (aided - kinematic)
            on the centred aided angle and ``se_d`` its block-jackknife standard error (15-s blocks, Kuensch
            1989). The kinematic angle's scale is set by geometry (GPS velocity, attitude), the aided one's
            by the force slope, which errors in variables attenuate; NaN where not aided. Read by the
            diagnosis as a type-B uncertainty (:func:`gcs_sysid.diagnose.uncertainty.air_data_uncertainty`).
        bias_sigma: 1-sigma of the angle's flight-common offset, rad (alpha: the flight-mean vertical
            wind over the airspeed, :func:`gcs_sysid.estimation.angleerrors.mean_wind_sigma`; NaN for beta,
            whose mean the wind fit and the CY0 prior set). Included in the per-sample sigma.
        wind_sigma: alpha moved onto a stated lift line (``mean_shift``): the flight-mean wind's 1-sigma before the
            move (``bias_sigma`` then holds the combined one), rad; NaN where no line moved the angle.
        map_columns: regressors of the force model the aided angle is built from: the angle itself, then
            the others (alpha: ``alpha q_hat delta_e``; beta: ``beta p_hat r_hat delta_a delta_r``), those that
            vary; empty where not aided.
        map_cov: ``(K, K)`` over ``map_columns``: second moment of the aided angle's flight-common *linear*
            error ``e(x) = sum_k M_k (x_k - mean x_k)`` (rad per unit of each regressor; the first entry is the
            scale). The force model's slopes, biased by errors in variables, make the aided angle's error
            follow the manoeuvre: in moderate turbulence it is 2-10 times the per-sample sigma, while what
            is left after this map is 0.5-1.7 times it (``docs/estimation.md``, "The aided angles' common
            linear error"). Stated as ``M M^T + Cov_jk(M)``: ``M`` the least-squares slopes of (aided -
            kinematic) on the centred columns, ``Cov_jk`` their block-jackknife covariance (15-s blocks,
            Kuensch 1989): :attr:`scale_sigma`'s rule on every column. Common to the flight, so it cancels
            at the flight's own regressors and belongs to the band at exact conditions only. Empty where
            not aided.
        band_hz: the edge, Hz, above which the slopes were fitted (:data:`HIGHPASS_HZ`, or for alpha the heave
            mode's corner where higher: :func:`heave_edge_hz`).
        slope_jackknife: (P,) delete-a-block jackknife standard errors of the *first* pass's coefficients (on the
            kinematic angle; :data:`SLOPE_JACKKNIFE_S`-second blocks, Kuensch 1989), NaN for the constant; all NaN
            where the first pass was not a plain least-squares or two-stage fit (a floored, profiled or given slope).
            The later passes refit the model on the angle the last one aided, which the force model itself built,
            so their standard errors (:attr:`coef_sigma`) say how well the aided angle reproduces the force, not
            how well the slopes are known: on the JSBSim SGS 1-26 (light turbulence) the side-force model's
            ``CY_r_hat`` is -0.539 +- 0.007 on the reference flight and -1.071 +- 0.011 on a clean flight of the
            same aircraft, while the first pass's jackknife gives +- 0.30 and +- 0.49 (``docs/benchmarks.md``,
            *Forty-second session, lead*). Read by the diagnosis as the aided angle's uncertain loading on the
            model's other columns (:func:`gcs_sysid.diagnose.uncertainty.air_data_uncertainty`, ``along_*``).
    """

    name: str
    used: bool
    reason: str
    columns: tuple[str, ...] = ()
    coef: np.ndarray = field(default_factory=lambda: np.zeros(0))
    coef_sigma: np.ndarray = field(default_factory=lambda: np.zeros(0))
    tau_s: float = float("nan")
    gust_sigma: float = float("nan")
    noise_sigma: float = float("nan")
    ratio: float = float("nan")
    r2: float = float("nan")
    mean_shift: float = 0.0
    shift_note: str = ""
    moment_rss: tuple[float, float] = (float("nan"), float("nan"))
    moment_lambda: tuple[float, float] = (float("nan"), float("nan"))
    slope_method: str = "OLS"
    first_stage_r2: float = float("nan")
    bias_sigma: float = float("nan")
    wind_sigma: float = float("nan")
    scale_sigma: float = float("nan")
    map_columns: tuple[str, ...] = ()
    map_cov: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    band_hz: float = HIGHPASS_HZ
    slope_jackknife: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def curvature_sigma(self) -> float:
        """Standard uncertainty of the aided angle's flight-common *curvature* error, 1/rad (alpha only).

        The aided angle ``x`` may carry ``e(x) = c (x - mean)^2`` that the kinematic one does not: the force model's
        curvature ``CZ_alpha2`` (the column ``(alpha - alpha0)^2``) and a curvature of the angle's error are one and
        the same to the aiding. Its later passes fit the model on the angle the last pass aided, and a measured
        coefficient linear in the true angle, ``CZ = CZ_alpha alpha_true``, read on ``alpha = alpha_true + c (alpha -
        mean)^2`` shows the curvature ``CZ_alpha2 = -CZ_alpha c``; the force-derived angle then keeps that ``c``
        (its curvature is divided out by the same slope). The fixed point is not identified by the data: where it
        lands follows the first pass on the kinematic angle (its gust error squared). Against JSBSim's exact alpha
        (t6 and b737, clean flights and their references, light turbulence) the aided alpha's curvature error is
        ``CZ_alpha2 / |CZ_alpha|`` within 0.01-0.41 /rad on 11 of 12 flights (t6 s13: 0.64; t6 s14: fitted
        -4.55 / 4.65 = -0.98, JSBSim -0.78; b737 s13: -5.11 / 4.91 = -1.04, JSBSim -0.89; ``docs/benchmarks.md``,
        "Twentieth session, i9-curv"), while the fit's own standard error of ``CZ_alpha2`` (0.05-0.17) is 20-100
        times smaller than its between-flight scatter (-5.1..+5.7). So the whole fitted curvature is stated as
        possible error of the angle (a type-B evaluation from the available information, GUM JCGM 100:2008
        sec. 4.3.1; Morelli and Klein, *Aircraft System Identification*, 2nd ed., ch. 5, errors in the regressors of
        an equation-error fit), with its standard error in quadrature, as :attr:`scale_sigma` states the scale:
        ``sqrt(CZ_alpha2^2 + se^2) / |CZ_alpha|``.

        Returns:
            1/rad (0.5 = half a radian of angle error per rad^2 of centred angle squared); NaN where the axis was
            not aided or its model holds no curvature column (the sideslip's).
        """
        cols = tuple(self.columns)
        q = f"({self.name} - {self.name}0)^2"
        if not self.used or q not in cols or len(self.coef) <= cols.index(q):
            return float("nan")
        i = cols.index(q)
        c = np.asarray(self.coef, float)
        s = np.asarray(self.coef_sigma, float)
        a1 = abs(float(c[1])) if c.size > 1 else 0.0
        if not a1 > 0 or not np.isfinite(c[i]):
            return float("nan")
        se = float(s[i]) if s.size > i and np.isfinite(s[i]) else 0.0
        return float(np.hypot(c[i], se) / a1)


@dataclass
class AidedAngles:
    """Result of :func:`aided_air_angles`.

    Attributes:
        alpha, beta: (T,) air angles, rad (the kinematic ones where an axis was not aided).
        alpha_sigma, beta_sigma: (T,) 1-sigma, rad (NaN where not aided; where the moment cross-check rejected
            the aiding, the kept kinematic angle's error from the gust found, :func:`kinematic_sigma`).
        axes: the two :class:`AxisFit` (alpha, beta).
    """

    alpha: np.ndarray
    beta: np.ndarray
    alpha_sigma: np.ndarray
    beta_sigma: np.ndarray
    axes: tuple[AxisFit, AxisFit]


def _lstsq(A: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Least squares ``y ~ A c``; returns (c, standard errors, residuals, covariance of c)."""
    c, *_ = np.linalg.lstsq(A, y, rcond=None)
    e = y - A @ c
    dof = max(len(y) - A.shape[1], 1)
    s2 = float(e @ e) / dof
    try:
        cov = np.linalg.inv(A.T @ A) * s2
    except np.linalg.LinAlgError:
        cov = np.linalg.pinv(A.T @ A) * s2
    return c, np.sqrt(np.maximum(np.diag(cov), 0.0)), e, cov


def _slope_jackknife(dt: float, n: int, refit) -> np.ndarray | None:
    """Delete-a-block jackknife standard errors of a fit's coefficients on ``n`` time-ordered rows.

    Args:
        dt: row spacing, s (the rows of the aiding's fit are its valid segments end to end).
        n: number of rows. refit: ``keep (n,) bool -> (P,) coefficients`` fitted on the kept rows.

    Returns:
        (P,) standard errors over the :data:`SLOPE_JACKKNIFE_S`-second blocks (Kuensch 1989;
        :func:`gcs_sysid.jackknife.block_jackknife_vars`), or None with fewer than 3 blocks or a failed refit.
    """
    try:
        v = block_jackknife_vars(np.arange(n) * dt, refit, SLOPE_JACKKNIFE_S)
    except (np.linalg.LinAlgError, ValueError):
        return None
    return None if v is None else np.sqrt(v)


def _block_mean_var(e: np.ndarray, segs: list[slice], n: int) -> float:
    """Variance of the mean of ``e`` (T,) over ``segs`` from the scatter of means of blocks of ``n`` samples
    (the residuals are correlated: gusts); ``inf`` with fewer than 3 blocks."""
    means = [float(e[s][i:i + n].mean()) for s in segs for i in range(0, s.stop - s.start - n + 1, n)]
    return float(np.var(means, ddof=1)) / len(means) if len(means) >= 3 else float("inf")


def _moment_rss(angle: np.ndarray, X_other: np.ndarray, moments: list[np.ndarray], m: np.ndarray) -> float:
    """Residual variance of the linear moment model(s) ``[1, angle, X_other]`` on ``m``, as a share of each
    moment coefficient's variance, averaged over ``moments`` (each (T,))."""
    A = np.column_stack([np.ones(m.sum()), angle[m], X_other[m]])
    out = []
    for M in moments:
        y = M[m]
        c, *_ = np.linalg.lstsq(A, y, rcond=None)
        out.append(float(np.var(y - A @ c)) / max(float(np.var(y)), 1e-300))
    return float(np.mean(out))


def _moment_check(dt: float, kin: np.ndarray, ang: np.ndarray, X_other: np.ndarray, moments: list[np.ndarray],
                  m: np.ndarray, block_s: float = MOMENT_BLOCK_S) -> tuple[float, float, float, float]:
    """The moment cross-check: the residual shares of the two angles' moment fits and, where the aided one's is
    the larger, which angle the moments follow (:func:`moment_lambda`).

    The difference of the residual shares has little power: on a 120-s flight with a slow force error that makes
    the aided alpha three times worse than the kinematic one it is one block-jackknife standard error; on the JSBSim
    gliders, whose moments the linear model explains poorly (40-70 % residual), it tips either way by chance.

    Args:
        dt: grid step, s. kin, ang: (T,) the kinematic and the aided angle, rad.
        X_other: (T, K) the moment model's other regressors. moments: list of (T,) moment coefficients.
        m: (T,) bool rows of the check. block_s: block length of the jackknife, s.

    Returns:
        (rk, ra, lam, se): the kinematic and the aided residual shares (:func:`_moment_rss`), and ``lambda`` with
        its standard error (NaN when ``ra <= rk``, where they are not needed).
    """
    rk, ra = _moment_rss(kin, X_other, moments, m), _moment_rss(ang, X_other, moments, m)
    if not ra > rk:
        return rk, ra, float("nan"), float("nan")
    return (rk, ra) + moment_lambda(dt, kin, ang, X_other, moments, m, block_s)


def moment_lambda(dt: float, kin: np.ndarray, ang: np.ndarray, X_other: np.ndarray, moments: list[np.ndarray],
                  m: np.ndarray, block_s: float = MOMENT_BLOCK_S) -> tuple[float, float]:
    """Which of two estimates of an air angle the gyro-measured moments follow, with a block-jackknife error.

    An encompassing regression (Davidson and MacKinnon, *Econometric Theory and Methods*, 2004, sec. 15.3): each
    moment coefficient, scaled by its standard deviation, on ``[1, kin, g, X_other]`` with ``g = ang - kin``. If the
    moments depend on the angle ``kin + lambda g``, the coefficients are ``b_kin = C`` and ``b_g = lambda C``;
    pooled over the moments, ``lambda = sum b_g b_kin / sum b_kin^2``. With angle errors independent of each other
    and of the regressors, ``lambda`` tends to ``var(e_kin) / (var(e_kin) + var(e_ang))``: 1 where ``ang`` is exact,
    0 where ``kin`` is, below 0.5 where ``kin`` is the closer. Its standard error is the delete-a-block jackknife
    over ``block_s`` blocks of the rows ``m`` (:func:`gcs_sysid.jackknife.block_jackknife_var`; Kuensch 1989),
    each leave-one-out fit from the blocks' normal equations. Moments that barely depend on the angle
    (``C ~ 0``) give a wide ``lambda``: no evidence either way.

    Args:
        dt: grid step, s. kin, ang: (T,) the two angle estimates, rad (the kinematic and the aided one).
        X_other: (T, K) the moment model's other regressors. moments: list of (T,) moment coefficients.
        m: (T,) bool rows. block_s: block length, s.

    Returns:
        (lambda, se); se NaN with fewer than 3 blocks of 50 rows, both NaN for a singular fit.
    """
    from ..jackknife import block_jackknife_var, block_labels

    nan = float("nan")
    idx = np.nonzero(m)[0]
    t = idx * dt
    k, labels = block_labels(t, block_s)
    if len(labels) < 3:
        k = np.zeros(idx.size, int)
    Y = np.column_stack([Mo[m] for Mo in moments])
    Y = (Y - Y.mean(axis=0)) / np.maximum(Y.std(axis=0), 1e-300)
    A = np.column_stack([np.ones(idx.size), kin[m], (ang - kin)[m], X_other[m]])
    nb = int(k.max()) + 1 if idx.size else 0
    G_b = np.zeros((nb, A.shape[1], A.shape[1]))
    g_b = np.zeros((nb, A.shape[1], Y.shape[1]))
    for b in range(nb):
        r = k == b
        G_b[b], g_b[b] = A[r].T @ A[r], A[r].T @ Y[r]
    G, g = G_b.sum(axis=0), g_b.sum(axis=0)

    def lam(keep: np.ndarray) -> float:
        drop = np.unique(k[~np.ravel(keep)])
        try:
            c = np.linalg.solve(G - G_b[drop].sum(axis=0), g - g_b[drop].sum(axis=0))
        except np.linalg.LinAlgError:
            return nan
        return float(np.sum(c[2] * c[1]) / max(float(np.sum(c[1] ** 2)), 1e-300))

    whole = lam(np.ones(idx.size, bool))
    if len(labels) < 3:
        return whole, nan
    v = block_jackknife_var(t, lam, block_s)
    return whole, float(np.sqrt(v)) if np.isfinite(v) else nan


def lift_level(dt: float, alpha: np.ndarray, CX: np.ndarray, CZ: np.ndarray, q_hat: np.ndarray,
               delta_e: np.ndarray, m: np.ndarray, CL0: float, CL_alpha: float, CL_q: float = 0.0,
               CL_delta_e: float = 0.0, CL0_sigma: float = STATED_CL0_SIGMA) -> tuple[float, float]:
    """The true alpha's flight mean against ``alpha``'s, from a stated lift line (:data:`STATED_LIFT_LEVEL`).

    The lift measured by the accelerometers, ``CL = -CZ cos(alpha) + CX sin(alpha)`` (wind axes; thrust along body x
    enters through ``sin(alpha)`` only), obeys the stated line ``CL = CL0 + CL_alpha alpha + CL_q q_hat + CL_delta_e
    delta_e`` at every sample whatever the wind; its flight mean therefore fixes the true angle's flight mean, which
    kinematics cannot (the flight-mean vertical wind goes into the fitted ``CZ0``; Jategaonkar 2015, flight path
    reconstruction, ch. 10: a constant air-data offset is observable only against a stated reference; Morelli
    and Klein 2016 ch. 10, the angle-of-attack bias of data compatibility analysis). The drag is in the rotation; the
    lift line's curvature is left out: on the JSBSim roster's light flights (alpha within a few degrees of trim) it
    moves the line's level by 0.00-0.06 deg (j3cub the largest).

    Args:
        dt: grid step, s.
        alpha: (T,) the angle whose mean is checked (the aided alpha), rad; the rotation to wind axes uses it.
        CX, CZ: (T,) body-axis force coefficients from the specific force, ``m f / (qbar S)``.
        q_hat: (T,) ``q c / (2 V)``. delta_e: (T,) elevator, rad.
        m: (T,) bool, the rows to average (finite everywhere there).
        CL0: stated lift at zero alpha, pitch rate and elevator. CL_alpha: stated lift slope, 1/rad (> 0).
        CL_q, CL_delta_e: stated lift per ``q_hat`` and per radian of elevator.
        CL0_sigma: stated 1-sigma of the line's level, in CL.

    Returns:
        ``(offset, sigma)``, rad: the line's mean alpha minus ``alpha``'s over ``m`` (add it to move ``alpha`` onto
        the line), and its 1-sigma: ``CL0_sigma / CL_alpha`` and the per-sample lift's block standard error
        (:data:`LEVEL_BLOCK_S` blocks) in quadrature. ``(nan, nan)`` if ``m`` has fewer than two blocks of rows.

    Raises:
        ValueError: if ``CL_alpha`` is not positive or ``CL0_sigma`` is negative.
    """
    if not CL_alpha > 0 or not CL0_sigma >= 0:
        raise ValueError(f"lift_level needs CL_alpha > 0 and CL0_sigma >= 0, got {CL_alpha!r}, {CL0_sigma!r}")
    nb = max(int(round(LEVEL_BLOCK_S / dt)), 1)
    if int(m.sum()) < 2 * nb:
        return float("nan"), float("nan")
    a = alpha[m]
    CL = -CZ[m] * np.cos(a) + CX[m] * np.sin(a)
    e = (CL - CL0 - CL_q * q_hat[m] - CL_delta_e * delta_e[m]) / CL_alpha - a
    var = _block_mean_var(e, [slice(0, len(e))], nb)
    return float(np.mean(e)), float(np.sqrt((CL0_sigma / CL_alpha) ** 2 + var))


def _highpass(dt: float, X: np.ndarray, segs: list[slice], edge_hz: float | None = None) -> np.ndarray:
    """Zero-phase second-order Butterworth high-pass at ``edge_hz`` (None: :data:`HIGHPASS_HZ`) of the
    columns of ``X`` (T, P) on each segment (NaN elsewhere)."""
    edge = HIGHPASS_HZ if edge_hz is None else float(edge_hz)
    sos = butter(2, edge, btype="highpass", fs=1.0 / dt, output="sos")
    out = np.full(X.shape, np.nan)
    for sg in segs:
        out[sg] = sosfiltfilt(sos, X[sg] - X[sg].mean(axis=0), axis=0, padtype="odd",
                              padlen=min(3 * int(1.0 / (edge * dt)), sg.stop - sg.start - 1))
    return out


def lift_slope(aspect_ratio: float) -> float:
    """The finite wing's lift-curve slope, 1/rad: Helmbold's formula for an unswept wing,
    ``2 pi A / (2 + sqrt(A^2 + 4))`` (USAF DATCOM sec. 4.1.3.2 with no sweep, section slope ``2 pi``, Mach 0;
    Anderson, *Fundamentals of Aerodynamics*, 5th ed., 2011, sec. 5.3). 4.9 for ``A`` = 8 (the rascal), 3.6 for 3.3
    (the f16). Used only for the heave mode's corner (:func:`heave_edge_hz`), where a 20 % error moves the edge
    by 20 %. NaN for a non-positive or non-finite ``A``."""
    if not np.isfinite(aspect_ratio) or aspect_ratio <= 0:
        return float("nan")
    return float(2.0 * np.pi * aspect_ratio / (2.0 + np.sqrt(aspect_ratio**2 + 4.0)))


def gust_share(dt: float, alpha_kin: np.ndarray, use: np.ndarray, beta_fit: AxisFit, edge_hz: float) -> float:
    """The share of the kinematic alpha's variance above ``edge_hz`` that the turbulence found on the lateral axis
    predicts as its gust error: the witness of :data:`SLOPE_FLOOR`.

    Errors in variables attenuate ``CZ_alpha`` only if the kinematic alpha has a gust error in the slopes' band. The
    beta axis (fitted first, without a floor) measures the lateral gust angle as a Gauss-Markov state (stationary
    1-sigma ``s``, correlation time ``tau``); in isotropic turbulence (MIL-F-8785C above 2000 ft: ``sigma_w =
    sigma_v``) the vertical gust angle has the same spectrum, whose share above the edge is ``1 - (2 / pi) atan(2 pi
    f tau)`` (first-order spectrum). Returns ``share x s^2 / var(highpassed kinematic alpha)``: 0.1 means the gust
    error alone would attenuate a least-squares slope by about 10 %. Measured on the JSBSim tuning flights in
    MIL-F-8785C light and moderate turbulence 0.16-3.8 (f16 0.16-0.18, t6 0.27-0.31, rascal and sgs126 1.0-3.8); on
    the project's kinematic synthetic flight (tests/estimation/test_estimation_states.py: no gust, CZ unrelated to
    alpha) beta is not aided and the share is 0.

    Args:
        dt: grid step, s. alpha_kin: (T,) kinematic alpha, rad. use: (T,) bool rows. beta_fit: the beta axis's
        :class:`AxisFit`. edge_hz: the alpha slopes' band edge, Hz.

    Returns:
        The share (dimensionless, >= 0); 0 where beta was not aided or the record is too short.
    """
    if not beta_fit.used or not np.isfinite(beta_fit.gust_sigma) or not np.isfinite(beta_fit.tau_s):
        return 0.0
    ok = np.asarray(use, bool) & np.isfinite(alpha_kin)
    segs = segments(ok, max(int(round(MIN_SEGMENT_S / dt)), 10))
    if sum(s.stop - s.start for s in segs) * dt < MIN_VALID_S:
        return 0.0
    ah = _highpass(dt, np.asarray(alpha_kin, float)[:, None], segs, edge_hz)[:, 0]
    va = float(np.nanvar(ah))
    frac = 1.0 - 2.0 / np.pi * np.arctan(2.0 * np.pi * edge_hz * beta_fit.tau_s)
    return float(frac * beta_fit.gust_sigma**2 / va) if va > 0 else 0.0


def heave_edge_hz(slope: float, heave_gain: float, factor: float | None = None) -> float:
    """The band edge above which the alpha model's slopes are fitted: ``max(HIGHPASS_HZ, factor x f_heave)``.

    The heave (plunge) mode of an aircraft hit by a vertical gust is first order with the rate
    ``|Z_w| = qbar S |CZ_alpha| / (m V)`` (Etkin, *Dynamics of Atmospheric Flight*, 1972, sec. 13.6, the
    response to a vertical gust; the CD term neglected). Below its corner ``f_heave = |Z_w| / (2 pi)`` the
    aircraft rides the gust: the true alpha barely moves, while the kinematic alpha (the inertial angle)
    takes the whole gust with the opposite sign, so in that band its error is correlated with the
    kinematic alpha itself, and least squares on it attenuates ``CZ_alpha`` and hands the rest to the
    correlated columns (``q_hat``). Above the corner the gust is an uncorrelated error with a falling
    spectrum. 0.3-0.4 Hz for the light aircraft at 50 m/s, 0.1-0.25 Hz for the fast and heavy ones, 1.3 Hz
    for the 6.6-kg rascal at 21 m/s.

    The slope is the wing's, from its aspect ratio (:func:`lift_slope`), not the flight's fitted ``CZ_alpha``:
    that is the attenuated one (on the rascal -2.3..-2.7 in light and -1.0..-1.1 per rad in moderate turbulence
    against JSBSim's -5.0), and an edge set from it stays below the corner.

    Args:
        slope: the lift-curve slope, 1/rad (its magnitude is used). heave_gain: ``qbar S / (m V)``, 1/s (the
            flight's median). factor: multiple of ``f_heave`` (None: :data:`HEAVE_EDGE`; None there too: the
            fixed edge).

    Returns:
        The edge, Hz, in ``[HIGHPASS_HZ, max(HIGHPASS_HZ, MAX_EDGE_HZ)]``.
    """
    k = HEAVE_EDGE if factor is None else factor
    if k is None or not np.isfinite(slope) or not np.isfinite(heave_gain) or heave_gain <= 0:
        return HIGHPASS_HZ
    f_h = k * abs(slope) * heave_gain / (2.0 * np.pi)
    return float(min(max(HIGHPASS_HZ, f_h), max(HIGHPASS_HZ, MAX_EDGE_HZ)))


def _gm_steady_state(dt: float, tau: float, ratio: float) -> tuple[float, float, float]:
    """The scalar steady-state Kalman filter of ``z = g + v`` (``g`` first-order Gauss-Markov with correlation time
    ``tau`` s, ``var(g) / var(v)`` = ``ratio``, ``var(v)`` = 1); returns ``(phi, K, S)``: the transition, the gain and
    the innovation variance. Closed form: ``Pp^2 + Pp ((1 - phi^2) - q) - q = 0`` with ``q = ratio (1 - phi^2)``."""
    phi = float(np.exp(-dt / tau))
    q = ratio * (1.0 - phi * phi)
    h = (1.0 - phi * phi) - q
    Pp = 0.5 * (-h + np.sqrt(h * h + 4.0 * q))
    return phi, Pp / (Pp + 1.0), Pp + 1.0


def _gm_innovations(z: np.ndarray, phi: float, K: float) -> np.ndarray:
    """The steady-state filter's innovations of ``z`` (N,) or of each column of ``z`` (N, P), from ``x_{-1} = 0``:
    ``x_k = (1 - K) phi x_{k-1} + K z_k``, ``e_k = z_k - phi x_{k-1}`` (a fixed linear filter of ``z``)."""
    x = lfilter([K], [1.0, -(1.0 - K) * phi], z, axis=0)
    e = np.array(z, dtype=float, copy=True)
    e[1:] -= phi * x[:-1]
    return e


def _gm_search(dt: float, z: np.ndarray, segs: list[slice], taus: tuple[float, ...],
               ratios: tuple[float, ...]) -> tuple[float, float, float, float]:
    """The Gauss-Markov gust model's concentrated log-likelihood of ``z = g + v`` (T,), maximised over ``taus`` x
    ``ratios`` (the noise scale profiled out; Harvey 1989 ch. 3). Returns ``(loglik, tau_s, ratio, s2)``."""
    best = None
    n = sum(s.stop - s.start for s in segs)
    for tau in taus:
        for ratio in ratios:
            phi, K, S = _gm_steady_state(dt, tau, ratio)
            ssq = 0.0
            for sg in segs:
                e = _gm_innovations(z[sg], phi, K)
                ssq += float(np.square(e).sum()) / S     # not e @ e: a BLAS call per candidate
            ll = -0.5 * n * (np.log(max(ssq / n, 1e-300)) + np.log(S))
            if best is None or ll > best[0]:
                best = (ll, tau, ratio, ssq / n)
    return best


def _gust_smoother(dt: float, z: np.ndarray, segs: list[slice], taus: tuple[float, ...],
                   ratios: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray, float, float, float]:
    """Smooth ``z = g + v`` (g first-order Gauss-Markov, v white) on each segment.

    Returns ``(g_smoothed (T,), g_sigma (T,), tau_s, gust_sigma, noise_sigma)``; NaN outside the
    segments. The model's two ratios are chosen by the concentrated likelihood (scale profiled out).
    """
    H, R = np.eye(1), np.eye(1)
    _, tau, ratio, s2 = _gm_search(dt, z, segs, taus, ratios)
    phi = float(np.exp(-dt / tau))
    F = np.array([[phi]])
    g = steady_state(F, np.array([[ratio * (1.0 - phi * phi)]]), H, R)
    out = np.full(len(z), np.nan)
    sig = np.full(len(z), np.nan)
    for sg in segs:
        xs, _ = steady_state_smoother(F, g, H, z[sg, None], np.zeros(1))
        out[sg] = xs[:, 0]
        sig[sg] = np.sqrt(g.Ps[0, 0] * s2)
    return out, sig, tau, float(np.sqrt(ratio * s2)), float(np.sqrt(s2))


def _gls_gust_fit(dt: float, A: np.ndarray, y: np.ndarray, segs: list[slice], taus: tuple[float, ...],
                  ratios: tuple[float, ...]
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float, float, np.ndarray, np.ndarray]:
    """Linear regression whose error is a first-order Gauss-Markov gust plus white noise, by maximum likelihood.

    Model: ``y = A c + e``, ``e_k = g_k + v_k``, ``g_{k+1} = phi g_k + w_k`` (``phi = exp(-dt / tau)``), ``v`` white,
    ``var(g) / var(v)`` the ratio. For each ``(tau, ratio)`` on the grid the steady-state Kalman filter of ``e`` is a
    fixed linear filter (``x_k = (1 - K) phi x_{k-1} + K z_k``, innovation ``z_k - phi x_{k-1}``, as
    :func:`_gm_search`); applied to ``y`` and to every column of ``A`` on each segment, it whitens the error, and least
    squares on the filtered data is the generalised least-squares estimate (a regression with ARMA(1, 1) errors:
    Harvey, *Forecasting, Structural Time Series Models and the Kalman Filter*, CUP 1989, sec. 3.4 and 7.2; the
    filter-error method's output equation with the turbulence as process noise, Jategaonkar 2015 ch. 5). The grid
    point with the largest concentrated log-likelihood is taken. A regressor that answers the gust only through the
    aircraft's dynamics (the rates, an autopilot's rudder) depends on the gust's past innovations, not on the
    current one, so it no longer takes the gust's side force as it does under least squares on the levels.

    Args:
        dt: grid step, s. A: (T, P) columns (NaN outside ``segs``). y: (T,) coefficient. segs: the rows to fit, as
        contiguous slices. taus: gust correlation times, s. ratios: gust / white variance ratios.

    Returns:
        ``(c (P,), se (P,), residual (N,) of the unfiltered rows, cov (P, P), tau_s, ratio, Wa (N, P), wy (N,))``;
        the residual is ``y - A c`` on the segments' rows, in their order; ``Wa``, ``wy`` the filtered columns and
        coefficient at the chosen grid point (for a jackknife at that point).

    Singular filtered columns (not expected: the caller leaves constant columns out) give least squares' minimum-norm
    solution and a pseudo-inverse covariance; nothing is raised.
    """
    rows = np.concatenate([np.arange(s.start, s.stop) for s in segs])
    best = None
    for tau in taus:
        for ratio in ratios:
            phi, K, _ = _gm_steady_state(dt, tau, ratio)
            W = np.vstack([_gm_innovations(np.column_stack([A[sg], y[sg]]), phi, K) for sg in segs])
            c, *_ = np.linalg.lstsq(W[:, :-1], W[:, -1], rcond=None)
            r = W[:, -1] - W[:, :-1] @ c
            n = len(r)
            s2 = float(r @ r) / n
            # innovations of variance sigma^2 S each: with sigma^2 profiled out the log-likelihood is -n/2 log(s2)
            ll = -0.5 * n * np.log(max(s2, 1e-300))
            if best is None or ll > best[0]:
                best = (ll, tau, ratio, c, W, s2)
    _, tau, ratio, c, W, s2 = best
    Wa = W[:, :-1]
    try:
        cov = np.linalg.inv(Wa.T @ Wa) * s2
    except np.linalg.LinAlgError:
        cov = np.linalg.pinv(Wa.T @ Wa) * s2
    se = np.sqrt(np.maximum(np.diag(cov), 0.0))
    return c, se, y[rows] - A[rows] @ c, cov, float(tau), float(ratio), Wa, W[:, -1]


def _floor_refit(A: np.ndarray, y: np.ndarray, a1: float, keep: list[int], held: dict[int, float] | None = None
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Least squares ``y ~ A c`` with ``c[0]`` held at ``a1``, the columns ``held`` (index -> slope) held at their
    slopes, and only the columns ``keep`` (indices into ``A``, not 0) refitted; the others are 0.

    Args:
        A: (N, P) band-passed regressors, the angle first. y: (N,) band-passed coefficient.
        a1: the held slope of column 0. keep: the columns fitted. held: other held columns (None: none); a column
        both held and in ``keep`` is held.

    Returns:
        ``(c (P,), standard errors (P,) (NaN for the held and dropped ones), residuals (N,), covariance (P, P))``.
    """
    P = A.shape[1]
    c, se, cov = np.zeros(P), np.full(P, np.nan), np.zeros((P, P))
    c[0] = a1
    for j, v in (held or {}).items():
        c[j] = v
    keep = [j for j in keep if j not in (held or {})]
    if keep:
        co, so, _, cv = _lstsq(A[:, keep], y - A @ c)
        c[keep], se[keep] = co, so
        cov[np.ix_(keep, keep)] = cv
    return c, se, y - A @ c, cov


def _profile_columns(dt: float, Ahm: np.ndarray, yhm: np.ndarray, A: np.ndarray, coeff: np.ndarray, kin: np.ndarray,
                     ang: np.ndarray, m: np.ndarray, segs: list[slice], cr: np.ndarray, free: list[int],
                     prof: list[int], quadratic: bool, ctr: float, sign: float, taus: tuple[float, ...],
                     ratios: tuple[float, ...]) -> tuple[np.ndarray, list[tuple[float, float]]]:
    """The slopes of the columns ``prof`` chosen by the gust model's likelihood (:data:`ALPHA_PROFILE_COLUMNS`).

    Least squares on the kinematic angle gives a column the part of the gust's force that correlates with it (errors
    in variables; in closed loop the stabilising autopilot moves the elevator against the gust's pitch, so
    ``CZ_delta_e`` takes the gust's normal force). The aiding's own model says what the gust is: a first-order
    Gauss-Markov state ``g`` seen as ``z = angle_f - angle_kin = g + v`` (v white). A wrong slope ``d`` leaves
    ``(d_true - d) x / CZ_alpha`` in ``z``, shaped like the regressor ``x`` (the elevator's steps and doublets), not
    like the gust. So ``d`` is chosen by the concentrated likelihood of ``z`` under the gust model (maximised over the
    correlation time and the variance ratio, :func:`_gm_search`), the other free columns refitted by least squares for
    each ``d`` (a profile likelihood): the filter-error method's parameter estimate with the gust as process noise
    (Jategaonkar, *Flight Vehicle System Identification*, 2nd ed., 2015, ch. 5; Maine and Iliff, NASA RP-1168, 1986,
    ch. 6-7, process noise and the output-error/filter-error likelihood), restricted to the columns least squares cannot
    separate from the gust. Searched (bounded Brent, scipy ``minimize_scalar``) within :data:`PROFILE_HALF_WIDTH` of
    the least-squares value.

    Args:
        dt: grid step, s. Ahm: (N, P) band-passed columns on the aided rows (the angle first). yhm: (N,) band-passed
        coefficient. A: (T, P) the columns. coeff: (T,) measured coefficient. kin, ang: (T,) kinematic and current
        angle, rad. m: (T,) bool aided rows. segs: their segments. cr: (P,) the least-squares slopes. free: columns
        refitted with each candidate (the held slope of a floored pass excluded). prof: the profiled columns (indices
        into ``A``). quadratic: column 1 is the curvature (the local slope then moves with the angle). ctr: the
        curvature's centre, rad. sign: the angle slope's expected sign. taus, ratios: the gust model's grid.

    Returns:
        ``(slopes (P,), [(least squares, chosen) per profiled column])``.
    """
    from scipy.optimize import minimize_scalar

    cr = np.asarray(cr, float).copy()
    moved = []
    for j in prof:
        others = [i for i in free if i != j]

        def refit(d: float, j: int = j, others: list[int] = others) -> np.ndarray:
            c = cr.copy()
            c[j] = d
            if others:
                held = [i for i in range(len(c)) if i not in others]
                c[others] = np.linalg.lstsq(Ahm[:, others], yhm - Ahm[:, held] @ c[held], rcond=None)[0]
            return c

        def nll(d: float) -> float:
            c = refit(d)
            model = float(np.mean(coeff[m] - A[m] @ c)) + A[m] @ c
            slope = np.full(int(m.sum()), c[0])
            if quadratic:
                slope = sign * np.maximum(sign * (slope + 2.0 * c[1] * (ang[m] - ctr)), 0.5 * abs(c[0]))
            if not sign * c[0] > 0:
                return np.inf
            z = np.full(len(kin), np.nan)
            z[m] = ang[m] + (coeff[m] - model) / slope - kin[m]
            return -_gm_search(dt, z, segs, taus, ratios)[0]

        b = float(cr[j])
        r = minimize_scalar(nll, bounds=(b - PROFILE_HALF_WIDTH, b + PROFILE_HALF_WIDTH), method="bounded",
                            options={"xatol": 0.005})
        d = float(r.x) if np.isfinite(r.fun) else b
        cr = refit(d)
        moved.append((b, d))
    return cr, moved


def _angle_profile_objective(dt: float, Ahm: np.ndarray, yhm: np.ndarray, A: np.ndarray, coeff: np.ndarray,
                             kin: np.ndarray, ang: np.ndarray, m: np.ndarray, segs: list[slice], cr: np.ndarray,
                             taus: tuple[float, ...], ratios: tuple[float, ...], edge_hz: float | None = -1.0):
    """The profile of :func:`_profile_angle_slope`: the other slopes for a candidate angle slope, and the
    coefficient's negative log-likelihood under the gust model there (the arguments are that function's).

    Returns:
        ``(refit, nll)``: ``refit(d)`` the slopes ``(P,)`` with the angle's at ``d`` and the others refitted by least
        squares on the band-passed rows; ``nll(d)`` the negative concentrated log-likelihood of ``z = g + e / d``
        under the Gauss-Markov gust model (:func:`_gm_search`) plus the Jacobian ``N log|d|``, ``z`` high-passed at
        ``edge_hz`` (None: the full band; negative: :data:`BETA_PROFILE_EDGE_HZ`).
    """
    cr = np.asarray(cr, float).copy()
    n = int(m.sum())
    edge_hz = BETA_PROFILE_EDGE_HZ if edge_hz is not None and edge_hz < 0 else edge_hz

    def refit(d: float) -> np.ndarray:
        c = cr.copy()
        c[0] = d
        if Ahm.shape[1] > 1:
            c[1:] = np.linalg.lstsq(Ahm[:, 1:], yhm - d * Ahm[:, 0], rcond=None)[0]
        return c

    def nll(d: float) -> float:
        c = refit(d)
        model = float(np.mean(coeff[m] - A[m] @ c)) + A[m] @ c
        z = np.full(len(kin), np.nan)
        z[m] = ang[m] + (coeff[m] - model) / d - kin[m]
        if edge_hz is not None:
            z = _highpass(dt, z[:, None], segs, edge_hz)[:, 0]
        return -(_gm_search(dt, z, segs, taus, ratios)[0] - n * np.log(abs(d)))

    return refit, nll


def _profile_angle_slope(dt: float, Ahm: np.ndarray, yhm: np.ndarray, A: np.ndarray, coeff: np.ndarray,
                         kin: np.ndarray, ang: np.ndarray, m: np.ndarray, segs: list[slice], cr: np.ndarray,
                         sign: float, taus: tuple[float, ...], ratios: tuple[float, ...],
                         search: tuple[float, float] | None = None,
                         edge_hz: float | None = -1.0, min_lr: float | None = None) -> tuple[np.ndarray, float]:
    """The angle's own slope (column 0, no curvature column) by the gust model's likelihood of the coefficient.

    The aiding's model is ``C = c0 + a (angle_kin + g) + X_other c_other + e`` with ``g`` a first-order
    Gauss-Markov gust angle and ``e`` white. For a candidate slope ``a`` (the other columns refitted by least squares
    on the band-passed rows, a profile) the force-derived departure ``z = (C - c0 - a angle - X_other c_other) / a +
    angle - angle_kin`` is ``g + e / a``, and the coefficient's log-likelihood is that of ``z`` under the gust model
    (:func:`_gm_search`: the correlation time and the variance ratio maximised, the scale profiled out) plus the change
    of variables' Jacobian ``-N log|a|`` (``z`` scales as ``1 / a``: without it a flatter slope always looks likelier).
    This is the filter-error method's estimate of the slope with the turbulence as process noise (Jategaonkar,
    *Flight Vehicle System Identification*, 2nd ed., 2015, ch. 5 and 7; Maine and Iliff, NASA RP-1168, 1986, ch. 6-7).
    Least squares instead reads the gust's sideslip wherever it correlates with the kinematic one: on the JSBSim
    flights that correlation is positive above the directional mode, so least squares above 0.3 Hz makes ``CY_beta``
    steep (s23 15-18 %), and negative below it (attenuated): no band edge is right on every aircraft, while the
    likelihood uses the whole record. ``z`` is high-passed at ``edge_hz`` first (the wind estimate's slow drift is no
    first-order gust). An optimum at either end of the search (the likelihood monotone: not identified) keeps least
    squares' slopes.

    Args:
        dt: grid step, s. Ahm: (N, P) band-passed columns on the aided rows (the angle first). yhm: (N,)
        band-passed coefficient. A: (T, P) the columns. coeff: (T,) measured coefficient. kin, ang: (T,) kinematic
        and current angle, rad. m: (T,) bool aided rows (N of them). segs: their segments. cr: (P,) least squares'
        slopes. sign: the slope's expected sign. taus, ratios: the gust model's grid. search: the slope is searched
        (bounded Brent, scipy ``minimize_scalar``) between these multiples of least squares' slope (None:
        :data:`BETA_PROFILE_RANGE`). edge_hz: ``z``'s high-pass edge, Hz (None: the full band; negative:
        :data:`BETA_PROFILE_EDGE_HZ`). min_lr: least squares' slopes are kept unless the likelihood-ratio statistic
        ``2 (nll(least squares) - nll(profiled))`` reaches it (None: no test; :data:`BETA_PROFILE_MIN_LR`).

    Returns:
        ``(slopes (P,), least squares' angle slope)``; least squares' slopes unchanged if its slope has the wrong sign.
    """
    from scipy.optimize import minimize_scalar

    cr = np.asarray(cr, float).copy()
    b = float(cr[0])
    if not sign * b > 0:
        return cr, b
    search = BETA_PROFILE_RANGE if search is None else search
    refit, nll = _angle_profile_objective(dt, Ahm, yhm, A, coeff, kin, ang, m, segs, cr, taus, ratios, edge_hz)
    lo, hi = sorted((search[0] * b, search[1] * b))
    r = minimize_scalar(nll, bounds=(lo, hi), method="bounded", options={"xatol": 1e-3 * abs(b)})
    d = float(r.x)
    if not np.isfinite(r.fun) or min(d - lo, hi - d) < 0.01 * (hi - lo):
        return cr, b
    if min_lr is not None and not 2.0 * (nll(b) - float(r.fun)) >= min_lr:
        return cr, b         # the likelihood does not prefer the profiled slope significantly: least squares'
    return refit(d), b


def _axis(name: str, dt: float, kin: np.ndarray, coeff: np.ndarray, others: dict[str, np.ndarray],
          use: np.ndarray, passes: int, sign: float, quadratic: bool, symmetric: bool,
          moments: list[np.ndarray] | None = None, instruments: np.ndarray | None = None,
          V: np.ndarray | None = None, given: AxisFit | None = None, band_hz: float | None = None,
          slope_floor: float | None = None, floor_held: dict[str, float] | None = None, endog: tuple[str, ...] = (),
          min_first_stage: float = MIN_FIRST_STAGE_R2, weak_test: str | None = None, profile: bool = False,
          gls: bool = False, profile_columns: tuple[str, ...] | None = None) -> tuple[np.ndarray, np.ndarray, AxisFit]:
    """Aid one angle; ``coeff`` is the measured CZ (alpha) or CY (beta), ``sign`` the expected sign
    of its slope (both negative), ``quadratic`` adds ``(angle - mean)^2`` to the model (CZ: lift
    curvature; measured on the SGS 2-33, where a linear CZ(alpha) leaves 0.3 deg of alpha error);
    ``symmetric`` takes the constant as ~0 (CY of a symmetric airframe) so that it measures the mean
    error of the kinematic angle (not with a varying throttle: a propeller side force); ``moments``: the
    moment coefficients that depend on this angle (Cm; Cl, Cn), for the cross-check against the kinematic
    angle (None: none); ``instruments`` (T, Q): instruments of the angle for the slopes (two-stage least
    squares, :mod:`.angleerrors`; None or too weak: ordinary least squares); ``V`` (T,) airspeed, m/s: with
    it the alpha axis gets the 1-sigma of its flight-common offset (the mean vertical wind); ``given``: another
    flight's fit of this axis whose slopes are used instead of fitting them here (the constant is still this
    flight's), when its columns are this flight's (:func:`aided_air_angles`, ``models``); ``band_hz``: the edge
    above which the slopes are fitted, Hz (at least :data:`HIGHPASS_HZ`; alpha: :func:`heave_edge_hz`), None:
    :data:`HIGHPASS_HZ`; ``slope_floor``: the least magnitude of the angle's slope in the first pass, 1/rad (alpha: the
    wing's lift slope, :data:`SLOPE_FLOOR`): a flatter or unidentified fitted slope is held there, the other columns
    refitted without :data:`FLOOR_DROPS`, and the identification check skipped for that pass; None: no floor;
    ``floor_held``: columns held at a stated slope where the floor holds (``{"q_hat": -CL_q}``,
    :data:`STATED_LIFT_SLOPE`) instead of refitted or left out (its presence also marks the floor as a stated one in the
    note); ``endog``: the other columns instrumented with the angle (beta: ``p_hat``, ``r_hat``, which answer the gust,
    :data:`INSTRUMENTED_BETA`); ``min_first_stage``: the instruments' least first-stage partial R^2, below which the
    slopes fall back to ordinary least squares; ``weak_test``: ``"f"`` tests the instruments by their first-stage F
    on the effective sample size instead (:func:`.angleerrors.first_stage_f`, at least
    :data:`BETA_MIN_FIRST_STAGE_F`; ``min_first_stage`` 0 skips the test), None: by ``min_first_stage``; ``profile``:
    the angle's slope of the first least-squares pass by the gust model's likelihood (:func:`_profile_angle_slope`; not
    with ``quadratic``, a floor, instruments or ``given``; :data:`BETA_PROFILE`); ``gls``: every slope of the first
    pass by generalised least squares under the gust model (:func:`_gls_gust_fit`, the columns high-passed at
    :data:`BETA_GLS_EDGE_HZ`), held in the later passes (not with ``quadratic``, a floor, instruments or ``given``;
    :data:`BETA_GLS`)."""
    cols = [k for k, v in others.items() if np.nanstd(v[use]) > 1e-9]
    ok = use & np.isfinite(kin) & np.isfinite(coeff)
    for k in cols:
        ok &= np.isfinite(others[k])
    if moments is not None:
        ok &= np.all([np.isfinite(M) for M in moments], axis=0)
    segs = segments(ok, max(int(round(MIN_SEGMENT_S / dt)), 10))
    n_ok = sum(s.stop - s.start for s in segs)
    if n_ok * dt < MIN_VALID_S:
        return kin, np.full(len(kin), np.nan), AxisFit(
            name, False, f"{n_ok * dt:.0f} s of usable flight with airspeed, accelerometers, rates and controls "
                         f"(needs {MIN_VALID_S:.0f} s in pieces of {MIN_SEGMENT_S:.0f} s)")
    m = np.zeros(len(kin), bool)
    for s in segs:
        m[s] = True
    kin0 = kin
    ang = kin.copy()
    sig = np.full(len(kin), np.nan)
    shift_note = ""
    names = ("1", name) + ((f"({name} - {name}0)^2",) if quadratic else ()) + tuple(cols)
    fixed, given_note = None, ""
    if given is not None and given.used:
        if tuple(given.columns) == names and len(given.coef) == len(names) and np.isfinite(given.coef[1:]).all():
            fixed = np.asarray(given.coef[1:], float)
            given_note = "slopes of the given model (another flight's fit of the same aircraft), constant fitted here"
        else:
            given_note = (f"the given model's terms ({', '.join(given.columns[1:])}) are not this flight's "
                          f"({', '.join(names[1:])}): slopes fitted here")
    nq = 2 if quadratic else 1
    fit = None
    floor_note = profile_note = ""
    gls_held = None        # BETA_GLS: the first pass's slopes, standard errors, covariance and note
    gls_note = ""
    held_slope = None      # BETA_PROFILE_HOLD: the first pass's profiled slope, kept in the later passes
    jk_first = None        # AxisFit.slope_jackknife: the first pass's block-jackknife standard errors
    keep: list[int] = []
    edge = HIGHPASS_HZ if band_hz is None else max(float(band_hz), HIGHPASS_HZ)
    ctr = float(np.mean(kin[m]))
    X_other = np.column_stack([others[k] for k in cols]) if cols else np.zeros((len(kin), 0))
    for ipass in range(passes):
        A = np.column_stack([ang] + ([(ang - ctr) ** 2] if quadratic else []) + [X_other])
        # slopes from the band above the edge (HIGHPASS_HZ, or for alpha the heave mode's corner where that is
        # higher: heave_edge_hz), where the kinematic angle is good (its gust errors are slow: the turbulence
        # scale over the airspeed; and below the heave corner the aircraft rides the gust); the constant from
        # the full band with them fixed
        Ah, yh = _highpass(dt, A, segs, edge), _highpass(dt, coeff[:, None], segs, edge)[:, 0]
        method, fs_r2 = "OLS", float("nan")
        if fixed is not None:
            cr, csr, method = fixed, np.full(len(fixed), np.nan), "given"
            res, cov_r = yh[m] - Ah[m] @ cr, np.zeros((len(fixed), len(fixed)))
        elif instruments is not None:
            # errors in variables: the kinematic angle misses the gust, and the aircraft's answer to the gust
            # correlates the two; instruments that move the angle but not the air give a consistent slope
            Zh = _highpass(dt, instruments, segs, edge)
            en = [0] + [nq + cols.index(k) for k in endog if k in cols]
            n_full = None
            if weak_test == "fuller":
                n_full = effective_n(yh[m], Ah[m][:, 0], max(int(round(WEAK_F_MAX_LAG_S / dt)), 1))
            cr, csr, res, cov_r, fs_r2 = iv_lstsq(Ah[m], yh[m], en, Zh[m], fuller_n=n_full)
            method = "2SLS" + (f" ({', '.join([name] + [k for k in endog if k in cols])} instrumented)" if len(en) > 1
                               else "")
            if n_full is not None:
                method += f" by Fuller's k-class (alpha 1, {n_full:.0f} effective samples)"
            weak, why = not fs_r2 >= min_first_stage, f"first-stage R2 {fs_r2:.2f} < {min_first_stage:g}"
            if weak_test == "fuller":
                weak = False
            if weak_test == "f" and min_first_stage > 0:
                f_st, _, n_eff = first_stage_f(Ah[m], en, Zh[m], max(int(round(WEAK_F_MAX_LAG_S / dt)), 1))
                weak = not f_st >= BETA_MIN_FIRST_STAGE_F
                why = (f"first-stage F {f_st:.1f} {'<' if weak else '>='} {BETA_MIN_FIRST_STAGE_F:g} on "
                       f"{n_eff:.0f} effective samples, R2 {fs_r2:.2f}")
                method += f" ({why})" if not weak else ""
            if weak:
                method = f"OLS (instruments too weak: {why})"
                if endog:
                    # a pass with weak instruments: least squares in every pass. The passes feed each other (each
                    # fits on the angle the last one aided), so a 2SLS pass followed by a least-squares pass keeps the
                    # first one's slope; and the aided angle that a wrong 2SLS slope gives is the one the controls
                    # then explain badly (JSBSim t6 light s2: first-stage R2 0.12, then 0.07; CY_beta -1.10 against
                    # JSBSim's -1.47 and least squares' -1.46)
                    a_ls, s_ls, refit = _axis(name, dt, kin0, coeff, others, use, passes, sign, quadratic, symmetric,
                                              moments, None, V, given, band_hz, slope_floor, floor_held)
                    ols = refit.slope_method
                    refit.slope_method = (f"{ols}; instruments too weak in pass {ipass + 1} ({why}): least squares "
                                          f"in every pass")
                    refit.first_stage_r2 = fs_r2
                    return a_ls, s_ls, refit
        if gls and fixed is None and not quadratic and slope_floor is None and method == "OLS":
            if gls_held is None:
                # the filter-error fit: all slopes on the gust model's innovations (the rates and an autopilot's
                # controls answer the gust's past, not its innovation), then held (least squares on the aided angle
                # would return the slopes that built it)
                Ag = (_highpass(dt, A, segs, BETA_GLS_EDGE_HZ) if BETA_GLS_EDGE_HZ is not None
                      else np.where(m[:, None], A - A[m].mean(axis=0), np.nan))
                yg = (_highpass(dt, coeff[:, None], segs, BETA_GLS_EDGE_HZ)[:, 0] if BETA_GLS_EDGE_HZ is not None
                      else np.where(m, coeff - coeff[m].mean(), np.nan))
                P = Ag.shape[1]
                free_g = list(range(P))
                for _attempt in range(P):          # each round holds the columns of the wrong sign at 0
                    cg_, sg0, _, cv0, tau_g, ratio_g, Wa, wy = _gls_gust_fit(dt, Ag[:, free_g], yg, segs,
                                                                            BETA_GLS_TAUS, RATIOS)
                    cg, sg_, cov_g = np.zeros(P), np.full(P, np.nan), np.zeros((P, P))
                    cg[free_g], sg_[free_g] = cg_, sg0
                    cov_g[np.ix_(free_g, free_g)] = cv0
                    wrong = [nq + cols.index(k) for k, sg_k in BETA_GLS_SIGNS.items()
                             if k in cols and nq + cols.index(k) in free_g and sg_k * cg[nq + cols.index(k)] < 0]
                    if not wrong:
                        break
                    free_g = [j for j in free_g if j not in wrong]
                if sign * cg[0] > 0 and abs(cg[0]) >= MIN_T_STAT * sg_[0]:
                    if len(free_g) == P:        # with a column held the jackknife is not stated (NaN)
                        jk_first = _slope_jackknife(dt, len(wy),
                                                    lambda k: np.linalg.lstsq(Wa[k], wy[k], rcond=None)[0])
                    gls_held = (cg, sg_, cov_g, f"GLS under the gust model (tau {tau_g:g} s, ratio {ratio_g:g})"
                                + "".join(f"; {names[j + 1]} held at 0 (wrong sign)" for j in range(P)
                                          if j not in free_g))
                else:
                    # not identified on the innovations: least squares as without the option, said in the note
                    gls, gls_note = False, (f"; GLS under the gust model not identified ({names[1]} {cg[0]:+.3g}, "
                                            f"{abs(cg[0]) / max(sg_[0], 1e-300):.1f} standard errors): least squares")
        if gls_held is not None:
            cr, csr, cov_r, method = gls_held
            res = yh[m] - Ah[m] @ cr
        elif not method.startswith(("2SLS", "given")):
            cr, csr, res, cov_r = _lstsq(Ah[m], yh[m])
            if held_slope is not None and fit is not None:
                # BETA_PROFILE_HOLD: the first pass's profiled slope kept (least squares on the aided angle is
                # circular); the other columns refitted with it held, the slope's standard error least squares'
                se0 = float(csr[0])
                cr, csr, res, cov_r = _floor_refit(Ah[m], yh[m], held_slope, list(range(1, Ah.shape[1])))
                csr[0] = se0
                method = "OLS with the first pass's profiled slope held"
        if fit is None and fixed is None and held_slope is None and gls_held is None:
            # the first pass's coefficients as a second flight would scatter them (AxisFit.slope_jackknife): the
            # later passes fit on the aided angle, so their own standard errors cannot say it
            Am, ym = Ah[m], yh[m]
            if method.startswith("2SLS"):
                Zm = Zh[m]
                jk_first = _slope_jackknife(dt, len(ym), lambda k: iv_lstsq(Am[k], ym[k], en, Zm[k],
                                                                             fuller_n=n_full)[0])
            else:
                jk_first = _slope_jackknife(dt, len(ym), lambda k: np.linalg.lstsq(Am[k], ym[k], rcond=None)[0])
        floored = False
        if slope_floor is not None and fixed is None and fit is None and not sign * cr[0] >= abs(slope_floor):
            # errors in variables only attenuate the fitted slope (the kinematic angle's gust error), and the wing's
            # own lift slope is a lower bound of the aircraft's (tail and fuselage add lift): the slope is held at
            # that floor. The pitch rate then goes too: with the slope held, the residual carries the gust the
            # kinematic angle misses, and the aircraft pitches into it, so a q_hat slope fitted here is the gust's
            # (docs/estimation.md, "The lift-slope floor")
            free, floored = float(cr[0]), True
            keep = [j for j in range(1, A.shape[1]) if (j < nq and not FLOOR_DROPS_CURVATURE)
                    or (j >= nq and cols[j - nq] not in FLOOR_DROPS)]
            hold = {nq + cols.index(k): float(v) for k, v in (floor_held or {}).items() if k in cols}
            keep = [j for j in keep if j not in hold]
            cr, csr, res, cov_r = _floor_refit(Ah[m], yh[m], sign * abs(slope_floor), keep, hold)
            jk_first = None       # a held slope: no sampling scatter of the first pass to state
            dropped = (([names[2]] if quadratic and FLOOR_DROPS_CURVATURE else [])
                       + [k for k in cols if k in FLOOR_DROPS and nq + cols.index(k) not in hold])
            whose = "the stated lift slope" if floor_held is not None else "the wing's lift slope"
            floor_note = (f"first pass with CZ_alpha held at {whose} {sign * abs(slope_floor):+.2f} "
                          f"(fitted {free:+.2f}: attenuated by the kinematic angle's gust error)"
                          + "".join(f", {names[j + 1]} held at the stated {v:+.2f}" for j, v in hold.items())
                          + (f" and {', '.join(dropped)} left out" if dropped else ""))
        if (profile and fit is None and fixed is None and not quadratic and slope_floor is None
                and method.startswith("OLS")):
            # the filter-error estimate of the angle's slope: least squares reads the gust's part of the angle that
            # correlates with the kinematic one (steep above the directional mode, flat below it)
            cr, b_ls = _profile_angle_slope(dt, Ah[m], yh[m], A, coeff, kin, ang, m, segs, cr, sign, TAUS_S, RATIOS,
                                            min_lr=BETA_PROFILE_MIN_LR)
            if cr[0] != b_ls:
                jk_first = None   # the slope is the likelihood's, not the least-squares fit the jackknife repeats
            res = yh[m] - Ah[m] @ cr      # the identification check keeps least squares' standard error
            if cr[0] != b_ls:
                profile_note = (f"; first pass {names[1] if name == 'alpha' else 'CY_beta'} by the gust model's "
                                f"likelihood {cr[0]:+.3f} (least squares {b_ls:+.3f})")
                if BETA_PROFILE_HOLD:
                    held_slope = float(cr[0])
                    profile_note += ", held in the later passes"
        cols_p = ALPHA_PROFILE_COLUMNS if profile_columns is None else profile_columns
        prof = ([names.index(k) - 1 for k in cols_p if k in names[2:]]
                if name == "alpha" and fixed is None and not method.startswith("2SLS") else [])
        if prof:
            # the columns least squares cannot separate from the gust get the slope under which the force-derived
            # angle's departure from the kinematic one is most like a Gauss-Markov gust (maximum likelihood)
            if fit is None:
                taus_p, ratios_p = TAUS_S, RATIOS
            else:
                it, ir = TAUS_S.index(fit.tau_s), RATIOS.index(fit.ratio)
                taus_p, ratios_p = TAUS_S[max(it - 1, 0):it + 2], RATIOS[max(ir - 1, 0):ir + 2]
            free_p = (keep if floored else list(range(A.shape[1]))) if PROFILE_REFIT else []
            cr, moved = _profile_columns(dt, Ah[m], yh[m], A, coeff, kin, ang, m, segs, cr, free_p, prof, quadratic,
                                         ctr, sign, taus_p, ratios_p)
            if fit is None:
                jk_first = None
            res = yh[m] - Ah[m] @ cr
            csr = csr.copy()
            csr[prof] = np.nan
            profile_note = "; by the gust model's likelihood: " + ", ".join(
                f"{names[j + 1]} {a:+.2f} (least squares {b:+.2f})" for j, (b, a) in zip(prof, moved))
        r2 = 1.0 - float(np.var(res)) / max(float(np.var(yh[m])), 1e-300)
        c0 = float(np.mean(coeff[m] - A[m] @ cr))
        c, cs = np.r_[c0, cr], np.r_[np.nan, csr]
        a1, t_stat = c[1], (abs(c[1]) / max(cs[1], 1e-300) if fixed is None and not floored else np.inf)
        if sign * a1 <= 0 or t_stat < MIN_T_STAT:
            if fit is None:
                return kin, sig, AxisFit(name, False, f"{'CZ_alpha' if name == 'alpha' else 'CY_beta'} not "
                                         f"identified from this flight ({a1:+.3g} 1/rad, {t_stat:.1f} standard "
                                         f"errors; too little {name} excitation)", names, c, cs)
            break
        # measurement linearised at the current angle (one Gauss-Newton step per pass: iterated EKF):
        # angle_f = angle + (C_meas - C_model(angle)) / C_model'(angle)
        model = c0 + A[m] @ cr
        shift = 0.0
        if symmetric and fit is None:
            # the constant CY0 = CY_beta * (mean error of the kinematic sideslip) + asymmetry; a symmetric
            # airframe's own CY0 is ~0 (prior SIGMA_CY0), the kinematic mean sideslip error ~ SIGMA_BETA_MEAN:
            # the posterior mean of that error moves the whole angle (the Gauss-Markov gust cannot). The
            # constant is itself uncertain: the slopes' errors times the regressors' means, and the gusts
            # (correlated residuals: the scatter of 5-s block means); a short record moves little.
            Am = A[m].mean(axis=0)
            var_c0 = float(Am @ cov_r @ Am) + _block_mean_var(coeff[m] - model, [slice(0, int(m.sum()))],
                                                              max(int(round(MEAN_BLOCK_S / dt)), 1))
            sb2 = SIGMA_BETA_MEAN**2
            shift = a1 * sb2 * c0 / (a1 * a1 * sb2 + SIGMA_CY0**2 + var_c0)
            shift_note = (f"sideslip mean moved by {np.degrees(shift):+.2f} deg (CY0 = {c0:+.4f} +- "
                          f"{np.sqrt(var_c0):.4f} against a symmetric airframe's ~0)")
            kin = np.where(m, kin + shift, kin)
            ang = np.where(m, ang + shift, ang)
        slope = np.full(m.sum(), a1)
        if quadratic:
            slope = slope + 2.0 * c[2] * (ang[m] - ctr)
            slope = sign * np.maximum(sign * slope, 0.5 * abs(a1))    # never flatter than half the mean slope
        z = np.full(len(kin), np.nan)
        z[m] = ang[m] + (coeff[m] - model) / slope - kin[m]     # force-derived angle minus the kinematic one
        if fit is None:
            taus, ratios = TAUS_S, RATIOS
        else:                    # later passes search only next to the first pass's choice
            it, ir = TAUS_S.index(fit.tau_s), RATIOS.index(fit.ratio)
            taus, ratios = TAUS_S[max(it - 1, 0):it + 2], RATIOS[max(ir - 1, 0):ir + 2]
        g, gs, tau, s_g, s_v = _gust_smoother(dt, z, segs, taus, ratios)
        if KINEMATIC_MEAN and name == "alpha" and np.any(m & np.isfinite(g)):
            g = g - float(np.nanmean(g[m]))    # the flight mean stays the kinematic one (KINEMATIC_MEAN)
        ang = np.where(m, kin + g, kin)
        sig = gs
        fit = AxisFit(name, True, "", names, c, cs, tau, s_g, s_v, RATIOS[int(np.argmin(np.abs(
            np.log(RATIOS) - np.log((s_g / s_v) ** 2))))], r2, shift if fit is None else fit.mean_shift,
            shift_note if fit is None else fit.shift_note, slope_method=method, first_stage_r2=fs_r2,
            band_hz=edge)
    if fit is not None:
        fit.slope_jackknife = (np.r_[np.nan, jk_first] if jk_first is not None and len(jk_first) == len(fit.coef) - 1
                               else np.full(len(fit.coef), np.nan))
    if fit is not None and given_note:
        fit.slope_method = f"{fit.slope_method}: {given_note}"
    if fit is not None and floor_note:
        fit.slope_method = f"{fit.slope_method}; {floor_note}"
    if fit is not None and profile_note:
        fit.slope_method += profile_note
    if fit is not None and gls_note:
        fit.slope_method += gls_note
    gust_sig = sig          # the gust smoother's posterior 1-sigma, before the flight-common offset is added
    if fit is not None and V is not None:
        # the flight-mean vertical wind is out of reach (a constant in alpha goes into CZ0): its 1-sigma, from
        # the vertical gusts found, is a common error of all samples (angleerrors module docstring)
        w = (V * (ang - kin0))[m]
        w = w[np.isfinite(w)]
        fit.bias_sigma = mean_wind_sigma(w, V[m][np.isfinite(V[m])], float(m.sum()) * dt)
        if np.isfinite(fit.bias_sigma):
            sig = np.sqrt(sig**2 + fit.bias_sigma**2)
    if fit is not None:
        fit.scale_sigma = _scale_disagreement(dt, ang, kin0, m)
        fit.map_columns, fit.map_cov = _map_disagreement(dt, name, ang, kin0, cols, X_other, m)
    if moments is not None and fit is not None:
        # cross-check that does not use the forces: the moments depend on the angle too (Cm_alpha; Cl_beta,
        # Cn_beta) and are measured by the gyro, not by the accelerometers the aiding used. If the aided
        # angle explains them worse than the kinematic one, the force model misled the aiding (e.g.
        # turbulence on a scale so short that the kinematic angle is poor above HIGHPASS_HZ too: the slopes
        # are then attenuated and the collinear terms take over): keep the kinematic angle.
        # a larger residual is evidence only where the moments follow the kinematic angle beyond their own
        # scatter (MOMENT_Z standard errors of lambda; the jackknife's blocks hold the gusts)
        rk, ra, lam, se = _moment_check(dt, kin0, ang, X_other, moments, m)
        fit.moment_rss, fit.moment_lambda = (rk, ra), (lam, se)
        if ra > rk and (MOMENT_Z is None or not np.isfinite(se) or lam + MOMENT_Z * se < 0.5):
            mname = "Cm" if name == "alpha" else "Cl, Cn"
            fit.used = False
            lam_note = (f"; the moments follow the kinematic one: lambda = {lam:.2f} +- {se:.2f}" if np.isfinite(se)
                        else "")
            fit.reason = (f"the aided {name} fits {mname} worse than the kinematic one (residual {100 * ra:.1f} % "
                          f"vs {100 * rk:.1f} % of the variance{lam_note}): the force model is not trusted")
            return kin0, kinematic_sigma(ang, kin0, gust_sig, m, int(round(MOMENT_WINDOW_TAUS * fit.tau_s / dt))), fit
    return ang, sig, fit


def kinematic_sigma(ang: np.ndarray, kin: np.ndarray, gust_sig: np.ndarray, m: np.ndarray,
                    window: int = 1) -> np.ndarray:
    """Per-row 1-sigma of a kinematic air angle kept where the aiding was rejected (the moment cross-check).

    The kinematic angle misses the gust angle ``g`` (the unmeasured gust over the airspeed) that the aiding
    estimated before its cross-check: ``g_hat = ang - kin``, with the Gauss-Markov smoother's posterior variance
    ``P`` (Rauch, Tung and Striebel 1965). Given the data ``g ~ N(g_hat, P)``, so the kinematic angle's mean
    squared error at a row is ``g_hat^2 + P`` (bias squared plus variance). A band centred on the kinematic
    angle needs the error's spread, not its value at the row (``g_hat^2`` is near 0 where the gust crosses
    zero and the 1.96-sigma band at its peaks covers ~100 %): the gust is taken as locally stationary,
    zero-mean with the local second moment, the centred moving mean of ``g_hat^2`` over ``window`` rows (the
    caller passes ``MOMENT_WINDOW_TAUS`` gust correlation times, a method-of-moments variance), plus ``P``. The
    part of ``g_hat`` common to the flight (its mean over the aided rows) is left out: a flight-common offset
    cancels at the flight's own regressors (as ``AxisFit.bias_sigma`` is left out of the per-row variance,
    :func:`gcs_sysid.aero.coefficients.stated_input_variance`). Before the fourteenth session such a fallback
    stated no sigma, and the GP's band carried no air-angle error there (f4n, light, seeds 1 and 3: the held-out
    alpha error 0.07-0.11 deg moved CZ by 2.5-3.7 % of its RMS against a band of 0.9-1.1 %).

    Args:
        ang: (T,) the rejected aided angle, rad. kin: (T,) the kinematic angle, rad.
        gust_sig: (T,) the gust smoother's posterior 1-sigma, rad (without the flight-common offset).
        m: (T,) bool, the aided rows.
        window: rows of the moving mean (1: ``g_hat^2`` of the row itself).

    Returns:
        (T,) 1-sigma, rad; NaN outside ``m`` or where an input is not finite.
    """
    out = np.full(len(kin), np.nan)
    g = np.where(m, np.asarray(ang, float) - np.asarray(kin, float), np.nan)
    ok = m & np.isfinite(g) & np.isfinite(gust_sig)
    if ok.any():
        g2 = np.where(ok, (g - float(np.mean(g[ok]))) ** 2, 0.0)
        w = max(int(window), 1)
        if w > 1:                      # gaps and ends: the mean over the aided rows inside the window
            k = np.ones(w)
            g2 = np.convolve(g2, k, mode="same") / np.maximum(np.convolve(ok.astype(float), k, mode="same"), 1.0)
        out[ok] = np.sqrt(g2[ok] + np.asarray(gust_sig, float)[ok] ** 2)
    return out


def _scale_disagreement(dt: float, ang: np.ndarray, kin: np.ndarray, m: np.ndarray, block_s: float = 15.0) -> float:
    """``sqrt(d^2 + se_d^2)``: the aided angle's scale against the kinematic one (:attr:`AxisFit.scale_sigma`).

    Args:
        dt: sample interval, s. ang, kin: (T,) aided and kinematic angle, rad. m: (T,) bool rows aided.

    Returns:
        dimensionless (0.05 = 5 %); NaN with too few rows or no excitation.
    """
    ok = np.asarray(m, bool) & np.isfinite(ang) & np.isfinite(kin)
    if ok.sum() < 150:
        return float("nan")
    x, y = ang[ok], (ang - kin)[ok]
    xc = x - x.mean()
    if not float(xc @ xc) > 0:
        return float("nan")
    d = float(xc @ (y - y.mean())) / float(xc @ xc)
    # delete-a-block jackknife over contiguous blocks of block_s (Kuensch 1989): the gusts are slow. The
    # shared estimator (gcs_sysid.jackknife, also the diagnosis's); its blocks start at the first aided row
    # (before the tenth session this loop's started at sample 0 of the log)
    cov = block_jackknife_cov(np.nonzero(ok)[0] * dt, np.column_stack([np.ones(x.size), x]), y, block_s)
    se = float(np.sqrt(max(cov[1, 1], 0.0))) if cov is not None and np.isfinite(cov[1, 1]) else 0.0
    return float(np.hypot(d, se))


def _map_disagreement(dt: float, name: str, ang: np.ndarray, kin: np.ndarray, cols: list[str], X_other: np.ndarray,
                      m: np.ndarray, block_s: float = 15.0) -> tuple[tuple[str, ...], np.ndarray]:
    """The aided angle's flight-common linear error along the force model's regressors (:attr:`AxisFit.map_cov`).

    The slopes ``M`` of (aided - kinematic) on the centred columns ``[angle, others]`` (least squares on the
    aided rows) and their delete-a-block jackknife covariance (:func:`gcs_sysid.jackknife.slope_second_moment`);
    :func:`_scale_disagreement` is the one-column case. Conservative where the true gust correlates with a
    column (the gust is part of the true angle and the aircraft answers it with its rates): that share
    counts as possible error too.

    Args:
        dt: sample interval, s. name: ``"alpha"`` or ``"beta"``. ang, kin: (T,) aided and kinematic angle, rad.
        cols: names of ``X_other``'s columns (T, Q). m: (T,) bool rows aided.

    Returns:
        ``(columns, (K, K) M M^T + Cov_jk)``, rad^2 per unit of the regressors; ``((), (0, 0))`` with too few
        rows or a singular fit.
    """
    ok = np.asarray(m, bool) & np.isfinite(ang) & np.isfinite(kin) & np.all(np.isfinite(X_other), axis=1)
    if ok.sum() < 150:
        return (), np.zeros((0, 0))
    A = np.column_stack([ang[ok], X_other[ok]])
    keep = A.std(axis=0) > 1e-12
    keep[0] = True
    names = tuple(n for n, k in zip((name, *cols), keep) if k)
    A = A[:, keep] - A[:, keep].mean(axis=0)
    C = slope_second_moment(np.nonzero(ok)[0] * dt, A, (ang - kin)[ok], block_s)
    return ((), np.zeros((0, 0))) if C is None else (names, C)


def aided_air_angles(dt: float, alpha_kin: np.ndarray, beta_kin: np.ndarray, V: np.ndarray, qbar: np.ndarray,
                     f_body: np.ndarray, rates: np.ndarray, controls: dict[str, np.ndarray], mass: float,
                     S: float, b: float, c: float, use: np.ndarray, passes: int = 2,
                     rate_dot: np.ndarray | None = None, inertia: np.ndarray | None = None,
                     instrument_slopes: bool | None = None, models: dict[str, AxisFit] | None = None,
                     instrument_beta: bool | None = None, beta_band_hz: float | None = None,
                     stated_slopes: tuple[float | None, float | None] | None = None,
                     profile_beta: bool | None = None, stated_level: dict[str, float | None] | None = None,
                     gls_beta: bool | None = None, alpha_profile: tuple[str, ...] | None = None) -> AidedAngles:
    """Fuse the kinematic air angles with the specific force (gust as a Gauss-Markov state).

    Args:
        dt: grid step, s.
        alpha_kin, beta_kin: (T,) kinematic angle of attack and sideslip, rad.
        V: (T,) true airspeed, m/s. qbar: (T,) dynamic pressure, Pa.
        f_body: (T, 3) specific force at the CG, body axes, m/s^2 (bias removed; white noise is fine).
        rates: (T, 3) body rates p q r, rad/s.
        controls: ``delta_e``, ``delta_a``, ``delta_r`` (rad) and optionally ``delta_t`` (0..1), each (T,);
            a missing or constant one is left out of the models; ``delta_t`` is no regressor, a varying
            one only keeps the sideslip mean (no CY0 ~ 0 prior for a powered flight).
        mass: kg. S: wing area, m^2. b: span, m. c: mean aerodynamic chord, m.
        use: (T,) bool, the airborne samples to fit and aid.
        passes: least-squares / smoother passes (the first on the kinematic angles).
        rate_dot: (T, 3) body angular accelerations p_dot q_dot r_dot, rad/s^2, and ``inertia`` (3, 3)
            the body inertia tensor, kg m^2: with both, the moment coefficients (Euler's equations)
            cross-check each aided axis (Cm for alpha; Cl, Cn for beta): an aided angle that explains
            them worse than the kinematic one is dropped (``AxisFit.moment_rss``). None: no check.
        instrument_slopes: fit the alpha model's slopes by two-stage least squares with the elevator and
            its delayed copies as instruments (errors in variables, :mod:`.angleerrors`), falling back to
            least squares when they are weak; None: :data:`INSTRUMENTED_SLOPES`.
        models: the axes of another flight's :class:`AidedAngles` by name (``{"alpha": AxisFit}``), e.g. the
            reference flight of a differential diagnosis: the alpha axis then uses that flight's CZ slopes
            (``CZ_alpha``, the curvature, ``CZ_q_hat``, ``CZ_delta_e``; its constant is fitted here) instead of
            fitting them on this flight, so that both flights' aided alpha share one scale (a fitted slope's
            error scales the aided alpha at manoeuvre frequencies: ``docs/estimation.md``). Used only when its
            terms are this flight's (else fitted here, said in ``AxisFit.slope_method``). ``{"beta": AxisFit}``: with
            ``instrument_beta`` on, the beta axis uses that flight's side-force *estimator* (2SLS where that flight's
            ``slope_method`` is 2SLS, with no fallback of its own; least squares where that flight fell back), its
            slopes still fitted here, so that two flights compared by a differential diagnosis carry the same errors in
            variables (``docs/benchmarks.md``, "Seventeenth session, i9-ivdiag"). None: fitted here.
        instrument_beta: fit the side-force model's slopes (``CY_beta`` and the rate terms :data:`BETA_ENDOGENOUS`) by
            two-stage least squares with :data:`BETA_INSTRUMENTS` and their delayed copies as instruments, falling
            back to least squares below :data:`BETA_MIN_FIRST_STAGE_R2`; None: :data:`INSTRUMENTED_BETA`.
        beta_band_hz: the edge above which the side-force model's slopes are fitted, Hz (at least
            :data:`HIGHPASS_HZ`); None: :data:`HIGHPASS_HZ`. For measurement only (``benchmarks/beta_band.py``):
            raising it to the directional (weathercock) corner does not remove the gust's side force from
            ``CY_r_hat`` and worsens the aided sideslip (``docs/estimation.md``, "The sideslip's band and the
            directional mode").
        stated_slopes: ``(CL_alpha, CL_q)``, the airframe's stated whole-aircraft lift-curve slope, 1/rad, and lift
            per unit ``q_hat = q c / (2 V)`` (either None: not stated; magnitudes are used): the floor of the first
            pass is ``CL_alpha`` instead of the wing's Helmbold slope, and where it holds ``q_hat`` is held at
            ``-CL_q`` instead of left out (:data:`STATED_LIFT_SLOPE`; the witness :data:`FLOOR_MIN_GUST_SHARE` still
            decides whether the floor holds). None: the wing's floor.
        profile_beta: ``CY_beta`` of the first pass by the gust model's likelihood (the filter-error estimate,
            :func:`_profile_angle_slope`) instead of least squares above the band edge; only where the side-force slopes
            are fitted by least squares (not with 2SLS or a given model). None: :data:`BETA_PROFILE`.
        stated_level: the airframe's stated lift line, ``{"CL0", "CL_alpha", "CL_q", "CL_delta_e", "CL0_sigma"}``
            (``CL0`` and ``CL_alpha`` required; the others None or missing: 0, 0 and :data:`STATED_CL0_SIGMA`): where
            alpha is aided, its flight mean is moved onto the line (:func:`lift_level`, :data:`STATED_LIFT_LEVEL`) by
            the weight ``s_w^2 / (s_w^2 + s_l^2)`` (``s_w`` the flight-mean wind's 1-sigma ``AxisFit.bias_sigma``,
            ``s_l`` the line's), ``bias_sigma`` becomes ``s_w s_l / sqrt(s_w^2 + s_l^2)`` and the move is said in
            ``AxisFit.shift_note`` (``mean_shift`` holds it, rad). None: alpha's mean is the aiding's.
        gls_beta: the side-force model's slopes of the first pass by generalised least squares under the gust model
            (:func:`_gls_gust_fit`), held in the later passes; only where they would be fitted by least squares (not
            with 2SLS or a given model). None: :data:`BETA_GLS`.
        alpha_profile: the alpha model's columns whose slopes are chosen by the gust model's likelihood (e.g.
            ``("delta_e",)``; :func:`_profile_columns`); None: :data:`ALPHA_PROFILE_COLUMNS` as it stands at the call.

    Returns:
        :class:`AidedAngles` (alpha's sigma includes ``AxisFit.bias_sigma``, the flight-mean vertical wind's
        offset, common to all samples); an axis whose slope is not identified (wrong sign or fewer than
        :data:`MIN_T_STAT` standard errors; for alpha only when :data:`SLOPE_FLOOR` is off or the wing's aspect
        ratio is unknown, since the floor holds a flatter slope), or with under :data:`MIN_VALID_S` s of usable data,
        or a grid slower than :data:`MIN_RATE_HZ`, or that fails the moment cross-check, keeps its
        kinematic angle (``AxisFit.used`` False, ``reason`` says why).

    Source: Jategaonkar (2015) ch. 5 and 7; Morelli and Klein (2016) ch. 6-7 (module docstring).
    """
    T = len(alpha_kin)
    if 1.0 / dt < 0.95 * MIN_RATE_HZ:      # 5 % margin for a nominal 20 Hz stream
        why = (f"samples at {1.0 / dt:.1f} Hz: below {MIN_RATE_HZ:g} Hz the control and rate terms of CY, CZ are "
               "smeared and the force model is not trusted")
        nan = np.full(T, np.nan)
        return AidedAngles(alpha_kin, beta_kin, nan, nan.copy(),
                           (AxisFit("alpha", False, why), AxisFit("beta", False, why)))
    with np.errstate(invalid="ignore", divide="ignore"):
        k = mass / (qbar * S)
        CY = k * f_body[:, 1]
        CZ = k * f_body[:, 2]
        Vs = np.where(V > 1.0, V, np.nan)
        p_hat, q_hat, r_hat = (rates[:, 0] * b / (2 * Vs), rates[:, 1] * c / (2 * Vs), rates[:, 2] * b / (2 * Vs))
    u = use & np.isfinite(qbar) & (qbar > 1.0)
    z0 = np.zeros(T)
    get = lambda n: np.asarray(controls[n], float) if n in controls else z0   # noqa: E731
    # no delta_t: the thrust acts along body x (in CX); a propeller's normal and side forces are second
    # order, and an autopilot's throttle follows the airspeed, i.e. the gusts, slowly: a throttle slope
    # fitted in the band is then spurious and, applied to the slow throttle changes, moves the angles
    # (the sim trainer with w20 = 2 m/s: CZ_delta_t = +1.3 against 0, alpha error 1.0 deg against 0.55)
    lon = {"q_hat": q_hat, "delta_e": get("delta_e")}
    lat = {"p_hat": p_hat, "r_hat": r_hat, "delta_a": get("delta_a"), "delta_r": get("delta_r")}
    dthr = get("delta_t")
    powered = bool(np.nanstd(dthr[use]) > 1e-9) if use.any() else False
    mom_lon = mom_lat = None
    if rate_dot is not None and inertia is not None:
        Mb = rate_dot @ inertia.T + np.cross(rates, rates @ inertia.T)     # M = I w_dot + w x I w, N m
        with np.errstate(invalid="ignore", divide="ignore"):
            qS = qbar * S
            mom_lon = [Mb[:, 1] / (qS * c)]
            mom_lat = [Mb[:, 0] / (qS * b), Mb[:, 2] / (qS * b)]
    de = get("delta_e")
    on = INSTRUMENTED_SLOPES if instrument_slopes is None else instrument_slopes
    inst = lagged_instruments(dt, de) if on and np.nanstd(de[u]) > 1e-9 and np.isfinite(de[u]).all() else None
    with np.errstate(invalid="ignore", divide="ignore"):
        hg = qbar * S / (mass * Vs)          # heave mode's rate per unit |CZ_alpha|, 1/s (heave_edge_hz)
    hg = float(np.nanmedian(hg[u])) if np.isfinite(hg[u]).any() else float("nan")
    floor = lift_slope(b * b / S)          # the wing's lift slope, 1/rad (NaN: no span or area)
    edge = heave_edge_hz(floor, hg)
    cla, clq = stated_slopes if stated_slopes is not None else (None, None)
    floor_held = None
    if cla is not None and np.isfinite(cla) and cla != 0:
        # the whole aircraft's lift slope (wing, tail and body) as stated for this airframe: the floor's value, and
        # with it (and only then) the stated pitch-rate lift that the wing-only floor had to leave out
        floor, floor_held = abs(float(cla)), {}
        if clq is not None and np.isfinite(clq):
            floor_held["q_hat"] = -abs(float(clq))
    inst_b = None
    on_b = INSTRUMENTED_BETA if instrument_beta is None else instrument_beta
    min_fs_b, given_b, est_note = BETA_MIN_FIRST_STAGE_R2, (models or {}).get("beta"), ""
    if on_b and given_b is not None and given_b.used:
        # a differential diagnosis compares two flights through their aided sideslips: both must come from one
        # estimator, or their errors in variables differ (least squares: CY_beta flattened and the gust's side
        # force given to r_hat; 2SLS: neither) and the difference reads as a change of the side force. The
        # given flight (the reference) decided between 2SLS and least squares; this flight follows it, with no
        # fallback of its own (its slopes are still fitted here: a changed side force changes them)
        on_b = given_b.slope_method.startswith("2SLS")
        min_fs_b = 0.0 if on_b else min_fs_b
        est_note = (f"; estimator of the given model (another flight's fit of the same aircraft): "
                    f"{'2SLS' if on_b else 'least squares'}, first-stage R2 there {given_b.first_stage_r2:.2f}")
    if on_b:
        U = [get(k) for k in BETA_INSTRUMENTS if k in controls]
        U = [x for x in U if np.isfinite(x[u]).all() and np.nanstd(x[u]) > 1e-9] if u.any() else []
        inst_b = lagged_instruments(dt, np.column_stack(U)) if U else None
        if inst_b is not None and not np.isfinite(inst_b[u]).all():    # a delay reaches outside the finite record
            inst_b = None
    be, b_sig, fb = _axis("beta", dt, beta_kin, CY, lat, u, passes, -1.0, False, not powered, mom_lat, inst_b,
                          endog=BETA_ENDOGENOUS if inst_b is not None else (), min_first_stage=min_fs_b,
                          weak_test=BETA_WEAK_TEST, band_hz=beta_band_hz,
                          profile=BETA_PROFILE if profile_beta is None else bool(profile_beta),
                          gls=BETA_GLS if gls_beta is None else bool(gls_beta))
    fb.slope_method += est_note
    share = gust_share(dt, alpha_kin, u, fb, edge)
    held = SLOPE_FLOOR and np.isfinite(floor) and share >= FLOOR_MIN_GUST_SHARE
    a, a_sig, fa = _axis("alpha", dt, alpha_kin, CZ, lon, u, passes, -1.0, True, False, mom_lon, inst, V,
                         (models or {}).get("alpha"), band_hz=edge, slope_floor=floor if held else None,
                         floor_held=floor_held, profile_columns=alpha_profile)
    if stated_level is not None and fa.used and stated_level.get("CL0") is not None:
        a, a_sig = _level_onto_line(dt, a, a_sig, fa, k * f_body[:, 0], CZ, q_hat, de, u, stated_level)
    if "first pass with CZ_alpha held at" in fa.slope_method:
        fa.slope_method += f" (lateral gust witness: {100 * share:.0f} % of the kinematic alpha's in-band variance)"
    if powered and fb.used:
        fb.shift_note = ("sideslip mean kept: the throttle varies, and a propeller's side force (slipstream on the "
                         "fin, P-factor) breaks the CY0 ~ 0 prior")
    return AidedAngles(a, be, a_sig, b_sig, (fa, fb))


def _level_onto_line(dt: float, a: np.ndarray, a_sig: np.ndarray, fa: AxisFit, CX: np.ndarray, CZ: np.ndarray,
                     q_hat: np.ndarray, de: np.ndarray, u: np.ndarray, line: dict[str, float | None]
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Move the aided alpha ``a`` (T,) onto the stated lift line's level (:func:`lift_level`) over the rows ``u`` where
    every input is finite, weighted against the flight-mean wind's prior ``fa.bias_sigma``; updates ``fa``'s
    ``mean_shift``, ``shift_note`` and ``bias_sigma`` and returns the moved ``(alpha, alpha_sigma)``."""
    g = lambda k, d: float(line[k]) if line.get(k) is not None else d    # noqa: E731
    cla = abs(g("CL_alpha", float("nan")))
    if not np.isfinite(cla) or cla == 0:
        return a, a_sig
    s_l0 = g("CL0_sigma", STATED_CL0_SIGMA)
    m = u & np.isfinite(a) & np.isfinite(CX) & np.isfinite(CZ) & np.isfinite(q_hat) & np.isfinite(de)
    d, s_l = lift_level(dt, a, CX, CZ, q_hat, de, m, g("CL0", 0.0), cla, abs(g("CL_q", 0.0)), g("CL_delta_e", 0.0),
                        s_l0)
    if not np.isfinite(d):
        return a, a_sig
    s_w = fa.bias_sigma
    if np.isfinite(s_w) and s_w > 0:
        w = s_w**2 / (s_w**2 + s_l**2)
        post = s_w * s_l / np.sqrt(s_w**2 + s_l**2)
    else:
        w, post = 1.0, s_l
    shift = w * d
    old = fa.bias_sigma if np.isfinite(fa.bias_sigma) else 0.0
    a = np.where(u, a + shift, a)
    a_sig = np.sqrt(np.maximum(a_sig**2 - old**2, 0.0) + post**2)
    fa.mean_shift = float(shift)
    fa.wind_sigma = float(s_w)
    fa.bias_sigma = float(post)
    fa.shift_note = (f"alpha mean moved by {np.degrees(shift):+.2f} deg onto the stated lift line (CL0 "
                     f"{g('CL0', 0.0):+.3f} +- {s_l0:.3f}: line's level {np.degrees(d):+.2f} +- {np.degrees(s_l):.2f} "
                     f"deg from the aided mean, weight {w:.2f} against the mean wind's {np.degrees(s_w):.2f} deg)")
    return a, a_sig


def describe(res: AidedAngles) -> list[str]:
    """One note per axis for ``FlightStates.notes``: the model, the gust parameters, or why it fell back."""
    out = []
    for ax in res.axes:
        cname = "CZ" if ax.name == "alpha" else "CY"
        if not ax.used:
            out.append(f"{ax.name}: kinematic only (specific-force aiding fell back: {ax.reason})")
            continue
        check = ""
        if np.isfinite(ax.moment_rss[1]):
            check = (f"; moment cross-check: residual {100 * ax.moment_rss[1]:.1f} % aided vs "
                     f"{100 * ax.moment_rss[0]:.1f} % kinematic")
            if np.isfinite(ax.moment_lambda[1]):
                # kept although the aided residual is the larger: the moments do not follow the kinematic angle
                check += (f", but the moments follow the aided angle (lambda = {ax.moment_lambda[0]:.2f} +- "
                          f"{ax.moment_lambda[1]:.2f}, not below 0.5 by {MOMENT_Z:g} standard errors)")
        terms = ", ".join(f"{cname}_{n} = {v:+.3g}" for n, v in zip(ax.columns[1:], ax.coef[1:]))
        out.append(f"{ax.name} aided by the specific force (R2 {ax.r2:.2f}; {cname} = {ax.coef[0]:+.3g} + linear in "
                   f"{', '.join(ax.columns[1:])}: {terms}); gust state: tau {ax.tau_s:g} s, "
                   f"{np.degrees(ax.gust_sigma):.2f} deg; force-derived {ax.name} noise "
                   f"{np.degrees(ax.noise_sigma):.2f} deg per sample{check}"
                   + (f"; {ax.shift_note}" if ax.shift_note else "")
                   + (f"; slopes by {ax.slope_method}" + (f" (first-stage R2 {ax.first_stage_r2:.2f})"
                                                          if np.isfinite(ax.first_stage_r2) else ""))
                   + f" above {ax.band_hz:.2f} Hz"
                   + (f"; offset common to the flight (mean vertical wind, not observable) 1-sigma "
                      f"{np.degrees(ax.bias_sigma):.2f} deg, included in sigma" if np.isfinite(ax.bias_sigma) else ""))
    return out
