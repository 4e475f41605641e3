"""Put asynchronous telemetry streams on one uniform time grid.

Choices (see ``docs/estimation.md``):

* The grid runs at ``rate_hz`` (default 50 Hz) or at the IMU's own rate if that is
  clearly (more than 10 %) lower (a 10 Hz IMU gives a 10 Hz grid: interpolating it to 50 Hz would invent
  data). Without an IMU the attitude stream sets the rate.
* Continuous signals (rates, accelerations, velocities, air data) are linearly
  interpolated. A source faster than the grid (e.g. a 100 Hz IMU on a 50 Hz grid)
  is first averaged over each grid interval (a boxcar anti-alias filter) instead
  of being picked at two neighbours, which would alias its noise.
* Angles (roll, pitch, yaw) are unwrapped before interpolation and wrapped back
  to (-pi, pi] after, so a yaw crossing +-180 deg is not swept through 0.
* Servo and RC PWM are commands that change in steps: zero-order hold (the last
  command received holds until the next one); no interpolation between them.
* Gaps: no value is produced between two source samples further apart than
  ``max_gap`` (default ``max(5 * median period, 0.5 s)``, the same rule as
  :class:`~gcs_sysid.telemetry.types.StreamSummary`), nor before the first or
  after the last sample (beyond half a source period); such grid points are NaN
  and their ``valid`` entry is False.
* Measurement streams used as Kalman-filter updates (attitude, GPS velocity) can
  instead be taken as *events*: each source sample placed at its nearest grid
  point (averaged when several fall on one), NaN elsewhere, so the filter never
  sees interpolated, correlated pseudo-measurements (:func:`events`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..telemetry.types import Flight, Stream

__all__ = ["Aligned", "make_grid", "median_rate", "resample", "events", "align_flight", "ANGLE_FIELDS",
           "HOLD_STREAMS"]

#: (stream, field) pairs interpolated as angles.
ANGLE_FIELDS = {("attitude", "roll"), ("attitude", "pitch"), ("attitude", "yaw"),
                ("ekf", "roll"), ("ekf", "pitch"), ("ekf", "yaw"), ("gps", "lat"), ("gps", "lon")}
#: Streams of step commands, put on the grid by zero-order hold.
HOLD_STREAMS = {"servo", "rc"}


@dataclass
class Aligned:
    """Streams resampled on one uniform grid.

    Attributes:
        t: grid times, s, shape (T,), spacing ``1/rate_hz``.
        rate_hz: grid rate, Hz.
        values: stream -> field -> array of shape (T,), NaN where not available.
        valid: stream -> (T,) bool, True where the stream covers the grid point.
        rates: stream -> median source rate, Hz.
    """

    t: np.ndarray
    rate_hz: float
    values: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)
    valid: dict[str, np.ndarray] = field(default_factory=dict)
    rates: dict[str, float] = field(default_factory=dict)

    def has(self, stream: str, fld: str | None = None) -> bool:
        """True if ``stream`` (and ``fld`` in it) was aligned and covers at least one grid point."""
        if stream not in self.values or not self.valid[stream].any():
            return False
        return fld is None or fld in self.values[stream]

    def get(self, stream: str, fld: str) -> np.ndarray:
        """Field on the grid (T,), NaN where invalid; all-NaN if the stream or field is absent."""
        if stream in self.values and fld in self.values[stream]:
            return self.values[stream][fld]
        return np.full(self.t.shape, np.nan)


def median_rate(t: np.ndarray) -> float:
    """Median sample rate (Hz) of time stamps ``t`` (N,); 0 for fewer than 2 samples."""
    if len(t) < 2:
        return 0.0
    d = float(np.median(np.diff(t)))
    return 1.0 / d if d > 0 else 0.0


def make_grid(flight: Flight, rate_hz: float = 50.0) -> tuple[np.ndarray, float]:
    """The uniform grid for a flight.

    Args:
        flight: decoded flight; its ``imu`` stream (else ``attitude``) sets the
            time span and caps the rate.
        rate_hz: wanted rate, Hz (> 0).

    Returns:
        ``(t, rate)``: grid times (T,) in s, on multiples of ``1/rate``, and the rate used.

    Raises:
        ValueError: ``rate_hz`` not positive, or neither ``imu`` nor ``attitude`` has 2 samples.
    """
    if not rate_hz > 0:
        raise ValueError(f"rate_hz must be > 0, got {rate_hz!r}")
    base = next((flight[n] for n in ("imu", "attitude") if flight.has(n)), None)
    if base is None:
        raise ValueError("no imu or attitude stream with at least 2 samples to define the time grid")
    src_rate = median_rate(base.t)
    # a nominal-rate IMU with timing jitter (49.96 Hz for 50) does not lower the grid rate
    rate = float(rate_hz) if src_rate <= 0 or src_rate >= 0.9 * rate_hz else round(src_rate, 2)
    k0 = np.ceil(base.t[0] * rate - 1e-9)
    k1 = np.floor(base.t[-1] * rate + 1e-9)
    t = np.arange(k0, k1 + 1) / rate
    return t, rate


def _bins(t_src: np.ndarray, t: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Index ranges [lo, hi) of source samples inside each grid cell [t - dt/2, t + dt/2)."""
    lo = np.searchsorted(t_src, t - 0.5 * dt, side="left")
    hi = np.searchsorted(t_src, t + 0.5 * dt, side="left")
    return lo, hi


def _bin_mean(y: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Mean of ``y[lo:hi]`` per cell, NaN for empty cells (NaN samples propagate)."""
    c = np.concatenate([[0.0], np.cumsum(y)])
    n = hi - lo
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, (c[hi] - c[lo]) / np.maximum(n, 1), np.nan)


def _wrap(a: np.ndarray) -> np.ndarray:
    return np.mod(a + np.pi, 2 * np.pi) - np.pi


def resample(t_src: np.ndarray, y_src: np.ndarray, t: np.ndarray, mode: str = "linear",
             max_gap: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Resample one field onto a uniform grid with gap awareness.

    Args:
        t_src: source times (N,), s, strictly increasing.
        y_src: source values (N,). NaN samples count as absent.
        t: uniform grid (T,), s.
        mode: ``"linear"``, ``"angle"`` (unwrap, interpolate, wrap to (-pi, pi]) or
            ``"hold"`` (zero-order hold of the last sample).
        max_gap: longest source interval (s) bridged; default ``max(5 * median period, 0.5)``.

    Returns:
        ``(y, ok)``: values (T,) with NaN where not covered, and the (T,) bool mask.

    Raises:
        ValueError: unknown mode or mismatched shapes.
    """
    if mode not in ("linear", "angle", "hold"):
        raise ValueError(f"resample mode must be linear, angle or hold, got {mode!r}")
    t_src = np.asarray(t_src, float)
    y_src = np.asarray(y_src, float)
    if t_src.shape != y_src.shape:
        raise ValueError(f"t_src and y_src shapes differ: {t_src.shape} vs {y_src.shape}")
    keep = np.isfinite(y_src) & np.isfinite(t_src)
    t_src, y_src = t_src[keep], y_src[keep]
    out = np.full(t.shape, np.nan)
    if len(t_src) < 2 or len(t) == 0:
        return out, np.zeros(t.shape, bool)
    d_src = np.diff(t_src)
    med = float(np.median(d_src))
    gap = max(5 * med, 0.5) if max_gap is None else float(max_gap)
    if mode == "angle":
        y_src = np.unwrap(y_src)
    # which source interval each grid point falls in, and whether it is bridged
    i = np.clip(np.searchsorted(t_src, t, side="right") - 1, 0, len(t_src) - 2)
    inside = (t >= t_src[0] - 0.5 * med) & (t <= t_src[-1] + 0.5 * med)
    bridged = d_src[i] <= gap
    # a grid point within half a period of a sample is covered even if next to a gap
    near = (np.abs(t - t_src[i]) <= 0.5 * med) | (np.abs(t_src[i + 1] - t) <= 0.5 * med)
    ok = inside & (bridged | near)
    if mode == "hold":
        j = np.clip(np.searchsorted(t_src, t + 1e-9, side="right") - 1, 0, len(t_src) - 1)
        y = y_src[j]
        ok &= (t >= t_src[0] - 1e-9) & ((t - t_src[j]) <= gap)
    else:
        y = np.interp(t, t_src, y_src)
        dt = float(t[1] - t[0]) if len(t) > 1 else med
        if med < dt / 1.5:  # source faster than the grid: boxcar average over each cell
            lo, hi = _bins(t_src, t, dt)
            ym = _bin_mean(y_src, lo, hi)
            y = np.where(np.isfinite(ym), ym, y)
        if mode == "angle":
            y = _wrap(y)
    out[ok] = y[ok]
    return out, ok


def events(stream: Stream, fields: tuple[str, ...], t: np.ndarray, angles: tuple[str, ...] = ()) -> np.ndarray:
    """Source samples placed at their nearest grid point, for Kalman-filter updates.

    Args:
        stream: source stream.
        fields: field names to take, in order.
        t: uniform grid (T,), s.
        angles: fields that are angles (averaged on the unit circle when several
            samples share a grid point).

    Returns:
        Array (T, len(fields)): the mean of the samples nearest to each grid point,
        NaN at grid points that got no sample (or a sample with a NaN field).
    """
    out = np.full((len(t), len(fields)), np.nan)
    if len(t) < 2 or len(stream) == 0:
        return out
    dt = float(t[1] - t[0])
    k = np.rint((stream.t - t[0]) / dt).astype(np.int64)
    m = (k >= 0) & (k < len(t))
    k = k[m]
    cnt = np.bincount(k, minlength=len(t))
    has = cnt > 0
    for j, f in enumerate(fields):
        y = np.asarray(stream[f], float)[m]
        if f in angles:
            s = np.bincount(k, np.sin(y), minlength=len(t))
            c = np.bincount(k, np.cos(y), minlength=len(t))
            out[has, j] = np.arctan2(s[has], c[has])
        else:
            out[has, j] = np.bincount(k, y, minlength=len(t))[has] / cnt[has]
    return out


def align_flight(flight: Flight, rate_hz: float = 50.0, max_gap: float | None = None) -> Aligned:
    """Resample every stream of a flight onto the flight's grid (:func:`make_grid`).

    Args:
        flight: decoded flight.
        rate_hz: wanted grid rate, Hz (the IMU rate caps it).
        max_gap: longest source interval bridged, s (default per stream, see :func:`resample`).

    Returns:
        :class:`Aligned` with every stream that has at least 2 samples.

    Raises:
        ValueError: as :func:`make_grid`.
    """
    t, rate = make_grid(flight, rate_hz)
    al = Aligned(t, rate)
    for name, st in flight.streams.items():
        if len(st) < 2:
            continue
        vals: dict[str, np.ndarray] = {}
        valid = np.zeros(t.shape, bool)
        for f, y in st.fields.items():
            mode = "hold" if name in HOLD_STREAMS else ("angle" if (name, f) in ANGLE_FIELDS else "linear")
            vals[f], ok = resample(st.t, y, t, mode, max_gap)
            valid |= ok
        al.values[name] = vals
        al.valid[name] = valid
        al.rates[name] = median_rate(st.t)
    return al
