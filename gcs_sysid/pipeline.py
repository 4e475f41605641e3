"""The replay job: log -> states -> coefficients -> GP -> confidence map -> suggestions -> report.

This module only wires the layers together; each stage lives in its own package.
"""

from __future__ import annotations

import importlib
import time
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable, Iterator

import numpy as np

from .aero import compute_coefficients
from .aero.table import COEFFICIENTS, MOMENT_COEFFICIENTS, REGRESSORS, CoefficientTable
from .airframe import load_airframe
from .errors import InputError
from .estimation.states import FlightStates
from .options import check_holdout, check_log, check_model_state, check_positive_int, check_rate, check_window
from .outdir import StagedDir, check_out_dir
from .parallel import Helper, Job
from .result import ReplayResult
from .telemetry import cut_window, read_log

__all__ = ["ReplayOptions", "REPLAY_OUTPUTS", "check_replay", "run_replay", "held_out_mask", "error_pct",
           "identifiability", "training_rows", "GP_NOISE_MODES", "gp_noise_fields", "replay_gp_config",
           "REPLAY_GUST_RATES", "replay_gust_rates", "replay_beta_gls"]

#: What a replay writes into its output folder (an existing folder holding only these may be replaced).
REPLAY_OUTPUTS = ("report.html", "summary.md", "coefficients.csv", "suggestions.json", "result", "model.npz",
                  "model.json")

#: The replay's rate regressors (``ReplayOptions.gust_rates`` None): ``"inertial"``, the gyro's ``p_hat q_hat r_hat``.
#: ``"path-yaw"`` (``r_hat`` relative to the air: the gyro's ``r`` less the yaw gust rate ``r_g = +(s/V)/(1 + 3b
#: s/(pi V)) v_g`` of the reconstructed lateral gust, :mod:`gcs_sysid.estimation.gustrates`) together with GLS's
#: sideslip (``beta_gls``) lifts issue 8's model at the true regressors (78 -> 110 of 450 within the lines) but failed
#: the sixty-third session's rule (rule 8(b) +112/-56 and +100/-56: the bands at exact conditions over-cover, the
#: held-out CY of four aircraft crosses 5 %; ``docs/benchmarks.md``, "Sixty-third session, lead"), so it stays opt-in.
REPLAY_GUST_RATES = "inertial"

#: Fewest valid rows the GP is fitted on.
MIN_TRAIN_ROWS = 50
#: Held-out error (%) above which the report warns that a coefficient's model does not generalise.
POOR_HELDOUT_PCT = 50.0


@dataclass(frozen=True)
class ReplayOptions:
    """Options of :func:`run_replay`.

    Attributes:
        rate_hz: estimation grid rate, Hz.
        holdout: fraction of the valid flight time, taken as the last contiguous segment, never fitted.
        t_from, t_to: vehicle-time window in s (None = open).
        model_in: directory of a saved model state to continue from (incremental update).
        n_inducing: inducing points of the global GP (None = the GP's default).
        progress: show rich progress bars.
        write: write the report files (False for tests that only need the result).
        parallel: use a second process for the work beside the main chain (decoding most of a
            .tlog, the specific-force smoother, the report's figures; :mod:`gcs_sysid.parallel`)
            when more than one CPU is usable; the results are the same.
        targets: coefficients the maneuver suggestions target (None: all, moment coefficients
            first; :class:`gcs_sysid.maneuvers.ManeuverConfig`).
        notify: called with each one-line note the user should see at once (the damage found in the
            log, :attr:`gcs_sysid.telemetry.Flight.damage`); None: notes go to the report only.
        can_log: a recorded CAN log (DroneCAN actuator status, airspeed) merged on the vehicle time
            axis (:mod:`gcs_sysid.telemetry.can_merge`); None: none.
        can_offset: s added to the CAN log's times (None: 0 with a .tlog; required with a .bin).
        gust_rates: a frame of :data:`gcs_sysid.estimation.gustrates.FRAMES` (the hats relative to the air, less
            the gust rates estimated from the reconstructed gusts; :func:`gcs_sysid.aero.compute_coefficients`) or
            ``"inertial"`` (the gyro's ``p_hat q_hat r_hat``). None: :data:`REPLAY_GUST_RATES`.
        beta_gls: the aided sideslip's side-force model by generalised least squares under the aiding's gust model
            (True) or by least squares (False; ``estimate_states(gls_beta=)``). None:
            :data:`gcs_sysid.estimation.airangles.BETA_GLS` as it stands at the call (off).
        air_yaw: train :data:`gcs_sysid.aero.airyaw.AIR_YAW_OUTPUTS` on the air-relative yaw rate (their targets
            ``C + C_r r_hat_g`` with the yaw gust rate of the reconstructed lateral gust,
            :func:`gcs_sysid.aero.airyaw.air_yaw_target`; the inputs stay the gyro's) and ask them at
            ``r_hat - r_hat_g`` on the held-out rows. None: :data:`gcs_sysid.aero.airyaw.AIR_YAW`
            (off). Not with a ``gust_rates`` frame (that moves the shared input instead).
        rate_errors: state the gyro rates' errors as stand-ins for the air-relative rates in the model's band at
            exact conditions (``gcs-sysid predict``'s sigma): ``p_hat``'s scale error from the roll fit's rolling
            gust, ``r_hat``'s linear error from the yaw gust rate (:func:`gcs_sysid.aero.rateerrors.
            stated_rate_errors`). The mean and the bands at the flight's own regressors are unchanged. None:
            :data:`gcs_sysid.aero.rateerrors.RATE_ERRORS` (on).
        alpha_dot_hat: give the GP ``alpha_dot_hat`` (``CoefficientTable.alpha_dot_hat``) as a mean-only input
            of Cm (:data:`ALPHA_DOT_GP`; ``docs/gp.md``, "Mean-only inputs"): a linear ``Cm_alpha_dot`` term,
            kept when its slope is significant with coloured residuals, negative, and lowers Cm's blocked
            cross-validation error; when the first two fail the model is fitted without the column. False: the
            ten regressors alone.
        gust_filter: train the GP on ``p_hat`` less the rotational gust ``p_g`` smoothed from the training rows'
            own measured Cl (the filter-error method, :func:`gcs_sysid.aero.gustfilter.filter_gust_table`);
            the held-out rows keep the gyro's hats (``p_g = 0``, its prior mean, with the prior variance stated in
            the band). True or ``"2sls"``: the measured Cl as the filter's output, slopes by two-stage least
            squares; ``"roll"``: the gust a state of the roll dynamics, estimated with the slopes from the causal
            step moment (:mod:`gcs_sysid.aero.rollgust`); ``"rollgp"``: the same with the moment's noise at the
            smoother's stated variance, and the GP's Cl target given the fit's slopes of
            :data:`gcs_sysid.aero.gustfilter.ROLL_GP_SLOPES` (:func:`gcs_sysid.gp.mixed.apply_fixed_slopes`).
            None: :data:`gcs_sysid.aero.gustfilter.GUST_FILTER`.
        heldout_air_roll: the held-out rows' ``p_hat`` (what the model is asked at there): ``"off"`` the gyro's;
            ``"smoothed"``, ``"filtered"`` or ``"predicted"``: less the rolling gust estimated on those rows from
            their own measured roll moment with the training rows' roll fit
            (:func:`gcs_sysid.aero.gustfilter.heldout_air_roll`; ``"predicted"`` reads only the moments before
            each row). ``"smoothed:Cl"``, ``"filtered:Cl"``, ``"predicted:Cl"``: per output, only Cl is asked at
            that rate, the other outputs at the gyro's (their slopes were learned there;
            :data:`gcs_sysid.aero.gustfilter.AIR_ROLL_MODES`). Training rows unchanged. None:
            :data:`gcs_sysid.aero.gustfilter.HELDOUT_AIR_ROLL`.
        air_roll_train: train the GP's Cl on the measured Cl less the roll fit's rolling-gust moment
            (``Cl + Cl_p p_hat_g``, the gust smoothed on the training rows; the inputs, the gyro's ``p_hat``, and
            CX..CZ, Cm, Cn unchanged), so that Cl is learned at the air-relative roll rate
            (:func:`gcs_sysid.aero.gustfilter.air_roll_target`). Pair it with ``heldout_air_roll="predicted:Cl"``
            (Cl asked at ``p_hat - p_hat_g`` on the held-out rows); with ``"off"`` the held-out Cl is the model's at
            ``p_g = 0``. Not with ``gust_filter`` (that moves every output's ``p_hat`` instead). None:
            :data:`gcs_sysid.aero.gustfilter.AIR_ROLL_TRAIN` (on), off when ``gust_filter`` is on.
        air_pitch: move every row's ``q_hat`` to the air-relative estimate ``q_hat - kappa g`` (``g`` the pitch gust
            rate from the reconstructed wind, ``kappa`` its share in Cm fitted on the training rows with a free sign,
            applied only when the fit shows it; :mod:`gcs_sysid.aero.airpitch`), for every output, training and
            held-out rows alike. None: :data:`gcs_sysid.aero.airpitch.AIR_PITCH` (on), off with a ``gust_rates`` frame
            that already moves ``q_hat`` (``"path"``, ``"mean-wind"``).
        gp_seed: ``GPConfig.seed`` of the GP fit (the hyperparameters' row subset, the inducing points; as the live
            learner's ``LearnOptions.gp_seed``). 0: ``GPConfig``'s own default. Issue 8's counts are judged at two
            seeds (the project's rule 8(b); ``benchmarks/eval_jsbsim.py --gp-seed``).
        coefficient_band: the coefficient's band at the flight's own regressors (``<C>_sigma``, ``pred_sigma``):
            ``"white"`` the measurement's band less its white part (``docs/gp.md``, "Two bands"); ``"stated"`` for
            the outputs of :data:`STATED_BAND_SIGN`, the blocked cross-validation's residual variance plus or minus
            the measured coefficient's error variance that the estimator states
            (:mod:`gcs_sysid.gp.coefband`), the white band elsewhere and where nothing is stated. Either way the
            outputs of :data:`WHITE_BAND_NO_STATED_INPUT` (CX) take the white band without the estimator's stated
            regressor variances. None: :data:`COEFFICIENT_BAND`. The means and the measurement's band do not change.
    """

    rate_hz: float = 50.0
    holdout: float = 0.2
    t_from: float | None = None
    t_to: float | None = None
    model_in: str | None = None
    n_inducing: int | None = None
    progress: bool = True
    write: bool = True
    parallel: bool = True
    notify: Callable[[str], None] | None = None
    targets: tuple[str, ...] | None = None
    can_log: str | None = None
    can_offset: float | None = None
    gust_rates: str | None = None
    beta_gls: bool | None = None
    air_yaw: bool | None = None
    rate_errors: bool | None = None
    alpha_dot_hat: bool = True
    gust_filter: bool | str | None = None
    heldout_air_roll: str | None = None
    air_roll_train: bool | None = None
    gp_noise: str | None = None
    gp_seed: int = 0
    air_pitch: bool | None = None
    coefficient_band: str | None = None


#: ``ReplayOptions.coefficient_band`` values (``docs/gp.md``, "The coefficient's band from the stated measurement
#: error").
COEFFICIENT_BANDS = ("white", "stated")

#: The replay's coefficient band when ``ReplayOptions.coefficient_band`` is None (``eval_jsbsim --coefficient-band``
#: sets it): ``"stated"`` since the seventy-first session (rule 74, fresh seeds 40-42, with Cl's ``"innov"`` band:
#: ``docs/benchmarks.md``, "Seventy-first session"); before, ``"white"``, the measurement's band less its white part
#: (the eleventh session's), which CX, CY and Cl keep.
COEFFICIENT_BAND = "stated"

#: With ``coefficient_band="stated"``, the sign of the measured error's variance per output
#: (:func:`gcs_sysid.gp.coefband.stated_band_variance`; an output not named keeps the white band): ``+1`` where the
#: model gives the measured error back (CZ: alpha is aided by the measured CZ, the specific-force aiding; Cm, whose
#: held-out error on issue 8's used flights kept about a third of its measured error, which the stated error, about
#: half the true one, matches through ``+1``); ``0`` the blocked validation's residual alone (Cn: the model averages its
#: error out, and ``cv - var E`` with the short stated error fell below 90 % on 14-17 of 75 flights). CY (``+1`` and the
#: white band tie over three flight sets, the white one with fewer flights below 90 %), CX (the same with ``0``) and Cl
#: (its held-out rows are asked at the held-out air roll rate, whose stated variance sets that band) keep the white
#: band (``docs/benchmarks.md``, "Seventy-first session": rules 72 and 73, and the signs chosen on their flights).
STATED_BAND_SIGN = {"CZ": 1.0, "Cm": 1.0, "Cn": 0.0}

#: With ``coefficient_band="stated"``, the outputs of :data:`STATED_BAND_SIGN` whose blocked-validation residual is
#: taken less its white nugget (the model discrepancy ``d_p``; ``less_white`` of
#: :func:`gcs_sysid.gp.coefband.stated_band_variance`): the model averages a white measurement error out. Empty: none.
#: CX with it (sign 0) gained 8 of 75 flights in 90-98 % on fresh seeds 43-45 at both GP seeds but failed rule 8(b)
#: there (+15/-7, +18/-10: rule 75, ``docs/benchmarks.md``, "Seventy-second session"), so it stays opt-in.
STATED_BAND_LESS_WHITE: tuple[str, ...] = ()

#: The outputs whose white coefficient band (``coefficient_band="white"``, or an output outside
#: :data:`STATED_BAND_SIGN`) leaves out the estimator's stated regressor variances (``CoefficientTable.x_var``) and
#: keeps NIGP's learned input noise: for an output that does not aid an air angle, the residual the likelihood's noise
#: is learned from already holds what the angles' errors do to it (``T = R + E``, the angle's error in both), so the
#: stated term through the slope counts it twice (``docs/gp.md``, "The coefficient's band from the stated measurement
#: error"). ``("CX",)`` since the seventy-second session (rule 76, written before its run on fresh seeds 46-48: CX in
#: 90-98 % on 35 -> 39 and 35 -> 40 of 75 flights at GP seeds 0 and 1, flips +5/-1 and +6/-1, the means identical;
#: ``docs/benchmarks.md``, "Seventy-second session"). CY and CZ aid an air angle and keep the stated term (without it
#: their bands collapse); Cl's stated term is its held-out air roll rate's; Cm and Cn take the stated band.
WHITE_BAND_NO_STATED_INPUT: tuple[str, ...] = ("CX",)


#: The GP settings that make ``alpha_dot_hat`` a mean-only input of Cm (not CZ, not a kernel input; the seventh
#: session's trial as an 11th input of every output made CZ worse, docs/benchmarks.md). Never CZ's mean: from the force
#: equations ``alpha_dot_hat = q_hat cos^2(alpha) + (c rho S / 4m) CZ cos(alpha) + gravity / V^2 terms`` carries the
#: measured CZ, so CZ with ``q_hat`` and ``alpha_dot_hat`` fits that identity (sgs126 light s1: CZ_alpha_dot +37, CZ_q
#: -37, 1/k = 38-40; twenty-fourth session, i8-noise3; docs/gp.md, "Identical regressors for Zellner's equivalence").
ALPHA_DOT_GP = {"mean_only_inputs": ("alpha_dot_hat",), "mean_only_outputs": ("Cm",), "mean_only_sign": -1.0}

#: Opt-in (``GPConfig(**ALPHA_DOT_GP, **ALPHA_DOT_PARTNER_RULE)``): ``q_hat`` as alpha_dot_hat's partner, the term
#: kept only where ``Cm_q < 0`` stays in the same fit and ``|Cm_alpha_dot| <= |Cm_q|``
#: (``GPConfig.mean_only_partners``). It refuses the F-16's false term but also the J-3 Cub's real one and puts the
#: F-16's light bands back above 98 % (fourteenth session, i8-adotgate; left off at the merge, docs/gp.md).
ALPHA_DOT_PARTNER_RULE = {"mean_only_partners": ("q_hat",), "mean_only_ratio": 1.0}

#: The GP settings of the decorrelated fit (eighteenth session, i8-decnt; ``docs/gp.md``, "The stride from the
#: decorrelation time"): the hyperparameters learned with the full noise covariance on rows one decorrelation time
#: of the training residual apart (``hyper_stride=0``), then the cross-output coupling removed (``coupling="off"``).
DECORRELATED_GP = {"noise_correlation": True, "hyper_stride": 0, "coupling": "off"}

#: Whether the replay's fit uses :data:`DECORRELATED_GP`. Off: opt-in (see docs/benchmarks.md, eighteenth session,
#: i8-decnt, for what it gains and loses in eval_jsbsim).
USE_DECORRELATED_GP = False

#: The replay's ``GPConfig.coupling_test`` (twenty-second session): ``"lr"`` (the default, as ``GPConfig``'s) keeps an
#: output's coupling only where the deflated likelihood-ratio test on every training row supports it
#: (:func:`gcs_sysid.gp.joint.lr_coupling`; docs/gp.md, "Coupling the data determine"); ``"none"`` keeps B's
#: off-diagonals as learned (the default until the twenty-second session; ``eval_jsbsim --gp-fit untested``).
GP_COUPLING_TEST = "lr"

#: The replay GP's noise, by name (``ReplayOptions.gp_noise``, ``gcs-sysid replay --gp-noise``, ``eval_jsbsim
#: --gp-noise``): the :class:`gcs_sysid.gp.GPConfig` fields ``(noise_correlation, noise_posterior, noise_start)``.
#:   ``learned``      (the default since the twenty-fifth session) the full ``P x P`` noise covariance learned with the
#:                    hyperparameters and used by every decision before the posterior (the bound, the coupling test, the
#:                    blocked validation's latent scales), only its diagonal in the posterior (twenty-third session,
#:                    i8-noise2; docs/gp.md, "Noise: learned, not conditioned on");
#:   ``independent``  one noise variance per output, no correlation learned (the default until the twenty-fifth
#:                    session; ``diagonal`` is its older name, kept);
#:   ``full``         the learned covariance in the posterior too (eval_gp_jsbsim's ``nigp``; twenty-second session);
#:   ``full-nstart``  ``full`` with the shared error started in the noise (``GPConfig.noise_start = "noise"``).
GP_NOISE_MODES = {"learned": (True, "diagonal", "signal"), "independent": (False, "full", "signal"),
                  "diagonal": (False, "full", "signal"), "full": (True, "full", "signal"),
                  "full-nstart": (True, "full", "noise")}

#: The replay's default noise (a name of :data:`GP_NOISE_MODES`), spelled out in the three constants below, which
#: :func:`run_replay` reads when ``ReplayOptions.gp_noise`` is None (``eval_jsbsim --gp-noise`` sets them).
#: ``learned`` since the twenty-fifth session (i8-learned), under the default rule for GP changes (judged at two GP
#: seeds against the default at the same seed; docs/gp.md, "The default noise"): on 99 tuning flights (22 aircraft)
#: flight x count flips +38/-8 at GPConfig.seed 0 and +41/-11 at seed 1 (docs/benchmarks.md, "Twenty-fifth session,
#: i8-learned"), learned output correlations above 0.5 on 32 -> 8 and 39 -> 8 flights; 3 aircraft lose a count at
#: both seeds, where the default merely reseeded loses one on 12. ``independent`` is the old default.
GP_NOISE = "learned"

#: The replay's ``GPConfig.noise_correlation``: True (the default since the twenty-fifth session, with
#: :data:`GP_NOISE_POSTERIOR` ``"diagonal"``: ``learned``) learns the full ``P x P`` noise covariance, so an error the
#: gust puts into several coefficients at once is explained as noise, not as signal coupling ``B`` (us25e light s1:
#: a learned output correlation of 0.99 with one variance per output); False (``independent``, the default until the
#: twenty-fifth session) one noise variance per output. Twenty-second session, lead, second round; twenty-third,
#: i8-noise (``full`` on the roster: correlations above 0.5 on 29 -> 6 of 87 flights, a count lost on 7 aircraft).
GP_NOISE_CORRELATION = GP_NOISE_MODES[GP_NOISE][0]

#: With :data:`GP_NOISE_CORRELATION`, the noise covariance the replay GP's posterior conditions on
#: (``GPConfig.noise_posterior``): ``"diagonal"`` (the default, ``learned``: the correlation learned with the
#: hyperparameters and the coupling test, dropped before the posterior and the blocked validation: twenty-third
#: session, i8-noise2) or ``"full"`` (the learned one: its seemingly-unrelated-regressions transfer moved sgs126 light
#: s1's Cm slopes and f16 light s2's). Twenty-third session (87 flights): correlations above 0.5 29 -> 7, GP<LS
#: 469 -> 475; twenty-fourth (i8-noise3, 93 flights): 9 aircraft win, 6 lose a count, the default merely reseeded
#: loses one on 12; twenty-fifth (i8-learned): made the default under the two-seed rule (:data:`GP_NOISE`).
GP_NOISE_POSTERIOR = GP_NOISE_MODES[GP_NOISE][1]

#: With :data:`GP_NOISE_CORRELATION`, where the shared error starts (``GPConfig.noise_start``): ``"signal"`` or
#: ``"noise"`` (``eval_jsbsim --gp-noise full-nstart``).
GP_NOISE_START = GP_NOISE_MODES[GP_NOISE][2]


def gp_noise_fields(name: str | None = None) -> dict:
    """The :class:`gcs_sysid.gp.GPConfig` noise fields of the replay's GP.

    Args:
        name: a key of :data:`GP_NOISE_MODES`, or None for the module's constants (:data:`GP_NOISE_CORRELATION`,
            :data:`GP_NOISE_POSTERIOR`, :data:`GP_NOISE_START`; by default :data:`GP_NOISE`'s).

    Returns:
        ``{"noise_correlation": bool, "noise_posterior": str, "noise_start": str}``.

    Raises:
        InputError: ``name`` is not a key of :data:`GP_NOISE_MODES`.
    """
    if name is None:
        values = (GP_NOISE_CORRELATION, GP_NOISE_POSTERIOR, GP_NOISE_START)
    elif name in GP_NOISE_MODES:
        values = GP_NOISE_MODES[name]
    else:
        raise InputError(f"--gp-noise: expected one of {', '.join(GP_NOISE_MODES)}, got {name!r}")
    return dict(zip(("noise_correlation", "noise_posterior", "noise_start"), values))


def replay_gp_config(options: ReplayOptions = ReplayOptions(), alpha_dot: bool = False):
    """The :class:`gcs_sysid.gp.GPConfig` of the replay's GP fit.

    Args:
        options: the replay's options (``gp_noise``, ``n_inducing``, ``gp_seed`` are read).
        alpha_dot: ``alpha_dot_hat`` is the 11th input (a mean-only input of Cm, :data:`ALPHA_DOT_GP`).

    Returns:
        the GPConfig: the noise of :func:`gp_noise_fields` (``learned`` by default), :data:`ALPHA_DOT_GP` when
        ``alpha_dot``, :data:`DECORRELATED_GP` when :data:`USE_DECORRELATED_GP`, :data:`GP_COUPLING_TEST`.

    Raises:
        InputError: an unknown ``options.gp_noise``.
    """
    from .gp import GPConfig

    return GPConfig(**{**gp_noise_fields(options.gp_noise), **(ALPHA_DOT_GP if alpha_dot else {}),
                       **(DECORRELATED_GP if USE_DECORRELATED_GP else {})},
                    coupling_test=GP_COUPLING_TEST, seed=int(options.gp_seed),
                    **({} if options.n_inducing is None else {"n_inducing": options.n_inducing}))

#: Opt-in (nineteenth session, i8-cyr): the std (CY per unit ``p_hat`` / ``r_hat``) of a zero-mean prior on CY's two
#: rate slopes, imposed by mixed estimation on the GP's training target (:func:`gcs_sysid.gp.mixed.apply_slope_prior`;
#: Theil and Goldberger 1961; ``docs/gp.md``, "Prior knowledge on the side-force rate slopes"). None: no prior (the
#: default). The gust's side force lands on ``r_hat`` (the aircraft yaws with the gust the aided sideslip misses):
#: CY_r_hat -1.7..-2.2 on the c684 and rascal against JSBSim's 0. JSBSim's models that have the terms: CY_r
#: 0.14..0.30 (the F-16's 0.9), CY_p -0.2..0.1.
SIDE_FORCE_RATE_PRIOR_STD: float | None = None


def side_force_rate_prior(std: float | None) -> tuple:
    """The prior of :func:`gcs_sysid.gp.mixed.apply_slope_prior` on CY's ``p_hat`` and ``r_hat`` slopes, std ``std``
    (CY per unit rate); ``()`` for None."""
    return () if std is None else (("CY", "p_hat", float(std)), ("CY", "r_hat", float(std)))


def gp_inputs(table, rows: np.ndarray, with_alpha_dot: bool) -> tuple[np.ndarray, np.ndarray | None]:
    """The GP's inputs of ``rows`` (``(T,)`` bool) of a :class:`~gcs_sysid.aero.table.CoefficientTable`:
    ``(X (n, 10), x_var (n, 10) or None)``, or with ``with_alpha_dot`` and a table that carries
    ``alpha_dot_hat``, ``X (n, 11)`` with it as the last column (NaN there: 0, steady flight, as a query that
    leaves it out). ``x_var`` stays ``(n, 10)``: the model pads it (nothing stated for ``alpha_dot_hat``)."""
    X = table.X[rows]
    xv = None if table.x_var is None else table.x_var[rows]
    if with_alpha_dot and table.alpha_dot_hat is not None:
        a = np.asarray(table.alpha_dot_hat, float)[rows]
        X = np.concatenate([X, np.where(np.isfinite(a), a, 0.0)[:, None]], axis=1)
    return X, xv


#: ``ReplayOptions.gust_rates`` values besides the frames of :data:`gcs_sysid.estimation.gustrates.FRAMES`
INERTIAL_RATES = "inertial"


def replay_gust_rates(options: ReplayOptions) -> str | None:
    """The gust-rate frame the replay's coefficients use: ``options.gust_rates``, :data:`REPLAY_GUST_RATES` when it is
    None, None (the gyro's rates, :func:`gcs_sysid.aero.compute_coefficients`' own meaning) for ``"inertial"``."""
    g = REPLAY_GUST_RATES if options.gust_rates is None else options.gust_rates
    return None if g == INERTIAL_RATES else g


def replay_beta_gls(options: ReplayOptions) -> bool:
    """Whether the replay's aided sideslip uses GLS: ``options.beta_gls``, or
    :data:`gcs_sysid.estimation.airangles.BETA_GLS` as it stands now when that is None."""
    from .estimation import airangles

    return bool(airangles.BETA_GLS if options.beta_gls is None else options.beta_gls)


def replay_air_pitch(options: ReplayOptions) -> bool:
    """Whether the replay moves ``q_hat`` to the air-relative estimate: ``options.air_pitch``, or when it is None
    :data:`gcs_sysid.aero.airpitch.AIR_PITCH` unless the gust-rate frame already moves ``q_hat``."""
    from .aero.airpitch import AIR_PITCH
    from .estimation.gustrates import PITCH_FRAMES

    if options.air_pitch is not None:
        return bool(options.air_pitch)
    return AIR_PITCH and replay_gust_rates(options) not in PITCH_FRAMES


def replay_coefficient_band(options: ReplayOptions) -> str:
    """The replay's coefficient band (a name of :data:`COEFFICIENT_BANDS`): ``options.coefficient_band``, or
    :data:`COEFFICIENT_BAND` as it stands now when that is None.

    Raises:
        InputError: the name is not one of :data:`COEFFICIENT_BANDS`.
    """
    name = COEFFICIENT_BAND if options.coefficient_band is None else options.coefficient_band
    if name not in COEFFICIENT_BANDS:
        raise InputError(f"coefficient band {name!r}: expected one of {', '.join(COEFFICIENT_BANDS)}")
    return name


def check_replay(log: str | Path, airframe_path: str | Path, out_dir: str | Path | None,
                 options: ReplayOptions = ReplayOptions()):
    """Check every input and option of a replay before any work; returns the loaded airframe.

    Raises:
        InputError: one line naming the option or file and what was expected (the log's first bytes
            are read to tell its format; nothing is decoded).
    """
    check_rate(options.rate_hz)
    check_holdout(options.holdout)
    from .aero.gustfilter import AIR_ROLL_MODES

    if options.heldout_air_roll is not None and options.heldout_air_roll not in AIR_ROLL_MODES:
        raise InputError(f"heldout_air_roll: expected one of {', '.join(AIR_ROLL_MODES)}, got "
                         f"{options.heldout_air_roll!r}")
    if options.air_roll_train and options.gust_filter:
        raise InputError("air_roll_train: not with gust_filter (both take the rolling gust out of Cl's training "
                         "rows: gust_filter through every output's p_hat, air_roll_train through Cl's target)")
    if options.gp_noise is not None:
        gp_noise_fields(options.gp_noise)
    from .estimation.gustrates import FRAMES, PITCH_FRAMES

    if options.gust_rates is not None and options.gust_rates not in (*FRAMES, INERTIAL_RATES):
        raise InputError(f"gust_rates: expected one of {', '.join((*FRAMES, INERTIAL_RATES))}, got "
                         f"{options.gust_rates!r}")
    if options.air_yaw and replay_gust_rates(options) is not None:
        raise InputError("air_yaw: not with a gust_rates frame (both take the yaw gust rate out of the moments: "
                         "air_yaw through Cl's and Cn's targets, gust_rates through every output's input)")
    if options.air_pitch and replay_gust_rates(options) in PITCH_FRAMES:
        raise InputError(f"air_pitch: not with the gust_rates frame {replay_gust_rates(options)!r} (both take the "
                         "pitch gust rate out of q_hat; 'path-yaw' leaves q_hat the gyro's)")
    check_window(options.t_from, options.t_to)
    check_positive_int(options.n_inducing, "--inducing")
    if options.targets is not None:
        bad = [c for c in options.targets if c not in COEFFICIENTS]
        if bad or not options.targets:
            raise InputError(f"--target {','.join(options.targets)}: expected comma-separated coefficients "
                             f"among {', '.join(COEFFICIENTS)}")
    if options.model_in:
        check_model_state(options.model_in)
    replay_coefficient_band(options)
    check_log(log)
    if options.can_log is not None:
        from .telemetry.can_merge import check_can_log

        check_can_log(options.can_log, log, options.can_offset)
    airframe = load_airframe(airframe_path)
    if out_dir is not None and options.write:
        check_out_dir(out_dir, "--out", REPLAY_OUTPUTS)
    return airframe


def error_pct(estimate: np.ndarray, reference: np.ndarray) -> float:
    """Coefficient error ``100 * RMS(estimate - reference) / RMS(reference)`` (DEVELOPERS.md), NaN-safe.

    Args:
        estimate, reference: arrays of shape (T,).
    """
    m = np.isfinite(estimate) & np.isfinite(reference)
    if not m.any():
        return float("nan")
    ref = float(np.sqrt(np.mean(reference[m] ** 2)))
    return 100.0 * float(np.sqrt(np.mean((estimate[m] - reference[m]) ** 2))) / ref if ref > 0 else float("nan")


def held_out_mask(t: np.ndarray, valid: np.ndarray, fraction: float) -> np.ndarray:
    """The last contiguous ``fraction`` of the valid flight time, as a (T,) bool mask.

    Raises:
        InputError: fraction outside [0, 0.9].
    """
    if not 0.0 <= fraction <= 0.9:
        raise InputError(f"--holdout must lie in [0, 0.9], got {fraction}")
    mask = np.zeros(len(t), bool)
    if fraction == 0 or not valid.any():
        return mask
    tv = t[valid]
    cut = tv[0] + (1.0 - fraction) * (tv[-1] - tv[0])
    mask[valid & (t >= cut)] = True
    return mask


def training_rows(X: np.ndarray, Y: np.ndarray, names: list[str], optional: int = 0
                  ) -> tuple[np.ndarray, np.ndarray, str]:
    """The GP's training rows: finite regressors and at least one finite coefficient.

    The last ``optional`` columns of ``X`` may be NaN (the mean-only ``alpha_dot_hat``): ``fit_gp`` keeps
    such rows when its gates leave the column out and drops them otherwise
    (:func:`gcs_sysid.gp.fit.rows_without_mean_only`).

    A row that misses some coefficients (NaN: e.g. an angular-acceleration estimate rejected, so its
    moments are missing while its forces are kept) is kept: the joint GP conditions each coefficient
    on the rows that carry it, and the coregionalisation lets the others inform it there
    (``docs/gp.md``, "Missing outputs").

    Args:
        X: ``(N, D)`` regressors; Y: ``(N, P)`` coefficients; names: the ``P`` coefficient names.

    Returns:
        ``(X, Y, note)``: the kept rows and a one-line note saying what is missing ("" when nothing is).
    """
    ok = np.all(np.isfinite(X[:, :X.shape[1] - int(optional)]), axis=1) & np.any(np.isfinite(Y), axis=1)
    X, Y = X[ok], Y[ok]
    miss = (~np.isfinite(Y)).sum(0)
    if not miss.any():
        return X, Y, ""
    return X, Y, ("training rows without some coefficients (each is learned from the rows that carry it, the "
                  "joint GP's other coefficients inform it there): " + ", ".join(
                      f"{n} missing on {int(m)} of {len(Y)}" for n, m in zip(names, miss) if m))


def identifiability(states: FlightStates, table: CoefficientTable) -> dict[str, tuple[bool, str]]:
    """Whether each coefficient can be identified from these data, with the reason when not.

    Uses the estimation layer's verdicts (``FlightStates.identifiability``: e.g. rate derivatives
    cannot be formed from 4 Hz gyro data) and checks that each coefficient has finite data.
    """
    verdict = dict(getattr(states, "identifiability", {}) or {})
    out: dict[str, tuple[bool, str]] = {}
    n_valid = int(table.valid.sum())
    for i, name in enumerate(COEFFICIENTS):
        ok, why = verdict.get(name, (True, ""))
        if ok:
            finite = np.isfinite(table.Y[table.valid, i]).sum() if n_valid else 0
            if finite < MIN_TRAIN_ROWS:
                ok, why = False, f"only {finite} valid samples (need {MIN_TRAIN_ROWS})"
        out[name] = (bool(ok), str(why))
    return out


@contextmanager
def _stage(name: str, timings: dict[str, float], bar) -> Iterator[Callable[[float], None]]:
    t0 = time.perf_counter()
    task = bar.add_task(name, total=1.0) if bar is not None else None

    def progress(frac: float) -> None:
        if bar is not None:
            bar.update(task, completed=min(max(frac, 0.0), 1.0))

    try:
        yield progress
    finally:
        timings[name] = time.perf_counter() - t0
        if bar is not None:
            bar.update(task, completed=1.0)


def _load_stages() -> None:
    """Import the estimation stage's modules (SciPy, filterpy: about 0.8 CPU s) and set up BLAS (one
    thread: the many small factorisations of the smoothers and the GP run faster without hand-offs, and
    the worker has the other core; ``docs/gp.md``). Run while the worker decodes most of the log."""
    from .jaxconfig import limit_blas_threads

    limit_blas_threads(1)
    importlib.import_module("gcs_sysid.estimation.estimate")


def _load_model_stages() -> None:
    """Import the modules of the stages after estimation (JAX, optax: about 0.6 CPU s) and set up JAX
    (64-bit; idempotent). Run while the worker smooths the specific force (the estimation stage's wait,
    :func:`gcs_sysid.estimation.estimate_states`' ``meanwhile``), and before the coefficients in any case."""
    from .jaxconfig import enable_x64

    enable_x64()
    for m in ("gcs_sysid.gp", "gcs_sysid.envelope", "gcs_sysid.maneuvers", "gcs_sysid.report"):
        importlib.import_module(m)


def _progress_bar(enabled: bool):
    if not enabled:
        return None
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    return Progress(TextColumn("{task.description:<22}"), BarColumn(), TimeElapsedColumn(), transient=False)


def run_replay(log: str | Path, airframe_path: str | Path, out_dir: str | Path,
               options: ReplayOptions = ReplayOptions()) -> ReplayResult:
    """Replay a flight log end to end and (optionally) write the report into ``out_dir``.

    Args:
        log: .tlog or DataFlash .bin path.
        airframe_path: airframe TOML file.
        out_dir: output directory (created).
        options: see :class:`ReplayOptions`.

    Returns:
        The :class:`~gcs_sysid.result.ReplayResult` that the report renders.

    The outputs are written into a staging folder beside ``out_dir`` and moved into place when all
    are written (:class:`gcs_sysid.outdir.StagedDir`): a failed or interrupted replay leaves
    ``out_dir`` as it was, and a finished one leaves only its own files there.

    Raises:
        InputError: unreadable log or airframe, bad options or output folder (all checked before
            the log is decoded: :func:`check_replay`).
        DataError: the log holds nothing the pipeline can use (e.g. no IMU and no attitude), or the
            window lies outside it.
    """
    airframe = check_replay(log, airframe_path, out_dir, options)
    out = Path(out_dir)
    stage = StagedDir(out, "replay", REPLAY_OUTPUTS) if options.write else None
    timings: dict[str, float] = {}
    notes: list[str] = []
    # the worker decodes part of the log, smooths the specific force, then draws the figures
    helper = Helper(enabled=None if options.parallel else False, warm=("gcs_sysid.telemetry.tlog_scan",))
    figures: dict[str, Job] = {}
    csv_job: Job | None = None   # coefficients.csv from the worker's measured fields, written by write_report

    def draw(name: str, function: str, *args) -> None:
        if options.write:
            figures[name] = helper.submit(f"gcs_sysid.report.plots:{function}", *args)

    bar = _progress_bar(options.progress)
    if bar is not None:
        bar.start()
    ok = False
    try:
        with _stage("decode log", timings, bar) as prog:
            # the estimation stage's imports (about 0.8 CPU s) run here while the worker decodes most of the log
            flight = read_log(log, progress=prog, helper=helper, meanwhile=_load_stages)
        from .estimation import estimate_states

        helper.preload(["gcs_sysid.estimation.rates"])   # for the specific-force smoother, next
        if options.notify is not None:
            for note in flight.damage:
                options.notify(f"damaged log: {note}")
        if options.can_log is not None:
            from .telemetry.can_merge import merge_can_log

            flight = merge_can_log(flight, log, options.can_log, options.can_offset)
        flight = cut_window(flight, options.t_from, options.t_to)
        with _stage("estimate states", timings, bar) as prog:
            # the later stages' imports (JAX) run here while the worker smooths the specific force
            states = estimate_states(flight, airframe, rate_hz=options.rate_hz, progress=prog, helper=helper,
                                     meanwhile=_load_model_stages, gls_beta=replay_beta_gls(options))
        _load_model_stages()   # idempotent: done already unless estimation had no specific force to hand over
        from .envelope import confidence_map
        from .gp import fit_gp, load_gp
        from .gp.discrepancy import with_offset_covariance
        from .jaxconfig import enable_compilation_cache
        from .maneuvers import ManeuverConfig, suggest_maneuvers
        from .report import write_report
        from .report.tables import correlation_of, csv_data

        helper.preload(["gcs_sysid.report.plots"])   # matplotlib for the figures, while the GP is fitted
        with _stage("coefficients", timings, bar):
            table = compute_coefficients(states, airframe, gust_rates=replay_gust_rates(options))
        ident = identifiability(states, table)
        held = held_out_mask(table.t, table.valid, options.holdout)
        train = table.valid & ~held
        if replay_air_pitch(options):
            from .aero.airpitch import apply_air_pitch

            with _stage("air pitch rate", timings, bar):
                table, fit, why = apply_air_pitch(table, states, airframe, train)
                if fit is None:                  # else the note is the table's
                    notes.append(why)
        from .aero.gustfilter import (AIR_ROLL_TRAIN, GUST_FILTER, HELDOUT_AIR_ROLL, air_roll_fit, air_roll_target,
                                      filter_gust_table, heldout_air_roll)

        gust_filter = GUST_FILTER if options.gust_filter is None else options.gust_filter
        air_roll = HELDOUT_AIR_ROLL if options.heldout_air_roll is None else options.heldout_air_roll
        # the default gives way to an explicit gust_filter (both would take the gust out of Cl's training rows)
        air_train = (AIR_ROLL_TRAIN and not gust_filter) if options.air_roll_train is None else options.air_roll_train
        if air_train and gust_filter:
            raise InputError("air_roll_train: not with gust_filter (both take the rolling gust out of Cl's training "
                             "rows)")
        air_info = None
        pair_fit = None             # both halves of the pair on: one roll fit (or why it was refused) for the two
        if air_roll != "off":       # the held-out rows at the reconstructed air-relative roll rate
            with _stage("held-out air roll rate", timings, bar):
                if air_train:
                    pair_fit = air_roll_fit(table, states, airframe, train)
                table_air, air_info = heldout_air_roll(table, states, airframe, train, held, mode=air_roll,
                                                       fit=pair_fit)
        Y_fit = table.Y             # the GP's training target (air_roll_train: Cl's moved to the air roll rate)
        if air_train:               # Cl's target less the training rows' smoothed gust moment
            with _stage("air roll training target", timings, bar):
                Y_fit, target_info = air_roll_target(table, states, airframe, train, fit=pair_fit)
            notes.append(target_info["note"])
        yaw_g = None                # air_yaw: the yaw gust rate as a hat, Cl's and Cn's targets at the air's rate
        from .aero.airyaw import AIR_YAW

        if AIR_YAW if options.air_yaw is None else options.air_yaw:
            from .aero.airyaw import air_yaw_target, yaw_gust_hat

            with _stage("air yaw training target", timings, bar):
                yaw_g, why = yaw_gust_hat(states, airframe.b)
                if yaw_g is not None:
                    Y_fit, yaw_info = air_yaw_target(table, Y_fit, yaw_g, train)
                    why = yaw_info["note"]
            notes.append(why)
        x_scale_var, x_map_cov = table.x_scale_var, table.x_map_cov   # the regressors' stated errors, for the model
        from .aero.rateerrors import RATE_ERRORS

        if RATE_ERRORS if options.rate_errors is None else options.rate_errors:
            from .aero.airyaw import yaw_gust_hat
            from .aero.rateerrors import stated_rate_errors

            with _stage("rates' errors", timings, bar):
                if gust_filter:         # the table's p_hat becomes the air-relative estimate: no gyro scale error
                    roll = "p_hat is the gust filter's air-relative rate"
                else:
                    roll = pair_fit if pair_fit is not None else air_roll_fit(table, states, airframe, train)
                if replay_gust_rates(options) is not None:     # r_hat is the air's already (said in the note)
                    r_g = None
                else:
                    r_g = yaw_g if yaw_g is not None else yaw_gust_hat(states, airframe.b)[0]
                x_scale_var, x_map_cov, why = stated_rate_errors(table, train, roll, r_g)
            notes.append(why)
        gust_fit = None
        if gust_filter:
            with _stage("gust filter", timings, bar):
                table, gust_fit = filter_gust_table(table, states, airframe, train,
                                                    method=gust_filter if isinstance(gust_filter, str) else "2sls")
        if air_roll != "off" and gust_filter:   # the held-out rows: the estimate and its variance, not the prior
            X, xv = table.X.copy(), table.x_var
            if air_info is not None:
                j = REGRESSORS.index("p_hat")
                X[:, j] -= air_info["g"]
                xv = np.full(X.shape, np.nan) if table.x_var is None else table.x_var.copy()
                xv[held, j] = table_air.x_var[held, j]
            table_air = replace(table, X=X, x_var=xv, notes=list(table.notes) + [table_air.notes[-1]])
        air_outputs = None          # per output ("MODE:Cl"): these outputs asked at table_air's held-out rows
        if air_roll != "off" and (air_info is None or air_info["outputs"] is None):
            table = table_air       # every output at the air rate (or no estimate: the table and its note)
        elif air_roll != "off":
            air_outputs = air_info["outputs"]
            table = replace(table, notes=list(table.notes) + [table_air.notes[-1]])
        draw("streams", "streams_figure", flight.summaries)   # drawn while the GP is fitted
        draw("states", "states_figure", states, held)
        measured_csv = None                      # coefficients.csv's measured fields, formatted while the GP is fitted
        if stage is not None:
            measured_csv = helper.submit("gcs_sysid.report.tables:csv_measured_text", table.t, table.X, table.Y)
        fit_cols = [i for i, c in enumerate(COEFFICIENTS) if ident[c][0]]
        pred_mean = np.full(table.Y.shape, np.nan)
        pred_sigma = np.full(table.Y.shape, np.nan)        # the coefficient itself (no white measurement noise)
        pred_sigma_obs = np.full(table.Y.shape, np.nan)    # a new measurement of it (with that noise)
        model = None
        envelope = None
        suggestions = []
        gp_summary: dict = {}
        if int(train.sum()) < MIN_TRAIN_ROWS or not fit_cols:
            notes.append(f"no model fitted: {int(train.sum())} valid training samples "
                         f"and {len(fit_cols)} identifiable coefficients")
        else:
            use_adot = options.alpha_dot_hat and table.alpha_dot_hat is not None
            if options.model_in:                 # a saved model takes what it was fitted with
                use_adot = use_adot and load_gp(check_model_state(options.model_in)).n_inputs == len(REGRESSORS) + 1
            X_all = gp_inputs(table, np.ones(len(table.t), bool), use_adot)[0]
            if use_adot:                         # NaN: fit_gp keeps the row only if the gates drop the column
                X_all[~np.isfinite(table.alpha_dot_hat), -1] = np.nan
                if options.model_in:             # a saved model's update needs every value
                    X_all[~np.isfinite(X_all[:, -1])] = np.nan
            X_train, Y_train, partial = training_rows(X_all[train], Y_fit[train][:, fit_cols],
                                                      [COEFFICIENTS[i] for i in fit_cols],
                                                      optional=int(use_adot and not options.model_in))
            if partial:
                notes.append(partial)
            with _stage("learn GP", timings, bar):
                # compiled GP programs are cached on disk (only the first run on a machine compiles)
                enable_compilation_cache()
                if options.model_in:
                    model = load_gp(check_model_state(options.model_in))   # DIR is taken as DIR/model
                    if model.n_outputs != len(fit_cols):
                        raise InputError(f"{options.model_in}: saved model has {model.n_outputs} outputs, "
                                         f"this flight identifies {len(fit_cols)}")
                    model = with_offset_covariance(model.update(X_train, Y_train), table.x_offset_cov,
                                                   rows=len(X_train), scale_var=x_scale_var, map_cov=x_map_cov)
                    notes.append(f"model continued from {options.model_in} (incremental update, "
                                 f"{len(X_train)} new samples)")
                else:
                    cfg = replay_gp_config(options, use_adot)
                    names = REGRESSORS + (("alpha_dot_hat",) if use_adot else ())
                    prior = side_force_rate_prior(SIDE_FORCE_RATE_PRIOR_STD)
                    if prior:                    # the target's linear part: the mixed estimate's (opt-in)
                        from .gp.mixed import apply_slope_prior

                        Y_train, info = apply_slope_prior(X_train[:, :len(REGRESSORS)], Y_train, REGRESSORS,
                                                          [COEFFICIENTS[i] for i in fit_cols], prior)
                        notes += [f"{o}: prior on its {', '.join(d['inputs'])} slopes (mixed estimation): "
                                  + ", ".join(f"{k} {d['ls'][k]:.3g} -> {d['mixed'][k]:.3g}" for k in d["inputs"])
                                  for o, d in info.items()]
                    if gust_fit is not None and gust_filter == "rollgp":   # the roll fit's slopes of Cl (opt-in)
                        from .aero.gustfilter import roll_gp_slopes
                        from .gp.mixed import apply_fixed_slopes

                        Y_train, info = apply_fixed_slopes(X_train[:, :len(REGRESSORS)], Y_train, REGRESSORS,
                                                           [COEFFICIENTS[i] for i in fit_cols],
                                                           {"Cl": roll_gp_slopes(gust_fit)})
                        notes += [f"{o}: {', '.join(d['inputs'])} slopes fixed at the roll fit's (least squares "
                                  "on p_hat - p_g -> fixed): "
                                  + ", ".join(f"{k} {d['ls'][k]:.3g} -> {d['fixed'][k]:.3g}" for k in d["inputs"])
                                  for o, d in info.items()]
                    model, _history = fit_gp(X_train, Y_train, cfg, input_names=names,
                                             output_names=[COEFFICIENTS[i] for i in fit_cols])
                    use_adot = use_adot and model.n_inputs == len(REGRESSORS) + 1   # kept by the gates
                    # the estimator's flight-common regressor offset (alpha: mean vertical wind / V): the
                    # band at exact conditions (gcs-sysid predict) carries it through the slope
                    # and the aided angles' common scale and linear error (docs/gp.md, "The band at exact conditions")
                    model = with_offset_covariance(model, table.x_offset_cov, scale_var=x_scale_var,
                                                   map_cov=x_map_cov)
            gp_summary = model.summary()
            gp_summary["outputs"] = [COEFFICIENTS[i] for i in fit_cols]
            corr = correlation_of(gp_summary, gp_summary["outputs"])
            if corr is not None:                 # drawn while the envelope is mapped
                draw("correlation", "correlation_figure", *corr)
            # the map before the predictions: its figures (the worker's longest) are drawn while the rows
            # are predicted
            with _stage("confidence map", timings, bar):
                envelope = confidence_map(model, table, train, outputs=[COEFFICIENTS[i] for i in fit_cols])
            draw("envelope", "envelope_figures", envelope, table.X[train])
            with _stage("predict", timings, bar):
                white = model.noise_var(white_noise=True) - model.noise_var(white_noise=False)
                band_sign = band_y_var = None
                if replay_coefficient_band(options) == "stated" and model.discrepancy is not None:
                    from .aero.coefficients import stated_output_variance

                    band_y_var = stated_output_variance(states, airframe)
                    band_sign = np.array([STATED_BAND_SIGN.get(COEFFICIENTS[i], np.nan) for i in fit_cols])
                    band_less_white = np.array([COEFFICIENTS[i] in STATED_BAND_LESS_WHITE for i in fit_cols])
                    if band_y_var is None:          # the outputs that need it keep the white band
                        band_y_var = np.full(table.Y.shape, np.nan)
                        notes.append("coefficient band: the estimator states no measurement error; "
                                     + ", ".join(c for c, v in STATED_BAND_SIGN.items() if v) + " keep the white band")

                no_stated = np.array([COEFFICIENTS[i] in WHITE_BAND_NO_STATED_INPUT for i in fit_cols])
                noise_coef = model.noise_var(white_noise=False)     # the noise less its white part

                def predict_rows(tab, rows, ks):
                    """The model's mean and both bands for outputs ``ks`` (indices into ``fit_cols``) on ``tab``'s
                    ``rows``, with the estimator's stated per-row air-angle variance (errors the residuals cannot
                    show); the coefficient's band is the same less the white measurement noise (docs/gp.md, "Two
                    bands"), or for the outputs of STATED_BAND_SIGN the stated band (gp.coefband)."""
                    Xq, xv = gp_inputs(tab, rows, use_adot)
                    # one pass: predict's mean and variance (to the last bit) and two of its terms
                    mean, var, lat, learned = model.predict_parts(Xq, x_var=xv)
                    at = np.ix_(rows, [fit_cols[k] for k in ks])
                    if band_sign is not None:        # the stated band (gp.coefband)
                        from .gp.coefband import stated_band_variance

                        vs = stated_band_variance(model, Xq, band_y_var[rows][:, fit_cols], band_sign,
                                                  parts=(lat, learned), less_white=band_less_white)[:, ks]
                    mean, var = mean[:, ks], var[:, ks]
                    pred_mean[at] = mean
                    pred_sigma_obs[at] = np.sqrt(var)
                    pred_sigma[at] = np.sqrt(np.maximum(var - white[None, ks], 0.0))
                    if no_stated[ks].any():          # the white band with the learned input noise alone
                        v0 = (lat + learned)[:, ks] + noise_coef[None, ks]
                        pred_sigma[at] = np.where(no_stated[ks][None, :], np.sqrt(v0), pred_sigma[at])
                    if band_sign is not None:
                        pred_sigma[at] = np.where(np.isfinite(vs), np.sqrt(vs), pred_sigma[at])

                rows = table.valid & np.all(np.isfinite(table.X), axis=1)
                if rows.any():
                    predict_rows(table, rows, list(range(len(fit_cols))))
                rows_air = held & table_air.valid & np.all(np.isfinite(table_air.X), axis=1) if air_outputs else None
                if air_outputs and rows_air.any():   # per output: these at the air-relative roll rate (opt-in)
                    predict_rows(table_air, rows_air,
                                 [k for k, i in enumerate(fit_cols) if COEFFICIENTS[i] in air_outputs])
                if yaw_g is not None:   # air_yaw: its outputs asked at r_hat - r_hat_g (Cl also at its air roll rate)
                    from .aero.airyaw import AIR_YAW_OUTPUTS

                    ir = REGRESSORS.index("r_hat")
                    for name in AIR_YAW_OUTPUTS:
                        if COEFFICIENTS.index(name) not in fit_cols:
                            continue
                        base = table_air if air_outputs and name in air_outputs else table
                        Xy = base.X.copy()
                        Xy[:, ir] -= yaw_g
                        rows_y = held & base.valid & np.all(np.isfinite(Xy), axis=1)
                        if rows_y.any():
                            predict_rows(replace(base, X=Xy), rows_y, [fit_cols.index(COEFFICIENTS.index(name))])
            # the measurements are drawn against the band for a measurement
            draw("coefficients", "coefficients_figure", table, pred_mean, pred_sigma_obs, held, ident)
            if stage is not None:
                # coefficients.csv: its measured fields were formatted by the worker while the GP was fitted; the
                # model's fields are formatted and the file written here, by write_report while the worker draws
                # the last figures (after the predictions the worker's figures are the longer chain): a deferred
                # call, a Job with no worker behind it, run when write_report collects it
                csv_job = Job("gcs_sysid.report.tables:write_csv_data",
                              (csv_data(table.t, table.X, table.Y, pred_mean, pred_sigma, pred_sigma_obs, held),
                               stage.path / "coefficients.csv", measured_csv.result()), {}, None)
            with _stage("suggest maneuvers", timings, bar):
                gate = {c: error_pct(pred_mean[held, i], table.Y[held, i]) for i, c in enumerate(COEFFICIENTS)}
                cfg = None if options.targets is None else ManeuverConfig(targets=options.targets)
                try:
                    suggestions = suggest_maneuvers(envelope, model, table, airframe, config=cfg,
                                                    heldout_error_pct=gate, identifiable=ident)
                except InputError as e:
                    # a limit the flown envelope cannot give (e.g. alpha_max from an alpha whose flight-common
                    # offset, the mean vertical wind, puts its whole range below 0): the model and report stand
                    suggestions = []
                    notes.append(f"no manoeuvre suggestions: {e}")
            if suggestions:
                draw("suggestions", "suggestions_figure", list(suggestions))
        metrics: dict[str, dict[str, float]] = {}
        for i, name in enumerate(COEFFICIENTS):
            y = table.Y[:, i]
            metrics[name] = {
                "error_pct_heldout": error_pct(pred_mean[held, i], y[held]),
                "error_pct_train": error_pct(pred_mean[train, i], y[train]),
                "rms_measured": float(np.sqrt(np.nanmean(y[table.valid] ** 2))) if table.valid.any() else float("nan"),
                "n_heldout": int(np.isfinite(pred_mean[held, i]).sum()),
                "n_train": int(train.sum()),
            }
        poor = [c for c in COEFFICIENTS if ident[c][0] and metrics[c]["error_pct_heldout"] > POOR_HELDOUT_PCT]
        if poor:
            notes.append("the model does not predict the held-out segment for " + ", ".join(
                f"{c} ({metrics[c]['error_pct_heldout']:.0f} %)" for c in poor)
                + ": these estimates are not trustworthy; likely causes: forces the airframe file does not "
                  "model (thrust without a thrust model, VTOL lift motors), too few samples or too little "
                  "excitation, or a held-out segment outside the trained envelope")
        weak_moments = [c for c in MOMENT_COEFFICIENTS if not ident[c][0]]
        if weak_moments:
            notes.append("not identified: " + "; ".join(f"{c} ({ident[c][1]})" for c in weak_moments))
        model_path = ""
        if model is not None and stage is not None:
            model_path = str(out / "model")
            model.save(stage.path / "model")
        result = ReplayResult(
            log_path=str(log), airframe_name=airframe.name, airframe_path=str(airframe_path),
            vehicle=dict(flight.vehicle), window=(options.t_from, options.t_to),
            summaries=dict(flight.summaries), messages=dict(flight.messages), states=states, table=table,
            held_out=held, train=train, pred_mean=pred_mean, pred_sigma=pred_sigma, pred_sigma_obs=pred_sigma_obs,
            metrics=metrics,
            identifiable=ident, envelope=envelope, suggestions=suggestions, gp_summary=gp_summary,
            model_path=model_path, missing=list(states.missing),
            notes=list(flight.warnings) + list(states.notes) + list(table.notes) + notes, timings=timings,
        )
        if stage is not None:
            with _stage("write report", timings, bar):
                write_report(result, stage.path, figures=figures, csv=csv_job)
                stage.commit()
        ok = True
        return result
    finally:
        if stage is not None and not ok:
            helper.close(wait=False)   # stopped first, before its staged folder is removed
            stage.abort()
        helper.close(wait=ok)
        if bar is not None:
            bar.stop()
