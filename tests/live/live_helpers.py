"""Shared pieces of the live tests: free ports, the player as a subprocess, a faulty UDP relay."""

from __future__ import annotations

import random
import shutil
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
FLIGHT = REPO / "data" / "flights" / "sim-trainer-sysid.tlog"
AIRFRAME = REPO / "data" / "airframes" / "sim-trainer.toml"


def free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def player(log, link: str, *args, cwd=None) -> subprocess.Popen:
    """The installed console command when on PATH beside this interpreter, else ``python -m replay``."""
    exe = Path(sys.executable).with_name("gcs-sysid-player")
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "replay"]
    return subprocess.Popen(cmd + [str(log), "--link", link, *map(str, args)], cwd=cwd or REPO,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def read_records(path) -> list[bytes]:
    """Packets of a tlog (framing by the package's own reader)."""
    from gcs_sysid.live.learner import iter_tlog_records

    return [p for _, p in iter_tlog_records(path)]


class FaultyRelay:
    """UDP relay 127.0.0.1:in_port -> 127.0.0.1:out_port that breaks the stream on purpose (seeded).

    Args:
        drop: probability a datagram is dropped.
        corrupt: probability one payload byte of a datagram is flipped (its CRC then fails).
        duplicate: probability a datagram is sent twice.
        reorder: probability a datagram is held back and sent after the next one.
        noise: probability a datagram of random bytes (no MAVLink magic) is sent before it.
        silence: (start, length) in datagrams: the ``length`` datagrams from ``start`` are held
            for ``pause_s`` and then dropped (a link outage).
        flood: each datagram sent this many times (a 10x flood), after the other faults.
    Attributes:
        delivered: the intact packets sent on, in order (what a listener can receive).
    """

    def __init__(self, out_port: int, drop=0.0, corrupt=0.0, duplicate=0.0, reorder=0.0, noise=0.0,
                 silence=None, pause_s=0.0, flood=1, seed=1):
        self.rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.rx.bind(("127.0.0.1", 0))
        self.rx.settimeout(0.2)
        self.in_port = self.rx.getsockname()[1]
        self.tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.out = ("127.0.0.1", out_port)
        self.p = dict(drop=drop, corrupt=corrupt, duplicate=duplicate, reorder=reorder, noise=noise)
        self.silence, self.pause_s, self.flood = silence, pause_s, flood
        self.rng = random.Random(seed)
        self.delivered: list[bytes] = []
        self.counts = dict(received=0, dropped=0, corrupted=0, duplicated=0, reordered=0, noise=0, silenced=0)
        self._stop = threading.Event()
        self._t = threading.Thread(target=self._run, daemon=True)

    def __enter__(self):
        self._t.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._t.join(5)
        self.rx.close()
        self.tx.close()

    def _send(self, data: bytes, intact: bool) -> None:
        for _ in range(self.flood):
            self.tx.sendto(data, self.out)
            if intact:
                self.delivered.append(data)
        time.sleep(0)   # let the listener's thread run

    def _run(self) -> None:
        held = None
        i = -1
        while not self._stop.is_set():
            try:
                data, _ = self.rx.recvfrom(65536)
            except socket.timeout:
                continue
            i += 1
            c, r = self.counts, self.rng
            c["received"] += 1
            if self.silence and self.silence[0] <= i < self.silence[0] + self.silence[1]:
                if i == self.silence[0]:
                    time.sleep(self.pause_s)
                c["silenced"] += 1
                continue
            if r.random() < self.p["drop"]:
                c["dropped"] += 1
                continue
            if r.random() < self.p["noise"]:
                c["noise"] += 1
                self._send(bytes(r.choice([b for b in range(256) if b not in (0xFD, 0xFE)]) for _ in range(20)),
                           False)
            intact = True
            if r.random() < self.p["corrupt"] and len(data) > 14:
                c["corrupted"] += 1
                k = r.randrange(10, len(data) - 2)   # a payload byte: the CRC fails, the framing holds
                data = data[:k] + bytes([data[k] ^ 0x5A]) + data[k + 1:]
                intact = False
            if held is None and r.random() < self.p["reorder"]:
                c["reordered"] += 1
                held = (data, intact)
                continue
            self._send(data, intact)
            if r.random() < self.p["duplicate"]:
                c["duplicated"] += 1
                self._send(data, intact)
            if held is not None:
                self._send(*held)
                held = None


def have(cmd: str) -> bool:
    return shutil.which(cmd) is not None or Path(sys.executable).with_name(cmd).exists()


def listen_options(monkeypatch, tmp_path, extras: list[list[str]]) -> list:
    """The :class:`~gcs_sysid.live.session.ListenOptions` ``gcs-sysid listen`` builds for each list of extra
    arguments (``run_listen`` replaced: nothing listens)."""
    import gcs_sysid.live.session as session
    from gcs_sysid.cli import build_parser
    from gcs_sysid.live.cli import cmd_listen

    got = []
    monkeypatch.setattr(session, "run_listen",
                        lambda af, out, opts: got.append(opts) or {"raw_log": "r", "raw_records": 0})
    base = ["listen", "udpin:0.0.0.0:14550", "--airframe", "a.toml", "--out", str(tmp_path)]
    for extra in extras:
        assert cmd_listen(build_parser().parse_args(base + extra)) == 0
    return got
