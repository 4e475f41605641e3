"""Scanning a tlog in two parts at once: this process the head, a helper's worker the tail.

Decoding is the one stage of a replay that only reads the file, so it splits cleanly: the
file is cut at a record boundary (:func:`~gcs_sysid.telemetry.tlog_scan.find_sync` near
:data:`HEAD_FRACTION` of its length), the worker (:class:`gcs_sysid.parallel.Helper`) scans
the tail while this process scans the head up to the cut, and the two
:class:`~gcs_sysid.telemetry.tlog_scan.TlogScan` are joined: record numbers of the tail are
shifted by the records of the head, counts added, and a tail packet that repeats the head's
last packet of its type (byte for byte, within 2 s) is dropped as a duplicate, as one scan
would have done.

The join is exact when the head's scan ends on the cut. When it does not (the cut sat on
bytes that only looked like a record, in a corrupt file), the head's scan runs on to the end
of the file by itself and the worker's result is not used, so the result is always that of
one scan of the whole file.
"""

from __future__ import annotations

from typing import Callable

from gcs_sysid.telemetry.tlog_scan import Collected, TlogScan, _crc_ok, find_sync, scan_tlog, seq_step

__all__ = ["HEAD_FRACTION", "HEAD_FRACTION_BUSY", "MIN_SPLIT_BYTES", "scan_tlog_split", "join_scans"]

#: Share of the file this process scans; the worker starts about 0.1 s later and hands back its rows.
HEAD_FRACTION = 0.55
#: The same when the caller has its own work to do first (``meanwhile``: the replay's estimation imports, ~0.8
#: CPU s since the twenty-ninth session, which moved JAX's to the estimation stage; ~1.6 CPU s before, when 10 %
#: was kept here). With 30 % the decode stage cost the main process 1.56 CPU s and the worker (its start-up
#: included) 1.23 on the benchmark flight; 20 % evens the two out (``docs/benchmarks.md``, "Twenty-ninth session,
#: speed29").
HEAD_FRACTION_BUSY = 0.2
#: Files smaller than this are scanned in one piece (the hand-over would cost more than it saves).
MIN_SPLIT_BYTES = 1 << 20


def join_scans(head: TlogScan, tail: TlogScan) -> TlogScan:
    """The scan of a file from the scans of its head (ending on a record boundary) and its tail.

    Args:
        head: scan of ``data[:cut]`` (its :attr:`~TlogScan.end` is the cut).
        tail: scan of ``data[cut:]``.

    Returns:
        The joined :class:`TlogScan`; ``end``, ``first`` and ``last`` describe the whole file. The
        head's per-type row lists are extended in place (no copy of the rows), so ``head`` is used up.
    """
    counts = dict(head.counts)
    dups = dict(head.duplicates)
    for k, v in tail.counts.items():
        counts[k] = counts.get(k, 0) + v
    for k, v in tail.duplicates.items():
        dups[k] = dups.get(k, 0) + v
    collected = {}
    for name in head.collected.keys() | tail.collected.keys():
        h, t = head.collected.get(name), tail.collected.get(name)
        if t is None or not t.seq:
            collected[name] = h if h is not None else t
            continue
        drop = 0
        prev, nxt = head.last.get(name), tail.first.get(name)
        if prev is not None and nxt is not None and prev[0] == nxt[0] and nxt[1] - prev[1] < 2_000_000:
            drop = 1   # the tail's first packet repeats the head's last: one scan counts it as a duplicate
            dups[name] = dups.get(name, 0) + 1
        off = head.records
        if h is None:
            h = Collected()
        h.seq.extend(s + off for s in t.seq[drop:])
        h.stamp_us.extend(t.stamp_us[drop:])
        h.src.extend(t.src[drop:])
        h.rows.extend(t.rows[drop:])
        collected[name] = h
    bad = head.bad_data + tail.bad_data
    if bad:
        counts["BAD_DATA"] = bad
    first = dict(tail.first)
    first.update(head.first)
    last = dict(head.last)
    last.update(tail.last)
    lost, disorder = head.seq_lost + tail.seq_lost, head.seq_disorder + tail.seq_disorder
    for src, sq in tail.seq_first.items():   # the step across the cut, as one scan sees it
        if src in head.seq_last:
            dl, dd = seq_step(head.seq_last[src], sq)
            lost, disorder = lost + dl, disorder + dd
    seq_first = dict(tail.seq_first)
    seq_first.update(head.seq_first)
    seq_last = dict(head.seq_last)
    seq_last.update(tail.seq_last)
    return TlogScan(collected, counts, dups, bad, tail.truncated, head.records + tail.records, end=tail.end + head.end,
                    first=first, last=last, seq_lost=lost, seq_disorder=disorder, seq_first=seq_first,
                    seq_last=seq_last, bad_stamps=head.bad_stamps + tail.bad_stamps)


def _sound_cut(data: bytes, start: int, tries: int = 64) -> int | None:
    """A record boundary at or after ``start`` whose record passes its CRC, or None.

    One scan never looks back past a sound record (it resynchronises at most from just after the start
    of the record before a damaged one), so a scan starting there sees what one scan of the whole file
    sees from there on.
    """
    pos = start
    for _ in range(tries):
        cut = find_sync(data, pos, None)
        if cut is None or _crc_ok(data, cut):
            return cut
        pos = cut + 1
    return None


def scan_tlog_split(data: bytes, wanted: dict[str, tuple[str, ...]], helper,
                    progress: Callable[[float], None] | None = None,
                    meanwhile: Callable[[], None] | None = None) -> TlogScan:
    """:func:`~gcs_sysid.telemetry.tlog_scan.scan_tlog` of ``data``, the tail scanned by ``helper``'s worker.

    Args:
        data: the whole file. wanted: message name -> fields (as for ``scan_tlog``).
        helper: a :class:`gcs_sysid.parallel.Helper`; without a worker (or for a small file) one scan.
        progress: optional callable given the fraction of the head done (0..1).
        meanwhile: optional callable run once, after the tail went to the worker and before the
            head is scanned (the caller's own preparation, e.g. its imports, overlaps the tail).

    Returns:
        The same :class:`TlogScan` as one scan of the whole file.
    """
    n = len(data)
    fraction = HEAD_FRACTION if meanwhile is None else HEAD_FRACTION_BUSY
    cut = _sound_cut(data, int(fraction * n)) if helper is not None and helper.parallel else None
    if n < MIN_SPLIT_BYTES or cut is None or cut <= 0:
        if meanwhile is not None:
            meanwhile()
        return scan_tlog(data, wanted, progress)
    job = helper.submit("gcs_sysid.telemetry.tlog_scan:scan_tlog", data[cut:], wanted)
    if meanwhile is not None:
        meanwhile()
    head = scan_tlog(data, wanted, progress, stop=cut)
    if head.end != cut:   # the head ran past the cut (it was no record boundary) or ended early
        return scan_tlog(data, wanted, progress)
    return join_scans(head, job.result())
