"""A lift line carried across the windows of a live session: alpha's level from the windows so far (issue 8).

Why. The live learner (:mod:`gcs_sysid.live.learner`) estimates every window (30 s by default) on its own. The
aided alpha's level is the window's: the specific-force aiding fits its lift model's offset (``CZ0``) on the window,
so the window's mean vertical wind, which no channel of the log sees, goes into alpha (``w_mean / V``). Over a whole
flight that mean is small; over 30 s of light turbulence it is not: on JSBSim's asw20 (seed 19) the ten windows'
alpha levels ran from -2.6 to +3.2 deg against the truth, correlated 0.99 with the windows' mean vertical wind
(``docs/benchmarks.md``, "Sixty-sixth session"). A model learning CZ and Cm on rows whose alpha jumps by degrees from
window to window learns that jump.

What. The lift the accelerometers measure obeys one line whatever the wind,
``CL = -CZ cos(alpha) + CX sin(alpha) = CL0 + CL_alpha alpha + CL_q q_hat + CL_delta_e delta_e``. Each window's own
alpha is the true one plus the window's level error ``e_k``, so each window's intercept reads ``CL0 - CL_alpha e_k``.
:class:`LiftLinePool` fits the line on the windows learned so far, each window's rows at the window's *own* level:

* the slopes by least squares *within* windows (each window's rows less their means: the windows' different level
  errors, which no slope explains, stay out of the slopes; Greene, *Econometric Analysis*, 7th ed., 2012, sec. 11.4,
  the within estimator);
* ``CL0`` from the pooled means, ``mean(CL) - slopes . mean(x)`` over every row: its error is ``CL_alpha`` times the
  row-weighted mean of the windows' level errors, which shrinks as windows accumulate;
* its 1-sigma ``CL0_sigma = CL_alpha sqrt(mean_k s_k^2 / K)``, ``s_k`` the windows' own flight-mean-wind 1-sigma
  (:func:`gcs_sysid.estimation.angleerrors.mean_wind_sigma`, ``AxisFit.bias_sigma``), ``K`` the number of
  independent windows' worth of rows learned (their span over the window length, at least 1: consecutive windows
  share two thirds of their records, so their levels are not independent).

The next window is estimated with this line as a stated one (:func:`gcs_sysid.estimation.estimate_states`,
``lift_line``; :func:`gcs_sysid.estimation.airangles.lift_level`): its alpha's mean moves onto the line by the
weight ``s_w^2 / (s_w^2 + s_l^2)`` against its own mean wind's ``s_w``. The move is undone before the window's rows
join the pool (``AxisFit.mean_shift``), so the pool always holds independent own-level windows and a window's level
never feeds back into the line that set it. The line is the flight's (a vertical wind the whole flight shares stays
in it, as it stays in the replay's single level); what goes is the wander from window to window.

Sources: Jategaonkar, *Flight Vehicle System Identification*, 2nd ed., 2015, ch. 10 (a constant air-data offset is
observable only against a stated reference); Morelli and Klein, *Aircraft System Identification*, 2016, ch. 10 (the
angle-of-attack bias of data compatibility analysis).
"""

from __future__ import annotations

import numpy as np

from .table import REGRESSORS

__all__ = ["LiftLinePool", "LINE_COLUMNS", "MIN_LINE_S", "MAX_LEVEL_SIGMA"]

#: the line's regressors after the intercept (names of :data:`gcs_sysid.aero.table.REGRESSORS`)
LINE_COLUMNS = ("alpha", "q_hat", "delta_e")
#: rows (seconds of them) the pool needs before it states a line
MIN_LINE_S = 5.0
#: a column whose within-window SD is below this (its units: rad or -) is left out of the slopes (held at 0)
MIN_COLUMN_SD = 1e-4
#: the largest 1-sigma of the line's level (``CL0_sigma / CL_alpha``, rad) at which the line is carried (:meth:`
#: LiftLinePool.carried`). Rows at one level are what a GP learns alpha's slopes from, but that level carries the
#: flight's mean vertical wind, which nothing in the log observes; where it is large (slow aircraft in turbulence) a
#: model learned on one biased level trusts it, while rows whose levels wander lean on the other regressors. Set at
#: 1 deg on the tuning flights of the sixty-seventh session (JSBSim, 25 aircraft, seed 19, 120 s, light): every
#: flight whose line stated 0.15-0.70 deg learned CZ better at JSBSim's regressors with its rows on the line
#: (12 of 12), those at 1.16-3.64 deg as often worse as better and up to three times worse (rascal, eternity, us25e;
#: ``docs/benchmarks.md``, "Sixty-seventh session").
MAX_LEVEL_SIGMA = float(np.radians(1.0))


class LiftLinePool:
    """The windows' lift line, accumulated as sums (see the module docstring).

    Args:
        window_s: the learner's window length, s (the span of rows that counts as one independent window).

    Attributes:
        windows: windows added with rows. rows: rows added. span_s: their time, s (rows x the grid step).
    """

    def __init__(self, window_s: float = 30.0):
        if not window_s > 0:
            raise ValueError(f"LiftLinePool needs window_s > 0, got {window_s!r}")
        self.window_s = float(window_s)
        k = len(LINE_COLUMNS)
        self._Sz = np.zeros(k)
        self._Sy = 0.0
        self._Wzz = np.zeros((k, k))
        self._Wzy = np.zeros(k)
        self._Ss2 = 0.0          # sum over windows of rows x s_k^2 (windows with a finite s_k)
        self._Ns2 = 0            # the rows of those windows
        self.windows = 0
        self.rows = 0
        self.span_s = 0.0
        self.handed = 0          # windows added that a carried line had moved
        self._means: dict = {}   # key -> (rows, mean of LINE_COLUMNS at the own level, mean CL, the line's move)

    def add(self, table, rows: np.ndarray, states, airframe, key=None) -> int:
        """Add one window's rows at the window's own alpha level.

        Args:
            table: the window's :class:`~gcs_sysid.aero.table.CoefficientTable` (T rows).
            rows: (T,) bool, the rows the window hands to the learner.
            states: the window's :class:`~gcs_sysid.estimation.states.FlightStates` on the table's grid (``ax``
                the specific force along body x, m/s^2; ``qbar``, Pa; ``angle_fits["alpha"]`` the aiding's fit:
                ``mean_shift`` is undone where a line moved alpha, ``wind_sigma`` or ``bias_sigma`` is ``s_k``).
            airframe: mass (kg) and S (m^2).
            key: a name for the window's rows (hashable; None: the count of windows added before): its means are
                kept for :meth:`move` (the window's rows moved onto a later line).

        Returns:
            the number of rows added (0: none finite).
        """
        idx = [REGRESSORS.index(c) for c in LINE_COLUMNS]
        fit = (states.angle_fits or {}).get("alpha") if states is not None else None
        moved = fit is not None and np.isfinite(getattr(fit, "wind_sigma", np.nan))
        shift = float(fit.mean_shift) if moved else 0.0
        s_k = float(fit.wind_sigma if moved else fit.bias_sigma) if fit is not None and fit.used else np.nan
        with np.errstate(invalid="ignore", divide="ignore"):
            ax = np.asarray(states.data.get("ax", np.full(len(table.t), np.nan)), float)
            qbar = np.asarray(table.qbar, float)
            CX = airframe.mass * ax / (qbar * airframe.S)      # thrust included, as the aiding's own lift
            Z = table.X[:, idx].astype(float).copy()
            Z[:, 0] -= shift
            a = Z[:, 0]
            CL = -table.Y[:, 2] * np.cos(a) + CX * np.sin(a)
        m = np.asarray(rows, bool) & np.all(np.isfinite(Z), axis=1) & np.isfinite(CL)
        n = int(m.sum())
        if n < 2:
            return 0
        z, y = Z[m], CL[m]
        self._means[self.windows if key is None else key] = (n, z.mean(axis=0), float(y.mean()), shift)
        self.handed += int(moved)
        zc, yc = z - z.mean(axis=0), y - y.mean()
        self._Sz += z.sum(axis=0)
        self._Sy += float(y.sum())
        self._Wzz += zc.T @ zc
        self._Wzy += zc.T @ yc
        if np.isfinite(s_k) and s_k > 0:
            self._Ss2 += n * s_k**2
            self._Ns2 += n
        dt = float(np.median(np.diff(table.t))) if len(table.t) > 1 else 0.0
        self.windows += 1
        self.rows += n
        self.span_s += n * dt
        return n

    def line(self) -> dict[str, float] | None:
        """The line the windows so far state, or None (fewer than :data:`MIN_LINE_S` of rows, no window's mean-wind
        1-sigma, or a lift slope that is not positive).

        Returns:
            ``{"CL0", "CL_alpha", "CL_q", "CL_delta_e", "CL0_sigma"}`` (1/rad for ``CL_alpha`` and ``CL_delta_e``,
            per unit ``q_hat`` for ``CL_q``), the form :func:`gcs_sysid.estimation.estimate_states` takes as
            ``lift_line``. ``CL_q`` is clipped at 0 (the aiding reads its magnitude; a negative fit is noise), a
            column that does not vary within windows is held at 0.
        """
        if self.rows < 2 or self.span_s < MIN_LINE_S or self._Ns2 == 0:
            return None
        dof = max(self.rows - self.windows, 1)
        sd = np.sqrt(np.maximum(np.diag(self._Wzz) / dof, 0.0))
        use = np.flatnonzero(sd >= MIN_COLUMN_SD)
        if 0 not in use:
            return None
        theta = np.zeros(len(LINE_COLUMNS))
        A = self._Wzz[np.ix_(use, use)]
        theta[use] = np.linalg.lstsq(A, self._Wzy[use], rcond=1e-10)[0]
        if not theta[0] > 0:
            return None
        CL0 = (self._Sy - float(theta @ self._Sz)) / self.rows
        K = max(1.0, self.span_s / self.window_s)
        s_line = theta[0] * np.sqrt(self._Ss2 / self._Ns2 / K)
        return {"CL0": float(CL0), "CL_alpha": float(theta[0]), "CL_q": float(max(theta[1], 0.0)),
                "CL_delta_e": float(theta[2]), "CL0_sigma": float(s_line)}

    def carried(self) -> dict[str, float] | None:
        """:meth:`line` where its level's 1-sigma ``CL0_sigma / CL_alpha`` is at most :data:`MAX_LEVEL_SIGMA`, else
        None (the windows keep their own levels)."""
        ln = self.line()
        return ln if ln is not None and ln["CL0_sigma"] / ln["CL_alpha"] <= MAX_LEVEL_SIGMA else None

    def move(self, key, line: dict[str, float] | None) -> float:
        """The move of window ``key``'s rows (as learned: their own level plus the carried line's move then) onto
        ``line``'s level, rad: ``d - shift``, ``d`` the window's own level's offset from the line
        (``mean((CL - CL0 - CL_q q_hat - CL_delta_e delta_e) / CL_alpha - alpha)`` over its rows, from the means kept;
        :func:`gcs_sysid.estimation.airangles.lift_level` with the full weight), ``shift`` the carried line's move.
        0 for a window without rows in the pool.

        Args:
            key: as given to :meth:`add`. line: a :meth:`line`; None: back to the window's own level (``-shift``).
        """
        if key not in self._means:
            return 0.0
        _, zm, ym, shift = self._means[key]
        if line is None:
            return -float(shift)
        d = (ym - line["CL0"] - line["CL_q"] * zm[1] - line["CL_delta_e"] * zm[2]) / line["CL_alpha"] - zm[0]
        return float(d - shift)

    def note(self) -> str:
        """One line: the line stated now, or why none."""
        ln = self.line()
        if ln is None:
            return (f"lift line: none yet ({self.windows} windows, {self.span_s:.0f} s of rows; needs "
                    f"{MIN_LINE_S:g} s, a mean-wind 1-sigma and a positive lift slope)")
        return (f"lift line from {self.windows} windows ({self.span_s:.0f} s of rows): CL0 {ln['CL0']:+.3f} "
                f"+- {ln['CL0_sigma']:.3f}, CL_alpha {ln['CL_alpha']:.2f}/rad, CL_q {ln['CL_q']:.2f}, "
                f"CL_delta_e {ln['CL_delta_e']:+.2f}/rad")
