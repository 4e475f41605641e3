"""Typed, SI-unit telemetry: what every source (tlog, DataFlash, live link, CAN) decodes to.

A :class:`Flight` is a set of named :class:`Stream` objects, each a strictly
increasing vehicle-time vector ``t`` (s since boot, wraps and reboots already
resolved) and a dict of equally long field arrays in SI units. The canonical
stream names and fields are listed in ``docs/architecture.md`` (section
"Canonical streams"); sources fill in what their messages carry.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import numpy as np

__all__ = ["Stream", "StreamSummary", "Flight"]


@dataclass
class Stream:
    """One decoded stream.

    Attributes:
        name: canonical name, e.g. ``"imu"``.
        source: message type(s) it came from, e.g. ``"RAW_IMU"`` or ``"IMU[0]"``.
        t: vehicle time in s, shape (N,), strictly increasing.
        fields: field name -> array of shape (N,), SI units.
    """

    name: str
    source: str
    t: np.ndarray
    fields: dict[str, np.ndarray]

    def __len__(self) -> int:
        return int(self.t.shape[0])

    def __getitem__(self, key: str) -> np.ndarray:
        return self.fields[key]

    def __contains__(self, key: str) -> bool:
        return key in self.fields

    def window(self, t0: float | None, t1: float | None) -> "Stream":
        """The samples with ``t0 <= t <= t1`` (None = open end)."""
        m = np.ones(len(self), bool)
        if t0 is not None:
            m &= self.t >= t0
        if t1 is not None:
            m &= self.t <= t1
        return Stream(self.name, self.source, self.t[m], {k: v[m] for k, v in self.fields.items()})


@dataclass
class StreamSummary:
    """Per-stream bookkeeping for the report.

    Attributes:
        name, source: as in :class:`Stream`.
        count: samples kept.
        rate_hz: median sample rate (1 / median dt), 0 for fewer than 2 samples.
        t_start, t_end: vehicle time of first and last sample, s.
        gaps: list of (t_start, t_end) intervals longer than 5 median periods (and > 0.5 s).
        dropped: duplicated or out-of-order samples removed.
    """

    name: str
    source: str
    count: int
    rate_hz: float
    t_start: float
    t_end: float
    gaps: list[tuple[float, float]] = field(default_factory=list)
    dropped: int = 0

    @staticmethod
    def of(stream: Stream, dropped: int = 0) -> "StreamSummary":
        """Summarise a stream (rate from the median sample interval)."""
        t = stream.t
        if len(t) < 2:
            return StreamSummary(stream.name, stream.source, len(t), 0.0,
                                 float(t[0]) if len(t) else float("nan"),
                                 float(t[-1]) if len(t) else float("nan"), [], dropped)
        dt = np.diff(t)
        med = float(np.median(dt))
        thr = max(5 * med, 0.5)
        gaps = [(float(t[i]), float(t[i + 1])) for i in np.nonzero(dt > thr)[0]]
        return StreamSummary(stream.name, stream.source, len(t), 1.0 / med if med > 0 else 0.0,
                             float(t[0]), float(t[-1]), gaps, dropped)


@dataclass
class Flight:
    """A decoded flight log or live session.

    Attributes:
        path: where it came from (file path or connection string).
        format: ``"tlog"``, ``"bin"``, ``"live"`` or ``"can"``.
        streams: canonical name -> :class:`Stream`.
        summaries: canonical name -> :class:`StreamSummary` (before any window).
        vehicle: facts from HEARTBEAT / VER (``mav_type``, ``autopilot``, ``system_id`` ...).
        params: autopilot parameters seen in the log (PARAM_VALUE / PARM), name -> value.
        messages: message type -> count of every message seen (including unknown / BAD_DATA).
        warnings: one-line notes on what was odd or missing (reboots, wraps, bad data).
        statustext: (t, text) pairs from STATUSTEXT / MSG.
        damage: the notes among ``warnings`` that say the log itself is damaged: corrupt packets,
            truncation, dropped (duplicated or out-of-order) samples, time jumps and gaps
            (empty for an intact log). Shown on the console as well as in the report.
    """

    path: str
    format: str
    streams: dict[str, Stream]
    summaries: dict[str, StreamSummary] = field(default_factory=dict)
    vehicle: dict[str, object] = field(default_factory=dict)
    params: dict[str, float] = field(default_factory=dict)
    messages: dict[str, int] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    statustext: list[tuple[float, str]] = field(default_factory=list)
    damage: list[str] = field(default_factory=list)

    def has(self, name: str) -> bool:
        """True if stream ``name`` exists and has at least 2 samples."""
        return name in self.streams and len(self.streams[name]) >= 2

    def __getitem__(self, name: str) -> Stream:
        return self.streams[name]

    @property
    def t_range(self) -> tuple[float, float]:
        """(first, last) vehicle time over all streams, s."""
        ts = [s.t for s in self.streams.values() if len(s)]
        if not ts:
            return (float("nan"), float("nan"))
        return (min(float(t[0]) for t in ts), max(float(t[-1]) for t in ts))

    def window(self, t0: float | None, t1: float | None) -> "Flight":
        """A copy restricted to ``t0 <= t <= t1`` vehicle time (s); summaries kept as decoded."""
        return Flight(self.path, self.format, {k: s.window(t0, t1) for k, s in self.streams.items()},
                      dict(self.summaries), dict(self.vehicle), dict(self.params), dict(self.messages),
                      list(self.warnings), [x for x in self.statustext
                                            if (t0 is None or x[0] >= t0) and (t1 is None or x[0] <= t1)],
                      list(self.damage))
