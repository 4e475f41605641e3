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
from pymavlink.generator.mavcrc import mcrf4xx as _fast_crc
from pymavlink.generator.mavcrc import x25crc

__all__ = ["MAX_STAMP_JUMP_US", "Collected", "TlogScan", "find_sync", "scan_tlog", "seq_step", "msgid_of",
           "msg_name"]

MAX_STAMP_JUMP_US = 3 * 24 * 3600 * 1_000_000
"""Largest jump between consecutive tlog stamps still taken as in sync (3 days, as pymavlink)."""

_V1, _V2 = 0xFE, 0xFD
_MIN_RECORD = 8 + 8  # stamp + shortest v1 packet (no payload)
_NAME_TO_ID = {cls.msgname: mid for mid, cls in mavlink.mavlink_map.items()}


def _crc16(buf: bytes, crc: int) -> int:
    """CRC-16/MCRF4XX of ``buf`` continuing from ``crc`` (MAVLink's X.25 checksum; fastcrc when installed)."""
    if _fast_crc is not None:
        return _fast_crc(bytes(buf), crc)
    x = x25crc()
    x.crc = crc
    x.accumulate(bytes(buf))
    return x.crc


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
        seq_lost: packets missing from the senders' MAVLink sequence numbers (each sender counts its
            packets modulo 256; a forward jump of ``d`` means ``d - 1`` packets lost on the link, to
            corrupt bytes, or cut out of the file).
        seq_disorder: packets whose sequence number repeats or goes back (duplicated, reordered or
            spliced data).
        seq_first, seq_last: sender ``src`` -> its first and last sequence number (to join scans).
        bad_stamps: sound packets kept behind a damaged log stamp (given the stamp before them).
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
    seq_lost: int = 0
    seq_disorder: int = 0
    seq_first: dict[int, int] = field(default_factory=dict)
    seq_last: dict[int, int] = field(default_factory=dict)
    bad_stamps: int = 0


def seq_step(prev: int, nxt: int) -> tuple[int, int]:
    """(lost, disorder) between two consecutive sequence numbers of one sender (see :class:`TlogScan`)."""
    d = (nxt - prev) & 255
    if d == 1:
        return 0, 0
    if 1 < d < 128:
        return d - 1, 0
    return 0, 1


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


def _crc_ok(data: bytes, pos: int) -> bool:
    """True if the MAVLink packet of the record at ``pos`` passes its CRC (with the dialect's crc_extra).

    A packet of an id the dialect does not define, or one running past the end of ``data``, fails.
    """
    rec = _record(data, pos)
    if rec is None:
        return False
    mid, ln, _src = rec
    cls = mavlink.mavlink_map.get(mid)
    if cls is None or pos + ln > len(data):
        return False
    hdr = 6 if data[pos + 8] == _V1 else 10
    body_end = pos + 8 + hdr + data[pos + 9]
    crc = _crc16(data[pos + 9:body_end], 0xFFFF)
    crc = _crc16(bytes((cls.crc_extra,)), crc)
    return crc == (data[body_end] | (data[body_end + 1] << 8))


def find_sync(data: bytes, start: int, ref_us: int | None, limit: int | None = None,
              crc: bool = False) -> int | None:
    """First offset ``>= start`` where a tlog record starts: three records chain consistently, or
    (with ``crc``) the record's packet passes its CRC.

    Args:
        data: whole file.
        start: first candidate offset.
        ref_us: last good stamp (us) the chained stamps must lie near, or None at the start of a file.
        limit: give up after this many bytes (None: search to the end).
        crc: also accept a single record whose packet passes its CRC (what pymavlink's byte-wise
            parser accepts), whatever its neighbours; used to resynchronise inside a damaged file,
            where the next records may be damaged too. Off for telling the format of a file and
            for choosing where to split one (a chain of three is the stricter test).

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
        if (crc and _crc_ok(data, p - 8)) or _chain_ok(data, p - 8, ref_us):
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
    unchecked = -1   # start of the previous record when it was framed on its length byte alone (no CRC)
    unchecked_mid = -1
    good = pos       # start of the last record taken with a sound stamp
    fixed_at = fixed_stamp = -1   # a record kept behind a damaged stamp, and the stamp it is given
    seqs: dict[int, int] = {}
    seq_first: dict[int, int] = {}
    glitch: dict[int, tuple[int, int, int, int]] = {}   # src -> (seq, seq before it, lost, disorder) of a jump
    lost = disorder = bad_stamps = 0
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
            if abs(stamp - ref) <= MAX_STAMP_JUMP_US:
                ref, prefix = stamp, data[pos:pos + 3]
            elif end <= n and _crc_ok(data, pos):
                # a sound packet behind a damaged stamp: keep it, at the stamp of the record before it
                fixed_at, fixed_stamp = pos, int.from_bytes(data[good:good + 8], "big")
                bad_stamps += 1
            else:
                end = -1
        if end < 0 or end > n:
            past_end = end > n
            back = pos + 1
            if unchecked >= 0 and not _crc_ok(data, unchecked):
                # the previous record was framed by its length byte alone and its packet is damaged: the
                # damage may have started there (a wrong length lands here), so search again from just
                # after its start rather than from here, which would skip the records in between
                counts[unchecked_mid] -= 1
                records -= 1
                back = unchecked + 1
            unchecked = -1
            nxt = find_sync(data, back, ref, crc=True)
            if nxt is None:
                if past_end:
                    truncated = True   # the last record runs past the end of the file
                else:
                    bad += 1
                break
            bad += 1
            pos = nxt
            continue
        records += 1
        counts[mid] = counts.get(mid, 0) + 1
        sq = data[pos + 10] if mk == _V1 else data[pos + 12]
        prev_sq = seqs.get(src, -1)
        seqs[src] = sq
        if prev_sq < 0:
            seq_first[src] = sq
        elif (prev_sq + 1) & 255 != sq:
            g = glitch.pop(src, None)
            base = prev_sq
            if g is not None and g[0] == prev_sq:
                # the previous packet jumped too: its sequence byte is taken as damaged, and the step is
                # counted from the last number before it (a run of damaged numbers counts as one step)
                lost -= g[2]
                disorder -= g[3]
                base = g[1]
            dl, dd = seq_step(base, sq)
            lost += dl
            disorder += dd
            glitch[src] = (sq, base, dl, dd)
        ent = getters.get(mid)
        if ent is None:
            unchecked, unchecked_mid = pos, mid
        else:
            unchecked = -1
            buf = data[pos + 8:end]
            stamp = int.from_bytes(data[pos:pos + 8], "big") if pos != fixed_at else fixed_stamp
            prev = last.get(mid)
            if prev is not None and prev[0] == buf and stamp - prev[1] < 2_000_000:
                dups[mid] = dups.get(mid, 0) + 1
            else:
                try:
                    msg = decode(bytearray(buf))
                except Exception:  # pymavlink raises MAVError, struct.error, ... on bad packets
                    counts[mid] -= 1
                    records -= 1
                    bad += 1
                    # a damaged packet whose length byte holds (the next record starts where it says):
                    # only this packet is lost; otherwise search from the next byte
                    if end == n or _chain_ok(data, end, ref, depth=1):
                        pos = end
                        continue
                    nxt = find_sync(data, pos + 1, ref, crc=True)
                    if nxt is None:
                        break
                    pos = nxt
                    continue
                last[mid] = (buf, stamp)
                if prev is None:
                    first[mid] = last[mid]
                get, col = ent
                col.seq.append(records)
                col.stamp_us.append(stamp)
                col.src.append(src)
                col.rows.append(get(msg))
        if pos != fixed_at:
            good = pos
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
                    last={msg_name(k): v for k, v in last.items()}, seq_lost=lost, seq_disorder=disorder,
                    seq_first=seq_first, seq_last=seqs, bad_stamps=bad_stamps)
