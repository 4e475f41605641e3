"""The air-relative pitch rate: the table's ``q_hat`` less the pitch gust rate the flight's own data support.

The aerodynamics reads the body's pitch rate relative to the air, ``q - q_g`` (Etkin, *Dynamics of Atmospheric
Flight*, Wiley 1972, ch. 13, gust gradients: ``q_g = -dw_g/dx``); the gyro measures ``q``. A coefficient learned at the
gyro's ``q_hat`` carries the pitching gust moment ``-Cm_q q_hat_g`` as noise in its input: the fitted ``Cm_q`` is too
weak (errors in variables; Fuller, *Measurement Error Models*, Wiley 1987, sec. 1.1) and ``Cm_alpha``, which moves with
``q`` in a pitch manoeuvre, takes up the difference. Measured on JSBSim flights (least squares of Cm on ``[1, alpha,
q_hat, delta_e]`` over the replay's training rows, each regressor swapped for JSBSim's in turn; ``docs/benchmarks.md``,
"Sixty-eighth session"): on the navion and the s23 only ``q_hat`` moves them; with JSBSim's ``q_aero`` the navion's
``Cm_alpha`` reads -0.57, as least squares of JSBSim's own Cm does, with the gyro's -0.73; the s23's 0.00 against
-0.47.

The pitch gust rate is estimated from the reconstructed wind (:func:`gcs_sysid.estimation.gustrates.gust_rates`,
frame ``"path"``: MIL-F-8785C's Dryden lag over ``4b/(pi V)`` of the vertical gust's derivative along the path, Etkin's
sign) as a hat, ``g = q_g c / (2V)``. Its sign relative to the aerodynamics is the flight's to say, not this module's:
JSBSim's turbulence (``FGWinds::Turbulence``, ``ttMilspec`` eq. 34, ``xi_q`` stepped with ``+d xi_w/dt / V``) has the
opposite of Etkin's, and its aerodynamics reads ``q - xi_q``. So the share is fitted: least squares of Cm on
``[1, x, g]`` (``x`` the regressors that vary over the training rows) gives ``Cm_q`` and ``c_g``, and with
``Cm = Cm_q (q_hat - kappa g) + ...``,

    kappa = -c_g / Cm_q,        q_hat_air = q_hat - kappa g        (every row, the held-out ones too)

(an estimate of the air-relative rate from the data the flight holds: ``g`` and the gyro; the least-squares ``kappa``
is the gust estimate's regression share, below 1 where ``g`` is noisy). It is applied only when the fit shows it:
``|t(c_g)| >=`` :data:`MIN_T`, a damping ``Cm_q < 0`` and ``|kappa| <=`` :data:`MAX_KAPPA`; otherwise the table is
returned as it is and the note says why. Every output then sees the air-relative ``q_hat`` (CZ's ``CZ_q`` reads the
same rate), the GP learns on it and is asked at it on the held-out rows; ``gcs-sysid predict`` at exact conditions asks
at the air's own rate, as JSBSim's truth and a user's simulator define it.

In a filter-error method (Jategaonkar, *Flight Vehicle System Identification*, 2nd ed., AIAA 2015, ch. 5 and 7) the
pitching gust is process noise of the pitch equation; here its estimate from the air data is used offline, as
:mod:`gcs_sysid.aero.airyaw` does for the yawing gust.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .table import COEFFICIENTS, REGRESSORS

__all__ = ["AIR_PITCH", "MIN_T", "MAX_KAPPA", "pitch_gust_hat", "air_pitch_fit", "air_pitch_table", "apply_air_pitch",
           "AirPitchPool"]

#: Whether the replay moves ``q_hat`` to the air-relative rate (``ReplayOptions.air_pitch`` None). On since the
#: sixty-eighth session: its rule, written before the run, held on fresh JSBSim flights (seeds 16-18, 25 aircraft, GP
#: seeds 0 and 1: held-out Cm 21.5 -> 14.6 % median, better on 67 of 75 flights and worse on none, at exact conditions
#: 38.4 -> 31.5 %; issue 8's counts +47/-14 and +46/-13; ``docs/benchmarks.md``, "Sixty-eighth session").
AIR_PITCH = True
#: The smallest ``|t|`` of the gust column's coefficient in the Cm fit that applies the share (frozen before the
#: sixty-eighth session's rule: on the tuning flights the shares that did not help had ``|t|`` 1-8)
MIN_T = 10.0
#: The largest ``|kappa|``: more than the gust estimate's own size would be a fit of something else
MAX_KAPPA = 1.5
_MIN_ROWS = 200
_IQ = REGRESSORS.index("q_hat")


def pitch_gust_hat(states, c: float, b: float) -> tuple[np.ndarray | None, str]:
    """The pitch gust rate as a hat, ``g = q_g c / (2 V)``, from the states' reconstructed wind.

    ``q_g`` is :func:`gcs_sysid.estimation.gustrates.gust_rates`' frame ``"path"`` (body axes, Etkin's sign, the
    MIL-F-8785C Dryden lag over ``4 b / (pi V)``).

    Args:
        states: smoothed states with ``phi theta psi`` (rad), ``wn we wd`` (m/s, NED) and ``V`` (m/s) on a uniform
            grid ``t`` (s).
        c: mean aerodynamic chord, m.
        b: wing span, m.

    Returns:
        ``((T,) g, note)``; ``(None, why)`` when a field is missing or the grid is shorter than 3 samples.
    """
    from ..estimation.gustrates import states_gust_hat

    g, why = states_gust_hat(states, b, "path", "q", c)
    if g is None:
        return None, why.replace("no gust rate", "no pitch gust rate")
    return g, "pitch gust rate from the reconstructed wind (MIL-F-8785C Dryden form along the path, Etkin's sign)"


def air_pitch_fit(table, g: np.ndarray, train: np.ndarray) -> dict:
    """The gust column's share in Cm, fitted on the training rows (module docstring).

    Args:
        table: :class:`~gcs_sysid.aero.table.CoefficientTable` (``X`` ``(T, 10)`` with the gyro's ``q_hat``,
            ``Y`` ``(T, 6)``).
        g: ``(T,)`` the pitch gust rate as a hat (:func:`pitch_gust_hat`), NaN where unknown.
        train: ``(T,)`` bool, the training rows (the only rows fitted).

    Returns:
        ``{"applied": bool, "kappa", "t", "c_g", "Cm_q", "rows", "note"}``: ``applied`` when the three conditions
        hold; ``kappa`` and the rest NaN where no fit was made (fewer than 200 usable rows, or a singular fit).

    Raises:
        ValueError: ``g`` or ``train`` not of the table's length.
    """
    X, y, g, rows = _usable(table, g, train, "air_pitch_fit", "train")
    nan = _no_fit(int(rows.sum()))
    if rows.sum() < _MIN_ROWS:
        return nan | {"note": f"q_hat is the gyro's: {int(rows.sum())} rows for the pitch gust fit (at least "
                              f"{_MIN_ROWS})"}
    Xr = X[rows]
    varying = [j for j in range(X.shape[1]) if np.std(Xr[:, j]) > 1e-9 * max(1.0, abs(np.mean(Xr[:, j])))]
    if _IQ not in varying:
        return nan | {"note": "q_hat is the gyro's: q_hat does not vary over the training rows"}
    A = np.column_stack([np.ones(len(Xr)), Xr[:, varying], g[rows]])
    coef, _, rank, _ = np.linalg.lstsq(A, y[rows], rcond=None)
    if rank < A.shape[1]:
        return nan | {"note": "q_hat is the gyro's: the pitch gust fit is singular"}
    resid = y[rows] - A @ coef
    s2 = float(resid @ resid) / max(len(resid) - A.shape[1], 1)
    # (A^T A)^-1 = R^-1 R^-T with R upper triangular: its last diagonal element is 1 / R_nn^2 (the last row of R^-1
    # is e_n / R_nn; until 2026-11-29 this read the last column's norm, the element of (R R^T)^-1, which is never
    # smaller: |t| was understated)
    R = np.linalg.qr(A, mode="r")
    se = float(np.sqrt(s2) / abs(R[-1, -1])) if R[-1, -1] != 0 else float("inf")
    return _judged(float(coef[-1]), float(coef[1 + varying.index(_IQ)]), se, int(rows.sum()))


def _usable(table, g, rows, who: str, name: str):
    """``(X (T, 10), Cm (T,), g (T,), usable (T,) bool)``: the table's regressors and Cm, ``g`` as floats, and the
    given ``rows`` that are valid with ``g``, Cm and every regressor finite. Raises ValueError (naming ``who`` and
    ``name``) where ``g`` or ``rows`` is not of the table's length."""
    T = len(table.t)
    g, rows = np.asarray(g, float), np.asarray(rows, bool)
    if g.shape != (T,) or rows.shape != (T,):
        raise ValueError(f"{who}: expected g and {name} of shape ({T},), got {g.shape} and {rows.shape}")
    X = np.asarray(table.X, float)
    y = np.asarray(table.Y, float)[:, COEFFICIENTS.index("Cm")]
    return X, y, g, rows & np.asarray(table.valid, bool) & np.isfinite(g) & np.isfinite(y) & np.isfinite(X).all(1)


def _no_fit(n_rows: int) -> dict:
    """The result's fields where no fit was made (the note is the caller's)."""
    return {"applied": False, "kappa": float("nan"), "t": float("nan"), "c_g": float("nan"), "Cm_q": float("nan"),
            "rows": n_rows}


def _judged(c_g: float, Cm_q: float, se: float, n_rows: int, where: str = "") -> dict:
    """:func:`air_pitch_fit`'s result from the gust column's coefficient ``c_g``, ``Cm_q`` and ``c_g``'s standard
    error ``se`` over ``n_rows`` training rows: the three conditions of the module docstring and the note."""
    t = c_g / se if se > 0 else float("inf")
    kappa = -c_g / Cm_q if Cm_q != 0 else float("nan")
    why = []
    if not abs(t) >= MIN_T:
        why.append(f"|t| {abs(t):.1f} < {MIN_T:g}")
    if not Cm_q < 0:
        why.append(f"Cm_q {Cm_q:+.3g} not a damping")
    if not abs(kappa) <= MAX_KAPPA:
        why.append(f"|kappa| {abs(kappa):.2f} > {MAX_KAPPA:g}")
    applied = not why
    sign = "Etkin's sign" if kappa > 0 else "the sign opposite to Etkin's, JSBSim ttMilspec's"
    head = (f"pitch gust share in Cm: kappa {kappa:+.2f} (t {t:+.1f}, Cm_q {Cm_q:+.3g}, {n_rows} training "
            f"rows{where}; {sign})")
    note = (f"q_hat is the air-relative estimate q_hat - kappa g: {head}" if applied
            else f"q_hat is the gyro's: {head} not applied ({'; '.join(why)})")
    return {"applied": applied, "kappa": kappa, "t": t, "c_g": c_g, "Cm_q": Cm_q, "rows": n_rows, "note": note}


class AirPitchPool:
    """The pitch gust share fitted over a live session's windows together: one ``kappa`` for every window.

    :func:`air_pitch_fit` on a 30-s window reads ``|t|`` 3-30 on JSBSim's flights, so a window-by-window fit moves
    some windows' ``q_hat`` and leaves others at the gyro's, and the learned model mixes the two rates (the sixty-eighth
    session's live runs: 5 of 10 windows moved on many flights). Here each window adds the normal equations of its
    new rows (each row once) to a pool and the share is judged on the pool: the same regression as
    :func:`air_pitch_fit`, ``Cm`` on the ten regressors and ``g``, with an intercept of its own per window (each
    window's columns centred on the window's means: its own alpha level and trim), so the pooled fit equals the
    whole-flight fit with per-window levels, and ``t`` grows with the rows pooled. The conditions of the module
    docstring (``MIN_T``, ``Cm_q < 0``, ``MAX_KAPPA``) apply to the pooled fit.

    Source: pooled least squares with group intercepts (the within estimator; Greene, *Econometric Analysis*, 7th ed.,
    Pearson 2012, sec. 11.4), by accumulated normal equations (Golub and Van Loan 2013, sec. 5.3).
    """

    _MIN_WINDOW_ROWS = 20

    def __init__(self) -> None:
        k = len(REGRESSORS) + 1
        self._S = np.zeros((k, k))           # centred cross-products of [X, g]
        self._sy = np.zeros(k)               # centred [X, g]^T Cm
        self._syy = 0.0
        self.rows = 0
        self.windows = 0

    def add(self, table, g: np.ndarray, rows: np.ndarray) -> int:
        """Pool one window's rows.

        Args:
            table: the window's :class:`~gcs_sysid.aero.table.CoefficientTable` (gyro ``q_hat``).
            g: ``(T,)`` its pitch gust rate as a hat (:func:`pitch_gust_hat`), NaN where unknown.
            rows: ``(T,)`` bool, the window's new rows (each row of the session pooled once).

        Returns:
            the rows added (0 where fewer than 20 are usable: a window's own level needs rows to be read).

        Raises:
            ValueError: ``g`` or ``rows`` not of the table's length.
        """
        X, y, g, ok = _usable(table, g, rows, "AirPitchPool.add", "rows")
        n = int(ok.sum())
        if n < self._MIN_WINDOW_ROWS:
            return 0
        A = np.column_stack([X[ok], g[ok]])
        A = A - A.mean(0)
        yc = y[ok] - y[ok].mean()
        self._S += A.T @ A
        self._sy += A.T @ yc
        self._syy += float(yc @ yc)
        self.rows += n
        self.windows += 1
        return n

    def fit(self) -> dict:
        """The pooled share: :func:`air_pitch_fit`'s dict (``applied``, ``kappa``, ``t``, ``c_g``, ``Cm_q``, ``rows``,
        ``note``) plus ``windows``; NaN values and ``applied`` False below 200 pooled rows or for a singular fit."""
        k = self._S.shape[0]
        nan = _no_fit(self.rows) | {"windows": self.windows}
        if self.rows < _MIN_ROWS:
            return nan | {"note": f"q_hat is the gyro's: {self.rows} rows pooled for the pitch gust fit (at least "
                                  f"{_MIN_ROWS})"}
        d = np.diag(self._S)
        keep = [j for j in range(k) if d[j] > 1e-18 * self.rows]     # columns that vary within some window
        flat = [name for j, name in ((_IQ, "q_hat"), (k - 1, "the pitch gust rate")) if j not in keep]
        if flat:
            return nan | {"note": f"q_hat is the gyro's: {' and '.join(flat)} does not vary over the "
                                  f"{self.rows} pooled rows"}
        S = self._S[np.ix_(keep, keep)]
        sc = 1.0 / np.sqrt(np.diag(S))                                 # equilibrated: columns of unit norm
        Ss = S * sc[:, None] * sc[None, :]
        try:
            L = np.linalg.cholesky(Ss)
        except np.linalg.LinAlgError:
            return nan | {"note": "q_hat is the gyro's: the pooled pitch gust fit is singular"}
        if np.min(np.diag(L)) ** 2 < 1e-12:
            return nan | {"note": "q_hat is the gyro's: the pooled pitch gust fit is singular"}
        b = np.linalg.solve(L.T, np.linalg.solve(L, self._sy[keep] * sc)) * sc
        dof = self.rows - len(keep) - self.windows                     # a level per window
        s2 = max(self._syy - float(b @ self._sy[keep]), 0.0) / max(dof, 1)
        e = np.linalg.solve(L, np.eye(len(keep))[:, -1])               # (S^-1)_gg = |L^-1 e_g|^2 sc_g^2
        se = float(np.sqrt(s2 * float(e @ e))) * sc[-1]
        out = _judged(float(b[-1]), float(b[keep.index(_IQ)]), se, self.rows, f" in {self.windows} windows pooled")
        return out | {"windows": self.windows}


def air_pitch_table(table, g: np.ndarray, fit: dict):
    """The table with ``q_hat`` at the air-relative estimate ``q_hat - kappa g`` on every row where ``g`` is known,
    when ``fit["applied"]``; the table as given otherwise. The fit's note is added to the table's notes either way.

    Args:
        table: :class:`~gcs_sysid.aero.table.CoefficientTable`.
        g: ``(T,)`` the pitch gust rate as a hat (:func:`pitch_gust_hat`).
        fit: :func:`air_pitch_fit`'s result on this table and ``g``.

    Returns:
        a new :class:`~gcs_sysid.aero.table.CoefficientTable` (the input is not changed).
    """
    notes = list(table.notes) + [fit["note"]]
    if not fit["applied"]:
        return replace(table, notes=notes)
    X = np.array(table.X, float, copy=True)
    g = np.asarray(g, float)
    ok = np.isfinite(g)
    X[ok, _IQ] = X[ok, _IQ] - fit["kappa"] * g[ok]
    return replace(table, X=X, notes=notes)


def apply_air_pitch(table, states, airframe, rows: np.ndarray, pool: AirPitchPool | None = None,
                    g: np.ndarray | None = None):
    """The three steps in one: :func:`pitch_gust_hat` of ``states``, :func:`air_pitch_fit` on ``rows`` and
    :func:`air_pitch_table` (what the replay's stage, the live learner's windows and the evaluations do).

    Args:
        table: :class:`~gcs_sysid.aero.table.CoefficientTable` on the states' grid.
        states: the smoothed states the table was computed from.
        airframe: :class:`~gcs_sysid.airframe.Airframe` (its chord ``c`` and span ``b``, m).
        rows: ``(T,)`` bool, the rows the share is fitted on; with ``pool``, the rows added to it (a live window's
            new rows).
        pool: the live session's :class:`AirPitchPool`: ``rows`` are added and the pooled share moves every row of
            the table; None: the table's own fit on ``rows``.
        g: ``(T,)`` the pitch gust rate as a hat when the caller has it already (:func:`pitch_gust_hat` of
            ``states``); None: computed here.

    Returns:
        ``(table, fit, note)``: the table with ``q_hat`` moved where the fit shows it (its note added), the fit's
        dict and its note; ``(table as given, None, why)`` where the states give no pitch gust rate.
    """
    if g is None:
        g, why = pitch_gust_hat(states, airframe.c, airframe.b)
        if g is None:
            return table, None, why
    if pool is None:
        fit = air_pitch_fit(table, g, rows)
    else:
        pool.add(table, g, rows)
        fit = pool.fit()
    return air_pitch_table(table, g, fit), fit, fit["note"]
