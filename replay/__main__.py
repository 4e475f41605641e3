"""``python -m replay LOG --link udpout:127.0.0.1:14550 [--speed 1.0] [--from S --to S]``.

Installed as the console command ``gcs-sysid-player`` (same arguments).
"""

from __future__ import annotations

import argparse
import struct
import sys
import time

from gcs_sysid.errors import SysidError
from replay.player import open_link, play, read_packets
from replay.vehicle import VehicleResponder, packet_source, recorded_rates


def _vehicle_ids(packets) -> tuple[int, int]:
    """(system, component) of the vehicle: the sender of ATTITUDE, else the most frequent non-GCS one."""
    from collections import Counter

    att = Counter(packet_source(p.data) for p in packets if p.name == "ATTITUDE")
    if att:
        return att.most_common(1)[0][0]
    other = Counter(packet_source(p.data) for p in packets)
    ids = [s for s, _ in other.most_common() if s[0] != 255]
    return ids[0] if ids else (1, 1)


def _responder(packets, link) -> VehicleResponder:
    from pymavlink.dialects.v20 import ardupilotmega as mavlink

    sysid, compid = _vehicle_ids(packets)
    mav = mavlink.MAVLink(None, srcSystem=sysid, srcComponent=compid)
    rates = recorded_rates(packets, (sysid, compid))
    return VehicleResponder(mav, rates, link.write)


def main(argv: list[str] | None = None) -> int:
    """Run the player; returns the exit code (0 ok, 2 bad log or link, 130 interrupted)."""
    ap = argparse.ArgumentParser(prog="python -m replay",
                                 description="Stream a recorded MAVLink telemetry log (.tlog) onto a link.")
    ap.add_argument("log", help="the .tlog file")
    ap.add_argument("--link", default="udpout:127.0.0.1:14550",
                    help="pymavlink connection string: udpout:HOST:PORT, tcp:HOST:PORT, udpin:..., or a serial "
                         "device (default %(default)s)")
    ap.add_argument("--baud", type=int, default=115200, help="serial baud rate (default %(default)s)")
    ap.add_argument("--speed", type=float, default=1.0, help="time scale: 1 real time, 0 as fast as possible")
    ap.add_argument("--from", dest="t_from", type=float, default=None, metavar="S",
                    help="start S seconds after the log's first record")
    ap.add_argument("--to", dest="t_to", type=float, default=None, metavar="S",
                    help="stop S seconds after the log's first record")
    ap.add_argument("--no-answer", action="store_true",
                    help="do not answer rate requests (by default the player answers SET_MESSAGE_INTERVAL and "
                         "REQUEST_DATA_STREAM like a vehicle, within the recorded rates)")
    ap.add_argument("--received", default=None, metavar="FILE",
                    help="write what the far end sends (requests, status texts) to this .tlog")
    ap.add_argument("--linger", type=float, default=0.0, metavar="S",
                    help="keep answering and recording what arrives for S seconds after the last packet")
    ap.add_argument("-q", "--quiet", action="store_true", help="no summary line")
    args = ap.parse_args(argv)
    try:
        if args.speed < 0:
            raise SysidError(f"--speed {args.speed}: must be >= 0 (0 = as fast as possible)")
        if args.t_from is not None and args.t_to is not None and args.t_to < args.t_from:
            raise SysidError(f"--to {args.t_to} is before --from {args.t_from}")
        bad = [0]
        packets = list(read_packets(args.log, bad))  # reads and checks the log before the link is opened
        link = open_link(args.link, args.baud)
        responder = None if args.no_answer else _responder(packets, link)
        t0 = time.monotonic()
        received = open(args.received, "wb") if args.received else None

        def poll() -> None:
            for _ in range(100):   # bounded: a flood of requests cannot stall the stream
                msg = link.recv_msg()
                if msg is None:
                    return
                if msg.get_type() != "BAD_DATA":
                    if received is not None:
                        received.write(struct.pack(">Q", int(time.time() * 1e6)) + bytes(msg.get_msgbuf()))
                        received.flush()
                    if responder is not None:
                        responder.handle(msg)
                    while responder is not None and responder.log and not args.quiet:
                        print(f"replay: request: {responder.log.pop(0)}", file=sys.stderr, flush=True)

        try:
            n = play(packets, link.write, args.speed, args.t_from, args.t_to,
                     poll=poll if (responder is not None or received is not None) else None,
                     allow=responder.allow if responder is not None else None)
            end = time.monotonic() + args.linger
            while True:
                poll()
                if time.monotonic() >= end:
                    break
                time.sleep(0.01)
        finally:
            link.close()
            if received is not None:
                received.close()
    except SysidError as exc:
        print(f"replay: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    if not args.quiet:
        extra = f", {bad[0]} corrupt record(s) skipped" if bad[0] else ""
        print(f"replay: sent {n} packets from {args.log} to {args.link} in {time.monotonic() - t0:.1f} s{extra}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
