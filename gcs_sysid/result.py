"""The replay job's result as plain data; the report renders it, it can be saved and re-rendered."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .aero.table import CoefficientTable
from .estimation.states import FlightStates
from .telemetry.types import StreamSummary

__all__ = ["ReplayResult"]


@dataclass
class ReplayResult:
    """Everything the report shows, computed once by :func:`gcs_sysid.pipeline.run_replay`.

    Attributes:
        log_path: the log that was replayed.
        airframe_name, airframe_path: the airframe used.
        vehicle: HEARTBEAT facts (mav_type, autopilot ...).
        window: (t_from, t_to) vehicle-time window in s, None for open ends.
        summaries: per-stream decode summaries (count, rate, gaps).
        messages: message type -> count in the log.
        states: smoothed states on the grid.
        table: regressors and measured coefficients on the grid.
        held_out: (T,) bool, the held-out time segment (never used for fitting).
        train: (T,) bool, rows the GP was fitted on (valid and not held out).
        pred_mean: (T, 6) model mean on every row; NaN where invalid.
        pred_sigma: (T, 6) 1-sigma of the coefficient itself at the row's estimated regressors: latent variance,
            the regressors' errors through the slope and the coloured part of the observation noise, without
            the white measurement noise (``docs/gp.md``, "Two bands"; the outputs of
            ``pipeline.WHITE_BAND_NO_STATED_INPUT`` with the learned input noise alone); with
            ``ReplayOptions.coefficient_band`` ``"stated"`` the outputs of ``pipeline.STATED_BAND_SIGN`` instead from
            the blocked validation's residual and the estimator's stated measurement error
            (:mod:`gcs_sysid.gp.coefband`); NaN where invalid.
        pred_sigma_obs: (T, 6) 1-sigma of a new measurement of it (the white band's ``pred_sigma`` plus the white
            measurement noise); NaN where invalid or not known (a result saved before the eleventh session: there
            ``pred_sigma`` held this band, and :func:`gcs_sysid.report.load_result` moves it here).
        metrics: coefficient -> {"error_pct_heldout", "error_pct_train", "rms_measured", "n_heldout", ...}.
        identifiable: coefficient -> (bool, reason) whether the data support an estimate.
        envelope: the confidence map (``gcs_sysid.envelope.EnvelopeMap``) or None.
        suggestions: ranked maneuver suggestions (``gcs_sysid.maneuvers.Suggestion``).
        gp_summary: hyperparameters and sizes of the fitted model (dict, JSON-able).
        model_path: where the model state was saved.
        missing: what was missing from the log, one line each.
        notes: remarks for the engineer, one line each (rates too low, assumptions made).
        timings: stage -> seconds.
    """

    log_path: str
    airframe_name: str
    airframe_path: str
    vehicle: dict[str, Any]
    window: tuple[float | None, float | None]
    summaries: dict[str, StreamSummary]
    messages: dict[str, int]
    states: FlightStates
    table: CoefficientTable
    held_out: np.ndarray
    train: np.ndarray
    pred_mean: np.ndarray
    pred_sigma: np.ndarray
    metrics: dict[str, dict[str, float]]
    identifiable: dict[str, tuple[bool, str]]
    envelope: Any = None
    suggestions: list[Any] = field(default_factory=list)
    gp_summary: dict[str, Any] = field(default_factory=dict)
    model_path: str = ""
    missing: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    timings: dict[str, float] = field(default_factory=dict)
    pred_sigma_obs: np.ndarray | None = None

    def __post_init__(self):
        if self.pred_sigma_obs is None:
            self.pred_sigma_obs = np.full(np.shape(self.pred_sigma), np.nan)
