"""Bad input: one-line InputError naming the file, or a partial flight with warnings."""

import numpy as np
import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink
from tlog_factory import TlogWriter, heartbeat, write_flight

from gcs_sysid.errors import InputError
from gcs_sysid.telemetry import detect_format, read_log


def _one_line_error(path, match):
    with pytest.raises(InputError, match=match) as ei:
        read_log(path)
    msg = str(ei.value)
    assert "\n" not in msg and str(path) in msg
    return msg


def test_missing_empty_directory(tmp_path):
    _one_line_error(tmp_path / "nope.tlog", "no such file")
    (tmp_path / "empty.tlog").write_bytes(b"")
    _one_line_error(tmp_path / "empty.tlog", "file is empty")
    _one_line_error(tmp_path, "is a directory")


def test_text_and_random_bytes_are_not_mavlink(tmp_path):
    (tmp_path / "notes.tlog").write_text("time,roll,pitch\n0.0,0.1,0.2\n" * 50)
    _one_line_error(tmp_path / "notes.tlog", "not a MAVLink log \\(a text file\\)")
    rng = np.random.default_rng(1)
    (tmp_path / "noise.bin").write_bytes(rng.integers(0, 256, 20000, dtype=np.uint8).tobytes())
    _one_line_error(tmp_path / "noise.bin", "not a MAVLink log \\(unrecognised binary data\\)")


def test_truncated_log_keeps_what_decoded(tmp_path):
    data = write_flight(tmp_path / "full.tlog", n=50).read_bytes()
    (tmp_path / "cut.tlog").write_bytes(data[: len(data) // 2 + 7])
    f = read_log(tmp_path / "cut.tlog")
    assert 20 <= len(f["attitude"]) < 50
    assert any("truncated" in w for w in f.warnings)
    (tmp_path / "stub.tlog").write_bytes(data[:12])
    _one_line_error(tmp_path / "stub.tlog", "not a MAVLink log")


def test_corrupt_bytes_are_counted_and_skipped(tmp_path):
    data = bytearray(write_flight(tmp_path / "ok.tlog", n=200).read_bytes())
    rng = np.random.default_rng(7)
    for pos in rng.integers(1000, len(data) - 1000, 12):
        data[pos] ^= 0xFF
    (tmp_path / "bad.tlog").write_bytes(bytes(data))
    f = read_log(tmp_path / "bad.tlog")
    assert f.messages["BAD_DATA"] >= 1
    assert len(f["attitude"]) >= 170 and len(f["imu"]) >= 170
    assert any("BAD_DATA" in w for w in f.warnings)
    for s in f.streams.values():
        assert np.all(np.diff(s.t) > 0)


def test_log_without_imu_or_servo_decodes_with_warnings(tmp_path):
    w = TlogWriter()
    w.add(0.0, heartbeat())
    for i in range(10):
        w.add(0.02 * i, mavlink.MAVLink_attitude_message(1000 + 20 * i, 0, 0, 0, 0, 0, 0))
    f = read_log(w.write(tmp_path / "att.tlog"))
    assert f.has("attitude")
    assert any(x.startswith("no IMU data") for x in f.warnings)
    assert any(x.startswith("no servo output data") for x in f.warnings)


def test_unknown_messages_are_counted(tmp_path):
    w = TlogWriter()
    for i in range(10):
        w.add(0.02 * i, mavlink.MAVLink_attitude_message(1000 + 20 * i, 0, 0, 0, 0, 0, 0))
        # a MAVLink 2 packet with an id no dialect defines (framing is all that is needed)
        payload = bytes(range(6))
        w.add_raw(0.02 * i + 0.001, bytes([0xFD, len(payload), 0, 0, i, 1, 1, 0x60, 0xEA, 0x00]) + payload + b"\0\0")
    f = read_log(w.write(tmp_path / "unk.tlog"))
    assert f.messages["UNKNOWN_60000"] == 10
    assert len(f["attitude"]) == 10


def test_only_unusable_messages_is_an_error(tmp_path):
    w = TlogWriter()
    for i in range(5):
        w.add(0.1 * i, mavlink.MAVLink_system_time_message(0, 100 * i))
    _one_line_error(w.write(tmp_path / "st.tlog"), "no usable messages")


def test_format_is_detected_from_content_not_extension(tmp_path):
    p = write_flight(tmp_path / "really_a_tlog.bin", n=5)
    assert detect_format(p) == "tlog"
    assert read_log(p).format == "tlog"


def test_progress_is_reported(tmp_path):
    seen = []
    read_log(write_flight(tmp_path / "p.tlog", n=50), progress=seen.append)
    assert seen and seen[-1] == 1.0 and all(0 <= a <= b <= 1 for a, b in zip(seen, seen[1:]))
