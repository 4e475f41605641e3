"""DataFlash (.bin): a minimal valid log written here (FMT records + messages), read with DFReader.

pymavlink cannot write DataFlash, so the bytes are built from the format: each record is
0xA3 0x95 <msg id> <payload>; FMT (id 128) defines the others: Type, Length (with the 3-byte
header), Name (4 chars), Format (16), Columns (64).
"""

import struct

import numpy as np
import pytest

from gcs_sysid.telemetry import detect_format, read_log

_CHARS = {"Q": "Q", "B": "B", "f": "f", "H": "H", "I": "I", "L": "i", "N": "16s", "Z": "64s"}
_TYPES = {  # name: (id, format, columns)
    "IMU": (1, "QBffffff", "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ"),
    "ATT": (2, "Qfff", "TimeUS,Roll,Pitch,Yaw"),
    "RCOU": (3, "Q" + "H" * 14, "TimeUS," + ",".join(f"C{i}" for i in range(1, 15))),
    "GPS": (4, "QBIHLLffff", "TimeUS,I,GMS,GWk,Lat,Lng,Alt,Spd,GCrs,VZ"),
    "XKF2": (5, "QBff", "TimeUS,C,VWN,VWE"),
    "PARM": (6, "QNf", "TimeUS,Name,Value"),
    "MSG": (7, "QZ", "TimeUS,Message"),
}


def _st(fmt):
    return "<" + "".join(_CHARS[c] for c in fmt)


class DFWriter:
    def __init__(self):
        self.buf = bytearray()
        for name, (mid, fmt, cols) in _TYPES.items():
            ln = 3 + struct.calcsize(_st(fmt))
            self.buf += b"\xa3\x95\x80" + struct.pack("<BB4s16s64s", mid, ln, name.encode(), fmt.encode(),
                                                      cols.encode())

    def add(self, name, *vals):
        mid, fmt, _ = _TYPES[name]
        self.buf += bytes([0xA3, 0x95, mid]) + struct.pack(_st(fmt), *vals)


def _flight(w, t0_us, n):
    for i in range(n):
        t = t0_us + i * 20_000
        w.add("IMU", t, 0, 0.1, 0.2, 0.3, 1.0, 2.0, -9.8)
        w.add("IMU", t, 1, 0.0, 0.0, 0.0, 0.0, 0.0, -9.8)
        w.add("ATT", t, 10.0, -5.0, 90.0)
        w.add("RCOU", t, *([1500 + i] + [1000] * 13))
        if i % 10 == 0:
            w.add("GPS", t, 0, 100_000 + t // 1000, 2200, -353632622, 1491652374, 584.0, 20.0, 90.0, 0.5)
            w.add("XKF2", t, 0, 3.0, -4.0)


@pytest.fixture()
def binlog(tmp_path):
    w = DFWriter()
    w.add("PARM", 1000, b"ARSPD_RATIO", 2.0)
    w.add("MSG", 1000, b"ArduPlane V4.7.0")
    _flight(w, 5_000_000, 50)
    p = tmp_path / "log.bin"
    p.write_bytes(bytes(w.buf))
    return p, w


def test_dataflash_streams_and_units(binlog):
    f = read_log(binlog[0])
    assert f.format == "bin"
    imu = f["imu"]
    assert imu.source == "IMU[0]" and len(imu) == 50 and f["imu2"].source == "IMU[1]"
    np.testing.assert_allclose(imu.t, 5.0 + 0.02 * np.arange(50))
    np.testing.assert_allclose([imu["p"][0], imu["az"][0]], [0.1, -9.8], rtol=1e-6)
    np.testing.assert_allclose([f["attitude"]["roll"][0], f["attitude"]["yaw"][0]], np.radians([10.0, 90.0]),
                               rtol=1e-6)
    np.testing.assert_allclose(f["servo"]["pwm1"], 1500 + np.arange(50))
    g = f["gps"]
    np.testing.assert_allclose([g["lat"][0], g["vn"][0], g["ve"][0], g["vd"][0]],
                               [np.radians(-35.3632622), 0.0, 20.0, 0.5], atol=1e-6)
    np.testing.assert_allclose([f["wind"]["wn"][0], f["wind"]["we"][0]], [3.0, -4.0])
    assert f.params["ARSPD_RATIO"] == 2.0
    assert f.statustext[0][1] == "ArduPlane V4.7.0"
    assert f.messages["IMU"] == 100 and f.summaries["imu"].rate_hz == pytest.approx(50.0)


def test_dataflash_reboot_and_corruption(binlog, tmp_path):
    _, w = binlog
    _flight(w, 1_000_000, 20)  # reboot: TimeUS starts again at 1 s
    data = bytes(w.buf[:3000]) + b"\x00\x17garbage!" + bytes(w.buf[3000:])
    p = tmp_path / "reboot.tlog"  # the extension lies: content decides
    p.write_bytes(data)
    assert detect_format(p) == "bin"
    f = read_log(p)
    att = f["attitude"]
    assert np.all(np.diff(att.t) > 0) and len(att) == 70
    assert any("reboot" in x for x in f.warnings)
    assert f.messages.get("BAD_DATA", 0) >= 1
