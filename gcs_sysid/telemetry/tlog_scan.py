"""Fast framing of MAVLink telemetry logs (.tlog), decoding with pymavlink.

A tlog is a sequence of records ``[8-byte big-endian usec wall-clock stamp][MAVLink v1 or v2 packet]``
(the format Mission Planner, MAVProxy and QGroundControl write). This module frames the records
itself, because the packet length sits in byte 1 of each packet, and hands only the packets of the
wanted message ids to pymavlink's generated ``MAVLink.decode`` (CRC check with the dialect's
``crc_extra``, unpacking, scaling of nothing: fields keep their wire units). Unwanted packets are
only counted by id, which is what makes the reader several times faster than a ``recv_match()``
loop, which decodes every packet through the byte-wise parser.

Framing is checked on every record: the packet must start with a MAVLink magic byte (0xFE v1,
0xFD v2) and its stamp must lie within :data:`MAX_STAMP_JUMP_US` of the previous good stamp (the
test pymavlink's ``mavlogfile.scan_timestamp`` uses). When either fails, or a wanted packet fails
its CRC, one ``BAD_DATA`` is counted and the scanner searches forward for the next offset where
three records chain consistently (:func:`find_sync`).

References:
    MAVLink serialization, https://mavlink.io/en/guide/serialization.html (packet layouts).
    pymavlink ``mavutil.mavlogfile`` / ``mavmmaplog`` (tlog record layout and resync heuristics).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from operator import attrgetter
from typing import Callable

from pymavlink.dialects.v20 import ardupilotmega as mavlink

__all__ = ["MAX_STAMP_JUMP_US", "Collected", "TlogScan", "find_sync", "scan_tlog", "msgid_of", "msg_name"]

MAX_STAMP_JUMP_US = 3 * 24 * 3600 * 1_000_000
"""Largest jump between consecutive tlog stamps still taken as in sync (3 days, as pymavlink)."""

_V1, _V2 = 0xFE, 0xFD
_MIN_RECORD = 8 + 8  # stamp + shortest v1 packet (no payload)
_NAME_TO_ID = {cls.msgname: mid for mid, cls in mavlink.mavlink_map.items()}


def msgid_of(name: str) -> int:
    """MAVLink message id of ``name`` in the ardupilotmega dialect (KeyError if unknown)."""
    return _NAME_TO_ID[name]


def msg_name(mid: int) -> str:
    """Message name of id ``mid``, or ``UNKNOWN_<id>`` when the dialect does not define it."""
    cls = mavlink.mavlink_map.get(mid)
    return cls.msgname if cls is not None else f"UNKNOWN_{mid}"


@dataclass
class Collected:
    """Rows of one message type, in file order.

    Attributes:
        seq: record index in the file (orders messages of different types).
        stamp_us: tlog wall-clock stamp, us.
        src: ``(system_id << 8) | component_id`` of the sender.
        rows: one tuple of the requested fields per message, wire units.
    """

    seq: list[int] = field(default_factory=list)
    stamp_us: list[int] = field(default_factory=list)
    src: list[int] = field(default_factory=list)
    rows: list[tuple] = field(default_factory=list)


@dataclass
class TlogScan:
    """What :func:`scan_tlog` found.

    Attributes:
        collected: message name -> :class:`Collected` (wanted types only).
        counts: message name -> count of every framed packet, plus ``BAD_DATA``.
        duplicates: message name -> byte-identical repeats dropped.
        bad_data: packets that failed their CRC or broke the framing.
        truncated: the file ends inside a record.
        records: records framed.
        end: offset where the scan stopped (``len(data)``, or the ``stop`` record boundary).
        first, last: message name -> ``(packet bytes, stamp_us)`` of the first and the last packet
            of each wanted type that was kept (to join the scans of two parts of a file).
    """

    collected: dict[str, Collected]
    counts: dict[str, int]
    duplicates: dict[str, int]
    bad_data: int
    truncated: bool
    records: int
    end: int = 0
    first: dict[str, tuple[bytes, int]] = field(default_factory=dict)
    last: dict[str, tuple[bytes, int]] = field(default_factory=dict)


def _record(data: bytes, pos: int) -> tuple[int, int, int] | None:
    """(msgid, record length, src) of the record at ``pos``, or None when no packet starts there."""
    n = len(data)
    if pos + _MIN_RECORD > n:
        return None
    mk = data[pos + 8]
    if mk == _V1:
        return data[pos + 13], 8 + data[pos + 9] + 8, (data[pos + 11] << 8) | data[pos + 12]
    if mk == _V2:
        if pos + 18 > n:
            return None
        ln = 8 + data[pos + 9] + 12 + (13 if data[pos + 10] & 1 else 0)
        mid = data[pos + 15] | (data[pos + 16] << 8) | (data[pos + 17] << 16)
        return mid, ln, (data[pos + 13] << 8) | data[pos + 14]
    return None


def _chain_ok(data: bytes, pos: int, ref_us: int | None, depth: int = 3) -> bool:
    """True if ``depth`` records chain from ``pos`` (or reach the end of file exactly)."""
    n = len(data)
    for _ in range(depth):
        if pos == n:
            return True
        rec = _record(data, pos)
        if rec is None or pos + rec[1] > n:
            return False
        stamp = int.from_bytes(data[pos:pos + 8], "big")
        if ref_us is not None and abs(stamp - ref_us) > MAX_STAMP_JUMP_US:
            return False
        ref_us = stamp
        pos += rec[1]
    return True


def find_sync(data: bytes, start: int, ref_us: int | None, limit: int | None = None) -> int | None:
    """First offset ``>= start`` where three tlog records chain consistently.

    Args:
        data: whole file.
        start: first candidate offset.
        ref_us: last good stamp (us) the next ones must lie near, or None at the start of a file.
        limit: give up after this many bytes (None: search to the end).

    Returns:
        The offset, or None when no consistent record was found.
    """
    n = len(data)
    end = n if limit is None else min(n, start + limit)
    p = start + 8
    while p < end + 8:
        a, b = data.find(b"\xfe", p, end + 8), data.find(b"\xfd", p, end + 8)
        cands = [c for c in (a, b) if c >= 0]
        if not cands:
            return None
        p = min(cands)
        if _chain_ok(data, p - 8, ref_us):
            return p - 8
        p += 1
    return None


def scan_tlog(data: bytes, wanted: dict[str, tuple[str, ...]],
              progress: Callable[[float], None] | None = None, stop: int | None = None) -> TlogScan:
    """Frame every record of a tlog and decode the wanted message types.

    Args:
        data: the whole file.
        wanted: message name -> field names to collect, in order (wire units).
        progress: optional callable given the fraction of the file done (0..1).
        stop: end the scan at the first record that starts at or after this offset
            (:attr:`TlogScan.end` tells where it ended); None: scan to the end.

    Returns:
        A :class:`TlogScan`. Never raises on bad bytes: they are counted as ``BAD_DATA``.
    """
    n = len(data)
    mav = mavlink.MAVLink(None)
    decode = mav.decode
    getters: dict[int, tuple[Callable, Collected]] = {}
    collected: dict[str, Collected] = {}
    for name, fields in wanted.items():
        if name not in _NAME_TO_ID:
            continue
        col = collected[name] = Collected()
        get = attrgetter(*fields)
        if len(fields) == 1:
            get = (lambda g: lambda m: (g(m),))(get)
        getters[_NAME_TO_ID[name]] = (get, col)
    counts: dict[int, int] = {}
    dups: dict[int, int] = {}
    first: dict[int, tuple[bytes, int]] = {}
    last: dict[int, tuple[bytes, int]] = {}
    bad = 0
    limit = n if stop is None else min(int(stop), n)
    truncated = False
    records = 0
    step = max(n // 100, 1 << 16)
    next_report = step
    pos = find_sync(data, 0, None)
    if pos is None:
        return TlogScan(collected, {}, {}, 0, False, 0, end=n)
    ref = int.from_bytes(data[pos:pos + 8], "big")
    prefix = data[pos:pos + 3]
    stopped = n
    while pos < limit:
        if pos + _MIN_RECORD > n:
            truncated = True
            break
        mk = data[pos + 8]
        if mk == _V1:
            end = pos + 16 + data[pos + 9]
            mid = data[pos + 13]
            src = (data[pos + 11] << 8) | data[pos + 12]
        elif mk == _V2 and pos + 18 <= n:
            end = pos + 20 + data[pos + 9] + (13 if data[pos + 10] & 1 else 0)
            mid = data[pos + 15] | (data[pos + 16] << 8) | (data[pos + 17] << 16)
            src = (data[pos + 13] << 8) | data[pos + 14]
        elif mk == _V2:
            truncated = True
            break
        else:
            end = -1
        if end >= 0 and data[pos:pos + 3] != prefix:
            stamp = int.from_bytes(data[pos:pos + 8], "big")
            if abs(stamp - ref) > MAX_STAMP_JUMP_US:
                end = -1
            else:
                ref, prefix = stamp, data[pos:pos + 3]
        if end > n:
            # the last record runs past the end of file: truncated, unless the framing is lost
            nxt = find_sync(data, pos + 1, ref)
            if nxt is None:
                truncated = True
                break
            end = -1
        if end < 0:
            bad += 1
            nxt = find_sync(data, pos + 1, ref)
            if nxt is None:
                break
            pos = nxt
            continue
        records += 1
        counts[mid] = counts.get(mid, 0) + 1
        ent = getters.get(mid)
        if ent is not None:
            buf = data[pos + 8:end]
            stamp = int.from_bytes(data[pos:pos + 8], "big")
            prev = last.get(mid)
            if prev is not None and prev[0] == buf and stamp - prev[1] < 2_000_000:
                dups[mid] = dups.get(mid, 0) + 1
            else:
                last[mid] = (buf, stamp)
                if prev is None:
                    first[mid] = last[mid]
                try:
                    msg = decode(bytearray(buf))
                except Exception:  # pymavlink raises MAVError, struct.error, ... on bad packets
                    counts[mid] -= 1
                    records -= 1
                    bad += 1
                    nxt = find_sync(data, pos + 1, ref)
                    if nxt is None:
                        break
                    pos = nxt
                    continue
                get, col = ent
                col.seq.append(records)
                col.stamp_us.append(stamp)
                col.src.append(src)
                col.rows.append(get(msg))
        pos = end
        if progress is not None and pos >= next_report:
            progress(min(pos / limit, 1.0))
            next_report = pos + step
    else:
        stopped = min(pos, n)   # reached ``stop`` (or the end); a break above consumed the rest of the file
    if progress is not None:
        progress(1.0)
    names = {msg_name(k): v for k, v in counts.items()}
    if bad:
        names["BAD_DATA"] = bad
    return TlogScan(collected, names, {msg_name(k): v for k, v in dups.items()}, bad, truncated, records,
                    end=stopped, first={msg_name(k): v for k, v in first.items()},
                    last={msg_name(k): v for k, v in last.items()})
