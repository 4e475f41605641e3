"""Scanning a tlog in two processes gives exactly the scan of one (clean, corrupt, duplicate at the cut)."""

from pathlib import Path

import numpy as np
import pytest

from gcs_sysid.parallel import Helper
from gcs_sysid.telemetry import read_log, tlog_split
from gcs_sysid.telemetry.mavlink_streams import wanted_fields
from gcs_sysid.telemetry.tlog_scan import find_sync, scan_tlog
from gcs_sysid.telemetry.tlog_split import join_scans, scan_tlog_split

FLIGHT = Path(__file__).resolve().parents[2] / "data" / "flights" / "sim-trainer-sysid.tlog"


@pytest.fixture(scope="module")
def helper():
    with Helper(enabled=True) as h:
        yield h


#: The split does not depend on the file's size beyond its threshold: the tests scan the first
#: ~600 kB of the sample flight (about a fifth of it, cut at a record boundary; every message type
#: the flight streams) with ``MIN_SPLIT_BYTES`` lowered to 256 KiB. On the whole 2.7 MB flight this
#: file took 12 % of the default suite's CPU time (ninth session, docs/benchmarks.md).
PART_BYTES = 600_000


@pytest.fixture(autouse=True)
def _small_threshold(monkeypatch):
    monkeypatch.setattr(tlog_split, "MIN_SPLIT_BYTES", 256 * 1024)


@pytest.fixture(scope="module")
def data() -> bytes:
    whole = FLIGHT.read_bytes()
    return whole[:find_sync(whole, PART_BYTES, None)]


def _same(a, b):
    assert a.counts == b.counts and a.duplicates == b.duplicates
    assert (a.bad_data, a.truncated, a.records) == (b.bad_data, b.truncated, b.records)
    assert (a.seq_lost, a.seq_disorder, a.bad_stamps) == (b.seq_lost, b.seq_disorder, b.bad_stamps)
    assert a.collected.keys() == b.collected.keys()
    for k in a.collected:
        ca, cb = a.collected[k], b.collected[k]
        assert (ca.seq, ca.stamp_us, ca.src, ca.rows) == (cb.seq, cb.stamp_us, cb.src, cb.rows), k


@pytest.mark.parametrize("fraction", [0.1, 0.3, 0.55, 0.8])
def test_split_equals_one_scan(data, helper, monkeypatch, fraction):
    assert len(data) > tlog_split.MIN_SPLIT_BYTES
    monkeypatch.setattr(tlog_split, "HEAD_FRACTION", fraction)
    _same(scan_tlog_split(data, wanted_fields(), helper), scan_tlog(data, wanted_fields()))


def test_corrupt_bytes_at_the_cut(data, helper):
    rng = np.random.default_rng(5)
    for _ in range(4):
        bad = bytearray(data)
        cut = int(tlog_split.HEAD_FRACTION * len(bad)) + int(rng.integers(-2000, 2000))
        for i in rng.integers(cut - 300, cut + 300, size=25):
            bad[i] = int(rng.integers(0, 256))
        bad = bytes(bad)
        one = scan_tlog(bad, wanted_fields())
        assert one.bad_data > 0
        _same(scan_tlog_split(bad, wanted_fields(), helper), one)


def _records(data: bytes, start: int, stop: int) -> list[int]:
    """Offsets of the records starting in [start, stop)."""
    out, pos = [], find_sync(data, start, None)
    while pos is not None and pos < stop:
        out.append(pos)
        pos = scan_tlog(data[pos:], {}, stop=1).end + pos
    return out


def test_duplicate_straddling_the_cut(data):
    """A wanted packet sent twice, the copy just after the cut: one scan drops it, so must the join."""
    wanted = wanted_fields()
    base = sum(scan_tlog(data, wanted).duplicates.values())
    starts = _records(data, len(data) // 2, len(data) // 2 + 4000)
    for a, cut in zip(starts, starts[1:]):
        rec = data[a:cut]
        dup = data[:cut] + rec + data[cut:]
        one = scan_tlog(dup, wanted)
        if sum(one.duplicates.values()) == base + 1:   # the record is of a wanted type
            break
    else:
        pytest.fail("no wanted record near the middle of the sample flight")
    head = scan_tlog(dup, wanted, stop=cut)
    assert head.end == cut
    _same(join_scans(head, scan_tlog(dup[cut:], wanted)), one)


def test_read_log_with_helper_equals_without(helper):
    a, b = read_log(FLIGHT), read_log(FLIGHT, helper=helper)
    assert a.messages == b.messages and a.warnings == b.warnings
    assert a.streams.keys() == b.streams.keys()
    for k in a.streams:
        np.testing.assert_array_equal(a.streams[k].t, b.streams[k].t)
        for f in a.streams[k].fields:
            np.testing.assert_array_equal(a.streams[k].fields[f], b.streams[k].fields[f])


@pytest.mark.parametrize("parallel", [True, False])
def test_meanwhile_runs_once_before_the_head(data, parallel):
    """The caller's own work (the replay's imports) runs once, while the worker scans the tail."""
    calls = []
    with Helper(enabled=parallel) as h:
        scan = scan_tlog_split(data, wanted_fields(), h, progress=lambda f: calls.append(("progress", f)),
                               meanwhile=lambda: calls.append(("meanwhile", None)))
    assert [c for c in calls if c[0] == "meanwhile"] == [("meanwhile", None)]
    assert calls[0] == ("meanwhile", None)   # before any of the head was scanned
    _same(scan, scan_tlog(data, wanted_fields()))
