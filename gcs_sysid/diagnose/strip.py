"""Rewrite a .tlog without some message types (PARAM_VALUE, STATUSTEXT): the evaluation's blindfold.

A fault-injection log says what was injected, and when, in a PARAM_VALUE (ArduPlane's
``DISABLE_<SURFACE>``) and often a STATUSTEXT; a diagnosis evaluated on such a log must
not be able to read them. :func:`strip_tlog` copies a tlog record by record (8-byte
big-endian capture time in microseconds, then the MAVLink packet unchanged, as parsed
by pymavlink), leaving out the named message types and packets pymavlink cannot parse.
"""

from __future__ import annotations

import struct
from pathlib import Path

from ..errors import InputError

__all__ = ["strip_tlog"]


def strip_tlog(src, dst, drop: tuple[str, ...] = ("PARAM_VALUE", "STATUSTEXT")) -> dict[str, int]:
    """Copy the tlog ``src`` to ``dst`` without the message types in ``drop``.

    Args:
        src: input .tlog path. dst: output .tlog path (overwritten).
        drop: MAVLink message names to leave out.

    Returns:
        counts: ``{"kept": n, "dropped": n, "bad_data": n}`` and one entry per dropped type.

    Raises:
        InputError: ``src`` does not exist or holds no MAVLink message.
    """
    from pymavlink import mavutil

    src = Path(src)
    if not src.is_file():
        raise InputError(f"{src}: no such tlog")
    m = mavutil.mavlink_connection(str(src), dialect="ardupilotmega", robust_parsing=True)
    counts: dict[str, int] = {"kept": 0, "dropped": 0, "bad_data": 0}
    with open(dst, "wb") as out:
        while True:
            msg = m.recv_match()
            if msg is None:
                break
            kind = msg.get_type()
            if kind == "BAD_DATA":
                counts["bad_data"] += 1
                continue
            if kind in drop:
                counts["dropped"] += 1
                counts[kind] = counts.get(kind, 0) + 1
                continue
            out.write(struct.pack(">Q", int(round(msg._timestamp * 1e6))) + bytes(msg.get_msgbuf()))
            counts["kept"] += 1
    m.close()
    if counts["kept"] == 0:
        raise InputError(f"{src}: no MAVLink message found (is it a .tlog?)")
    return counts
