"""Damaged logs: the resync keeps every sound packet (at least what pymavlink's reader keeps), and the
damage is named in ``Flight.damage`` (corrupt, truncated incl. DataFlash, missing, out of sequence)."""

from collections import Counter
from pathlib import Path

import pytest
from pymavlink import mavutil
from test_telemetry_dataflash import DFWriter, _flight
from tlog_factory import write_flight

from gcs_sysid.telemetry import read_log
from gcs_sysid.telemetry.mavlink_streams import wanted_fields
from gcs_sysid.telemetry.tlog_scan import scan_tlog

FLIGHT = Path(__file__).resolve().parents[2] / "data" / "flights" / "sim-trainer-sysid.tlog"


def _records(data: bytes) -> list[int]:
    """Record offsets of an intact tlog."""
    out, pos = [], 0
    while pos + 16 <= len(data):
        out.append(pos)
        pos += 16 + data[pos + 9] if data[pos + 8] == 0xFE else 20 + data[pos + 9] + (13 if data[pos + 10] & 1 else 0)
    return out


def test_resync_keeps_at_least_what_pymavlink_keeps(tmp_path):
    """Every 50th byte corrupted (the issue's case): pymavlink kept 1,296 ATTITUDE where the old resync kept
    1,010. Now at least as many, and every row kept is a row of the intact log (no false packets)."""
    clean = FLIGHT.read_bytes()[: 700_000]
    bad = bytearray(clean)
    for i in range(49, len(bad), 50):
        bad[i] ^= 0xFF
    path = tmp_path / "bad.tlog"
    path.write_bytes(bytes(bad))
    conn = mavutil.mavlink_connection(str(path), dialect="ardupilotmega")
    theirs = Counter()
    while (m := conn.recv_match()) is not None:
        theirs[m.get_type()] += 1
    conn.close()
    wanted = wanted_fields()
    ours = scan_tlog(bytes(bad), wanted)
    truth = scan_tlog(clean, wanted)
    for name in ("ATTITUDE", "RAW_IMU", "SERVO_OUTPUT_RAW", "VFR_HUD", "SCALED_PRESSURE"):
        kept = ours.collected[name].rows
        assert len(kept) >= theirs[name] > 0, (name, len(kept), theirs[name])
        assert set(kept) <= set(truth.collected[name].rows), name
    f = read_log(path)
    assert any("corrupt packet" in d for d in f.damage)
    assert f.t_range[0] >= 29.9 and f.t_range[1] <= 270.1   # damaged stamps do not throw times around


def test_intact_logs_have_no_damage():
    assert read_log(FLIGHT).damage == []


def test_dropped_duplicated_and_spliced_packets_are_named(tmp_path):
    data = write_flight(tmp_path / "ok.tlog", n=200).read_bytes()
    assert read_log(tmp_path / "ok.tlog").damage == []
    rec = _records(data)
    a, b = rec[100], rec[101]
    (tmp_path / "drop.tlog").write_bytes(data[:a] + data[b:])
    assert any("missing from the MAVLink sequence" in d for d in read_log(tmp_path / "drop.tlog").damage)
    (tmp_path / "dup.tlog").write_bytes(data[:b] + data[a:b] + data[b:])
    dmg = read_log(tmp_path / "dup.tlog").damage
    assert any("out of sequence" in d or "duplicated" in d for d in dmg), dmg
    (tmp_path / "splice.tlog").write_bytes(data[: rec[300] + 11] + data[rec[40]:])
    dmg = read_log(tmp_path / "splice.tlog").damage
    assert any("corrupt packet" in d for d in dmg) and any("sequence" in d for d in dmg), dmg


@pytest.fixture()
def binlog(tmp_path):
    w = DFWriter()
    w.add("PARM", 1000, b"ARSPD_RATIO", 2.0)
    _flight(w, 5_000_000, 50)
    return bytes(w.buf)


def test_dataflash_truncated_mid_record(binlog, tmp_path):
    whole = tmp_path / "whole.bin"
    whole.write_bytes(binlog)
    assert read_log(whole).damage == []
    for cut in (len(binlog) - 7, len(binlog) - 40, len(binlog) - 1):   # inside the last records
        p = tmp_path / f"cut{cut}.bin"
        p.write_bytes(binlog[:cut])
        f = read_log(p)
        assert any("truncated" in d for d in f.damage), (cut, f.damage)
        assert len(f["attitude"]) >= 48
