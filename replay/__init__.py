"""Log player: streams a recorded MAVLink telemetry log (.tlog) onto a live link.

Ground-station plugins, gcs-sysid's live mode and MAVProxy modules can then be exercised against a
real recorded flight: ``python -m replay flight.tlog --link udpout:127.0.0.1:14550``.
"""

from replay.player import Packet, open_link, play, read_packets

__all__ = ["Packet", "read_packets", "open_link", "play"]
