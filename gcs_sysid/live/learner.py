"""The incremental pipeline of a live session: records in, coefficient rows learned by the GP.

The same stages as the replay (:mod:`gcs_sysid.pipeline`), run causally on a lagging window:

1. every received record (tlog stamp + raw packet) is appended to a window of the last
   ``window_s`` seconds (tlog stamp time, i.e. arrival time);
2. every ``step_s`` seconds of stamp time the window's bytes are decoded by the telemetry layer's
   own tlog decoder (:func:`gcs_sysid.telemetry.tlog_reader.read_tlog`: no second decoder), the
   states are estimated with the smoother (:func:`gcs_sysid.estimation.estimate_states`) and the
   coefficients computed (:func:`gcs_sysid.aero.compute_coefficients`);
3. the rows between the last learned vehicle time and ``lag_s`` before the window's end (the
   smoother has had its future context for them) are new: the first ``min_rows`` of them fit the GP
   (:func:`gcs_sysid.gp.fit_gp`), later ones go to its incremental update (``model.update``); with
   ``LearnOptions.air_roll`` Cl's target is first moved to the air-relative roll rate (the air-rate pair's
   roll fit made once on the first fit's rows, its fixed parameters on every later window; ``docs/live.md``,
   "The air-rate pair");
4. every ``refresh_every`` steps the confidence map and the maneuver suggestions are refreshed;
5. with ``LearnOptions.lift_line`` (opt-in) each window's alpha level is set on the lift line of the windows so far,
   and the final step moves every kept row onto the line of all windows and learns the GP again on them
   (:meth:`Learner.relevel`; ``docs/live.md``, "The lift line carried across windows").

The schedule is driven by the records' stamps, never by the processing's wall clock, so feeding the
records of a session's ``raw.tlog`` again (:func:`learn_from_tlog`) gives the same windows, the same
rows and the same model.
"""

from __future__ import annotations

import struct
import time
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..aero.table import COEFFICIENTS, REGRESSORS, CoefficientTable
from ..airframe import Airframe
from ..errors import InputError, SysidError
from .heap import release_free_heap

__all__ = ["LearnOptions", "Learner", "learn_from_tlog", "iter_tlog_records", "GP_NOISE", "learner_gp_config"]

#: The live learner's GP noise (a name of :data:`gcs_sysid.pipeline.GP_NOISE_MODES`) when ``LearnOptions.gp_noise``
#: is None: ``"learned"`` since the twenty-sixth session (i8-live), the replay's default too
#: (:data:`gcs_sysid.pipeline.GP_NOISE`), so ``listen`` and ``replay`` on the same flight learn the same noise model.
#: Under the default rule for GP changes (two GP seeds against ``"independent"``, the default until then, at the same
#: seed) on 66 tuning flights (22 aircraft x light s1-3, streamed through the learner;
#: ``benchmarks/eval_live_jsbsim.py``): flight x count flips +34/-11 at GPConfig.seed 0 and +33/-12 at seed 1, learned
#: output correlations above 0.5 on 24 -> 8 and 25 -> 7 flights, 5 aircraft losing a count at both seeds where
#: ``"independent"`` merely reseeded loses one on 10 (docs/benchmarks.md, "Twenty-sixth session, i8-live"; docs/live.md,
#: "The GP's noise").
GP_NOISE = "learned"


@dataclass(frozen=True)
class LearnOptions:
    """Schedule and sizes of the incremental pipeline.

    ``window_s`` and ``step_s`` count arrival time (the records' tlog stamps: real time on a live
    link, compressed N times when a log player streams at xN); ``lag_s`` counts vehicle time.

    Attributes:
        window_s: stamp time (s) of records decoded and smoothed per step.
        step_s: stamp time (s) between steps.
        lag_s: rows within this vehicle time (s) of the window's end wait for the next step (the
            smoother's future context).
        rate_hz: estimation grid, Hz.
        min_rows: rows collected before the GP is first fitted.
        refresh_every: steps between refreshes of the confidence map and the suggestions.
        max_rows: learned rows kept for the confidence map (every other one is dropped when full).
        n_inducing: inducing points of the global GP (None: the GP's default).
        gp_noise: the GP's output noise, a name of :data:`gcs_sysid.pipeline.GP_NOISE_MODES` (``"learned"``: a
            ``P x P`` noise covariance learned with the hyperparameters, only its variances in the posterior, the
            default here and in the replay; ``"independent"``: one variance per output, the default until the
            twenty-sixth session; ``"full"``: the learned covariance in the posterior too; ``docs/gp.md``, "Noise");
            None: :data:`GP_NOISE`. Rows that miss an output in the first fit make it ``independent`` (the fit's
            note: the noise correlation needs complete rows), as in the replay. It sets the first fit's
            ``GPConfig`` (:func:`learner_gp_config`); the incremental updates and the hyperparameter refreshes keep
            that config.
        gp_seed: ``GPConfig.seed`` of the fit (the hyperparameters' row subset, the inducing-point choice).
        hyper_every: rows learned between light hyperparameter refreshes of the GP
            (:func:`gcs_sysid.gp.streaming.light_refresh`: warm start, 40 Adam steps on 1,000 stored
            rows; so the length-scales follow an envelope that grows); 0: never.
        max_window_s: longest window (stamp time) a step decodes when steps were coalesced (below).
        trim_heap: after each step that decoded a window, and between the stages of a refresh (after
            the hyperparameter refresh, between the confidence map and the suggestions), give the C
            heap's free pages back to the system (:func:`gcs_sysid.live.heap.release_free_heap`), so
            the resident size follows what is held, not the high-water mark of the longest window or
            refresh so far, and one stage's freed temporaries do not stack under the next one's.
        air_roll: the air-rate pair's training half (``gcs-sysid listen --air-roll on|off``; on by default since the
            sixty-sixth session, ``docs/live.md``, "The air-rate pair"): the replay's roll fit with its two checks
            (:func:`gcs_sysid.aero.gustfilter.air_roll_fit`: the Dryden check and the instruments' check) made once
            on the rows of the GP's first fit, their Cl moved to the air-relative roll rate
            (:func:`~gcs_sysid.aero.gustfilter.air_roll_target`), and every later window's new rows' Cl moved with
            that fit's fixed parameters (:func:`~gcs_sysid.aero.gustfilter.air_roll_target_on_rows`, the gust
            smoothed over the window on its residual less the window's mean) before ``model.update``. A refused fit
            leaves Cl at the gyro's rate for the whole session (the learner's notes and ``air_roll`` status say why).
            The inputs stay the gyro's for every output; the learner asks its model nowhere at the air rate.
        stated_errors: give the model the windows' stated regressor errors for its band at exact conditions (what
            ``gcs-sysid predict`` states from the saved model), pooled over the windows learned
            (:class:`gcs_sysid.aero.errorpool.WindowErrorPool`); the replay gives its model the flight's
            (``docs/live.md``, "The band at exact conditions"). False: none (the learner before the sixty-fifth
            session). The model's mean and its bands at the flight's own regressors do not change.
        rate_errors: with ``stated_errors``, also the gyro rates' errors (:mod:`gcs_sysid.aero.rateerrors`; ``gcs-sysid
            listen --rate-errors on|off``); None: :data:`gcs_sysid.aero.rateerrors.RATE_ERRORS`, as the replay.
        lift_line: carry a lift line across the windows (``gcs-sysid listen --lift-line on|off``; opt-in: the rule
            written for it held for CZ and failed for Cm on fresh flights, ``docs/benchmarks.md``, "Sixty-seventh
            session"): every window's rows, at the window's own alpha level, join a pool
            (:class:`gcs_sysid.aero.liftline.LiftLinePool`: slopes within windows, the level from all of them); the
            next window's aided alpha is set on the pool's line (:func:`gcs_sysid.estimation.estimate_states`,
            ``lift_line``) instead of on its own 30 s of mean vertical wind, and at the session's end every kept row
            is moved onto the line of all windows and learned again (:meth:`Learner.relevel`); both only where the
            line's level is known to :data:`gcs_sysid.aero.liftline.MAX_LEVEL_SIGMA` (``docs/live.md``, "The lift
            line carried across windows").
        alpha_profile: the windows' alpha aiding's columns whose slopes are chosen by the gust model's likelihood
            (``("delta_e",)``, ``gcs-sysid listen --alpha-profile on``: the elevator's slope, which least squares loads
            with the gust's normal force in closed loop, so that the aided alpha carries a share of the elevator and
            the model reads ``Cm_delta_e - k Cm_alpha``; :func:`gcs_sysid.estimation.estimate_states`,
            ``alpha_profile``); None: :data:`gcs_sysid.estimation.airangles.ALPHA_PROFILE_COLUMNS` (``()``, least
            squares), as the replay and the diagnosis.
        air_pitch: each window's ``q_hat`` moved to the air-relative estimate, the gyro's less the pitch gust rate
            from the window's reconstructed wind times its share in Cm (free sign, applied only when the fit shows
            it; :mod:`gcs_sysid.aero.airpitch`, ``gcs-sysid listen --air-pitch on|off``), the share fitted on every
            window's new rows so far together, each window with its own level
            (:class:`~gcs_sysid.aero.airpitch.AirPitchPool`, since the sixty-ninth session: a fit per window moved
            some windows and left others at the gyro's rate). On by default since the sixty-ninth session: the rule
            written before its run held on fresh JSBSim flights (seeds 30-31, 25 aircraft, GP seeds 0 and 1: 445 of
            500 windows moved; at JSBSim's regressors Cm 45.7 -> 37.5 % median, better on 36 of 50 flights and worse
            on 11; held-out flight x coefficients within the lines +8/-0 and +6/-0 at the two GP seeds;
            ``docs/benchmarks.md``, "Sixty-ninth session"); with a fit per window two rules had failed (sixty-eighth
            session). ``False``: the gyro's ``q_hat``, as before.
        air_pitch_relearn: with ``air_pitch``, at the session's end every kept row's ``q_hat`` is moved to the final
            pooled share's (the gyro's less ``kappa g`` with the share of all windows; the gyro's where that fit
            does not pass the gates) and the GP is learned again on the kept rows as the session learned them
            (:meth:`Learner.pitch_relearn`; ``gcs-sysid listen --air-pitch-relearn on|off``): each window was
            learned at the share of its time, which settles over the windows and starts at the gyro's rate on
            slow aircraft. Opt-in (``docs/live.md``, "The air-relative pitch rate in the windows").
    """

    window_s: float = 30.0
    step_s: float = 10.0
    lag_s: float = 3.0
    rate_hz: float = 50.0
    min_rows: int = 500
    refresh_every: int = 3
    max_rows: int = 20000
    n_inducing: int | None = None
    gp_noise: str | None = None
    gp_seed: int = 0
    hyper_every: int = 15000
    max_window_s: float | None = None
    trim_heap: bool = True
    air_roll: bool = True
    stated_errors: bool = True
    rate_errors: bool | None = None
    lift_line: bool = False
    alpha_profile: tuple[str, ...] | None = None
    air_pitch: bool = True
    air_pitch_relearn: bool = False

    def __post_init__(self):
        if self.air_pitch_relearn and not self.air_pitch:
            raise InputError("--air-pitch-relearn on needs --air-pitch on (it moves the rows to the pooled share)")
        if not (self.step_s > 0 and self.window_s > self.step_s and self.lag_s >= 0):
            raise InputError(f"--window {self.window_s} s must be longer than --step {self.step_s} s > 0, "
                             f"and --lag {self.lag_s} s >= 0")
        if self.gp_noise is not None:
            from ..pipeline import gp_noise_fields

            gp_noise_fields(self.gp_noise)      # InputError on an unknown name, before any record is read


def learner_gp_config(options: LearnOptions):
    """The :class:`gcs_sysid.gp.GPConfig` of the live learner's first fit.

    Args:
        options: the learner's options (``gp_noise``, ``gp_seed``, ``n_inducing`` are read).

    Returns:
        ``GPConfig()`` with the noise fields of :func:`gcs_sysid.pipeline.gp_noise_fields` (``options.gp_noise``, or
        :data:`GP_NOISE` when None), ``seed = options.gp_seed`` and ``n_inducing`` when given. The replay adds its
        own settings on top (:func:`gcs_sysid.pipeline.replay_gp_config`: the alpha_dot input, the coupling test);
        with the same noise name the noise fields are the same.

    Raises:
        InputError: an unknown ``options.gp_noise``.
    """
    from ..gp import GPConfig
    from ..pipeline import gp_noise_fields

    extra = {} if options.n_inducing is None else {"n_inducing": options.n_inducing}
    return GPConfig(**gp_noise_fields(GP_NOISE if options.gp_noise is None else options.gp_noise),
                    seed=int(options.gp_seed), **extra)


@dataclass
class Learner:
    """Incremental learner fed with tlog records.

    Args:
        airframe: the airframe.
        options: :class:`LearnOptions`.

    Attributes:
        model: the GP (None until ``min_rows`` rows were learned).
        outputs: coefficient names of the model's output columns.
        X, Y, t: learned rows kept (bounded by ``max_rows``), shapes (N, 10), (N, 6), (N,).
        n_learned: rows given to the GP so far.
        envelope, suggestions: the latest confidence map and maneuver suggestions.
        identifiable: coefficient -> (ok, why) of the latest window.
        notes: what happened (reboots, skipped windows), in order.
        steps: steps run; timings: stage -> seconds of the last step.
        can_source: optional callable returning DroneCAN streams on the host clock (the session's
            :meth:`~gcs_sysid.telemetry.can.CanListener.streams`, or a decoded ``can.log``); each window
            then gets them merged on its vehicle time (:mod:`gcs_sysid.telemetry.can_merge`; only CAN
            samples stamped up to the window's last record, so a replay of ``raw.tlog`` + ``can.log``
            sees what the session saw), and measured surface positions replace PWM per the airframe's
            ``[[can_actuator]]`` map.
        control_sources: control -> where the latest window's deflections came from (PWM or CAN).
        behind: optional callable, True while the learner is behind its input (the session: too many
            records queued). Then a due step is *coalesced* into the next one (the window keeps every
            record since the start of the last window decoded, up to ``max_window_s``, so no row is
            left out; one smoothing pass over the longer window instead of several overlapping ones)
            and the confidence map and suggestions wait until it has caught up. Neither happens when
            it keeps up; the stamps of the steps merged are kept (``coalesced_at``, in
            ``session.json`` as ``coalesced_at_us``), so a replay of ``raw.tlog`` given them
            (:func:`learn_from_tlog`'s ``coalesced_at``) follows the same schedule and learns exactly
            what the session learned.
        coalesced, refreshes_deferred: steps merged and map refreshes put off while behind.
        coalesced_at: stamps (us) of the records at which a due step was merged into the next.
        air_roll: the air-rate pair's status (``LearnOptions.air_roll``): ``state`` (``"off"``, ``"waiting"`` for
            the first fit, ``"applied"`` or ``"refused"``), ``note`` (the replay's wording: what was fitted, or why
            not), and once applied ``Cl_p``, ``tau_s``, ``sigma`` (the roll fit's), ``rows_moved`` (rows learned
            with a moved Cl so far) and ``sd_first`` (the first fit's correction SD, Cl units).
        errors: the pooled regressor errors the model carries (``LearnOptions.stated_errors``): ``state`` (``"off"``,
            ``"pooling"``), ``windows``, ``rows`` and ``note`` (what is stated, :meth:`WindowErrorPool.statement`).
        air_pitch: the air-relative pitch rate's status (``LearnOptions.air_pitch``): ``state`` (``"off"``,
            ``"waiting"`` before the first window, ``"applied"``, ``"gyro's rate"`` while the pooled fit does not show
            the share, ``"no gust rate"``), ``windows`` seen, ``applied`` (windows moved), the pooled ``kappa`` and
            ``t``, ``rows_pooled`` and the fit's ``note``; after :meth:`pitch_relearn` also ``relearn`` (``kappa``
            the rows were moved to, ``rows_moved``, ``moved_rms`` in ``q_hat`` units, ``rows`` learned again).
        lift_line: the carried lift line's status (``LearnOptions.lift_line``): ``state`` (``"off"``, ``"pooling"``
            before the pool states a line, ``"carried"``, and at the end ``"relevelled"`` or ``"own levels"``,
            :meth:`relevel`), ``windows`` (pooled), ``handed`` (windows a carried line moved), ``note``
            (:meth:`~gcs_sysid.aero.liftline.LiftLinePool.note` and what the end did) and after the end
            ``moved_rms``, ``level_sigma`` (rad) and ``rows``.
    """

    airframe: Airframe
    options: LearnOptions = field(default_factory=LearnOptions)
    model: object = None
    outputs: tuple[str, ...] = ()
    n_learned: int = 0
    envelope: object = None
    suggestions: list = field(default_factory=list)
    identifiable: dict = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    steps: int = 0
    timings: dict[str, float] = field(default_factory=dict)
    can_source: object = None
    control_sources: dict = field(default_factory=dict)
    behind: object = None
    coalesced: int = 0
    refreshes_deferred: int = 0
    coalesced_at: list = field(default_factory=list)
    air_roll: dict = field(default_factory=dict)
    errors: dict = field(default_factory=dict)
    lift_line: dict = field(default_factory=dict)

    def __post_init__(self):
        from ..jaxconfig import enable_compilation_cache, enable_x64, limit_blas_threads

        enable_x64()             # the GP's numerics need float64 (docs/gp.md); the replay does the same
        limit_blas_threads(1)    # small factorisations: one BLAS thread is faster (docs/gp.md)
        enable_compilation_cache()   # compiled GP programs load from disk after the first session
        self._window: deque = deque()
        self._next_step_us: int | None = None
        self._t_done: float | None = None
        self.X = np.zeros((0, len(REGRESSORS)))
        self.Y = np.zeros((0, len(COEFFICIENTS)))
        self.t = np.zeros(0)
        self._pending: list[tuple[np.ndarray, np.ndarray]] = []
        self._hold_us: int | None = None         # keep records from here while steps are coalesced
        self._last_step_us: int | None = None
        self._refresh_due = False
        self._since_hyper = 0
        self._due_us = 0
        self._replayed: set | None = None     # coalesced stamps of a session being replayed
        self._roll_fit = None                 # the air-rate pair's roll fit (LearnOptions.air_roll), once applied
        self._pending_roll: dict | None = None   # the pending rows' grid slices for that fit
        self.air_roll = {"state": "waiting" if self.options.air_roll else "off", "note": ""}
        self._errors = None                   # the windows' stated regressor errors (LearnOptions.stated_errors)
        if self.options.stated_errors:
            from ..aero.errorpool import WindowErrorPool
            from ..aero.rateerrors import RATE_ERRORS

            rates = RATE_ERRORS if self.options.rate_errors is None else self.options.rate_errors
            self._errors = WindowErrorPool(rate_errors=rates)
        self.errors = {"state": "pooling" if self._errors is not None else "off", "windows": 0, "rows": 0,
                       "note": ""}
        self._line = None                     # the lift line carried across windows (LearnOptions.lift_line)
        if self.options.lift_line:
            from ..aero.liftline import LiftLinePool

            self._line = LiftLinePool(self.options.window_s)
        self.lift_line = {"state": "pooling" if self._line is not None else "off", "windows": 0, "handed": 0,
                          "note": ""}
        self._pitch_pool = None               # the pitch gust share pooled over windows (LearnOptions.air_pitch)
        if self.options.air_pitch:
            from ..aero.airpitch import AirPitchPool

            self._pitch_pool = AirPitchPool()
        self.air_pitch = {"state": "waiting" if self.options.air_pitch else "off", "windows": 0, "applied": 0,
                          "note": ""}
        self._win = np.zeros(0, int)          # the window (learning call) each kept row came from
        self._win_key = 0
        # with LearnOptions.air_pitch_relearn: each kept row's pitch gust rate as a hat (0 where unknown) and the
        # share its q_hat was moved with (0: the gyro's rate)
        self._pitch_g = np.zeros(0)
        self._pitch_k = np.zeros(0)
        self._pitch_window: tuple | None = None   # the current window's (g (T,), share applied)

    # --- feeding -----------------------------------------------------------------------------

    def feed(self, stamp_us: int, packet: bytes) -> bool:
        """Add one record; run a step when its stamp reaches the schedule. Returns True if a step ran."""
        w = self._window
        w.append((stamp_us, packet))
        opt = self.options
        if self._next_step_us is None:
            self._next_step_us = stamp_us + int(opt.window_s * 1e6)
        horizon = stamp_us - int(opt.window_s * 1e6)
        if self._hold_us is not None:   # steps coalesced: keep the records since the last window's start
            longest = opt.max_window_s if opt.max_window_s is not None else 4.0 * opt.window_s
            horizon = max(min(horizon, self._hold_us), stamp_us - int(longest * 1e6))
        while w and w[0][0] < horizon:
            w.popleft()
        if stamp_us >= self._next_step_us:
            self._next_step_us = stamp_us + int(opt.step_s * 1e6)
            self._due_us = stamp_us
            if self.behind is not None and self._last_step_us is not None and self.behind():
                if self._hold_us is None:
                    self._hold_us = self._last_step_us - int(opt.window_s * 1e6)
                self.coalesced += 1
                self.coalesced_at.append(int(stamp_us))
                return False
            self._hold_us = None
            self._last_step_us = stamp_us
            self.step()
            return True
        return False

    def finish(self) -> None:
        """Learn what is left in the window (at the end of a session): rows up to its very end."""
        if self._window:
            self.step(final=True)       # with LearnOptions.lift_line it relevels before its refresh
        else:
            if self.options.air_pitch_relearn:
                self.pitch_relearn()
            if self._line is not None:
                self.relevel()
        if self._errors is not None and self.model is not None:
            self.notes.append(f"end: {self.errors['note']}")

    # --- one step ----------------------------------------------------------------------------

    def step(self, final: bool = False) -> None:
        """Decode, smooth and learn the current window (see the module docstring)."""
        from ..aero import compute_coefficients
        from ..estimation import estimate_states
        from ..pipeline import identifiability
        from ..telemetry.tlog_reader import read_tlog

        t0 = time.perf_counter()
        data = b"".join(struct.pack(">Q", s) + p for s, p in self._window)
        self.steps += 1
        try:
            flight = read_tlog("live window", data)
            if not flight.streams:
                raise SysidError("no usable messages in the window")
            if self.can_source is not None:
                flight = self._merge_can(flight, data)
            line = self._line.carried() if self._line is not None else None
            states = estimate_states(flight, self.airframe, rate_hz=self.options.rate_hz, lift_line=line,
                                     alpha_profile=self.options.alpha_profile)
            self.control_sources = {k: v for k, v in states.sources.items() if k.startswith("delta_")}
            table = compute_coefficients(states, self.airframe)
        except SysidError as exc:
            self.notes.append(f"step {self.steps}: window skipped ({exc})")
            return
        if not len(table.t):
            self.identifiable = identifiability(states, table)
            return
        end = table.t[-1] if final else table.t[-1] - self.options.lag_s
        start = self._t_done
        if start is not None and end < start - 1.0:
            # the vehicle clock started again (a reboot): this window's times are on a new axis
            self.notes.append(f"step {self.steps}: vehicle time went back from {start:.1f} s to "
                              f"{table.t[-1]:.1f} s (reboot): learning resumes on the new clock")
            start = table.t[0] + self.options.lag_s
        rows = table.valid & (table.t <= end) & np.all(np.isfinite(table.X), axis=1)
        if start is not None:
            rows &= table.t > start
        self._t_done = max(end, start) if start is not None else end
        if self._pitch_pool is not None:      # the new rows into the pool; the pooled share moves the window's q_hat
            table = self._air_pitch(table, states, rows)
        t1 = time.perf_counter()
        self.identifiable = identifiability(states, table)
        self._window_in(table, rows, states)
        self._learn(table, rows, states)
        if final and self.options.air_pitch_relearn:
            self.pitch_relearn()
        if final and self._line is not None:
            self.relevel()
        t2 = time.perf_counter()
        if self.model is not None and (final or self._refresh_due or self.steps % self.options.refresh_every == 0):
            if not final and self.behind is not None and self._replayed is None and self.behind():
                self._refresh_due = True            # the map and suggestions wait until caught up
                self.refreshes_deferred += 1
            else:
                self._refresh_due = False
                self.refresh()
        t3 = time.perf_counter()
        del data, flight, states, table          # the window's temporaries, before the trim
        if self.options.trim_heap:
            release_free_heap()
        self.timings = {"decode+estimate": t1 - t0, "learn": t2 - t1, "refresh": t3 - t2,
                        "trim": time.perf_counter() - t3}

    def _air_pitch(self, table: CoefficientTable, states, rows: np.ndarray) -> CoefficientTable:
        """The window's table with ``q_hat`` at the air-relative estimate where the session's pooled fit shows the
        pitch gust's share (``LearnOptions.air_pitch``; the window's new ``rows`` (T,) bool added to the
        :class:`gcs_sysid.aero.airpitch.AirPitchPool` first); :attr:`air_pitch` counts the windows and says the
        pooled fit, the notes each change of state."""
        from ..aero.airpitch import apply_air_pitch, pitch_gust_hat

        g, why = pitch_gust_hat(states, self.airframe.c, self.airframe.b)
        if g is None:
            table, fit, note = table, None, why
        else:
            table, fit, note = apply_air_pitch(table, states, self.airframe, rows, pool=self._pitch_pool, g=g)
        applied = fit is not None and fit["applied"]
        self._pitch_window = (None if g is None else np.where(np.isfinite(g), g, 0.0),
                              float(fit["kappa"]) if applied else 0.0)
        state = "no gust rate" if fit is None else "applied" if applied else "gyro's rate"
        if state != self.air_pitch["state"]:
            self.notes.append(f"step {self.steps}: {note}")
        self.air_pitch = {"state": state, "windows": self.air_pitch["windows"] + 1,
                          "applied": self.air_pitch["applied"] + int(state == "applied"),
                          "kappa": None if fit is None else fit["kappa"], "t": None if fit is None else fit["t"],
                          "rows_pooled": self._pitch_pool.rows, "note": note}
        return table

    def _window_in(self, table: CoefficientTable, rows: np.ndarray, states) -> None:
        """A window's rows are about to be learned (``rows`` (T,) bool): a new key for the rows kept, and with
        ``LearnOptions.lift_line`` the rows into the lift-line pool (at the window's own level, under that key).
        The step runs it before :meth:`_learn`; so does a caller feeding :meth:`_learn` recorded windows."""
        if not rows.any():
            return
        self._win_key += 1
        if self._line is None:
            return
        self._line.add(table, rows, states, self.airframe, key=self._win_key)
        self.lift_line = {**self.lift_line, "state": "carried" if self._line.line() is not None else "pooling",
                          "windows": self._line.windows, "handed": self._line.handed, "note": self._line.note()}
        self.lift_line = {**self.lift_line, "state": "carried" if self._line.line() is not None else "pooling",
                          "windows": self._line.windows, "handed": self._line.handed, "note": self._line.note()}

    def relevel(self) -> None:
        """Move every kept row's alpha onto the lift line of all windows so far and learn the GP again on them
        (``LearnOptions.lift_line``; run by the final step, before its refresh; ``docs/live.md``, "The lift line
        carried across windows").

        Each window's rows were learned at the level of the line carried when it was estimated; the line of all
        windows is the best level the session has, and rows at one level are what a GP learns a slope from (the
        windows' levels differ by degrees; :mod:`gcs_sysid.aero.liftline`). The rows kept (:attr:`X`, at most
        ``max_rows``, thinned evenly beyond) are moved by their window's :meth:`LiftLinePool.move` and learned
        again as the session learned them: the first fit on the first ``min_rows`` rows (the same outputs and
        ``GPConfig``), then ``model.update`` window by window with the light hyperparameter refreshes; targets as
        learned (the air-rate pair's Cl included). The model's band at exact conditions then states alpha's offset
        as the line's level's 1-sigma (``CL0_sigma / CL_alpha``) in place of the windows' own. Where that 1-sigma
        exceeds :data:`gcs_sysid.aero.liftline.MAX_LEVEL_SIGMA` (1 deg) the rows go back to their own windows'
        levels instead (learned again only if a carried line had moved some) and the windows' own statement stays.
        Nothing happens without a model or a line; :attr:`lift_line` says what was done (``state`` ``"relevelled"``
        or ``"own levels"``, ``moved_rms`` and ``level_sigma`` rad, ``rows``).
        """
        from ..aero.liftline import MAX_LEVEL_SIGMA

        line = self._line.line() if self._line is not None else None
        if self.model is None or line is None or not len(self.t):
            if self._line is not None:
                self.lift_line = {**self.lift_line, "note": self._line.note() + "; rows not relevelled"}
            return
        s_a = line["CL0_sigma"] / line["CL_alpha"]
        onto = line if s_a <= MAX_LEVEL_SIGMA else None
        keys, inv = np.unique(self._win, return_inverse=True)
        moves = np.array([self._line.move(int(k), onto) for k in keys])[inv]      # one move per window
        rms = float(np.sqrt(np.mean(moves**2)))
        base = {**self.lift_line, "moved_rms": rms, "level_sigma": float(s_a), "rows": 0}
        if onto is None:
            self.lift_line = {**base, "state": "own levels",
                              "note": (f"{self._line.note()}; its level's 1-sigma {np.degrees(s_a):.2f} deg is above "
                                       f"{np.degrees(MAX_LEVEL_SIGMA):g} deg: the rows keep their own windows' "
                                       "levels" + (f" (moved back by {np.degrees(rms):.2f} deg RMS and learned again)"
                                                   if rms > 0 else ""))}
            self.notes.append(f"step {self.steps}: {self.lift_line['note']}")
            if rms == 0:
                return
        self.X[:, REGRESSORS.index("alpha")] += moves
        n = self._learn_again()
        self.lift_line["rows"] = n
        if onto is None:
            self._state_errors()
            return
        self._state_errors(alpha_sigma=s_a)
        self.lift_line = {**base, "state": "relevelled", "rows": n,
                          "note": (f"{self._line.note()}; the {n} rows kept moved onto it (RMS move "
                                   f"{np.degrees(rms):.2f} deg) and learned again; alpha's stated offset "
                                   f"{np.degrees(s_a):.2f} deg")}
        self.notes.append(f"step {self.steps}: {self.lift_line['note']}")

    def pitch_relearn(self, fit: dict | None = None) -> int:
        """Move every kept row's ``q_hat`` to the session's final pitch gust share and learn the GP again on them
        (``LearnOptions.air_pitch_relearn``; run by the final step, before :meth:`relevel`).

        Each window was learned at the share pooled up to it (:class:`gcs_sysid.aero.airpitch.AirPitchPool`), which
        settles over the windows and, on slow aircraft, starts at the gyro's rate until the pool passes its gates.
        The share of all windows is the best the session has: each kept row's ``q_hat`` becomes the gyro's less
        ``kappa g`` with that share (the gyro's where the final fit does not pass the gates), so every row is at one
        kind of rate, and the GP is learned again as the session learned it (:meth:`_learn_again`).

        Args:
            fit: the pooled fit to move to (:meth:`AirPitchPool.fit`'s dict: ``applied``, ``kappa``); None: the
                session's pool now.

        Returns:
            the rows learned again (0 when nothing moved, without a model, or with ``LearnOptions.air_pitch`` or
            ``air_pitch_relearn`` off: the rows' gust rates are kept only with the latter).
        """
        if not self.options.air_pitch_relearn or self._pitch_pool is None or self.model is None or not len(self.t):
            return 0
        fit = self._pitch_pool.fit() if fit is None else fit
        kappa = float(fit["kappa"]) if fit.get("applied") else 0.0
        d = (self._pitch_k - kappa) * self._pitch_g       # q_hat_gyro - kappa g  less  q_hat_gyro - k g
        moved = int(np.count_nonzero(d))
        info = {"kappa": kappa, "rows_moved": moved, "moved_rms": float(np.sqrt(np.mean(d**2))), "rows": 0}
        if moved:
            self.X[:, REGRESSORS.index("q_hat")] += d
            self._pitch_k[:] = kappa
            info["rows"] = self._learn_again()
            self._state_errors()
        what = (f"the share of all {fit.get('windows', self._pitch_pool.windows)} windows, kappa {kappa:.3f}" if kappa
                else "the gyro's rate (the pooled fit of all windows does not show the share)")
        info["note"] = (f"end: {moved} of {len(self.t)} kept rows' q_hat moved to {what} (RMS move "
                        f"{info['moved_rms']:.2e})" + (" and learned again" if moved else ""))
        self.air_pitch = {**self.air_pitch, "relearn": info}
        self.notes.append(f"step {self.steps}: {info['note']}")
        return info["rows"]

    def _learn_again(self) -> int:
        """The GP learned again on the kept rows as the session learned them (:meth:`relevel`); returns the rows."""
        cols = [COEFFICIENTS.index(c) for c in self.outputs]
        self.model, pending, self.n_learned, self._since_hyper = None, [], 0, 0
        for k in dict.fromkeys(self._win.tolist()):      # the windows in the order learned
            sel = self._win == k
            X, Y = self.X[sel], self.Y[sel][:, cols]
            if self.model is not None:
                self._update_gp(X, Y)
                continue
            ok = np.any(np.isfinite(Y), axis=1)
            pending.append((X[ok], Y[ok]))
            if sum(len(x) for x, _ in pending) >= self.options.min_rows:
                self._first_fit_again(pending)
        if self.model is None:                             # fewer kept rows than min_rows: one fit on them all
            self._first_fit_again(pending)
        return int(self.n_learned)

    def _first_fit_again(self, pending: list[tuple[np.ndarray, np.ndarray]]) -> None:
        """:meth:`_learn_again`'s first fit on the rows held (the session's outputs and ``GPConfig``)."""
        from ..gp import fit_gp

        X, Y = np.concatenate([x for x, _ in pending]), np.concatenate([y for _, y in pending])
        self.model, _ = fit_gp(X, Y, learner_gp_config(self.options))
        self.n_learned = len(X)

    def _update_gp(self, X: np.ndarray, Y: np.ndarray) -> None:
        """``model.update`` with the rows ``X`` (N, 10), ``Y`` (N, P: the model's outputs) that carry an output
        (partial rows kept, as in the first fit), and the light hyperparameter refresh when it is due."""
        ok = np.any(np.isfinite(Y), axis=1)
        if not ok.any():
            return
        self.model = self.model.update(X[ok], Y[ok])
        self.n_learned += int(ok.sum())
        self._since_hyper += int(ok.sum())
        if self.options.hyper_every and self._since_hyper >= self.options.hyper_every:
            self._refresh_hyper()

    def _merge_can(self, flight, data: bytes):
        """The window's flight with the CAN streams stamped up to its last record merged (or as it was)."""
        from ..telemetry.can_merge import can_host_clock, host_clock_of_tlog, merge_can_streams

        last = self._window[-1][0] * 1e-6
        streams = {}
        for name, st in self.can_source().items():
            m = st.t <= last
            if m.sum() >= 2:
                streams[name] = type(st)(st.name, st.source, st.t[m], {k: v[m] for k, v in st.fields.items()})
        if not streams:
            return flight
        try:   # DroneCAN time sync when its master is the vehicle, else the window's time_boot_ms
            clock, why = can_host_clock(streams, host_clock_of_tlog("live window", data))
            if why and not any(n.startswith("DroneCAN GlobalTimeSync") for n in self.notes):
                self.notes.append(why)
            return merge_can_streams(flight, streams, clock, 0.0, "CAN bus")
        except InputError as exc:
            if not any(n.startswith("CAN not merged") for n in self.notes):
                self.notes.append(f"CAN not merged (step {self.steps}): {exc}")
            return flight

    def _learn(self, table: CoefficientTable, rows: np.ndarray, states=None) -> None:
        """Learn ``table``'s ``rows`` ((T,) bool): pending until the first fit, then ``model.update``.

        ``states``: the window's smoothed states (:class:`gcs_sysid.estimation.states.FlightStates` on the table's
        grid); read only with ``LearnOptions.air_roll`` (the roll fit's rate, wind and stated noise).
        """
        from ..gp import fit_gp

        if not rows.any():
            return
        if self._errors is not None:
            self._errors.add(table, rows, states, self.airframe)
        X, Y, t = table.X[rows], table.Y[rows], table.t[rows]
        if self.model is not None and self._roll_fit is not None:
            Y = self._air_roll_later(table, rows, states)
        g, k = self._pitch_window if self._pitch_window is not None else (None, 0.0)
        self._keep(X, Y, t, None if g is None or len(g) != len(rows) else g[rows], k)
        if self.model is None:
            self._pending.append((X, Y))
            if self.options.air_roll:
                self._hold_roll_rows(table, rows, states)
            n = sum(len(x) for x, _ in self._pending)
            if n < self.options.min_rows:
                return
            Xa = np.concatenate([x for x, _ in self._pending])
            Ya = np.concatenate([y for _, y in self._pending])
            cols = [i for i, c in enumerate(COEFFICIENTS) if self.identifiable.get(c, (True, ""))[0]
                    and np.isfinite(Ya[:, i]).mean() > 0.5]
            if not cols:   # nothing identifiable yet: keep only the newest min_rows rows waiting
                self._pending = [(Xa[-self.options.min_rows:], Ya[-self.options.min_rows:])]
                if self._pending_roll is not None:
                    self._trim_roll_rows(self.options.min_rows)
                return
            self._pending = []
            if self.options.air_roll:
                Ya = self._air_roll_first(Ya)
            # a row that misses some coefficients (an angular-acceleration estimate rejected) is kept for the
            # others: the joint GP conditions each on the rows that carry it (docs/gp.md, "Missing outputs")
            ok = np.any(np.isfinite(Ya[:, cols]), axis=1)
            self.outputs = tuple(COEFFICIENTS[i] for i in cols)
            self.model, _ = fit_gp(Xa[ok], Ya[ok][:, cols], learner_gp_config(self.options))
            self.n_learned += int(ok.sum())
            self.notes.append(f"step {self.steps}: GP fitted on {int(ok.sum())} rows "
                              f"({', '.join(self.outputs)})")
            self._state_errors()
            return
        self._update_gp(X, Y[:, [COEFFICIENTS.index(c) for c in self.outputs]])
        self._state_errors()

    def _state_errors(self, alpha_sigma: float | None = None) -> None:
        """Give the model the pooled statement of the windows learned so far (``LearnOptions.stated_errors``): its
        band at exact conditions only (:func:`gcs_sysid.gp.discrepancy.with_offset_covariance`, the replay's).
        ``alpha_sigma`` (rad): alpha's offset stated as this 1-sigma, uncorrelated with the others' (the rows at
        one lift line's level, :meth:`relevel`), in place of the windows' pooled one."""
        if self._errors is None or self.model is None:
            return
        from ..gp.discrepancy import with_offset_covariance

        off, sv, mc, note = self._errors.statement()
        if alpha_sigma is not None and off is not None:
            off = off.copy()
            off[0, :] = off[:, 0] = 0.0
            off[0, 0] = alpha_sigma**2
            note += f"; alpha offset restated {alpha_sigma:.4f} rad (the rows at the lift line's level)"
        self.model = with_offset_covariance(self.model, off, scale_var=sv, map_cov=mc)
        self.errors = {"state": "pooling", "windows": self._errors.windows, "rows": self._errors.rows, "note": note}

    # --- the air-rate pair (LearnOptions.air_roll) ---------------------------------------------

    def _hold_roll_rows(self, table: CoefficientTable, rows: np.ndarray, states) -> None:
        """Keep the grid slice of ``table`` and ``states`` from the first to the last of ``rows`` for the roll fit
        (every grid row in between: the fit needs contiguous rows), ``rows`` within it as its training rows."""
        from ..aero.gustfilter import AIR_ROLL_STATE_KEYS

        if self._pending_roll is not None and self._pending_roll.get("missing"):
            return
        if states is None or any(k not in states.data for k in AIR_ROLL_STATE_KEYS["data"]):
            self._pending_roll = {"missing": "gust filter not run: the window's states carry no roll rate and wind"}
            return
        i = np.flatnonzero(rows)
        sl = slice(int(i[0]), int(i[-1]) + 1)
        part = {"t": table.t[sl], "X": table.X[sl], "Y": table.Y[sl], "valid": np.asarray(table.valid[sl], bool),
                "qbar": table.qbar[sl], "train": np.asarray(rows[sl], bool)}
        # a join to the previous slice off the grid (another window's grid, a reboot) starts a new run for the fit
        brk = np.zeros(len(part["t"]), bool)
        prev = self._pending_roll
        if prev is not None and len(prev["t"]):
            dt = 1.0 / self.options.rate_hz
            brk[0] = not (0.5 * dt <= part["t"][0] - prev["t"][-1] <= 1.5 * dt)
        part["brk"] = brk
        for k in AIR_ROLL_STATE_KEYS["data"]:
            part["d_" + k] = np.asarray(states.data[k])[sl]
        for k in AIR_ROLL_STATE_KEYS["sigma"]:
            if k in states.sigma:
                part["s_" + k] = np.asarray(states.sigma[k])[sl]
        if prev is None:
            self._pending_roll = part
        else:
            self._pending_roll = {k: np.concatenate([prev[k], part[k]]) for k in part if k in prev}

    def _trim_roll_rows(self, n: int) -> None:
        """Keep the held grid rows from the ``n``-th last training row on (as the pending rows are trimmed)."""
        P = self._pending_roll
        if P.get("missing"):
            return
        i = np.flatnonzero(P["train"])
        cut = int(i[-n]) if len(i) >= n else 0
        self._pending_roll = {k: v[cut:] for k, v in P.items()}
        self._pending_roll["brk"][0] = True

    def _roll_table_states(self, P: dict):
        """The held grid rows as a coefficient table and the states the pair reads."""
        from ..aero.gustfilter import AIR_ROLL_STATE_KEYS
        from ..estimation.states import FlightStates

        table = CoefficientTable(P["t"], P["X"], P["Y"], P["valid"], P["qbar"])
        states = FlightStates(P["t"], self.options.rate_hz, {k: P["d_" + k] for k in AIR_ROLL_STATE_KEYS["data"]},
                              {k: P["s_" + k] for k in AIR_ROLL_STATE_KEYS["sigma"] if "s_" + k in P})
        return table, states

    def _air_roll_first(self, Ya: np.ndarray) -> np.ndarray:
        """The pair's roll fit on the first fit's rows (made once, with its two checks); their Cl moved when it
        is accepted. Returns the first fit's targets (``Ya`` itself when refused)."""
        from ..aero.gustfilter import air_roll_fit, air_roll_target

        P, self._pending_roll = self._pending_roll, None
        if P is None or P.get("missing"):
            why = (P or {}).get("missing", "gust filter not run: no rows held for the roll fit")
        else:
            table, states = self._roll_table_states(P)
            train = P["train"]
            if int(train.sum()) != len(Ya):
                raise SysidError(f"air roll: {int(train.sum())} held rows against {len(Ya)} pending")
            why = air_roll_fit(table, states, self.airframe, train & ~P["brk"]) if len(table.t) >= 3 else \
                "gust filter not run: fewer than 3 rows"
        if isinstance(why, str):
            self.air_roll = {"state": "refused",
                             "note": why.replace("gust filter", "Cl's air-rate training target") +
                             " (Cl learned at the gyro's roll rate for the whole session)"}
            self.notes.append(f"step {self.steps}: {self.air_roll['note']}")
            return Ya
        G = why
        Y, info = air_roll_target(table, states, self.airframe, train, fit=G)
        self._roll_fit = G
        self.air_roll = {"state": "applied", "note": info["note"], "Cl_p": float(G.Cl_p), "tau_s": float(G.tau),
                         "sigma": float(G.sigma), "rows_moved": int(info["rows"].sum()), "sd_first": info["sd"]}
        self.notes.append(f"step {self.steps}: {info['note']}")
        i = COEFFICIENTS.index("Cl")
        tp, cl = table.t[train], Y[train, i]
        order = np.argsort(tp, kind="stable")
        k = np.clip(np.searchsorted(tp[order], self.t), 0, len(tp) - 1)
        hit = tp[order][k] == self.t                 # the kept rows of the first fit take the learned target
        self.Y[hit, i] = cl[order][k[hit]]
        return Y[train]

    def _air_roll_later(self, table: CoefficientTable, rows: np.ndarray, states) -> np.ndarray:
        """``rows``' targets with Cl moved by the stored roll fit, the gust smoothed over the window's valid rows."""
        from ..aero.gustfilter import air_roll_target_on_rows

        if states is None or "p" not in states.data:
            raise SysidError("air roll: the window's states are needed to move Cl's target")
        context = np.asarray(table.valid, bool) & np.all(np.isfinite(table.X), axis=1)
        Y, info = air_roll_target_on_rows(self._roll_fit, table, states, self.airframe, rows, context=context)
        self.air_roll["rows_moved"] = self.air_roll.get("rows_moved", 0) + int(info["rows"].sum())
        return Y[rows]

    def _refresh_hyper(self) -> None:
        """A light hyperparameter refresh of the GP (warm start, few steps; ``docs/live.md``)."""
        from ..gp.streaming import RefreshBudget, light_refresh

        self._since_hyper = 0
        try:
            self.model = light_refresh(self.model, RefreshBudget())
            self.notes.append(f"step {self.steps}: GP hyperparameters refreshed (light) after {self.n_learned} rows")
        except SysidError as exc:
            self.notes.append(f"step {self.steps}: GP hyperparameters not refreshed ({exc})")
        if self.options.trim_heap:   # its ~35-40 MiB of temporaries, before the map reuses the heap
            release_free_heap()

    def _keep(self, X: np.ndarray, Y: np.ndarray, t: np.ndarray, g: np.ndarray | None = None,
              kappa: float = 0.0) -> None:
        """Keep learned rows: ``X`` (N, 10), ``Y`` (N, 6), ``t`` (N,) s; with ``LearnOptions.air_pitch_relearn``
        also their pitch gust rate ``g`` (N,) as a hat (None: zeros) and the share ``kappa`` their ``q_hat`` was
        moved with (for :meth:`pitch_relearn`)."""
        self.X = np.concatenate([self.X, X])
        self.Y = np.concatenate([self.Y, Y])
        self.t = np.concatenate([self.t, t])
        self._win = np.concatenate([self._win, np.full(len(t), self._win_key, int)])
        relearn = self.options.air_pitch_relearn
        if relearn:
            self._pitch_g = np.concatenate([self._pitch_g, np.zeros(len(t)) if g is None else np.asarray(g, float)])
            self._pitch_k = np.concatenate([self._pitch_k, np.full(len(t), float(kappa))])
        if len(self.t) > self.options.max_rows:   # thin evenly: the flown envelope stays covered
            self.X, self.Y, self.t, self._win = self.X[::2], self.Y[::2], self.t[::2], self._win[::2]
            if relearn:
                self._pitch_g, self._pitch_k = self._pitch_g[::2], self._pitch_k[::2]

    def table(self) -> CoefficientTable:
        """The learned rows kept, as a :class:`CoefficientTable` (all rows valid)."""
        n = len(self.t)
        return CoefficientTable(self.t.copy(), self.X.copy(), self.Y.copy(), np.ones(n, bool),
                                np.full(n, np.nan), ["rows learned by a live session"])

    def refresh(self) -> None:
        """Recompute the confidence map and the maneuver suggestions from the model and kept rows."""
        from ..envelope import confidence_map
        from ..maneuvers import suggest_maneuvers

        table = self.table()
        if self.model is None or len(table.t) < 2:
            return
        try:
            self.envelope = confidence_map(self.model, table, table.valid, outputs=self.outputs)
            if self.options.trim_heap:   # the map's freed chunks back before the ranking's (no stacking)
                release_free_heap()
            self.suggestions = list(suggest_maneuvers(self.envelope, self.model, table, self.airframe))
        except SysidError as exc:
            self.notes.append(f"step {self.steps}: confidence map not refreshed ({exc})")

    def confidence(self) -> dict[str, float]:
        """Coefficient -> confidence score in [0, 1] from the latest map (empty before the first)."""
        return dict(self.envelope.scores) if self.envelope is not None else {}


def iter_tlog_records(path: str | Path):
    """Yield ``(stamp_us, packet bytes)`` of a tlog's well-framed records, in file order.

    Uses the telemetry layer's framing (:func:`gcs_sysid.telemetry.tlog_scan.find_sync`) to resync
    after corrupt bytes.
    """
    from ..telemetry.tlog_scan import find_sync

    data = Path(path).read_bytes()
    pos, n = 0, len(data)
    while pos + 16 <= n:
        magic = data[pos + 8]
        if magic == 0xFD and pos + 9 < n:
            plen = 12 + data[pos + 9] + (13 if data[pos + 10] & 1 else 0)
        elif magic == 0xFE:
            plen = 8 + data[pos + 9]
        else:
            nxt = find_sync(data, pos + 1, None)
            if nxt is None:
                return
            pos = nxt
            continue
        if pos + 8 + plen > n:
            return
        yield int.from_bytes(data[pos:pos + 8], "big"), data[pos + 8:pos + 8 + plen]
        pos += 8 + plen


def learn_from_tlog(path: str | Path, airframe: Airframe, options: LearnOptions = LearnOptions(),
                    can_log: str | Path | None = None, coalesced_at=None) -> Learner:
    """Feed a tlog (e.g. a live session's ``raw.tlog``) through a fresh :class:`Learner`.

    Args:
        path: the tlog.
        airframe: the airframe.
        options: the schedule.
        can_log: the session's ``can.log`` (or any CAN log on the same host clock), merged per window.
        coalesced_at: the session's ``coalesced_at_us`` (``session.json``): the steps it merged while
            behind are merged here too, so the schedule and the model are the session's.

    Returns:
        The learner after :meth:`Learner.finish`: the model a live session with the same records
        and options ends with.
    """
    learner = Learner(airframe, options)
    if coalesced_at:
        learner._replayed = {int(x) for x in coalesced_at}
        learner.behind = lambda: learner._due_us in learner._replayed
    if can_log is not None:
        from ..telemetry.can import read_can_log

        streams, _ = read_can_log(can_log)
        learner.can_source = lambda: streams
    for stamp_us, packet in iter_tlog_records(path):
        learner.feed(stamp_us, packet)
    learner.finish()
    return learner
