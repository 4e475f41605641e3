"""A live session inside a host that owns the link (a MAVProxy module, any GCS plugin).

The host hands every received message to :meth:`HostedSession.feed` (which writes it to
``raw.tlog`` and queues it for the learner thread, then returns) and calls :meth:`HostedSession.tick`
from its idle loop. Outgoing packets (requests, the component's heartbeat, status texts, confidence
values, parameter answers) go through the host's ``write`` callable. No import of the host here.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Callable

from .learner import LearnOptions
from .session import TICK_S, ListenOptions, LiveSession

__all__ = ["HostLink", "HostedSession"]


class HostLink:
    """The link as seen by a :class:`LiveSession` when the host reads the real one: write only."""

    def __init__(self, write: Callable[[bytes], object]):
        self.write = write
        self.mav_loss = 0

    def recv_msg(self):
        return None

    def close(self) -> None:
        pass


class HostedSession:
    """Incremental identification fed by a host.

    Args:
        airframe_path: airframe TOML file.
        out_dir: output directory (``raw.tlog``, ``session.json``, ``report.md``, ``model``).
        write: sends raw bytes on the host's link to the vehicle.
        learn: learner schedule (None: log and monitor only).
        request, component, system_id, use_mavsdk: as in :class:`ListenOptions`.

    Raises:
        InputError: bad airframe file.
    """

    def __init__(self, airframe_path: str | Path, out_dir: str | Path, write: Callable[[bytes], object],
                 learn: LearnOptions | None = LearnOptions(), request: bool = True, component: bool = True,
                 system_id: int | None = None, use_mavsdk: bool = True, name: str = "host"):
        from ..airframe import load_airframe

        opts = ListenOptions(connection=name, learn=learn, request=request, component=component,
                             system_id=system_id, console=False, use_mavsdk=use_mavsdk)
        self.session = LiveSession(load_airframe(airframe_path), out_dir, opts, link=HostLink(write))
        self.session.start_learning()
        self._last_tick = 0.0
        self.closed = False

    def feed(self, msg) -> None:
        """One received message: logged to raw.tlog and queued; returns at once."""
        if not self.closed:
            self.session.receiver.handle(msg, time.time())

    def tick(self) -> None:
        """Periodic work (at most every :data:`TICK_S`): requests, heartbeat, status texts."""
        now = time.monotonic()
        if not self.closed and now - self._last_tick >= TICK_S:
            self._last_tick = now
            self.session.tick()

    def status(self) -> str:
        """One paragraph: link, packets, rates short of the asked ones, samples learned, confidence."""
        s = self.session.snapshot()
        conf = ", ".join(f"{k} {v:.2f}" for k, v in (s.get("confidence") or {}).items()) or "no model yet"
        short = ", ".join(f"{k} {g:.0f}/{a:g} Hz" for k, (a, g) in s.get("shortfalls", {}).items()) or "none"
        return (f"sysid: {s['link']}, {s['raw_records']} packets in {s['raw_log']}, corrupt {s['bad_data']}; "
                f"learned {s.get('samples_learned', 0)} samples in {s.get('steps', 0)} steps "
                f"(queue {s.get('queue', 0)}); confidence: {conf}; rates short: {short}")

    def suggest(self) -> str:
        """The current top maneuver suggestion (or why there is none yet)."""
        s = self.session.snapshot()
        return s.get("top_suggestion") or "sysid: no suggestion yet (the model needs more samples)"

    def report(self) -> Path:
        """Write ``session.json`` and ``report.md`` now (the session goes on); returns the report path."""
        from .report import write_session_report

        write_session_report(self.session.snapshot(), self.session.out)
        return self.session.out / "report.md"

    def save(self) -> Path | None:
        """Save the model now into ``out_dir/model``; returns the path or None without a model."""
        learner = self.session.learner
        if learner is None:
            return None
        if hasattr(learner, "save"):   # the learner runs in the worker process (live.remote)
            return self.session.out / "model" if learner.save(self.session.out / "model") else None
        if learner.model is None:
            return None
        learner.model.save(self.session.out / "model")
        return self.session.out / "model"

    def close(self) -> dict:
        """End: finish learning, save the model, write the report. Returns the final snapshot."""
        if self.closed:
            return {}
        self.closed = True
        return self.session.close()
