"""Telemetry decoding: MAVLink telemetry logs (.tlog) and ArduPilot DataFlash logs (.bin) to a
:class:`Flight` of typed SI streams on the vehicle clock.

Entry point: :func:`read_log`. The stream names, fields and units are in ``docs/telemetry.md``.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Callable

from gcs_sysid.errors import DataError, InputError
from gcs_sysid.telemetry.types import Flight, Stream, StreamSummary

__all__ = ["read_log", "detect_format", "cut_window", "Flight", "Stream", "StreamSummary"]

_DF_HEAD = b"\xa3\x95"
_SNIFF = 1 << 16


def detect_format(path: str | os.PathLike, head: bytes | None = None) -> str:
    """Tell a log's format from its content (the extension is not trusted).

    Args:
        path: the file.
        head: its first bytes, if already read (at least 64 KiB or the whole file).

    Returns:
        ``"bin"`` (DataFlash: starts with 0xA3 0x95 and a FMT message, id 128) or ``"tlog"``
        (8-byte big-endian timestamp before each MAVLink v1/v2 packet, three records chaining).

    Raises:
        InputError: missing, unreadable, empty, or neither format.
    """
    from gcs_sysid.telemetry.tlog_scan import find_sync

    p = Path(path)
    if head is None:
        if not p.exists():
            raise InputError(f"{p}: no such file; expected a MAVLink telemetry log (.tlog) or DataFlash log (.bin)")
        if p.is_dir():
            raise InputError(f"{p}: is a directory; expected a log file (.tlog or .bin)")
        try:
            with open(p, "rb") as f:
                head = f.read(_SNIFF)
        except OSError as exc:
            raise InputError(f"{p}: cannot be read ({exc.strerror}); expected a log file (.tlog or .bin)") from None
    if not head:
        raise InputError(f"{p}: file is empty; expected a MAVLink telemetry log (.tlog) or DataFlash log (.bin)")
    if head[:2] == _DF_HEAD and len(head) > 2 and head[2] == 0x80:
        return "bin"
    if find_sync(head, 0, None, limit=4096) is not None:
        return "tlog"
    kind = "a text file" if _looks_like_text(head) else "unrecognised binary data"
    raise InputError(f"{p}: not a MAVLink log ({kind}); expected a .tlog (8-byte timestamp + MAVLink "
                     "packet per record) or an ArduPilot DataFlash .bin (starting 0xA3 0x95)")


def _looks_like_text(head: bytes) -> bool:
    sample = head[:4096]
    return sum(32 <= b < 127 or b in (9, 10, 13) for b in sample) > 0.95 * len(sample)


def read_log(path: str | os.PathLike, progress: Callable[[float], None] | None = None, helper=None,
             meanwhile: Callable[[], None] | None = None) -> Flight:
    """Decode a flight log to typed SI streams on the vehicle clock.

    The format is detected from the content (:func:`detect_format`); .tlog files are framed here
    and decoded with pymavlink's ardupilotmega dialect, .bin files are read with pymavlink's
    ``DFReader``. Reboots, the 32-bit ``SERVO_OUTPUT_RAW.time_usec`` wrap, duplicated and
    out-of-order packets, corrupt bytes and a truncated end are survived and reported in
    :attr:`Flight.warnings`.

    Args:
        path: the log file.
        progress: optional callable taking the fraction of the file decoded (0..1).
        helper: optional :class:`gcs_sysid.parallel.Helper`: its worker decodes the second part of a
            .tlog while this process decodes the first (same result).
        meanwhile: optional callable run once, while the worker decodes (before this process does;
            for a .bin log or without a worker, simply first): the caller's own preparation.

    Returns:
        A :class:`Flight` with streams named as in ``docs/architecture.md`` ("Canonical streams"),
        per-stream summaries, vehicle facts, parameters, message counts and warnings.

    Raises:
        InputError: a missing, empty or unreadable file, a file in neither format, or a log from
            which no usable message could be decoded. The message is one line naming the file.
    """
    p = Path(path)
    fmt = detect_format(p)
    if fmt == "bin":
        from gcs_sysid.telemetry.dataflash import read_dataflash

        if meanwhile is not None:
            meanwhile()
        flight = read_dataflash(str(p), progress)
    else:
        from gcs_sysid.telemetry.tlog_reader import read_tlog

        flight = read_tlog(str(p), p.read_bytes(), progress, helper, meanwhile)
    if not flight.streams:
        seen = ", ".join(sorted(k for k in flight.messages if k != "BAD_DATA")[:8]) or "nothing"
        raise InputError(f"{p}: no usable messages decoded (found {seen}); expected IMU, attitude, "
                         "air data or servo messages")
    return flight


def cut_window(flight: Flight, t_from: float | None, t_to: float | None) -> Flight:
    """``flight`` restricted to the vehicle-time window ``[t_from, t_to]`` s (None: open end).

    Raises:
        DataError: the window lies outside the log's span (the message gives the span), or holds
            fewer than 2 samples of every stream.
    """
    if t_from is None and t_to is None:
        return flight
    t0, t1 = flight.t_range

    def span() -> str:
        what = " ".join(f"{o} {v:g}" for o, v in (("--from", t_from), ("--to", t_to)) if v is not None)
        return f"{flight.path}: window {what}"

    if not (t0 == t0 and t1 == t1):   # no samples at all (NaN range)
        raise DataError(f"{span()}: the log holds no timed samples")
    lo = -float("inf") if t_from is None else float(t_from)
    hi = float("inf") if t_to is None else float(t_to)
    if hi < t0 or lo > t1:
        raise DataError(f"{span()} is outside the log's {t0:.0f}-{t1:.0f} s (vehicle time since boot); "
                        "expected a window that overlaps it")
    cut = flight.window(t_from, t_to)
    if not any(len(s) >= 2 for s in cut.streams.values()):
        raise DataError(f"{span()} holds fewer than 2 samples of any stream (the log spans "
                        f"{t0:.0f}-{t1:.0f} s); expected a longer window")
    return cut
