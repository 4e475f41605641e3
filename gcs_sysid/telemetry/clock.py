"""Vehicle time: reboots, counter wraps and messages without a clock of their own.

The vehicle clock is taken from a *track*: every message carrying ``time_boot_ms`` (or, without
those, a 64-bit ``time_usec``; DataFlash: ``TimeUS``), in file order. A reboot shows as the clock
falling more than :data:`REBOOT_DROP_S` below its running maximum and staying there for the next
samples; each reboot starts a new segment whose times are shifted to continue after the previous
segment, spaced by the log (wall-clock) time between the two records.

Messages with a wrapping counter (``SERVO_OUTPUT_RAW.time_usec`` is uint32 us and wraps every
2^32 us = 71.6 min) are unwrapped against the track: the number of wraps is the one that brings the
counter closest to the track clock at that point of the file. Messages without a clock (VFR_HUD,
WIND, HEARTBEAT, SIMSTATE ...) get the vehicle time of the latest timed record before them plus the
log-clock time elapsed since it (the running offset between the log clock and the vehicle clock).
"""

from __future__ import annotations

import datetime as _dt
from dataclasses import dataclass, field

import numpy as np

__all__ = ["REBOOT_DROP_S", "REBOOT_WINDOW_S", "VehicleClock", "sort_unique"]

REBOOT_DROP_S = 1.0
"""A fall of the vehicle clock larger than this (s), confirmed by the next samples, is a reboot."""

REBOOT_WINDOW_S = 5.0
"""Log time after a fall of the clock over which a reboot is told apart from delayed packets."""


def _is_reboot(raw: np.ndarray, stamp: np.ndarray, old_max: float) -> bool:
    """After a fall at ``raw[0]``: do the next samples follow the new clock rather than the old one?

    Delayed (out-of-order) packets show as a short dip after which the samples rejoin the old clock
    (``raw >= old_max - REBOOT_DROP_S``); after a reboot they advance from ``raw[0]`` at the rate of
    the log clock. The samples within :data:`REBOOT_WINDOW_S` of log time (at least 3, at most 200)
    vote.
    """
    n = int(np.searchsorted(stamp[:200], stamp[0] + REBOOT_WINDOW_S, side="right"))
    n = min(max(n, 3), 200, len(raw))
    r, s = raw[:n], stamp[:n]
    old_line = r >= old_max - REBOOT_DROP_S
    new_line = (np.abs((r - r[0]) - (s - s[0])) < REBOOT_DROP_S) & ~old_line
    return bool(new_line.sum() > old_line.sum() and new_line.sum() >= min(3, n))


def _fmt_log_time(stamp_s: float, log_t0: float) -> str:
    """``2018-07-30 16:39:05 UTC, 123.4 s into the log`` (wall clock only when it looks like one)."""
    rel = f"{stamp_s - log_t0:.1f} s into the log"
    if 946684800 < stamp_s < 4102444800:  # 2000 .. 2100: a real wall clock
        wall = _dt.datetime.fromtimestamp(stamp_s, _dt.timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC")
        return f"log time {wall}, {rel}"
    return f"log time {rel}"


@dataclass
class VehicleClock:
    """Piecewise vehicle clock built from a track of timed records.

    Attributes:
        seq: record index of each track sample, shape (K,), increasing.
        t: re-based vehicle time of each track sample, s, shape (K,).
        stamp: log-clock time of each track sample, s, shape (K,).
        seg_start: record index where each segment starts, shape (S,), first is -inf-like 0.
        seg_offset: seconds added to the raw clock in each segment, shape (S,).
        warnings: one line per reboot found.
    """

    seq: np.ndarray
    t: np.ndarray
    stamp: np.ndarray
    seg_start: np.ndarray
    seg_offset: np.ndarray
    warnings: list[str] = field(default_factory=list)

    @staticmethod
    def from_track(seq: np.ndarray, raw: np.ndarray, stamp: np.ndarray, source: str = "vehicle clock",
                   log_t0: float | None = None) -> "VehicleClock":
        """Build the clock, finding reboots.

        Args:
            seq: record index per track sample, shape (K,) (any order; sorted here).
            raw: vehicle clock reading, s, shape (K,).
            stamp: log-clock time, s, shape (K,) (for DataFlash pass ``raw``).
            source: what the track is made of, for the warnings.
            log_t0: log-clock time of the first record (for the warnings).
        """
        order = np.argsort(seq, kind="stable")
        seq, raw, stamp = np.asarray(seq)[order], np.asarray(raw, float)[order], np.asarray(stamp, float)[order]
        k = len(seq)
        if k == 0:
            return VehicleClock(seq, raw, stamp, np.array([0]), np.array([0.0]))
        log_t0 = float(stamp[0]) if log_t0 is None else log_t0
        starts, offsets, warnings = [0], [0.0], []
        i0 = 0
        while i0 < k:
            sub = raw[i0:]
            cmax = np.maximum.accumulate(sub)
            below = sub[1:] < cmax[:-1] - REBOOT_DROP_S
            b = None
            for c in np.nonzero(below)[0] + 1:
                if _is_reboot(sub[c:], stamp[i0 + c:], float(cmax[c - 1])):
                    b = int(c)
                    break
            if b is None:
                break
            gi = i0 + b
            prev_end = float(cmax[b - 1]) + offsets[-1]
            gap = max(float(stamp[gi] - stamp[gi - 1]), 1e-3)
            off = prev_end + gap - float(raw[gi])
            warnings.append(
                f"reboot at {_fmt_log_time(float(stamp[gi]), log_t0)}: {source} fell from "
                f"{cmax[b - 1]:.3f} s to {raw[gi]:.3f} s; later times re-based to continue at {prev_end + gap:.3f} s")
            starts.append(int(seq[gi]))
            offsets.append(off)
            i0 = gi
        seg_start = np.array(starts)
        seg_offset = np.array(offsets)
        seg = np.searchsorted(seg_start, seq, side="right") - 1
        return VehicleClock(seq, raw + seg_offset[np.maximum(seg, 0)], stamp, seg_start, seg_offset, warnings)

    def segment_offset(self, seq: np.ndarray) -> np.ndarray:
        """Re-basing offset (s) of the segment each record index falls in, shape like ``seq``."""
        seg = np.searchsorted(self.seg_start, np.asarray(seq), side="right") - 1
        return self.seg_offset[np.maximum(seg, 0)]

    def map_untimed(self, seq: np.ndarray, stamp: np.ndarray) -> np.ndarray:
        """Vehicle time (s) of records without a clock: latest track sample + log time since it.

        Args:
            seq: record indices, shape (N,).
            stamp: log-clock times, s, shape (N,).
        """
        seq = np.asarray(seq)
        if len(self.seq) == 0:
            return np.asarray(stamp, float) - (float(stamp[0]) if len(stamp) else 0.0)
        j = np.maximum(np.searchsorted(self.seq, seq, side="right") - 1, 0)
        return self.t[j] + (np.asarray(stamp, float) - self.stamp[j])

    def map_timed(self, seq: np.ndarray, stamp: np.ndarray, raw: np.ndarray,
                  wrap: float | None = None) -> tuple[np.ndarray, bool, int]:
        """Vehicle time (s) of records with their own clock reading ``raw`` (s).

        Args:
            seq, stamp: record indices and log-clock times, shape (N,).
            raw: the message's clock, s, shape (N,).
            wrap: counter period, s (2**32 us = 4294.967296 s for a uint32 usec counter), or None.

        Returns:
            (t, same_clock, wraps): ``same_clock`` is False when ``raw`` is plainly another clock
            (median disagreement with the track over 5 s after unwrapping; ``t`` is then from
            :meth:`map_untimed`); ``wraps`` is how many counter wraps were undone.
        """
        raw = np.asarray(raw, float)
        if len(self.seq) == 0 or len(raw) == 0:
            return raw.copy(), True, 0
        off = self.segment_offset(seq)
        est = self.map_untimed(seq, stamp) - off
        wraps = 0
        if wrap:
            k = np.round((est - raw) / wrap)
            raw = raw + k * wrap
            wraps = int(np.ptp(k)) if len(k) else 0
        if np.median(np.abs(raw - est)) > 5.0:
            return self.map_untimed(seq, stamp), False, 0
        return raw + off, True, wraps


def sort_unique(t: np.ndarray) -> tuple[np.ndarray, int]:
    """Indices that sort ``t`` and drop repeated times, and how many samples were dropped.

    Args:
        t: times, shape (N,); NaN entries are dropped too.

    Returns:
        (idx, dropped): ``t[idx]`` is strictly increasing.
    """
    t = np.asarray(t, float)
    order = np.argsort(t, kind="stable")
    order = order[np.isfinite(t[order])]
    ts = t[order]
    keep = np.ones(len(ts), bool)
    if len(ts) > 1:
        keep[1:] = np.diff(ts) > 0
    idx = order[keep]
    return idx, int(len(t) - len(idx))
