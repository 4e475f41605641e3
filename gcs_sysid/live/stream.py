"""Stream a tlog onto a live link as a stand-in vehicle (the log player, run as its own process).

Used by ``gcs-sysid simulate --live CONNECTION``: the project's simulation written as a tlog, then
played like a recorded flight, answering rate requests within its rates (``replay/``). The player
runs as ``python -m replay`` in a subprocess, so the package does not import the player.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from ..errors import InputError

__all__ = ["stream_tlog"]


def stream_tlog(path: str | Path, connection: str, speed: float = 1.0) -> int:
    """Play ``path`` onto ``connection`` at ``speed`` (1 real time, 0 as fast as possible).

    Returns:
        The number of packets sent.

    Raises:
        InputError: the player refused the log or the link (its one-line message).
    """
    r = subprocess.run([sys.executable, "-m", "replay", str(path), "--link", connection, "--speed", str(speed)],
                       capture_output=True, text=True)
    if r.returncode != 0:
        lines = (r.stderr.strip().splitlines() or [f"player exited with {r.returncode}"])
        raise InputError(lines[-1].removeprefix("replay: error: "))
    return int(r.stdout.split("sent ")[1].split()[0]) if "sent " in r.stdout else 0
