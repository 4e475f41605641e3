"""The regressors' stated flight-common errors pooled over the windows of a live session (issue 8).

The replay states once per flight what its regressors' estimates share across the flight (the table's
``x_offset_cov``, ``x_scale_var`` and ``x_map_cov``, and the gyro rates' errors of :mod:`gcs_sysid.aero.rateerrors`)
and gives them to :func:`gcs_sysid.gp.discrepancy.with_offset_covariance`: the band at exact conditions, what
``gcs-sysid predict`` states (``docs/gp.md``, "The band at exact conditions"). The live learner
(:mod:`gcs_sysid.live.learner`) estimates every window (30 s by default) on its own, so every window's table carries
its own statement, about its own estimate, and the rows a live model learned come from many windows. A learned row's
error is then a draw from a mixture of the windows' errors, and the second moment of a mixture is the mean of its
components' second moments, weighted by their shares. That is what :class:`WindowErrorPool` states:

* ``offset_cov``, ``scale_var`` and ``map_cov``: the row-weighted means of the windows' ``x_offset_cov``,
  ``x_scale_var`` and ``x_map_cov`` over the windows that state each (weights: the rows each window hands to the
  learner; the few that never reach the model, a first fit's trimmed backlog or rows without an identifiable output,
  are counted too);
* with ``rate_errors``, ``scale_var[p_hat] = rho^2`` with ``rho`` the ratio of the row-weighted sums of ``var(g)`` and
  ``var(p_hat)`` (:func:`gcs_sysid.aero.rateerrors.roll_rate_variances`) over the windows whose roll fit was accepted,
  and ``map_cov[r_hat]`` the row-weighted mean of the windows' yaw-rate maps
  (:func:`~gcs_sysid.aero.rateerrors.yaw_rate_map`). Each window's roll fit and map are made on all its valid rows (the
  fit's context) up to the last row it hands over, not only those rows (10 s by default: too few for the fit's
  checks). A ratio of pooled variances, not a mean of ratios: on JSBSim's rascal one 30-s window with little roll
  excitation read ``rho`` 14 against 0.4-2.8 in the others (1.56 over the whole flight).

The mixture's second moment bounds the learned model's from above: the model's error is roughly the row-weighted mean
of the windows' errors, and ``E[(sum_w a_w e_w)^2] <= sum_w a_w E[e_w^2]`` (``sum a_w = 1``; Jensen), with equality
when the windows' errors are one (a vertical wind the whole flight shares). Nothing here changes the model's mean or
its bands at the flight's own regressors.
"""

from __future__ import annotations

import numpy as np

from ..errors import SysidError
from .table import REGRESSORS

__all__ = ["WindowErrorPool", "POOL_STATE_KEYS"]

#: The window states the pool's rates' errors read: the roll fit's
#: (:data:`gcs_sysid.aero.gustfilter.AIR_ROLL_STATE_KEYS`) and the yaw gust rate's
#: (:func:`gcs_sysid.aero.airyaw.yaw_gust_hat`: attitude, wind, airspeed).
POOL_STATE_KEYS = {"data": ("p", "wn", "we", "wd", "phi", "theta", "psi", "V"), "sigma": ("p_dot", "r_dot")}

_IP, _IR = REGRESSORS.index("p_hat"), REGRESSORS.index("r_hat")


class WindowErrorPool:
    """Row-weighted pool of the windows' stated regressor errors (module docstring).

    Args:
        rate_errors: also pool the gyro rates' errors (``p_hat``'s scale, ``r_hat``'s map), as the replay's
            ``ReplayOptions.rate_errors``.

    Attributes:
        windows: windows added with at least one row.
        rows: rows added over them.
    """

    def __init__(self, rate_errors: bool = True):
        D = len(REGRESSORS)
        self.rate_errors = bool(rate_errors)
        self.windows = 0
        self.rows = 0
        self._off, self._n_off = np.zeros((D, D)), 0
        self._sv, self._n_sv = np.zeros(D), 0
        self._mc, self._n_mc = np.zeros((D, D, D)), 0
        self._var_g, self._var_p, self._n_roll = 0.0, 0.0, 0
        self._yaw, self._n_yaw = np.zeros((D, D)), 0
        self._why_roll: str | None = None
        self._why_yaw: str | None = None

    def add(self, table, rows: np.ndarray, states=None, airframe=None) -> None:
        """Add one window: its statement, weighted by the rows it hands to the model.

        Args:
            table: the window's :class:`~gcs_sysid.aero.table.CoefficientTable` (``x_offset_cov`` ``(10, 10)``,
                ``x_scale_var`` ``(10,)``, ``x_map_cov`` ``(10, 10, 10)``, each or None).
            rows: ``(T,)`` bool, the rows the window hands to the model (their count is the weight).
            states: the window's smoothed states on the table's grid with :data:`POOL_STATE_KEYS` (or None: no
                rates' errors from this window).
            airframe: the :class:`~gcs_sysid.airframe.Airframe` (span for the yaw rate; the roll fit's geometry).

        Raises:
            ValueError: ``rows`` is not ``(T,)``.
        """
        rows = np.asarray(rows, bool)
        if rows.shape != (len(table.t),):
            raise ValueError(f"WindowErrorPool.add: rows must be ({len(table.t)},), got {rows.shape}")
        n = int(rows.sum())
        if n == 0:
            return
        self.windows += 1
        self.rows += n
        if table.x_offset_cov is not None and np.isfinite(table.x_offset_cov).all():
            self._off += n * np.asarray(table.x_offset_cov, float)
            self._n_off += n
        if table.x_scale_var is not None and np.isfinite(table.x_scale_var).all():
            self._sv += n * np.asarray(table.x_scale_var, float)
            self._n_sv += n
        if table.x_map_cov is not None and np.isfinite(table.x_map_cov).all():
            self._mc += n * np.asarray(table.x_map_cov, float)
            self._n_mc += n
        if self.rate_errors:
            self._add_rates(table, rows, states, airframe)

    def _add_rates(self, table, rows: np.ndarray, states, airframe) -> None:
        """The window's roll-rate variances and yaw-rate map, each on its valid rows up to the last of ``rows``,
        weighted by ``rows``' count (module docstring)."""
        from .airyaw import yaw_gust_hat
        from .gustfilter import air_roll_fit
        from .rateerrors import roll_fit_refusal, roll_rate_variances, yaw_rate_map

        rows = np.asarray(rows, bool)
        n = int(rows.sum())
        missing = [k for k in POOL_STATE_KEYS["data"] if states is None or k not in states.data]
        if missing or airframe is None:
            why = f"no {' '.join(missing)} in the window's states" if missing else "no airframe"
            self._why_roll = self._why_roll or why
            self._why_yaw = self._why_yaw or why
            return
        # the window's valid rows up to the last it hands over (the lag's rows come with the next window)
        t = np.asarray(table.t, float)
        ctx = np.asarray(table.valid, bool) & np.all(np.isfinite(table.X), axis=1) & (t <= t[rows].max())
        try:
            fit = air_roll_fit(table, states, airframe, ctx)
        except (SysidError, np.linalg.LinAlgError) as exc:    # one window's fit must not end a live session
            fit = f"roll fit failed on a window ({exc})"
        v = None if isinstance(fit, str) else roll_rate_variances(fit, table, ctx)
        if v is None:
            self._why_roll = roll_fit_refusal(fit) if isinstance(fit, str) else "too few rows"
        else:
            self._var_g += n * v[0]
            self._var_p += n * v[1]
            self._n_roll += n
        g, why = yaw_gust_hat(states, airframe.b)
        C = None if g is None else yaw_rate_map(table, g, ctx)
        if C is None:
            self._why_yaw = why if g is None else "too few rows"
        else:
            self._yaw += n * C
            self._n_yaw += n

    def statement(self) -> tuple[np.ndarray | None, np.ndarray | None, np.ndarray | None, str]:
        """The pooled statement for :func:`gcs_sysid.gp.discrepancy.with_offset_covariance`.

        Returns:
            ``(offset_cov (10, 10), scale_var (10,), map_cov (10, 10, 10), note)``: each the row-weighted mean over
            the windows that stated it, the rates' errors put in as :func:`gcs_sysid.aero.rateerrors.stated_rate_errors`
            does (``scale_var[p_hat] = rho^2``, ``map_cov[r_hat]``); None where no window stated anything; the note
            says what was pooled over how many of the rows.
        """
        D = len(REGRESSORS)
        off = self._off / self._n_off if self._n_off else None
        sv = self._sv / self._n_sv if self._n_sv else None
        mc = self._mc / self._n_mc if self._n_mc else None
        said = [f"pooled over {self.windows} windows, {self.rows} rows (row-weighted)"]
        if off is not None:
            said.append(f"alpha offset {np.sqrt(max(off[0, 0], 0.0)):.4f} rad rms ({self._n_off} rows)")
        if self.rate_errors:
            if self._n_roll and self._var_p > 0:
                rho = self._var_g / self._var_p
                sv = np.zeros(D) if sv is None else sv.copy()
                sv[_IP] = rho**2
                said.append(f"p_hat scale error {rho:.2f} ({self._n_roll} rows)")
            else:
                said.append(f"p_hat: none ({self._why_roll or 'no window'})")
            if self._n_yaw:
                mc = np.zeros((D, D, D)) if mc is None else mc.copy()
                mc[_IR] = self._yaw / self._n_yaw
                said.append(f"r_hat linear error ({self._n_yaw} rows)")
            else:
                said.append(f"r_hat: none ({self._why_yaw or 'no window'})")
        return off, sv, mc, "stated regressor errors in the band at exact conditions: " + "; ".join(said)
